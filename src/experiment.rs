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

use crate::analytic::{self, ModelParams};
use crate::engine::{Event, EventKind, Ignore, Observer, RunError, World};
use crate::model::pool::NvDelay;
use crate::run::{execute, EngineKind, FixedNews, RunConfig, SectorChoice};
use crate::scenario::builtin::{self, Params};
use crate::scenario::Scenario;
use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// Where Debian's `fonts-dejavu-core` puts the font the figures' text is drawn with.
pub const DEFAULT_FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

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
    /// Numbers of balls, square numbers (default 4, 16, 36, 64; 4, 16 when quick).
    pub balls: Option<Vec<usize>>,
    /// A reduced grid for CI: 4 and 16 balls, 2 seeds, until 4.
    pub quick: bool,
    /// TrueType font for the figures' text (default [`DEFAULT_FONT`]).
    pub font: Option<PathBuf>,
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
    pub fn from_options(a: &ExperimentOptions) -> Result<Plan, String> {
        let seeds = a.seeds.unwrap_or(if a.quick { 2 } else { 6 });
        if seeds == 0 || seeds > 1000 {
            return Err(format!("--seeds must be from 1 to 1000, got {seeds}"));
        }
        let mut balls = a.balls.clone().unwrap_or_else(|| {
            if a.quick {
                vec![4, 16]
            } else {
                vec![4, 16, 36, 64]
            }
        });
        if balls.is_empty() {
            return Err("--balls needs at least one number of balls".into());
        }
        for &n in &balls {
            if !(1..=4096).contains(&n) || isqrt(n).is_none() {
                return Err(format!(
                    "--balls: {n} is not a square number from 1 to 4096 (the gas is k x k balls)"
                ));
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

/// The thesis' own numbers (Goldberg 1984, tables 5-10), as printed.
mod thesis {
    /// A cell of a thesis table.
    #[derive(Clone, Copy, Debug, PartialEq)]
    pub enum T {
        /// A number.
        V(f64),
        /// No run ("-").
        No,
        /// Memory overflow on the Dolphin ("mo").
        Mo,
    }
    use T::{Mo, No, V};

    impl T {
        /// The number, if any.
        pub fn value(self) -> Option<f64> {
            match self {
                V(x) => Some(x),
                _ => None,
            }
        }

        /// As printed.
        pub fn text(self) -> String {
            match self {
                V(x) => format!("{x}"),
                No => "-".into(),
                Mo => "mo".into(),
            }
        }

        /// For JSON.
        pub fn json(self) -> serde_json::Value {
            match self {
                V(x) => x.into(),
                No => serde_json::Value::Null,
                Mo => "mo".into(),
            }
        }
    }

    /// Table 5: messages; columns no sectors, sizes 200, 150, 100, 50, 25.
    pub const TABLE5: [(usize, [T; 6]); 4] = [
        (4, [V(632.0), No, No, V(1001.0), V(1627.0), V(3445.0)]),
        (
            16,
            [V(4936.0), V(7677.0), No, V(5366.0), V(6549.0), V(11831.0)],
        ),
        (36, [V(17313.0), No, V(13942.0), V(11492.0), V(13837.0), No]),
        (64, [Mo, No, No, V(17801.0), V(21330.0), Mo]),
    ];

    /// Table 6: elapsed seconds on the Dolphin; columns as table 5.
    pub const TABLE6: [(usize, [T; 6]); 4] = [
        (4, [V(580.0), No, No, V(1114.0), V(1807.0), V(4086.0)]),
        (
            16,
            [V(4540.0), V(5956.0), No, V(5562.0), V(8426.0), V(18564.0)],
        ),
        (36, [V(38575.0), No, V(15926.0), V(13097.0), V(20234.0), No]),
        (64, [Mo, No, No, V(36256.0), V(68843.0), Mo]),
    ];

    /// Table 7: balls, mean and sd of messages, mean and sd of elapsed seconds (non-sectored,
    /// several seeds).
    pub const TABLE7: [(usize, [f64; 4]); 3] = [
        (4, [452.0, 109.0, 545.0, 55.0]),
        (16, [3850.0, 708.0, 3536.0, 612.0]),
        (36, [14293.0, 1412.0, 26336.0, 5903.0]),
    ];

    /// Table 8 (36 balls): message type and counts for no sectors and sizes 150, 100, 50.
    pub const TABLE8: [(&str, [T; 4]); 6] = [
        ("SectorDeparture", [No, V(1080.0), V(1206.0), V(1952.0)]),
        ("SectorEntry", [No, V(480.0), V(680.0), V(1282.0)]),
        ("VelocityChange", [No, V(341.0), V(373.0), V(609.0)]),
        ("Collision", [V(2880.0), V(1746.0), V(1280.0), V(1070.0)]),
        ("Cancel", [V(2304.0), V(2616.0), V(2404.0), V(3092.0)]),
        ("NewVelocity", [V(12129.0), V(7679.0), V(5549.0), V(5832.0)]),
    ];

    /// Table 9 (36 balls; 4, 9, 36 sectors): VelocityChange, estimated sector entries, sectors
    /// occupied by a ball, estimated balls per sector, estimated and actual NewVelocity.
    pub const TABLE9: [[f64; 6]; 3] = [
        [341.0, 155.0, 1.23, 11.0, 7459.0, 7679.0],
        [373.0, 232.0, 1.34, 5.4, 5671.0, 5549.0],
        [609.0, 465.0, 2.19, 2.2, 6648.0, 5832.0],
    ];
    /// Table 9's parameters: total free path, number of collisions, table side.
    pub const TABLE9_PARAMS: (f64, f64, f64) = (7749.0, 278.0, 600.0);

    /// Table 10: messages by balls per sector 16, 9, 4, 1, 1/4 (note 5368 where table 5 has
    /// 5366).
    pub const TABLE10: [(usize, [T; 5]); 4] = [
        (4, [No, No, V(1001.0), V(1627.0), V(3445.0)]),
        (16, [V(7677.0), No, V(5368.0), V(6549.0), V(11831.0)]),
        (36, [No, V(13942.0), V(11492.0), V(13837.0), No]),
        (64, [No, No, V(17801.0), V(21330.0), Mo]),
    ];

    /// Row `n` of a table keyed by balls.
    pub fn row<const C: usize>(table: &[(usize, [T; C])], n: usize) -> [T; C] {
        table
            .iter()
            .find(|r| r.0 == n)
            .map(|r| r.1)
            .unwrap_or([No; C])
    }
}
use thesis::T;

/// One objects-engine run.
#[derive(Clone, Debug, Serialize)]
pub struct RunRecord {
    /// Number of balls.
    pub balls: usize,
    /// Scenario seed.
    pub seed: u64,
    /// `none` or `KxK`.
    pub setting: String,
    /// Sectors per side (none for the non-sectored engine).
    pub sectors_per_side: Option<u32>,
    /// Mean balls per sector, `N / k²`.
    pub balls_per_sector: Option<f64>,
    /// Messages sent by type, and `total`: the six types the thesis counts.
    pub messages: BTreeMap<String, u64>,
    /// Wall-clock seconds of the run (setup included): the median of the plan's repetitions.
    pub wall_seconds: f64,
    /// Physical events executed.
    pub events: u64,
    /// Hash of the final state (equal digests: bit-identical final states).
    pub digest: String,
}

impl RunRecord {
    fn total(&self) -> f64 {
        self.msg("total")
    }

    fn msg(&self, name: &str) -> f64 {
        self.messages.get(name).copied().unwrap_or(0) as f64
    }
}

/// The physics of one gas, from the event-list engine (the same for every engine).
#[derive(Clone, Debug, Serialize)]
pub struct PhysicsRecord {
    /// Number of balls.
    pub balls: usize,
    /// Scenario seed.
    pub seed: u64,
    /// Table side (length units).
    pub table_side: f64,
    /// Total free path: Σ over balls of speed × time, between time 0 and the end (length).
    pub free_path: f64,
    /// Ball–ball collisions.
    pub ball_ball: u64,
    /// Ball–cushion bounces.
    pub ball_cushion: u64,
    /// Ball velocity changes: two per ball–ball collision, one per bounce.
    pub velocity_changes: u64,
    /// The event-list engine's final-state digest.
    pub digest: String,
}

/// Adds up the free path of every ball from the events and the world state after each.
struct FreePath {
    /// Per ball: the speed since its last change, and that change's time.
    last: Vec<(f64, f64)>,
    path: f64,
    ball_ball: u64,
    ball_cushion: u64,
    changes: u64,
}

impl FreePath {
    fn new(s: &Scenario) -> FreePath {
        FreePath {
            last: s.balls.iter().map(|b| (b.velocity.norm(), 0.0)).collect(),
            path: 0.0,
            ball_ball: 0,
            ball_cushion: 0,
            changes: 0,
        }
    }

    fn advance(&mut self, i: u32, t: f64, world: &dyn World) {
        let (v, t0) = self.last[i as usize];
        self.path += v * (t - t0);
        self.last[i as usize] = (world.ball(i).velocity().norm(), t);
    }

    /// The path up to `until`.
    fn finish(&self, until: f64) -> f64 {
        self.path
            + self
                .last
                .iter()
                .map(|&(v, t0)| v * (until - t0))
                .sum::<f64>()
    }
}

impl Observer for FreePath {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        self.advance(ev.a, ev.t, world);
        self.changes += 1;
        match ev.kind {
            EventKind::BallBall => {
                self.advance(ev.b, ev.t, world);
                self.ball_ball += 1;
                self.changes += 1;
            }
            EventKind::BallCushion => self.ball_cushion += 1,
            EventKind::BallCorner | EventKind::BallPocket => {}
        }
        Ok(())
    }
}

fn gas(n: usize, seed: u64) -> Result<Scenario, String> {
    builtin::build(
        "gas",
        &Params {
            balls: Some(n),
            seed: Some(seed),
            radius: Some(RADIUS),
            speed_max: Some(SPEED_MAX),
            ..Params::default()
        },
    )
    .map_err(|e| {
        format!(
            "gas with {n} balls, seed {seed}: {}: {}",
            e.field, e.message
        )
    })
}

/// Runs one gas with the event-list engine, measuring its physics.
fn physics(s: &Scenario, n: usize, seed: u64, until: f64) -> Result<PhysicsRecord, String> {
    let mut fp = FreePath::new(s);
    let cfg = RunConfig {
        engine: EngineKind::EventList,
        until,
        check: false,
        span: Default::default(),
    };
    let report = execute(s, &cfg, &mut fp).map_err(|e| format!("{n} balls, seed {seed}: {e}"))?;
    let (lo, hi) = s.bounds();
    Ok(PhysicsRecord {
        balls: n,
        seed,
        table_side: hi.x - lo.x,
        free_path: fp.finish(until),
        ball_ball: fp.ball_ball,
        ball_cushion: fp.ball_cushion,
        velocity_changes: fp.changes,
        digest: report.summary.final_state_digest.clone(),
    })
}

/// Runs one gas with the objects engine in one setting.
fn objects(
    s: &Scenario,
    n: usize,
    seed: u64,
    setting: Setting,
    until: f64,
    repeats: u32,
) -> Result<RunRecord, String> {
    let engine = match setting {
        Setting::NoSectors => EngineKind::Objects {
            delay: NvDelay::Exact,
        },
        // the thesis' message counts: every ball tells every fixed object
        Setting::Grid(k) => EngineKind::Sectored {
            sectors: SectorChoice::Grid(k, k),
            news: FixedNews::Thesis,
        },
    };
    let cfg = RunConfig {
        engine,
        until,
        check: false,
        span: Default::default(),
    };
    let fail = |e: RunError| format!("{n} balls, seed {seed}, sectors {}: {e}", setting.name());
    let report = execute(s, &cfg, &mut Ignore).map_err(fail)?;
    let mut walls = vec![report.wall_seconds];
    for _ in 1..repeats.max(1) {
        let again = execute(s, &cfg, &mut Ignore).map_err(fail)?;
        if again.summary.messages != report.summary.messages {
            return Err(format!(
                "{n} balls, seed {seed}, sectors {}: a repeated run sent different messages",
                setting.name()
            ));
        }
        walls.push(again.wall_seconds);
    }
    walls.sort_by(f64::total_cmp);
    let wall = walls[walls.len() / 2];
    let messages = report.summary.messages.by_name();
    Ok(RunRecord {
        balls: n,
        seed,
        setting: setting.name(),
        sectors_per_side: setting.per_side(),
        balls_per_sector: setting.per_side().map(|k| n as f64 / (k * k) as f64),
        messages,
        wall_seconds: wall,
        events: report.outcome.events.total(),
        digest: report.summary.final_state_digest.clone(),
    })
}

/// Mean, sample standard deviation and range of a few numbers.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Stat {
    /// How many numbers.
    pub n: usize,
    /// Their mean.
    pub mean: f64,
    /// Their sample standard deviation (`n − 1`); `None` for fewer than two.
    pub sd: Option<f64>,
    /// The smallest.
    pub min: f64,
    /// The largest.
    pub max: f64,
}

impl Stat {
    /// The statistics of `xs`.
    pub fn of(xs: &[f64]) -> Stat {
        let n = xs.len();
        if n == 0 {
            return Stat::default();
        }
        let mean = xs.iter().sum::<f64>() / n as f64;
        let sd = (n > 1).then(|| {
            (xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64).sqrt()
        });
        Stat {
            n,
            mean,
            sd,
            min: xs.iter().copied().fold(f64::INFINITY, f64::min),
            max: xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }

    /// `mean ± sd`, rounded to whole numbers.
    fn pm(&self) -> String {
        match self.sd {
            Some(sd) => format!("{:.0} ± {:.0}", self.mean, sd),
            None => format!("{:.0}", self.mean),
        }
    }
}

/// Everything the experiment measured, indexed.
struct Data {
    plan: Plan,
    runs: Vec<RunRecord>,
    physics: Vec<PhysicsRecord>,
    /// `(balls, setting)` → indices into `runs`, by seed.
    cells: BTreeMap<(usize, Setting), Vec<usize>>,
    mismatches: Vec<String>,
    wall_total: f64,
}

impl Data {
    fn cell(&self, n: usize, s: Setting) -> Vec<&RunRecord> {
        self.cells
            .get(&(n, s))
            .map(|v| v.iter().map(|&i| &self.runs[i]).collect())
            .unwrap_or_default()
    }

    /// Statistics of `f` over the seeds of a cell.
    fn stat(&self, n: usize, s: Setting, f: impl Fn(&RunRecord) -> f64) -> Option<Stat> {
        let xs: Vec<f64> = self.cell(n, s).into_iter().map(f).collect();
        (!xs.is_empty()).then(|| Stat::of(&xs))
    }

    fn total(&self, n: usize, s: Setting) -> Option<Stat> {
        self.stat(n, s, RunRecord::total)
    }

    fn phys(&self, n: usize) -> Vec<&PhysicsRecord> {
        self.physics.iter().filter(|p| p.balls == n).collect()
    }

    fn phys_stat(&self, n: usize, f: impl Fn(&PhysicsRecord) -> f64) -> Stat {
        let xs: Vec<f64> = self.phys(n).into_iter().map(f).collect();
        Stat::of(&xs)
    }

    /// The number of balls tables 8 and 9 describe: 36 if run, else the largest.
    fn focus(&self) -> usize {
        if self.plan.balls.contains(&36) {
            36
        } else {
            *self.plan.balls.last().expect("a plan has balls")
        }
    }

    /// The sectored setting with the fewest mean messages for `n`, with its mean.
    fn best_sectored(&self, n: usize) -> Option<(Setting, f64)> {
        settings(n)
            .into_iter()
            .filter(|s| *s != Setting::NoSectors)
            .filter_map(|s| self.total(n, s).map(|t| (s, t.mean)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// `V T` in table widths (mean free path per ball over the table side) and `m` (velocity
    /// changes), averaged over seeds: the chapter 7 parameters of our gas of `n` balls.
    fn model_params(&self, n: usize) -> (f64, f64) {
        let ph = self.phys(n);
        if ph.is_empty() {
            return (0.0, 0.0);
        }
        let k = ph.len() as f64;
        let vt = ph
            .iter()
            .map(|p| p.free_path / n as f64 / p.table_side)
            .sum::<f64>()
            / k;
        let m = ph.iter().map(|p| p.velocity_changes as f64).sum::<f64>() / k;
        (vt, m)
    }
}

/// Runs every cell of the plan, telling `progress` how far it has come.
fn measure(plan: &Plan, progress: &mut dyn FnMut(Progress)) -> Result<Data, String> {
    let start = Instant::now();
    let total: u64 = plan
        .balls
        .iter()
        .map(|&n| (settings(n).len() as u64 + 1) * plan.seeds)
        .sum();
    progress(Progress::Start(total));
    let mut runs = Vec::new();
    let mut physics_runs = Vec::new();
    let mut cells: BTreeMap<(usize, Setting), Vec<usize>> = BTreeMap::new();
    let mut mismatches = Vec::new();
    for &n in &plan.balls {
        for seed in 1..=plan.seeds {
            let s = gas(n, seed)?;
            progress(Progress::Cell { balls: n, seed });
            let ph = physics(&s, n, seed, plan.until)?;
            progress(Progress::RunDone);
            for setting in settings(n) {
                let r = objects(&s, n, seed, setting, plan.until, plan.timing_repeats)?;
                if r.digest != ph.digest {
                    mismatches.push(format!(
                        "{n} balls, seed {seed}, sectors {}: final state {} differs from the \
                         event-list engine's {}",
                        setting.name(),
                        r.digest,
                        ph.digest
                    ));
                }
                cells.entry((n, setting)).or_default().push(runs.len());
                runs.push(r);
                progress(Progress::RunDone);
            }
            physics_runs.push(ph);
        }
    }
    progress(Progress::Finished);
    Ok(Data {
        plan: plan.clone(),
        runs,
        physics: physics_runs,
        cells,
        mismatches,
        wall_total: start.elapsed().as_secs_f64(),
    })
}

/// A Markdown table.
fn md_table(header: &[String], rows: &[Vec<String>]) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "| {} |", header.join(" | "));
    let _ = writeln!(
        out,
        "|{}",
        header
            .iter()
            .enumerate()
            .map(|(i, _)| if i == 0 { "---|" } else { "---:|" })
            .collect::<String>()
    );
    for r in rows {
        let _ = writeln!(out, "| {} |", r.join(" | "));
    }
    out
}

fn strings(xs: &[&str]) -> Vec<String> {
    xs.iter().map(|s| s.to_string()).collect()
}

/// The setting of thesis column `c` (0 = none, 1..=5 balls per sector) for `n` balls, if run.
fn setting_at(n: usize, c: usize) -> Option<Setting> {
    settings(n).into_iter().find(|&s| column(n, s) == c)
}

/// A table in the layout of thesis table 5 (rows: balls; columns: no sectors and sizes 200..25)
/// with our cell text and the thesis' value beside it.
fn size_layout(
    data: &Data,
    thesis_table: &[(usize, [T; 6])],
    ours: impl Fn(usize, Setting) -> Option<String>,
) -> String {
    let mut header = vec!["Balls".to_string(), "No sectors".to_string()];
    header.extend(
        SIZE_LABEL
            .iter()
            .zip(BPS_LABEL)
            .map(|(s, b)| format!("Size {s} ({b}/sector)")),
    );
    let mut rows = Vec::new();
    for &n in &data.plan.balls {
        let th = thesis::row(thesis_table, n);
        let mut row = vec![n.to_string()];
        for (c, t) in th.iter().enumerate() {
            let cell = match setting_at(n, c).and_then(|s| ours(n, s).map(|o| (s, o))) {
                Some((_, o)) if c == 0 => format!("{o} ({})", t.text()),
                Some((s, o)) => format!("{}: {o} ({})", s.label(), t.text()),
                None if *t == T::No => "-".into(),
                None => format!("- ({})", t.text()),
            };
            row.push(cell);
        }
        rows.push(row);
    }
    md_table(&header, &rows)
}

/// The thesis' table as printed, in the size layout.
fn thesis_size_table(table: &[(usize, [T; 6])]) -> String {
    let mut header = vec!["Balls".to_string(), "No sectors".to_string()];
    header.extend(SIZE_LABEL.iter().map(|s| s.to_string()));
    let rows: Vec<Vec<String>> = table
        .iter()
        .map(|(n, r)| {
            let mut row = vec![n.to_string()];
            row.extend(r.iter().map(|t| t.text()));
            row
        })
        .collect();
    md_table(&header, &rows)
}

fn table5(data: &Data) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Table 5. Message count of pool ball simulations\n");
    let _ = writeln!(
        out,
        "Our runs: mean ± sample standard deviation over {} seeds of the total messages of the six \
         types the thesis counts (VelocityChange, NewVelocity, SectorDeparture, SectorEntry, Cancel, \
         Collision); in parentheses the thesis' single run (Goldberg 1984, table 5). Columns are \
         the thesis' sector sizes; each cell names the grid (sectors per side) that size means \
         for its number of balls: size S holds (S/50)² balls per sector. \"-\": not run; \
         \"mo\": the thesis' run overflowed the Dolphin's memory.\n",
        data.plan.seeds
    );
    out.push_str(&size_layout(data, &thesis::TABLE5, |n, s| {
        data.total(n, s).map(|t| t.pm())
    }));
    let _ = writeln!(out, "\nThe thesis' table 5 as printed:\n");
    out.push_str(&thesis_size_table(&thesis::TABLE5));
    out
}

fn table6(data: &Data) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Table 6. Elapsed time of pool ball simulations\n");
    let _ = writeln!(
        out,
        "Our wall time per run in milliseconds (for each seed the median of {} repetitions, then \
         the mean over {} seeds; one core, setup included), with the Dolphin's seconds from the \
         thesis' table 6 in parentheses.\n",
        data.plan.timing_repeats, data.plan.seeds
    );
    out.push_str(&size_layout(data, &thesis::TABLE6, |n, s| {
        data.stat(n, s, |r| r.wall_seconds * 1e3)
            .map(|t| format!("{:.2} ms", t.mean))
    }));
    let _ = writeln!(
        out,
        "\nMessages per second: ours (mean total messages / mean wall time), and in parentheses \
         the Dolphin's (thesis table 5 / table 6).\n"
    );
    let rate_thesis: Vec<(usize, [T; 6])> = thesis::TABLE5
        .iter()
        .zip(thesis::TABLE6.iter())
        .map(|((n, m), (_, t))| {
            let mut r = [T::No; 6];
            for c in 0..6 {
                r[c] = match (m[c], t[c]) {
                    (T::V(a), T::V(b)) => T::V((a / b * 100.0).round() / 100.0),
                    (x, _) => x,
                };
            }
            (*n, r)
        })
        .collect();
    out.push_str(&size_layout(data, &rate_thesis, |n, s| {
        let m = data.total(n, s)?;
        let w = data.stat(n, s, |r| r.wall_seconds)?;
        Some(format!("{:.2} M/s", m.mean / w.mean / 1e6))
    }));
    let _ = writeln!(out, "\nThe thesis' table 6 (seconds) as printed:\n");
    out.push_str(&thesis_size_table(&thesis::TABLE6));
    out
}

fn table7(data: &Data) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Table 7. Mean and standard deviation of message counts and elapsed time\n"
    );
    let _ = writeln!(
        out,
        "The non-sectored objects engine over {} seeds (the thesis ran six seeds for its \
         non-sectored cases). Ours: messages and wall milliseconds; thesis: messages and Dolphin \
         seconds.\n",
        data.plan.seeds
    );
    let header = strings(&[
        "Balls",
        "Messages mean",
        "SD",
        "Thesis mean",
        "Thesis SD",
        "Wall ms mean",
        "SD",
        "Thesis s mean",
        "Thesis SD",
    ]);
    let mut rows = Vec::new();
    for &n in &data.plan.balls {
        let m = data.total(n, Setting::NoSectors).unwrap_or_default();
        let w = data
            .stat(n, Setting::NoSectors, |r| r.wall_seconds * 1e3)
            .unwrap_or_default();
        let th = thesis::TABLE7.iter().find(|r| r.0 == n).map(|r| r.1);
        let f = |i: usize| th.map_or("-".to_string(), |t| format!("{}", t[i]));
        let sd = |s: Option<f64>, p: usize| s.map_or("-".to_string(), |x| format!("{x:.p$}"));
        rows.push(vec![
            n.to_string(),
            format!("{:.0}", m.mean),
            sd(m.sd, 0),
            f(0),
            f(1),
            format!("{:.3}", w.mean),
            sd(w.sd, 3),
            f(2),
            f(3),
        ]);
    }
    out.push_str(&md_table(&header, &rows));
    let _ = writeln!(
        out,
        "\nAll settings, messages (mean ± SD, coefficient of variation):\n"
    );
    let header = strings(&["Balls", "Sectors", "Messages", "CV"]);
    let mut rows = Vec::new();
    for &n in &data.plan.balls {
        for s in settings(n) {
            if let Some(t) = data.total(n, s) {
                rows.push(vec![
                    n.to_string(),
                    s.label(),
                    t.pm(),
                    t.sd.map_or("-".into(), |sd| format!("{:.1}%", 100.0 * sd / t.mean)),
                ]);
            }
        }
    }
    out.push_str(&md_table(&header, &rows));
    out
}

