//! `poolsim run`: one scenario on one engine, with its trace, final state and summary.

use crate::checkpoints::{open_trace, Saver, Trace};
use crate::common::*;
use crate::signals::{interrupted, stop_on_signals};
use crate::values::{nv_delay, sector_choice, Delay, Engine, MemoryLimit, News, Sectors};
use pdes_kernel::time_warp::TwConfig;
use pdes_kernel::Interrupt;
use poolsim::checkpoint::Checkpoint;
use poolsim::engine::{Event, Observer, RunError, Span, World};
use poolsim::memory::human_bytes;
use poolsim::model::pool::NvDelay;
use poolsim::output::FinalState;
use poolsim::run::{execute, EngineKind, RunConfig};
use poolsim::scenario::Scenario;
use poolsim::structure::{Structure, Wanted};
use poolsim::summary::{KineticEnergy, RunSummary};
use std::io::Write;
use std::path::PathBuf;

#[derive(clap::Args, Clone, Debug)]
pub struct RunArgs {
    /// A built-in scenario name (see `poolsim scenarios`), a TOML file, or - for TOML on stdin.
    pub scenario: String,
    /// The engine.
    #[arg(long, value_enum, default_value = "event-list")]
    pub engine: Engine,
    /// Sector layout: none, auto, N or NxM (sectored engines only).
    #[arg(long)]
    pub sectors: Option<Sectors>,
    /// End time (default: the scenario's).
    #[arg(long, allow_negative_numbers = true)]
    pub until: Option<f64>,
    #[command(flatten)]
    pub gen: GenArgs,
    /// Write the trace (JSON Lines, one line per physical event) here; `-` writes it to stdout,
    /// and the summary then goes to stderr.
    #[arg(long)]
    pub trace: Option<PathBuf>,
    /// Write the final state (JSON) here.
    #[arg(long = "final-state")]
    pub final_state: Option<PathBuf>,
    /// Print the run summary as one JSON object on stdout, and nothing else there.
    #[arg(long)]
    pub json: bool,
    /// Check invariants at every event; a violation stops the run with exit status 1.
    #[arg(long)]
    pub check: bool,
    /// Worker threads (time-warp and regions engines; default: this machine's cores).
    #[arg(long)]
    pub workers: Option<usize>,
    /// Strips the regions engine cuts the table into (default: one per worker).
    #[arg(long)]
    pub regions: Option<u32>,
    /// Time Warp's optimism window: no batch later than this past the least floor any worker
    /// holds, GVT or later (simulation time).
    #[arg(long = "tw-window", allow_negative_numbers = true)]
    pub tw_window: Option<f64>,
    /// Time Warp's memory budget: uncommitted batches per worker.
    #[arg(long = "tw-memory")]
    pub tw_memory: Option<usize>,
    /// Batches a Time Warp worker runs between GVT rounds (default 2048 on threads, 256
    /// across MPI ranks).
    #[arg(long = "gvt-interval")]
    pub gvt_interval: Option<u32>,
    /// Pure Time Warp: every batch runs optimistically, with its state saved, even one that
    /// nothing can roll back any more (by default such a batch runs as final).
    #[arg(long = "tw-pure")]
    pub tw_pure: bool,
    /// Batches a Time Warp worker runs between looks at its inbox (default 128; 64 with
    /// --tw-pure).
    #[arg(long = "tw-burst")]
    pub tw_burst: Option<u32>,
    /// Delay of NewVelocity messages (objects engines): a time, or auto.
    #[arg(long = "newvelocity-delay")]
    pub newvelocity_delay: Option<Delay>,
    /// Which balls tell cushions, pockets and corners of a new trajectory on a sectored table:
    /// near (those in sectors within reach; the default) or thesis (all: fig. 15's counts).
    #[arg(long = "fixed-news", value_enum)]
    pub fixed_news: Option<News>,
    /// Time step of the time-step engine.
    #[arg(long, allow_negative_numbers = true)]
    pub dt: Option<f64>,
    /// No progress bar and no human summary (`--json` still prints).
    #[arg(long)]
    pub quiet: bool,
    /// The memory to check the run's estimate against before it allocates (512M, 8G, 1.5T),
    /// or none; by default what this machine and its control group have available.
    #[arg(long = "memory-limit")]
    pub memory_limit: Option<MemoryLimit>,
    /// Write the run's complete state here (atomically) at the end, where an interrupt stops
    /// it, and every --checkpoint-every; `poolsim resume FILE` takes the run up from it.
    #[arg(long)]
    pub checkpoint: Option<PathBuf>,
    /// Simulation time between checkpoints.
    #[arg(long = "checkpoint-every", allow_negative_numbers = true)]
    pub checkpoint_every: Option<f64>,
    /// Write every ball on the table every --sample-every here, as extended XYZ (OVITO, ASE).
    #[arg(long)]
    pub samples: Option<PathBuf>,
    /// Simulation time between samples (default: about 40 samples, rounded to 1, 2 or 5 times
    /// a power of 10).
    #[arg(long = "sample-every", allow_negative_numbers = true)]
    pub sample_every: Option<f64>,
    /// Observe the pressure (collision virial and cushions), the compressibility factor, the
    /// temperature and the collision rate in blocks of this much simulation time; the summary
    /// gains `observables` (mean and standard error of the blocks).
    #[arg(long = "observe-every", allow_negative_numbers = true)]
    pub observe_every: Option<f64>,
    /// Where the observed blocks start (default: the start of the run), so that the gas can
    /// settle first.
    #[arg(long = "observe-from", allow_negative_numbers = true)]
    pub observe_from: Option<f64>,
    /// Andersen's thermostat at this temperature kT: at random instants one disk at a time
    /// takes a fresh Maxwell-Boltzmann velocity (event-list engine).
    #[arg(long, allow_negative_numbers = true)]
    pub thermostat: Option<f64>,
    /// Structure at the sample times (--sample-every), comma separated: gr (the pair
    /// correlation function, averaged over the samples), msd (the mean squared displacement
    /// since the first sample), psi6 (the hexatic order); from --observe-from on.
    #[arg(long, value_delimiter = ',')]
    pub observe: Option<Vec<String>>,
    /// How far g(r) reaches (default: five of the largest diameters, at most half a periodic
    /// box's shorter side).
    #[arg(long = "gr-max", allow_negative_numbers = true)]
    pub gr_max: Option<f64>,
    /// The thermostat's kicks per disk and unit time (default 0.1).
    #[arg(long = "thermostat-rate", allow_negative_numbers = true)]
    pub thermostat_rate: Option<f64>,
    /// The seed of the thermostat's kicks (default 1).
    #[arg(long = "thermostat-seed")]
    pub thermostat_seed: Option<u64>,
}

