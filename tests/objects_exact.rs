//! The objects engine (thesis fig. 3) against the event-list engine: with zero NewVelocity delay
//! both execute the same physical events, in the same order, at the same times, and end in the
//! same state, bit for bit, on every built-in, every hard case and random tables.

use poolsim::model::pool::NvDelay;
use poolsim::output::TraceLine;
use poolsim::run::{execute, EngineKind, RunConfig};
use poolsim::scenario::{builtin, load, Scenario};
use proptest::prelude::*;

mod common;

fn run(s: &Scenario, engine: EngineKind, check: bool) -> (Vec<TraceLine>, serde_json::Value) {
    let (trace, summary) = common::traced(s, engine, check);
    (trace, serde_json::to_value(&summary).unwrap())
}

fn assert_same(s: &Scenario) {
    let (want, ws) = run(s, EngineKind::EventList, true);
    let objects = EngineKind::Objects {
        delay: NvDelay::Exact,
    };
    let (got, gs) = run(s, objects, true);
    assert_eq!(got, want, "{}: traces differ", s.name);
    assert_eq!(
        gs["final_state_digest"], ws["final_state_digest"],
        "{}: final states differ",
        s.name
    );
}

#[test]
fn every_builtin_runs_identically() {
    for (name, _) in builtin::list() {
        let s = builtin::build(name, &builtin::Params::default()).unwrap();
        assert_same(&s);
    }
    for (balls, phi, seed) in [(100, 0.5, 7), (64, 0.75, 2), (16, 0.3, 9)] {
        let p = builtin::Params {
            balls: Some(balls),
            area_fraction: Some(phi),
            seed: Some(seed),
            ..Default::default()
        };
        assert_same(&builtin::build("gas", &p).unwrap());
    }
}

#[test]
fn every_hard_case_runs_identically() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let s = load(path.to_str().unwrap(), &builtin::Params::default()).unwrap();
            assert_same(&s);
            n += 1;
        }
    }
    assert!(n >= 10, "only {n} hard cases found");
}

#[test]
fn message_counts_follow_the_thesis_accounting() {
    let s = builtin::build("gas", &builtin::Params::default()).unwrap();
    let objects = EngineKind::Objects {
        delay: NvDelay::Exact,
    };
    let (trace, summary) = run(&s, objects, false);
    let m = &summary["messages"];
    let get = |k: &str| m[k].as_u64().unwrap();
    // every executed collision was scheduled by two Collision messages; scheduled ones that did
    // not happen were retracted, two Cancel messages each
    assert!(get("Collision") >= 2 * trace.len() as u64);
    assert_eq!(get("Cancel") % 2, 0);
    // 36 balls at start: ball k tells the 36 - k higher balls and the 4 cushions
    assert!(get("NewVelocity") >= (35 * 36 / 2 + 36 * 4) as u64);
    assert_eq!(
        get("total"),
        get("NewVelocity") + get("Collision") + get("Cancel")
    );
}

/// Thesis table 2: with NewVelocity delayed, the collision 2-3 runs with Ball-2's velocity from
/// before its collision with Ball-1, so an update is lost and momentum is not conserved; the
/// exact mode gives table 1.
#[test]
fn delay_mode_loses_an_update_as_in_table_2() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/fig10_three_in_line.toml"
    );
    let s = load(path, &builtin::Params::default()).unwrap();
    let delayed = EngineKind::Objects {
        delay: NvDelay::Delay(0.01),
    };
    let cfg = RunConfig {
        engine: delayed,
        until: s.until,
        check: false,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let report = execute(&s, &cfg, &mut poolsim::engine::Ignore).unwrap();
    let v: Vec<f64> = report
        .outcome
        .balls
        .iter()
        .map(|b| b.traj.velocity.x)
        .collect();
    assert_eq!(
        v,
        vec![-10.0, 0.0, 0.0],
        "table 2's final row, scaled by 10"
    );
    let exact = EngineKind::Objects {
        delay: NvDelay::Exact,
    };
    let cfg = RunConfig {
        engine: exact,
        ..cfg
    };
    let report = execute(&s, &cfg, &mut poolsim::engine::Ignore).unwrap();
    let v: Vec<f64> = report
        .outcome
        .balls
        .iter()
        .map(|b| b.traj.velocity.x)
        .collect();
    assert_eq!(
        v,
        vec![-10.0, 0.0, 10.0],
        "table 1's final row, scaled by 10"
    );
}

