//! The measurements of `poolsim bench`: physical events per second and nanoseconds per event of the event-list engine
//! on the thesis gas, over ball counts and area fractions, with the machine's description; then
//! the objects engine's cost over ball counts, Time Warp against the sequential objects engine
//! on the sectored gas, and PHOLD's committed events per second.
//!
//! Setup (generating the gas and predicting every ball's first event) is timed apart from the
//! event loop, so the figures are the steady cost of an event. Each configuration runs a fixed
//! number of events on one thread.

use crate::engine::event_list::{EventList, Options};
use crate::engine::{Ignore, RunError};
use crate::run::SectorLayoutError;
use crate::scenario::builtin::{self, Params};
use crate::scenario::Invalid;
use pdes_kernel::phold::{PholdConfig, PholdError, PholdReport, ROSS_EVENTS_PER_SECOND_PER_CORE};
use std::time::Instant;

/// What `poolsim bench` measures.
#[derive(Clone, Debug)]
pub struct BenchOptions {
    /// Ball counts of the event-list rows.
    pub balls: Vec<usize>,
    /// Area fractions of the event-list rows.
    pub area_fractions: Vec<f64>,
    /// Physical events measured per event-list row (at least 5 per ball are run).
    pub events: u64,
    /// Ball counts for the objects engine (non-sectored: its cost per event grows with N).
    pub objects_balls: Vec<usize>,
    /// Ball counts for the sectored objects engine (`--sectors auto`, area fraction 0.3).
    pub sectored_balls: Vec<usize>,
    /// Ball counts for Time Warp (on each of `tw_workers`) against the sequential objects
    /// engine: whole runs of the sectored gas until `tw_until`, set-up included.
    pub tw_balls: Vec<usize>,
    /// Ball counts for the regions engine (on each of `tw_workers`, four regions per worker,
    /// one on one worker) against the event list: whole runs of the gas at area fraction 0.5
    /// until `tw_until`, set-up included.
    pub regions_balls: Vec<usize>,
    /// Worker counts of the Time Warp, regions and PHOLD rows.
    pub tw_workers: Vec<usize>,
    /// Simulated time of the Time Warp runs.
    pub tw_until: f64,
    /// Pure Time Warp in the Time Warp and PHOLD runs: no batch runs as final.
    pub tw_pure: bool,
    /// PHOLD objects (16 messages each, remote 0.1, lookahead 0.1; as many partitions as the
    /// most workers of `tw_workers`, at least 2, in every row).
    pub phold_objects: u32,
    /// Grid cell width in ball diameters.
    pub cell_diameters: f64,
    /// Runs of each configuration; the fastest is reported.
    pub repeat: u32,
}

/// Everything `poolsim bench` measured (its `--json` object).
#[derive(Clone, Debug, serde::Serialize)]
pub struct BenchReport {
    /// This machine ([`machine`]).
    pub machine: String,
    /// The engine of `rows`: `event-list`.
    pub engine: &'static str,
    /// The event-list rows.
    pub rows: Vec<BenchRow>,
    /// How their cost per event grows with the ball count.
    pub growth: Vec<Growth>,
    /// The plain objects engine's rows.
    pub objects: Vec<ObjectsRow>,
    /// The sectored objects engine's rows.
    pub sectored: Vec<ObjectsRow>,
    /// Time Warp against the sequential objects engine.
    pub time_warp: Vec<TwRow>,
    /// The regions engine against the event list (workers 0).
    pub regions: Vec<TwRow>,
    /// PHOLD on the sequential kernel, then on each worker count.
    pub phold: Vec<PholdReport>,
    /// ROSS's published PHOLD record per core, for comparison.
    pub phold_ross_events_per_second_per_core: f64,
}

/// The parts of a bench, in the order they run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// The event-list rows.
    EventList,
    /// The plain and sectored objects engine rows.
    Objects,
    /// The Time Warp rows: a program that runs the objects engines without transparent huge
    /// pages ([`crate::memory`]) turns them off here.
    TimeWarp,
    /// The regions engine's rows.
    Regions,
    /// PHOLD on the kernel.
    Phold,
}

