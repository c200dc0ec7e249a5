//! A pool shot: the built-in racked table broken by the cue ball, run on the event list and on
//! the thesis' object-oriented simulation, which must agree bit for bit.
//!
//! Shows how to run a scenario through the library, read the summary, and watch pockets fill: it
//! prints each ball that drops, where and when, and asserts that the two engines end in the same
//! state, that no energy was made, and that the cue ball's break reached the rack.
//!
//! Run it with `cargo run --release --example pool_shot`.

use poolsim::engine::{Event, EventKind, Observer, RunError, World};
use poolsim::model::pool::NvDelay;
use poolsim::run::{execute, EngineKind, RunConfig};
use poolsim::scenario::builtin::{build, Params};

/// Prints every ball that drops into a pocket.
#[derive(Default)]
struct Pockets {
    dropped: Vec<(f64, String, String)>,
}

impl Observer for Pockets {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        if ev.kind == EventKind::BallPocket {
            let table = world.table();
            self.dropped
                .push((ev.t, table.name(ev.a), table.name(ev.b)));
        }
        Ok(())
    }

    fn reads_balls(&self) -> bool {
        false
    }
}

fn main() {
    let table = build("pool", &Params::default()).expect("the built-in pool table");
    let run = |engine| {
        let cfg = RunConfig {
            engine,
            until: table.until,
            check: true,
            span: Default::default(),
            interrupt: None,
            checkpoint_every: None,
            thermostat: None,
        };
        let mut pockets = Pockets::default();
        let report = execute(&table, &cfg, &mut pockets).expect("the shot runs");
        (report.summary, pockets.dropped)
    };
    let (list, dropped) = run(EngineKind::EventList);
    let (objects, _) = run(EngineKind::Objects {
        delay: NvDelay::Exact,
    });
    println!(
        "the break: {} collisions, {} cushion bounces, {} corner bounces, {} balls pocketed in {} \
         time units",
        list.events.ball_ball,
        list.events.ball_cushion,
        list.events.ball_corner,
        list.events.ball_pocket,
        list.until
    );
    for (t, ball, pocket) in &dropped {
        println!("  t = {t:.4}: {ball} into {pocket}");
    }
    let energy = &list.kinetic_energy;
    println!(
        "kinetic energy: {:.6e} at the start, {:.6e} on the table and {:.6e} in the pockets at \
         the end; digest {} on both engines",
        energy.initial, energy.end, energy.pocketed, list.final_state_digest
    );
    assert_eq!(
        list.final_state_digest, objects.final_state_digest,
        "the objects engine ends in the event list's state"
    );
    assert_eq!(list.events, objects.events, "and runs the same events");
    assert!(list.events.ball_ball > 15, "the cue ball broke the rack");
    assert_eq!(dropped.len() as u64, list.events.ball_pocket);
    assert!(
        energy.end + energy.pocketed <= energy.initial * (1.0 + 1e-9),
        "no energy was made"
    );
}
