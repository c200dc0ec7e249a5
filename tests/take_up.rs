//! Checkpoints: a run cut into stretches equals the run in one go, and a run taken up from any
//! checkpoint, on any engine, executes the same events and ends in the same state as the run
//! that never stopped (the built-in gas and the break, with balls in pockets).

mod common;

use common::two_workers;
use poolsim::checkpoint::Checkpoint;
use poolsim::engine::Span;
use poolsim::engine::{Event, Observer, RunError, World};
use poolsim::model::pool::NvDelay;
use poolsim::output::{TraceLine, TraceRecorder};
use poolsim::run::{execute, EngineKind, FixedNews, RunConfig, SectorChoice};
use poolsim::scenario::{builtin, Scenario};

/// A trace and the checkpoints handed over.
#[derive(Default)]
struct Kept {
    trace: TraceRecorder,
    checkpoints: Vec<Checkpoint>,
}

impl Observer for Kept {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        self.trace.on_event(ev, world)
    }

    fn reads_balls(&self) -> bool {
        false
    }

    fn on_checkpoint(&mut self, checkpoint: Checkpoint) -> Result<(), RunError> {
        self.checkpoints.push(checkpoint);
        Ok(())
    }
}

/// Runs `s` from `start` to `until` on `engine`, with checkpoints every `every`: the trace,
/// the final digest and the checkpoints.
fn run(
    s: &Scenario,
    engine: EngineKind,
    start: f64,
    until: f64,
    every: Option<f64>,
) -> (Vec<TraceLine>, String, Vec<Checkpoint>) {
    let cfg = RunConfig {
        engine,
        until,
        check: true,
        span: Span {
            start,
            ..Span::default()
        },
        interrupt: None,
        checkpoint_every: every,
        thermostat: None,
    };
    let mut kept = Kept::default();
    let report = execute(s, &cfg, &mut kept).unwrap_or_else(|e| panic!("{}: {e}", s.name));
    let events = report.summary.events.total;
    assert_eq!(events as usize, kept.trace.lines.len(), "{}", s.name);
    (
        kept.trace.lines,
        report.summary.final_state_digest,
        kept.checkpoints,
    )
}

fn engines() -> Vec<(&'static str, EngineKind)> {
    vec![
        ("event list", EngineKind::EventList),
        (
            "objects",
            EngineKind::Objects {
                delay: NvDelay::Exact,
            },
        ),
        (
            "sectored objects",
            EngineKind::Sectored {
                sectors: SectorChoice::Auto,
                news: FixedNews::default(),
            },
        ),
        ("time warp, sectored", two_workers(Some(SectorChoice::Auto))),
        ("time warp, plain", two_workers(None)),
    ]
}

/// The checkpoint as it reads back from its file.
fn through_a_file(cp: &Checkpoint) -> Checkpoint {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cp.json");
    cp.write(&path).unwrap();
    let back = Checkpoint::read(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(&back, cp, "a checkpoint reads back as written");
    back
}

fn check_taken_up(s: &Scenario, until: f64) {
    let whole = run(s, EngineKind::EventList, 0.0, until, None);
    assert!(whole.0.len() > 50, "{}: {} events", s.name, whole.0.len());
    for (name, engine) in engines() {
        let what = format!("{} on the {name}", s.name);
        let cut = run(s, engine, 0.0, until, Some(until / 3.0));
        assert!(cut.0 == whole.0, "{what}: a run in stretches differs");
        assert_eq!(cut.1, whole.1, "{what}: digest");
        let times: Vec<f64> = cut.2.iter().map(|c| c.t).collect();
        assert_eq!(times.len(), 3, "{what}: checkpoints at {times:?}");
        assert_eq!(times[2], until, "{what}: the last at the end");
        assert_eq!(cut.2[2].events.total as usize, whole.0.len(), "{what}");
        for cp in &cut.2[..2] {
            let cp = through_a_file(cp);
            let before = whole.0.iter().filter(|l| l.t <= cp.t).count();
            assert_eq!(
                cp.events.total as usize, before,
                "{what}: events by {}",
                cp.t
            );
            // taken up on another engine than the one that wrote it
            for (other, engine) in engines() {
                let rest = run(&cp.scenario, engine, cp.t, until, None);
                let how = format!("{what}, taken up at {} on the {other}", cp.t);
                assert!(
                    rest.0 == whole.0[before..],
                    "{how}: the events after differ"
                );
                assert_eq!(rest.1, whole.1, "{how}: digest");
            }
        }
    }
}

#[test]
fn the_gas_taken_up_from_any_checkpoint_on_any_engine_ends_the_same() {
    let params = builtin::Params {
        balls: Some(64),
        seed: Some(3),
        ..Default::default()
    };
    let s = builtin::build("gas", &params).unwrap();
    check_taken_up(&s, 6.0);
}

#[test]
fn the_break_taken_up_with_balls_in_pockets_ends_the_same() {
    let s = builtin::build("pool", &builtin::Params::default()).unwrap();
    let until = s.until;
    let whole = run(&s, EngineKind::EventList, 0.0, until, Some(until / 3.0));
    assert!(
        whole.2[0].scenario.balls.iter().any(|b| b.pocket.is_some()),
        "a ball is in a pocket at the first checkpoint"
    );
    check_taken_up(&s, until);
}
