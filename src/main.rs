//! `poolsim`: the command line over the library. Parses arguments, loads the scenario, runs the
//! pipeline of `poolsim::run`, writes the outputs. Exit status: 0 done, 2 bad input or usage,
//! 1 internal failure or a failed `--check`.

use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use pdes_kernel::time_warp::TwConfig;
use poolsim::engine::{Event, Observer, RunError, World};
use poolsim::model::pool::NvDelay;
use poolsim::output::{FinalState, TraceWriter};
use poolsim::run::{execute, EngineKind, FixedNews, RunConfig, SectorChoice};
use poolsim::scenario::{self, builtin, Scenario};
use poolsim::summary::RunSummary;
use std::fs::File;
use std::io::{BufWriter, IsTerminal};
use std::path::PathBuf;
use std::process::ExitCode;

/// mimalloc: Time Warp's saved states and messages churn the heap; glibc's per-thread arenas
/// hand pages back and fault them in again (a fifth of a worker's time, measured).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// `mi_option_purge_delay`, entry 15 of `mi_option_t` in mimalloc.h (v2 and v3 alike; the Rust
/// bindings do not name it).
const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Lets mimalloc keep the memory it frees instead of handing it back to the system after 10 ms:
/// the engines free and reallocate large blocks all the time, and with transparent huge pages
/// every block handed back costs the kernel a 2 MiB page to zero when it is touched again (a
/// sixth of the sectored objects engine's time at 16k balls, measured with perf; a one-second
/// delay did not help). Resident memory then stays at its peak, which is what a run reports.
fn keep_freed_memory() {
    // SAFETY: sets one of mimalloc's global options, which mimalloc allows at any time.
    unsafe { libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, -1) }
}

#[derive(Parser)]
#[command(
    name = "poolsim",
    version,
    about = "Exact event-driven simulation of pool balls and hard disks (after Goldberg, UCLA 1984)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Parameters of generated scenarios.
#[derive(clap::Args, Clone, Debug, Default)]
struct GenArgs {
    /// Number of balls (gas: a square number).
    #[arg(long)]
    balls: Option<usize>,
    /// Random seed of generated scenarios.
    #[arg(long)]
    seed: Option<u64>,
    /// Fraction of the table's area covered by balls (gas).
    #[arg(long = "area-fraction")]
    area_fraction: Option<f64>,
    /// Ball radius (gas).
    #[arg(long)]
    radius: Option<f64>,
    /// Speeds are drawn uniform in [0, V) (gas, reversal).
    #[arg(long = "speed-max")]
    speed_max: Option<f64>,
}

impl GenArgs {
    fn params(&self) -> builtin::Params {
        builtin::Params {
            balls: self.balls,
            seed: self.seed,
            area_fraction: self.area_fraction,
            radius: self.radius,
            speed_max: self.speed_max,
        }
    }
}

#[derive(clap::Args, Clone, Debug)]
struct RunArgs {
    /// A built-in scenario name (see `poolsim scenarios`) or a TOML file.
    scenario: String,
    /// event-list, time-step, objects or time-warp.
    #[arg(long, default_value = "event-list")]
    engine: String,
    /// Sector layout: none, auto, N or NxM (sectored engines only).
    #[arg(long)]
    sectors: Option<String>,
    /// End time (default: the scenario's).
    #[arg(long, allow_negative_numbers = true)]
    until: Option<f64>,
    #[command(flatten)]
    gen: GenArgs,
    /// Write the trace (JSON Lines, one line per physical event) here.
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Write the final state (JSON) here.
    #[arg(long = "final-state")]
    final_state: Option<PathBuf>,
    /// Print the run summary as one JSON object on stdout, and nothing else there.
    #[arg(long)]
    json: bool,
    /// Check invariants at every event; a violation stops the run with exit status 1.
    #[arg(long)]
    check: bool,
    /// Worker threads (time-warp engine; default: this machine's cores).
    #[arg(long)]
    workers: Option<usize>,
    /// Time Warp's optimism window: no batch later than GVT plus this (simulation time).
    #[arg(long = "tw-window", allow_negative_numbers = true)]
    tw_window: Option<f64>,
    /// Time Warp's memory budget: uncommitted batches per worker.
    #[arg(long = "tw-memory")]
    tw_memory: Option<usize>,
    /// Batches a Time Warp worker runs between GVT rounds (default 2048 on threads, 256
    /// across MPI ranks).
    #[arg(long = "gvt-interval")]
    gvt_interval: Option<u32>,
    /// Pure Time Warp: every batch runs optimistically, with its state saved, even one that
    /// nothing can roll back any more (by default such a batch runs as final).
    #[arg(long = "tw-pure")]
    tw_pure: bool,
    /// Delay of NewVelocity messages (objects engines).
    #[arg(long = "newvelocity-delay")]
    newvelocity_delay: Option<String>,
    /// Which balls tell cushions, pockets and corners of a new trajectory on a sectored table:
    /// near (those in sectors within reach; the default) or thesis (all: fig. 15's counts).
    #[arg(long = "fixed-news")]
    fixed_news: Option<String>,
    /// Time step of the time-step engine.
    #[arg(long, allow_negative_numbers = true)]
    dt: Option<f64>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in scenarios.
    Scenarios,
    /// Run a scenario.
    Run(Box<RunArgs>),
    /// The main job: run the thesis' 36-ball gas with checks on and print the summary.
    Demo {
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
        /// Where to write the player page (or FILE.gif, or a folder of frames).
        #[arg(long, default_value = "poolsim-demo.html")]
        out: PathBuf,
    },
    /// Draw a run's frames (thesis 4.2): a folder of SVG and PNG frames, FILE.gif, or FILE.html
    /// (one self-contained page with a player).
    Render(Box<RenderArgs>),
    /// Measure events per second over ball counts and densities.
    Bench(poolsim::bench::BenchArgs),
    /// Run PHOLD, the standard PDES benchmark, and report committed events per second.
    Phold(PholdArgs),
    /// The analytic model of message counts (thesis ch. 7): F(s) and the best sector size.
    Model(ModelArgs),
    /// Run the thesis' chapter 6 experiment (tables 5-10, figures 17-18) and write a report.
    Experiment(poolsim::experiment::ExperimentArgs),
    /// Run from -Q to 0, reverse every ball, run on to Q, and report how far the balls end from
    /// where they started (thesis 4.6-4.7).
    Reverse(Box<ReverseArgs>),
}

