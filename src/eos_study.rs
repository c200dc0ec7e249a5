//! `poolsim experiment eos`: the equation of state of the hard-disk fluid, measured in a
//! periodic box and set beside the literature.
//!
//! For each area fraction η the `disks` start (a triangular lattice in a periodic box, unit
//! radius and mass, Maxwell-Boltzmann velocities at kT = 1, zero momentum) runs on the event
//! list for a set number of collisions per disk to melt the lattice and forget it, then as many
//! again in blocks, each block giving the compressibility factor Z from the collision virial
//! (`crate::observe`). Times are set from the collision rate that Henderson's equation of state
//! predicts through the identity `Z − 1 = (√π / 4) ν σ √(m / kT)`, so every density gets about
//! the same number of collisions. The reference values are Liu's (2020, arXiv 2010.10624,
//! from simulations of large systems); the curve is Henderson's (1975),
//! `Z = (1 + η² / 8) / (1 − η)²`.

use crate::engine::RunError;
use crate::experiment::{
    create_dir, draw_error, register_font, write, write_svg_png, ExperimentError, Figure,
};
use crate::observe::{Estimate, Observables};
use crate::run::{execute, EngineKind, RunConfig};
use crate::scenario::builtin::{build, Boundary, Params};
use plotters::prelude::*;
use std::path::Path;

/// Liu's (2020) compressibility factors of the hard-disk fluid: (area fraction, Z).
pub const LIU: [(f64, f64); 4] = [(0.3, 2.0637), (0.5, 4.1052), (0.6, 6.4520), (0.65, 8.4414)];

/// Henderson's (1975) equation of state of the hard-disk fluid.
pub fn henderson(eta: f64) -> f64 {
    (1.0 + eta * eta / 8.0) / ((1.0 - eta) * (1.0 - eta))
}

/// What one invocation runs.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct EosPlan {
    /// Disks in the box.
    pub balls: usize,
    /// The area fractions, ascending.
    pub area_fractions: Vec<f64>,
    /// Collisions per disk run before measuring (melting the lattice).
    pub equilibrate: f64,
    /// Collisions per disk measured.
    pub measure: f64,
    /// Blocks the measurement is cut into.
    pub blocks: usize,
}

impl EosPlan {
    /// The full plan: 10^4 disks at Liu's four area fractions, 200 collisions per disk to
    /// equilibrate and 2000 measured in 20 blocks; `--quick`: 1000 disks at 0.3 and 0.5, 100
    /// and 1000 collisions per disk. `balls` and `area_fractions` replace the defaults.
    pub fn new(
        quick: bool,
        balls: Option<usize>,
        area_fractions: Option<Vec<f64>>,
    ) -> Result<EosPlan, ExperimentError> {
        let (n, etas, equilibrate, measure) = match quick {
            true => (1000, vec![0.3, 0.5], 100.0, 1000.0),
            false => (10_000, LIU.iter().map(|p| p.0).collect(), 200.0, 2000.0),
        };
        let mut etas = area_fractions.unwrap_or(etas);
        if etas.is_empty() || etas.iter().any(|&e| !(e > 0.0 && e < 0.7)) {
            return Err(ExperimentError::AreaFractions(etas));
        }
        etas.sort_by(f64::total_cmp);
        Ok(EosPlan {
            balls: balls.unwrap_or(n),
            area_fractions: etas,
            equilibrate,
            measure,
            blocks: 20,
        })
    }
}

/// One area fraction's result.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct EosPoint {
    /// The area fraction.
    pub area_fraction: f64,
    /// Disks.
    pub balls: usize,
    /// The time measuring started and the run's end.
    pub from: f64,
    /// The run's end.
    pub until: f64,
    /// Ball-ball collisions over the whole run.
    pub collisions: u64,
    /// Z from the collision virial, with its standard error over the blocks.
    pub z: Estimate,
    /// Z from the collision rate by the identity `Z − 1 = (√π / 4) ν σ √(m / kT)`.
    pub z_from_rate: Estimate,
    /// Liu's value at this area fraction, if it has one.
    pub liu: Option<f64>,
    /// Henderson's value.
    pub henderson: f64,
    /// The wall time of the run (seconds).
    pub wall_seconds: f64,
}

impl EosPoint {
    /// `(Z − Liu) / Liu` in percent and in standard errors, where Liu has a value.
    pub fn deviation(&self) -> Option<(f64, f64)> {
        self.liu.map(|l| {
            (
                100.0 * (self.z.mean - l) / l,
                (self.z.mean - l) / self.z.error,
            )
        })
    }
}