impl RunArgs {
    /// The arguments of a quiet run of `scenario` on `engine`, everything else at its default:
    /// what `render` and `reverse` hand to [`engine_of`].
    pub fn for_engine(
        scenario: &str,
        engine: Engine,
        sectors: Option<Sectors>,
        gen: &GenArgs,
        newvelocity_delay: Option<Delay>,
    ) -> RunArgs {
        RunArgs {
            scenario: scenario.to_string(),
            engine,
            sectors,
            until: None,
            gen: gen.clone(),
            trace: None,
            final_state: None,
            json: false,
            check: false,
            workers: None,
            regions: None,
            tw_window: None,
            tw_memory: None,
            gvt_interval: None,
            tw_pure: false,
            tw_burst: None,
            newvelocity_delay,
            fixed_news: None,
            dt: None,
            quiet: true,
            memory_limit: None,
            checkpoint: None,
            checkpoint_every: None,
            samples: None,
            sample_every: None,
            observe_every: None,
            observe_from: None,
            thermostat: None,
            thermostat_rate: None,
            thermostat_seed: None,
            observe: None,
            gr_max: None,
        }
    }
}

/// The engine the arguments ask for on `scenario`, its options checked against each other.
pub fn engine_of(a: &RunArgs, scenario: &Scenario) -> Result<EngineKind, Failure> {
    let news = a.fixed_news.unwrap_or(News::Near).into();
    match a.engine {
        Engine::EventList => {
            if let Some(flag) = a.dt.map(|_| "--dt") {
                return Err(usage(format!("{flag}: only the time-step engine takes it")));
            }
            Ok(EngineKind::EventList)
        }
        Engine::TimeStep => {
            let dt =
                a.dt.ok_or_else(|| usage("--dt: the time-step engine needs a time step"))?;
            if !(dt.is_finite() && dt > 0.0) {
                return Err(usage(format!("--dt: must be a positive number, got {dt}")));
            }
            Ok(EngineKind::TimeStep { dt })
        }
        Engine::Objects => {
            let delay = nv_delay(a.newvelocity_delay, scenario);
            match sector_choice(a.sectors, scenario) {
                None => Ok(EngineKind::Objects { delay }),
                Some(_) if delay != NvDelay::Exact => Err(usage(
                    "--newvelocity-delay: the thesis' delay runs on non-sectored tables only \
                     (--sectors none)",
                )),
                Some(sectors) => {
                    poolsim::run::sector_layout(scenario, sectors)
                        .map_err(|e| usage(format!("--sectors: {e}")))?;
                    Ok(EngineKind::Sectored { sectors, news })
                }
            }
        }
        Engine::Regions => {
            let tw = tw_config(a)?;
            // every rank's workers, under MPI
            let workers = pdes_kernel::time_warp::threads::total_workers(&tw);
            let count = a.regions.unwrap_or(workers as u32);
            if count == 0 {
                return Err(usage("--regions: must be at least 1"));
            }
            // one worker runs the regions in turn on the sequential executor
            let tw = (workers > 1).then_some(tw);
            Ok(EngineKind::Regions { count, tw })
        }
        Engine::TimeWarp => {
            let delay = nv_delay(a.newvelocity_delay, scenario);
            let sectors = sector_choice(a.sectors, scenario);
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
                news,
            })
        }
    }
}