/// The thesis' order of message types in table 8, then ours not in the total.
const TYPES8: [&str; 6] = [
    "SectorDeparture",
    "SectorEntry",
    "VelocityChange",
    "Collision",
    "Cancel",
    "NewVelocity",
];

fn table8(data: &Data) -> String {
    let n = data.focus();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Table 8. Number of messages tabulated by message type\n"
    );
    let _ = writeln!(
        out,
        "{n} balls: our mean over {} seeds{}. VelocityInitialization (thesis 5.4) and \
         CollisionConfirm (ours, beyond the thesis) are shown but, like the thesis, not counted \
         in the total.\n",
        data.plan.seeds,
        if n == 36 {
            ", and in parentheses the thesis' 36-ball run (table 8; sizes 150, 100, 50 are 2×2, \
             3×3, 6×6 sectors)"
        } else {
            " (the thesis' table 8 is for 36 balls, which this run did not include)"
        }
    );
    let sets = settings(n);
    let mut header = vec!["Message type".to_string()];
    header.extend(sets.iter().map(|s| s.label()));
    // thesis table 8 columns: none, b = 9, 4, 1 (columns 0, 2, 3, 4 of table 5)
    let thesis_col = |s: Setting| -> Option<usize> {
        if n != 36 {
            return None;
        }
        match column(n, s) {
            0 => Some(0),
            2 => Some(1),
            3 => Some(2),
            4 => Some(3),
            _ => None,
        }
    };
    let mut rows = Vec::new();
    let mut names: Vec<&str> = TYPES8.to_vec();
    names.push("total");
    names.extend(["VelocityInitialization", "CollisionConfirm"]);
    for name in names {
        let mut row = vec![if name == "total" {
            "**Total**".to_string()
        } else {
            name.to_string()
        }];
        for &s in &sets {
            let ours = data.stat(n, s, |r| r.msg(name)).unwrap_or_default().mean;
            let th = thesis_col(s).map(|c| {
                if name == "total" {
                    thesis::row(&thesis::TABLE5, 36)[column(36, s)]
                } else {
                    thesis::TABLE8
                        .iter()
                        .find(|r| r.0 == name)
                        .map_or(T::No, |r| r.1[c])
                }
            });
            row.push(match th {
                Some(t) => format!("{ours:.0} ({})", t.text()),
                None => format!("{ours:.0}"),
            });
        }
        rows.push(row);
    }
    out.push_str(&md_table(&header, &rows));
    out
}

