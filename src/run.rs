//! One run of one engine on one scenario, with its sinks, and its [`RunSummary`].
//!
//! This is the whole pipeline `scenario → engine → committed events → sinks` behind
//! `poolsim run`, `poolsim demo` and `poolsim bench`; the binary only parses arguments.

use crate::check::Checker;
use crate::checkpoint::Checkpoint;
use crate::engine::event_list::{self, EventList};
use crate::engine::objects::Objects;
use crate::engine::regions::RegionsEngine;
use crate::engine::time_step::{self, TimeStep};
use crate::engine::{
    BallState, Engine, Event, EventCounts, Frame, Observer, Outcome, RunError, Span, Table, World,
};
use crate::model::pool::NvDelay;
/// Which balls tell the fixed objects of a sectored table (re-exported for engine choices).
pub use crate::model::sectored::FixedNews;
use crate::model::sectored::Layout;
use crate::output::digest;
use crate::physics::kinetic_energy;
use crate::polygon::{LayoutError, Polygon, PolygonError};
use crate::scenario::Scenario;
use crate::scenario::SectorSpec;
use crate::summary::{
    EventTotals, Interruption, KineticEnergy, MessageCounts, RunSummary, TimeWarpSummary,
};
use pdes_kernel::time_warp::TwConfig;
use pdes_kernel::Interrupt;
use std::time::Instant;

/// Which engine runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EngineKind {
    /// The event-list engine (thesis fig. 2), the reference.
    EventList,
    /// The time-step engine (thesis fig. 1) with step `dt`.
    TimeStep {
        /// The time step.
        dt: f64,
    },
    /// The objects engine (thesis fig. 3), sequential, non-sectored.
    Objects {
        /// How NewVelocity messages travel.
        delay: NvDelay,
    },
    /// The objects engine on a sectored table (thesis fig. 14), sequential.
    Sectored {
        /// How the table is cut into sectors.
        sectors: SectorChoice,
        /// Which balls tell the fixed objects of their trajectories.
        news: FixedNews,
    },
    /// The objects run optimistically in parallel by Time Warp, plain or sectored.
    TimeWarp {
        /// Workers, chaos, throttles.
        tw: TwConfig,
        /// How NewVelocity messages travel (plain objects).
        delay: NvDelay,
        /// How the table is cut into sectors; `None`: not sectored.
        sectors: Option<SectorChoice>,
        /// Which balls tell the fixed objects of their trajectories (sectored).
        news: FixedNews,
    },
    /// The event list cut into strips of the table, each a kernel object: sequential, or in
    /// parallel under Time Warp.
    Regions {
        /// How many strips.
        count: u32,
        /// Time Warp's workers, chaos and throttles; `None`: the sequential executor.
        tw: Option<TwConfig>,
    },
}

/// How a sectored run cuts the table (`--sectors`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SectorChoice {
    /// A grid from the analytic model of chapter 7: about eight balls per sector.
    Auto,
    /// An `nx` × `ny` grid over the table's box.
    Grid(u32, u32),
    /// The scenario's own `[sectors]` (a grid or polygons).
    Scenario,
}

/// Why a sector choice gives no layout on a scenario ([`sector_layout`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SectorLayoutError {
    /// The scenario's own sectors were asked for, and it has none.
    #[error("the scenario has no [sectors]")]
    NoSectors,
    /// One of the scenario's polygons is not a simple polygon.
    #[error("sectors.polygon[{index}]: {source}")]
    Polygon {
        /// Which polygon, counted from 1.
        index: usize,
        /// What is wrong with it.
        #[source]
        source: PolygonError,
    },
    /// The scenario's polygons do not tile the table.
    #[error(transparent)]
    Layout(#[from] LayoutError),
}

/// The sector layout a choice gives on a scenario, or what is wrong with it.
pub fn sector_layout(s: &Scenario, choice: SectorChoice) -> Result<Layout, SectorLayoutError> {
    let table = Table::new(s);
    Ok(match choice {
        SectorChoice::Auto => Layout::auto(&table, s.balls.len()),
        SectorChoice::Grid(nx, ny) => Layout::grid(&table, nx, ny),
        SectorChoice::Scenario => match &s.sectors {
            None => return Err(SectorLayoutError::NoSectors),
            Some(SectorSpec::Grid { nx, ny }) => Layout::grid(&table, *nx, *ny),
            Some(SectorSpec::Polygons(polys)) => {
                let mut out = Vec::new();
                for (k, p) in polys.iter().enumerate() {
                    out.push(Polygon::new(p.clone()).map_err(|source| {
                        SectorLayoutError::Polygon {
                            index: k + 1,
                            source,
                        }
                    })?);
                }
                Layout::new(out, &table)?
            }
        },
    })
}