/// One result as soon as it is measured, for a caller that shows them as they come, and the
/// start of each part, for a caller that sets the process up for it.
#[derive(Clone, Copy, Debug)]
pub enum Measured<'a> {
    /// A part of the bench starts.
    Starting(Part),
    /// An event-list row.
    Row(&'a BenchRow),
    /// The event-list rows' growth, after the last of them.
    Growth(&'a [Growth]),
    /// A plain objects engine row.
    Objects(&'a ObjectsRow),
    /// A sectored objects engine row.
    Sectored(&'a ObjectsRow),
    /// A Time Warp row.
    TimeWarp(&'a TwRow),
    /// A regions engine row (workers 0: the event list).
    Regions(&'a TwRow),
    /// A PHOLD run.
    Phold(&'a PholdReport),
}

/// Why `poolsim bench` stopped: a bad option (the message names its flag), or a run that failed
/// or disagreed with the sequential one.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// An area fraction outside (0, 1).
    #[error("--area-fractions: each must lie in (0, 1), got {0}")]
    AreaFraction(f64),
    /// No repeats.
    #[error("--repeat: must be at least 1")]
    Repeat,
    /// A ball count of 0.
    #[error("{flag}: each ball count must be at least 1")]
    NoBalls {
        /// The flag of the list.
        flag: &'static str,
    },
    /// No events to measure.
    #[error("--events: must be at least 1")]
    Events,
    /// No worker counts, or a count of 0.
    #[error("--tw-workers: each worker count must be at least 1")]
    Workers,
    /// Fewer PHOLD objects than partitions.
    #[error(
        "--phold-objects: PHOLD runs on {partitions} partitions here, so it needs at least \
         {partitions} objects, got {objects}"
    )]
    PholdObjects {
        /// The partitions PHOLD runs on.
        partitions: usize,
        /// The objects asked for.
        objects: u32,
    },
    /// A grid cell narrower than a ball.
    #[error("--cell-diameters: a cell must be at least one ball diameter wide, got {0:?}")]
    CellDiameters(f64),
    /// A simulated time of the Time Warp runs that is not positive.
    #[error("--tw-until: must be a positive simulated time, got {0}")]
    TwUntil(f64),
    /// The gas could not be built.
    #[error("{}: {}", .0.field, .0.message)]
    Scenario(Invalid),
    /// The sector layout could not be built.
    #[error(transparent)]
    Layout(#[from] SectorLayoutError),
    /// A run of the pool failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A PHOLD run failed.
    #[error(transparent)]
    Phold(#[from] PholdError),
    /// PHOLD on a parallel executor ended in another state than on the sequential kernel.
    #[error(
        "bench: PHOLD on {engine} with {workers} workers ended in state {digest}, on the \
         sequential kernel in {sequential}"
    )]
    PholdDigest {
        /// The executor.
        engine: &'static str,
        /// The workers (0: none).
        workers: usize,
        /// Its final state digest.
        digest: String,
        /// The sequential kernel's.
        sequential: String,
    },
    /// A parallel run (Time Warp, or the regions engine) ended in another state than its
    /// sequential baseline.
    #[error(
        "bench: the run on {workers} workers ended in state {digest}, the sequential baseline \
         in {sequential} ({balls} balls until {until})"
    )]
    TimeWarpDigest {
        /// The workers.
        workers: usize,
        /// Its final state digest.
        digest: String,
        /// The sequential engine's.
        sequential: String,
        /// Balls of the gas.
        balls: usize,
        /// Simulated time of the run.
        until: f64,
    },
}

/// The fastest of `n` (at least one) runs of `f`, by the seconds `secs` reads off each result.
fn fastest<T, E>(
    n: u32,
    secs: impl Fn(&T) -> f64,
    mut f: impl FnMut() -> Result<T, E>,
) -> Result<T, E> {
    let mut best = f()?;
    for _ in 1..n {
        let r = f()?;
        if secs(&r) < secs(&best) {
            best = r;
        }
    }
    Ok(best)
}

/// Each executor's fastest row over runs of the same rows (one run: the sequential engine, then
/// Time Warp on each worker count, taken in turn), with its speed-up against the fastest
/// sequential row: the VM's speed drifts within a run of rows too, so a whole run's rows are no
/// fairer a comparison than each one's best. Beside it, the median over the runs of the
/// speed-up within each run, which shows how far the best one stands from the typical one.
fn fastest_rows(runs: Vec<Vec<TwRow>>) -> Vec<TwRow> {
    let mut within: Vec<Vec<f64>> = Vec::new();
    let mut best: Vec<TwRow> = Vec::new();
    for run in runs {
        let seq = run.first().map_or(0.0, |r| r.seconds);
        for (k, r) in run.into_iter().enumerate() {
            if within.len() <= k {
                within.push(Vec::new());
            }
            within[k].push(seq / r.seconds);
            match best.get_mut(k) {
                Some(b) if r.seconds < b.seconds => *b = r,
                Some(_) => {}
                None => best.push(r),
            }
        }
    }
    let seq = best.first().map_or(0.0, |r| r.seconds);
    for (r, ratios) in best.iter_mut().zip(&mut within) {
        r.speedup = seq / r.seconds;
        ratios.sort_by(f64::total_cmp);
        let n = ratios.len();
        r.median_speedup = 0.5 * (ratios[(n - 1) / 2] + ratios[n / 2]);
    }
    best
}

/// One measured configuration.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BenchRow {
    /// Balls.
    pub balls: usize,
    /// Area fraction.
    pub area_fraction: f64,
    /// Physical events run.
    pub events: u64,
    /// Setup seconds (generation and first predictions).
    pub setup_seconds: f64,
    /// Event-loop seconds.
    pub seconds: f64,
    /// Events per second in the loop.
    pub events_per_second: f64,
    /// Nanoseconds per event in the loop.
    pub ns_per_event: f64,
    /// Resident memory of the process after the run (MiB).
    pub rss_mib: f64,
}

