//! A frame as SVG (thesis 4.2, plates 1–13).
//!
//! The picture is split in two layers: the table ([`table_layer`]: cushions, pockets, corners,
//! sector outlines), which is the same in every frame, and what moves ([`moving_layer`]: balls,
//! velocity vectors, names, the lists under pocket and sector labels, the title). The HTML player
//! embeds the first and draws the second itself with the same [`View`] and the same rules.
//!
//! Coordinates are pixels: `x` grows to the right and `y` downwards, so the table's `y` is
//! flipped. The root element carries the mapping (`data-scale`, `data-left`, `data-top`,
//! `data-lo-x`, `data-hi-y`): a table point `(x, y)` is drawn at
//! `(left + (x - lo_x)·scale, top + (hi_y - y)·scale)`. Balls and vectors carry `data-ball`
//! with the ball's name.

use super::text_box::{self, Rect};
use super::{centroid, format_time, sectors_of, Scene, Shot, Turn};
use crate::engine::{BallState, EventKind, Fixed};
use crate::geometry::Vec2;
use crate::summary::MessageCounts;
use std::fmt::Write;

/// The longer side of the table, in pixels.
pub const TABLE_PIXELS: f64 = 800.0;
/// Room left and right of the table (pocket and cushion labels).
pub const MARGIN_X: f64 = 110.0;
/// Height of the title's band at the top (pixels).
pub const TITLE_BAND: f64 = 56.0;
/// Height of the counts' band at the bottom (pixels).
pub const COUNTS_BAND: f64 = 40.0;
/// Font size of labels and lists (pixels).
pub const FONT: f64 = 12.0;
/// Line height of lists (pixels).
pub const LINE: f64 = 14.0;
/// The most names a list under a label shows before `… N more`.
pub const LIST_MAX: usize = 6;
/// Balls are named only on tables with at most this many balls.
pub const MAX_NAMED_BALLS: usize = 400;
/// Balls are named only when their radius is at least this many pixels.
pub const MIN_NAMED_RADIUS: f64 = 6.0;

/// Colours of the picture.
pub mod colour {
    /// The table's cloth.
    pub const CLOTH: &str = "#d8ecd4";
    /// Cushions.
    pub const CUSHION: &str = "#5d4037";
    /// Pocket lines and corners.
    pub const POCKET: &str = "#111111";
    /// Sector outlines and labels.
    pub const SECTOR: &str = "#1f5fbf";
    /// Balls.
    pub const BALL: &str = "#fffdf5";
    /// Velocity vectors.
    pub const VECTOR: &str = "#c62828";
    /// Text.
    pub const TEXT: &str = "#111111";
    /// Quiet text (cushion names, counts).
    pub const QUIET: &str = "#555555";
}

/// Which optional parts a picture shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Velocity vectors.
    pub vectors: bool,
    /// Names of balls, cushions, pockets and sectors, and the lists under them.
    pub labels: bool,
    /// Sector outlines and labels (when the scene has sectors).
    pub sectors: bool,
    /// The time a velocity arrow spans: each arrow runs from the ball to where it would be this
    /// much later (cut at the table's edge).
    pub arrow_time: f64,
}

impl Default for Style {
    fn default() -> Style {
        Style {
            vectors: true,
            labels: true,
            sectors: true,
            arrow_time: 1.0,
        }
    }
}

/// The longest velocity arrow, as a share of the table's shorter side.
const ARROW_SHARE: f64 = 0.3;

impl Style {
    /// The style of a run's pictures: vectors only up to [`MAX_NAMED_BALLS`] balls (beyond,
    /// they cover the table), each arrow spanning one time unit, or less where the fastest
    /// ball of `balls` (the first frame's) would otherwise run past 30 % of the
    /// table's shorter side.
    pub fn for_run(scene: &Scene, balls: &[BallState]) -> Style {
        let side = (scene.table.hi - scene.table.lo)
            .x
            .min((scene.table.hi - scene.table.lo).y);
        let fastest = balls
            .iter()
            .map(|b| b.velocity().norm())
            .fold(0.0, f64::max);
        let arrow_time = if fastest > 0.0 && side.is_finite() {
            (ARROW_SHARE * side / fastest).min(1.0)
        } else {
            1.0
        };
        Style {
            vectors: balls.len() <= MAX_NAMED_BALLS,
            arrow_time,
            ..Style::default()
        }
    }
}