impl EngineKind {
    /// The name used on the command line and in summaries.
    pub fn name(self) -> &'static str {
        match self {
            EngineKind::EventList => "event-list",
            EngineKind::TimeStep { .. } => "time-step",
            EngineKind::Objects { .. } | EngineKind::Sectored { .. } => "objects",
            EngineKind::TimeWarp { .. } => "time-warp",
            EngineKind::Regions { .. } => "regions",
        }
    }
}

/// How to run.
#[derive(Clone, Debug)]
pub struct RunConfig {
    /// The engine.
    pub engine: EngineKind,
    /// End time.
    pub until: f64,
    /// Check invariants at every event.
    pub check: bool,
    /// Start time and reversal.
    pub span: Span,
    /// Ends the run early and cleanly once raised (a signal handler raises it with the
    /// signal's number): the run stops at a time of the engine's choosing, every event up to
    /// it reported, and its report says so.
    pub interrupt: Option<Interrupt>,
    /// Simulation time between checkpoints: the run stops at each multiple of it after the
    /// start (and where an interrupt stops it, and at its end) and hands its observer a
    /// [`Checkpoint`]. Not on the time-step engine, whose state is its grid of steps.
    pub checkpoint_every: Option<f64>,
    /// Andersen's thermostat (event-list engine only; not with checkpoints, which do not
    /// carry its generator).
    pub thermostat: Option<crate::thermostat::Thermostat>,
}

/// What a run produced.
#[derive(Clone, Debug)]
pub struct Report {
    /// The engine's outcome.
    pub outcome: Outcome,
    /// Wall-clock seconds spent in the engine (setup included).
    pub wall_seconds: f64,
    /// Of those, the seconds before the first event: building the engine and setting its
    /// objects up (their `init`s included).
    pub setup_seconds: f64,
    /// The largest relative energy drift the checker saw, when checking.
    pub max_energy_drift: Option<f64>,
    /// The run summary (`--json`).
    pub summary: RunSummary,
}

/// Total kinetic energy of balls on the table, and of balls carried into pockets.
fn energies(balls: &[BallState]) -> (f64, f64) {
    let mut on_table = 0.0;
    let mut pocketed = 0.0;
    for b in balls {
        let e = kinetic_energy(b.mass, b.traj.velocity);
        if b.pocket.is_some() {
            pocketed += e;
        } else {
            on_table += e;
        }
    }
    (on_table, pocketed)
}

/// The most steps a time-step run may take (each one moves and tests every ball).
pub const MAX_TIME_STEPS: f64 = 1e9;

/// Forwards events to an optional checker, then to the caller's observer.
pub(crate) struct Checked<'a> {
    /// The invariant checker, when checking.
    pub(crate) checker: Option<Checker>,
    /// The caller's observer.
    pub(crate) user: &'a mut dyn Observer,
}

impl Observer for Checked<'_> {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        if let Some(c) = &mut self.checker {
            c.on_event(ev, world)?;
        }
        self.user.on_event(ev, world)
    }

    fn reads_balls(&self) -> bool {
        self.checker.is_some() || self.user.reads_balls()
    }

    fn on_frame(&mut self, frame: &Frame, table: &Table) -> Result<(), RunError> {
        self.user.on_frame(frame, table)
    }

    fn on_checkpoint(&mut self, checkpoint: Checkpoint) -> Result<(), RunError> {
        self.user.on_checkpoint(checkpoint)
    }

    fn on_kick(&mut self, ball: u32, t: f64, world: &dyn World) -> Result<(), RunError> {
        if let Some(c) = &mut self.checker {
            c.on_kick(ball, t, world)?;
        }
        self.user.on_kick(ball, t, world)
    }
}

/// Refuses a ball so fast that it crosses its own radius in less time than the run's clock can
/// tell apart (10^4 units in the last place at the run's latest time): its events would pile up
/// at times that round together, and the run would never end.
fn check_time_resolution(scenario: &Scenario, cfg: &RunConfig) -> Result<(), RunError> {
    let latest = cfg.until.abs().max(cfg.span.start.abs()).max(1.0);
    let resolution = 1e4 * f64::EPSILON * latest;
    for (i, b) in scenario.balls.iter().enumerate() {
        let crossing = b.radius / b.velocity.norm();
        if crossing < resolution {
            return Err(RunError::Input(format!(
                "ball[{}].velocity: Ball-{} crosses its radius in {crossing:e} time units, \
                 below the {resolution:e} that times up to {latest:e} resolve",
                i + 1,
                i + 1
            )));
        }
    }
    Ok(())
}