/// Time Warp's settings from the flags and `POOLSIM_CHAOS`.
pub fn tw_config(a: &RunArgs) -> Result<TwConfig, Failure> {
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
    tw.burst = burst(a.tw_burst)?;
    Ok(tw)
}

/// The trace, the final state and the checkpoint must go to different files, none of them the
/// scenario (a checkpoint taken up may be written over by the run's own): writing one would
/// truncate another.
pub fn check_outputs_apart(a: &RunArgs, resuming: bool) -> Result<(), Failure> {
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
    // `-` is stdin or stdout, never a file
    let same = |x: &std::path::Path, y: &std::path::Path| {
        let named = |p: &std::path::Path| p.as_os_str() != "-";
        named(x) && named(y) && resolved(x).is_some_and(|x| resolved(y) == Some(x))
    };
    let scenario = std::path::Path::new(&a.scenario);
    let outputs = [
        ("--trace", &a.trace),
        ("--final-state", &a.final_state),
        ("--checkpoint", &a.checkpoint),
        ("--samples", &a.samples),
    ];
    for (k, &(flag, out)) in outputs.iter().enumerate() {
        let Some(out) = out else { continue };
        if same(out, scenario) && !(resuming && flag == "--checkpoint") {
            return Err(usage(format!(
                "{flag}: {} is the scenario file; writing it would destroy it",
                out.display()
            )));
        }
        for &(other, theirs) in &outputs[k + 1..] {
            if theirs.as_ref().is_some_and(|o| same(out, o)) {
                return Err(usage(format!(
                    "{flag} and {other}: both name {}; give two files",
                    out.display()
                )));
            }
        }
    }
    Ok(())
}

/// Refuses options the chosen engine does not take.
pub fn check_options_fit(a: &RunArgs, engine: &EngineKind) -> Result<(), Failure> {
    let objects = !matches!(
        engine,
        EngineKind::EventList | EngineKind::TimeStep { .. } | EngineKind::Regions { .. }
    );
    let regions = matches!(engine, EngineKind::Regions { .. });
    let time_warp = regions || matches!(engine, EngineKind::TimeWarp { .. });
    if a.regions.is_some() && !regions {
        return Err(usage("--regions: only the regions engine takes it"));
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
        ("--tw-burst", a.tw_burst.is_some()),
    ] {
        if given && !time_warp {
            return Err(usage(format!(
                "{flag}: only the time-warp and regions engines take it"
            )));
        }
    }
    if a.sample_every.is_some() && a.samples.is_none() && a.observe.is_none() {
        return Err(usage(
            "--sample-every: only --samples and --observe take samples",
        ));
    }
    let sampling = [
        ("--samples", a.samples.is_some()),
        ("--observe", a.observe.is_some()),
    ];
    if let Some((flag, _)) = sampling.iter().find(|(_, given)| *given) {
        if sectored
            || matches!(
                engine,
                EngineKind::TimeStep { .. } | EngineKind::Regions { .. }
            )
        {
            return Err(usage(format!(
                "{flag}: the event-list engine, and the objects and time-warp engines without \
                 sectors, take samples"
            )));
        }
    }
    Ok(())
}