/// Where an arrow from `p` (on the table) towards `head` ends: at `head`, or where it leaves
/// the table's box from `lo` to `hi`.
pub fn arrow_head(p: Vec2, head: Vec2, lo: Vec2, hi: Vec2) -> Vec2 {
    let d = head - p;
    let mut s: f64 = 1.0;
    for (x, dx, a, b) in [(p.x, d.x, lo.x, hi.x), (p.y, d.y, lo.y, hi.y)] {
        if dx > 0.0 && x + dx > b {
            s = s.min(((b - x) / dx).max(0.0));
        } else if dx < 0.0 && x + dx < a {
            s = s.min(((a - x) / dx).max(0.0));
        }
    }
    p + s * d
}

/// How table coordinates map to pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Pixels per length unit.
    pub scale: f64,
    /// Table coordinates drawn at the left edge of the table's box.
    pub lo_x: f64,
    /// Table coordinate drawn at the top edge of the table's box.
    pub hi_y: f64,
    /// Pixel column of `lo_x`.
    pub left: f64,
    /// Pixel row of `hi_y`.
    pub top: f64,
    /// Width of the picture (pixels).
    pub width: f64,
    /// Height of the picture (pixels).
    pub height: f64,
}

impl View {
    /// The view of a scene's table: its longer side [`TABLE_PIXELS`] long, with margins.
    pub fn new(scene: &Scene) -> View {
        let (lo, hi) = (scene.table.lo, scene.table.hi);
        let span = hi - lo;
        let extent = span.x.max(span.y);
        let scale = if extent > 0.0 && extent.is_finite() {
            TABLE_PIXELS / extent
        } else {
            1.0
        };
        // Room for the longest list under a pocket label above or below the table.
        let lines = 1 + (scene.table.n_balls as usize).min(LIST_MAX);
        let block = lines as f64 * LINE + 16.0;
        let room = |side: &str| {
            let facing = scene
                .table
                .pockets
                .iter()
                .any(|(from, to)| outward(*from, *to).3 == side);
            if facing {
                block
            } else {
                24.0
            }
        };
        let (top, bottom) = (TITLE_BAND + room("up"), COUNTS_BAND + room("down"));
        View {
            scale,
            lo_x: lo.x,
            hi_y: hi.y,
            left: MARGIN_X,
            top,
            width: (span.x * scale + 2.0 * MARGIN_X).ceil(),
            height: (span.y * scale + top + bottom).ceil(),
        }
    }

    /// The pixel position of table point `p`.
    pub fn px(&self, p: Vec2) -> (f64, f64) {
        (
            self.left + (p.x - self.lo_x) * self.scale,
            self.top + (self.hi_y - p.y) * self.scale,
        )
    }
}

/// Where a block of text lines stands and how it is aligned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anchor {
    /// Pixel column.
    pub x: f64,
    /// Pixel row.
    pub y: f64,
    /// `start`, `middle` or `end` (SVG `text-anchor`).
    pub h: &'static str,
    /// `up` (the block ends above `y`), `down` (it starts below `y`) or `center`.
    pub v: &'static str,
}

impl Anchor {
    /// The baseline of the first of `n` lines `line` apart in font size `font`.
    pub fn first_baseline(&self, n: usize, line: f64, font: f64) -> f64 {
        let n = n.max(1) as f64;
        match self.v {
            "up" => self.y - (n - 1.0) * line - 2.0,
            "down" => self.y + font,
            _ => self.y - (n - 1.0) * line / 2.0 + 0.35 * font,
        }
    }
}

