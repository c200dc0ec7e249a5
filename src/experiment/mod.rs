//! `poolsim experiment thesis`: the experiment of thesis chapter 6 run again, with the analytic
//! model of chapter 7 beside it, written up as tables, figures and a report.
//!
//! ```text
//!  for N in --balls, seed in 1..=S:
//!    gas(N, seed) ──event-list + FreePath observer──► free path, collisions   (table 9, figures)
//!                 ──objects, no sectors──────────────► messages by type, wall (tables 5-8, 10)
//!                 ──objects, k × k sectors, each k───► messages by type, wall
//!  all runs ──► results.json, table5.md … table10.md, fig17/fig18 (.svg, .png), report.md
//! ```
//!
//! The thesis gives sector sizes for a table "50 times the number of balls along the side" whose
//! radius-30 balls would overlap on their starting grid, and its tables agree with each other only
//! as sector counts per side (DESIGN.md, "a known ambiguity"). We therefore lay `k × k` balls out on
//! a table of side `100 k` (the `gas` scenario's default, and the 600 × 600 table the thesis' own
//! table 9 names for 36 balls), and run the sector grids with the thesis' balls per sector
//! `b ∈ {16, 9, 4, 1, 1/4}`: `k = √(N / b)` sectors per side wherever that is a whole number. A
//! thesis sector size `S` is then `b = (S / 50)²` balls per sector, whatever `N`.
//!
//! Message counts are exact and deterministic (seeded scenarios, exact virtual time): the same on
//! every machine. Wall times are this machine's.

// The code follows that flow: `thesis` holds the thesis' numbers as printed, `data` runs the plan
// and indexes what it measured, `tables` writes tables 5-10, `findings` compares the settings
// seed by seed, `report` fills the template `report.md.j2`, `figures` draws figures 17 and 18,
// and `results` gathers `results.json`.

mod data;
mod error;
mod figures;
mod findings;
mod report;
mod results;
mod tables;
mod thesis;

pub use data::{PhysicsRecord, RunRecord, Stat};
pub use error::ExperimentError;
pub(crate) use figures::{draw_error, register_font, write_svg_png, Figure};

use serde::Serialize;
use std::path::{Path, PathBuf};

/// Where Debian's `fonts-dejavu-core` puts the font the figures' text is drawn with (the
/// renderer's default font).
pub use crate::render::raster::DEFAULT_FONT;

/// Ball radius of the thesis gas (chapter 6), in table length units.
const RADIUS: f64 = 30.0;
/// Speeds are drawn uniform in `[0, SPEED_MAX)` (chapter 6), in length per time unit.
const SPEED_MAX: f64 = 100.0;
/// Every thesis run goes from time 0 to time 4.
const UNTIL: f64 = 4.0;
/// The thesis' `c` in "sector entries ≈ c · total path / sector size" (6.1).
const C_ENTRIES: f64 = 3.0;
/// The thesis' "number of adjacent objects" per sector (6.1, ch. 7).
const THESIS_ADJACENT: f64 = 4.0;

/// Which experiment to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Which {
    /// Thesis chapter 6 (tables 5-10) with the chapter 7 model (figures 17-18).
    Thesis,
    /// Thesis 4.6-4.7: the reversal error against the quitting time Q.
    Reversal,
    /// The hard-disk fluid's equation of state in a periodic box, beside the literature.
    Eos,
    /// The jammed area fraction of a binary disk mixture against the compression rate.
    Jamming,
}

/// What `poolsim experiment` was asked for; options left `None` take the plan's defaults.
#[derive(Clone, Debug)]
pub struct ExperimentOptions {
    /// The experiment.
    pub which: Which,
    /// Directory to write the tables, figures, `results.json` and `report.md` into (created if
    /// missing; files already there are overwritten).
    pub out: PathBuf,
    /// Seeds per cell, 1..=S (default 6, as the thesis ran its non-sectored cases; 2 when quick).
    pub seeds: Option<u64>,
    /// Numbers of balls (default 4, 16, 36, 64, the thesis' squares; 4, 16 when quick).
    pub balls: Option<Vec<usize>>,
    /// A reduced grid for CI: 4 and 16 balls, 2 seeds, until 4.
    pub quick: bool,
    /// TrueType font for the figures' text (default [`DEFAULT_FONT`]).
    pub font: Option<PathBuf>,
    /// The equation of state's area fractions (default Liu's 0.3, 0.5, 0.6, 0.65).
    pub area_fractions: Option<Vec<f64>>,
    /// The jamming study's growth rates (default 0.1, 0.03, 0.01, 0.003, 0.001).
    pub rates: Option<Vec<f64>>,
}