/// The time between samples that `--samples` asks for, checked (`None` without it).
fn sample_every(a: &RunArgs, start: f64, until: f64) -> Result<Option<f64>, Failure> {
    if a.samples.is_none() && wanted_structure(a)? == Wanted::default() {
        return Ok(None);
    }
    match a.sample_every {
        Some(dt) if !(dt.is_finite() && dt > 0.0) => Err(usage(format!(
            "--sample-every: must be a positive number, got {dt}"
        ))),
        Some(dt) => Ok(Some(dt)),
        None => Ok(Some(poolsim::render::default_frame_time(until - start))),
    }
}

/// Runs `poolsim run`: the scenario on its engine, the trace as it goes, then the final state
/// and the summary.
pub fn run(a: &RunArgs) -> Result<(), Failure> {
    // a built-in is generated in memory: refuse what no engine could hold before that
    if let Some(n) = a.gen.balls {
        let least = poolsim::memory::least(n);
        fits(a.memory_limit, least, || {
            format!(
                "--balls: {n} balls need at least {} on any engine",
                human_bytes(least)
            )
        })?;
    }
    let scenario = load(&a.scenario, &a.gen)?;
    run_from(a, &scenario, None)
}

/// The settings of a run of `scenario` from its start, or from checkpoint `from` (whose
/// scenario it is), as the arguments ask, checked.
fn config_of(
    a: &RunArgs,
    scenario: &Scenario,
    from: Option<&Checkpoint>,
) -> Result<RunConfig, Failure> {
    let engine = engine_of(a, scenario)?;
    check_memory(a, scenario, &engine)?;
    // huge pages pay where memory is laid out once (the event list; regions on the sequential
    // executor), and cost where Time Warp touches fresh memory all run long
    if !matches!(
        engine,
        EngineKind::EventList | EngineKind::TimeStep { .. } | EngineKind::Regions { tw: None, .. }
    ) {
        poolsim::memory::transparent_huge_pages(false);
    }
    check_options_fit(a, &engine)?;
    check_outputs_apart(a, from.is_some())?;
    let until = a.until.unwrap_or(from.map_or(scenario.until, |c| c.until));
    if !until.is_finite() || until < 0.0 {
        return Err(usage(format!(
            "--until: must be a finite number not below 0, got {until}"
        )));
    }
    let start = from.map_or(0.0, |c| c.t);
    Ok(RunConfig {
        checkpoint_every: checkpoint_every(a, &engine, start, until)?,
        thermostat: thermostat(a)?,
        engine,
        until,
        check: a.check,
        span: Span {
            start,
            frame_time: sample_every(a, start, until)?,
            ..Span::default()
        },
        interrupt: None,
    })
}

/// The thermostat `a` asks for: `--thermostat-rate` and `--thermostat-seed` need
/// `--thermostat`.
fn thermostat(a: &RunArgs) -> Result<Option<poolsim::thermostat::Thermostat>, Failure> {
    let Some(kt) = a.thermostat else {
        if a.thermostat_rate.is_some() || a.thermostat_seed.is_some() {
            return Err(usage(
                "--thermostat-rate and --thermostat-seed need --thermostat KT",
            ));
        }
        return Ok(None);
    };
    Ok(Some(poolsim::thermostat::Thermostat {
        kt,
        rate: a.thermostat_rate.unwrap_or(0.1),
        seed: a.thermostat_seed.unwrap_or(1),
    }))
}

