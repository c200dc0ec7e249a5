//! Shared test helpers: random tables for property tests, a traced run, Time Warp on two
//! workers.

// each test crate that includes this module uses a part of it
#![allow(dead_code)]

use pdes_kernel::time_warp::TwConfig;
use poolsim::geometry::Vec2;
use poolsim::model::pool::NvDelay;
use poolsim::output::{TraceLine, TraceRecorder};
use poolsim::run::{execute, EngineKind, FixedNews, RunConfig, SectorChoice};
use poolsim::scenario::{BallSpec, CushionSpec, PocketSpec, Scenario};
use poolsim::summary::RunSummary;
use proptest::prelude::*;

/// Runs `s` to its end on `engine` (checking invariants with `check`): its trace and summary.
pub fn traced(s: &Scenario, engine: EngineKind, check: bool) -> (Vec<TraceLine>, RunSummary) {
    let mut rec = TraceRecorder::default();
    let cfg = RunConfig {
        engine,
        until: s.until,
        check,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let report = execute(s, &cfg, &mut rec).unwrap_or_else(|e| panic!("{}: {e}", s.name));
    (rec.lines, report.summary)
}

/// Time Warp on two workers with the given sectors, exact NewVelocity delays.
pub fn two_workers(sectors: Option<SectorChoice>) -> EngineKind {
    EngineKind::TimeWarp {
        tw: TwConfig {
            workers: 2,
            ..TwConfig::default()
        },
        delay: NvDelay::Exact,
        sectors,
        news: FixedNews::default(),
    }
}

/// A random table: a box with random elasticities, sometimes a pocket in the top side, and balls
/// of random sizes and masses, some placed touching others.
pub fn random_scenario() -> impl Strategy<Value = Scenario> {
    (
        2usize..14,
        any::<u64>(),
        prop::bool::ANY,
        prop::collection::vec(0.5..=1.0f64, 5),
    )
        .prop_map(|(n, seed, with_pocket, elasticities)| {
            use rand::{Rng, SeedableRng};
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let (w, h) = (100.0, 80.0);
            let mut balls: Vec<BallSpec> = Vec::new();
            let mut tries = 0;
            while balls.len() < n && tries < 10_000 {
                tries += 1;
                let radius = rng.gen_range(2.0..8.0);
                let position = if !balls.is_empty() && rng.gen_bool(0.3) {
                    // touching an earlier ball, along an exact direction
                    let other: &BallSpec = &balls[rng.gen_range(0..balls.len())];
                    let (dx, dy) =
                        [(1.0, 0.0), (0.0, 1.0), (0.6, 0.8), (-0.8, 0.6)][rng.gen_range(0..4)];
                    let d = other.radius + radius;
                    other.position + Vec2::new(dx * d, dy * d)
                } else {
                    Vec2::new(
                        rng.gen_range(radius..w - radius),
                        rng.gen_range(radius..h - radius),
                    )
                };
                let inside = position.x >= radius
                    && position.x <= w - radius
                    && position.y >= radius
                    && position.y <= h - radius;
                let clear = balls.iter().all(|b| {
                    (b.position - position).norm2() >= (b.radius + radius).powi(2) * (1.0 - 1e-12)
                });
                if inside && clear {
                    let speed = rng.gen_range(0.0..40.0);
                    let dir = rng.gen_range(0.0..std::f64::consts::TAU);
                    balls.push(BallSpec {
                        position,
                        velocity: Vec2::new(speed * dir.cos(), speed * dir.sin()),
                        radius,
                        mass: rng.gen_range(0.5..3.0),
                        fixed: None,
                        pocket: None,
                        colour: None,
                        label: None,
                    });
                }
            }
            let c = |a: (f64, f64), b: (f64, f64), e: f64| CushionSpec {
                from: Vec2::new(a.0, a.1),
                to: Vec2::new(b.0, b.1),
                elasticity: e,
            };
            let mut cushions = vec![c((0.0, 0.0), (0.0, h), elasticities[0])];
            let mut pockets = Vec::new();
            if with_pocket {
                cushions.push(c((0.0, h), (40.0, h), elasticities[1]));
                cushions.push(c((60.0, h), (w, h), elasticities[4]));
                pockets.push(PocketSpec {
                    from: Vec2::new(40.0, h),
                    to: Vec2::new(60.0, h),
                    corner_elasticity: elasticities[1],
                });
            } else {
                cushions.push(c((0.0, h), (w, h), elasticities[1]));
            }
            cushions.push(c((w, h), (w, 0.0), elasticities[2]));
            cushions.push(c((w, 0.0), (0.0, 0.0), elasticities[3]));
            Scenario {
                name: format!("random-{seed}"),
                until: 15.0,
                balls,
                cushions,
                pockets,
                sectors: None,
                periodic: None,
            }
        })
}