/// The engine `cfg` asks for, set up on `scenario` and ready to run: the one factory of engines
/// (event list, time step, objects plain or sectored, sequential or under Time Warp).
pub fn build_engine(scenario: &Scenario, cfg: &RunConfig) -> Result<Box<dyn Engine>, RunError> {
    if scenario.periodic.is_some() && cfg.engine != EngineKind::EventList {
        return Err(RunError::Input(format!(
            "--engine {}: a periodic box runs on the event-list engine only",
            cfg.engine.name()
        )));
    }
    if let Some(t) = &cfg.thermostat {
        t.check().map_err(RunError::Input)?;
        if cfg.engine != EngineKind::EventList {
            return Err(RunError::Input(format!(
                "--thermostat: runs on the event-list engine only, not on {}",
                cfg.engine.name()
            )));
        }
        if cfg.checkpoint_every.is_some() {
            return Err(RunError::Input(
                "--thermostat: a checkpoint cannot carry the thermostat's generator; run \
                 without --checkpoint"
                    .into(),
            ));
        }
    }
    Ok(match cfg.engine {
        EngineKind::EventList => {
            let opts = event_list::Options {
                span: cfg.span,
                thermostat: cfg.thermostat,
                ..Default::default()
            };
            Box::new(EventList::new(scenario, opts))
        }
        EngineKind::TimeStep { .. } if scenario.balls.iter().any(|b| b.fixed.is_some()) => {
            return Err(RunError::Input(
                "the time-step engine does not take up a checkpoint: its state is its grid of \
                 steps"
                    .into(),
            ))
        }
        EngineKind::TimeStep { dt } => {
            let steps = (cfg.until - cfg.span.start) / dt;
            if steps > MAX_TIME_STEPS {
                return Err(RunError::Input(format!(
                    "--dt: {dt:?} makes {steps:.3e} steps from {:?} to {:?}, more than the \
                     {MAX_TIME_STEPS:e} the time-step engine takes",
                    cfg.span.start, cfg.until
                )));
            }
            Box::new(TimeStep::new(
                scenario,
                time_step::Options { dt, span: cfg.span },
            ))
        }
        EngineKind::Regions { count, tw } => {
            if cfg.span.frame_time.is_some() || cfg.span.reverse_at.is_some() {
                return Err(RunError::Input(
                    "--engine regions: draws no frames and runs no reversal yet; use the event \
                     list"
                        .into(),
                ));
            }
            if cfg.checkpoint_every.is_some() {
                return Err(RunError::Input(
                    "--engine regions: takes no checkpoints yet; use the event list".into(),
                ));
            }
            let engine = RegionsEngine::new(scenario, count, cfg.span.start, tw)
                .map_err(|e| RunError::Input(e.to_string()))?;
            Box::new(engine)
        }
        kind => Box::new(
            build_objects(scenario, kind, cfg.span)?.expect("every other kind runs objects"),
        ),
    })
}

/// The objects engine `kind` asks for (plain or sectored; sequential or Time Warp), set up on
/// `scenario` at `span`; `None` for the event-list and time-step engines, which run no objects.
pub fn build_objects(
    scenario: &Scenario,
    kind: EngineKind,
    span: Span,
) -> Result<Option<Objects>, RunError> {
    let layout = |sectors, news| {
        if span.frame_time.is_some() {
            return Err(RunError::Input(
                "the sectored engine draws no frames itself (poolsim render does)".into(),
            ));
        }
        // sectors cover the table alone: two balls that left it through a gap would meet in no
        // sector, unseen, where the event list sees them collide
        if !scenario.is_closed() {
            return Err(RunError::Input(
                "--sectors: a sectored run needs a closed table (this one has a gap: a ball that \
                 leaves through it leaves every sector, where the engine cannot see it meet \
                 another); run it without sectors"
                    .into(),
            ));
        }
        let mut layout = sector_layout(scenario, sectors)?;
        layout.fixed_news = news;
        Ok(layout)
    };
    Ok(Some(match kind {
        EngineKind::EventList | EngineKind::TimeStep { .. } | EngineKind::Regions { .. } => {
            return Ok(None)
        }
        EngineKind::Objects { delay } => Objects::new(scenario, delay, span),
        EngineKind::Sectored { sectors, news } => {
            Objects::sectored(scenario, layout(sectors, news)?, span)
        }
        EngineKind::TimeWarp {
            tw,
            delay,
            sectors,
            news,
        } => match sectors {
            None => Objects::plain_on(scenario, delay, span, Some(tw)),
            Some(choice) => Objects::sectored_on(scenario, layout(choice, news)?, span, Some(tw)),
        },
    }))
}

