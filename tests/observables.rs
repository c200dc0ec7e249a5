//! The observables: exact on a collision worked by hand, and, in an equilibrium gas, the two
//! pressures (virial and cushions) in agreement on the square the centres touch, and the
//! identity that ties the virial to the collision rate, Z − 1 = (√π / 4) ν σ √(m / kT), each
//! within three standard errors.

use poolsim::observe::{Observables, Observed};
use poolsim::run::{execute, EngineKind, RunConfig};
use poolsim::scenario::builtin::{build, Params};
use poolsim::scenario::Scenario;

fn observe(s: &Scenario, engine: EngineKind, from: f64, every: f64) -> Observed {
    let cfg = RunConfig {
        engine,
        until: s.until,
        check: false,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let mut o = Observables::new(s, 0.0, from, every);
    let report = execute(s, &cfg, &mut o).expect("the run");
    o.finish(report.outcome.t)
}

#[test]
fn one_head_on_collision_gives_the_virial_worked_by_hand() {
    // balls of radius 5 at x = 20 and 60 meet at t = 15 (x = 35 and 45), swap velocities and
    // reach no cushion before t = 40
    let text = "[run]\nuntil = 40.0\n\
        [[ball]]\nposition = [20.0, 500.0]\nvelocity = [1.0, 0.0]\nradius = 5.0\n\
        [[ball]]\nposition = [60.0, 500.0]\nvelocity = [-1.0, 0.0]\nradius = 5.0\n\
        [[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 1000.0]\n\
        [[cushion]]\nfrom = [0.0, 1000.0]\nto = [1000.0, 1000.0]\n\
        [[cushion]]\nfrom = [1000.0, 1000.0]\nto = [1000.0, 0.0]\n\
        [[cushion]]\nfrom = [1000.0, 0.0]\nto = [0.0, 0.0]\n";
    let s = poolsim::scenario::toml::parse(text, "head-on.toml").expect("a scenario");
    for engine in [EngineKind::EventList, common_objects()] {
        let o = observe(&s, engine, 0.0, 40.0);
        assert_eq!(o.blocks, 1);
        // kT = K / N = 1 / 2; the virial r_ab . dp_a = (35 - 45)(-2) = 20
        assert_eq!(o.kt.mean, 0.5);
        assert_eq!(o.z.mean, 1.0 + 20.0 / (2.0 * 40.0 * 2.0 * 0.5));
        assert_eq!(o.pressure.mean, (1.0 + 20.0 / 80.0) / 1e6);
        assert_eq!(o.collision_rate.mean, 2.0 / (2.0 * 40.0));
        assert_eq!(o.pressure_walls.mean, 0.0);
        assert_eq!(o.z.error, 0.0);
    }
}

fn common_objects() -> EngineKind {
    EngineKind::Objects {
        delay: poolsim::model::pool::NvDelay::Exact,
    }
}

#[test]
fn an_equilibrium_gas_keeps_the_collision_identity_and_one_pressure() {
    let params = Params {
        balls: Some(400),
        area_fraction: Some(0.4),
        seed: Some(3),
        ..Params::default()
    };
    let mut gas = build("gas", &params).expect("the gas");
    gas.until = 60.0;
    let o = observe(&gas, EngineKind::EventList, 10.0, 5.0);
    assert_eq!(o.blocks, 10);
    let (sigma, m) = (2.0 * gas.balls[0].radius, gas.balls[0].mass);
    // elastic: the temperature does not move
    assert!(o.kt.error <= 1e-12 * o.kt.mean, "{:?}", o.kt);
    let identity =
        std::f64::consts::PI.sqrt() / 4.0 * o.collision_rate.mean * sigma * (m / o.kt.mean).sqrt();
    let (z1, err) = (o.z.mean - 1.0, o.z.error);
    assert!(
        (z1 - identity).abs() < 3.0 * err,
        "Z - 1 = {z1} +- {err}, identity {identity}"
    );
    // both pressures are the force per unit length on the square the centres touch, side
    // L - 2r, once each is put over it: P L^2 / (L - 2r)^2 and P_walls L / (L - 2r)
    let (lo, hi) = gas.bounds();
    let side = hi.x - lo.x;
    let inset = side / (side - sigma);
    let (p, q) = (o.pressure, o.pressure_walls);
    let (pv, pw) = (p.mean * inset * inset, q.mean * inset);
    let both = ((p.error * inset * inset).powi(2) + (q.error * inset).powi(2)).sqrt();
    assert!(
        (pv - pw).abs() < 3.0 * both,
        "virial {pv} and cushions {pw} on the centres' square, +- {both}"
    );
    assert!(o.z.mean > 1.5 && o.z.mean < 4.0, "{:?}", o.z);
}