/// Runs `scenario` as `a` asks, from its start or from checkpoint `from`: the trace as it goes
/// (continuing `from`'s), checkpoints, then the final state and the summary.
pub fn run_from(
    a: &RunArgs,
    scenario: &Scenario,
    from: Option<&Checkpoint>,
) -> Result<(), Failure> {
    // the engines on Time Warp run across ranks: their layout counts every rank's workers
    #[cfg(feature = "mpi")]
    let _mpi = if matches!(a.engine, Engine::TimeWarp | Engine::Regions) {
        start_mpi()?
    } else {
        None
    };
    let mut cfg = config_of(a, scenario, from)?;
    let interrupt = Interrupt::new();
    stop_on_signals(&interrupt)?;
    cfg.interrupt = Some(interrupt.clone());
    // under MPI only rank 0 writes anything
    let root = pdes_kernel::time_warp::threads::collects_results();
    let mark = from.and_then(|c| c.trace.as_ref());
    let mut trace = match a.trace.as_ref().filter(|_| root) {
        Some(p) => Some(open_trace(p, mark)?),
        None => None,
    };
    let saver = a.checkpoint.as_ref().filter(|_| root).map(|p| Saver {
        path: p.clone(),
        trace_path: a
            .trace
            .as_ref()
            .filter(|t| t.as_os_str() != "-")
            .map(|t| t.display().to_string()),
        base: from.map(|c| (c.events, c.initial_energy)),
    });
    let mut progress = Progress::new(cfg.until, a.quiet || !root, a.trace.as_deref());
    let mut samples = match a.samples.as_ref().filter(|_| root) {
        Some(p) => Some(Samples::create(p)?),
        None => None,
    };
    let mut observables = observables(a, scenario, &cfg)?;
    let mut structure = structure(a, scenario)?;
    let report = {
        let mut sinks = Sinks {
            trace: trace.as_mut(),
            progress: progress.as_mut(),
            saver: saver.as_ref(),
            samples: samples.as_mut(),
            observables: observables.as_mut(),
            structure: structure.as_mut(),
        };
        execute(scenario, &cfg, &mut sinks)
    };
    if let Some(s) = samples {
        s.finish()?;
    }
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
        t.writer.finish().map_err(|e| trace_failed(&e))?;
    }
    let mut report = report.map_err(|e| match e {
        RunError::Output(m) => trace_failed(&m),
        e => run_failure(e),
    })?;
    if !root {
        return interrupted(&interrupt, report.outcome.t);
    }
    if let Some(c) = from {
        count_from(&mut report.summary, c);
    }
    report.summary.observables = observables.map(|o| o.finish(report.outcome.t));
    report.summary.structure = structure.map(Structure::finish);
    if let Some(p) = &a.final_state {
        write_final_state(p, &report.outcome, scenario)?;
    }
    print_summary(a, &report.summary)?;
    interrupted(&interrupt, report.outcome.t)
}

/// The structural observables `--observe` names.
fn wanted_structure(a: &RunArgs) -> Result<Wanted, Failure> {
    a.observe
        .as_deref()
        .map_or(Ok(Wanted::default()), Wanted::parse)
        .map_err(usage)
}

/// The structural observables `--observe` asks for, g(r) out to `--gr-max`.
fn structure(a: &RunArgs, scenario: &Scenario) -> Result<Option<Structure>, Failure> {
    let wanted = wanted_structure(a)?;
    if wanted == Wanted::default() {
        return match a.gr_max {
            Some(_) => Err(usage("--gr-max: needs --observe gr")),
            None => Ok(None),
        };
    }
    let table = poolsim::engine::Table::new(scenario);
    let rmax = scenario.balls.iter().map(|b| b.radius).fold(0.0, f64::max);
    let size = table.hi - table.lo;
    let reach = a.gr_max.unwrap_or_else(|| match table.period {
        Some(_) => (10.0 * rmax).min(size.x.min(size.y) / 2.0),
        None => 10.0 * rmax,
    });
    let from = a.observe_from.unwrap_or(f64::NEG_INFINITY);
    Structure::new(wanted, &table, from, reach)
        .map(Some)
        .map_err(usage)
}

/// The observables `--observe-every` and `--observe-from` ask for, checked against the run.
fn observables(
    a: &RunArgs,
    scenario: &Scenario,
    cfg: &RunConfig,
) -> Result<Option<poolsim::observe::Observables>, Failure> {
    let Some(every) = a.observe_every else {
        return match a.observe_from {
            Some(_) if a.observe.is_none() => {
                Err(usage("--observe-from: needs --observe-every or --observe"))
            }
            _ => Ok(None),
        };
    };
    let span = (cfg.span.start, cfg.until);
    poolsim::observe::Observables::over(scenario, span, a.observe_from, every)
        .map(Some)
        .map_err(|e| {
            let flag = if e.is_about_every() {
                "--observe-every"
            } else {
                "--observe-from"
            };
            usage(format!("{flag}: {e}"))
        })
}

