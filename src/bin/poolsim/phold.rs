//! `poolsim phold`: PHOLD, the standard PDES benchmark, on the kernel.

use crate::common::*;
use pdes_kernel::phold::{PholdError, PholdExecutor};
use pdes_kernel::time_warp::ObjectMap;

/// `poolsim phold --engine`: which executor runs PHOLD.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PholdEngine {
    /// The sequential kernel.
    Objects,
    /// Time Warp.
    TimeWarp,
    /// The conservative executor: windows of the lookahead (needs --lookahead above 0).
    Conservative,
}

/// `poolsim phold --map`: how Time Warp places the objects on its workers.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PholdMap {
    /// A contiguous block of objects per worker: each partition on one worker.
    Block,
    /// Objects dealt out in turn: every partition spread over every worker.
    RoundRobin,
}

/// Arguments of `poolsim phold`.
#[derive(clap::Args, Clone, Debug)]
pub struct PholdArgs {
    /// Number of objects.
    #[arg(long, default_value_t = 1024)]
    pub objects: u32,
    /// Messages each object starts with.
    #[arg(long = "events-per-object", default_value_t = 16)]
    pub events_per_object: u32,
    /// Probability that a message goes to another partition.
    #[arg(long, default_value_t = 0.1)]
    pub remote: f64,
    /// Partitions; objects are split in equal blocks (default: the Time Warp workers of all
    /// ranks, or 2 on the sequential kernel).
    #[arg(long)]
    pub partitions: Option<u32>,
    /// objects (the sequential kernel), time-warp, or conservative (threads of one process).
    #[arg(long, value_enum, default_value = "objects")]
    pub engine: PholdEngine,
    /// Workers of Time Warp (per rank) or of the conservative executor (default: this
    /// machine's cores).
    #[arg(long)]
    pub workers: Option<usize>,
    /// Time Warp and conservative: how objects are placed on the workers (block keeps each partition on one
    /// worker; round-robin spreads them, so most messages cross between workers).
    #[arg(long, value_enum)]
    pub map: Option<PholdMap>,
    /// Time Warp: run every batch as undoable (no final batches), to measure optimism alone.
    #[arg(long = "tw-pure")]
    pub tw_pure: bool,
    /// Time Warp: batches a worker runs between looks at its inbox (default 128; 64 with
    /// --tw-pure).
    #[arg(long = "tw-burst")]
    pub tw_burst: Option<u32>,
    /// End time.
    #[arg(long, default_value_t = 100.0)]
    pub end: f64,
    /// Minimum delay of a message.
    #[arg(long, default_value_t = 0.1)]
    pub lookahead: f64,
    /// Mean of the exponential part of the delay.
    #[arg(long, default_value_t = 1.0)]
    pub mean: f64,
    /// Seed of the objects' random streams.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// Time Warp: write one JSON line per GVT round to this file: the round, GVT, seconds
    /// since the start, and each worker's committed, processed and rolled-back batches, final
    /// batches, rollbacks and remote messages so far.
    #[arg(long)]
    pub stats: Option<std::path::PathBuf>,
    /// Time Warp and conservative: run the same model on the sequential kernel first (rank 0
    /// alone under MPI) and report the speed-up over it.
    #[arg(long)]
    pub baseline: bool,
}

/// The most PHOLD events in flight (objects times events per object): about a gigabyte.
pub const MAX_PHOLD_EVENTS: u64 = 10_000_000;

/// Refuses values PHOLD cannot run with.
fn check_values(a: &PholdArgs) -> Result<(), Failure> {
    let positive = |flag: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(usage(format!("{flag}: must be a positive number, got {v}")))
        }
    };
    positive("--end", a.end)?;
    positive("--mean", a.mean)?;
    if !(a.lookahead.is_finite() && a.lookahead >= 0.0) {
        return Err(usage(format!(
            "--lookahead: must not be negative, got {}",
            a.lookahead
        )));
    }
    if !(0.0..=1.0).contains(&a.remote) {
        return Err(usage(format!(
            "--remote: must lie in [0, 1], got {}",
            a.remote
        )));
    }
    Ok(())
}