/// Arguments of `poolsim model`.
#[derive(clap::Args, Clone, Debug)]
struct ModelArgs {
    /// Number of balls N on the unit-square table.
    #[arg(long, allow_negative_numbers = true)]
    balls: f64,
    /// Ball speed V.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    speed: f64,
    /// Duration T.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    time: f64,
    /// Number of velocity changes m (0: equation 1; otherwise equation 2).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    changes: f64,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
}

fn model(a: &ModelArgs) -> Result<(), Failure> {
    use poolsim::analytic::{report, report_json, ModelParams};
    let p = ModelParams {
        balls: a.balls,
        speed: a.speed,
        time: a.time,
        changes: a.changes,
    };
    p.validate().map_err(usage)?;
    if a.json {
        println!("{}", report_json(&p));
    } else {
        print!("{}", report(&p));
    }
    Ok(())
}

/// Arguments of `poolsim reverse`.
#[derive(clap::Args, Clone, Debug)]
struct ReverseArgs {
    /// A built-in scenario name or a TOML file; its balls are placed at time -Q.
    scenario: String,
    /// Quitting time Q.
    #[arg(long, allow_negative_numbers = true)]
    quit: f64,
    /// event-list, time-step, objects or time-warp.
    #[arg(long, default_value = "event-list")]
    engine: String,
    /// Sector layout of the objects engines: none, auto, N or NxM.
    #[arg(long)]
    sectors: Option<String>,
    #[command(flatten)]
    gen: GenArgs,
    /// Time step of the time-step engine.
    #[arg(long, allow_negative_numbers = true)]
    dt: Option<f64>,
    /// Delay of NewVelocity messages (objects engine).
    #[arg(long = "newvelocity-delay")]
    newvelocity_delay: Option<String>,
    /// Check invariants at every event.
    #[arg(long)]
    check: bool,
    /// Print the report as one JSON object.
    #[arg(long)]
    json: bool,
}

fn reverse(a: &ReverseArgs) -> Result<(), Failure> {
    if !(a.quit.is_finite() && a.quit > 0.0) {
        return Err(usage(format!(
            "--quit: must be a positive number, got {}",
            a.quit
        )));
    }
    let scenario = load(&a.scenario, &a.gen)?;
    let run_args = RunArgs {
        scenario: a.scenario.clone(),
        engine: a.engine.clone(),
        sectors: a.sectors.clone(),
        until: None,
        gen: a.gen.clone(),
        trace: None,
        final_state: None,
        json: a.json,
        check: a.check,
        workers: None,
        tw_window: None,
        tw_memory: None,
        gvt_interval: None,
        tw_pure: false,
        newvelocity_delay: a.newvelocity_delay.clone(),
        fixed_news: None,
        dt: a.dt,
        quiet: true,
    };
    let engine = engine_of(&run_args, &scenario)?;
    let r = poolsim::run::reverse(&scenario, engine, a.quit, a.check).map_err(run_failure)?;
    if a.json {
        println!(
            "{}",
            serde_json::to_string(&r).expect("a report serializes")
        );
    } else {
        println!(
            "{} on {}: -{} to {}, {} events ({} before the reversal); largest error: position \
             {:e}, velocity {:e}{}",
            r.scenario,
            r.engine,
            r.quit,
            r.quit,
            r.events,
            r.forward_events,
            r.max_position_error,
            r.max_velocity_error,
            if r.still_pocketed > 0 {
                format!("; {} balls still in pockets", r.still_pocketed)
            } else {
                String::new()
            }
        );
    }
    Ok(())
}