/// The summary of a run taken up from checkpoint `c` counts the events before it, and the
/// energy at the first run's start.
fn count_from(summary: &mut RunSummary, c: &Checkpoint) {
    summary.events = crate::checkpoints::add(c.events, summary.events);
    let ke = &summary.kinetic_energy;
    summary.kinetic_energy = KineticEnergy::new(c.initial_energy, ke.end, ke.pocketed);
}

/// `--checkpoint-every`, checked: a positive time, the whole run by default (a checkpoint at
/// the end and where an interrupt stops the run); not on the time-step engine.
fn checkpoint_every(
    a: &RunArgs,
    engine: &EngineKind,
    start: f64,
    until: f64,
) -> Result<Option<f64>, Failure> {
    let Some(path) = &a.checkpoint else {
        return match a.checkpoint_every {
            Some(_) => Err(usage("--checkpoint-every: give --checkpoint FILE too")),
            None => Ok(None),
        };
    };
    if matches!(engine, EngineKind::TimeStep { .. }) {
        return Err(usage(
            "--checkpoint: the time-step engine cannot be taken up exactly (its state is its \
             grid of steps)",
        ));
    }
    if path.as_os_str() == "-" {
        return Err(usage("--checkpoint: give a file (not -)"));
    }
    match a.checkpoint_every {
        Some(t) if !(t.is_finite() && t > 0.0) => Err(usage(format!(
            "--checkpoint-every: must be a positive time, got {t}"
        ))),
        Some(t) => Ok(Some(t)),
        None => Ok(Some((until - start).max(f64::MIN_POSITIVE))),
    }
}

/// Prints the summary (human or `--json`): on stdout, or on stderr when the trace is there.
fn print_summary(a: &RunArgs, summary: &RunSummary) -> Result<(), Failure> {
    if !a.json && a.quiet {
        return Ok(());
    }
    let to_stdout = a.trace.as_ref().is_none_or(|p| p.as_os_str() != "-");
    let text = if a.json {
        serde_json::to_string(summary).expect("plain data") + "\n"
    } else {
        human_summary(summary)
    };
    let written = if to_stdout {
        std::io::stdout().write_all(text.as_bytes())
    } else {
        std::io::stderr().write_all(text.as_bytes())
    };
    written.map_err(|e| usage(format!("writing the summary failed: {e}")))
}

/// Writes the final state of `outcome` to `p` as pretty JSON.
fn write_final_state(
    p: &std::path::Path,
    outcome: &poolsim::engine::Outcome,
    scenario: &Scenario,
) -> Result<(), Failure> {
    let fs = FinalState::new(outcome.t, &outcome.balls, scenario);
    let text = serde_json::to_string_pretty(&fs).expect("a final state serializes");
    std::fs::write(p, text + "\n").map_err(|e| {
        usage(format!(
            "{}: cannot write the final state: {e}",
            p.display()
        ))
    })
}

/// Trace, progress, checkpoints and samples, each optional.
pub struct Sinks<'a> {
    pub trace: Option<&'a mut Trace>,
    pub progress: Option<&'a mut Progress>,
    pub saver: Option<&'a Saver>,
    pub samples: Option<&'a mut Samples>,
    pub observables: Option<&'a mut poolsim::observe::Observables>,
    pub structure: Option<&'a mut Structure>,
}

/// The samples file: extended XYZ frames written as the run reaches each sample time. The first
/// failure to write is kept, and reported once the run is over.
pub struct Samples {
    path: PathBuf,
    out: std::io::BufWriter<std::fs::File>,
    failed: Option<std::io::Error>,
}

impl Samples {
    /// Creates (or empties) the file before the run, so that a path that cannot be written
    /// fails at once.
    fn create(path: &std::path::Path) -> Result<Samples, Failure> {
        let file = std::fs::File::create(path)
            .map_err(|e| usage(format!("{}: cannot write the samples: {e}", path.display())))?;
        Ok(Samples {
            path: path.to_path_buf(),
            out: std::io::BufWriter::new(file),
            failed: None,
        })
    }

    /// Flushes the file, or reports the first failure to write it.
    fn finish(mut self) -> Result<(), Failure> {
        use std::io::Write;
        let flushed = self.out.flush();
        match self.failed.map_or(flushed, Err) {
            Ok(()) => Ok(()),
            Err(e) => Err(usage(format!(
                "{}: writing the samples failed: {e}",
                self.path.display()
            ))),
        }
    }
}