/// Runs `poolsim phold` and prints its report (on rank 0 under MPI).
pub fn phold(a: &PholdArgs) -> Result<(), Failure> {
    use pdes_kernel::phold::{run, run_with};
    check_values(a)?;
    let executor = executor(a)?;
    if !matches!(executor, PholdExecutor::Sequential) {
        poolsim::memory::transparent_huge_pages(false);
    }
    #[cfg(feature = "mpi")]
    let _mpi = if matches!(executor, PholdExecutor::TimeWarp(..)) {
        start_mpi()?
    } else {
        None
    };
    let partitions = a.partitions.unwrap_or(match &executor {
        PholdExecutor::Sequential => 2,
        PholdExecutor::TimeWarp(c, _) => pdes_kernel::time_warp::threads::total_workers(c) as u32,
        PholdExecutor::Conservative(c, _) => c.workers as u32,
    });
    check_sizes(a, partitions)?;
    let stats = match &a.stats {
        Some(p) if pdes_kernel::time_warp::threads::collects_results() => Some(stats_file(p)?),
        _ => None,
    };
    let cfg = config(a, partitions);
    let rank = pdes_kernel::time_warp::threads::place().0;
    // rank 0 runs the baseline alone; the other ranks wait for it in Time Warp's first round
    let baseline = if a.baseline && rank == 0 {
        Some(run(cfg.clone(), a.end, None).map_err(|e| internal(e.to_string()))?)
    } else {
        None
    };
    let mut report = run_with(cfg, a.end, executor).map_err(|e| match e {
        PholdError::Refused(r) => usage(format!("--engine conservative: {r}")),
        e => internal(e.to_string()),
    })?;
    if rank != 0 {
        return Ok(());
    }
    if let Some(b) = &baseline {
        report = report.against(b);
    }
    if let (Some(file), Some(p)) = (stats, &a.stats) {
        write_rounds(file, &report.rounds).map_err(|e| {
            usage(format!(
                "{}: writing the round statistics failed: {e}",
                p.display()
            ))
        })?;
    }
    print_report(&report, a.json);
    Ok(())
}

/// The executor the flags ask for, with its settings; refuses flags its executor does not take.
fn executor(a: &PholdArgs) -> Result<PholdExecutor, Failure> {
    use pdes_kernel::conservative::ConservativeConfig;
    let map = match a.map {
        Some(PholdMap::RoundRobin) => ObjectMap::RoundRobin,
        Some(PholdMap::Block) | None => ObjectMap::Block,
    };
    let time_warp_only = [
        ("--tw-pure", a.tw_pure),
        ("--tw-burst", a.tw_burst.is_some()),
        ("--stats", a.stats.is_some()),
    ];
    let parallel_only = [
        ("--workers", a.workers.is_some()),
        ("--map", a.map.is_some()),
        ("--baseline", a.baseline),
    ];
    let refuse = |flags: &[(&str, bool)], who: &str| match flags.iter().find(|f| f.1) {
        Some((flag, _)) => Err(usage(format!("{flag}: only {who} takes it"))),
        None => Ok(()),
    };
    match a.engine {
        PholdEngine::TimeWarp => {
            let cfg = pdes_kernel::time_warp::TwConfig {
                final_batches: !a.tw_pure,
                burst: burst(a.tw_burst)?,
                record_rounds: a.stats.is_some(),
                ..tw_workers(a.workers)?
            };
            Ok(PholdExecutor::TimeWarp(cfg, map))
        }
        PholdEngine::Conservative => {
            refuse(&time_warp_only, "the time-warp engine")?;
            let tw = tw_workers(a.workers)?;
            let cfg = ConservativeConfig {
                workers: tw.workers,
                chaos: tw.chaos,
            };
            Ok(PholdExecutor::Conservative(cfg, map))
        }
        PholdEngine::Objects => {
            refuse(&time_warp_only, "the time-warp engine")?;
            refuse(
                &parallel_only,
                "a parallel engine (time-warp, conservative)",
            )?;
            Ok(PholdExecutor::Sequential)
        }
    }
}

