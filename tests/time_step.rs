//! The time-step engine (thesis fig. 1), the baseline the thesis argues against: it sees every
//! contact late and with the balls overlapping, by less than a step when a contact is isolated;
//! it converges to the exact (event-list) answer as the step shrinks, at a cost in steps and pair
//! tests that grows as 1/dt. Only counts and errors are asserted, never wall-clock time.

use poolsim::engine::{BallState, Ignore};
use poolsim::output::TraceRecorder;
use poolsim::run::{execute, EngineKind, Report, RunConfig};
use poolsim::scenario::builtin::{self, Params};
use poolsim::scenario::{toml, Scenario};
use std::path::Path;

/// Four elastic cushions around a 400 × 400 table, in TOML.
const BOX: &str = r#"
[[cushion]]
from = [0.0, 0.0]
to = [0.0, 400.0]
[[cushion]]
from = [0.0, 400.0]
to = [400.0, 400.0]
[[cushion]]
from = [400.0, 400.0]
to = [400.0, 0.0]
[[cushion]]
from = [400.0, 0.0]
to = [0.0, 0.0]
"#;

fn scenario(balls: &str) -> Scenario {
    toml::parse(&format!("{balls}\n{BOX}"), "test.toml").expect("a valid scenario")
}

fn scenario_file(name: &str) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenarios")
        .join(name);
    toml::load(&path).expect("a valid scenario file")
}

fn gas36() -> Scenario {
    builtin::build("gas", &Params::default()).expect("the default gas builds")
}

fn run_traced(s: &Scenario, engine: EngineKind, until: f64) -> (Report, TraceRecorder) {
    let cfg = RunConfig {
        engine,
        until,
        check: false,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let mut trace = TraceRecorder::default();
    let report = execute(s, &cfg, &mut trace).expect("the run completes");
    (report, trace)
}

fn run(s: &Scenario, engine: EngineKind, until: f64) -> Report {
    let cfg = RunConfig {
        engine,
        until,
        check: false,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    execute(s, &cfg, &mut Ignore).expect("the run completes")
}

/// An engine-specific counter of the run summary, by name.
fn stat(r: &Report, name: &str) -> f64 {
    r.outcome
        .engine_stats
        .iter()
        .find(|(k, _)| *k == name)
        .unwrap_or_else(|| panic!("no engine stat {name}: {:?}", r.outcome.engine_stats))
        .1
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

/// The largest distance between the same ball's final positions in two runs.
fn max_position_error(a: &[BallState], b: &[BallState], t: f64) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x.position(t) - y.position(t)).norm())
        .fold(0.0, f64::max)
}

/// Two balls of radius 10 close head-on at relative speed 20 across a gap of 80: they touch at
/// t = 4. A step that does not divide 4 finds them at the first multiple k·dt past 4, overlapping
/// by 20·(k·dt − 4), and reports a detection delay of k·dt − 4 < dt.
#[test]
fn head_on_pair_is_found_late_and_overlapping_by_less_than_a_step() {
    let s = scenario(
        r#"
[run]
until = 5.0
[[ball]]
position = [100.0, 200.0]
velocity = [10.0, 0.0]
radius = 10.0
[[ball]]
position = [200.0, 200.0]
velocity = [-10.0, 0.0]
radius = 10.0
"#,
    );
    let (exact, exact_trace) = run_traced(&s, EngineKind::EventList, 5.0);
    assert_eq!(exact_trace.lines.len(), 1);
    assert_eq!(exact_trace.lines[0].t, 4.0);
    for dt in [0.3, 0.7, 0.15, 0.09] {
        let (r, trace) = run_traced(&s, EngineKind::TimeStep { dt }, 5.0);
        assert_eq!(trace.lines.len(), 1, "dt {dt}: {:?}", trace.lines);
        assert_eq!(trace.lines[0].kind, "ball-ball");
        assert_eq!(trace.lines[0].objects, ["Ball-1", "Ball-2"]);
        let k = (4.0 / dt).ceil();
        let late = k * dt - 4.0;
        assert!(late > 1e-6 && late < dt, "dt {dt} must not divide 4");
        let seen = trace.lines[0].t;
        assert!(close(seen, 4.0 + late, 1e-9), "dt {dt}: seen at {seen}");
        let overlap = stat(&r, "max_overlap_fraction_of_radius");
        assert!(
            close(overlap, 2.0 * late, 1e-9),
            "dt {dt}: overlap {overlap}"
        );
        let mean = stat(&r, "mean_detection_delay");
        let max = stat(&r, "max_detection_delay");
        assert!(close(mean, late, 1e-9), "dt {dt}: mean delay {mean}");
        assert_eq!(mean, max, "one contact");
        assert!(mean > 0.0 && max < dt, "dt {dt}: delay {max}");
        // The velocities come out exchanged, as in the exact run.
        for (a, b) in r.outcome.balls.iter().zip(&exact.outcome.balls) {
            assert_eq!(a.traj.velocity, b.traj.velocity);
        }
    }
}

