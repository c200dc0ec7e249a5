//! Figures 17 and 18: the thesis' curves of the chapter 7 model (left), and the model at our
//! measured parameters against our message counts (right), as SVG and PNG.

use super::data::Data;
use super::{settings, write, ExperimentError, Setting};
use crate::analytic::{self, ModelParams};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Font files read so far, by path: plotters keeps `&'static` font data, so each file is read
/// and leaked once per process.
static FONTS: Mutex<Vec<(PathBuf, &'static [u8])>> = Mutex::new(Vec::new());

/// Reads the font at `path` and registers it as plotters' `sans-serif` (the family every text
/// of the figures uses). A missing or unreadable font is an error naming the file and the
/// Debian package, never a panic.
pub(crate) fn register_font(path: &Path) -> Result<(), ExperimentError> {
    let mut fonts = FONTS.lock().unwrap_or_else(|e| e.into_inner());
    let bytes = match fonts.iter().find(|f| f.0 == path) {
        Some(f) => f.1,
        None => {
            let bytes = std::fs::read(path).map_err(|source| ExperimentError::ReadFont {
                path: path.to_path_buf(),
                source,
            })?;
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            fonts.push((path.to_path_buf(), bytes));
            bytes
        }
    };
    for family in ["sans-serif", "serif", "monospace"] {
        plotters::style::register_font(family, FontStyle::Normal, bytes)
            .map_err(|_| ExperimentError::NotAFont(path.to_path_buf()))?;
    }
    Ok(())
}

/// What one figure's right panel shows for one number of balls.
pub(super) struct Measured {
    n: usize,
    vt: f64,
    m: f64,
    /// `(s = 1/k, mean, sd)` per sectored setting.
    points: Vec<(f64, f64, f64)>,
    none: Option<f64>,
}

/// What the right panels show, per number of balls of the plan.
pub(super) fn measured(data: &Data) -> Vec<Measured> {
    data.plan
        .balls
        .iter()
        .map(|&n| {
            let (vt, m) = data.model_params(n);
            let points = settings(n)
                .into_iter()
                .filter_map(|s| {
                    let k = s.per_side()?;
                    let t = data.total(n, s)?;
                    Some((1.0 / k as f64, t.mean, t.sd.unwrap_or(0.0)))
                })
                .collect();
            Measured {
                n,
                vt,
                m,
                points,
                none: data.total(n, Setting::NoSectors).map(|t| t.mean),
            }
        })
        .collect()
}

/// The colour of the curves and points of `n` balls.
fn color_of(n: usize) -> RGBColor {
    match n {
        4 => RGBColor(117, 112, 179),
        8 => RGBColor(230, 159, 0),
        16 => RGBColor(0, 114, 178),
        32 => RGBColor(0, 158, 115),
        36 => RGBColor(0, 150, 150),
        64 => RGBColor(213, 94, 0),
        _ => {
            const MORE: [RGBColor; 4] = [
                RGBColor(204, 121, 167),
                RGBColor(86, 180, 233),
                RGBColor(120, 120, 120),
                RGBColor(160, 120, 40),
            ];
            MORE[n % MORE.len()]
        }
    }
}

const W: u32 = 1280;
const H: u32 = 600;
const THESIS_N: [f64; 4] = [8.0, 16.0, 32.0, 64.0];

/// An error mapper naming what was being drawn.
pub(crate) fn draw_error<E>(what: &str) -> impl Fn(E) -> ExperimentError + '_
where
    E: std::error::Error + Send + Sync + 'static,
{
    move |e| ExperimentError::Draw {
        what: what.to_string(),
        source: Box::new(e),
    }
}

/// Draws figure 17 (`eq == 1`) or 18 (`eq == 2`) on any plotters backend.
fn draw_figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    eq: u32,
    ms: &[Measured],
    name: &str,
) -> Result<(), ExperimentError>
where
    DB::ErrorType: 'static,
{
    let e = draw_error(name);
    root.fill(&WHITE).map_err(&e)?;
    let title = if eq == 1 {
        "Figure 17. Messages as a function of sector size: no collisions (eq. 1)"
    } else {
        "Figure 18. Messages as a function of sector size: with collisions (eq. 2)"
    };
    let root = root.titled(title, ("sans-serif", 22)).map_err(&e)?;
    let (left, right) = root.split_horizontally(W / 2);
    draw_thesis_panel(&left, eq, name)?;
    draw_measured_panel(&right, eq, ms, name)?;
    root.present().map_err(&e)?;
    Ok(())
}

