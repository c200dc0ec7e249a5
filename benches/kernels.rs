//! Criterion benchmarks of the kernels: contact prediction and collision velocities
//! (`physics`), the event-list engine's events per second on the thesis gas, and the time-step
//! baseline. Sample sizes and times are kept low so the whole run takes about a minute;
//! `cargo bench --bench kernels -- --test` runs each benchmark once as a smoke test.

use criterion::{
    black_box, criterion_group, criterion_main, BatchSize, Criterion, SamplingMode, Throughput,
};
use poolsim::engine::event_list::{self, EventList};
use poolsim::engine::time_step::{self, TimeStep};
use poolsim::engine::Ignore;
use poolsim::geometry::{Trajectory, Vec2};
use poolsim::physics::{self, Contact};
use poolsim::scenario::builtin::{self, Params};
use poolsim::scenario::Scenario;
use std::time::Duration;

fn traj(x: f64, y: f64, vx: f64, vy: f64, t0: f64) -> Trajectory {
    Trajectory {
        position: Vec2::new(x, y),
        velocity: Vec2::new(vx, vy),
        t0,
    }
}

fn gas(balls: usize, area_fraction: Option<f64>) -> Scenario {
    builtin::build(
        "gas",
        &Params {
            balls: Some(balls),
            seed: Some(1),
            area_fraction,
            ..Params::default()
        },
    )
    .expect("the gas builds")
}

fn physics_kernels(c: &mut Criterion) {
    let mut g = c.benchmark_group("physics");
    g.sample_size(30)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(1));

    // Two balls fixed at different times, closing at an angle: they meet.
    let a = traj(0.0, 0.0, 30.0, 10.0, 0.5);
    let hit = traj(200.0, 40.0, -40.0, 0.0, 0.25);
    assert!(matches!(
        physics::ball_ball_contact(&a, 30.0, &hit, 30.0),
        Contact::At(_)
    ));
    // Closing, but passing wide: the discriminant is negative.
    let miss = traj(200.0, 200.0, -40.0, 0.0, 0.25);
    assert_eq!(
        physics::ball_ball_contact(&a, 30.0, &miss, 30.0),
        Contact::Never
    );
    g.bench_function("ball_ball_contact/hit", |b| {
        b.iter(|| physics::ball_ball_contact(black_box(&a), 30.0, black_box(&hit), 30.0))
    });
    g.bench_function("ball_ball_contact/miss", |b| {
        b.iter(|| physics::ball_ball_contact(black_box(&a), 30.0, black_box(&miss), 30.0))
    });

    // A ball heading for the left side of a 600 × 600 table.
    let ball = traj(300.0, 200.0, -50.0, 20.0, 1.0);
    let (from, to) = (Vec2::new(0.0, 0.0), Vec2::new(0.0, 600.0));
    assert!(matches!(
        physics::ball_face_contact(&ball, 30.0, from, to),
        Contact::At(_)
    ));
    g.bench_function("ball_face_contact", |b| {
        b.iter(|| {
            physics::ball_face_contact(black_box(&ball), 30.0, black_box(from), black_box(to))
        })
    });

    // Unequal masses take the general branch.
    let (pa, va, pb, vb) = (
        Vec2::new(0.0, 0.0),
        Vec2::new(30.0, 10.0),
        Vec2::new(48.0, 36.0),
        Vec2::new(-20.0, 5.0),
    );
    g.bench_function("ball_ball_velocities/unequal_masses", |b| {
        b.iter(|| {
            physics::ball_ball_velocities(
                black_box(pa),
                black_box(va),
                black_box(1.0),
                black_box(pb),
                black_box(vb),
                black_box(2.5),
            )
        })
    });
    g.finish();
}

/// Physical events per measured iteration of the event-list engine.
const EVENTS: u64 = 50_000;

fn event_list(c: &mut Criterion) {
    let mut g = c.benchmark_group("event_list/gas_phi0.5");
    // Flat sampling: every sample runs the same number of iterations (of EVENTS events each),
    // so ten samples fit in the measurement time.
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements(EVENTS));
    for balls in [1_024, 10_000] {
        // 1,024 = 32²: the gas is k × k balls, so 1,000 rounds to the nearest square.
        let scenario = gas(balls, Some(0.5));
        g.bench_function(format!("{balls}_balls"), |b| {
            b.iter_batched(
                || EventList::new(&scenario, event_list::Options::default()),
                |mut engine| {
                    let out = engine
                        .run_for(f64::INFINITY, EVENTS, &mut Ignore)
                        .expect("the run completes");
                    assert_eq!(out.events.total(), EVENTS);
                    black_box(out)
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

fn time_step_engine(c: &mut Criterion) {
    let mut g = c.benchmark_group("time_step");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    let scenario = gas(36, None);
    g.bench_function("gas36_dt0.01_until1", |b| {
        b.iter_batched(
            || {
                TimeStep::new(
                    &scenario,
                    time_step::Options {
                        dt: 0.01,
                        span: Default::default(),
                    },
                )
            },
            |mut engine| black_box(engine.run(black_box(1.0), &mut Ignore).expect("runs")),
            BatchSize::SmallInput,
        )
    });
    g.finish();
}

criterion_group!(benches, physics_kernels, event_list, time_step_engine);
criterion_main!(benches);