/// Arguments of `poolsim phold`.
#[derive(clap::Args, Clone, Debug)]
struct PholdArgs {
    /// Number of objects.
    #[arg(long, default_value_t = 1024)]
    objects: u32,
    /// Messages each object starts with.
    #[arg(long = "events-per-object", default_value_t = 16)]
    events_per_object: u32,
    /// Probability that a message goes to another partition.
    #[arg(long, default_value_t = 0.1)]
    remote: f64,
    /// Partitions; objects are split in equal blocks (default: the Time Warp workers of all
    /// ranks, or 2 on the sequential kernel).
    #[arg(long)]
    partitions: Option<u32>,
    /// objects (the sequential kernel) or time-warp.
    #[arg(long, default_value = "objects")]
    engine: String,
    /// Time Warp workers per rank (default: this machine's cores).
    #[arg(long)]
    workers: Option<usize>,
    /// End time.
    #[arg(long, default_value_t = 100.0)]
    end: f64,
    /// Minimum delay of a message.
    #[arg(long, default_value_t = 0.1)]
    lookahead: f64,
    /// Mean of the exponential part of the delay.
    #[arg(long, default_value_t = 1.0)]
    mean: f64,
    /// Seed of the objects' random streams.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print the report as one JSON object.
    #[arg(long)]
    json: bool,
}

/// The most PHOLD events in flight (objects times events per object): about a gigabyte.
const MAX_PHOLD_EVENTS: u64 = 10_000_000;

fn phold(a: &PholdArgs) -> Result<(), Failure> {
    use pdes_kernel::phold::{run, PholdConfig};
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
    let tw = match a.engine.as_str() {
        "objects" => {
            if a.workers.is_some() {
                return Err(usage("--workers: only the time-warp engine takes it"));
            }
            None
        }
        "time-warp" => Some(tw_workers(a.workers)?),
        other => {
            return Err(usage(format!(
                "--engine: PHOLD runs on objects or time-warp, not `{other}`"
            )))
        }
    };
    if tw.is_some() {
        poolsim::memory::transparent_huge_pages(false);
    }
    #[cfg(feature = "mpi")]
    let _mpi = if tw.is_some() { start_mpi()? } else { None };
    let partitions = a.partitions.unwrap_or_else(|| match &tw {
        Some(c) => pdes_kernel::time_warp::threads::total_workers(c) as u32,
        None => 2,
    });
    if u64::from(a.objects) * u64::from(a.events_per_object) > MAX_PHOLD_EVENTS {
        return Err(usage(format!(
            "--objects x --events-per-object: at most {MAX_PHOLD_EVENTS} events in flight, got \
             {} x {}",
            a.objects, a.events_per_object
        )));
    }
    if a.objects == 0 || partitions == 0 || partitions > a.objects {
        return Err(usage(format!(
            "--objects and --partitions: need 1 <= partitions <= objects, got {} and {}",
            partitions, a.objects
        )));
    }
    let report = run(
        PholdConfig {
            objects: a.objects,
            events_per_object: a.events_per_object,
            remote: a.remote,
            partitions,
            lookahead: a.lookahead,
            mean: a.mean,
            seed: a.seed,
        },
        a.end,
        tw,
    )
    .map_err(internal)?;
    if pdes_kernel::time_warp::threads::place().0 != 0 {
        return Ok(());
    }
    if a.json {
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
    }
    Ok(())
}

/// A failure with its exit status.
struct Failure {
    code: u8,
    message: String,
}

fn usage(message: impl Into<String>) -> Failure {
    Failure {
        code: 2,
        message: message.into(),
    }
}

fn internal(message: impl Into<String>) -> Failure {
    Failure {
        code: 1,
        message: message.into(),
    }
}

/// Shows progress in simulated time on stderr.
struct Progress {
    bar: ProgressBar,
    until: f64,
    seen: u64,
}

impl Progress {
    fn new(until: f64, quiet: bool) -> Option<Progress> {
        if quiet || !std::io::stderr().is_terminal() || until.is_nan() || until <= 0.0 {
            return None;
        }
        let bar = ProgressBar::new(1000);
        bar.set_style(
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {msg}")
                .expect("a valid template"),
        );
        // the spinner and clock move even before the first event: setting up a large sectored
        // table takes a while
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        bar.set_message(format!("t = 0 / {until}, 0 events"));
        Some(Progress {
            bar,
            until,
            seen: 0,
        })
    }
}

impl Observer for Progress {
    fn on_event(&mut self, ev: &Event, _: &dyn World) -> Result<(), RunError> {
        self.seen += 1;
        if self.seen.is_multiple_of(8192) {
            self.bar
                .set_position((ev.t / self.until * 1000.0).clamp(0.0, 1000.0) as u64);
            self.bar.set_message(format!(
                "t = {:.3} / {}, {} events",
                ev.t, self.until, self.seen
            ));
        }
        Ok(())
    }