/// The model's parameters for the thesis' curves of `n` balls: `V T = 1`, and `m = 0` (eq. 1)
/// or `m = N` (eq. 2).
fn thesis_params(eq: u32, n: f64) -> ModelParams {
    ModelParams {
        balls: n,
        speed: 1.0,
        time: 1.0,
        changes: if eq == 1 { 0.0 } else { n },
    }
}

/// The thesis' curves `F(s)`, one per [`THESIS_N`], on the unit-square table.
fn thesis_curves(eq: u32) -> Vec<(f64, Vec<(f64, f64)>)> {
    let s_lo = 0.05;
    THESIS_N
        .iter()
        .map(|&n| {
            let p = thesis_params(eq, n);
            let pts = (0..=190)
                .map(|i| {
                    let s = s_lo + (1.0 - s_lo) * i as f64 / 190.0;
                    (s, analytic::messages(&p, s))
                })
                .collect();
            (n, pts)
        })
        .collect()
}

/// The curve of minima: continuous in N, from the smallest curve's to the largest's.
fn thesis_minima(eq: u32) -> Vec<(f64, f64)> {
    (0..=100)
        .map(|i| {
            let n = 8.0 * (8.0f64).powf(i as f64 / 100.0);
            let mut p = thesis_params(eq, n);
            if eq == 1 {
                p.changes = 0.0;
            }
            let s = analytic::optimal_sector(&p);
            (s, analytic::messages(&thesis_params(eq, n), s))
        })
        .collect()
}

/// Eq. 2 at eight balls per sector (the minima of eq. 1), over the same range of N.
fn eight_per_sector(eq: u32) -> Vec<(f64, f64)> {
    (0..=100)
        .map(|i| {
            let n = 8.0 * (8.0f64).powf(i as f64 / 100.0);
            let s = (8.0 / n).sqrt();
            (s, analytic::messages(&thesis_params(eq, n), s))
        })
        .collect()
}

/// The left panel: the thesis' figure as it is.
fn draw_thesis_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    eq: u32,
    name: &str,
) -> Result<(), ExperimentError>
where
    DB::ErrorType: 'static,
{
    let e = draw_error(name);
    let curves = thesis_curves(eq);
    let y_max = curves
        .iter()
        .flat_map(|c| c.1.iter().map(|p| p.1))
        .fold(0.0, f64::max)
        * 1.05;
    let mut chart = ChartBuilder::on(area)
        .caption(
            "Thesis: unit-square table, V T = 1".to_string()
                + if eq == 1 { ", m = 0" } else { ", m = N" },
            ("sans-serif", 17),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0f64..1.0f64, 0.0f64..y_max)
        .map_err(&e)?;
    chart
        .configure_mesh()
        .x_desc("sector width s")
        .y_desc("messages F(s)")
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .x_label_formatter(&|x| format!("{x:.1}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .draw()
        .map_err(&e)?;
    draw_thesis_curves(&mut chart, eq, &curves, name)?;
    draw_legend(&mut chart, name)
}

/// The thesis' curves, their minima and (eq. 2) eight balls per sector, on the left panel.
fn draw_thesis_curves<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    eq: u32,
    curves: &[(f64, Vec<(f64, f64)>)],
    name: &str,
) -> Result<(), ExperimentError>
where
    DB::ErrorType: 'static,
{
    let e = draw_error(name);
    for (n, pts) in curves {
        let c = color_of(*n as usize);
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(&e)?
            .label(format!("N = {n}"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    }
    chart
        .draw_series(DashedLineSeries::new(
            thesis_minima(eq),
            8,
            5,
            BLACK.stroke_width(1),
        ))
        .map_err(&e)?
        .label("minima")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    if eq == 2 {
        chart
            .draw_series(DashedLineSeries::new(
                eight_per_sector(eq),
                2,
                4,
                BLACK.stroke_width(1),
            ))
            .map_err(&e)?
            .label("8 balls/sector")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5)));
    }
    for (n, _) in curves {
        let s = analytic::optimal_sector(&thesis_params(eq, *n));
        let f = analytic::messages(&thesis_params(eq, *n), s);
        chart
            .draw_series(std::iter::once(Circle::new(
                (s, f),
                4,
                color_of(*n as usize).filled(),
            )))
            .map_err(&e)?;
    }
    Ok(())
}