/// How the event-list engine's cost per event grows with the ball count at one area fraction:
/// the cost at the largest count measured over the cost at the smallest.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Growth {
    /// Area fraction.
    pub area_fraction: f64,
    /// The smallest ball count measured.
    pub from_balls: usize,
    /// The largest ball count measured.
    pub to_balls: usize,
    /// Nanoseconds per event at `to_balls` over nanoseconds per event at `from_balls`.
    pub ratio: f64,
}

/// The growth of the cost per event for every area fraction measured at two ball counts or more.
pub fn growth(rows: &[BenchRow]) -> Vec<Growth> {
    let mut phis: Vec<f64> = rows.iter().map(|r| r.area_fraction).collect();
    phis.sort_by(f64::total_cmp);
    phis.dedup();
    phis.iter()
        .filter_map(|&phi| {
            let at: Vec<&BenchRow> = rows.iter().filter(|r| r.area_fraction == phi).collect();
            let lo = at.iter().min_by_key(|r| r.balls)?;
            let hi = at.iter().max_by_key(|r| r.balls)?;
            (hi.balls > lo.balls).then(|| Growth {
                area_fraction: phi,
                from_balls: lo.balls,
                to_balls: hi.balls,
                ratio: hi.ns_per_event / lo.ns_per_event,
            })
        })
        .collect()
}

/// A line describing this machine: processor model, logical cores, OS.
pub fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown processor".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    format!(
        "{cpu}, {cores} logical cores, {} {}",
        std::env::consts::OS,
        std::env::consts::ARCH
    )
}

/// Resident set size of this process in MiB (Linux), or 0 where unknown.
pub fn rss_mib() -> f64 {
    proc_status_mib("VmRSS:")
}

/// The largest resident set size this process has had, in MiB (Linux), or 0 where unknown.
pub fn peak_rss_mib() -> f64 {
    proc_status_mib("VmHWM:")
}

/// A size field of `/proc/self/status` in MiB.
fn proc_status_mib(field: &str) -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with(field))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}