    fn reads_balls(&self) -> bool {
        false
    }
}

fn load(spec: &str, gen: &GenArgs) -> Result<Scenario, Failure> {
    scenario::load(spec, &gen.params()).map_err(|e| usage(e.to_string()))
}

/// `--fixed-news`: near (the default) or thesis.
fn fixed_news(arg: Option<&str>) -> Result<FixedNews, Failure> {
    match arg {
        None | Some("near") => Ok(FixedNews::Near),
        Some("thesis") => Ok(FixedNews::Thesis),
        Some(other) => Err(usage(format!(
            "--fixed-news: expected near or thesis, got `{other}`"
        ))),
    }
}

/// `--newvelocity-delay`: absent or 0 is exact; `auto` is the thesis' choice (4.4): a ball at the
/// fastest initial speed moves 1% of the smallest diameter in the delay.
fn nv_delay(arg: Option<&str>, s: &Scenario) -> Result<NvDelay, Failure> {
    let d = match arg {
        None => return Ok(NvDelay::Exact),
        Some("auto") => {
            let vmax = s
                .balls
                .iter()
                .map(|b| b.velocity.norm())
                .fold(0.0, f64::max);
            let dmin = s
                .balls
                .iter()
                .map(|b| 2.0 * b.radius)
                .fold(f64::INFINITY, f64::min);
            if vmax > 0.0 && dmin.is_finite() {
                0.01 * dmin / vmax
            } else {
                0.0
            }
        }
        Some(text) => text.parse::<f64>().map_err(|_| {
            usage(format!(
                "--newvelocity-delay: expected a number or `auto`, got `{text}`"
            ))
        })?,
    };
    if !d.is_finite() || d < 0.0 {
        return Err(usage(format!(
            "--newvelocity-delay: must be a finite number not below 0, got {d}"
        )));
    }
    Ok(if d == 0.0 {
        NvDelay::Exact
    } else {
        NvDelay::Delay(d)
    })
}

/// `--sectors`: none, auto, N (N x N) or NxM; absent means the scenario's own `[sectors]`, if
/// any.
fn sector_choice(arg: Option<&str>, s: &Scenario) -> Result<Option<SectorChoice>, Failure> {
    let bad = || {
        usage(format!(
            "--sectors: expected none, auto, N or NxM (sectors per side, at least 1 each, at most \
             {} sectors in all), got `{}`",
            scenario::MAX_SECTORS,
            arg.unwrap_or_default()
        ))
    };
    let count = |text: &str| match text.parse::<u32>() {
        Ok(n) if n >= 1 && u64::from(n) <= scenario::MAX_SECTORS => Ok(n),
        _ => Err(bad()),
    };
    let grid = |nx: u32, ny: u32| {
        if u64::from(nx) * u64::from(ny) > scenario::MAX_SECTORS {
            Err(bad())
        } else {
            Ok(Some(SectorChoice::Grid(nx, ny)))
        }
    };
    Ok(match arg {
        None => s.sectors.as_ref().map(|_| SectorChoice::Scenario),
        Some("none") => None,
        Some("auto") => Some(SectorChoice::Auto),
        Some(text) => match text.split_once(['x', 'X']) {
            Some((nx, ny)) => grid(count(nx)?, count(ny)?)?,
            None => {
                let n = count(text)?;
                grid(n, n)?
            }
        },
    })
}

/// A run's failure: bad input (exit 2) or the run's own (exit 1).
fn run_failure(e: RunError) -> Failure {
    match e {
        RunError::Input(m) => usage(m),
        e => internal(e.to_string()),
    }
}