/// Where the label of a fixed segment (a pocket or cushion) from `from` to `to` stands: beyond
/// its midpoint, `gap` pixels outside the table (the table lies on the right going from → to).
pub fn outside_anchor(view: &View, from: Vec2, to: Vec2, gap: f64) -> Anchor {
    let (nx, ny, h, v) = outward(from, to);
    let (mx, my) = view.px(Vec2::new((from.x + to.x) / 2.0, (from.y + to.y) / 2.0));
    Anchor {
        x: mx + nx * gap,
        y: my + ny * gap,
        h,
        v,
    }
}

/// The outward unit normal of a fixed segment on the screen (`y` down), and how text beyond it
/// is aligned: the table lies on the right going from → to, so outward is the left normal.
fn outward(from: Vec2, to: Vec2) -> (f64, f64, &'static str, &'static str) {
    let d = to - from;
    let len = d.norm().max(f64::MIN_POSITIVE);
    let (nx, ny) = (-d.y / len, -(d.x / len));
    let h = if nx > 0.4 {
        "start"
    } else if nx < -0.4 {
        "end"
    } else {
        "middle"
    };
    let v = if ny < -0.4 {
        "up"
    } else if ny > 0.4 {
        "down"
    } else {
        "center"
    };
    (nx, ny, h, v)
}

/// The anchor of pocket `k`'s label.
pub fn pocket_anchor(scene: &Scene, view: &View, k: usize) -> Anchor {
    let (from, to) = scene.table.pockets[k];
    outside_anchor(view, from, to, 12.0)
}

/// Where sector `k`'s label may stand, best first: its centroid, then points inside the sector
/// on rings around the centroid, nearest first, so that a label can step off the names of the
/// balls it would cover.
pub fn sector_anchors(scene: &Scene, view: &View, k: usize) -> Vec<Anchor> {
    let Some(layout) = &scene.sectors else {
        return Vec::new();
    };
    let poly = &layout.polys[k];
    let c = centroid(&poly.points);
    let (lo, hi) = poly.bounds();
    let step = (hi - lo).x.min((hi - lo).y) / 10.0;
    let d = std::f64::consts::FRAC_1_SQRT_2;
    let directions = [
        (0.0, 1.0),
        (0.0, -1.0),
        (1.0, 0.0),
        (-1.0, 0.0),
        (d, d),
        (-d, d),
        (d, -d),
        (-d, -d),
    ];
    let rings =
        (1..=4).flat_map(|j| directions.map(|(x, y)| c + j as f64 * step * Vec2::new(x, y)));
    std::iter::once(c)
        .chain(rings.filter(|&p| poly.contains(p)))
        .map(|p| {
            let (x, y) = view.px(p);
            Anchor {
                x,
                y,
                h: "middle",
                v: "center",
            }
        })
        .collect()
}

/// A list of names under a label, at most [`LIST_MAX`] lines with `… N more` at the end.
pub fn list_lines(label: String, names: Vec<String>) -> Vec<String> {
    let mut lines = vec![label];
    if names.len() > LIST_MAX {
        let more = names.len() - (LIST_MAX - 1);
        lines.extend(names.into_iter().take(LIST_MAX - 1));
        lines.push(format!("\u{2026} {more} more"));
    } else {
        lines.extend(names);
    }
    lines
}

/// Escapes text for XML.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// Two decimals are a hundredth of a pixel.
fn n(x: f64) -> String {
    let s = format!("{x:.2}");
    if s == "-0.00" {
        "0.00".into()
    } else {
        s
    }
}

/// Writes a block of lines at an anchor; sector and pocket labels get a white outline under the
/// letters so that they read over balls and vectors.
fn text_block(out: &mut String, a: &Anchor, lines: &[String], class: &str, fill: &str, font: f64) {
    let line = LINE * font / FONT;
    let y0 = a.first_baseline(lines.len(), line, font);
    let halo = if class.contains("sector-label") || class.contains("pocket-label") {
        r#" stroke="white" stroke-width="3" stroke-linejoin="round" paint-order="stroke""#
    } else {
        ""
    };
    let _ = write!(
        out,
        r#"<text class="{class}" x="{}" y="{}" text-anchor="{}" font-size="{}" fill="{fill}"{halo}>"#,
        n(a.x),
        n(y0),
        a.h,
        n(font)
    );
    for (i, l) in lines.iter().enumerate() {
        let _ = write!(
            out,
            r#"<tspan x="{}" y="{}">{}</tspan>"#,
            n(a.x),
            n(y0 + i as f64 * line),
            escape(l)
        );
    }
    out.push_str("</text>");
}