/// A ball of radius 10 at x = 100 moving at −10 toward the cushion at x = 0 touches it at t = 9;
/// with dt = 0.7 the engine finds it at 13·0.7 = 9.1, 1 deep (a tenth of the radius), 0.1 late.
#[test]
fn head_on_cushion_contact_is_found_late() {
    let s = scenario(
        r#"
[[ball]]
position = [100.0, 200.0]
velocity = [-10.0, 0.0]
radius = 10.0
"#,
    );
    let (r, trace) = run_traced(&s, EngineKind::TimeStep { dt: 0.7 }, 10.0);
    assert_eq!(trace.lines.len(), 1, "{:?}", trace.lines);
    assert_eq!(trace.lines[0].kind, "ball-cushion");
    assert_eq!(trace.lines[0].objects, ["Ball-1", "Cushion-1"]);
    assert!(close(trace.lines[0].t, 9.1, 1e-9), "{}", trace.lines[0].t);
    assert!(close(stat(&r, "max_overlap_fraction_of_radius"), 0.1, 1e-9));
    let delay = stat(&r, "mean_detection_delay");
    assert!(close(delay, 0.1, 1e-9) && delay < 0.7, "{delay}");
    assert_eq!(r.outcome.balls[0].traj.velocity.x, 10.0);
}

/// Thesis fig. 10 (Ball-1 and Ball-3 strike the resting Ball-2 from both sides at t = 8) with
/// dt = 0.3, which does not divide 8. The exact engine runs the instant as 1-2, 2-3, 1-2 at t = 8.
/// The time-step engine finds the first two contacts at 27·0.3 = 8.1, overlapping, less than a
/// step late; the third (Ball-2 sent back into Ball-1 by the second) is only seen at the next
/// step, 8.4: a cascade costs it a whole extra step, so its largest delay (0.4) exceeds dt while
/// the mean stays below it. The velocities still come out bubble-sorted, −10, 0, 10.
#[test]
fn fig10_three_in_line_is_resolved_late_with_overlap() {
    let s = scenario_file("fig10_three_in_line.toml");
    let (exact, exact_trace) = run_traced(&s, EngineKind::EventList, 10.0);
    assert_eq!(exact_trace.lines.len(), 3);
    assert!(exact_trace.lines.iter().all(|l| l.t == 8.0));

    let dt = 0.3;
    let (r, trace) = run_traced(&s, EngineKind::TimeStep { dt }, 10.0);
    let pairs: Vec<[&str; 2]> = trace
        .lines
        .iter()
        .map(|l| [l.objects[0].as_str(), l.objects[1].as_str()])
        .collect();
    assert_eq!(
        pairs,
        [
            ["Ball-1", "Ball-2"],
            ["Ball-2", "Ball-3"],
            ["Ball-1", "Ball-2"]
        ]
    );
    assert!(trace.lines.iter().all(|l| l.kind == "ball-ball"));
    assert!(close(trace.lines[0].t, 8.1, 1e-9));
    assert_eq!(trace.lines[1].t, trace.lines[0].t);
    assert!(close(trace.lines[2].t, 8.4, 1e-9));

    let overlap = stat(&r, "max_overlap_fraction_of_radius");
    let mean = stat(&r, "mean_detection_delay");
    let max = stat(&r, "max_detection_delay");
    assert!(overlap > 0.0, "{overlap}");
    // Deepest: Ball-1 (stopped at 181) and Ball-2 (197, coming back) at 8.4: 4 deep, 0.4 radius.
    assert!(close(overlap, 0.4, 1e-9), "{overlap}");
    // Delays 0.1 (1-2), 0.05 (2-3, closing at 20 from 1 deep) and 0.4 (the cascade).
    assert!(close(mean, (0.1 + 0.05 + 0.4) / 3.0, 1e-9), "{mean}");
    assert!(mean > 0.0 && mean < dt, "{mean}");
    assert!(max > dt && max < 2.0 * dt, "{max}");

    let v: Vec<f64> = r.outcome.balls.iter().map(|b| b.traj.velocity.x).collect();
    let v_exact: Vec<f64> = exact
        .outcome
        .balls
        .iter()
        .map(|b| b.traj.velocity.x)
        .collect();
    assert_eq!(v_exact, [-10.0, 0.0, 10.0]);
    assert_eq!(v, v_exact);
    // Positions are off by the lateness: Ball-2 ends 3 short of where the exact run leaves it.
    assert!(max_position_error(&r.outcome.balls, &exact.outcome.balls, 10.0) > 1.0);
}