fn engine_of(a: &RunArgs, scenario: &Scenario) -> Result<EngineKind, Failure> {
    match a.engine.as_str() {
        "event-list" => {
            if let Some(flag) = a.dt.map(|_| "--dt") {
                return Err(usage(format!("{flag}: only the time-step engine takes it")));
            }
            Ok(EngineKind::EventList)
        }
        "time-step" => {
            let dt =
                a.dt.ok_or_else(|| usage("--dt: the time-step engine needs a time step"))?;
            if !(dt.is_finite() && dt > 0.0) {
                return Err(usage(format!("--dt: must be a positive number, got {dt}")));
            }
            Ok(EngineKind::TimeStep { dt })
        }
        "objects" => {
            let delay = nv_delay(a.newvelocity_delay.as_deref(), scenario)?;
            match sector_choice(a.sectors.as_deref(), scenario)? {
                None => Ok(EngineKind::Objects { delay }),
                Some(_) if delay != NvDelay::Exact => Err(usage(
                    "--newvelocity-delay: the thesis' delay runs on non-sectored tables only \
                     (--sectors none)",
                )),
                Some(sectors) => {
                    poolsim::run::sector_layout(scenario, sectors)
                        .map_err(|e| usage(format!("--sectors: {e}")))?;
                    Ok(EngineKind::Sectored {
                        sectors,
                        news: fixed_news(a.fixed_news.as_deref())?,
                    })
                }
            }
        }
        "time-warp" => {
            let delay = nv_delay(a.newvelocity_delay.as_deref(), scenario)?;
            let sectors = sector_choice(a.sectors.as_deref(), scenario)?;
            if let Some(choice) = sectors {
                if delay != NvDelay::Exact {
                    return Err(usage(
                        "--newvelocity-delay: the thesis' delay runs on non-sectored tables \
                         only (--sectors none)",
                    ));
                }
                poolsim::run::sector_layout(scenario, choice)
                    .map_err(|e| usage(format!("--sectors: {e}")))?;
            }
            Ok(EngineKind::TimeWarp {
                tw: tw_config(a)?,
                delay,
                sectors,
                news: fixed_news(a.fixed_news.as_deref())?,
            })
        }
        other => Err(usage(format!(
            "--engine: unknown engine `{other}`; available: event-list, time-step, objects, \
             time-warp"
        ))),
    }
}

/// MPI, when this process was started by `mpirun` (cargo feature `mpi`), held for the run.
#[cfg(feature = "mpi")]
fn start_mpi() -> Result<Option<mpi::environment::Universe>, Failure> {
    let launched = ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"]
        .iter()
        .any(|v| std::env::var_os(v).is_some());
    if !launched {
        return Ok(None);
    }
    use mpi::Threading;
    match mpi::initialize_with_threading(Threading::Serialized) {
        Some((u, Threading::Serialized | Threading::Multiple)) => Ok(Some(u)),
        Some(_) => Err(internal(
            "MPI: the library cannot serve calls from several threads (MPI_THREAD_SERIALIZED)",
        )),
        None => Err(internal("MPI: initialization failed")),
    }
}

/// Time Warp's default settings with `--workers` (default: this machine's cores) and
/// `POOLSIM_CHAOS`.
fn tw_workers(workers: Option<usize>) -> Result<TwConfig, Failure> {
    let mut tw = TwConfig {
        workers: std::thread::available_parallelism().map_or(1, |n| n.get()),
        chaos: chaos_from_env().map_err(usage)?,
        ..TwConfig::default()
    };
    if let Some(w) = workers {
        if !(1..=1024).contains(&w) {
            return Err(usage(format!("--workers: must be 1 to 1024, got {w}")));
        }
        tw.workers = w;
    }
    Ok(tw)
}

/// Time Warp's settings from the flags and `POOLSIM_CHAOS`.
fn tw_config(a: &RunArgs) -> Result<TwConfig, Failure> {
    let mut tw = tw_workers(a.workers)?;
    if let Some(w) = a.tw_window {
        if !(w.is_finite() && w > 0.0) {
            return Err(usage(format!(
                "--tw-window: must be a positive number, got {w}"
            )));
        }
        tw.window = Some(w);
    }
    if let Some(m) = a.tw_memory {
        if m < 16 {
            return Err(usage(format!(
                "--tw-memory: must be at least 16 batches, got {m}"
            )));
        }
        tw.max_uncommitted = m;
    }
    if let Some(g) = a.gvt_interval {
        if g == 0 {
            return Err(usage("--gvt-interval: must be at least 1"));
        }
        tw.gvt_interval = Some(g);
    }
    tw.final_batches = !a.tw_pure;
    Ok(tw)
}

/// The trace and the final state must go to two files, neither of them the scenario: writing
/// one would truncate the other.
fn check_outputs_apart(a: &RunArgs) -> Result<(), Failure> {
    // where a path points, resolved as far as it exists; devices such as /dev/null are shared
    let resolved = |p: &std::path::Path| {
        if p.exists() && !p.is_file() {
            return None;
        }
        p.canonicalize().ok().or_else(|| {
            let dir = p.parent().filter(|d| !d.as_os_str().is_empty());
            let dir = dir.unwrap_or(std::path::Path::new("."));
            Some(dir.canonicalize().ok()?.join(p.file_name()?))
        })
    };
    let same = |x: &std::path::Path, y: &std::path::Path| {
        resolved(x).is_some_and(|x| resolved(y) == Some(x))
    };
    let scenario = std::path::Path::new(&a.scenario);
    for (flag, out) in [("--trace", &a.trace), ("--final-state", &a.final_state)] {
        if let Some(out) = out {
            if same(out, scenario) {
                return Err(usage(format!(
                    "{flag}: {} is the scenario file; writing it would destroy it",
                    out.display()
                )));
            }
        }
    }
    if let (Some(t), Some(f)) = (&a.trace, &a.final_state) {
        if same(t, f) {
            return Err(usage(format!(
                "--trace and --final-state: both name {}; give two files",
                t.display()
            )));
        }
    }
    Ok(())
}