/// The font size of ball names for balls of `r_px` pixels.
pub fn ball_font(r_px: f64) -> f64 {
    (r_px * 0.55).clamp(7.0, 11.0)
}

/// Whether balls get names on this table at this view.
pub fn names_balls(scene: &Scene, view: &View, balls: &[BallState]) -> bool {
    let small = balls.iter().map(|b| b.radius).fold(f64::INFINITY, f64::min);
    balls.len() <= MAX_NAMED_BALLS
        && small * view.scale >= MIN_NAMED_RADIUS
        && scene.table.n_balls > 0
}

/// The `<svg>` start tag with the coordinate mapping; `xmlns` for a file of its own.
pub fn open_svg(view: &View, standalone: bool) -> String {
    format!(
        r#"<svg {}width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="DejaVu Sans, Verdana, sans-serif" data-scale="{}" data-left="{}" data-top="{}" data-lo-x="{}" data-hi-y="{}">"#,
        if standalone {
            r#"xmlns="http://www.w3.org/2000/svg" "#
        } else {
            ""
        },
        view.scale,
        view.left,
        view.top,
        view.lo_x,
        view.hi_y,
        w = view.width,
        h = view.height,
    )
}

/// The fixed part of the picture: background, cloth, sector outlines, cushions with their names,
/// pockets and corners, and the arrowhead of velocity vectors.
pub fn table_layer(scene: &Scene, view: &View, style: &Style) -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        r#"<defs><marker id="poolsim-arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" markerHeight="7" orient="auto"><path d="M0,0 L10,5 L0,10 z" fill="{}"/></marker></defs>"#,
        colour::VECTOR
    );
    let _ = write!(
        out,
        r#"<rect x="0" y="0" width="{}" height="{}" fill="white"/>"#,
        view.width, view.height
    );
    let (x0, y0) = view.px(Vec2::new(scene.table.lo.x, scene.table.hi.y));
    let (x1, y1) = view.px(Vec2::new(scene.table.hi.x, scene.table.lo.y));
    let _ = write!(
        out,
        r#"<rect class="cloth" x="{}" y="{}" width="{}" height="{}" fill="{}"/>"#,
        n(x0),
        n(y0),
        n(x1 - x0),
        n(y1 - y0),
        colour::CLOTH
    );
    if let (Some(layout), true) = (&scene.sectors, style.sectors) {
        for (k, poly) in layout.polys.iter().enumerate() {
            let pts: Vec<String> = poly
                .points
                .iter()
                .map(|p| {
                    let (x, y) = view.px(*p);
                    format!("{},{}", n(x), n(y))
                })
                .collect();
            let _ = write!(
                out,
                r#"<polygon class="sector" data-sector="{}" points="{}" fill="none" stroke="{}" stroke-width="1.5" stroke-dasharray="8 5"/>"#,
                Scene::sector_name(k),
                pts.join(" "),
                colour::SECTOR
            );
        }
    }
    let t = &scene.table;
    for (k, (from, to, _)) in t.cushions.iter().enumerate() {
        let (ax, ay) = view.px(*from);
        let (bx, by) = view.px(*to);
        let _ = write!(
            out,
            r#"<line class="cushion" data-cushion="Cushion-{}" x1="{}" y1="{}" x2="{}" y2="{}" stroke="{}" stroke-width="5" stroke-linecap="round"/>"#,
            k + 1,
            n(ax),
            n(ay),
            n(bx),
            n(by),
            colour::CUSHION
        );
        if style.labels {
            let a = outside_anchor(view, *from, *to, 8.0);
            text_block(
                &mut out,
                &a,
                &[format!("Cushion-{}", k + 1)],
                "label cushion-label",
                colour::QUIET,
                10.0,
            );
        }
    }
    for (k, (from, to)) in t.pockets.iter().enumerate() {
        let (ax, ay) = view.px(*from);
        let (bx, by) = view.px(*to);
        let _ = write!(
            out,
            r#"<line class="pocket" data-pocket="Pocket-{}" x1="{}" y1="{}" x2="{}" y2="{}" stroke="{}" stroke-width="3" stroke-dasharray="4 3"/>"#,
            k + 1,
            n(ax),
            n(ay),
            n(bx),
            n(by),
            colour::POCKET
        );
    }
    for (k, (c, _)) in t.corners.iter().enumerate() {
        let (x, y) = view.px(*c);
        let _ = write!(
            out,
            r#"<circle class="corner" data-corner="Corner-{}" cx="{}" cy="{}" r="4" fill="{}"/>"#,
            k + 1,
            n(x),
            n(y),
            colour::POCKET
        );
    }
    out
}