/// On the 36-ball gas up to t = 1 (25 exact events, all of them well separated, so no chaotic
/// divergence yet), the final positions approach the exact ones as dt shrinks through 0.1, 0.01
/// and 0.001, with the error falling at least threefold per decade; the overlap at detection
/// shrinks too, and the step count grows as 1/dt.
#[test]
fn shrinking_dt_converges_to_the_event_list_engine() {
    let s = gas36();
    let until = 1.0;
    let exact = run(&s, EngineKind::EventList, until);
    let exact_events = exact.outcome.events;
    assert!(exact_events.total() >= 20, "{:?}", exact_events);

    let mut errors = Vec::new();
    let mut overlaps = Vec::new();
    for dt in [0.1, 0.01, 0.001] {
        let r = run(&s, EngineKind::TimeStep { dt }, until);
        assert_eq!(r.outcome.t, until);
        let err = max_position_error(&r.outcome.balls, &exact.outcome.balls, until);
        errors.push(err);
        overlaps.push(stat(&r, "max_overlap_fraction_of_radius"));
        let steps = stat(&r, "steps");
        // ceil(until / dt) steps; floating-point accumulation of t may add one sliver step.
        let ideal = (until / dt).round();
        assert!(
            steps >= ideal && steps <= ideal + 1.0,
            "dt {dt}: {steps} steps"
        );
        if dt <= 0.01 {
            // Fine enough to see the same collisions as the exact engine.
            assert_eq!(r.outcome.events, exact_events, "dt {dt}");
        }
    }
    for w in errors.windows(2) {
        assert!(w[1] < w[0] / 3.0, "errors {errors:?} do not fall with dt");
    }
    for w in overlaps.windows(2) {
        assert!(w[1] < w[0], "overlaps {overlaps:?} do not fall with dt");
    }
    // At dt = 0.001 every ball ends within a fiftieth of a radius (30) of its exact position.
    assert!(errors[2] < 0.6, "errors {errors:?}");
    assert!(
        errors[0] > 1.0,
        "errors {errors:?}: dt = 0.1 should be visibly wrong"
    );
}

/// Cost (thesis 2.1, O(n T / Δt)): each step tests about the same number of pairs, so the pair
/// tests grow as 1/dt: tenfold per decade of dt, within 15%.
#[test]
fn pair_tests_grow_linearly_with_one_over_dt() {
    let s = gas36();
    let until = 1.0;
    let mut tests = Vec::new();
    let mut per_step = Vec::new();
    for dt in [0.1, 0.01, 0.001] {
        let r = run(&s, EngineKind::TimeStep { dt }, until);
        let pairs = stat(&r, "pair_tests");
        let steps = stat(&r, "steps");
        // Each step tests each ball against its grid neighbours and nearby fixed objects: some
        // tests, and far fewer than all 36·35/2 pairs plus 36·4 ball–cushion pairs.
        assert!(
            (1.0..=774.0).contains(&(pairs / steps)),
            "dt {dt}: {pairs} in {steps}"
        );
        tests.push(pairs);
        per_step.push(pairs / steps);
    }
    let lo = per_step.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = per_step.iter().copied().fold(0.0, f64::max);
    assert!(hi / lo < 1.15, "pair tests per step vary: {per_step:?}");
    for w in tests.windows(2) {
        let ratio = w[1] / w[0];
        assert!(
            (8.5..=11.5).contains(&ratio),
            "pair tests {tests:?}: ratio {ratio} per decade of dt"
        );
    }
}

/// Thesis plate 1 with dt = 0.01: Ball-1 still ends in Pocket-1. Here dt divides the contact
/// time: at the 160th step the balls are exactly touching, which is no overlap yet, so the contact
/// is found a whole step late (t ≈ 1.61, 1 deep) and Ball-1, sent off 0.01 late, crosses the
/// pocket line at about 2.62 rather than 2.6: delays of at most dt each, adding up along a chain.
#[test]
fn plate1_with_dt_001_still_pockets_ball1() {
    let s = builtin::build("plate1", &Params::default()).expect("plate1 builds");
    let dt = 0.01;
    let (r, trace) = run_traced(&s, EngineKind::TimeStep { dt }, 3.0);
    assert_eq!(
        r.outcome.balls[0].pocket,
        Some(0),
        "Ball-1 is not in Pocket-1"
    );
    assert_eq!(r.outcome.balls[1].pocket, None);
    let kinds: Vec<&str> = trace.lines.iter().map(|l| l.kind.as_str()).collect();
    assert_eq!(kinds, ["ball-ball", "ball-pocket"]);
    assert_eq!(trace.lines[0].objects, ["Ball-1", "Ball-2"]);
    assert_eq!(trace.lines[1].objects, ["Ball-1", "Pocket-1"]);
    let (hit, drop) = (trace.lines[0].t, trace.lines[1].t);
    let eps = 1e-9;
    assert!(hit > 1.6 && hit <= 1.6 + dt + eps, "hit at {hit}");
    assert!(drop > 2.6 && drop <= 2.6 + 2.0 * dt + eps, "drop at {drop}");
    // Ball-2 stops dead at the contact (to rounding), as in the exact run; Ball-1 drops in where its centre
    // crosses the line (the engine keeps the first position past it).
    assert!(r.outcome.balls[1].traj.velocity.norm() < 1e-9);
    let p = r.outcome.balls[0].traj.position;
    assert!(p.y > 400.0 && p.y <= 400.0 + 100.0 * dt + eps, "{p:?}");
    let delay = stat(&r, "max_detection_delay");
    assert!(delay > 0.0 && delay <= dt * (1.0 + eps), "{delay}");
    assert!(close(
        stat(&r, "max_overlap_fraction_of_radius"),
        0.05,
        1e-9
    ));
}