/// The thesis gas (seed 1) of `balls` balls, at `area_fraction` where given.
fn thesis_gas(
    balls: usize,
    area_fraction: Option<f64>,
) -> Result<crate::scenario::Scenario, BenchError> {
    let params = Params {
        balls: Some(balls),
        seed: Some(1),
        area_fraction,
        ..Params::default()
    };
    builtin::build("gas", &params).map_err(BenchError::Scenario)
}

/// Measures one configuration.
pub fn measure(
    balls: usize,
    area_fraction: f64,
    events: u64,
    cell_diameters: f64,
) -> Result<BenchRow, BenchError> {
    let start = Instant::now();
    let (n_balls, scenario) = (balls, thesis_gas(balls, Some(area_fraction))?);
    let opts = Options {
        cell_diameters,
        ..Options::default()
    };
    let mut engine = EventList::new(&scenario, opts);
    let setup = start.elapsed().as_secs_f64();
    let target = events.max(5 * n_balls as u64);
    let start = Instant::now();
    let out = engine.run_for(f64::INFINITY, target, &mut Ignore)?;
    let secs = start.elapsed().as_secs_f64();
    let n = out.events.total();
    Ok(BenchRow {
        balls: n_balls,
        area_fraction,
        events: n,
        setup_seconds: setup,
        seconds: secs,
        events_per_second: n as f64 / secs,
        ns_per_event: secs * 1e9 / n.max(1) as f64,
        rss_mib: rss_mib(),
    })
}

/// Checks the options; errors name the command line's flag.
fn validate(a: &BenchOptions) -> Result<usize, BenchError> {
    for &phi in &a.area_fractions {
        if !(phi > 0.0 && phi < 1.0) {
            return Err(BenchError::AreaFraction(phi));
        }
    }
    if a.repeat == 0 {
        return Err(BenchError::Repeat);
    }
    for (flag, counts) in [
        ("--balls", &a.balls),
        ("--objects-balls", &a.objects_balls),
        ("--sectored-balls", &a.sectored_balls),
        ("--tw-balls", &a.tw_balls),
        ("--regions-balls", &a.regions_balls),
    ] {
        if counts.contains(&0) {
            return Err(BenchError::NoBalls { flag });
        }
    }
    if a.events == 0 {
        return Err(BenchError::Events);
    }
    if a.tw_workers.is_empty() || a.tw_workers.contains(&0) {
        return Err(BenchError::Workers);
    }
    let partitions = a.tw_workers.iter().copied().max().unwrap_or(2).max(2);
    if (a.phold_objects as usize) < partitions {
        return Err(BenchError::PholdObjects {
            partitions,
            objects: a.phold_objects,
        });
    }
    if !(a.cell_diameters.is_finite() && a.cell_diameters >= 1.0) {
        return Err(BenchError::CellDiameters(a.cell_diameters));
    }
    if !(a.tw_until.is_finite() && a.tw_until > 0.0) {
        return Err(BenchError::TwUntil(a.tw_until));
    }
    Ok(partitions)
}

