//! The thesis' hard cases (`scenarios/`): each asserts its exact outcome on the event-list engine,
//! with every invariant checked at every event.

use poolsim::engine::BallState;
use poolsim::geometry::Vec2;
use poolsim::output::{TraceLine, TraceRecorder};
use poolsim::physics::ball_ball_velocities;
use poolsim::run::{execute, EngineKind, RunConfig};
use poolsim::scenario::{builtin, load, Scenario};

fn scenario(name: &str) -> Scenario {
    let path = format!("{}/scenarios/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    load(&path, &builtin::Params::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs on the event-list engine with checks on; returns the trace and the final balls.
fn run(s: &Scenario) -> (Vec<TraceLine>, Vec<BallState>) {
    let mut rec = TraceRecorder::default();
    let cfg = RunConfig {
        engine: EngineKind::EventList,
        until: s.until,
        check: true,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let report = execute(s, &cfg, &mut rec).unwrap_or_else(|e| panic!("{}: {e}", s.name));
    (rec.lines, report.outcome.balls)
}

fn events(trace: &[TraceLine]) -> Vec<(f64, &str, &str, &str)> {
    trace
        .iter()
        .map(|l| {
            (
                l.t,
                l.kind.as_str(),
                l.objects[0].as_str(),
                l.objects[1].as_str(),
            )
        })
        .collect()
}

fn v(x: f64, y: f64) -> Vec2 {
    Vec2::new(x, y)
}

fn assert_close(a: Vec2, b: Vec2, tol: f64) {
    assert!((a - b).norm() <= tol, "{a:?} != {b:?}");
}

#[test]
fn fig06_ball_hits_the_corner_not_the_pocket() {
    let (trace, balls) = run(&scenario("fig06_corner"));
    let t = (100.0 - 300f64.sqrt()) / 100.0;
    assert_eq!(trace.len(), 1);
    assert_eq!(trace[0].kind, "ball-corner");
    assert_eq!(
        trace[0].objects,
        ["Ball-1".to_string(), "Corner-1".to_string()]
    );
    assert!((trace[0].t - t).abs() < 1e-12);
    assert_eq!(balls[0].pocket, None);
    assert_close(balls[0].traj.velocity, v(50.0 * 3f64.sqrt(), -50.0), 1e-9);
}

#[test]
fn ball_aimed_at_a_corner_point_comes_straight_back() {
    let (trace, balls) = run(&scenario("corner_point"));
    assert_eq!(
        events(&trace),
        vec![(9.0, "ball-corner", "Ball-1", "Corner-1")]
    );
    assert_eq!(balls[0].traj.velocity, v(6.0, -8.0));
}

#[test]
fn fig09_collision_before_new_velocity() {
    let (trace, balls) = run(&scenario("fig09_simultaneous"));
    assert_eq!(
        events(&trace),
        vec![
            (1.6, "ball-ball", "Ball-1", "Ball-2"),
            (1.6, "ball-ball", "Ball-3", "Ball-4"),
            (3.2, "ball-ball", "Ball-1", "Ball-3"),
        ]
    );
    assert_eq!(balls[0].traj.velocity, v(0.0, -50.0));
    assert_eq!(balls[1].traj.velocity, v(50.0, 0.0));
    assert_eq!(balls[2].traj.velocity, v(0.0, 0.0));
    assert_eq!(balls[3].traj.velocity, v(0.0, 0.0));
}

#[test]
fn fig10_table1_bubble_sorts_the_velocities() {
    let (trace, balls) = run(&scenario("fig10_three_in_line"));
    assert_eq!(
        events(&trace),
        vec![
            (8.0, "ball-ball", "Ball-1", "Ball-2"),
            (8.0, "ball-ball", "Ball-2", "Ball-3"),
            (8.0, "ball-ball", "Ball-1", "Ball-2"),
        ]
    );
    // Table 1's final row, scaled by 10
    assert_eq!(balls[0].traj.velocity, v(-10.0, 0.0));
    assert_eq!(balls[1].traj.velocity, v(0.0, 0.0));
    assert_eq!(balls[2].traj.velocity, v(10.0, 0.0));
}

#[test]
fn fig11_serial_order_matters_and_is_canonical() {
    let s = scenario("fig11_three_ball");
    let (trace, balls) = run(&s);
    // Positions at the instant of contact (t = 8), exact by construction.
    let (p1, p2, p3) = (v(180.0, 200.0), v(200.0, 200.0), v(212.0, 184.0));
    let serial = |first12: bool| {
        let mut u = [v(10.0, 0.0), v(0.0, 0.0), v(-6.0, 8.0)];
        let c12 = |u: &mut [Vec2; 3]| {
            let (a, b) = ball_ball_velocities(p1, u[0], 1.0, p2, u[1], 1.0);
            u[0] = a;
            u[1] = b;
        };
        let c23 = |u: &mut [Vec2; 3]| {
            let (a, b) = ball_ball_velocities(p2, u[1], 1.0, p3, u[2], 1.0);
            u[1] = a;
            u[2] = b;
        };
        let closing = |pa: Vec2, ua: Vec2, pb: Vec2, ub: Vec2| (pb - pa).dot(ub - ua) < 0.0;
        // keep colliding while some touching pair closes, starting with the chosen pair
        let mut next12 = first12;
        for _ in 0..10 {
            if next12 && closing(p1, u[0], p2, u[1]) {
                c12(&mut u);
            } else if !next12 && closing(p2, u[1], p3, u[2]) {
                c23(&mut u);
            } else if !closing(p1, u[0], p2, u[1]) && !closing(p2, u[1], p3, u[2]) {
                break;
            }
            next12 = !next12;
        }
        u
    };
    let canonical = serial(true);
    let other = serial(false);
    assert!(
        (canonical[1] - other[1]).norm() > 1.0,
        "order must matter here"
    );
    assert_eq!(trace[0].t, 8.0);
    assert_eq!(
        trace[0].objects,
        ["Ball-1".to_string(), "Ball-2".to_string()]
    );
    assert!(trace.iter().all(|l| l.t == 8.0 && l.kind == "ball-ball"));
    for (b, want) in balls.iter().zip(canonical) {
        assert_close(b.traj.velocity, want, 1e-12);
    }
}

#[test]
fn fig12_ball_resting_on_a_cushion_struck() {
    let (trace, balls) = run(&scenario("fig12_resting_on_cushion"));
    assert_eq!(
        events(&trace),
        vec![
            (7.0, "ball-ball", "Ball-1", "Ball-2"),
            (7.0, "ball-cushion", "Ball-1", "Cushion-3"),
            (7.0, "ball-ball", "Ball-1", "Ball-2"),
        ]
    );
    assert_eq!(balls[0].traj.velocity, v(0.0, 0.0));
    assert_eq!(balls[0].traj.position, v(390.0, 200.0));
    assert_eq!(balls[1].traj.velocity, v(-10.0, 0.0));
}

#[test]
fn sandwiched_ball() {
    let (trace, balls) = run(&scenario("sandwich"));
    assert_eq!(
        events(&trace),
        vec![
            (0.0, "ball-ball", "Ball-1", "Ball-2"),
            (0.0, "ball-ball", "Ball-2", "Ball-3"),
            (0.0, "ball-ball", "Ball-1", "Ball-2"),
        ]
    );
    assert_eq!(balls[0].traj.velocity, v(-10.0, 0.0));
    assert_eq!(balls[1].traj.velocity, v(0.0, 0.0));
    assert_eq!(balls[2].traj.velocity, v(10.0, 0.0));
}

#[test]
fn balls_touching_at_start() {
    let (trace, balls) = run(&scenario("touching_at_start"));
    assert_eq!(events(&trace), vec![(0.0, "ball-ball", "Ball-1", "Ball-2")]);
    assert_eq!(balls[0].traj.velocity, v(0.0, 0.0));
    assert_eq!(balls[1].traj.velocity, v(10.0, 0.0));
    assert_eq!(balls[2].traj.velocity, v(-10.0, 0.0));
    assert_eq!(balls[3].traj.velocity, v(0.0, 0.0));
}

#[test]
fn exact_graze_is_no_collision() {
    let (trace, balls) = run(&scenario("grazing"));
    assert!(trace.is_empty(), "{trace:?}");
    assert_eq!(balls[0].traj.position, v(250.0, 200.0));
}

#[test]
fn ball_sliding_along_a_cushion() {
    let (trace, balls) = run(&scenario("along_cushion"));
    assert_eq!(
        events(&trace),
        vec![(29.0, "ball-cushion", "Ball-1", "Cushion-2")]
    );
    assert_eq!(balls[0].traj.velocity, v(0.0, -10.0));
    assert_eq!(balls[0].traj.position, v(10.0, 380.0));
}

#[test]
fn plate1_ball_two_sinks_ball_one() {
    let s = builtin::build("plate1", &builtin::Params::default()).unwrap();
    let (trace, balls) = run(&s);
    assert_eq!(
        events(&trace),
        vec![
            (1.6, "ball-ball", "Ball-1", "Ball-2"),
            (2.6, "ball-pocket", "Ball-1", "Pocket-1"),
        ]
    );
    assert_eq!(balls[0].pocket, Some(0));
    assert_eq!(balls[1].traj.velocity, v(0.0, 0.0));
}

#[test]
fn newtons_cradle_passes_the_blow_along() {
    let s = builtin::build("cradle", &builtin::Params::default()).unwrap();
    let (trace, balls) = run(&s);
    let instant: Vec<_> = events(&trace).into_iter().filter(|e| e.0 == 1.8).collect();
    assert_eq!(
        instant,
        vec![
            (1.8, "ball-ball", "Ball-1", "Ball-6"),
            (1.8, "ball-ball", "Ball-1", "Ball-2"),
            (1.8, "ball-ball", "Ball-2", "Ball-3"),
            (1.8, "ball-ball", "Ball-3", "Ball-4"),
            (1.8, "ball-ball", "Ball-4", "Ball-5"),
        ]
    );
    for b in &balls[..4] {
        assert_eq!(b.traj.velocity, v(0.0, 0.0));
    }
    assert_eq!(balls[4].traj.velocity, v(100.0, 0.0));
    assert_eq!(balls[5].traj.velocity, v(0.0, 0.0));
}

#[test]
fn the_break_is_deterministic_and_conserves_energy() {
    let s = builtin::build("pool", &builtin::Params::default()).unwrap();
    let (trace_a, balls_a) = run(&s);
    let (trace_b, balls_b) = run(&s);
    assert_eq!(trace_a, trace_b);
    assert_eq!(balls_a, balls_b);
    // the cue ball strikes the apex ball first
    assert_eq!(
        trace_a[0].objects,
        ["Ball-1".to_string(), "Ball-2".to_string()]
    );
    assert!(
        trace_a.len() > 30,
        "the rack scatters: {} events",
        trace_a.len()
    );
}
