//! Lubachevsky-Stillinger compression: the event list with growing disks against a brute-force
//! reference over every pair and image, jamming of a binary mixture, a target area fraction
//! reached exactly, the same packing from the same start, and the input it refuses.

mod common;

use poolsim::compress::{area_fraction, compress, CompressConfig, CompressError, Ending};
use poolsim::engine::event_list::{EventList, Options};
use poolsim::engine::{Event, Observer, RunError, World};
use poolsim::geometry::{PeriodicBox, Trajectory, Vec2};
use poolsim::growth::Growth;
use poolsim::physics::Contact;
use poolsim::run::EngineKind;
use poolsim::scenario::builtin::{build, Boundary, Lattice, Mixture, Params};
use poolsim::scenario::Scenario;
use std::process::Command;

/// A periodic start of `n` disks at area fraction `phi`, half of them 1.4 times as wide, on
/// random sites.
fn start(n: usize, phi: f64, seed: u64) -> Scenario {
    let params = Params {
        balls: Some(n),
        area_fraction: Some(phi),
        seed: Some(seed),
        boundary: Some(Boundary::Periodic),
        lattice: Some(Lattice::Random),
        mixture: Some(Mixture {
            large: 0.5,
            ratio: 1.4,
        }),
        ..Params::default()
    };
    let s = build("disks", &params).expect("the disks");
    s.validate().expect("a valid start");
    s
}

/// The ball-ball events an engine reports.
struct Events(Vec<(f64, u32, u32)>);

impl Observer for Events {
    fn on_event(&mut self, ev: &Event, _: &dyn World) -> Result<(), RunError> {
        self.0.push((ev.t, ev.a, ev.b));
        Ok(())
    }
}

/// The first `events` collisions of growing disks by brute force: every pair with every image
/// within 2 sides of the nearest, the earliest contact next.
fn reference(s: &Scenario, growth: Growth, events: usize) -> Vec<(f64, u32, u32)> {
    let b: PeriodicBox = s.periodic.expect("a periodic box");
    let mut traj: Vec<Trajectory> = s
        .balls
        .iter()
        .map(|x| Trajectory {
            position: x.position,
            velocity: x.velocity,
            t0: 0.0,
        })
        .collect();
    let r: Vec<f64> = s.balls.iter().map(|x| x.radius).collect();
    let mut out = Vec::new();
    while out.len() < events {
        let mut best: Option<(f64, usize, usize, Vec2)> = None;
        for i in 0..traj.len() {
            for j in i + 1..traj.len() {
                let tref = traj[i].t0.max(traj[j].t0);
                let (nx, ny) = b.images(traj[i].at(tref) - traj[j].at(tref));
                for mx in (-2..=2).map(|k| nx + f64::from(k)) {
                    for my in (-2..=2).map(|k| ny + f64::from(k)) {
                        let shift = b.shift((mx, my));
                        let c = growth.contact(&traj[i], r[i], &traj[j], r[j], shift);
                        if let Contact::At(t) = c {
                            if best.is_none_or(|x| t < x.0) {
                                best = Some((t, i, j, shift));
                            }
                        }
                    }
                }
            }
        }
        let (t, i, j, shift) = best.expect("growing disks always meet again");
        let (ti, tj) = (traj[i], traj[j]);
        let (va, vb) = growth.velocities(
            (ti.at(t), ti.velocity, 1.0, r[i]),
            (tj.at(t) + shift, tj.velocity, 1.0, r[j]),
        );
        traj[i] = Trajectory {
            position: ti.at(t),
            velocity: va,
            t0: t,
        };
        traj[j] = Trajectory {
            position: tj.at(t),
            velocity: vb,
            t0: t,
        };
        out.push((t, i as u32, j as u32));
    }
    out
}

#[test]
fn growing_disks_collide_as_the_brute_force_reference_says() {
    for seed in 1..=4 {
        let s = start(24, 0.3, seed);
        let growth = Growth {
            rate: 0.05,
            from: 0.0,
        };
        let want = reference(&s, growth, 80);
        let until = want.last().unwrap().0 * (1.0 + 1e-9);
        let mut engine =
            EventList::growing(&s, Options::default(), growth, until).expect("a growing engine");
        let mut got = Events(Vec::new());
        engine.run(until, &mut got).expect("the run");
        // the two round differently and the disks' chaos parts them in the end
        let agreed = got
            .0
            .iter()
            .zip(&want)
            .take_while(|(g, w)| (g.0 - w.0).abs() <= 1e-6 * w.0.max(1.0))
            .inspect(|(g, w)| assert_eq!((g.1, g.2), (w.1, w.2), "seed {seed}: {g:?} {w:?}"))
            .count();
        assert!(agreed >= 50, "seed {seed}: parted after {agreed} events");
        // the disks grew as the rate says
        let grown = engine.state_at(until);
        assert!((grown[0].radius / s.balls[0].radius - growth.factor(until)).abs() < 1e-12);
    }
}

/// The smallest gap between two disks of `s` over their contact distance (negative: overlap).
fn smallest_gap(s: &Scenario) -> f64 {
    let b = s.periodic.unwrap();
    let mut least = f64::INFINITY;
    for (i, x) in s.balls.iter().enumerate() {
        for y in &s.balls[i + 1..] {
            let sigma = x.radius + y.radius;
            least = least.min(b.nearest(y.position - x.position).norm() / sigma - 1.0);
        }
    }
    least
}