/// The names of the balls in each pocket, by pocket.
fn pocket_contents(scene: &Scene, balls: &[BallState]) -> Vec<Vec<String>> {
    let mut lists = vec![Vec::new(); scene.table.pockets.len()];
    for (i, b) in balls.iter().enumerate() {
        if let Some(k) = b.pocket {
            if let Some(list) = lists.get_mut(k as usize) {
                list.push(scene.table.name(i as u32));
            }
        }
    }
    lists
}

/// The counts line under the table: events by kind and, for objects engines, messages.
pub fn counts_lines(shot: &Shot) -> Vec<String> {
    let e = &shot.events;
    let mut lines = vec![format!(
        "events {} (ball-ball {}, ball-cushion {}, ball-corner {}, ball-pocket {})",
        e.total(),
        e.get(EventKind::BallBall),
        e.get(EventKind::BallCushion),
        e.get(EventKind::BallCorner),
        e.get(EventKind::BallPocket)
    )];
    if let Some(m) = &shot.messages {
        let total = MessageCounts::from_named(m).total;
        let parts: Vec<String> = m
            .iter()
            .filter(|(_, c)| *c > 0)
            .map(|(name, c)| format!("{name} {c}"))
            .collect();
        lines.push(format!("messages {total} ({})", parts.join(", ")));
    }
    lines
}

/// What moves: balls with their names (and sectors), velocity vectors, the lists under pocket
/// and sector labels, the title and the counts.
pub fn moving_layer(scene: &Scene, view: &View, shot: &Shot, style: &Style) -> String {
    let mut out = String::new();
    let balls = &shot.frame.balls;
    let sectored = style.sectors && scene.sectors.is_some();
    let in_sectors: Vec<Vec<u32>> = if sectored {
        balls.iter().map(|b| sectors_of(scene, b)).collect()
    } else {
        vec![Vec::new(); balls.len()]
    };
    if let Some(turn) = scene.turn.as_ref().filter(|t| t.end == shot.frame.t) {
        start_outlines(&mut out, view, turn, balls);
    }
    ball_circles(&mut out, scene, view, balls);
    if style.vectors {
        velocity_arrows(&mut out, scene, view, balls, style.arrow_time);
    }
    if style.labels {
        let mut taken = Vec::new();
        if names_balls(scene, view, balls) {
            taken = ball_labels(&mut out, scene, view, balls, &in_sectors);
        }
        if sectored {
            sector_labels(&mut out, scene, view, balls, &in_sectors, taken);
        }
    }
    // Pocket labels and their lists are part of the state: always shown.
    for (k, names) in pocket_contents(scene, balls).into_iter().enumerate() {
        let pocket = scene
            .table
            .name(scene.table.fixed_id(Fixed::Pocket(k as u32)));
        let a = pocket_anchor(scene, view, k);
        let lines = list_lines(pocket, names);
        text_block(&mut out, &a, &lines, "pocket-label", colour::TEXT, FONT);
    }
    title_and_counts(&mut out, scene, view, shot);
    out
}

