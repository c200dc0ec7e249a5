//! Dense clusters on large tables: many ball centres per table-sized share of the grid (a rack on
//! a big table, tiny balls packed close, a dilute gas that gathers into one disc). Every engine
//! runs them; the exact ones end exactly as the event list does, event for event, and the
//! time-step engine runs them to the end.

use poolsim::geometry::Vec2;
use poolsim::model::pool::NvDelay;
use poolsim::output::TraceLine;
use poolsim::run::{EngineKind, FixedNews, SectorChoice};
use poolsim::scenario::{builtin, BallSpec, CushionSpec, Scenario};
use rand::{Rng, SeedableRng};

mod common;

/// Balls at `centres` with radius `radius` and random velocities of up to `speed` per axis, in a
/// box of four elastic cushions from the origin to `(w, h)`.
fn scenario(name: &str, centres: &[Vec2], radius: f64, speed: f64, (w, h): (f64, f64)) -> Scenario {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let balls = centres
        .iter()
        .map(|&position| BallSpec {
            position,
            velocity: Vec2::new(rng.gen_range(-speed..speed), rng.gen_range(-speed..speed)),
            radius,
            mass: 1.0,
            fixed: None,
            pocket: None,
            colour: None,
            label: None,
        })
        .collect();
    let c = |a: (f64, f64), b: (f64, f64)| CushionSpec {
        from: Vec2::new(a.0, a.1),
        to: Vec2::new(b.0, b.1),
        elasticity: 1.0,
    };
    Scenario {
        name: name.to_string(),
        until: 1.0,
        balls,
        cushions: vec![
            c((0.0, 0.0), (0.0, h)),
            c((0.0, h), (w, h)),
            c((w, h), (w, 0.0)),
            c((w, 0.0), (0.0, 0.0)),
        ],
        pockets: Vec::new(),
        sectors: None,
        periodic: None,
    }
}

/// 129 touching balls of radius 1 in columns of 11, on a 4000 × 4000 table.
fn rack_on_a_big_table() -> Scenario {
    let centres: Vec<Vec2> = (0..129)
        .map(|k| {
            Vec2::new(
                100.0 + 2.0 * f64::from(k / 11),
                100.0 + 2.0 * f64::from(k % 11),
            )
        })
        .collect();
    scenario("rack-on-a-big-table", &centres, 1.0, 1.0, (4000.0, 4000.0))
}

/// 130 balls of radius 0.001 in a line, 0.01 apart, on a 4000 × 4000 table.
fn tiny_line() -> Scenario {
    let centres: Vec<Vec2> = (0..130)
        .map(|k| Vec2::new(100.0 + 0.01 * f64::from(k), 100.0))
        .collect();
    scenario("tiny-line", &centres, 0.001, 0.01, (4000.0, 4000.0))
}

/// `n` balls of radius 1e-6 packed 1e-5 apart in columns of 32, on a 2.54 × 1.27 table.
fn specks(n: u32) -> Scenario {
    let centres: Vec<Vec2> = (0..n)
        .map(|k| {
            Vec2::new(
                1.0 + 1e-5 * f64::from(k / 32),
                0.6 + 1e-5 * f64::from(k % 32),
            )
        })
        .collect();
    scenario("specks", &centres, 1e-6, 1e-5, (2.54, 1.27))
}

/// One ball of radius 5 and 300 of radius 0.01 packed 0.05 apart beside it, on a `side` ×
/// `side` table: the cells, sized for the big ball, each hold far more of the small ones than
/// their slots.
fn grains_and_a_boulder(side: f64) -> Scenario {
    let centres: Vec<Vec2> = (0..300)
        .map(|k| {
            Vec2::new(
                20.0 + 0.05 * f64::from(k / 20),
                20.0 + 0.05 * f64::from(k % 20),
            )
        })
        .collect();
    let mut s = scenario("grains-and-a-boulder", &centres, 0.01, 0.3, (side, side));
    s.balls.push(BallSpec {
        position: Vec2::new(10.0, 12.0),
        velocity: Vec2::new(3.0, 2.0),
        radius: 5.0,
        mass: 1.0,
        fixed: None,
        pocket: None,
        colour: None,
        label: None,
    });
    s.until = 3.0;
    s
}