/// Refuses object, event and partition counts PHOLD cannot run with.
fn check_sizes(a: &PholdArgs, partitions: u32) -> Result<(), Failure> {
    if u64::from(a.objects) * u64::from(a.events_per_object) > MAX_PHOLD_EVENTS {
        return Err(usage(format!(
            "--objects x --events-per-object: at most {MAX_PHOLD_EVENTS} events in flight, got \
             {} x {}",
            a.objects, a.events_per_object
        )));
    }
    if a.objects == 0 {
        return Err(usage("--objects: must be at least 1, got 0"));
    }
    if partitions == 0 || partitions > a.objects {
        return Err(usage(match a.partitions {
            Some(p) => format!(
                "--partitions: must be from 1 to --objects ({}), got {p}",
                a.objects
            ),
            None => format!(
                "--objects: {} is fewer than the {partitions} partitions of the workers; give \
                 more objects or --partitions",
                a.objects
            ),
        }));
    }
    Ok(())
}

/// The model the flags describe.
fn config(a: &PholdArgs, partitions: u32) -> pdes_kernel::phold::PholdConfig {
    pdes_kernel::phold::PholdConfig {
        objects: a.objects,
        events_per_object: a.events_per_object,
        remote: a.remote,
        partitions,
        lookahead: a.lookahead,
        mean: a.mean,
        seed: a.seed,
    }
}

/// The file of `--stats`, created before the run, so that a path that cannot be written fails
/// at once.
fn stats_file(p: &std::path::Path) -> Result<std::fs::File, Failure> {
    std::fs::File::create(p).map_err(|e| {
        usage(format!(
            "{}: cannot create the round statistics file: {e}",
            p.display()
        ))
    })
}

/// Writes one JSON line per GVT round.
fn write_rounds(
    file: std::fs::File,
    rounds: &[pdes_kernel::time_warp::RoundRecord],
) -> std::io::Result<()> {
    use std::io::Write;
    let mut out = std::io::BufWriter::new(file);
    for r in rounds {
        serde_json::to_writer(&mut out, r)?;
        out.write_all(b"\n")?;
    }
    out.flush()
}

/// Prints a PHOLD report as text, or as one JSON object.
fn print_report(report: &pdes_kernel::phold::PholdReport, json: bool) {
    if json {
        println!(
            "{}",
            serde_json::to_string(&report).expect("a report serializes")
        );
    } else {
        println!(
            "PHOLD on {}, {} objects x {} events, remote {}, {} partitions, end {}: {} committed \
             events in {:.3} s, {:.0} events/s ({:.2} M per core; ROSS's published record: \
             {:.2} M per core), digest {}",
            report.engine,
            report.objects,
            report.events_per_object,
            report.remote,
            report.partitions,
            report.end,
            report.committed,
            report.wall_seconds,
            report.events_per_second,
            report.events_per_second_per_core / 1e6,
            pdes_kernel::phold::ROSS_EVENTS_PER_SECOND_PER_CORE / 1e6,
            report.final_state_digest
        );
        if let Some(t) = &report.time_warp {
            println!(
                "time warp: {} workers on {} ranks, processed {}, committed {}, efficiency {:.3}, \
                 {} rollbacks, {} GVT rounds",
                t.workers,
                t.ranks,
                t.processed,
                t.committed,
                t.efficiency(),
                t.rollbacks,
                t.gvt_rounds
            );
        }
        if let Some(c) = &report.conservative {
            println!(
                "conservative: {} workers, {} windows of {}, {:.0} batches per window, {} \
                 messages between workers",
                c.workers,
                c.windows,
                c.lookahead,
                c.batches.iter().sum::<u64>() as f64 / c.windows.max(1) as f64,
                c.remote_messages
            );
        }
        if let (Some(x), Some(seq)) = (report.speedup, report.sequential_wall_seconds) {
            println!(
                "speed-up: {x:.2}x the sequential kernel, which took {seq:.3} s for the same \
                 model in this invocation"
            );
        }
    }
}