fn run(a: &RunArgs) -> Result<(), Failure> {
    let scenario = load(&a.scenario, &a.gen)?;
    let engine = engine_of(a, &scenario)?;
    let objects = matches!(
        engine,
        EngineKind::Objects { .. } | EngineKind::Sectored { .. } | EngineKind::TimeWarp { .. }
    );
    let time_warp = matches!(engine, EngineKind::TimeWarp { .. });
    if objects {
        poolsim::memory::transparent_huge_pages(false);
    }
    let sectored = matches!(
        engine,
        EngineKind::Sectored { .. }
            | EngineKind::TimeWarp {
                sectors: Some(_),
                ..
            }
    );
    if a.fixed_news.is_some() && !sectored {
        return Err(usage(
            "--fixed-news: only sectored runs take it (--engine objects or time-warp with --sectors)",
        ));
    }
    for (flag, given) in [
        ("--sectors", a.sectors.is_some() && !objects),
        (
            "--newvelocity-delay",
            a.newvelocity_delay.is_some() && !objects,
        ),
    ] {
        if given {
            return Err(usage(format!(
                "{flag}: only the objects and time-warp engines take it"
            )));
        }
    }
    for (flag, given) in [
        ("--workers", a.workers.is_some()),
        ("--tw-window", a.tw_window.is_some()),
        ("--tw-memory", a.tw_memory.is_some()),
        ("--gvt-interval", a.gvt_interval.is_some()),
        ("--tw-pure", a.tw_pure),
    ] {
        if given && !time_warp {
            return Err(usage(format!("{flag}: only the time-warp engine takes it")));
        }
    }
    check_outputs_apart(a)?;
    let until = a.until.unwrap_or(scenario.until);
    if !until.is_finite() || until < 0.0 {
        return Err(usage(format!(
            "--until: must be a finite number not below 0, got {until}"
        )));
    }
    let cfg = RunConfig {
        engine,
        until,
        check: a.check,
        span: Default::default(),
    };
    #[cfg(feature = "mpi")]
    let _mpi = if time_warp { start_mpi()? } else { None };
    // under MPI only rank 0 writes anything
    let root = pdes_kernel::time_warp::threads::collects_results();
    let mut trace = match a.trace.as_ref().filter(|_| root) {
        Some(p) => Some(TraceWriter::new(BufWriter::new(File::create(p).map_err(
            |e| {
                usage(format!(
                    "{}: cannot create the trace file: {e}",
                    p.display()
                ))
            },
        )?))),
        None => None,
    };
    let mut progress = Progress::new(until, a.quiet || !root);
    let report = {
        let mut sinks = Sinks {
            trace: trace.as_mut(),
            progress: progress.as_mut(),
        };
        execute(&scenario, &cfg, &mut sinks)
    };
    if let Some(p) = &progress {
        p.bar.finish_and_clear();
    }
    // the trace is the run's only output written as it goes
    let trace_failed = |e: &dyn std::fmt::Display| {
        let path = a.trace.as_ref().map(|p| p.display().to_string());
        usage(format!(
            "{}: writing the trace failed: {e}",
            path.unwrap_or_default()
        ))
    };
    if let Some(t) = trace {
        t.finish().map_err(|e| trace_failed(&e))?;
    }
    let report = report.map_err(|e| match e {
        RunError::Output(m) => trace_failed(&m),
        e => run_failure(e),
    })?;
    if !root {
        return Ok(());
    }
    if let Some(p) = &a.final_state {
        let fs = FinalState::new(report.outcome.t, &report.outcome.balls);
        let text = serde_json::to_string_pretty(&fs).expect("a final state serializes");
        std::fs::write(p, text + "\n").map_err(|e| {
            usage(format!(
                "{}: cannot write the final state: {e}",
                p.display()
            ))
        })?;
    }
    print_summary(&report.summary, a.json);
    Ok(())
}

/// Trace and progress, each optional.
struct Sinks<'a, W: std::io::Write> {
    trace: Option<&'a mut TraceWriter<W>>,
    progress: Option<&'a mut Progress>,
}

impl<W: std::io::Write> Observer for Sinks<'_, W> {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        if let Some(t) = &mut self.trace {
            t.on_event(ev, world)?;
        }
        if let Some(p) = &mut self.progress {
            p.on_event(ev, world)?;
        }
        Ok(())
    }

    fn reads_balls(&self) -> bool {
        self.trace.as_ref().is_some_and(|t| t.reads_balls())
            || self.progress.as_ref().is_some_and(|p| p.reads_balls())
    }
}