/// Where each ball started, outlined (dashed) beneath the balls: on a reversal's last frame the
/// eye sees each ball back on its start.
fn start_outlines(out: &mut String, view: &View, turn: &Turn, balls: &[BallState]) {
    for (p, b) in turn.starts.iter().zip(balls) {
        if let Some(p) = p {
            let (x, y) = view.px(*p);
            let _ = write!(
                out,
                r#"<circle class="start" cx="{}" cy="{}" r="{}" fill="none" stroke="{}" stroke-width="1.5" stroke-dasharray="4 3"/>"#,
                n(x),
                n(y),
                n(b.radius * view.scale + 3.0),
                colour::SECTOR
            );
        }
    }
}

/// What a frame of a run with a reversal says under its title: the reversal to come, or, once
/// it is past, how far the balls are from retracing their steps.
pub fn turn_line(turn: &Turn, t: f64, mirror_distance: Option<f64>) -> String {
    let at = format_time(turn.at);
    match mirror_distance {
        Some(d) if t >= turn.at => format!(
            "turned around at {at}: the farthest any ball is from where it was at {} is {}",
            format_time(2.0 * turn.at - t),
            if d == 0.0 {
                "0".to_string()
            } else {
                format!("{d:.1e}")
            }
        ),
        _ if t >= turn.at => format!("turned around at {at}"),
        _ => format!("every ball turns around at {at}"),
    }
}

/// Every ball on the table as a circle.
fn ball_circles(out: &mut String, scene: &Scene, view: &View, balls: &[BallState]) {
    for (i, b) in balls.iter().enumerate() {
        if b.pocket.is_some() {
            continue;
        }
        let (x, y) = view.px(b.traj.position);
        let look = scene.looks.get(i);
        let fill = look
            .and_then(|l| l.colour.as_deref())
            .unwrap_or(colour::BALL);
        let _ = write!(
            out,
            r#"<circle class="ball" data-ball="{}" cx="{}" cy="{}" r="{}" fill="{}" stroke="black" stroke-width="1.5"/>"#,
            scene.table.name(i as u32),
            n(x),
            n(y),
            n(b.radius * view.scale),
            fill
        );
        // a label (a pool ball's number) sits on a white disc, readable on any colour
        if look
            .and_then(|l| l.label.as_deref())
            .is_some_and(|l| !l.is_empty())
        {
            let _ = write!(
                out,
                r#"<circle class="ball-disc" cx="{}" cy="{}" r="{}" fill="white"/>"#,
                n(x),
                n(y),
                n(0.55 * b.radius * view.scale)
            );
        }
    }
}

/// Every moving ball's velocity, as an arrow `arrow_time` long, cut at the table's edge.
fn velocity_arrows(
    out: &mut String,
    scene: &Scene,
    view: &View,
    balls: &[BallState],
    arrow_time: f64,
) {
    let (lo, hi) = (scene.table.lo, scene.table.hi);
    for (i, b) in balls.iter().enumerate() {
        let v = b.velocity();
        if b.pocket.is_some() || v == Vec2::ZERO {
            continue;
        }
        let p = b.traj.position;
        let (x, y) = view.px(p);
        let (hx, hy) = view.px(arrow_head(p, p + arrow_time * v, lo, hi));
        let _ = write!(
            out,
            r#"<line class="velocity" data-ball="{}" x1="{}" y1="{}" x2="{}" y2="{}" stroke="{}" stroke-width="1.5" marker-end="url(#poolsim-arrow)"/>"#,
            scene.table.name(i as u32),
            n(x),
            n(y),
            n(hx),
            n(hy),
            colour::VECTOR
        );
    }
}