#[test]
fn a_mixture_jams_near_random_close_packing() {
    let s = start(200, 0.2, 7);
    let cfg = CompressConfig {
        rate: 0.1,
        check: true,
        ..CompressConfig::default()
    };
    let done = compress(&s, &cfg, None, &mut |_| {}).expect("the compression");
    assert_eq!(done.ending, Ending::Jammed);
    let phi = done.area_fraction();
    // 200 disks at this fast rate jam a little below the 0.84 of slow compressions
    assert!((0.80..0.86).contains(&phi), "jammed at {phi}");
    assert!(done.z() >= cfg.max_pressure);
    let gap = smallest_gap(&done.scenario);
    assert!(gap > -1e-9 && gap < 1e-6, "smallest gap {gap}");
    // the thermostat leaves kT = 1; growth conserves momentum
    let n = done.scenario.balls.len() as f64;
    let kinetic: f64 = done
        .scenario
        .balls
        .iter()
        .map(|b| 0.5 * b.mass * b.velocity.norm2())
        .sum();
    assert!((kinetic / n - 1.0).abs() < 1e-12, "kT {}", kinetic / n);
    let p = done
        .scenario
        .balls
        .iter()
        .fold(Vec2::ZERO, |a, b| a + b.mass * b.velocity);
    assert!(p.norm() < 1e-9 * n, "momentum {p:?}");
    // the size ratio is kept
    let (small, large) = done
        .scenario
        .balls
        .iter()
        .fold((f64::MAX, 0.0f64), |(s, l), b| {
            (s.min(b.radius), l.max(b.radius))
        });
    assert!((large / small - 1.4).abs() < 1e-12);
    // the pressure rose cycle after cycle to the threshold, and the area fraction with it
    let zs: Vec<f64> = done.cycles.iter().map(|c| c.z).collect();
    assert!(zs.first().unwrap() < &10.0 && zs.last().unwrap() >= &1e12);
    assert!(done
        .cycles
        .windows(2)
        .all(|w| w[1].area_fraction > w[0].area_fraction));
}

#[test]
fn a_compression_stops_at_its_target_and_the_packing_runs_on() {
    let s = start(150, 0.2, 3);
    let cfg = CompressConfig {
        rate: 0.05,
        target: Some(0.7),
        check: true,
        ..CompressConfig::default()
    };
    let done = compress(&s, &cfg, None, &mut |_| {}).expect("the compression");
    assert_eq!(done.ending, Ending::Target);
    assert!(
        (done.area_fraction() - 0.7).abs() < 1e-9,
        "{}",
        done.area_fraction()
    );
    assert!(smallest_gap(&done.scenario) > -1e-9);
    // the same start, the same packing, bit for bit
    let again = compress(&s, &cfg, None, &mut |_| {}).expect("the compression");
    let positions = |s: &Scenario| -> Vec<(u64, u64)> {
        s.balls
            .iter()
            .map(|b| (b.position.x.to_bits(), b.position.y.to_bits()))
            .collect()
    };
    assert_eq!(positions(&done.scenario), positions(&again.scenario));
    // a fluid at 0.7 that runs on as rigid disks without an overlap
    let mut packing = done.scenario.clone();
    packing.until = 10.0;
    packing.validate().expect("the packing is a valid start");
    let (_, summary) = common::traced(&packing, EngineKind::EventList, true);
    assert!(summary.events.ball_ball > 1000);
}

#[test]
fn compression_refuses_what_it_cannot_do() {
    let s = start(50, 0.2, 1);
    let refused = |cfg: CompressConfig, s: &Scenario| cfg.check(s).unwrap_err();
    let walled = build(
        "disks",
        &Params {
            balls: Some(50),
            ..Params::default()
        },
    )
    .unwrap();
    assert_eq!(
        refused(CompressConfig::default(), &walled),
        CompressError::NotPeriodic
    );
    for (cfg, flag) in [
        (
            CompressConfig {
                rate: 0.0,
                ..CompressConfig::default()
            },
            "--rate",
        ),
        (
            CompressConfig {
                target: Some(0.1),
                ..CompressConfig::default()
            },
            "--target",
        ),
        (
            CompressConfig {
                max_pressure: f64::NAN,
                ..CompressConfig::default()
            },
            "--max-pressure",
        ),
    ] {
        match refused(cfg, &s) {
            CompressError::Setting { flag: f, .. } => assert_eq!(f, flag),
            e => panic!("{e}"),
        }
    }
    assert!((area_fraction(&s) - 0.2).abs() < 1e-12);
    // a walled table cannot take growing disks at all
    assert!(matches!(
        EventList::growing(
            &walled,
            Options::default(),
            Growth {
                rate: 0.1,
                from: 0.0
            },
            1.0
        ),
        Err(RunError::Input(_))
    ));
}

fn poolsim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_poolsim"))
        .args(args)
        .output()
        .expect("poolsim runs")
}

#[test]
fn the_command_writes_a_packing_that_starts_a_run() {
    let dir = std::env::temp_dir().join(format!("poolsim-compress-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let packing = dir.join("packing.json");
    let cycles = dir.join("cycles.jsonl");
    let out = poolsim(&[
        "compress",
        "--balls",
        "100",
        "--mixture",
        "0.5:1.4",
        "--rate",
        "0.1",
        "--target",
        "0.75",
        "--final-state",
        packing.to_str().unwrap(),
        "--cycles",
        cycles.to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["ending"], "target");
    assert!((summary["area_fraction"].as_f64().unwrap() - 0.75).abs() < 1e-9);
    let lines = std::fs::read_to_string(&cycles).unwrap();
    assert_eq!(
        lines.lines().count() as u64,
        summary["cycles"].as_u64().unwrap()
    );
    let run = poolsim(&["run", packing.to_str().unwrap(), "--until", "1", "--check"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // bad input: one line, exit 2
    for args in [
        vec!["compress", "--boundary", "walled"],
        vec!["compress", "--rate", "-1"],
        vec!["compress", "--target", "0.1"],
        vec!["compress", "--area-fraction", "0.7"],
    ] {
        let out = poolsim(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