fn print_summary(s: &RunSummary, json: bool) {
    if json {
        println!("{}", serde_json::to_string(s).expect("plain data"));
        return;
    }
    println!("scenario      {}", s.scenario);
    println!("engine        {}", s.engine);
    println!("balls         {}", s.balls);
    println!("until         {:?}", s.until);
    let ev = &s.events;
    println!(
        "events        {} (ball-ball {}, ball-cushion {}, ball-corner {}, ball-pocket {})",
        ev.total, ev.ball_ball, ev.ball_cushion, ev.ball_corner, ev.ball_pocket
    );
    let ke = &s.kinetic_energy;
    println!(
        "energy        initial {:?}, final {:?} on the table + {:?} in pockets (relative drift {:e})",
        ke.initial, ke.end, ke.pocketed, ke.relative_drift
    );
    println!("digest        {}", s.final_state_digest);
    println!(
        "wall          {:.3} s ({:.3} s set-up), {:.0} events/s{}",
        s.wall_seconds,
        s.setup_seconds,
        s.events_per_second,
        if s.checked {
            ", invariants checked at every event"
        } else {
            ""
        }
    );
    if let Some(tw) = &s.time_warp {
        let st = &tw.stats;
        let count = |n: u64, one: &str| match n {
            1 => format!("1 {one}"),
            m => format!("{m} {one}s"),
        };
        println!(
            "time warp     {} on {}: efficiency {:.3}, {:.0} % of batches final, {} rollbacks, \
             {:.2} % of messages remote, {} GVT rounds",
            count(st.workers, "worker"),
            count(st.ranks, "rank"),
            tw.efficiency,
            100.0 * st.final_batches as f64 / st.committed.max(1) as f64,
            st.rollbacks,
            100.0 * tw.remote_fraction,
            st.gvt_rounds
        );
    }
}

/// Arguments of `poolsim render`.
#[derive(clap::Args, Clone, Debug)]
struct RenderArgs {
    /// A built-in scenario name or a TOML file.
    scenario: String,
    /// A folder (frame-0000.svg and .png, ...), FILE.html (one page with a player) or FILE.gif.
    #[arg(long)]
    out: PathBuf,
    /// Time between frames (default: about 40 frames, rounded to 1, 2 or 5 times a power of 10).
    #[arg(long = "frame-time", allow_negative_numbers = true)]
    frame_time: Option<f64>,
    /// End time (default: the scenario's).
    #[arg(long, allow_negative_numbers = true)]
    until: Option<f64>,
    /// event-list, objects or time-warp.
    #[arg(long, default_value = "event-list")]
    engine: String,
    /// Sectors: none, auto, N or NxM; drawn on any engine, run by the objects engines.
    #[arg(long)]
    sectors: Option<String>,
    #[command(flatten)]
    gen: GenArgs,
    /// Delay of NewVelocity messages (objects engine).
    #[arg(long = "newvelocity-delay")]
    newvelocity_delay: Option<String>,
    /// Check invariants at every event.
    #[arg(long)]
    check: bool,
}

/// Records a run and writes its frames where `out` says.
fn render_to(
    scenario: &Scenario,
    cfg: &poolsim::render::RenderConfig,
    out: &std::path::Path,
) -> Result<(poolsim::render::Recording, String), Failure> {
    use poolsim::render::{raster::Rasterizer, record, write, Output, RenderError};
    let out = Output::from_path(out).map_err(usage)?;
    let rasterizer = if out.needs_font() {
        Some(Rasterizer::new().map_err(|e| internal(e.to_string()))?)
    } else {
        None
    };
    let rec = record(scenario, cfg).map_err(run_failure)?;
    let line = write(&rec, &out, rasterizer.as_ref()).map_err(|e| match e {
        RenderError::Io { .. } => usage(e.to_string()),
        e => internal(e.to_string()),
    })?;
    Ok((rec, line))
}

fn render(a: &RenderArgs) -> Result<(), Failure> {
    let scenario = load(&a.scenario, &a.gen)?;
    let run_args = RunArgs {
        scenario: a.scenario.clone(),
        engine: a.engine.clone(),
        sectors: a.sectors.clone(),
        until: a.until,
        gen: a.gen.clone(),
        trace: None,
        final_state: None,
        json: false,
        check: a.check,
        workers: None,
        tw_window: None,
        tw_memory: None,
        gvt_interval: None,
        tw_pure: false,
        newvelocity_delay: a.newvelocity_delay.clone(),
        fixed_news: None,
        dt: None,
        quiet: true,
    };
    if a.engine == "time-step" {
        return Err(usage(
            "--engine: render draws with event-list, objects or time-warp",
        ));
    }
    let engine = engine_of(&run_args, &scenario)?;
    if a.newvelocity_delay.is_some() && engine == EngineKind::EventList {
        return Err(usage(
            "--newvelocity-delay: only the objects engine takes it",
        ));
    }
    let until = a.until.unwrap_or(scenario.until);
    let frame_time = a
        .frame_time
        .unwrap_or_else(|| poolsim::render::default_frame_time(until));
    let cfg = poolsim::render::RenderConfig {
        check: a.check,
        sectors: sector_choice(a.sectors.as_deref(), &scenario)?,
        ..poolsim::render::RenderConfig::new(engine, until, frame_time)
    };
    let (_, line) = render_to(&scenario, &cfg, &a.out)?;
    println!("wrote {line}");
    Ok(())
}