/// Each ball's name, and the sectors it is in, on the ball. The boxes the names and the balls
/// take.
fn ball_labels(
    out: &mut String,
    scene: &Scene,
    view: &View,
    balls: &[BallState],
    in_sectors: &[Vec<u32>],
) -> Vec<Rect> {
    let mut taken = Vec::new();
    for (i, b) in balls.iter().enumerate() {
        if b.pocket.is_some() {
            continue;
        }
        let (x, y) = view.px(b.traj.position);
        let label = scene.looks.get(i).and_then(|l| l.label.clone());
        if label.as_deref() == Some("") {
            continue;
        }
        let mut lines = vec![label.unwrap_or_else(|| scene.table.name(i as u32))];
        lines.extend(
            in_sectors[i]
                .iter()
                .map(|&k| Scene::sector_name(k as usize)),
        );
        let a = Anchor {
            x,
            y,
            h: "middle",
            v: "center",
        };
        let font = ball_font(b.radius * view.scale);
        text_block(out, &a, &lines, "label ball-label", colour::TEXT, font);
        taken.push(text_box::block(&a, &lines, font));
        let r = b.radius * view.scale;
        taken.push(Rect {
            x0: x - r,
            y0: y - r,
            x1: x + r,
            y1: y + r,
        });
    }
    taken
}

/// Each sector's name and the balls in it, at the first of its anchors ([`sector_anchors`])
/// where they cover no named ball (`taken`) nor another sector's label; else its name alone at
/// the first such anchor; else nothing (each ball's label names its sectors, so nothing is
/// lost). Text widths are DejaVu Sans'; the page follows the same rule with the sizes its browser
/// measures.
fn sector_labels(
    out: &mut String,
    scene: &Scene,
    view: &View,
    balls: &[BallState],
    in_sectors: &[Vec<u32>],
    mut taken: Vec<Rect>,
) {
    let Some(layout) = &scene.sectors else {
        return;
    };
    for k in 0..layout.polys.len() {
        let names: Vec<String> = (0..balls.len())
            .filter(|&i| in_sectors[i].contains(&(k as u32)))
            .map(|i| scene.table.name(i as u32))
            .collect();
        let lines = list_lines(Scene::sector_name(k), names);
        let anchors = sector_anchors(scene, view, k);
        let fits = [&lines[..], &lines[..1]].into_iter().find_map(|lines| {
            anchors.iter().find_map(|a| {
                let rect = text_box::block(a, lines, FONT);
                (!taken.iter().any(|t| t.meets(&rect))).then_some((a, lines, rect))
            })
        });
        if let Some((a, lines, rect)) = fits {
            text_block(out, a, lines, "label sector-label", colour::SECTOR, FONT);
            taken.push(rect);
        }
    }
}

/// The title, "POOL SIMULATION AT t" (thesis plates), with the reversal's line under it in a run
/// that has one, and the counts of events and messages.
fn title_and_counts(out: &mut String, scene: &Scene, view: &View, shot: &Shot) {
    let title = Anchor {
        x: view.width / 2.0,
        y: 14.0,
        h: "middle",
        v: "down",
    };
    text_block(
        out,
        &title,
        &[format!("POOL SIMULATION AT {}", format_time(shot.frame.t))],
        "title",
        colour::TEXT,
        22.0,
    );
    if let Some(turn) = &scene.turn {
        let under = Anchor { y: 40.0, ..title };
        let line = turn_line(turn, shot.frame.t, shot.mirror_distance);
        text_block(out, &under, &[line], "turn", colour::QUIET, FONT);
    }
    let counts = Anchor {
        x: 12.0,
        y: view.height - 8.0,
        h: "start",
        v: "up",
    };
    text_block(
        out,
        &counts,
        &counts_lines(shot),
        "counts",
        colour::QUIET,
        11.0,
    );
}

/// One frame as a standalone SVG document.
pub fn frame(scene: &Scene, shot: &Shot, style: &Style) -> String {
    let view = View::new(scene);
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    out.push_str(&open_svg(&view, true));
    let _ = write!(
        out,
        "<title>{} at {}</title>",
        escape(&scene.name),
        format_time(shot.frame.t)
    );
    out.push_str(&table_layer(scene, &view, style));
    out.push_str(&moving_layer(scene, &view, shot, style));
    out.push_str("</svg>\n");
    out
}