/// The legend of the series labelled so far, in the upper right corner.
fn draw_legend<'a, 'b, DB: DrawingBackend + 'a + 'b, CT: CoordTranslate>(
    chart: &'b mut ChartContext<'a, DB, CT>,
    name: &str,
) -> Result<(), ExperimentError>
where
    DB::ErrorType: 'static,
{
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(draw_error(name))
}

/// The model's parameters at what we measured for `m.n` balls, for eq. 1 or eq. 2.
fn measured_params(eq: u32, m: &Measured) -> ModelParams {
    ModelParams {
        balls: m.n as f64,
        speed: m.vt,
        time: 1.0,
        changes: if eq == 1 { 0.0 } else { m.m },
    }
}

/// The model at our parameters, `s` from `s_min` to 1 on a log scale, per number of balls.
fn model_curves(eq: u32, ms: &[Measured], s_min: f64) -> Vec<(usize, Vec<(f64, f64)>)> {
    ms.iter()
        .filter(|m| m.vt > 0.0)
        .map(|m| {
            let p = measured_params(eq, m);
            let pts: Vec<(f64, f64)> = (0..=120)
                .map(|i| {
                    let s = s_min * (1.0 / s_min).powf(i as f64 / 120.0);
                    (s, analytic::messages(&p, s))
                })
                .collect();
            (m.n, pts)
        })
        .collect()
}

/// The range of messages the right panel shows: every curve, point, error bar and line.
fn message_range(curves: &[(usize, Vec<(f64, f64)>)], ms: &[Measured]) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi: f64 = 1.0;
    for (_, pts) in curves {
        for p in pts {
            lo = lo.min(p.1);
            hi = hi.max(p.1);
        }
    }
    for m in ms {
        for p in &m.points {
            lo = lo.min((p.1 - p.2).max(p.1 * 0.5));
            hi = hi.max(p.1 + p.2);
        }
        if let Some(x) = m.none {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    }
    if !lo.is_finite() || lo <= 0.0 {
        lo = 1.0;
    }
    (lo, hi)
}

/// The sector widths `1/k` measured, for ticks on the right panel's axis.
fn width_ticks(ms: &[Measured]) -> Vec<f64> {
    let mut ks: Vec<u32> = ms
        .iter()
        .flat_map(|m| m.points.iter().map(|p| (1.0 / p.0).round() as u32))
        .collect();
    ks.sort_unstable();
    ks.dedup();
    ks.iter().map(|&k| 1.0 / k as f64).collect()
}

/// The right panel: our measurements against the model at our parameters, absolute, log-log.
fn draw_measured_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    eq: u32,
    ms: &[Measured],
    name: &str,
) -> Result<(), ExperimentError>
where
    DB::ErrorType: 'static,
{
    let e = draw_error(name);
    let s_min = ms
        .iter()
        .flat_map(|m| m.points.iter().map(|p| p.0))
        .fold(0.25, f64::min)
        * 0.8;
    let curves = model_curves(eq, ms, s_min);
    let (lo, hi) = message_range(&curves, ms);
    let mut chart = ChartBuilder::on(area)
        .caption(
            if eq == 1 {
                "Ours: eq. 1 at measured V T (lines), measured totals (points)"
            } else {
                "Ours: eq. 2 at measured V T, m (lines), measured totals (points)"
            },
            ("sans-serif", 17),
        )
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (s_min..1.1f64).log_scale().with_key_points(width_ticks(ms)),
            ((lo * 0.7)..(hi * 6.0)).log_scale(),
        )
        .map_err(&e)?;
    chart
        .configure_mesh()
        .x_desc("sector width s = 1/k of the table side (k sectors per side; log scale)")
        .y_desc("messages (log scale)")
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .x_label_formatter(&|x| match (1.0 / x).round() as u32 {
            1 => "1".to_string(),
            k => format!("1/{k}"),
        })
        .y_label_formatter(&|y| format!("{y:.0}"))
        .draw()
        .map_err(&e)?;
    for m in ms {
        let curve = curves.iter().find(|x| x.0 == m.n).map(|x| &x.1[..]);
        draw_measured(&mut chart, eq, m, curve, s_min, name)?;
    }
    draw_legend(&mut chart, name)
}