/// Runs one area fraction of `plan`.
fn measure(plan: &EosPlan, eta: f64) -> Result<EosPoint, ExperimentError> {
    let params = Params {
        balls: Some(plan.balls),
        area_fraction: Some(eta),
        boundary: Some(Boundary::Periodic),
        ..Params::default()
    };
    let s = build("disks", &params).map_err(ExperimentError::Scenario)?;
    // collisions per disk and unit time at kT = m = 1, σ = 2, by Henderson's Z
    let rate = 2.0 * (henderson(eta) - 1.0) / std::f64::consts::PI.sqrt();
    let from = plan.equilibrate / rate;
    let every = plan.measure / rate / plan.blocks as f64;
    let until = from + every * plan.blocks as f64;
    let cfg = RunConfig {
        engine: EngineKind::EventList,
        until,
        check: false,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let mut o = Observables::over(&s, (0.0, until), Some(from), every)
        .map_err(|e| RunError::Input(e.to_string()))?;
    let report = execute(&s, &cfg, &mut o)?;
    let o = o.finish(report.outcome.t);
    let factor = std::f64::consts::PI.sqrt() / 4.0 * 2.0 / o.kt.mean.sqrt();
    Ok(EosPoint {
        area_fraction: eta,
        balls: plan.balls,
        from,
        until,
        collisions: report.outcome.events.total(),
        z: o.z,
        z_from_rate: Estimate {
            mean: 1.0 + factor * o.collision_rate.mean,
            error: factor * o.collision_rate.error,
        },
        liu: LIU.iter().find(|p| p.0 == eta).map(|p| p.1),
        henderson: henderson(eta),
        wall_seconds: report.summary.wall_seconds,
    })
}

/// Runs `plan`, its area fractions on as many threads as the machine has cores, and reports
/// each one done to `done`.
pub fn measure_all(
    plan: &EosPlan,
    done: &(dyn Fn(&EosPoint) + Sync),
) -> Result<Vec<EosPoint>, ExperimentError> {
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut out = Vec::new();
    for chunk in plan.area_fractions.chunks(threads) {
        let results: Vec<Result<EosPoint, ExperimentError>> = std::thread::scope(|s| {
            let handles: Vec<_> = chunk
                .iter()
                .map(|&eta| s.spawn(move || measure(plan, eta)))
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("an equation-of-state run panicked"))
                .collect()
        });
        for r in results {
            let point = r?;
            done(&point);
            out.push(point);
        }
    }
    Ok(out)
}

/// Runs the experiment and writes `eos.md`, `eos.json` and the figure `eos.svg` / `eos.png`
/// into `dir`, the figure's text in `font`.
pub fn run(
    dir: &Path,
    font: &Path,
    plan: &EosPlan,
    done: &(dyn Fn(&EosPoint) + Sync),
) -> Result<Vec<EosPoint>, ExperimentError> {
    create_dir(dir)?;
    let points = measure_all(plan, done)?;
    write(&dir.join("eos.md"), report(plan, &points).as_bytes())?;
    let json = serde_json::json!({ "plan": plan, "points": points });
    write(
        &dir.join("eos.json"),
        serde_json::to_string_pretty(&json)?.as_bytes(),
    )?;
    register_font(font)?;
    write_svg_png(dir, "eos", (W, H), &EosFigure(&points))?;
    Ok(points)
}

/// The table of `eos.md`.
fn report(plan: &EosPlan, points: &[EosPoint]) -> String {
    let mut md = format!(
        "# The hard-disk fluid's equation of state\n\n\
         `poolsim experiment eos`: {} disks in a periodic box at each area fraction, from a \
         triangular lattice, {} collisions per disk to melt it, then {} collisions per disk \
         measured in {} blocks (kT = m = 1, radius 1). Z is the collision virial's, with the \
         standard error of its block means; Z from the rate is the identity \
         Z - 1 = (sqrt(pi)/4) nu sigma sqrt(m/kT) applied to the measured collision rate; Liu \
         (2020) and Henderson (1975) are the references.\n\n\
         | area fraction | collisions | Z (virial) | Z (rate) | Liu | Z - Liu | in std. errors | Henderson | wall s |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        plan.balls, plan.equilibrate, plan.measure, plan.blocks
    );
    for p in points {
        let (liu, dev, sig) = match (p.liu, p.deviation()) {
            (Some(l), Some((pc, s))) => {
                (format!("{l:.4}"), format!("{pc:+.3} %"), format!("{s:+.2}"))
            }
            _ => ("".into(), "".into(), "".into()),
        };
        md.push_str(&format!(
            "| {} | {} | {:.4} ± {:.4} | {:.4} ± {:.4} | {liu} | {dev} | {sig} | {:.4} | {:.1} |\n",
            p.area_fraction,
            p.collisions,
            p.z.mean,
            p.z.error,
            p.z_from_rate.mean,
            p.z_from_rate.error,
            p.henderson,
            p.wall_seconds
        ));
    }
    md
}