fn run(s: &Scenario, engine: EngineKind, check: bool) -> (Vec<TraceLine>, String) {
    let (trace, summary) = common::traced(s, engine, check);
    (trace, summary.final_state_digest)
}

/// The objects engines: plain, sectored, and both under Time Warp on two workers.
fn objects_engines() -> Vec<EngineKind> {
    let tw = common::two_workers;
    vec![
        EngineKind::Objects {
            delay: NvDelay::Exact,
        },
        EngineKind::Sectored {
            sectors: SectorChoice::Auto,
            news: FixedNews::default(),
        },
        tw(None),
        tw(Some(SectorChoice::Auto)),
    ]
}

/// The event list runs `s` with every invariant checked and with some collisions; each objects
/// engine (if `objects`) ends in the same state, and the time-step engine runs to the end (it is
/// not exact, and its balls overlap, so nothing more is asserted of it).
fn every_engine(s: &Scenario, objects: bool) {
    let (trace, digest) = run(s, EngineKind::EventList, true);
    assert!(
        trace.iter().any(|l| l.kind == "ball-ball"),
        "{}: no collision",
        s.name
    );
    if objects {
        for engine in objects_engines() {
            let (_, got) = run(s, engine, false);
            assert_eq!(got, digest, "{} on {engine:?}", s.name);
        }
        let plain = EngineKind::Objects {
            delay: NvDelay::Exact,
        };
        assert_eq!(run(s, plain, true).0, trace, "{}: traces differ", s.name);
    }
    run(s, EngineKind::TimeStep { dt: 0.001 }, false);
}

#[test]
fn a_rack_of_129_on_a_big_table_runs_on_every_engine() {
    every_engine(&rack_on_a_big_table(), true);
}

#[test]
fn a_line_of_130_tiny_balls_runs_on_every_engine() {
    every_engine(&tiny_line(), true);
}

#[test]
fn a_thousand_specks_run_on_every_engine() {
    every_engine(&specks(1000), false);
    every_engine(&specks(200), true);
}

#[test]
fn an_exploding_rack_recycles_its_cells_and_stays_exact() {
    // long enough for the balls to spread over far more cells than the grid keeps at once
    let mut s = rack_on_a_big_table();
    s.until = 60.0;
    let (_, digest) = run(&s, EngineKind::EventList, true);
    let objects = EngineKind::Objects {
        delay: NvDelay::Exact,
    };
    assert_eq!(run(&s, objects, false).1, digest);
}

#[test]
fn balls_of_very_different_sizes_crowd_a_cell_on_any_table() {
    for side in [100.0, 4000.0] {
        let s = grains_and_a_boulder(side);
        let (_, digest) = run(&s, EngineKind::EventList, true);
        let objects = EngineKind::Objects {
            delay: NvDelay::Exact,
        };
        assert_eq!(run(&s, objects, false).1, digest, "on a {side} table");
        run(&s, EngineKind::TimeStep { dt: 0.001 }, false);
    }
}

#[test]
fn a_cluster_that_forms_and_flies_apart_is_followed_by_the_grid() {
    // 1,000 balls gather at t = 1 into a disc at area fraction 0.5 and then fly apart: the grid
    // goes finer as they gather and coarser as they leave, and every event is checked on the way
    let p = builtin::Params {
        balls: Some(1000),
        ..Default::default()
    };
    let s = builtin::build("implosion", &p).unwrap();
    let (_, summary) = common::traced(&s, EngineKind::EventList, true);
    let stats = &summary.engine_stats;
    let stat = |name: &str| *stats.get(name).expect("reported");
    assert!(stat("grid_layouts") >= 2.0, "{stats:?}");
    // the cluster's events are most of the run, and a cluster at area fraction 0.5 in cells of
    // at most 8 balls tests few pairs per prediction
    let events = summary.events.total as f64;
    assert!(events > 10_000.0, "{events} events");
    assert!(stat("predictions") < 200.0 * events, "{stats:?}");
}