/// Mean number of sectors adjacent (by an edge or a corner) to a sector of a `k × k` grid.
fn mean_adjacent(k: u32) -> f64 {
    if k < 2 {
        return 0.0;
    }
    let k = k as f64;
    (4.0 * 3.0 + 4.0 * (k - 2.0) * 5.0 + (k - 2.0) * (k - 2.0) * 8.0) / (k * k)
}

/// One column of the table 9 spreadsheet.
#[derive(Clone, Debug, Serialize)]
struct Sheet {
    sectors_per_side: u32,
    sectors: u32,
    sector_width: f64,
    velocity_change: f64,
    estimated_entries: f64,
    scheduled_entries: f64,
    fitted_c: f64,
    sectors_occupied: f64,
    estimated_balls_per_sector: f64,
    estimated_new_velocity: f64,
    mean_adjacent_sectors: f64,
    estimated_new_velocity_our_adjacency: f64,
    actual_new_velocity: f64,
}

fn spreadsheet(data: &Data, n: usize) -> Vec<Sheet> {
    let path = data.phys_stat(n, |p| p.free_path).mean;
    let changes = data.phys_stat(n, |p| p.velocity_changes as f64).mean;
    let side = data.phys_stat(n, |p| p.table_side).mean;
    let mut out = Vec::new();
    for s in settings(n) {
        let Setting::Grid(k) = s else { continue };
        let vc = data
            .stat(n, s, |r| r.msg("VelocityChange"))
            .unwrap_or_default()
            .mean;
        let entries = data
            .stat(n, s, |r| r.msg("SectorEntry"))
            .unwrap_or_default()
            .mean
            / 2.0;
        let nv = data
            .stat(n, s, |r| r.msg("NewVelocity"))
            .unwrap_or_default()
            .mean;
        let width = side / k as f64;
        let est_entries = C_ENTRIES * path / width;
        let occupied = if changes > 0.0 { vc / changes } else { 0.0 };
        let bps = occupied * n as f64 / (k * k) as f64;
        let adj = mean_adjacent(k);
        out.push(Sheet {
            sectors_per_side: k,
            sectors: k * k,
            sector_width: width,
            velocity_change: vc,
            estimated_entries: est_entries,
            scheduled_entries: entries,
            fitted_c: if path > 0.0 {
                entries * width / path
            } else {
                0.0
            },
            sectors_occupied: occupied,
            estimated_balls_per_sector: bps,
            estimated_new_velocity: (bps + THESIS_ADJACENT) * (vc + est_entries),
            mean_adjacent_sectors: adj,
            estimated_new_velocity_our_adjacency: (bps + adj) * (vc + est_entries),
            actual_new_velocity: nv,
        });
    }
    out
}

fn table9(data: &Data) -> String {
    let n = data.focus();
    let sheets = spreadsheet(data, n);
    let path = data.phys_stat(n, |p| p.free_path);
    let bb = data.phys_stat(n, |p| p.ball_ball as f64);
    let cush = data.phys_stat(n, |p| p.ball_cushion as f64);
    let changes = data.phys_stat(n, |p| p.velocity_changes as f64);
    let side = data.phys_stat(n, |p| p.table_side).mean;
    let (tp, tc, tside) = thesis::TABLE9_PARAMS;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Table 9. Spreadsheet for estimating the number of NewVelocity messages\n"
    );
    let _ = writeln!(
        out,
        "The thesis' estimator (6.1) applied to our {n}-ball runs (means over {} seeds){}:\n\n\
         - estimated sector entries = c · total free path / sector width, c = {C_ENTRIES};\n\
         - sectors occupied by a ball = VelocityChange / velocity changes;\n\
         - estimated balls per sector = sectors occupied · N / sectors;\n\
         - estimated NewVelocity = (estimated balls per sector + 4 adjacent objects) · \
         (VelocityChange + estimated sector entries).\n",
        data.plan.seeds,
        if n == 36 {
            ", beside the thesis' 36-ball values in parentheses"
        } else {
            " (the thesis' table 9 is for 36 balls, which this run did not include)"
        }
    );
    let _ = writeln!(
        out,
        "Parameters (ours, mean ± SD over seeds; thesis in parentheses):\n\n\
         - number of balls = {n} (36)\n\
         - total free path = {} ({tp}), measured as Σ over balls of speed × time on the table \
         by an observer of the event-list engine (the same physical events as every objects run)\n\
         - number of collisions: {} ball–ball collisions and {} cushion bounces, so {} ball \
         velocity changes (thesis: {tc} \"collisions\"; we read them as velocity changes, the \
         only reading under which VelocityChange / collisions is the number of sectors a ball \
         occupies)\n\
         - table dimensions = {side}×{side} ({tside}×{tside})\n",
        path.pm(),
        bb.pm(),
        cush.pm(),
        changes.pm(),
    );
    let mut header = vec!["".to_string()];
    header.extend(
        sheets
            .iter()
            .map(|s| format!("{}×{}", s.sectors_per_side, s.sectors_per_side)),
    );
    let thesis_col = |k: u32| -> Option<usize> {
        if n != 36 {
            return None;
        }
        match k {
            2 => Some(0),
            3 => Some(1),
            6 => Some(2),
            _ => None,
        }
    };
    type Row<'a> = (&'a str, Box<dyn Fn(&Sheet) -> String>, Option<usize>);
    let rows_spec: Vec<Row> = vec![
        (
            "Number of sectors",
            Box::new(|s: &Sheet| s.sectors.to_string()),
            None,
        ),
        (
            "Sector width (ours; thesis label)",
            Box::new(|s: &Sheet| format!("{:.0}", s.sector_width)),
            None,
        ),
        (
            "VelocityChange",
            Box::new(|s: &Sheet| format!("{:.0}", s.velocity_change)),
            Some(0),
        ),
        (
            "Estimated sector entries",
            Box::new(|s: &Sheet| format!("{:.0}", s.estimated_entries)),
            Some(1),
        ),
        (
            "Scheduled sector entries (SectorEntry / 2)",
            Box::new(|s: &Sheet| format!("{:.0}", s.scheduled_entries)),
            None,
        ),
        (
            "c that fits our entries",
            Box::new(|s: &Sheet| {
                if s.sectors_per_side > 1 {
                    format!("{:.2}", s.fitted_c)
                } else {
                    "-".into()
                }
            }),
            None,
        ),
        (
            "Sectors occupied by a ball",
            Box::new(|s: &Sheet| format!("{:.2}", s.sectors_occupied)),
            Some(2),
        ),
        (
            "Estimated balls per sector",
            Box::new(|s: &Sheet| format!("{:.1}", s.estimated_balls_per_sector)),
            Some(3),
        ),
        (
            "Estimated NewVelocity messages",
            Box::new(|s: &Sheet| format!("{:.0}", s.estimated_new_velocity)),
            Some(4),
        ),
        (
            "Actual NewVelocity messages",
            Box::new(|s: &Sheet| format!("{:.0}", s.actual_new_velocity)),
            Some(5),
        ),
        (
            "Estimate / actual",
            Box::new(|s: &Sheet| {
                format!("{:.2}", s.estimated_new_velocity / s.actual_new_velocity)
            }),
            None,
        ),
        (
            "Mean adjacent sectors (ours: edges and corners)",
            Box::new(|s: &Sheet| format!("{:.2}", s.mean_adjacent_sectors)),
            None,
        ),
        (
            "Estimated NewVelocity with our adjacency",
            Box::new(|s: &Sheet| format!("{:.0}", s.estimated_new_velocity_our_adjacency)),
            None,
        ),
    ];
    let mut rows = Vec::new();
    for (label, f, tcol) in &rows_spec {
        let mut row = vec![label.to_string()];
        for s in &sheets {
            let ours = f(s);
            let th = thesis_col(s.sectors_per_side);
            let cell = match (th, tcol) {
                (Some(c), Some(t)) => format!("{ours} ({})", thesis::TABLE9[c][*t]),
                (Some(c), None) if *label == "Estimate / actual" => format!(
                    "{ours} ({:.2})",
                    thesis::TABLE9[c][4] / thesis::TABLE9[c][5]
                ),
                (Some(c), None) if label.starts_with("Sector width") => {
                    format!("{ours} ({})", SIZE_LABEL[c + 1])
                }
                _ => ours,
            };
            row.push(cell);
        }
        rows.push(row);
    }
    out.push_str(&md_table(&header, &rows));
    let _ = writeln!(
        out,
        "\nThe thesis' sector sizes 150, 100, 50 are in units of its \"50 × balls per side\" \
         table (300 for 36 balls), while its free path and its 600×600 table are in the units \
         of our table; so its estimated entries, c · 7749 / 150 etc., use half the real sector \
         width, and equal ours with c = 6. We divide by the real width and keep c = 3."
    );
    out
}