/// Measures everything `a` asks for, handing each result to `each` as soon as it is measured.
pub fn run(a: &BenchOptions, each: &mut dyn FnMut(Measured)) -> Result<BenchReport, BenchError> {
    let partitions = validate(a)?;
    each(Measured::Starting(Part::EventList));
    let mut rows = Vec::new();
    for &n in &a.balls {
        for &phi in &a.area_fractions {
            let r = fastest(
                a.repeat,
                |r: &BenchRow| r.seconds,
                || measure(n, phi, a.events, a.cell_diameters),
            )?;
            each(Measured::Row(&r));
            rows.push(r);
        }
    }
    let growth = growth(&rows);
    each(Measured::Growth(&growth));
    each(Measured::Starting(Part::Objects));
    let objects_row = |n: usize, sectors: Option<crate::run::SectorChoice>| {
        fastest(
            a.repeat,
            |r: &ObjectsRow| r.seconds,
            || measure_objects(n, sectors),
        )
    };
    let mut objects = Vec::new();
    for &n in &a.objects_balls {
        let r = objects_row(n, None)?;
        each(Measured::Objects(&r));
        objects.push(r);
    }
    let mut sectored = Vec::new();
    for &n in &a.sectored_balls {
        let r = objects_row(n, Some(crate::run::SectorChoice::Auto))?;
        each(Measured::Sectored(&r));
        sectored.push(r);
    }
    // each ball count's repetitions, the fastest row of each worker count reported
    let mut parallel_rows =
        |balls: &[usize], part: Part, measure: MeasureParallel| -> Result<Vec<TwRow>, BenchError> {
            each(Measured::Starting(part));
            let mut rows = Vec::new();
            for &n in balls {
                let mut runs = Vec::new();
                for _ in 0..a.repeat.max(1) {
                    runs.push(measure(n, a.tw_until, a.tw_pure, &a.tw_workers)?);
                }
                for r in fastest_rows(runs) {
                    each(match part {
                        Part::Regions => Measured::Regions(&r),
                        _ => Measured::TimeWarp(&r),
                    });
                    rows.push(r);
                }
            }
            Ok(rows)
        };
    let time_warp = parallel_rows(&a.tw_balls, Part::TimeWarp, measure_time_warp)?;
    let regions = parallel_rows(&a.regions_balls, Part::Regions, measure_regions)?;
    each(Measured::Starting(Part::Phold));
    let phold = measure_phold(a, partitions as u32, each)?;
    Ok(BenchReport {
        machine: machine(),
        engine: "event-list",
        rows,
        growth,
        objects,
        sectored,
        time_warp,
        regions,
        phold,
        phold_ross_events_per_second_per_core: ROSS_EVENTS_PER_SECOND_PER_CORE,
    })
}

/// PHOLD on the sequential kernel, then under Time Warp and on the conservative executor on
/// each worker count, one model throughout; fails if a digest differs.
fn measure_phold(
    a: &BenchOptions,
    partitions: u32,
    each: &mut dyn FnMut(Measured),
) -> Result<Vec<PholdReport>, BenchError> {
    use pdes_kernel::conservative::ConservativeConfig;
    use pdes_kernel::phold::PholdExecutor;
    use pdes_kernel::time_warp::{ObjectMap, TwConfig};
    let phold_cfg = PholdConfig {
        objects: a.phold_objects,
        events_per_object: 16,
        remote: 0.1,
        partitions,
        lookahead: 0.1,
        mean: 1.0,
        seed: 1,
    };
    let time_warp = a.tw_workers.iter().map(|&w| {
        let cfg = TwConfig {
            workers: w,
            final_batches: !a.tw_pure,
            ..Default::default()
        };
        (w, PholdExecutor::TimeWarp(cfg, ObjectMap::Block))
    });
    let conservative = a.tw_workers.iter().map(|&w| {
        let cfg = ConservativeConfig {
            workers: w,
            chaos: None,
        };
        (w, PholdExecutor::Conservative(cfg, ObjectMap::Block))
    });
    let mut phold: Vec<PholdReport> = Vec::new();
    for (workers, executor) in std::iter::once((0, PholdExecutor::Sequential))
        .chain(time_warp)
        .chain(conservative)
    {
        let p = pdes_kernel::phold::run_with(phold_cfg.clone(), 20.0, executor)?;
        if let Some(first) = phold
            .first()
            .filter(|f| f.final_state_digest != p.final_state_digest)
        {
            return Err(BenchError::PholdDigest {
                engine: p.engine,
                workers,
                digest: p.final_state_digest,
                sequential: first.final_state_digest.clone(),
            });
        }
        let p = match phold.first() {
            Some(sequential) => p.against(sequential),
            None => p,
        };
        each(Measured::Phold(&p));
        phold.push(p);
    }
    Ok(phold)
}