impl Observer for Sinks<'_> {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        if let Some(t) = &mut self.trace {
            t.writer.on_event(ev, world)?;
        }
        if let Some(p) = &mut self.progress {
            p.on_event(ev, world)?;
        }
        if let Some(o) = &mut self.observables {
            o.on_event(ev, world)?;
        }
        Ok(())
    }

    fn on_kick(&mut self, ball: u32, t: f64, world: &dyn World) -> Result<(), RunError> {
        match &mut self.observables {
            Some(o) => o.on_kick(ball, t, world),
            None => Ok(()),
        }
    }

    fn reads_balls(&self) -> bool {
        self.observables.is_some() || self.progress.as_ref().is_some_and(|p| p.reads_balls())
    }

    fn on_checkpoint(&mut self, checkpoint: Checkpoint) -> Result<(), RunError> {
        match self.saver {
            Some(s) => s.save(checkpoint, self.trace.as_deref_mut()),
            None => Ok(()),
        }
    }

    fn on_frame(
        &mut self,
        frame: &poolsim::engine::Frame,
        table: &poolsim::engine::Table,
    ) -> Result<(), RunError> {
        if let Some(s) = self.samples.as_deref_mut().filter(|s| s.failed.is_none()) {
            s.failed = poolsim::samples::write_frame(&mut s.out, frame, table).err();
        }
        match self.structure.as_deref_mut() {
            Some(s) => s.on_frame(frame, table),
            None => Ok(()),
        }
    }
}

/// The summary as the human reads it, one line per item.
pub fn human_summary(s: &RunSummary) -> String {
    let ev = &s.events;
    let ke = &s.kinetic_energy;
    let checked = if s.checked {
        ", invariants checked at every event"
    } else {
        ""
    };
    let mut lines = vec![
        format!("scenario      {}", s.scenario),
        format!("engine        {}", s.engine),
        format!("balls         {}", s.balls),
        format!("until         {:?}", s.until),
        format!(
            "events        {} (ball-ball {}, ball-cushion {}, ball-corner {}, ball-pocket {})",
            ev.total, ev.ball_ball, ev.ball_cushion, ev.ball_corner, ev.ball_pocket
        ),
        format!(
            "energy        initial {:?}, final {:?} on the table + {:?} in pockets (relative drift {:e})",
            ke.initial, ke.end, ke.pocketed, ke.relative_drift
        ),
        format!("digest        {}", s.final_state_digest),
        format!(
            "wall          {:.3} s ({:.3} s set-up), {:.0} events/s{checked}",
            s.wall_seconds, s.setup_seconds, s.events_per_second
        ),
    ];
    if !matches!(s.engine.as_str(), "event-list" | "time-step" | "regions") {
        let m = &s.messages;
        lines.push(format!(
            "messages      {} (thesis table 5 total: NewVelocity {}, Collision {}, Cancel {}, \
             VelocityChange {}, SectorEntry {}, SectorDeparture {})",
            m.total,
            m.NewVelocity,
            m.Collision,
            m.Cancel,
            m.VelocityChange,
            m.SectorEntry,
            m.SectorDeparture
        ));
    }
    if let Some(r) = &s.regions {
        let news: u64 = ["GhostEnter", "GhostUpdate", "GhostLeave", "Handover"]
            .iter()
            .map(|k| r.messages.get(*k).copied().unwrap_or(0))
            .sum();
        lines.push(format!(
            "regions       {} strips of {:?} grid columns, balls {:?} at the start; {:.2} % of \
             events across a border; {} messages between regions, {} wake-ups",
            r.count,
            r.columns,
            r.balls_start,
            100.0 * r.fraction_across,
            news,
            r.messages.get("Wake").copied().unwrap_or(0)
        ));
    }
    if let Some(tw) = &s.time_warp {
        let st = &tw.stats;
        let count = |n: u64, one: &str| match n {
            1 => format!("1 {one}"),
            m => format!("{m} {one}s"),
        };
        lines.push(format!(
            "time warp     {} on {}: efficiency {:.3}, {:.0} % of batches final, {} rollbacks, \
             {:.2} % of messages remote, {} GVT rounds",
            count(st.workers, "worker"),
            count(st.ranks, "rank"),
            tw.efficiency,
            100.0 * st.final_batches as f64 / st.committed.max(1) as f64,
            st.rollbacks,
            100.0 * tw.remote_fraction,
            st.gvt_rounds
        ));
    }
    if let Some(o) = &s.observables {
        lines.push(format!(
            "observed      {} blocks of {:?} from t = {:?}: Z = {:.5} ± {:.5}, P = {:.6e} ± {:.1e} \
             (cushions {:.6e} ± {:.1e}), kT = {:.6e}, {:.4} collisions per ball and unit time",
            o.blocks,
            o.every,
            o.from,
            o.z.mean,
            o.z.error,
            o.pressure.mean,
            o.pressure.error,
            o.pressure_walls.mean,
            o.pressure_walls.error,
            o.kt.mean,
            o.collision_rate.mean
        ));
    }
    if let Some(st) = &s.structure {
        lines.extend(structure_lines(st));
    }
    if let Some(i) = &s.interrupted {
        lines.push(format!(
            "interrupted   by {} at t = {:?}, every event up to it done",
            i.signal, i.at
        ));
    }
    lines.join("\n") + "\n"
}