/// Runs `scenario` as `cfg` says, passing every event to `obs`.
pub fn execute(
    scenario: &Scenario,
    cfg: &RunConfig,
    obs: &mut dyn Observer,
) -> Result<Report, RunError> {
    let start = Instant::now();
    check_time_resolution(scenario, cfg)?;
    let initial = BallState::initial(scenario, cfg.span.start);
    let table = Table::new(scenario);
    let checker = cfg
        .check
        .then(|| Checker::new(&initial, table.is_elastic() && cfg.thermostat.is_none()));
    let mut sinks = Checked { checker, user: obs };
    let (e0, _) = energies(&initial);
    // the engine holds the balls from here on: a copy less at the peak of memory
    drop(initial);
    let mut engine = build_engine(scenario, cfg)?;
    if let Some(i) = &cfg.interrupt {
        engine.stop_on(i.clone());
    }
    // the engine built and its objects set up, before the first event
    let setup = start.elapsed().as_secs_f64();
    let outcome = if cfg.checkpoint_every.is_some() {
        run_with_checkpoints(engine.as_mut(), scenario, cfg, e0, &mut sinks)?
    } else {
        engine.run(cfg.until, &mut sinks)?
    };
    let time_warp = engine.tw_stats();
    let regions = engine.regions();
    engine.free();
    // every engine ends with a sweep of the state it ends in (a tunnelled ball has no event);
    // under MPI only rank 0 collects the final state
    let collects = pdes_kernel::time_warp::threads::collects_results();
    if let Some(c) = sinks.checker.as_mut().filter(|_| collects) {
        c.sweep_final(&table, &outcome.balls, outcome.t)?;
    }
    let wall = start.elapsed().as_secs_f64();
    let (e1, ep) = energies(&outcome.balls);
    let n_events = outcome.events.total();
    let engine_stats = outcome
        .engine_stats
        .iter()
        .map(|(k, v)| ((*k).to_string(), *v))
        .collect();
    let max_drift = sinks.checker.as_ref().map(|c| c.max_energy_drift);
    let summary = RunSummary {
        scenario: scenario.name.clone(),
        engine: cfg.engine.name().to_string(),
        balls: scenario.balls.len(),
        until: cfg.until,
        events: EventTotals::from(&outcome.events),
        messages: MessageCounts::from_named(&outcome.messages),
        kinetic_energy: KineticEnergy::new(e0, e1, ep),
        final_state_digest: digest(outcome.t, &outcome.balls),
        wall_seconds: wall,
        setup_seconds: setup,
        events_per_second: if wall > 0.0 {
            n_events as f64 / wall
        } else {
            0.0
        },
        checked: cfg.check,
        engine_stats,
        time_warp: time_warp.map(|tw| TimeWarpSummary::new(tw, crate::bench::peak_rss_mib())),
        interrupted: cfg
            .interrupt
            .as_ref()
            .and_then(Interrupt::cause)
            .map(|cause| Interruption::new(outcome.t, cause)),
        observables: None,
        structure: None,
        regions,
    };
    Ok(Report {
        outcome,
        wall_seconds: wall,
        setup_seconds: setup,
        max_energy_drift: max_drift,
        summary,
    })
}

/// Runs `engine` to `cfg.until` in stretches of `cfg.checkpoint_every`, handing `obs` a
/// checkpoint after each, after an interrupted one, and at the end; the outcome counts every
/// stretch's events.
fn run_with_checkpoints(
    engine: &mut dyn Engine,
    scenario: &Scenario,
    cfg: &RunConfig,
    initial_energy: f64,
    obs: &mut dyn Observer,
) -> Result<Outcome, RunError> {
    let every = cfg.checkpoint_every.expect("checkpoints asked for");
    if matches!(cfg.engine, EngineKind::TimeStep { .. }) {
        return Err(RunError::Input(
            "--checkpoint: the time-step engine cannot be taken up exactly".into(),
        ));
    }
    let mut events = EventCounts::default();
    for k in 1u64.. {
        let next = (cfg.span.start + k as f64 * every).min(cfg.until);
        let mut outcome = engine.run(next, obs)?;
        for (all, more) in events.by_kind.iter_mut().zip(outcome.events.by_kind) {
            *all += more;
        }
        outcome.events = events;
        let mut balls = engine
            .balls_to_take_up()
            .expect("every engine but the time-step one is taken up");
        // the engines hold physics alone: the balls keep their looks from the scenario
        for (b, spec) in balls.iter_mut().zip(&scenario.balls) {
            b.colour.clone_from(&spec.colour);
            b.label.clone_from(&spec.label);
        }
        obs.on_checkpoint(Checkpoint {
            format: crate::checkpoint::FORMAT.into(),
            version: crate::checkpoint::VERSION,
            t: outcome.t,
            until: cfg.until,
            engine: cfg.engine.name().into(),
            // the table alone is copied: the balls are the engine's
            scenario: Scenario {
                name: scenario.name.clone(),
                until: scenario.until,
                balls,
                cushions: scenario.cushions.clone(),
                pockets: scenario.pockets.clone(),
                sectors: scenario.sectors.clone(),
                periodic: scenario.periodic,
            },
            events: EventTotals::from(&events),
            initial_energy,
            trace: None,
        })?;
        // the end, or an interrupt before the stretch's end
        if outcome.t >= cfg.until || outcome.t < next {
            return Ok(outcome);
        }
    }
    unreachable!("a run ends")
}

