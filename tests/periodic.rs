//! The periodic box: the event list against a brute-force reference that tries every pair with
//! every image, a ball through a corner of the box, a Newton's cradle across a side, positions
//! kept in the box with the unwrapped ones beside them, the observables' identity, and the input
//! a periodic box refuses.

mod common;

use common::traced;
use poolsim::engine::event_list::{EventList, Options};
use poolsim::engine::{Ignore, World};
use poolsim::geometry::{PeriodicBox, Trajectory, Vec2};
use poolsim::observe::Observables;
use poolsim::physics::{self, Contact};
use poolsim::run::{execute, EngineKind, RunConfig};
use poolsim::scenario::builtin::{build, Boundary, Mixture, Params};
use poolsim::scenario::{toml, BallSpec, Scenario};

/// A periodic box of side `side` with `balls` and the given end time.
fn boxed(side: f64, balls: Vec<BallSpec>, until: f64) -> Scenario {
    let s = Scenario {
        name: "periodic".into(),
        until,
        balls,
        cushions: Vec::new(),
        pockets: Vec::new(),
        sectors: None,
        periodic: Some(PeriodicBox {
            lo: Vec2::ZERO,
            size: Vec2::new(side, side),
        }),
    };
    s.validate().expect("a valid periodic scenario");
    s
}

fn ball(x: f64, y: f64, vx: f64, vy: f64) -> BallSpec {
    BallSpec::moving(Vec2::new(x, y), Vec2::new(vx, vy), 1.0, 1.0)
}

/// The first `events` collisions of `s` by brute force: every pair, every image of its second
/// ball within 8 sides of the nearest, the earliest contact next (a pair that has just collided is
/// parting, and has no contact through that image); then both balls take their new velocities
/// from their positions at contact, the second one's image next to the first.
fn reference(s: &Scenario, events: usize) -> Vec<(f64, u32, u32)> {
    let b = s.periodic.expect("a periodic box");
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
        let mut best: Option<(f64, u32, u32, Vec2)> = None;
        for i in 0..traj.len() {
            for j in i + 1..traj.len() {
                // the nearest image at the later fix, and those up to 8 sides further along
                // either axis (a long flight in a small box meets far images)
                let tref = traj[i].t0.max(traj[j].t0);
                let (nx, ny) = b.images(traj[i].at(tref) - traj[j].at(tref));
                for mx in (-8..=8).map(|k| nx + f64::from(k)) {
                    for my in (-8..=8).map(|k| ny + f64::from(k)) {
                        let shift = b.shift((mx, my));
                        let c = physics::ball_ball_contact_across(
                            &traj[i], r[i], &traj[j], r[j], shift,
                        );
                        if let Contact::At(t) = c {
                            if best.is_none_or(|x| t < x.0) {
                                best = Some((t, i as u32, j as u32, shift));
                            }
                        }
                    }
                }
            }
        }
        let Some((t, i, j, shift)) = best else {
            panic!("no next collision after {out:?} of {:?}", s.balls.len())
        };
        let (ti, tj) = (traj[i as usize], traj[j as usize]);
        let (va, vb) = physics::ball_ball_velocities(
            ti.at(t),
            ti.velocity,
            1.0,
            tj.at(t) + shift,
            tj.velocity,
            1.0,
        );
        traj[i as usize] = Trajectory {
            position: ti.at(t),
            velocity: va,
            t0: t,
        };
        traj[j as usize] = Trajectory {
            position: tj.at(t),
            velocity: vb,
            t0: t,
        };
        out.push((t, i, j));
    }
    out
}

/// The ball-ball events of the event list on `s`, as (time, lower ball, higher ball).
fn event_list(s: &Scenario) -> Vec<(f64, u32, u32)> {
    let (trace, _) = traced(s, EngineKind::EventList, true);
    let index = |name: &str| name.trim_start_matches("Ball-").parse::<u32>().unwrap() - 1;
    trace
        .iter()
        .map(|l| (l.t, index(&l.objects[0]), index(&l.objects[1])))
        .collect()
}

#[test]
fn the_event_list_finds_the_collisions_of_every_image() {
    // 24 disks; 5 in a box of three cells a side; a mixture with diameter ratio 1.4
    let configs = [(24, 0.3, None), (5, 0.3, None), (24, 0.4, Some((0.5, 1.4)))];
    for (seed, (balls, phi, mixture)) in (1..=9).zip(configs.iter().cycle()) {
        let params = Params {
            balls: Some(*balls),
            area_fraction: Some(*phi),
            seed: Some(seed),
            boundary: Some(Boundary::Periodic),
            mixture: mixture.map(|(large, ratio)| Mixture { large, ratio }),
            ..Params::default()
        };
        let mut s = build("disks", &params).expect("the disks");
        let want = reference(&s, 60);
        s.until = want.last().unwrap().0 * (1.0 + 1e-9);
        let got = event_list(&s);
        // the two differ in their roundings, and the disks' chaos multiplies the differences
        // until the runs part: the events agree, pair for pair, up to there
        let mut across = 0;
        let mut agreed = 0;
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            if (g.0 - w.0).abs() > 1e-6 * w.0.max(1.0) {
                break;
            }
            assert_eq!(
                (g.1, g.2),
                (w.1, w.2),
                "seed {seed}, event {k}: {g:?} vs {w:?}"
            );
            across += usize::from(is_across(&s, g));
            agreed += 1;
        }
        assert!(
            agreed >= 40,
            "seed {seed}: the runs part after {agreed} events"
        );
        assert!(across > 0, "seed {seed}: no collision across a side");
        if *balls == 5 {
            let el = EventList::new(&s, Options::default());
            assert_eq!(el.grid_dims(), (3, 3));
        }
    }
}