/// One measured run of the objects engine.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ObjectsRow {
    /// Balls.
    pub balls: usize,
    /// Physical events.
    pub events: u64,
    /// Messages sent (the thesis' total: NewVelocity, Collision, Cancel).
    pub messages: u64,
    /// Wall seconds (set-up included for the plain engine; the measured window only for the
    /// sectored one).
    pub seconds: f64,
}

/// Simulated time the sectored bench runs before it measures: set-up, the first trajectories
/// (every ball's VelocityInitialization) and the transient after them.
pub const SECTORED_WARM_UP: f64 = 1.0;
/// Simulated time the sectored bench measures after the warm-up (about 1.7 events per ball).
pub const SECTORED_WINDOW: f64 = 2.0;

/// Runs the thesis gas (seed 1) on the objects engine: plain (thesis table, until 4, set-up
/// included), or sectored (area fraction 0.3: the steady state, the events and messages from
/// [`SECTORED_WARM_UP`] to the end of [`SECTORED_WINDOW`] only).
pub fn measure_objects(
    balls: usize,
    sectors: Option<crate::run::SectorChoice>,
) -> Result<ObjectsRow, BenchError> {
    let (n_balls, mut scenario) = (balls, thesis_gas(balls, sectors.map(|_| 0.3))?);
    let start = Instant::now();
    if let Some(choice) = sectors {
        scenario.until = SECTORED_WARM_UP + SECTORED_WINDOW;
        let layout = crate::run::sector_layout(&scenario, choice)?;
        let mut engine =
            crate::engine::objects::Objects::sectored(&scenario, layout, Default::default());
        let sent =
            |out: &crate::engine::Outcome| -> u64 { out.messages.iter().map(|(_, c)| c).sum() };
        let warm = engine.run(SECTORED_WARM_UP, &mut Ignore)?;
        let measured = Instant::now();
        let out = engine.run(scenario.until, &mut Ignore)?;
        return Ok(ObjectsRow {
            balls: n_balls,
            events: out.events.total(),
            messages: sent(&out) - sent(&warm),
            seconds: measured.elapsed().as_secs_f64(),
        });
    }
    let mut engine = crate::engine::objects::Objects::new(
        &scenario,
        crate::model::pool::NvDelay::Exact,
        Default::default(),
    );
    let out = engine.run(scenario.until, &mut Ignore)?;
    let seconds = start.elapsed().as_secs_f64();
    Ok(ObjectsRow {
        balls: n_balls,
        events: out.events.total(),
        messages: out.messages.iter().map(|(_, c)| c).sum(),
        seconds,
    })
}

/// One whole run of the sectored gas for `poolsim bench`'s Time Warp table.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TwRow {
    /// Balls.
    pub balls: usize,
    /// Simulated time run.
    pub until: f64,
    /// Time Warp workers (0: the sequential objects engine).
    pub workers: usize,
    /// Wall seconds, set-up included.
    pub seconds: f64,
    /// Of those, the set-up's: building the model and running the objects' `init`s.
    pub setup_seconds: f64,
    /// The sequential run's seconds over this run's.
    pub speedup: f64,
    /// Over repeated runs, the median of the speed-up within each run (the sequential engine
    /// and Time Warp taken in turn); `speedup` is then the fastest over the fastest.
    pub median_speedup: f64,
    /// Physical events.
    pub events: u64,
    /// Committed over processed batches (1 for the sequential engine).
    pub efficiency: f64,
    /// Messages that crossed workers over all messages.
    pub remote_fraction: f64,
    /// Batches run as final (without state saving) over batches committed; 0 for the
    /// sequential engine.
    pub final_fraction: f64,
    /// The final state digest (the same for every executor, or the bench fails).
    pub digest: String,
}