/// How far the experiment has come, for a progress display.
#[derive(Clone, Debug, PartialEq)]
pub enum Progress {
    /// The runs are about to start; there are this many.
    Start(u64),
    /// The runs of `balls` balls with this seed are under way.
    Cell {
        /// Balls.
        balls: usize,
        /// Seed.
        seed: u64,
    },
    /// One more run is done.
    RunDone,
    /// Every run is done.
    Finished,
}

/// What one invocation runs: resolved from [`ExperimentOptions`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Plan {
    /// Numbers of balls, each a square, ascending.
    pub balls: Vec<usize>,
    /// Seeds `1..=seeds` for every cell.
    pub seeds: u64,
    /// End time of every run.
    pub until: f64,
    /// Whether this is the reduced CI grid.
    pub quick: bool,
    /// Each objects run is repeated this many times; its wall time is the median.
    pub timing_repeats: u32,
}

impl Plan {
    /// The plan the arguments ask for: `--quick` changes the defaults, explicit `--seeds` and
    /// `--balls` win over them. Errors name the option.
    pub fn from_options(a: &ExperimentOptions) -> Result<Plan, ExperimentError> {
        let seeds = a.seeds.unwrap_or(if a.quick { 2 } else { 6 });
        if seeds == 0 || seeds > 1000 {
            return Err(ExperimentError::Seeds(seeds));
        }
        let mut balls = a.balls.clone().unwrap_or_else(|| {
            if a.quick {
                vec![4, 16]
            } else {
                vec![4, 16, 36, 64]
            }
        });
        if balls.is_empty() {
            return Err(ExperimentError::NoBalls);
        }
        for &n in &balls {
            if !(1..=4096).contains(&n) {
                return Err(ExperimentError::BallsOutOfRange(n));
            }
        }
        balls.sort_unstable();
        balls.dedup();
        Ok(Plan {
            balls,
            seeds,
            until: UNTIL,
            quick: a.quick,
            timing_repeats: if a.quick { 1 } else { 5 },
        })
    }
}

fn isqrt(n: usize) -> Option<usize> {
    let r = (n as f64).sqrt().round() as usize;
    (r * r == n).then_some(r)
}

/// The thesis' balls per sector, as `(numerator, denominator)`, in its column order (table 10);
/// sector size `S` of tables 5, 6 and 8 is `50 √b`: 200, 150, 100, 50, 25.
const BPS: [(usize, usize); 5] = [(16, 1), (9, 1), (4, 1), (1, 1), (1, 4)];
/// Labels of [`BPS`].
const BPS_LABEL: [&str; 5] = ["16", "9", "4", "1", "1/4"];
/// The thesis' sector sizes for [`BPS`].
const SIZE_LABEL: [&str; 5] = ["200", "150", "100", "50", "25"];

/// One way to run the objects engine on a gas.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Setting {
    /// The plain objects engine (thesis fig. 3): every ball tells every object.
    NoSectors,
    /// The sectored engine on a `k × k` grid (thesis fig. 14).
    Grid(u32),
}

impl Setting {
    /// `none` or `KxK`.
    pub fn name(self) -> String {
        match self {
            Setting::NoSectors => "none".into(),
            Setting::Grid(k) => format!("{k}x{k}"),
        }
    }

    /// `no sectors` or `K×K`, for tables.
    fn label(self) -> String {
        match self {
            Setting::NoSectors => "no sectors".into(),
            Setting::Grid(k) => format!("{k}×{k}"),
        }
    }

    /// Sectors per side, if sectored.
    pub fn per_side(self) -> Option<u32> {
        match self {
            Setting::NoSectors => None,
            Setting::Grid(k) => Some(k),
        }
    }
}

