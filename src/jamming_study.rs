//! `poolsim experiment jamming`: the area fraction at which a 50:50 binary mixture of disks
//! (diameter ratio 1.4) jams under Lubachevsky-Stillinger compression, against the growth rate.
//!
//! Each run starts from random sequential addition at area fraction 0.1 in a periodic box
//! (Maxwell-Boltzmann velocities at kT = 1) and grows the disks at a fixed rate until the
//! reduced pressure passes 10¹² ([`crate::compress`]). O'Hern, Silbert, Liu and Nagel (2003)
//! found random close packing of this mixture at 0.84 by energy minimisation of soft disks; a
//! compression's jammed packing depends on its rate, denser the slower it goes.

use crate::compress::{compress, CompressConfig, Compressed, Ending};
use crate::experiment::{
    create_dir, draw_error, register_font, write, write_svg_png, ExperimentError, Figure,
};
use crate::observe::Estimate;
use crate::scenario::builtin::{build, Boundary, Lattice, Mixture, Params};
use plotters::prelude::*;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// O'Hern et al.'s (2003) random close packing of the 50:50 mixture with diameter ratio 1.4.
pub const OHERN: f64 = 0.84;

/// The start's area fraction.
const START: f64 = 0.1;

/// What one invocation runs.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct JammingPlan {
    /// Disks in the box.
    pub balls: usize,
    /// Growth rates, fastest first.
    pub rates: Vec<f64>,
    /// Seeds per rate, 1..=seeds.
    pub seeds: u64,
}

impl JammingPlan {
    /// The full plan: 1000 disks at rates 0.1 to 0.001, 3 seeds each; `--quick`: 200 disks at
    /// 0.1 and 0.01, 2 seeds. `balls`, `seeds` and `rates` replace the defaults.
    pub fn new(
        quick: bool,
        balls: Option<usize>,
        seeds: Option<u64>,
        rates: Option<Vec<f64>>,
    ) -> Result<JammingPlan, ExperimentError> {
        let (n, default_rates, s) = match quick {
            true => (200, vec![0.1, 0.01], 2),
            false => (1000, vec![0.1, 0.03, 0.01, 0.003, 0.001], 3),
        };
        let mut rates = rates.unwrap_or(default_rates);
        if rates.is_empty() || rates.iter().any(|&r| !(r.is_finite() && r > 0.0)) {
            return Err(ExperimentError::Rates(rates));
        }
        rates.sort_by(|a, b| b.total_cmp(a));
        rates.dedup();
        Ok(JammingPlan {
            balls: balls.unwrap_or(n),
            rates,
            seeds: seeds.unwrap_or(s),
        })
    }
}

/// One compression's result.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct JammingRun {
    /// The growth rate.
    pub rate: f64,
    /// The seed of the start.
    pub seed: u64,
    /// The area fraction it jammed at.
    pub area_fraction: f64,
    /// The last cycle's reduced pressure.
    pub z: f64,
    /// Ball-ball collisions.
    pub collisions: u64,
    /// Cycles.
    pub cycles: usize,
    /// Wall time (seconds).
    pub wall_seconds: f64,
}

/// One rate's runs together.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct JammingPoint {
    /// The growth rate.
    pub rate: f64,
    /// The jammed area fraction: the mean over the seeds and its standard error.
    pub area_fraction: Estimate,
    /// Mean collisions per disk to jam.
    pub collisions_per_disk: f64,
    /// Mean wall time per run (seconds).
    pub wall_seconds: f64,
}

/// Compresses the start of `seed` at `rate` until it jams.
fn jam(plan: &JammingPlan, rate: f64, seed: u64) -> Result<JammingRun, ExperimentError> {
    let params = Params {
        balls: Some(plan.balls),
        seed: Some(seed),
        area_fraction: Some(START),
        boundary: Some(Boundary::Periodic),
        lattice: Some(Lattice::Random),
        mixture: Some(Mixture {
            large: 0.5,
            ratio: 1.4,
        }),
        ..Params::default()
    };
    let s = build("disks", &params).map_err(ExperimentError::Scenario)?;
    let cfg = CompressConfig {
        rate,
        ..CompressConfig::default()
    };
    let clock = std::time::Instant::now();
    let done: Compressed = compress(&s, &cfg, None, &mut |_| {})?;
    debug_assert_eq!(done.ending, Ending::Jammed);
    Ok(JammingRun {
        rate,
        seed,
        area_fraction: done.area_fraction(),
        z: done.z(),
        collisions: done.collisions(),
        cycles: done.cycles.len(),
        wall_seconds: clock.elapsed().as_secs_f64(),
    })
}

/// Every run of `plan`, on as many threads as the machine has cores, slowest rates first.
pub fn jam_all(plan: &JammingPlan) -> Result<Vec<JammingRun>, ExperimentError> {
    let mut jobs: Vec<(f64, u64)> = plan
        .rates
        .iter()
        .flat_map(|&r| (1..=plan.seeds).map(move |s| (r, s)))
        .collect();
    jobs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let next = AtomicUsize::new(0);
    let results = Mutex::new(Vec::new());
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    std::thread::scope(|scope| {
        for _ in 0..threads.min(jobs.len()) {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(&(rate, seed)) = jobs.get(k) else {
                    break;
                };
                let run = jam(plan, rate, seed);
                results.lock().expect("no thread panicked").push(run);
            });
        }
    });
    let mut runs = results
        .into_inner()
        .expect("no thread panicked")
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?;
    runs.sort_by(|a, b| b.rate.total_cmp(&a.rate).then(a.seed.cmp(&b.seed)));
    Ok(runs)
}