/// The demo's summary: the run's, with its sector layout and the page it wrote.
#[derive(serde::Serialize)]
struct DemoSummary<'a> {
    #[serde(flatten)]
    run: &'a RunSummary,
    sectors: &'static str,
    page: String,
}

/// The main job: the thesis' sectored 36-ball gas (plates 9-13: 2 x 2 sectors, frames every 0.1
/// up to 4) on the objects engine with the thesis' message flow, checked at every event, drawn
/// as one page with a player.
fn demo(json: bool, out: &std::path::Path) -> Result<(), Failure> {
    let scenario = load("gas", &GenArgs::default())?;
    let sectors = SectorChoice::Grid(2, 2);
    let cfg = poolsim::render::RenderConfig {
        check: true,
        sectors: Some(sectors),
        ..poolsim::render::RenderConfig::new(
            EngineKind::Sectored {
                sectors,
                news: FixedNews::Thesis,
            },
            scenario.until,
            0.1,
        )
    };
    let (rec, line) = render_to(&scenario, &cfg, out)?;
    if json {
        let demo = DemoSummary {
            run: &rec.summary,
            sectors: "2x2",
            page: out.display().to_string(),
        };
        println!("{}", serde_json::to_string(&demo).expect("plain data"));
        return Ok(());
    }
    print_summary(&rec.summary, false);
    {
        let m = &rec.summary.messages;
        println!(
            "messages      {} (thesis table 5 total: NewVelocity {}, Collision {}, Cancel {}, \
             VelocityChange {}, SectorEntry {}, SectorDeparture {})",
            m.total,
            m.NewVelocity,
            m.Collision,
            m.Cancel,
            m.VelocityChange,
            m.SectorEntry,
            m.SectorDeparture
        );
        println!("sectors       2 x 2 (thesis plates 9-13)");
        println!("page          {line}");
    }
    Ok(())
}

/// Lets a closed pipe end the process quietly, as it does every Unix filter (`poolsim bench |
/// head`): Rust ignores SIGPIPE, and printing to a closed pipe would then panic.
fn die_quietly_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: restores the default action of one signal before any thread is started.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Parses the command line; every subcommand takes negative numbers as values, so that a
/// negative value is reported by the check of its option, not as an unknown option.
fn parse_command_line() -> Result<Cli, clap::Error> {
    use clap::{CommandFactory, FromArgMatches};
    let mut cmd = Cli::command();
    let names: Vec<String> = cmd
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    for name in names {
        cmd = cmd.mut_subcommand(name, |s| s.allow_negative_numbers(true));
    }
    Cli::from_arg_matches(&cmd.try_get_matches()?)
}

/// One line for a usage error: clap's first paragraph (the problem, with the arguments it names
/// and the possible values), without its usage and help hints.
fn usage_line(e: &clap::Error) -> String {
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::MissingSubcommand | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        return "no command given (try `poolsim --help`)".to_string();
    }
    let text = e.to_string();
    let first: Vec<&str> = text
        .lines()
        .take_while(|l| !l.trim().is_empty())
        .map(str::trim)
        .collect();
    let line = first.join(" ");
    let line = line.trim_start_matches("error: ");
    if line.is_empty() {
        "bad usage".to_string()
    } else {
        line.to_string()
    }
}

fn main() -> ExitCode {
    keep_freed_memory();
    die_quietly_on_closed_pipe();
    let cli = match parse_command_line() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => e.exit(), // --help, --version
        Err(e) => {
            eprintln!("poolsim: {}", usage_line(&e));
            return ExitCode::from(2);
        }
    };
    let result = match &cli.command {
        Command::Scenarios => {
            for (name, about) in builtin::list() {
                println!("{name:<10} {about}");
            }
            Ok(())
        }
        Command::Run(a) => run(a),
        Command::Demo { json, out } => demo(*json, out),
        Command::Render(a) => render(a),
        Command::Bench(b) => poolsim::bench::run(b).map_err(usage),
        Command::Phold(a) => phold(a),
        Command::Reverse(a) => reverse(a),
        Command::Model(a) => model(a),
        Command::Experiment(a) => poolsim::experiment::run(a).map_err(usage),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("poolsim: {}", f.message);
            ExitCode::from(f.code)
        }
    }
}

/// Seeds for chaos mode from `POOLSIM_CHAOS`, when set to a number.
fn chaos_from_env() -> Result<Option<u64>, String> {
    match std::env::var("POOLSIM_CHAOS") {
        Err(_) => Ok(None),
        Ok(s) if s.is_empty() => Ok(None),
        Ok(s) => s
            .parse()
            .map(Some)
            .map_err(|_| format!("POOLSIM_CHAOS: expected a seed (an integer), got `{s}`")),
    }
}