fn table10(data: &Data) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Table 10. Message count by balls per sector\n");
    let _ = writeln!(
        out,
        "Table 5 regrouped by the mean number of balls per sector, N / k²: our mean ± SD over \
         {} seeds, and the thesis' table 10 in parentheses (the thesis prints 5368 here for the \
         16-ball, 4-per-sector run it lists as 5366 in table 5).\n",
        data.plan.seeds
    );
    let mut header = vec!["Balls".to_string()];
    header.extend(BPS_LABEL.iter().map(|s| s.to_string()));
    let mut rows = Vec::new();
    for &n in &data.plan.balls {
        let th = thesis::row(&thesis::TABLE10, n);
        let mut row = vec![n.to_string()];
        for (c, t) in th.iter().enumerate() {
            row.push(
                match setting_at(n, c + 1).and_then(|s| data.total(n, s).map(|x| (s, x))) {
                    Some((s, x)) => format!("{}: {} ({})", s.label(), x.pm(), t.text()),
                    None if *t == T::No => "-".into(),
                    None => format!("- ({})", t.text()),
                },
            );
        }
        rows.push(row);
    }
    out.push_str(&md_table(&header, &rows));
    out
}

/// A paired comparison of two settings over the seeds both ran: `a − b` in total messages.
#[derive(Clone, Copy, Debug, Serialize)]
struct Paired {
    a: Setting,
    b: Setting,
    /// Mean of `a − b` over the seeds.
    diff_mean: f64,
    /// Standard error of that mean (`None` for fewer than two seeds).
    diff_se: Option<f64>,
    /// Seeds in which `a` sent fewer messages than `b`.
    a_wins: usize,
    /// Seeds compared.
    seeds: usize,
}

impl Paired {
    /// Whether the difference is within two standard errors of zero: no winner.
    fn tie(&self) -> bool {
        self.diff_se
            .is_none_or(|se| self.diff_mean.abs() <= 2.0 * se)
    }

    /// `−161 ± 120, fewer in 4/6 seeds`.
    fn text(&self) -> String {
        match self.diff_se {
            Some(se) => format!(
                "difference {:+.0} ± {:.0} (standard error), {} fewer in {}/{} seeds",
                self.diff_mean,
                se,
                self.a.label(),
                self.a_wins,
                self.seeds
            ),
            None => format!("difference {:+.0}, one seed", self.diff_mean),
        }
    }
}

impl Data {
    /// Settings `a` and `b` compared seed by seed.
    fn paired(&self, n: usize, a: Setting, b: Setting) -> Paired {
        let ra = self.cell(n, a);
        let rb = self.cell(n, b);
        let mut diffs = Vec::new();
        let mut a_wins = 0;
        for x in &ra {
            if let Some(y) = rb.iter().find(|y| y.seed == x.seed) {
                diffs.push(x.total() - y.total());
                if x.total() < y.total() {
                    a_wins += 1;
                }
            }
        }
        let st = Stat::of(&diffs);
        Paired {
            a,
            b,
            diff_mean: st.mean,
            diff_se: st.sd.map(|sd| sd / (st.n as f64).sqrt()),
            a_wins,
            seeds: st.n,
        }
    }
}

/// What the numbers say, per number of balls.
#[derive(Clone, Debug, Serialize)]
struct Finding {
    balls: usize,
    /// Every setting, fewest mean messages first.
    ranked: Vec<(Setting, f64)>,
    /// Settings statistically tied with the best (paired, within two standard errors).
    ties_best: Vec<Paired>,
    /// The sectored setting with the fewest mean messages.
    best_sectored: Option<Setting>,
    /// Other sectored settings tied with it.
    ties_sectored: Vec<Paired>,
    /// The best sectored setting against no sectors.
    sectored_vs_none: Option<Paired>,
    /// Settings with more than 8 balls per sector against the best sectored one.
    over_eight: Vec<Paired>,
    /// The chapter 7 parameters of our gas: `V T` in table widths and `m`.
    model_vt: f64,
    model_m: f64,
    /// Eq. 2's optimal sectors per side at those parameters, and its best grid of ours.
    model_optimal_per_side: f64,
    model_best_grid: Option<Setting>,
    /// Measured / eq. 2 at the best measured grid and at the finest grid.
    model_ratio_best: Option<f64>,
    model_ratio_finest: Option<f64>,
    /// The thesis' best setting and best sectored setting (table 5), if it ran this N.
    thesis_best: Option<Setting>,
    thesis_best_sectored: Option<Setting>,
}

impl Finding {
    fn best(&self) -> Setting {
        self.ranked[0].0
    }

    fn mean(&self, s: Setting) -> Option<f64> {
        self.ranked.iter().find(|r| r.0 == s).map(|r| r.1)
    }

    /// Whether `s` is the best sectored setting or tied with it.
    fn among_best_sectored(&self, s: Setting) -> bool {
        self.best_sectored == Some(s) || self.ties_sectored.iter().any(|p| p.b == s)
    }
}

fn bps_of(n: usize, s: Setting) -> Option<f64> {
    s.per_side().map(|k| n as f64 / (k * k) as f64)
}