/// One number of balls on the right panel: the model's curve (if any), the measured means with
/// their ± 1 SD bars, and the non-sectored mean as a dashed line.
fn draw_measured<DB: DrawingBackend, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    eq: u32,
    m: &Measured,
    curve: Option<&[(f64, f64)]>,
    s_min: f64,
    name: &str,
) -> Result<(), ExperimentError>
where
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let e = draw_error(name);
    let c = color_of(m.n);
    if let Some(pts) = curve {
        chart
            .draw_series(LineSeries::new(pts.to_vec(), c.stroke_width(2)))
            .map_err(&e)?
            .label(format!(
                "N = {} (V T = {:.2}, m = {:.0})",
                m.n,
                m.vt,
                if eq == 1 { 0.0 } else { m.m }
            ))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    }
    chart
        .draw_series(
            m.points
                .iter()
                .map(|&(s, y, _)| Circle::new((s, y), 5, c.filled())),
        )
        .map_err(&e)?;
    chart
        .draw_series(m.points.iter().filter(|p| p.2 > 0.0).map(|&(s, y, sd)| {
            PathElement::new(
                vec![(s, (y - sd).max(y * 0.5)), (s, y + sd)],
                c.stroke_width(2),
            )
        }))
        .map_err(&e)?;
    if let Some(none) = m.none {
        chart
            .draw_series(DashedLineSeries::new(
                vec![(s_min, none), (1.05, none)],
                6,
                6,
                c.stroke_width(1),
            ))
            .map_err(&e)?;
    }
    Ok(())
}

/// Writes `figNN.svg` and `figNN.png` for equation `eq`.
pub(super) fn write_figure(dir: &Path, eq: u32, ms: &[Measured]) -> Result<(), ExperimentError> {
    let stem = if eq == 1 { "fig17" } else { "fig18" };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
        draw_figure(&root, eq, ms, &format!("{stem}.svg"))?;
    }
    write(&dir.join(format!("{stem}.svg")), svg.as_bytes())?;
    let mut buf = vec![255u8; (W * H * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
        draw_figure(&root, eq, ms, &format!("{stem}.png"))?;
    }
    write_png(&dir.join(format!("{stem}.png")), &buf, W, H)
}

/// A figure that draws itself on any of plotters' backends.
pub(crate) trait Figure {
    /// Draws the figure on `root`.
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), ExperimentError>
    where
        DB::ErrorType: 'static;
}

/// Writes `figure` as `stem.svg` and `stem.png`, `w` × `h` pixels, into `dir`.
pub(crate) fn write_svg_png(
    dir: &Path,
    stem: &str,
    (w, h): (u32, u32),
    figure: &impl Figure,
) -> Result<(), ExperimentError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        figure.draw(&root)?;
    }
    write(&dir.join(format!("{stem}.svg")), svg.as_bytes())?;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        figure.draw(&root)?;
    }
    write_png(&dir.join(format!("{stem}.png")), &buf, w, h)
}

/// Encodes an RGB buffer of `w` × `h` pixels as a PNG file.
pub(crate) fn write_png(path: &Path, buf: &[u8], w: u32, h: u32) -> Result<(), ExperimentError> {
    let mut png_bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut png_bytes, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Best);
        enc.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
        let encode = |source| ExperimentError::Encode {
            path: path.to_path_buf(),
            source,
        };
        let mut w = enc.write_header().map_err(encode)?;
        w.write_image_data(buf).map_err(encode)?;
    }
    write(path, &png_bytes)
}
