//! Property tests of the event-list engine on random tables: it must execute exactly the events
//! of a brute-force reference (all pairs tested after every event, no grid, no calendar, no
//! incremental updates) with the same virtual-time rules, and keep every invariant on the way.

use poolsim::engine::event_list::{EventList, Options};
use poolsim::engine::{BallState, Fixed, Table};
use poolsim::geometry::{Trajectory, Vec2};
use poolsim::output::{TraceLine, TraceRecorder};
use poolsim::physics::{ball_ball_contact, ball_ball_velocities, Contact};
use poolsim::run::{execute, EngineKind, RunConfig};
use poolsim::scenario::Scenario;
use poolsim::vtime::{pair, Key};
use proptest::prelude::*;

mod common;
use common::random_scenario;

/// The simplest correct event-driven simulation: after every event, test every pair.
fn reference(s: &Scenario) -> (Vec<TraceLine>, Vec<BallState>) {
    let table = Table::new(s);
    let mut balls = BallState::initial(s, 0.0);
    let mut fixed_at = vec![Key::start(0.0); balls.len()];
    let n = balls.len() as u32;
    let mut trace = Vec::new();
    loop {
        let mut best: Option<(Key, u32, u32)> = None;
        let mut offer = |key: Key, a: u32, b: u32| {
            if best.as_ref().is_none_or(|(k, _, _)| key < *k) {
                best = Some((key, a, b));
            }
        };
        for i in 0..n {
            let bi = balls[i as usize];
            if bi.pocket.is_some() {
                continue;
            }
            for j in i + 1..n {
                let bj = balls[j as usize];
                if bj.pocket.is_some() {
                    continue;
                }
                match ball_ball_contact(&bi.traj, bi.radius, &bj.traj, bj.radius) {
                    Contact::Never => {}
                    Contact::At(t) => offer(Key::at(t, pair(i, j)), i, j),
                    Contact::Immediate => {
                        let parent = fixed_at[i as usize]
                            .clone()
                            .max(fixed_at[j as usize].clone());
                        offer(parent.child(pair(i, j)), i, j)
                    }
                }
            }
            for f in n..n + table.n_fixed() {
                match table.contact(f, &bi.traj, bi.radius) {
                    Contact::Never => {}
                    Contact::At(t) => offer(Key::at(t, pair(i, f)), i, f),
                    Contact::Immediate => offer(fixed_at[i as usize].child(pair(i, f)), i, f),
                }
            }
        }
        let Some((key, a, b)) = best else { break };
        if key.t > s.until {
            break;
        }
        let set = |balls: &mut Vec<BallState>, fixed_at: &mut Vec<Key>, i: u32, v: Vec2| {
            let tr = &mut balls[i as usize].traj;
            *tr = Trajectory {
                position: tr.at(key.t),
                velocity: v,
                t0: key.t,
            };
            fixed_at[i as usize] = key.clone();
        };
        let kind;
        if b < n {
            let (ba, bb) = (balls[a as usize], balls[b as usize]);
            let (va, vb) = ball_ball_velocities(
                ba.traj.at(key.t),
                ba.traj.velocity,
                ba.mass,
                bb.traj.at(key.t),
                bb.traj.velocity,
                bb.mass,
            );
            set(&mut balls, &mut fixed_at, a, va);
            set(&mut balls, &mut fixed_at, b, vb);
            kind = "ball-ball";
        } else {
            let ba = balls[a as usize];
            let p = ba.traj.at(key.t);
            match table.bounce(b, p, ba.traj.velocity) {
                Some(v) => set(&mut balls, &mut fixed_at, a, v),
                None => {
                    set(&mut balls, &mut fixed_at, a, ba.traj.velocity);
                    let Fixed::Pocket(k) = table.fixed(b) else {
                        unreachable!()
                    };
                    balls[a as usize].pocket = Some(k);
                }
            }
            kind = table.event_kind(b).name();
        }
        trace.push(TraceLine {
            t: key.t,
            kind: kind.into(),
            objects: [table.name(a), table.name(b)],
        });
        assert!(trace.len() < 100_000, "runaway reference");
    }
    (trace, balls)
}

fn engine_run(s: &Scenario, check: bool) -> (Vec<TraceLine>, Vec<BallState>) {
    let mut rec = TraceRecorder::default();
    let cfg = RunConfig {
        engine: EngineKind::EventList,
        until: s.until,
        check,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let report = execute(s, &cfg, &mut rec).unwrap_or_else(|e| panic!("{}: {e}", s.name));
    (rec.lines, report.outcome.balls)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn event_list_matches_the_brute_force_reference(s in random_scenario()) {
        prop_assume!(s.validate().is_ok());
        let (want_trace, want_balls) = reference(&s);
        let (trace, balls) = engine_run(&s, true);
        prop_assert_eq!(&trace, &want_trace);
        for (b, w) in balls.iter().zip(&want_balls) {
            prop_assert_eq!(b.pocket, w.pocket);
            prop_assert_eq!(b.traj.velocity, w.traj.velocity);
            prop_assert_eq!(b.position(s.until), w.position(s.until));
        }
    }

    #[test]
    fn wide_cells_change_nothing(s in random_scenario()) {
        prop_assume!(s.validate().is_ok());
        let mut a = EventList::new(&s, Options::default());
        let mut b = EventList::new(&s, Options { cell_diameters: 3.5, ..Options::default() });
        let (mut ra, mut rb) = (TraceRecorder::default(), TraceRecorder::default());
        let oa = a.run(s.until, &mut ra).unwrap();
        let ob = b.run(s.until, &mut rb).unwrap();
        prop_assert_eq!(ra.lines, rb.lines);
        prop_assert_eq!(oa.balls, ob.balls);
    }
}