/// Whether the collision `e` of `s` happened across a side of the box (its two centres more
/// than half a side apart in the box).
fn is_across(s: &Scenario, e: &(f64, u32, u32)) -> bool {
    let mut el = EventList::new(s, Options::default());
    el.run(e.0, &mut Ignore).unwrap();
    let side = s.periodic.unwrap().size.x;
    let (p, q) = (el.ball(e.1).position(e.0), el.ball(e.2).position(e.0));
    let wrap = |v: Vec2| s.periodic.unwrap().wrap(v);
    let d = wrap(p) - wrap(q);
    d.x.abs() > side / 2.0 || d.y.abs() > side / 2.0
}

#[test]
fn a_ball_through_a_corner_meets_a_ball_at_the_opposite_corner() {
    // Ball-1 heads for the corner (10, 10) and comes out at (0, 0), where Ball-2 waits by the
    // opposite corner's other side: they touch when the centres are 2 apart along the diagonal.
    let s = boxed(
        10.0,
        vec![ball(8.0, 8.0, 1.0, 1.0), ball(1.5, 1.5, 0.0, 0.0)],
        4.0,
    );
    let got = event_list(&s);
    // centres meet at 2 apart: Ball-1 at (11.5 - sqrt 2, 11.5 - sqrt 2) in the unwrapped plane
    let t = 3.5 - 2f64.sqrt();
    assert_eq!(got.len(), 1, "{got:?}");
    assert!((got[0].0 - t).abs() < 1e-12, "{got:?} vs {t}");
    let (trace, summary) = traced(&s, EngineKind::EventList, true);
    assert_eq!(trace.len(), 1);
    // head-on along the diagonal, equal masses: Ball-1 stops, Ball-2 goes on
    let mut el = EventList::new(&s, Options::default());
    let out = el.run(4.0, &mut Ignore).unwrap();
    assert!(out.balls[0].velocity().norm() < 1e-12);
    assert!((out.balls[1].velocity() - Vec2::new(1.0, 1.0)).norm() < 1e-12);
    // positions in the box; the unwrapped ones carry the sides Ball-1 crossed
    for b in &out.balls {
        let p = b.position(4.0);
        assert!(
            (0.0..10.0).contains(&p.x) && (0.0..10.0).contains(&p.y),
            "{p:?}"
        );
    }
    let unwrapped = el.unwrapped_at(4.0);
    let stop = Vec2::new(8.0 + t, 8.0 + t);
    assert!((unwrapped[0] - stop).norm() < 1e-9, "{:?}", unwrapped[0]);
    assert_eq!(summary.final_state_digest.len(), 16);
}

#[test]
fn a_cradle_across_a_side_passes_the_blow_on_at_one_instant() {
    // Ball-1 touches Ball-2 across the right side and drives into it: Ball-2 passes the blow to
    // Ball-3 at the same instant; Ball-3 then runs into Ball-1, which passes the blow across the
    // side to Ball-2 at once; Ball-2 runs into Ball-3, which touches Ball-1 and passes it on.
    let s = boxed(
        10.0,
        vec![
            ball(8.0, 5.0, 1.0, 0.0),
            ball(0.0, 5.0, 0.0, 0.0),
            ball(2.0, 5.0, 0.0, 0.0),
        ],
        8.5,
    );
    let got = event_list(&s);
    let pairs: Vec<(u32, u32)> = got.iter().map(|e| (e.1, e.2)).collect();
    assert_eq!(
        pairs,
        vec![(0, 1), (1, 2), (0, 2), (0, 1), (1, 2), (0, 2)],
        "{got:?}"
    );
    let times: Vec<f64> = got.iter().map(|e| e.0).collect();
    for (t, want) in times.iter().zip([0.0, 0.0, 4.0, 4.0, 8.0, 8.0]) {
        assert!((t - want).abs() < 1e-12, "{times:?}");
    }
    let mut el = EventList::new(&s, Options::default());
    let out = el.run(8.5, &mut Ignore).unwrap();
    let v: Vec<Vec2> = out.balls.iter().map(|b| b.velocity()).collect();
    assert_eq!(v, vec![Vec2::new(1.0, 0.0), Vec2::ZERO, Vec2::ZERO]);
}