/// The summary's lines for the structure: g's highest peak, the last MSD, the mean of ψ6.
fn structure_lines(st: &poolsim::structure::StructureFigures) -> Vec<String> {
    let mut lines = Vec::new();
    if let Some(gr) = &st.gr {
        let (k, g) = gr.g.iter().enumerate().fold(
            (0, 0.0),
            |best, (k, &g)| if g > best.1 { (k, g) } else { best },
        );
        lines.push(format!(
            "g(r)          over {} samples: highest {g:.4} at r = {:.4}",
            gr.samples,
            gr.r.get(k).copied().unwrap_or(0.0)
        ));
    }
    if let (Some(m), true) = (&st.msd, st.msd.as_ref().is_some_and(|m| !m.t.is_empty())) {
        lines.push(format!(
            "msd           {:.6e} after {:?}",
            m.value[m.value.len() - 1],
            m.t[m.t.len() - 1]
        ));
    }
    if let Some(p) = st.psi6.as_ref().filter(|p| !p.value.is_empty()) {
        let mean = p.value.iter().sum::<f64>() / p.value.len() as f64;
        lines.push(format!(
            "psi6          mean {mean:.4} over {} samples",
            p.value.len()
        ));
    }
    lines
}

/// Refuses a run whose estimated memory is more than it may take, before it allocates; says
/// so, unless quiet, when the engine grows with the square of the balls.
fn check_memory(a: &RunArgs, scenario: &Scenario, engine: &EngineKind) -> Result<(), Failure> {
    let n = scenario.balls.len();
    let need = poolsim::memory::estimate(n, engine);
    fits(a.memory_limit, need.bytes, || {
        format!(
            "{}: {n} balls on the {} engine{} need about {}",
            a.scenario,
            engine.name(),
            if need.quadratic {
                " without sectors"
            } else {
                ""
            },
            human_bytes(need.bytes)
        )
    })?;
    if need.quadratic && need.bytes > QUADRATIC_NOTE && !a.quiet {
        eprintln!(
            "poolsim: note: without sectors every ball object keeps a record of every other \
             ball: {n} balls need about {} and a set-up that grows as the square of the balls \
             (--sectors auto keeps both linear)",
            human_bytes(need.bytes)
        );
    }
    Ok(())
}

/// Above this estimate, a run whose memory grows as the square of the balls says so.
const QUADRATIC_NOTE: u64 = 256 << 20;

/// Checks `need` bytes against `limit`, or against what is available; the refusal is
/// `what()` and why, one line, exit 2.
fn fits(limit: Option<MemoryLimit>, need: u64, what: impl Fn() -> String) -> Result<(), Failure> {
    let (room, source) = match limit {
        Some(MemoryLimit::None) => return Ok(()),
        Some(MemoryLimit::Bytes(b)) => (b, "--memory-limit"),
        None => match poolsim::memory::available() {
            Some(a) => (a.bytes, a.source),
            None => return Ok(()),
        },
    };
    if need <= room {
        return Ok(());
    }
    let hint = if limit.is_some() {
        ""
    } else {
        "; --memory-limit SIZE or none overrides the check"
    };
    Err(usage(format!(
        "{}, more than the {} this run may take ({source}){hint}",
        what(),
        human_bytes(room)
    )))
}