/// Runs the sectored gas (`--sectors auto`) of `balls` balls until `until` on the sequential
/// objects engine and under Time Warp on each of `workers` (`pure`: no batch run as final);
/// fails if any digest differs.
pub fn measure_time_warp(
    balls: usize,
    until: f64,
    pure: bool,
    workers: &[usize],
) -> Result<Vec<TwRow>, BenchError> {
    use crate::run::{EngineKind, FixedNews, SectorChoice};
    let engines = std::iter::once(0).chain(workers.iter().copied()).map(|w| {
        let engine = match w {
            0 => EngineKind::Sectored {
                sectors: SectorChoice::Auto,
                news: FixedNews::default(),
            },
            w => EngineKind::TimeWarp {
                tw: tw_config(w, pure),
                delay: crate::model::pool::NvDelay::Exact,
                sectors: Some(SectorChoice::Auto),
                news: FixedNews::default(),
            },
        };
        (w, engine)
    });
    timed_rows(&thesis_gas(balls, None)?, until, engines)
}

/// Measures a parallel engine against its sequential baseline: balls, simulated time, pure
/// Time Warp, worker counts; the baseline's row first.
type MeasureParallel = fn(usize, f64, bool, &[usize]) -> Result<Vec<TwRow>, BenchError>;

/// Runs the gas of `balls` balls at area fraction 0.5 until `until` on the event list and on
/// the regions engine on each of `workers` (four regions per worker, one on one worker;
/// `pure`: no batch run as final); fails if any digest differs.
pub fn measure_regions(
    balls: usize,
    until: f64,
    pure: bool,
    workers: &[usize],
) -> Result<Vec<TwRow>, BenchError> {
    use crate::run::EngineKind;
    let engines = std::iter::once(0).chain(workers.iter().copied()).map(|w| {
        let engine = match w {
            0 => EngineKind::EventList,
            1 => EngineKind::Regions { count: 1, tw: None },
            w => EngineKind::Regions {
                count: 4 * w as u32,
                tw: Some(tw_config(w, pure)),
            },
        };
        (w, engine)
    });
    timed_rows(&thesis_gas(balls, Some(0.5))?, until, engines)
}

/// Time Warp on `workers` workers (`pure`: no batch runs as final).
fn tw_config(workers: usize, pure: bool) -> pdes_kernel::time_warp::TwConfig {
    pdes_kernel::time_warp::TwConfig {
        workers,
        final_batches: !pure,
        ..Default::default()
    }
}