/// Thesis 4.4 and fig. 12 with a delay: the ball driven into the cushion runs into it by
/// `v d` before the cushion hears of it, and the whole exchange is smeared over `2 d`.
#[test]
fn delay_mode_compresses_the_ball_against_the_cushion() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/fig12_resting_on_cushion.toml"
    );
    let s = load(path, &builtin::Params::default()).unwrap();
    let d = 0.01;
    let (trace, _) = run(
        &s,
        EngineKind::Objects {
            delay: NvDelay::Delay(d),
        },
        false,
    );
    let times: Vec<f64> = trace.iter().map(|l| l.t).collect();
    assert_eq!(times.len(), 3);
    assert_eq!(times[0], 7.0);
    assert!((times[1] - (7.0 + d)).abs() < 1e-12);
    assert!((times[2] - (7.0 + 2.0 * d)).abs() < 1e-12);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(120))]

    #[test]
    fn random_tables_run_identically(s in common::random_scenario()) {
        prop_assume!(s.validate().is_ok());
        let (want, ws) = run(&s, EngineKind::EventList, false);
        let (got, gs) = run(&s, EngineKind::Objects { delay: NvDelay::Exact }, false);
        prop_assert_eq!(got, want);
        prop_assert_eq!(&gs["final_state_digest"], &ws["final_state_digest"]);
    }
}

/// Collects frames.
#[derive(Default)]
struct Frames(Vec<poolsim::engine::Frame>);

impl poolsim::engine::Observer for Frames {
    fn on_event(
        &mut self,
        _: &poolsim::engine::Event,
        _: &dyn poolsim::engine::World,
    ) -> Result<(), poolsim::engine::RunError> {
        Ok(())
    }

    fn on_frame(
        &mut self,
        frame: &poolsim::engine::Frame,
        _: &poolsim::engine::Table,
    ) -> Result<(), poolsim::engine::RunError> {
        self.0.push(frame.clone());
        Ok(())
    }
}

/// The Projector's frames (thesis 4.2) are the event-list engine's snapshots, bit for bit, and
/// each costs one DisplayYourself per object.
#[test]
fn projector_frames_match_the_event_list() {
    for name in ["plate1", "gas", "pool"] {
        let s = builtin::build(name, &builtin::Params::default()).unwrap();
        let span = poolsim::engine::Span {
            frame_time: Some(0.25),
            ..Default::default()
        };
        let mut got = Vec::new();
        let mut summaries = Vec::new();
        for engine in [
            EngineKind::EventList,
            EngineKind::Objects {
                delay: NvDelay::Exact,
            },
        ] {
            let cfg = RunConfig {
                engine,
                until: s.until,
                check: true,
                span,
                interrupt: None,
                checkpoint_every: None,
                thermostat: None,
            };
            let mut frames = Frames::default();
            let report = execute(&s, &cfg, &mut frames).unwrap();
            got.push(frames.0);
            summaries.push(serde_json::to_value(&report.summary).unwrap());
        }
        let expected = (s.until / 0.25) as usize + 1;
        assert_eq!(got[0].len(), expected, "{name}");
        assert_eq!(got[0], got[1], "{name}");
        let objects = (s.balls.len() + s.cushions.len() + 3 * s.pockets.len()) as u64;
        assert_eq!(
            summaries[1]["messages"]["DisplayYourself"]
                .as_u64()
                .unwrap(),
            expected as u64 * (objects + 1) + 1,
            "{name}: one to each object and one to the Projector itself per frame (and one for \
             the frame after the end)"
        );
    }
}
