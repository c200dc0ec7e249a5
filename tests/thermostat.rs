//! Andersen's thermostat: a hot start with uniform speeds brought to the bath's temperature
//! with Maxwell's distribution of velocities, the collision identity kept at that temperature,
//! the same kicks from the same seed, and the input it refuses.

use poolsim::engine::{BallState, Event, Observer, RunError, World};
use poolsim::observe::Observables;
use poolsim::run::{execute, EngineKind, Report, RunConfig};
use poolsim::scenario::builtin::{build, Boundary, Params};
use poolsim::scenario::Scenario;
use poolsim::thermostat::Thermostat;
use std::process::Command;

/// 900 disks in a periodic box at area fraction 0.3, every speed drawn uniform up to 20.
fn hot_start() -> Scenario {
    let mut s = build(
        "disks",
        &Params {
            balls: Some(900),
            area_fraction: Some(0.3),
            boundary: Some(Boundary::Periodic),
            temperature: Some(50.0),
            ..Params::default()
        },
    )
    .expect("the disks");
    // a distribution far from Maxwell's: every disk at one speed, in its own direction
    for b in &mut s.balls {
        let v = b.velocity;
        b.velocity = (10.0 / v.norm().max(1e-300)) * v;
    }
    s
}

fn run_with(
    s: &Scenario,
    until: f64,
    thermostat: Option<Thermostat>,
    obs: &mut dyn Observer,
) -> Report {
    let cfg = RunConfig {
        engine: EngineKind::EventList,
        until,
        check: true,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat,
    };
    execute(s, &cfg, obs).expect("a checked run")
}

/// Counts the kicks.
#[derive(Default)]
struct Kicks(u64);

impl Observer for Kicks {
    fn on_event(&mut self, _: &Event, _: &dyn World) -> Result<(), RunError> {
        Ok(())
    }
    fn on_kick(&mut self, _: u32, _: f64, _: &dyn World) -> Result<(), RunError> {
        self.0 += 1;
        Ok(())
    }
}

/// `<v⁴> / <v²>²` of the disks (2 for Maxwell's distribution in two dimensions, 1 for one
/// speed) and the mean kinetic energy per disk.
fn shape_and_kt(balls: &[BallState]) -> (f64, f64) {
    let n = balls.len() as f64;
    let v2: f64 = balls.iter().map(|b| b.velocity().norm2()).sum::<f64>() / n;
    let v4: f64 = balls
        .iter()
        .map(|b| b.velocity().norm2().powi(2))
        .sum::<f64>()
        / n;
    (v4 / (v2 * v2), 0.5 * v2)
}

#[test]
fn a_hot_start_takes_the_baths_temperature_and_maxwells_distribution() {
    let s = hot_start();
    let bath = Thermostat {
        kt: 1.0,
        rate: 0.5,
        seed: 7,
    };
    let (shape, kt) = shape_and_kt(&BallState::initial(&s, 0.0));
    assert!((shape - 1.0).abs() < 1e-9 && (kt - 50.0).abs() < 1e-9);
    let mut o = Observables::new(&s, 0.0, 20.0, 4.0);
    let report = run_with(&s, 100.0, Some(bath), &mut o);
    let o = o.finish(report.outcome.t);
    // 20 blocks after 10 kicks per disk: within three standard errors of the bath
    assert!((o.kt.mean - 1.0).abs() < 3.0 * o.kt.error, "{:?}", o.kt);
    let (shape, kt) = shape_and_kt(&report.outcome.balls);
    assert!((shape - 2.0).abs() < 0.25, "<v4>/<v2>^2 = {shape}");
    assert!((kt - 1.0).abs() < 0.15, "final kT {kt}");
    // at the bath's temperature the virial keeps its tie to the collision rate
    let factor = std::f64::consts::PI.sqrt() / 4.0 * 2.0 / o.kt.mean.sqrt();
    let from_rate = 1.0 + factor * o.collision_rate.mean;
    let both = o.z.error.hypot(factor * o.collision_rate.error);
    assert!(
        (o.z.mean - from_rate).abs() < 4.0 * both,
        "Z {:?} rate {from_rate}",
        o.z
    );
}

#[test]
fn the_same_seed_gives_the_same_kicks() {
    let s = hot_start();
    let bath = |seed| {
        Some(Thermostat {
            kt: 1.0,
            rate: 0.2,
            seed,
        })
    };
    let mut kicks = Kicks::default();
    let a = run_with(&s, 10.0, bath(1), &mut kicks);
    // 900 disks, 0.2 kicks each per unit time, for 10: about 1800
    assert!((1500..2100).contains(&kicks.0), "{} kicks", kicks.0);
    let b = run_with(&s, 10.0, bath(1), &mut Kicks::default());
    let c = run_with(&s, 10.0, bath(2), &mut Kicks::default());
    assert_eq!(a.summary.final_state_digest, b.summary.final_state_digest);
    assert_ne!(a.summary.final_state_digest, c.summary.final_state_digest);
    // without a thermostat the energy is conserved, with it not
    let none = run_with(&s, 10.0, None, &mut Kicks::default());
    assert!(none.summary.kinetic_energy.relative_drift.abs() < 1e-9);
    assert!(a.summary.kinetic_energy.relative_drift < -0.5);
}

#[test]
fn the_command_line_refuses_what_the_thermostat_cannot_do() {
    for args in [
        vec!["run", "gas", "--thermostat", "1", "--engine", "objects"],
        vec!["run", "gas", "--thermostat", "-1"],
        vec!["run", "gas", "--thermostat", "1", "--thermostat-rate", "0"],
        vec!["run", "gas", "--thermostat-seed", "3"],
        vec!["run", "gas", "--thermostat", "1", "--checkpoint", "x.json"],
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_poolsim"))
            .args(&args)
            .current_dir(std::env::temp_dir())
            .output()
            .expect("poolsim runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains("--thermostat"), "{args:?}: {err}");
    }
}