/// The thesis column (0 = no sectors, 1..=5 = [`BPS`]) of a setting for `n` balls.
fn column(n: usize, s: Setting) -> usize {
    match s {
        Setting::NoSectors => 0,
        Setting::Grid(k) => {
            let k2 = (k * k) as usize;
            1 + BPS
                .iter()
                .position(|&(num, den)| n * den == num * k2)
                .expect("settings come from BPS")
        }
    }
}

/// The settings run for `n` balls: no sectors, then `k × k` for each of the thesis' balls per
/// sector where `k = √(n / b)` is a whole number, fewest sectors first.
pub fn settings(n: usize) -> Vec<Setting> {
    let mut out = vec![Setting::NoSectors];
    for (num, den) in BPS {
        if (n * den).is_multiple_of(num) {
            if let Some(k) = isqrt(n * den / num) {
                if k >= 1 {
                    out.push(Setting::Grid(k as u32));
                }
            }
        }
    }
    out
}

/// Writes `bytes` to `path`, with an error naming the file.
pub(crate) fn write(path: &Path, bytes: &[u8]) -> Result<(), ExperimentError> {
    std::fs::write(path, bytes).map_err(|source| ExperimentError::Write {
        path: path.to_path_buf(),
        source,
    })
}

/// Runs `poolsim experiment jamming`: one number of disks (`--balls`), `--seeds` per rate.
fn run_jamming(
    args: &ExperimentOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<(), ExperimentError> {
    let balls = match args.balls.as_deref() {
        None => None,
        Some([n]) if (16..=super::scenario::builtin::MAX_BALLS).contains(n) => Some(*n),
        Some(_) => return Err(ExperimentError::JammingBalls),
    };
    if let Some(s) = args.seeds.filter(|s| !(1..=1000).contains(s)) {
        return Err(ExperimentError::Seeds(s));
    }
    let plan =
        crate::jamming_study::JammingPlan::new(args.quick, balls, args.seeds, args.rates.clone())?;
    let font = args
        .font
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_FONT));
    progress(Progress::Start(plan.rates.len() as u64 * plan.seeds));
    crate::jamming_study::run(&args.out, &font, &plan)?;
    progress(Progress::Finished);
    Ok(())
}

/// Creates the directory `dir` and its parents, with an error naming it.
pub(crate) fn create_dir(dir: &Path) -> Result<(), ExperimentError> {
    std::fs::create_dir_all(dir).map_err(|source| ExperimentError::CreateDir {
        path: dir.to_path_buf(),
        source,
    })
}