/// Runs `scenario` until `until` on each of `engines` (with its worker count, 0 for the
/// baseline, which comes first), whole runs; fails if a digest differs from the first's.
fn timed_rows(
    scenario: &crate::scenario::Scenario,
    until: f64,
    engines: impl Iterator<Item = (usize, crate::run::EngineKind)>,
) -> Result<Vec<TwRow>, BenchError> {
    use crate::run::{execute, RunConfig};
    let n_balls = scenario.balls.len();
    let mut rows: Vec<TwRow> = Vec::new();
    for (workers, engine) in engines {
        let cfg = RunConfig {
            engine,
            until,
            check: false,
            span: Default::default(),
            interrupt: None,
            checkpoint_every: None,
            thermostat: None,
        };
        let report = execute(scenario, &cfg, &mut Ignore)?;
        let s = &report.summary;
        let tw = s.time_warp.as_ref();
        let digest = s.final_state_digest.clone();
        if let Some(first) = rows.first() {
            if first.digest != digest {
                return Err(BenchError::TimeWarpDigest {
                    workers,
                    digest,
                    sequential: first.digest.clone(),
                    balls: n_balls,
                    until,
                });
            }
        }
        let seconds = report.wall_seconds;
        let speedup = rows.first().map_or(1.0, |r| r.seconds / seconds);
        rows.push(TwRow {
            balls: n_balls,
            until,
            workers,
            seconds,
            setup_seconds: report.setup_seconds,
            speedup,
            // one run: its own speed-up is the median
            median_speedup: speedup,
            events: report.outcome.events.total(),
            efficiency: tw.map_or(1.0, |tw| tw.efficiency),
            remote_fraction: tw.map_or(0.0, |tw| tw.remote_fraction),
            final_fraction: tw.filter(|tw| tw.stats.committed > 0).map_or(0.0, |tw| {
                tw.stats.final_batches as f64 / tw.stats.committed as f64
            }),
            digest,
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(balls: usize, area_fraction: f64, ns_per_event: f64) -> BenchRow {
        BenchRow {
            balls,
            area_fraction,
            events: 1,
            setup_seconds: 0.0,
            seconds: 0.0,
            events_per_second: 0.0,
            ns_per_event,
            rss_mib: 0.0,
        }
    }

    #[test]
    fn time_warp_rows_agree_with_the_sequential_run() {
        let rows = measure_time_warp(100, 0.5, false, &[1, 2, 3]).unwrap();
        assert_eq!(
            rows.iter().map(|r| r.workers).collect::<Vec<_>>(),
            [0, 1, 2, 3]
        );
        assert!(rows
            .iter()
            .all(|r| r.digest == rows[0].digest && r.balls == 100));
        assert!(rows
            .iter()
            .all(|r| r.events == rows[0].events && r.events > 0));
        assert_eq!(rows[0].speedup, 1.0);
        assert_eq!(rows[1].efficiency, 1.0);
        // alone, a worker runs every batch as final; pure, none
        assert_eq!((rows[0].final_fraction, rows[1].final_fraction), (0.0, 1.0));
        let pure = measure_time_warp(100, 0.5, true, &[1, 2]).unwrap();
        assert!(pure.iter().all(|r| r.final_fraction == 0.0));
        assert!(pure.iter().all(|r| r.digest == rows[0].digest));
    }

    #[test]
    fn each_executor_keeps_its_fastest_row() {
        let row = |workers: usize, seconds: f64| TwRow {
            balls: 10,
            until: 1.0,
            workers,
            seconds,
            setup_seconds: 0.0,
            speedup: 0.0,
            median_speedup: 0.0,
            events: 1,
            efficiency: 1.0,
            remote_fraction: 0.0,
            final_fraction: 0.0,
            digest: format!("{workers}"),
        };
        let runs = vec![
            vec![row(0, 4.0), row(1, 5.0), row(2, 3.0)],
            vec![row(0, 3.0), row(1, 6.0), row(2, 2.5)],
            vec![row(0, 4.0), row(1, 8.0), row(2, 2.0)],
        ];
        let best = fastest_rows(runs);
        let got: Vec<(usize, f64, f64)> = best
            .iter()
            .map(|r| (r.workers, r.seconds, r.speedup))
            .collect();
        assert_eq!(got, [(0, 3.0, 1.0), (1, 5.0, 0.6), (2, 2.0, 1.5)]);
        // within each run: 2 workers at 4/3, 1.2 and 2; 1 worker at 0.8, 0.5 and 0.5
        let medians: Vec<f64> = best.iter().map(|r| r.median_speedup).collect();
        assert_eq!(medians, [1.0, 0.5, 4.0 / 3.0]);
    }

    #[test]
    fn the_fastest_run_is_kept_and_errors_pass_through() {
        let mut times = [3.0, 1.0, 2.0].into_iter();
        let mut calls = 0;
        let best = fastest(
            3,
            |t: &f64| *t,
            || {
                calls += 1;
                Ok::<_, String>(times.next().unwrap())
            },
        );
        assert_eq!((best, calls), (Ok(1.0), 3));
        let failed = fastest(2, |t: &f64| *t, || Err::<f64, _>("no".to_string()));
        assert_eq!(failed, Err("no".to_string()));
    }

    #[test]
    fn growth_is_largest_over_smallest_count_per_area_fraction() {
        let rows = [
            row(1024, 0.3, 700.0),
            row(1024, 0.6, 650.0),
            row(10_000, 0.3, 800.0),
            row(1_000_000, 0.3, 2100.0),
            row(1_000_000, 0.6, 1300.0),
            row(500, 0.5, 600.0),
        ];
        let g = growth(&rows);
        assert_eq!(g.len(), 2, "0.5 was measured at one count only");
        assert_eq!(
            (g[0].area_fraction, g[0].from_balls, g[0].to_balls),
            (0.3, 1024, 1_000_000)
        );
        assert_eq!(g[0].ratio, 3.0);
        assert_eq!((g[1].area_fraction, g[1].ratio), (0.6, 2.0));
    }
}
