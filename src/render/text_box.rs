//! How much room a block of text takes in a frame, without a font at hand: the advance widths of
//! DejaVu Sans (the font the frames name first and the PNG frames are drawn with), so that
//! labels can be kept from covering one another.

use super::svg::{Anchor, LINE};

/// DejaVu Sans' advance widths of the printable ASCII characters, from the space (32) to `~`
/// (126), in units of 1/2048 em (the font's `hmtx` table).
const ADVANCE: [u16; 95] = [
    651, 821, 942, 1716, 1303, 1946, 1597, 563, 799, 799, 1024, 1716, 651, 739, 651, 690, 1303,
    1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 690, 690, 1716, 1716, 1716, 1087, 2048,
    1401, 1405, 1430, 1577, 1294, 1178, 1587, 1540, 604, 604, 1343, 1141, 1767, 1532, 1612, 1235,
    1612, 1423, 1300, 1251, 1499, 1401, 2025, 1403, 1251, 1403, 799, 690, 799, 1716, 1024, 1024,
    1255, 1300, 1126, 1300, 1260, 721, 1300, 1298, 569, 569, 1186, 569, 1995, 1298, 1253, 1300,
    1300, 842, 1067, 803, 1298, 1212, 1675, 1212, 1212, 1075, 1303, 690, 1303, 1716,
];

/// The font's ascent and descent, in em (`hhea`: 1901 and 483 of 2048).
const ASCENT: f64 = 1901.0 / 2048.0;
const DESCENT: f64 = 483.0 / 2048.0;

/// The width of `text` in pixels at font size `font`; a character beyond ASCII counts as one em
/// (as wide as the widest).
pub fn width(text: &str, font: f64) -> f64 {
    let units: u32 = text
        .chars()
        .map(|c| match c as usize {
            k @ 32..=126 => u32::from(ADVANCE[k - 32]),
            _ => 2048,
        })
        .sum();
    f64::from(units) / 2048.0 * font
}

/// A rectangle of pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Left edge.
    pub x0: f64,
    /// Top edge.
    pub y0: f64,
    /// Right edge.
    pub x1: f64,
    /// Bottom edge.
    pub y1: f64,
}

impl Rect {
    /// Whether the two rectangles share some area.
    pub fn meets(&self, other: &Rect) -> bool {
        self.x0 < other.x1 && other.x0 < self.x1 && self.y0 < other.y1 && other.y0 < self.y1
    }
}

/// The box of `lines` written at anchor `a` in font size `font`, as a frame writes them.
pub fn block(a: &Anchor, lines: &[String], font: f64) -> Rect {
    let line = LINE * font / super::svg::FONT;
    let y0 = a.first_baseline(lines.len(), line, font);
    let w = lines.iter().map(|l| width(l, font)).fold(0.0, f64::max);
    let x0 = match a.h {
        "start" => a.x,
        "end" => a.x - w,
        _ => a.x - w / 2.0,
    };
    Rect {
        x0,
        y0: y0 - ASCENT * font,
        x1: x0 + w,
        y1: y0 + (lines.len().max(1) - 1) as f64 * line + DESCENT * font,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_follow_the_font() {
        // "Ball-1" in DejaVu Sans: B a l l - 1
        let units = 1405 + 1255 + 569 + 569 + 739 + 1303;
        assert_eq!(width("Ball-1", 2048.0), f64::from(units));
        assert_eq!(width("\u{2026}", 12.0), 12.0);
        assert!(width("WWW", 12.0) > width("iii", 12.0));
    }

    #[test]
    fn a_block_grows_with_its_lines_and_follows_its_anchor() {
        let a = Anchor {
            x: 100.0,
            y: 50.0,
            h: "middle",
            v: "center",
        };
        let one = block(&a, &["Sector-1".to_string()], 12.0);
        let three = block(
            &a,
            &["Sector-1".into(), "Ball-1".into(), "Ball-2".into()],
            12.0,
        );
        assert!((one.x0 + one.x1) / 2.0 - 100.0 < 1e-9);
        assert!(three.y0 < one.y0 && three.y1 > one.y1);
        assert!(one.y0 < 50.0 && one.y1 > 50.0);
        let start = block(&Anchor { h: "start", ..a }, &["x".into()], 12.0);
        assert_eq!(start.x0, 100.0);
        assert!(
            one.meets(&three)
                && !one.meets(&Rect {
                    x0: 0.0,
                    y0: 0.0,
                    x1: 1.0,
                    y1: 1.0
                })
        );
    }
}