/// The runs of each rate together, fastest rate first.
pub fn points(plan: &JammingPlan, runs: &[JammingRun]) -> Vec<JammingPoint> {
    plan.rates
        .iter()
        .map(|&rate| {
            let mine: Vec<&JammingRun> = runs.iter().filter(|r| r.rate == rate).collect();
            let k = mine.len().max(1) as f64;
            JammingPoint {
                rate,
                area_fraction: Estimate::of(
                    &mine.iter().map(|r| r.area_fraction).collect::<Vec<_>>(),
                ),
                collisions_per_disk: mine.iter().map(|r| r.collisions as f64).sum::<f64>()
                    / k
                    / plan.balls as f64,
                wall_seconds: mine.iter().map(|r| r.wall_seconds).sum::<f64>() / k,
            }
        })
        .collect()
}

/// Runs the experiment and writes `jamming.md`, `jamming.json` and the figure `jamming.svg` /
/// `jamming.png` into `dir`, the figure's text in `font`.
pub fn run(
    dir: &Path,
    font: &Path,
    plan: &JammingPlan,
) -> Result<Vec<JammingPoint>, ExperimentError> {
    create_dir(dir)?;
    let runs = jam_all(plan)?;
    let points = points(plan, &runs);
    write(&dir.join("jamming.md"), report(plan, &points).as_bytes())?;
    let json = serde_json::json!({ "plan": plan, "points": points, "runs": runs });
    write(
        &dir.join("jamming.json"),
        serde_json::to_string_pretty(&json)?.as_bytes(),
    )?;
    register_font(font)?;
    write_svg_png(dir, "jamming", (W, H), &JammingFigure(&points))?;
    Ok(points)
}

/// The table of `jamming.md`.
fn report(plan: &JammingPlan, points: &[JammingPoint]) -> String {
    let mut md = format!(
        "# Jamming of a binary disk mixture under compression\n\n\
         `poolsim experiment jamming`: {} disks, half of them 1.4 times as wide, from random \
         sequential addition at area fraction {START} in a periodic box, grown \
         (Lubachevsky-Stillinger, kT = m = 1, the velocities rescaled to kT = 1 every 2 \
         collisions per disk) until the reduced pressure passes 1e12; {} seeds per rate. The \
         rate is the small disks' diameter gained per unit time; the jammed area fraction is \
         the mean over the seeds with its standard error. O'Hern et al. (2003) give {OHERN} \
         for this mixture, from energy minimisation of soft disks.\n\n\
         | rate | jammed area fraction | collisions per disk | wall s per run |\n\
         |---:|---:|---:|---:|\n",
        plan.balls, plan.seeds
    );
    for p in points {
        md.push_str(&format!(
            "| {} | {:.4} ± {:.4} | {:.0} | {:.1} |\n",
            p.rate,
            p.area_fraction.mean,
            p.area_fraction.error,
            p.collisions_per_disk,
            p.wall_seconds
        ));
    }
    md
}

/// The figure of `jamming.svg` and `jamming.png`.
struct JammingFigure<'a>(&'a [JammingPoint]);

const W: u32 = 900;
const H: u32 = 550;

/// The jammed area fraction against the rate (logarithmic), with O'Hern's value.
impl Figure for JammingFigure<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), ExperimentError>
    where
        DB::ErrorType: 'static,
    {
        let points = self.0;
        let e = draw_error("the jamming plot");
        root.fill(&WHITE).map_err(&e)?;
        let lo = points.iter().map(|p| p.rate).fold(f64::INFINITY, f64::min) / 2.0;
        let hi = points.iter().map(|p| p.rate).fold(0.0, f64::max) * 2.0;
        let mut chart = ChartBuilder::on(root)
            .caption(
                "Binary disks (1:1.4): jammed area fraction against the growth rate",
                ("sans-serif", 20),
            )
            .margin(15)
            .x_label_area_size(40)
            .y_label_area_size(60)
            .build_cartesian_2d((lo..hi).log_scale(), 0.80..0.86)
            .map_err(&e)?;
        chart
            .configure_mesh()
            .x_desc("growth rate (diameter per unit time, kT = m = 1)")
            .y_desc("jammed area fraction")
            .draw()
            .map_err(&e)?;
        chart
            .draw_series(LineSeries::new(
                [(lo, OHERN), (hi, OHERN)],
                RED.stroke_width(1),
            ))
            .map_err(&e)?
            .label("O'Hern et al. (2003)")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        chart
            .draw_series(points.iter().map(|p| {
                let (y, s) = (p.area_fraction.mean, p.area_fraction.error);
                PathElement::new(vec![(p.rate, y - s), (p.rate, y + s)], BLUE.stroke_width(2))
            }))
            .map_err(&e)?;
        chart
            .draw_series(
                points
                    .iter()
                    .map(|p| Circle::new((p.rate, p.area_fraction.mean), 4, BLUE.filled())),
            )
            .map_err(&e)?
            .label("poolsim compress")
            .legend(|(x, y)| Circle::new((x + 10, y), 4, BLUE.filled()));
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerLeft)
            .background_style(WHITE)
            .border_style(BLACK)
            .draw()
            .map_err(&e)?;
        root.present().map_err(&e)?;
        Ok(())
    }
}
