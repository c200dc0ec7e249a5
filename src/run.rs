//! One run of one engine on one scenario, with its sinks, and the run summary of DESIGN.md.
//!
//! This is the whole pipeline `scenario → engine → committed events → sinks` behind
//! `poolsim run`, `poolsim demo` and `poolsim bench`; the binary only parses arguments.

use crate::check::Checker;
use crate::engine::event_list::{self, EventList};
use crate::engine::objects::Objects;
use crate::engine::time_step::{self, TimeStep};
use crate::engine::{BallState, Event, Observer, Outcome, RunError, Span, Table, World};
use crate::model::pool::NvDelay;
use crate::output::{digest, events_json};
use crate::physics::kinetic_energy;
use crate::scenario::Scenario;
use serde_json::{json, Value};
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
}

impl EngineKind {
    /// The name used on the command line and in summaries.
    pub fn name(self) -> &'static str {
        match self {
            EngineKind::EventList => "event-list",
            EngineKind::TimeStep { .. } => "time-step",
            EngineKind::Objects { .. } => "objects",
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
}

/// What a run produced.
#[derive(Clone, Debug)]
pub struct Report {
    /// The engine's outcome.
    pub outcome: Outcome,
    /// Wall-clock seconds spent in the engine (setup included).
    pub wall_seconds: f64,
    /// The largest relative energy drift the checker saw, when checking.
    pub max_energy_drift: Option<f64>,
    /// The run summary (`--json`).
    pub summary: Value,
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

/// Forwards events to an optional checker, then to the caller's observer.
struct Sinks<'a> {
    checker: Option<Checker>,
    user: &'a mut dyn Observer,
}

impl Observer for Sinks<'_> {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        if let Some(c) = &mut self.checker {
            c.on_event(ev, world)?;
        }
        self.user.on_event(ev, world)
    }
}

/// Runs `scenario` as `cfg` says, passing every event to `obs`.
pub fn execute(
    scenario: &Scenario,
    cfg: &RunConfig,
    obs: &mut dyn Observer,
) -> Result<Report, RunError> {
    let start = Instant::now();
    let initial = BallState::initial(scenario, cfg.span.start);
    let table = Table::new(scenario);
    let checker = cfg
        .check
        .then(|| Checker::new(&initial, table.is_elastic()));
    let mut sinks = Sinks { checker, user: obs };
    let outcome = match cfg.engine {
        EngineKind::EventList => {
            let opts = event_list::Options {
                span: cfg.span,
                ..Default::default()
            };
            let mut e = EventList::new(scenario, opts);
            let out = e.run(cfg.until, &mut sinks)?;
            if let Some(c) = &mut sinks.checker {
                c.sweep(&e, cfg.until.min(out.t))?;
            }
            out
        }
        EngineKind::TimeStep { dt } => {
            let mut e = TimeStep::new(scenario, time_step::Options { dt, span: cfg.span });
            e.run(cfg.until, &mut sinks)?
        }
        EngineKind::Objects { delay } => {
            let mut e = Objects::new(scenario, delay, cfg.span);
            e.run(cfg.until, &mut sinks)?
        }
    };
    let wall = start.elapsed().as_secs_f64();
    let (e0, _) = energies(&initial);
    let (e1, ep) = energies(&outcome.balls);
    let n_events = outcome.events.total();
    let mut stats = serde_json::Map::new();
    for (k, v) in &outcome.engine_stats {
        stats.insert((*k).to_string(), json!(v));
    }
    let max_drift = sinks.checker.as_ref().map(|c| c.max_energy_drift);
    let summary = json!({
        "scenario": scenario.name,
        "engine": cfg.engine.name(),
        "balls": scenario.balls.len(),
        "until": cfg.until,
        "events": events_json(&outcome.events),
        "messages": messages_json(&outcome.messages),
        "kinetic_energy": {
            "initial": e0,
            "final": e1,
            "pocketed": ep,
            "relative_drift": if e0 > 0.0 { (e1 + ep - e0) / e0 } else { 0.0 },
        },
        "final_state_digest": digest(outcome.t, &outcome.balls),
        "wall_seconds": wall,
        "events_per_second": if wall > 0.0 { n_events as f64 / wall } else { 0.0 },
        "checked": cfg.check,
        "engine_stats": stats,
    });
    Ok(Report {
        outcome,
        wall_seconds: wall,
        max_energy_drift: max_drift,
        summary,
    })
}

/// The thesis' message types that count towards its totals (table 5).
const THESIS_TOTAL: [&str; 6] = [
    "VelocityChange",
    "NewVelocity",
    "SectorDeparture",
    "SectorEntry",
    "Cancel",
    "Collision",
];

/// The summary's `messages` object: every type DESIGN.md names, zero where the engine sends none
/// (the event-list and time-step engines send no messages at all), and the thesis' `total`.
fn messages_json(sent: &[(&'static str, u64)]) -> Value {
    let count = |name: &str| sent.iter().find(|(n, _)| *n == name).map_or(0, |(_, c)| *c);
    let mut m = serde_json::Map::new();
    for name in [
        "NewVelocity",
        "Collision",
        "Cancel",
        "VelocityChange",
        "SectorEntry",
        "SectorDeparture",
        "VelocityInitialization",
        "DisplayYourself",
        "ReverseYourself",
        "ReturnToTable",
    ] {
        m.insert(name.into(), count(name).into());
    }
    let total: u64 = THESIS_TOTAL.iter().map(|n| count(n)).sum();
    m.insert("total".into(), total.into());
    Value::Object(m)
}
