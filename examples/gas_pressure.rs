//! A physicist's use of the library: a hard-disk gas in a box, observed event by event through
//! the public API, gives the pressure on its walls, which the example sets beside the equation
//! of state of hard disks.
//!
//! The pressure is the momentum the walls take per unit time and unit length of wall: each
//! elastic bounce of a disk of mass m with normal speed v_n gives the wall 2 m v_n. With kT the
//! mean kinetic energy per disk (two degrees of freedom), the reduced pressure P A / (N kT) is
//! compared with Henderson's equation of state for hard disks, (1 + η²/8) / (1 − η)², η being
//! the area fraction (D. Henderson, Mol. Phys. 30, 971, 1975). A finite box has walls that the
//! formula knows nothing of (disk centres stay a radius away from them), so the example measures
//! the area the centres can reach and asserts agreement to within 10 %.
//!
//! Run it with `cargo run --release --example gas_pressure`.

use poolsim::engine::{Event, EventKind, Ignore, Observer, RunError, World};
use poolsim::run::{execute, EngineKind, RunConfig};
use poolsim::scenario::builtin::{build, Params};

/// Sums the momentum every wall bounce gives the walls.
#[derive(Default)]
struct WallImpulse {
    /// Momentum given to the walls (mass × length / time).
    impulse: f64,
    /// Wall bounces seen.
    bounces: u64,
}

impl Observer for WallImpulse {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        if ev.kind != EventKind::BallCushion {
            return Ok(());
        }
        let table = world.table();
        let (from, to, _) = table.cushions[(ev.b - table.n_balls) as usize];
        let along = to - from;
        let ball = world.ball(ev.a);
        let normal_speed = ball.velocity().dot(along.perp_cw()).abs() / along.norm();
        self.impulse += 2.0 * ball.mass * normal_speed;
        self.bounces += 1;
        Ok(())
    }
}

fn main() {
    let (balls, phi, until) = (1024, 0.25, 40.0);
    let params = Params {
        balls: Some(balls),
        seed: Some(7),
        area_fraction: Some(phi),
        ..Params::default()
    };
    let gas = build("gas", &params).expect("the built-in gas");
    // the first time units let the gas forget its square lattice start
    let settle = 10.0;
    let warm = execute(
        &gas,
        &RunConfig {
            engine: EngineKind::EventList,
            until: settle,
            check: false,
            span: Default::default(),
            interrupt: None,
            checkpoint_every: None,
            thermostat: None,
        },
        &mut Ignore,
    )
    .expect("the gas settles");
    let mut settled = gas.clone();
    for (spec, b) in settled.balls.iter_mut().zip(&warm.outcome.balls) {
        spec.position = b.position(settle);
        spec.velocity = b.velocity();
    }
    settled.until = until;
    let mut walls = WallImpulse::default();
    let cfg = RunConfig {
        engine: EngineKind::EventList,
        until,
        check: true,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let report = execute(&settled, &cfg, &mut walls).expect("the gas runs");

    let (lo, hi) = settled.bounds();
    let r = settled.balls[0].radius;
    let side = hi - lo;
    let perimeter = 2.0 * (side.x + side.y);
    // the box the disk centres move in, as the equation of state counts area
    let free_area = (side.x - 2.0 * r) * (side.y - 2.0 * r);
    let kinetic = report.summary.kinetic_energy.end;
    let kt = kinetic / balls as f64;
    let pressure = walls.impulse / (until * perimeter);
    let measured = pressure * free_area / (balls as f64 * kt);
    let eta = balls as f64 * std::f64::consts::PI * r * r / free_area;
    let henderson = (1.0 + eta * eta / 8.0) / (1.0 - eta).powi(2);
    println!(
        "{balls} disks at area fraction {eta:.3} (of the centres' box), {} wall bounces and {} \
         collisions in {until} time units",
        walls.bounces, report.summary.events.ball_ball
    );
    println!(
        "reduced pressure P A / (N kT): measured {measured:.3}, Henderson's equation of state \
         {henderson:.3} (ratio {:.3})",
        measured / henderson
    );
    assert!(walls.bounces > 1000, "enough bounces to measure");
    assert!(
        (measured / henderson - 1.0).abs() < 0.10,
        "the walls feel the pressure hard disks exert"
    );
}