fn findings(data: &Data) -> Vec<Finding> {
    let mut out = Vec::new();
    for &n in &data.plan.balls {
        let mut ranked: Vec<(Setting, f64)> = settings(n)
            .into_iter()
            .filter_map(|s| data.total(n, s).map(|t| (s, t.mean)))
            .collect();
        ranked.sort_by(|a, b| a.1.total_cmp(&b.1));
        let best = ranked[0].0;
        let ties_best = ranked[1..]
            .iter()
            .map(|r| data.paired(n, best, r.0))
            .filter(Paired::tie)
            .collect();
        let bs = data.best_sectored(n).map(|b| b.0);
        let ties_sectored = match bs {
            Some(b) => ranked
                .iter()
                .filter(|r| r.0 != b && r.0 != Setting::NoSectors)
                .map(|r| data.paired(n, b, r.0))
                .filter(Paired::tie)
                .collect(),
            None => Vec::new(),
        };
        let over_eight = match bs {
            Some(b) => settings(n)
                .into_iter()
                .filter(|&s| bps_of(n, s).is_some_and(|x| x > 8.0) && s != b)
                .map(|s| data.paired(n, s, b))
                .collect(),
            None => Vec::new(),
        };
        let (vt, m) = data.model_params(n);
        let p = ModelParams {
            balls: n as f64,
            speed: vt,
            time: 1.0,
            changes: m,
        };
        let ok = p.validate().is_ok();
        let model_at = |s: Setting| {
            s.per_side()
                .filter(|_| ok)
                .map(|k| analytic::messages(&p, 1.0 / k as f64))
        };
        let model_best_grid = settings(n)
            .into_iter()
            .filter_map(|s| model_at(s).map(|f| (s, f)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|x| x.0);
        let ratio = |s: Setting| Some(data.total(n, s)?.mean / model_at(s)?);
        let finest = settings(n)
            .into_iter()
            .last()
            .filter(|s| s.per_side().is_some());
        let th = thesis::row(&thesis::TABLE5, n);
        let thesis_min = |from: usize| {
            (from..6)
                .filter_map(|c| th[c].value().map(|v| (c, v)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .and_then(|(c, _)| setting_at(n, c))
        };
        out.push(Finding {
            balls: n,
            ranked,
            ties_best,
            best_sectored: bs,
            ties_sectored,
            sectored_vs_none: bs.map(|b| data.paired(n, b, Setting::NoSectors)),
            over_eight,
            model_vt: vt,
            model_m: m,
            model_optimal_per_side: if ok {
                1.0 / analytic::optimal_sector(&p)
            } else {
                f64::NAN
            },
            model_best_grid,
            model_ratio_best: bs.and_then(ratio),
            model_ratio_finest: finest.and_then(ratio),
            thesis_best: thesis_min(0),
            thesis_best_sectored: thesis_min(1),
        });
    }
    out
}

fn bps_text(b: Option<f64>) -> String {
    match b {
        None => "-".into(),
        Some(b) if b < 1.0 => format!("1/{:.0}", 1.0 / b),
        Some(b) => format!("{b:.0}"),
    }
}

fn join(xs: &[String], last: &str) -> String {
    match xs.len() {
        0 => String::new(),
        1 => xs[0].clone(),
        k => format!("{} {last} {}", xs[..k - 1].join(", "), xs[k - 1]),
    }
}

fn opt_label(s: Option<Setting>) -> String {
    s.map_or("-".into(), Setting::label)
}

/// Whether a sequence only grows (`up`) or only falls.
fn monotone(xs: &[f64], up: bool) -> bool {
    xs.windows(2)
        .all(|w| if up { w[1] > w[0] } else { w[1] < w[0] })
}

/// The report: setup, what agrees and what does not, with every table inlined.
fn report(data: &Data, tables: &[(&str, String)], fs: &[Finding], figures: bool) -> String {
    let mut o = String::new();
    let p = &data.plan;
    let balls_list: Vec<String> = p.balls.iter().map(|n| n.to_string()).collect();
    let _ = writeln!(
        o,
        "# The thesis experiment (Goldberg 1984, chapter 6) run again\n\n\
         Generated by `poolsim experiment thesis{}`: {} balls, {} seed{} per cell (seeds 1 to \
         {}), until {}; {} objects-engine runs (each timed as the median of {} repetitions) plus \
         one event-list run per gas, {:.1} s of wall time in all. Message counts are exact and \
         deterministic (the same on every machine); wall times are this machine's. Raw numbers: \
         `results.json`; tables: `table5.md` to `table10.md`; figures: `fig17`, `fig18` (.svg, \
         .png).\n",
        if p.quick { " --quick" } else { "" },
        join(&balls_list, "and"),
        p.seeds,
        if p.seeds == 1 { "" } else { "s" },
        p.seeds,
        p.until,
        data.runs.len(),
        p.timing_repeats,
        data.wall_total,
    );
    let _ = writeln!(o, "## Setup, and our reading of the thesis\n");
    let _ = writeln!(
        o,
        "- **The gas** (thesis ch. 6): k × k balls of radius {RADIUS} on a grid, each with a \
         uniformly random direction and a speed uniform in [0, {SPEED_MAX}), a square table with \
         four cushions and no pockets, from time 0 to {}: the built-in scenario `gas`, seeds 1 \
         to {}.\n\
         - **Table size.** The thesis says the table is 50 × (balls per side) long, e.g. 300 × \
         300 for 36 balls; but radius-30 balls 50 apart overlap on that starting grid, and its \
         own table 9 names a 600 × 600 table for the same 36 balls. We use side 100 · k (600 for \
         36 balls): the balls start 100 apart and do not overlap; speeds, radius and duration \
         are the thesis'.\n\
         - **Sector sizes as counts per side.** The thesis' tables 5, 9 and 10 agree with each \
         other only as sectors per side (36 balls: sizes 150/100/50 are 4, 9, 36 sectors, i.e. \
         9, 4, 1 balls per sector), so a thesis size S means b = (S/50)² balls per sector and \
         k = √(N / b) sectors per side on our table. We run every b in {{16, 9, 4, 1, 1/4}} \
         that gives a whole k, which adds two cells the thesis left empty (36 balls on 12×12, \
         64 balls on 2×2).\n\
         - **Engines.** No sectors: the objects engine of thesis fig. 3, with exact, zero-delay \
         NewVelocity messages. Sectored: the engine of fig. 14 on a k × k grid. Both execute \
         exactly the physical events of the event-list engine: {}.\n\
         - **What is counted.** The total is the thesis' six types: VelocityChange, \
         NewVelocity, SectorDeparture, SectorEntry, Cancel and Collision, each counted when \
         sent, whether later cancelled or not. Our sectored engine also sends \
         VelocityInitialization (thesis 5.4, at start) and CollisionConfirm (ours: before a \
         ball–ball collision acts, the two balls confirm they are still on the trajectories it \
         was predicted for); table 8 shows them, the totals leave them out, as the thesis' \
         totals leave out initialization and statistics.\n\
         - **Means, not single runs.** The thesis reports one run per cell (tables 5, 6, 8-10) \
         and six seeds only for its non-sectored cases (table 7); we report means and standard \
         deviations over {} seeds everywhere, and compare settings seed by seed (paired): a \
         difference within two standard errors is called a tie.\n",
        p.until,
        p.seeds,
        if data.mismatches.is_empty() {
            format!(
                "all {} runs ended in the event-list engine's final state, bit for bit",
                data.runs.len()
            )
        } else {
            format!(
                "**{} runs did not end in the event-list engine's final state** (see \
                 results.json)",
                data.mismatches.len()
            )
        },
        p.seeds,
    );

    let _ = writeln!(o, "## Headline: table 5\n");
    o.push_str(&strip_title(&tables[0].1));
    let _ = writeln!(o);

    let _ = writeln!(o, "## What agrees with the thesis\n");
    let header = strings(&[
        "Balls",
        "Thesis best",
        "Ours best",
        "Thesis best sectored",
        "Ours best sectored (balls/sector)",
        "Best sectored vs no sectors",
    ]);
    let mut rows = Vec::new();
    for f in fs {
        let with_ties = |s: Setting, ties: &[Paired]| {
            let mut t = s.label();
            if !ties.is_empty() {
                let names: Vec<String> = ties.iter().map(|p| p.b.label()).collect();
                let _ = write!(t, " (tied with {})", names.join(", "));
            }
            t
        };
        rows.push(vec![
            f.balls.to_string(),
            opt_label(f.thesis_best),
            with_ties(f.best(), &f.ties_best),
            opt_label(f.thesis_best_sectored),
            match f.best_sectored {
                Some(b) => {
                    let mut t = format!("{} ({})", b.label(), bps_text(bps_of(f.balls, b)));
                    let ties: Vec<String> = f
                        .ties_sectored
                        .iter()
                        .map(|p| format!("{} ({})", p.b.label(), bps_text(bps_of(f.balls, p.b))))
                        .collect();
                    if !ties.is_empty() {
                        let _ = write!(t, ", tied with {}", join(&ties, "and"));
                    }
                    t
                }
                None => "-".into(),
            },
            match (f.sectored_vs_none, f.mean(Setting::NoSectors)) {
                (Some(pv), Some(none)) => format!(
                    "{:+.0}% ({}; fewer in {}/{} seeds)",
                    100.0 * pv.diff_mean / none,
                    if pv.tie() {
                        "tie"
                    } else if pv.diff_mean < 0.0 {
                        "sectors pay"
                    } else {
                        "sectors cost"
                    },
                    pv.a_wins,
                    pv.seeds
                ),
                _ => "-".into(),
            },
        ]);
    }
    o.push_str(&md_table(&header, &rows));
    let _ = writeln!(o);

    // The optimum.
    let mut same = Vec::new();
    let mut noise = Vec::new();
    let mut differ = Vec::new();
    for f in fs {
        let (Some(th), Some(b)) = (f.thesis_best_sectored, f.best_sectored) else {
            continue;
        };
        if th == b {
            same.push(format!("{} balls ({})", f.balls, b.label()));
        } else if f.among_best_sectored(th) {
            let pv = f.ties_sectored.iter().find(|p| p.b == th).copied();
            noise.push(format!(
                "{} balls, where our best, {} ({} per sector), ties the thesis' {} ({} per \
                 sector): {}",
                f.balls,
                b.label(),
                bps_text(bps_of(f.balls, b)),
                th.label(),
                bps_text(bps_of(f.balls, th)),
                pv.map_or(String::new(), |p| p.text())
            ));
        } else {
            differ.push(format!(
                "{} balls (ours {}, thesis {})",
                f.balls,
                b.label(),
                th.label()
            ));
        }
    }
    let _ = writeln!(
        o,
        "- **Optimum sector count.** Our best sectored grid is the thesis' for {}{}{}. The \
         thesis found the fewest messages at four balls per sector for every number of balls \
         (table 10).",
        if same.is_empty() {
            "no number of balls".to_string()
        } else {
            join(&same, "and")
        },
        if noise.is_empty() {
            String::new()
        } else {
            format!(
                "; it agrees within our seed-to-seed noise for {}",
                noise.join("; ")
            )
        },
        if differ.is_empty() {
            String::new()
        } else {
            format!("; it differs for {}", join(&differ, "and"))
        },
    );
    // Where sectors pay.
    let verdict = |f: &Finding| -> Option<i32> {
        let pv = f.sectored_vs_none?;
        Some(if pv.tie() {
            0
        } else if pv.diff_mean < 0.0 {
            1
        } else {
            -1
        })
    };
    let by = |v: i32| -> Vec<String> {
        fs.iter()
            .filter(|f| verdict(f) == Some(v))
            .map(|f| f.balls.to_string())
            .collect()
    };
    let (pay, tie, cost) = (by(1), by(0), by(-1));
    let first_pay = fs.iter().find(|f| verdict(f) == Some(1)).map(|f| f.balls);
    let keeps = first_pay.is_some_and(|n0| {
        fs.iter()
            .filter(|f| f.balls >= n0)
            .all(|f| verdict(f) == Some(1))
    });
    let _ =
        writeln!(
        o,
        "- **Where sectors start to pay.** The thesis: \"for simulations with 36 or more balls \
         the sectored simulation employs fewer messages\"; with 4 and 16 balls no sectors was \
         cheapest. Ours, best sectored grid against no sectors, seed by seed: sectors pay for \
         {} balls{}{}.{}",
        if pay.is_empty() { "no number of".into() } else { join(&pay, "and") },
        if cost.is_empty() {
            String::new()
        } else {
            format!(", cost messages for {} balls", join(&cost, "and"))
        },
        if tie.is_empty() {
            String::new()
        } else {
            format!(", and tie for {} balls", join(&tie, "and"))
        },
        match first_pay {
            Some(36) if keeps => " The crossover is where the thesis found it.".to_string(),
            Some(n0) if keeps => format!(
                " Sectors start to pay at {n0} balls and keep paying above; the thesis' \
                 crossover is 36."
            ),
            Some(n0) => format!(" Sectors first pay at {n0} balls."),
            None => String::new(),
        }
    );
    // Eight balls per sector.
    let mut lines = Vec::new();
    for f in fs {
        let Some(b) = f.best_sectored else { continue };
        if bps_of(f.balls, b).is_some_and(|x| x > 8.0) {
            let others: Vec<String> = f
                .ties_sectored
                .iter()
                .map(|p| {
                    format!(
                        "{} ({} per sector; {})",
                        p.b.label(),
                        bps_text(bps_of(f.balls, p.b)),
                        p.text()
                    )
                })
                .collect();
            lines.push(format!(
                "{} balls: the best grid, {}, has {} balls per sector{}",
                f.balls,
                b.label(),
                bps_text(bps_of(f.balls, b)),
                if others.is_empty() {
                    ", and no grid ties it: this contradicts the bound".to_string()
                } else {
                    format!(
                        ", but ties {}: the bound is borderline there",
                        join(&others, "and")
                    )
                }
            ));
        }
        for pv in &f.over_eight {
            lines.push(format!(
                "{} balls on {} ({} per sector): {} than the best grid, {} ({:+.0}, fewer in \
                 {}/{} seeds)",
                f.balls,
                pv.a.label(),
                bps_text(bps_of(f.balls, pv.a)),
                if pv.tie() {
                    "no more (a tie)"
                } else if pv.diff_mean > 0.0 {
                    "more"
                } else {
                    "fewer"
                },
                b.label(),
                pv.diff_mean,
                pv.a_wins,
                pv.seeds
            ));
        }
    }
    let _ = writeln!(
        o,
        "- **Eight balls per sector as an upper bound** (ch. 7). The thesis: with 16 and 36 \
         balls a grid of more than 8 balls per sector sends more than the minimum. Ours: {}.",
        if lines.is_empty() {
            "no grid of this run has more than 8 balls per sector".to_string()
        } else {
            lines.join("; ")
        }
    );
    // Non-sectored counts against table 7.
    let t7: Vec<String> = fs
        .iter()
        .filter_map(|f| {
            let t = thesis::TABLE7.iter().find(|r| r.0 == f.balls)?.1;
            let ours = data.total(f.balls, Setting::NoSectors)?;
            let z = (ours.mean - t[0]) / t[1];
            Some(format!(
                "{} balls: {:.0} against {:.0} ± {:.0} ({:+.1} thesis SD)",
                f.balls, ours.mean, t[0], t[1], z
            ))
        })
        .collect();
    if !t7.is_empty() {
        let within = fs.iter().all(|f| {
            let Some(t) = thesis::TABLE7.iter().find(|r| r.0 == f.balls) else {
                return true;
            };
            data.total(f.balls, Setting::NoSectors)
                .is_some_and(|o| (o.mean - t.1[0]).abs() <= t.1[1])
        });
        let _ = writeln!(
            o,
            "- **Non-sectored message counts** {} the thesis' six-seed means (table 7): {}.",
            if within {
                "lie within one standard deviation of"
            } else {
                "are compared with"
            },
            t7.join("; ")
        );
    }
    // Message mix.
    let n = data.focus();
    let ks: Vec<Setting> = settings(n)
        .into_iter()
        .filter(|s| s.per_side().is_some())
        .collect();
    if ks.len() >= 2 {
        let series = |name: &str| -> Vec<f64> {
            ks.iter()
                .filter_map(|&s| data.stat(n, s, |r| r.msg(name)).map(|t| t.mean))
                .collect()
        };
        let checks = [
            ("SectorEntry", true),
            ("SectorDeparture", true),
            ("VelocityChange", true),
            ("Collision", false),
        ];
        let ok: Vec<String> = checks
            .iter()
            .filter(|(t, up)| monotone(&series(t), *up))
            .map(|(t, up)| format!("{t} {}", if *up { "grows" } else { "falls" }))
            .collect();
        let bad: Vec<String> = checks
            .iter()
            .filter(|(t, up)| !monotone(&series(t), *up))
            .map(|(t, up)| {
                format!(
                    "{t} does not steadily {} ({})",
                    if *up { "grow" } else { "fall" },
                    series(t)
                        .iter()
                        .map(|x| format!("{x:.0}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })
            .collect();
        let _ = writeln!(
            o,
            "- **Message mix** (table 8, {n} balls). The thesis expects and finds that as the \
             sectors shrink SectorEntry, SectorDeparture and VelocityChange grow and Collision \
             falls. Ours, from {} to {}: {}{}.",
            ks[0].label(),
            ks[ks.len() - 1].label(),
            if ok.is_empty() {
                "none of these holds".into()
            } else {
                join(&ok, "and")
            },
            if bad.is_empty() {
                String::new()
            } else {
                format!("; but {}", join(&bad, "and"))
            }
        );
        let sheets = spreadsheet(data, n);
        if !sheets.is_empty() {
            let r4: Vec<f64> = sheets
                .iter()
                .map(|s| s.estimated_new_velocity / s.actual_new_velocity)
                .collect();
            let ra: Vec<f64> = sheets
                .iter()
                .map(|s| s.estimated_new_velocity_our_adjacency / s.actual_new_velocity)
                .collect();
            let range = |xs: &[f64]| {
                format!(
                    "{:.2} to {:.2}",
                    xs.iter().copied().fold(f64::INFINITY, f64::min),
                    xs.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                )
            };
            let _ = writeln!(
                o,
                "- **The NewVelocity estimator** of 6.1 (table 9): the thesis' estimates were \
                 within 20% of its counts. On our runs, estimate / actual is {} with the \
                 thesis' 4 adjacent objects, and {} with the number of sectors our sectors \
                 actually relay to (those sharing an edge or a corner){}.",
                range(&r4),
                range(&ra),
                occupied_text(n, &sheets)
            );
        }
    }
    let _ = writeln!(o);

    let _ = writeln!(o, "## What does not agree, and why\n");
    // Ratios ours / thesis by balls per sector.
    let mut ratio_rows = Vec::new();
    let mut sectored_ratios: Vec<(usize, Setting, f64)> = Vec::new();
    for &n in &data.plan.balls {
        let th = thesis::row(&thesis::TABLE5, n);
        let mut row = vec![n.to_string()];
        let mut any = false;
        for (c, t) in th.iter().enumerate() {
            let cell =
                setting_at(n, c).and_then(|s| Some((s, data.total(n, s)?.mean / t.value()?)));
            row.push(match cell {
                Some((s, r)) => {
                    any = true;
                    if s != Setting::NoSectors {
                        sectored_ratios.push((n, s, r));
                    }
                    format!("{r:.2}")
                }
                None => "-".into(),
            });
        }
        if any {
            ratio_rows.push(row);
        }
    }
    if !ratio_rows.is_empty() {
        let mut header = vec!["Balls".to_string(), "No sectors".to_string()];
        header.extend(
            BPS_LABEL
                .iter()
                .zip(SIZE_LABEL)
                .map(|(b, s)| format!("{s} ({b}/sector)")),
        );
        let _ = writeln!(
            o,
            "Our mean total over the thesis' single run, cell by cell (table 5):\n"
        );
        o.push_str(&md_table(&header, &ratio_rows));
        let _ = writeln!(o);
        let _ = writeln!(o, "{}", ratio_text(data, &sectored_ratios));
    }
    let _ = writeln!(o, "{}", wall_text(data, fs));
    let model_lines: Vec<String> = fs
        .iter()
        .filter_map(|f| {
            Some(format!(
                "{} balls: eq. 2 best {} (optimum {:.1} per side), measured best {}; measured / \
                 eq. 2 = {:.1} there and {:.1} on the finest grid",
                f.balls,
                f.model_best_grid?.label(),
                f.model_optimal_per_side,
                f.best_sectored?.label(),
                f.model_ratio_best?,
                f.model_ratio_finest?
            ))
        })
        .collect();
    let finer = fs.iter().all(|f| {
        match (
            f.model_best_grid.and_then(Setting::per_side),
            f.best_sectored.and_then(Setting::per_side),
        ) {
            (Some(a), Some(b)) => a >= b,
            _ => true,
        }
    });
    let _ =
        writeln!(
        o,
        "- **The model of chapter 7 against our counts** (figures 17-18, right panels). With our \
         measured V T and m, eq. 2 {} and predicts {} messages than we count: {}. The model \
         treats balls as points; ours are 60 wide, wider than the 50-wide sectors of the finest \
         grids, so a ball occupies several sectors at once (table 9) and each velocity change and \
         crossing costs several times what the model counts; and it assumes Collision = 2m, \
         with no collision scheduled and then cancelled, while {}. The thesis' c ≈ 3 in 6.1 \
         corrects for the ball size; eqs. 1-2 do not.\n",
        if finer {
            "puts the optimum on a grid as fine as or finer than the measured one"
        } else {
            "puts the optimum on a different grid from the measured one for some N"
        },
        if fs.iter().all(|f| f.model_ratio_best.is_none_or(|r| r > 1.05)) {
            "fewer"
        } else {
            "as many or fewer"
        },
        model_lines.join("; "),
        scheduled_text(data),
    );
    let _ = writeln!(o, "## Inconsistencies in the thesis we had to resolve\n");
    let _ = writeln!(
        o,
        "- The text (6.0) says the fewest messages for 16 and 36 balls came at sector size 200; \
         its table 5 has them at size 100 (16 balls: 5366 against 7677 at 200; 36 balls: 11492, \
         with no run at 200), and table 10 and chapter 7 say four balls per sector, which is \
         size 100. We follow the tables.\n\
         - Table 10 prints 5368 for the 16-ball, 4-per-sector run that table 5 prints as 5366.\n\
         - Table 9's \"Number of collisions = 278\" gives the sectors occupied by a ball as \
         VelocityChange / 278 = 1.23; we take it to count ball velocity changes (two per \
         ball–ball collision, one per bounce), the quantity that makes that ratio meaningful.\n\
         - Table 9's estimated sector entries divide the free path, in the units of a 600-wide \
         table, by sector sizes in the units of a 300-wide one (see table 9 below).\n\
         - The table size: see the setup above.\n"
    );
    for (name, text) in tables.iter().skip(1) {
        let _ = writeln!(o, "## {}\n", title_of(text).unwrap_or(name));
        o.push_str(&strip_title(text));
        let _ = writeln!(o);
    }
    let _ = writeln!(o, "## Figures 17 and 18: the model of chapter 7\n");
    if figures {
        let _ = writeln!(
            o,
            "![Figure 17](fig17.svg)\n\n{FIG17_CAPTION}\n\n![Figure 18](fig18.svg)\n\n\
             {FIG18_CAPTION}\n"
        );
    } else {
        let _ = writeln!(
            o,
            "(The figures could not be drawn: see the error `poolsim experiment` printed.)\n"
        );
    }
    let _ = writeln!(
        o,
        "**How the measurements are put beside the model.** The thesis' curves are for V T = 1 \
         and m = 0 or m = N, on a unit-square table. Our gas has V T = {} table widths (mean free \
         path per ball over the table side) and m = {} velocity changes. Moving our points onto \
         the thesis' curves would take the model itself to convert them, and the model is what \
         is under test; so the left panels reproduce the thesis' figures as they are, and the \
         right panels put the model, evaluated at the parameters we measured, against our \
         counts in absolute units, with the sector width as the fraction s = 1/k of the table \
         side. No scaling is applied anywhere.",
        join(
            &fs.iter()
                .map(|f| format!("{:.3} ({} balls)", f.model_vt, f.balls))
                .collect::<Vec<_>>(),
            "and"
        ),
        join(
            &fs.iter()
                .map(|f| format!("{:.0}", f.model_m))
                .collect::<Vec<_>>(),
            "and"
        ),
    );
    o
}

/// What the cell-by-cell ratios of our totals to the thesis' say.
fn ratio_text(data: &Data, ratios: &[(usize, Setting, f64)]) -> String {
    let mut o = String::new();
    // Non-sectored: against the single runs and against the thesis' own six-seed means.
    let none: Vec<String> = data
        .plan
        .balls
        .iter()
        .filter_map(|&n| {
            let single = thesis::row(&thesis::TABLE5, n)[0].value()?;
            let t7 = thesis::TABLE7.iter().find(|r| r.0 == n)?.1;
            Some(format!(
                "{n} balls: {single:.0} against {:.0} ± {:.0}, {:+.1} SD",
                t7[0],
                t7[1],
                (single - t7[0]) / t7[1]
            ))
        })
        .collect();
    if !none.is_empty() {
        let _ = writeln!(
            o,
            "- **Single runs against means.** The thesis' non-sectored runs of table 5 against \
             its own six-seed means and standard deviations of table 7: {}. Its single runs are \
             thus not typical of its own seeds, while our non-sectored means match table 7 \
             (above). Every thesis cell is one run, and our seed-to-seed coefficient of \
             variation is {} (table 7): a single run can be off by that much.",
            join(&none, "and"),
            cv_range(data)
        );
    }
    if ratios.is_empty() {
        return o;
    }
    let (lo_n, lo_s, lo) = ratios
        .iter()
        .copied()
        .min_by(|a, b| a.2.total_cmp(&b.2))
        .expect("not empty");
    let (hi_n, hi_s, hi) = ratios
        .iter()
        .copied()
        .max_by(|a, b| a.2.total_cmp(&b.2))
        .expect("not empty");
    let per_n: Vec<(usize, f64)> = data
        .plan
        .balls
        .iter()
        .filter_map(|&n| {
            let rs: Vec<f64> = ratios.iter().filter(|r| r.0 == n).map(|r| r.2).collect();
            (!rs.is_empty()).then(|| (n, rs.iter().sum::<f64>() / rs.len() as f64))
        })
        .collect();
    let grows = monotone(&per_n.iter().map(|x| x.1).collect::<Vec<_>>(), true);
    let _ = write!(
        o,
        "- **Sectored totals.** Ours / thesis runs from {lo:.2} ({lo_n} balls on {}, {} per \
         sector) to {hi:.2} ({hi_n} balls on {}, {} per sector); by number of balls the mean \
         ratio is {}{}. Two differences of mechanism, which we have not isolated, plausibly pull in \
         opposite directions. (1) The thesis delays NewVelocity by a small d and makes \
         collisions found in the past immediate (4.4, 5.3), so its balls reschedule and cancel \
         more, and its simultaneous collisions lose updates (tables 2-3), which changes the \
         trajectories themselves. Our NewVelocity has \
         zero delay in an exact lexicographic virtual time, so nothing is lost and every run \
         executes exactly the event-list engine's collisions. We would expect this to save \
         most where a sector holds many balls and each velocity change reaches many of them. (2) Our sectors relay a \
         velocity change to every sector sharing an edge or a corner (up to 8), the thesis' to 4 \
         adjacent objects; that adds NewVelocity messages on fine grids (table 8), and the more \
         sectors, the more of them are interior ones with 8 neighbours (table 9).",
        lo_s.label(),
        bps_text(bps_of(lo_n, lo_s)),
        hi_s.label(),
        bps_text(bps_of(hi_n, hi_s)),
        join(
            &per_n
                .iter()
                .map(|(n, r)| format!("{r:.2} ({n} balls)"))
                .collect::<Vec<_>>(),
            "and"
        ),
        if grows && per_n.len() > 1 {
            ", growing with the number of balls"
        } else {
            ""
        }
    );
    o
}

/// The wall-time bullet: our rates per message against the Dolphin's, and the speed of the best
/// sectored grid against no sectors.
fn wall_text(data: &Data, fs: &[Finding]) -> String {
    let rate = |n: usize, s: Setting| -> Option<f64> {
        Some(data.total(n, s)?.mean / data.stat(n, s, |r| r.wall_seconds)?.mean)
    };
    let ours: Vec<f64> = data
        .plan
        .balls
        .iter()
        .flat_map(|&n| settings(n).into_iter().map(move |s| (n, s)))
        .filter_map(|(n, s)| rate(n, s))
        .collect();
    let dolphin: Vec<f64> = thesis::TABLE5
        .iter()
        .zip(thesis::TABLE6.iter())
        .flat_map(|((_, m), (_, t))| {
            m.iter()
                .zip(t.iter())
                .filter_map(|(a, b)| Some(a.value()? / b.value()?))
                .collect::<Vec<_>>()
        })
        .collect();
    let lo = |xs: &[f64]| xs.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = |xs: &[f64]| xs.iter().copied().fold(0.0, f64::max);
    let mut o = format!(
        "- **Wall time** (table 6) is not comparable. The Dolphin processed {:.2} to {:.2} \
         messages a second (a factor {:.1} between cells, slowest where it paged: its \
         non-sectored 36-ball run took 38575 s); we process {:.1} to {:.1} million a second (a \
         factor {:.1} between cells), and a whole run takes milliseconds. Our times are of one \
         shared machine and vary between invocations by tens of percent; the message counts do \
         not vary at all.",
        lo(&dolphin),
        hi(&dolphin),
        hi(&dolphin) / lo(&dolphin),
        lo(&ours) / 1e6,
        hi(&ours) / 1e6,
        hi(&ours) / lo(&ours),
    );
    if let Some(f) = fs.iter().find(|f| f.balls == 36) {
        if let (Some(b), Some(none_w), Some(none_m)) = (
            f.best_sectored,
            data.stat(36, Setting::NoSectors, |r| r.wall_seconds),
            f.mean(Setting::NoSectors),
        ) {
            if let (Some(bw), Some(bm)) = (data.stat(36, b, |r| r.wall_seconds), f.mean(b)) {
                let _ = write!(
                    o,
                    " The thesis' sectored 36-ball run was nearly 3 times as fast as its \
                     non-sectored one while sending only 30% fewer messages, because the \
                     non-sectored run paged. Ours, on {}, sends {:.0}% fewer messages and runs \
                     {}: no paging here{}.",
                    b.label(),
                    100.0 * (1.0 - bm / none_m),
                    match none_w.mean / bw.mean {
                        r if (0.9..=1.1).contains(&r) => "about as fast".to_string(),
                        r if r > 1.0 => format!("{r:.1} times as fast"),
                        r => format!("in {:.1} times the time", 1.0 / r),
                    },
                    if bm / bw.mean < none_m / none_w.mean {
                        ", and a sectored message costs more than a plain one"
                    } else {
                        ""
                    }
                );
            }
        }
    }
    o.push_str(
        "\n- **Memory overflow.** The thesis could not run 64 balls without sectors, nor on the \
         smallest sectors (\"mo\"); we run both.",
    );
    o
}

/// How our sectors occupied per ball compare with table 9's, for 36 balls.
fn occupied_text(n: usize, sheets: &[Sheet]) -> String {
    if n != 36 {
        return String::new();
    }
    let pairs: Vec<(f64, f64)> = sheets
        .iter()
        .filter_map(|s| {
            let c = match s.sectors_per_side {
                2 => 0,
                3 => 1,
                6 => 2,
                _ => return None,
            };
            Some((s.sectors_occupied, thesis::TABLE9[c][2]))
        })
        .collect();
    if pairs.is_empty() {
        return String::new();
    }
    let worst = pairs
        .iter()
        .map(|(a, b)| (a / b - 1.0).abs())
        .fold(0.0, f64::max);
    format!(
        "; the sectors occupied per ball, ours against the thesis', are {}: within {:.0}%",
        pairs
            .iter()
            .map(|(a, b)| format!("{a:.2} against {b}"))
            .collect::<Vec<_>>()
            .join(", "),
        100.0 * worst
    )
}

/// How many collisions were scheduled (Collision / 2) against how many happened, no sectors.
fn scheduled_text(data: &Data) -> String {
    let n = data.focus();
    let Some(c) = data.stat(n, Setting::NoSectors, |r| r.msg("Collision")) else {
        return "ours are mostly cancelled".into();
    };
    let happened = data
        .phys_stat(n, |p| (p.ball_ball + p.ball_cushion) as f64)
        .mean;
    format!(
        "with {n} balls and no sectors ours schedule {:.0} collisions (Collision / 2) of which \
         {happened:.0} happen",
        c.mean / 2.0
    )
}

/// `4% to 34%`: the range of coefficients of variation of the totals over all cells.
fn cv_range(data: &Data) -> String {
    let cvs: Vec<f64> = data
        .cells
        .keys()
        .filter_map(|&(n, s)| {
            let t = data.total(n, s)?;
            Some(t.sd? / t.mean)
        })
        .collect();
    if cvs.is_empty() {
        return "unknown with one seed".into();
    }
    format!(
        "{:.0}% to {:.0}%",
        100.0 * cvs.iter().copied().fold(f64::INFINITY, f64::min),
        100.0 * cvs.iter().copied().fold(0.0, f64::max)
    )
}

const FIG17_CAPTION: &str = "**Figure 17. Messages as a function of sector size, no collisions \
(eq. 1).** Left, the thesis' figure: F(s) = (N V T / s)(N s² + 8) on the unit-square table with \
V T = 1, for N = 8, 16, 32 and 64; dots mark each minimum and the dashed curve joins the minima \
(s = 2√2 / √N, eight balls per sector). Right, in absolute units: for each of our numbers of \
balls, eq. 1 at our measured V T (mean free path per ball over the table side) as a line, and \
our measured mean totals at sector width s = 1/k (k sectors per side) as dots with ± 1 SD bars; \
the dashed horizontal lines are the non-sectored engine's means. Eq. 1 leaves out collisions, so \
it lies below every measurement.";

const FIG18_CAPTION: &str = "**Figure 18. Messages as a function of sector size, with \
collisions (eq. 2).** Left, the thesis' figure: F(s) = (N V T / s)(N s² + 8) + m (N s² + 15) \
with V T = 1 and m = N, for N = 8, 16, 32 and 64; dots mark each minimum, the dashed curve joins \
the minima and the dotted one marks eight balls per sector, the minima of figure 17. Right, in \
absolute units: eq. 2 at our measured V T and m (ball velocity changes: two per ball–ball \
collision, one per bounce) for each of our numbers of balls as a line, against our measured mean \
totals at s = 1/k (dots, ± 1 SD), and the non-sectored means (dashed horizontal lines).";

fn title_of(text: &str) -> Option<&str> {
    text.lines().next()?.strip_prefix("# ")
}

fn strip_title(text: &str) -> String {
    match text.split_once('\n') {
        Some((first, rest)) if first.starts_with("# ") => rest.trim_start().to_string(),
        _ => text.to_string(),
    }
}

// ---------------------------------------------------------------------------------------------
// Figures.

/// Font files read so far, by path: plotters keeps `&'static` font data, so each file is read
/// and leaked once per process.
static FONTS: Mutex<Vec<(PathBuf, &'static [u8])>> = Mutex::new(Vec::new());

/// Reads the font at `path` and registers it as plotters' `sans-serif` (the family every text
/// of the figures uses). A missing or unreadable font is an error naming the file and the
/// Debian package, never a panic.
pub(crate) fn register_font(path: &Path) -> Result<(), String> {
    let mut fonts = FONTS.lock().unwrap_or_else(|e| e.into_inner());
    let bytes = match fonts.iter().find(|f| f.0 == path) {
        Some(f) => f.1,
        None => {
            let bytes = std::fs::read(path).map_err(|e| {
                format!(
                    "cannot read the font {} for the figures: {e} (install Debian's \
                     fonts-dejavu-core, or pass --font FILE with a TrueType font)",
                    path.display()
                )
            })?;
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            fonts.push((path.to_path_buf(), bytes));
            bytes
        }
    };
    for family in ["sans-serif", "serif", "monospace"] {
        plotters::style::register_font(family, FontStyle::Normal, bytes).map_err(|_| {
            format!(
                "the font {} is not a TrueType or OpenType font",
                path.display()
            )
        })?;
    }
    Ok(())
}

/// What one figure's right panel shows for one number of balls.
struct Measured {
    n: usize,
    vt: f64,
    m: f64,
    /// `(s = 1/k, mean, sd)` per sectored setting.
    points: Vec<(f64, f64, f64)>,
    none: Option<f64>,
}

fn measured(data: &Data) -> Vec<Measured> {
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

fn err<E: std::fmt::Display>(what: &str) -> impl Fn(E) -> String + '_ {
    move |e| format!("drawing {what}: {e}")
}

/// Draws figure 17 (`eq == 1`) or 18 (`eq == 2`) on any plotters backend.
fn draw_figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    eq: u32,
    ms: &[Measured],
    name: &str,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let e = err(name);
    root.fill(&WHITE).map_err(&e)?;
    let title = if eq == 1 {
        "Figure 17. Messages as a function of sector size: no collisions (eq. 1)"
    } else {
        "Figure 18. Messages as a function of sector size: with collisions (eq. 2)"
    };
    let root = root.titled(title, ("sans-serif", 22)).map_err(&e)?;
    let (left, right) = root.split_horizontally(W / 2);
    let thesis_params = |n: f64| ModelParams {
        balls: n,
        speed: 1.0,
        time: 1.0,
        changes: if eq == 1 { 0.0 } else { n },
    };
    // Left: the thesis' figure.
    let s_lo = 0.05;
    let curves: Vec<(f64, Vec<(f64, f64)>)> = THESIS_N
        .iter()
        .map(|&n| {
            let p = thesis_params(n);
            let pts = (0..=190)
                .map(|i| {
                    let s = s_lo + (1.0 - s_lo) * i as f64 / 190.0;
                    (s, analytic::messages(&p, s))
                })
                .collect();
            (n, pts)
        })
        .collect();
    let y_max = curves
        .iter()
        .flat_map(|c| c.1.iter().map(|p| p.1))
        .fold(0.0, f64::max)
        * 1.05;
    let mut chart = ChartBuilder::on(&left)
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
    for (n, pts) in &curves {
        let c = color_of(*n as usize);
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(&e)?
            .label(format!("N = {n}"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    }
    // The curve of minima: continuous in N, from the smallest curve's to the largest's.
    let minima = |eqn: u32| -> Vec<(f64, f64)> {
        (0..=100)
            .map(|i| {
                let n = 8.0 * (8.0f64).powf(i as f64 / 100.0);
                let mut p = thesis_params(n);
                if eqn == 1 {
                    p.changes = 0.0;
                }
                let s = analytic::optimal_sector(&p);
                (s, analytic::messages(&thesis_params(n), s))
            })
            .collect()
    };
    chart
        .draw_series(DashedLineSeries::new(
            minima(eq),
            8,
            5,
            BLACK.stroke_width(1),
        ))
        .map_err(&e)?
        .label("minima")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    if eq == 2 {
        let eight: Vec<(f64, f64)> = (0..=100)
            .map(|i| {
                let n = 8.0 * (8.0f64).powf(i as f64 / 100.0);
                let s = (8.0 / n).sqrt();
                (s, analytic::messages(&thesis_params(n), s))
            })
            .collect();
        chart
            .draw_series(DashedLineSeries::new(eight, 2, 4, BLACK.stroke_width(1)))
            .map_err(&e)?
            .label("8 balls/sector")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.5)));
    }
    for (n, _) in &curves {
        let s = analytic::optimal_sector(&thesis_params(*n));
        let f = analytic::messages(&thesis_params(*n), s);
        chart
            .draw_series(std::iter::once(Circle::new(
                (s, f),
                4,
                color_of(*n as usize).filled(),
            )))
            .map_err(&e)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(&e)?;

    // Right: our measurements against the model at our parameters, absolute, log-log.
    let model = |m: &Measured| ModelParams {
        balls: m.n as f64,
        speed: m.vt,
        time: 1.0,
        changes: if eq == 1 { 0.0 } else { m.m },
    };
    let s_min = ms
        .iter()
        .flat_map(|m| m.points.iter().map(|p| p.0))
        .fold(0.25, f64::min)
        * 0.8;
    let mut lo = f64::INFINITY;
    let mut hi: f64 = 1.0;
    let model_curves: Vec<(usize, Vec<(f64, f64)>)> = ms
        .iter()
        .filter(|m| m.vt > 0.0)
        .map(|m| {
            let p = model(m);
            let pts: Vec<(f64, f64)> = (0..=120)
                .map(|i| {
                    let s = s_min * (1.0 / s_min).powf(i as f64 / 120.0);
                    (s, analytic::messages(&p, s))
                })
                .collect();
            (m.n, pts)
        })
        .collect();
    for (_, pts) in &model_curves {
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
    let mut ks: Vec<u32> = ms
        .iter()
        .flat_map(|m| m.points.iter().map(|p| (1.0 / p.0).round() as u32))
        .collect();
    ks.sort_unstable();
    ks.dedup();
    let ticks: Vec<f64> = ks.iter().map(|&k| 1.0 / k as f64).collect();
    let mut chart = ChartBuilder::on(&right)
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
            (s_min..1.1f64).log_scale().with_key_points(ticks),
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
        let c = color_of(m.n);
        if let Some((_, pts)) = model_curves.iter().find(|x| x.0 == m.n) {
            chart
                .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
                .map_err(&e)?
                .label(format!(
                    "N = {} (V T = {:.2}, m = {:.0})",
                    m.n,
                    m.vt,
                    if eq == 1 { 0.0 } else { m.m }
                ))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
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
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(&e)?;
    root.present().map_err(&e)?;
    Ok(())
}

/// Writes `figNN.svg` and `figNN.png` for equation `eq`.
fn write_figure(dir: &Path, eq: u32, ms: &[Measured]) -> Result<(), String> {
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

/// Encodes an RGB buffer of `w` × `h` pixels as a PNG file.
pub(crate) fn write_png(path: &Path, buf: &[u8], w: u32, h: u32) -> Result<(), String> {
    let mut png_bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut png_bytes, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Best);
        enc.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
        let mut w = enc
            .write_header()
            .map_err(|e| format!("encoding {}: {e}", path.display()))?;
        w.write_image_data(buf)
            .map_err(|e| format!("encoding {}: {e}", path.display()))?;
    }
    write(path, &png_bytes)
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), String> {
    std::fs::write(path, bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

// ---------------------------------------------------------------------------------------------

/// The raw numbers and the thesis' tables, for `results.json`.
fn results_json(data: &Data, fs: &[Finding]) -> Value {
    let mut aggregates = Vec::new();
    for &n in &data.plan.balls {
        for s in settings(n) {
            let mut by_type = serde_json::Map::new();
            let mut names: Vec<String> = data
                .cell(n, s)
                .first()
                .map(|r| r.messages.keys().cloned().collect())
                .unwrap_or_default();
            names.sort();
            for name in names {
                let st = data.stat(n, s, |r| r.msg(&name));
                by_type.insert(name, json!(st));
            }
            aggregates.push(json!({
                "balls": n,
                "setting": s.name(),
                "sectors_per_side": s.per_side(),
                "balls_per_sector": s.per_side().map(|k| n as f64 / (k * k) as f64),
                "thesis_size": (column(n, s) > 0).then(|| SIZE_LABEL[column(n, s) - 1]),
                "messages": by_type,
                "wall_seconds": data.stat(n, s, |r| r.wall_seconds),
            }));
        }
    }
    let cells = |r: &[T]| -> Vec<Value> { r.iter().map(|c| c.json()).collect() };
    let by_balls = |t: &[(usize, Vec<Value>)]| -> Value {
        t.iter()
            .map(|(n, r)| json!({ "balls": n, "cells": r }))
            .collect()
    };
    let t5: Vec<(usize, Vec<Value>)> = thesis::TABLE5.iter().map(|(n, r)| (*n, cells(r))).collect();
    let t6: Vec<(usize, Vec<Value>)> = thesis::TABLE6.iter().map(|(n, r)| (*n, cells(r))).collect();
    let t10: Vec<(usize, Vec<Value>)> = thesis::TABLE10
        .iter()
        .map(|(n, r)| (*n, cells(r)))
        .collect();
    let t7: Vec<Value> = thesis::TABLE7
        .iter()
        .map(|(n, r)| {
            json!({
                "balls": n,
                "messages_mean": r[0],
                "messages_sd": r[1],
                "seconds_mean": r[2],
                "seconds_sd": r[3],
            })
        })
        .collect();
    let t8: Vec<Value> = thesis::TABLE8
        .iter()
        .map(|(t, r)| json!({ "type": t, "cells": cells(r) }))
        .collect();
    let (free_path, collisions, table_side) = thesis::TABLE9_PARAMS;
    let n = data.focus();
    json!({
        "experiment": "thesis",
        "source": "Goldberg 1984, Object-Oriented Simulation of Pool Ball Motion, ch. 6-7",
        "plan": data.plan,
        "scenario": {
            "name": "gas",
            "radius": RADIUS,
            "speed_max": SPEED_MAX,
            "table_side": "100 * sqrt(balls)",
            "until": data.plan.until,
        },
        "columns": {
            "balls_per_sector": BPS_LABEL,
            "thesis_sector_size": SIZE_LABEL,
        },
        "wall_seconds_total": data.wall_total,
        "digests_agree": data.mismatches.is_empty(),
        "digest_mismatches": data.mismatches,
        "runs": data.runs,
        "physics": data.physics,
        "aggregates": aggregates,
        "table9": { "balls": n, "columns": spreadsheet(data, n) },
        "findings": fs,
        "thesis": {
            "table5": by_balls(&t5),
            "table6": by_balls(&t6),
            "table7": t7,
            "table8": t8,
            "table9": thesis::TABLE9,
            "table9_params": {
                "free_path": free_path,
                "collisions": collisions,
                "table_side": table_side,
            },
            "table10": by_balls(&t10),
        },
    })
}

/// Runs `poolsim experiment`: every run of the plan, then the tables, `results.json` and the
/// report, then the figures. Errors are one line for the user (bad arguments, a failed run, an
/// unwritable directory, a missing font); files written before an error stay.
pub fn run(args: &ExperimentOptions, progress: &mut dyn FnMut(Progress)) -> Result<(), String> {
    if args.which == Which::Reversal {
        if let Some(flag) = [
            ("--seeds", args.seeds.is_some()),
            ("--balls", args.balls.is_some()),
        ]
        .iter()
        .find_map(|&(flag, given)| given.then_some(flag))
        {
            return Err(format!(
                "{flag}: only the thesis experiment takes it (the reversal study has its own \
                 scenarios and quitting times)"
            ));
        }
        let font = args
            .font
            .clone()
            .unwrap_or_else(|| PathBuf::from(DEFAULT_FONT));
        return crate::reversal_study::run(&args.out, &font, args.quick);
    }
    let plan = Plan::from_options(args)?;
    let dir = &args.out;
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let data = measure(&plan, progress)?;
    let tables = vec![
        ("table5", table5(&data)),
        ("table6", table6(&data)),
        ("table7", table7(&data)),
        ("table8", table8(&data)),
        ("table9", table9(&data)),
        ("table10", table10(&data)),
    ];
    for (name, text) in &tables {
        write(&dir.join(format!("{name}.md")), text.as_bytes())?;
    }
    let fs = findings(&data);
    let results = serde_json::to_string_pretty(&results_json(&data, &fs))
        .map_err(|e| format!("results.json: {e}"))?;
    write(&dir.join("results.json"), results.as_bytes())?;
    let font = args
        .font
        .clone()
        .unwrap_or_else(|| PathBuf::from(DEFAULT_FONT));
    let figures = register_font(&font).and_then(|()| {
        let ms = measured(&data);
        write_figure(dir, 1, &ms)?;
        write_figure(dir, 2, &ms)
    });
    write(
        &dir.join("report.md"),
        report(&data, &tables, &fs, figures.is_ok()).as_bytes(),
    )?;
    figures?;
    if !data.mismatches.is_empty() {
        return Err(format!(
            "{} runs did not end in the event-list engine's final state; first: {}",
            data.mismatches.len(),
            data.mismatches[0]
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
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
        };
        let p = Plan::from_options(&a).unwrap();
        assert_eq!((p.balls.clone(), p.seeds), (vec![4, 16, 36, 64], 6));
        a.quick = true;
        let p = Plan::from_options(&a).unwrap();
        assert_eq!((p.balls, p.seeds, p.until), (vec![4, 16], 2, 4.0));
        a.balls = Some(vec![10]);
        assert!(Plan::from_options(&a).unwrap_err().contains("--balls"));
        a.balls = None;
        a.seeds = Some(0);
        assert!(Plan::from_options(&a).unwrap_err().contains("--seeds"));
    }
}