/// The figure of `eos.svg` and `eos.png`.
struct EosFigure<'a>(&'a [EosPoint]);

const W: u32 = 900;
const H: u32 = 800;

/// Z against the area fraction (Henderson's curve, Liu's points, the measured ones with their
/// error bars) above the measured points' deviation from Liu's in percent.
impl Figure for EosFigure<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), ExperimentError>
    where
        DB::ErrorType: 'static,
    {
        let points = self.0;
        let e = draw_error("the equation-of-state plot");
        root.fill(&WHITE).map_err(&e)?;
        let (top, bottom) = root.split_vertically(H * 5 / 8);
        let zmax = henderson(0.7) * 1.05;
        let mut chart = ChartBuilder::on(&top)
            .caption(
                "Hard-disk fluid: Z against the area fraction",
                ("sans-serif", 20),
            )
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..0.72, 0.0..zmax)
            .map_err(&e)?;
        chart
            .configure_mesh()
            .x_desc("area fraction")
            .y_desc("Z = PA / NkT")
            .draw()
            .map_err(&e)?;
        let curve = (0..=140)
            .map(|k| f64::from(k) * 0.005)
            .map(|x| (x, henderson(x)));
        chart
            .draw_series(LineSeries::new(curve, BLACK.stroke_width(1)))
            .map_err(&e)?
            .label("Henderson (1975)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
        chart
            .draw_series(LIU.iter().map(|&p| Cross::new(p, 7, RED.stroke_width(2))))
            .map_err(&e)?
            .label("Liu (2020)")
            .legend(|(x, y)| Cross::new((x + 10, y), 5, RED.stroke_width(2)));
        chart
            .draw_series(
                points
                    .iter()
                    .map(|p| Circle::new((p.area_fraction, p.z.mean), 4, BLUE.filled())),
            )
            .map_err(&e)?
            .label("poolsim, periodic box")
            .legend(|(x, y)| Circle::new((x + 10, y), 4, BLUE.filled()));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE)
            .border_style(BLACK)
            .draw()
            .map_err(&e)?;
        draw_deviation(&bottom, points, &e)?;
        root.present().map_err(&e)?;
        Ok(())
    }
}

/// The measured points' deviation from Liu's, in percent, with their error bars.
fn draw_deviation<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    points: &[EosPoint],
    e: &impl Fn(DrawingAreaErrorKind<DB::ErrorType>) -> ExperimentError,
) -> Result<(), ExperimentError>
where
    DB::ErrorType: 'static,
{
    let bars: Vec<(f64, f64, f64)> = points
        .iter()
        .filter_map(|p| {
            let l = p.liu?;
            Some((
                p.area_fraction,
                100.0 * (p.z.mean - l) / l,
                100.0 * p.z.error / l,
            ))
        })
        .collect();
    let span = bars
        .iter()
        .map(|b| b.1.abs() + 2.0 * b.2)
        .fold(0.1, f64::max)
        * 1.2;
    let mut chart = ChartBuilder::on(area)
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..0.72, -span..span)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc("area fraction")
        .y_desc("(Z - Liu) / Liu, %")
        .draw()
        .map_err(e)?;
    chart
        .draw_series(LineSeries::new([(0.0, 0.0), (0.72, 0.0)], BLACK))
        .map_err(e)?;
    chart
        .draw_series(
            bars.iter().map(|&(x, y, s)| {
                PathElement::new(vec![(x, y - s), (x, y + s)], BLUE.stroke_width(2))
            }),
        )
        .map_err(e)?;
    chart
        .draw_series(
            bars.iter()
                .map(|&(x, y, _)| Circle::new((x, y), 4, BLUE.filled())),
        )
        .map_err(e)?;
    Ok(())
}