/// Runs `poolsim experiment`: every run of the plan, then the tables, `results.json` and the
/// report, then the figures. Errors are one line for the user (bad arguments, a failed run, an
/// unwritable directory, a missing font); files written before an error stay.
pub fn run(
    args: &ExperimentOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<(), ExperimentError> {
    if args.which == Which::Eos {
        if args.rates.is_some() {
            return Err(ExperimentError::JammingOnly { flag: "--rates" });
        }
        if args.seeds.is_some() {
            return Err(ExperimentError::ThesisOnly { flag: "--seeds" });
        }
        let balls = match args.balls.as_deref() {
            None => None,
            Some([n]) if (16..=super::scenario::builtin::MAX_BALLS).contains(n) => Some(*n),
            Some(_) => return Err(ExperimentError::EosBalls),
        };
        let plan = crate::eos_study::EosPlan::new(args.quick, balls, args.area_fractions.clone())?;
        let font = args
            .font
            .clone()
            .unwrap_or_else(|| PathBuf::from(DEFAULT_FONT));
        progress(Progress::Start(plan.area_fractions.len() as u64));
        crate::eos_study::run(&args.out, &font, &plan, &|_| {})?;
        progress(Progress::Finished);
        return Ok(());
    }
    if args.area_fractions.is_some() {
        return Err(ExperimentError::EosOnly {
            flag: "--area-fractions",
        });
    }
    if args.which == Which::Jamming {
        return run_jamming(args, progress);
    }
    if args.rates.is_some() {
        return Err(ExperimentError::JammingOnly { flag: "--rates" });
    }
    if args.which == Which::Reversal {
        if let Some(flag) = [
            ("--seeds", args.seeds.is_some()),
            ("--balls", args.balls.is_some()),
        ]
        .iter()
        .find_map(|&(flag, given)| given.then_some(flag))
        {
            return Err(ExperimentError::ThesisOnly { flag });
        }
        let font = args
            .font
            .clone()
            .unwrap_or_else(|| PathBuf::from(DEFAULT_FONT));
        return crate::reversal_study::run(&args.out, &font, args.quick);
    }
    let plan = Plan::from_options(args)?;
    let dir = &args.out;
    create_dir(dir)?;
    let data = data::measure(&plan, progress)?;
    let tables = vec![
        ("table5", tables::table5(&data)),
        ("table6", tables::table6(&data)),
        ("table7", tables::table7(&data)),
        ("table8", tables::table8(&data)),
        ("table9", tables::table9(&data)),
        ("table10", tables::table10(&data)),
    ];
    for (name, text) in &tables {
        write(&dir.join(format!("{name}.md")), text.as_bytes())?;
    }
    let fs = findings::findings(&data);
    let results = serde_json::to_string_pretty(&results::results_json(&data, &fs))
        .map_err(ExperimentError::Results)?;
    write(&dir.join("results.json"), results.as_bytes())?;
    let font = args
        .font
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_FONT));
    let figures = register_font(&font).and_then(|()| {
        let ms = figures::measured(&data);
        figures::write_figure(dir, 1, &ms)?;
        figures::write_figure(dir, 2, &ms)
    });
    let report = report::report(&data, &tables, &fs, figures.is_ok())?;
    write(&dir.join("report.md"), report.as_bytes())?;
    figures?;
    if !data.mismatches.is_empty() {
        return Err(ExperimentError::Mismatch {
            count: data.mismatches.len(),
            first: data.mismatches[0].clone(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::tables::mean_adjacent;
    use super::*;

    #[test]
    fn settings_follow_the_thesis_grid() {
        let ks = |n| {
            settings(n)
                .into_iter()
                .filter_map(Setting::per_side)
                .collect::<Vec<_>>()
        };
        assert_eq!(ks(4), [1, 2, 4]);
        assert_eq!(ks(16), [1, 2, 4, 8]);
        assert_eq!(ks(36), [2, 3, 6, 12]);
        assert_eq!(ks(64), [2, 4, 8, 16]);
        // a thesis size S is (S/50)² balls per sector whatever N
        assert_eq!(column(36, Setting::Grid(3)), 3); // size 100
        assert_eq!(column(64, Setting::Grid(4)), 3); // size 100
        assert_eq!(column(16, Setting::Grid(1)), 1); // size 200
    }

    #[test]
    fn adjacency_of_a_grid() {
        assert_eq!(mean_adjacent(1), 0.0);
        assert_eq!(mean_adjacent(2), 3.0);
        assert!((mean_adjacent(3) - (12.0 + 20.0 + 8.0) / 9.0).abs() < 1e-12);
    }

    #[test]
    fn thesis_tables_add_up() {
        // table 8's types sum to table 5's 36-ball totals
        for (c, t5) in [(0, 0), (1, 2), (2, 3), (3, 4)] {
            let sum: f64 = thesis::TABLE8.iter().filter_map(|r| r.1[c].value()).sum();
            assert_eq!(Some(sum), thesis::row(&thesis::TABLE5, 36)[t5].value());
        }
    }

    #[test]
    fn plan_defaults_and_errors() {
        let mut a = ExperimentOptions {
            which: Which::Thesis,
            out: PathBuf::from("x"),
            seeds: None,
            balls: None,
            quick: false,
            font: None,
            area_fractions: None,
            rates: None,
        };
        let p = Plan::from_options(&a).unwrap();
        assert_eq!((p.balls.clone(), p.seeds), (vec![4, 16, 36, 64], 6));
        a.quick = true;
        let p = Plan::from_options(&a).unwrap();
        assert_eq!((p.balls, p.seeds, p.until), (vec![4, 16], 2, 4.0));
        a.balls = Some(vec![5000]);
        assert_eq!(
            Plan::from_options(&a).unwrap_err().to_string(),
            "--balls: 5000 is not a whole number from 1 to 4096"
        );
        a.balls = None;
        a.seeds = Some(0);
        assert_eq!(
            Plan::from_options(&a).unwrap_err().to_string(),
            "--seeds must be from 1 to 1000, got 0"
        );
    }
}