#[test]
fn a_lone_ball_crosses_the_box_many_times_and_stays_in_it() {
    let s = boxed(7.0, vec![ball(3.5, 3.5, 3.3, -1.7)], 100.0);
    let mut el = EventList::new(&s, Options::default());
    let out = el.run(100.0, &mut Ignore).unwrap();
    let p = out.balls[0].position(100.0);
    assert!(
        (0.0..7.0).contains(&p.x) && (0.0..7.0).contains(&p.y),
        "{p:?}"
    );
    let far = Vec2::new(3.5 + 330.0, 3.5 - 170.0);
    assert!((el.unwrapped_at(100.0)[0] - far).norm() < 1e-9);
    assert!((s.periodic.unwrap().wrap(far) - p).norm() < 1e-9);
    assert!(el.stats().cell_crossings > 100);
}

#[test]
fn a_periodic_fluid_keeps_the_collision_identity() {
    let params = Params {
        balls: Some(400),
        area_fraction: Some(0.4),
        seed: Some(3),
        boundary: Some(Boundary::Periodic),
        ..Params::default()
    };
    let mut s = build("disks", &params).expect("the disks");
    s.until = 60.0;
    let cfg = RunConfig {
        engine: EngineKind::EventList,
        until: s.until,
        check: true,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let mut o = Observables::new(&s, 0.0, 10.0, 5.0);
    let report = execute(&s, &cfg, &mut o).expect("the run");
    let o = o.finish(report.outcome.t);
    let sigma = 2.0;
    let identity = std::f64::consts::PI.sqrt() / 4.0 * o.collision_rate.mean * sigma;
    let (z1, err) = (o.z.mean - 1.0, o.z.error);
    assert!(
        (z1 - identity).abs() < 3.0 * err,
        "Z - 1 = {z1} +- {err}, identity {identity}"
    );
    // Liu (2020) gives Z = 2.9327 at area fraction 0.4; N = 400 over 50 time units is loose
    assert!((o.z.mean - 2.93).abs() < 0.1, "{:?}", o.z);
}

#[test]
fn a_periodic_box_refuses_what_it_cannot_hold() {
    let err = |text: &str| toml::parse(text, "box.toml").unwrap_err().to_string();
    let small = "[box]\nsize = [5.0, 20.0]\nboundary = \"periodic\"\n\
                 [[ball]]\nposition = [1.0, 1.0]\nradius = 1.0\n";
    let e = err(small);
    assert!(
        e.starts_with("box.toml:2: box.size[1]: 5 is too small"),
        "{e}"
    );
    let both = "[box]\nsize = [50.0, 50.0]\nboundary = \"periodic\"\n\
                [[ball]]\nposition = [1.0, 1.0]\nradius = 1.0\n\
                [[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 10.0]\n";
    assert!(
        err(both).contains("a box brings its own boundary"),
        "{}",
        err(both)
    );
    let kind = "[box]\nsize = [50.0, 50.0]\nboundary = \"torus\"\n\
                [[ball]]\nposition = [1.0, 1.0]\nradius = 1.0\n";
    assert!(
        err(kind).starts_with("box.toml:3: box: boundary must be"),
        "{}",
        err(kind)
    );
    let overlap = "[box]\nsize = [50.0, 50.0]\nboundary = \"periodic\"\n\
                   [[ball]]\nposition = [0.5, 1.0]\nradius = 1.0\n\
                   [[ball]]\nposition = [49.0, 1.0]\nradius = 1.0\n";
    assert!(
        err(overlap).contains("its image across the periodic box"),
        "{}",
        err(overlap)
    );
    // a position outside the box is taken into it
    let outside = "[box]\nsize = [50.0, 50.0]\nboundary = \"periodic\"\n\
                   [[ball]]\nposition = [-1.0, 120.0]\nradius = 1.0\n";
    let s = toml::parse(outside, "box.toml").unwrap();
    assert_eq!(s.balls[0].position, Vec2::new(49.0, 20.0));
    // walled: four elastic cushions round the box
    let walled = "[box]\nsize = [50.0, 30.0]\norigin = [10.0, 0.0]\n\
                  [[ball]]\nposition = [20.0, 10.0]\nradius = 1.0\n";
    let s = toml::parse(walled, "box.toml").unwrap();
    assert_eq!(s.cushions.len(), 4);
    assert_eq!(s.bounds(), (Vec2::new(10.0, 0.0), Vec2::new(60.0, 30.0)));
    // too dense for the lattice, and the engines without a periodic box
    let dense = Params {
        area_fraction: Some(0.95),
        boundary: Some(Boundary::Periodic),
        ..Params::default()
    };
    let e = build("disks", &dense).unwrap_err();
    assert!(e.message.contains("periodic box: at most"), "{}", e.message);
}