/// What a reversal run (thesis 4.6–4.7) found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ReversalReport {
    /// The scenario.
    pub scenario: String,
    /// The engine.
    pub engine: &'static str,
    /// The run went from `-quit` to 0, reversed, and on to `quit`.
    pub quit: f64,
    /// Physical events (collisions and pocket crossings) over the whole run.
    pub events: u64,
    /// Events in the forward half (before the reversal).
    pub forward_events: u64,
    /// The largest distance between a ball's final and initial positions.
    pub max_position_error: f64,
    /// The largest difference between a ball's final velocity and its initial one reversed.
    pub max_velocity_error: f64,
    /// Balls still in a pocket at the end (they should all have come back).
    pub still_pocketed: usize,
    /// Wall-clock seconds.
    pub wall_seconds: f64,
    /// Every ball: where it was at `-quit` and where it is at `quit`.
    pub balls: Vec<ReversedBall>,
}

/// Where one ball of a reversal run started and ended.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ReversedBall {
    /// Its name.
    pub name: String,
    /// Its position at `-quit` (`null` if it started in a pocket).
    pub start: Option<[f64; 2]>,
    /// Its position at `quit` (`null` if it ended in a pocket).
    pub end: Option<[f64; 2]>,
}

/// Runs `scenario` from `-quit` to `quit` with every ball reversed at 0, and measures how far the
/// balls end from where they started (thesis 4.6: time reversibility as a test of accuracy).
pub fn reverse(
    scenario: &Scenario,
    engine: EngineKind,
    quit: f64,
    check: bool,
) -> Result<ReversalReport, RunError> {
    /// Counts events before the reversal.
    struct Forward(u64);
    impl Observer for Forward {
        fn on_event(&mut self, ev: &Event, _: &dyn World) -> Result<(), RunError> {
            if ev.t < 0.0 || (ev.t == 0.0 && ev.kind != crate::engine::EventKind::BallPocket) {
                self.0 += 1;
            }
            Ok(())
        }

        fn reads_balls(&self) -> bool {
            false
        }
    }
    let cfg = RunConfig {
        engine,
        until: quit,
        check,
        span: Span {
            start: -quit,
            reverse_at: Some(0.0),
            frame_time: None,
        },
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let mut forward = Forward(0);
    let report = execute(scenario, &cfg, &mut forward)?;
    let initial = BallState::initial(scenario, -quit);
    let table = crate::engine::Table::new(scenario);
    let place = |b: &BallState, t: f64| {
        let p = b.traj.at(t);
        b.pocket.is_none().then_some([p.x, p.y])
    };
    let balls = (report.outcome.balls.iter().zip(&initial))
        .enumerate()
        .map(|(i, (b, a))| ReversedBall {
            name: table.name(i as u32),
            start: place(a, -quit),
            end: place(b, quit),
        })
        .collect();
    let mut pos = 0.0f64;
    let mut vel = 0.0f64;
    let mut still = 0;
    for (b, a) in report.outcome.balls.iter().zip(&initial) {
        if b.pocket.is_some() {
            still += 1;
            continue;
        }
        pos = pos.max((b.traj.at(quit) - a.traj.position).norm());
        vel = vel.max((b.traj.velocity + a.traj.velocity).norm());
    }
    Ok(ReversalReport {
        scenario: scenario.name.clone(),
        engine: engine.name(),
        quit,
        events: report.outcome.events.total(),
        forward_events: forward.0,
        max_position_error: pos,
        max_velocity_error: vel,
        still_pocketed: still,
        wall_seconds: report.wall_seconds,
        balls,
    })
}
