//! The objects engine (thesis fig. 3): the pool objects of [`crate::model::pool`] run by the
//! sequential kernel executor. With zero NewVelocity delay it executes exactly the event-list
//! engine's physical events.

use super::{BallState, EventCounts, Frame, Observer, Outcome, RunError, Span, Table, World};
use crate::kernel::sequential::Sequential;
use crate::kernel::{MessageStats, Model, VTime};
use crate::model::pool::{NvDelay, Pool, PoolOutput, PoolState};
use crate::scenario::Scenario;
use crate::vtime::Key;

/// The objects engine over one scenario.
pub struct Objects {
    exec: Sequential<Pool>,
}

/// A read-only view of the pool objects' states for observers.
struct View<'a> {
    table: &'a Table,
    states: &'a [PoolState],
}

impl World for View<'_> {
    fn table(&self) -> &Table {
        self.table
    }

    fn n_balls(&self) -> usize {
        self.table.n_balls as usize
    }

    fn ball(&self, i: u32) -> BallState {
        match &self.states[i as usize] {
            PoolState::Ball { info, .. } => BallState {
                traj: info.traj,
                radius: info.radius,
                mass: info.mass,
                pocket: info.pocket,
            },
            _ => unreachable!("objects below n_balls are balls"),
        }
    }

    fn for_each_neighbor(&self, i: u32, f: &mut dyn FnMut(u32)) {
        for j in (0..self.table.n_balls).filter(|&j| j != i) {
            f(j);
        }
    }
}

impl Objects {
    /// Sets the objects up at `span.start` (their `init` sends the first NewVelocity messages).
    pub fn new(s: &Scenario, delay: NvDelay, span: Span) -> Objects {
        let (model, states) = Pool::new(s, delay, span);
        Objects {
            exec: Sequential::new(model, states, VTime::at(Key::start(span.start))),
        }
    }

    /// Message statistics so far.
    pub fn stats(&self) -> &MessageStats {
        self.exec.stats()
    }

    /// Runs every batch up to time `until`, reporting each physical event to `obs`.
    pub fn run(&mut self, until: f64, obs: &mut dyn Observer) -> Result<Outcome, RunError> {
        let mut counts = EventCounts::default();
        let n = self.exec.model().table().n_balls as usize;
        // A frame is complete when every ball has drawn itself for it.
        let mut frame: Option<Frame> = None;
        self.exec
            .run(until, &mut |model: &Pool, states, out| match out {
                PoolOutput::Event(ev) => {
                    counts.add(ev.kind);
                    let view = View {
                        table: model.table(),
                        states,
                    };
                    obs.on_event(&ev, &view)
                }
                PoolOutput::Draw { t, ball, state } => {
                    let f = frame.get_or_insert_with(|| Frame {
                        t,
                        balls: Vec::with_capacity(n),
                    });
                    debug_assert_eq!(f.balls.len(), ball as usize, "balls draw in order");
                    f.balls.push(BallState {
                        traj: state.traj,
                        radius: state.radius,
                        mass: state.mass,
                        pocket: state.pocket,
                    });
                    if f.balls.len() == n {
                        let done = frame.take().expect("a frame is being drawn");
                        obs.on_frame(&done, model.table())?;
                    }
                    Ok(())
                }
            })?;
        let view = View {
            table: self.exec.model().table(),
            states: self.exec.states(),
        };
        let balls = (0..view.n_balls() as u32)
            .map(|i| {
                let mut b = view.ball(i);
                if b.pocket.is_none() {
                    b.traj.position = b.traj.at(until);
                    b.traj.t0 = until;
                }
                b
            })
            .collect();
        let stats = self.exec.stats();
        let names = self.exec.model().kind_names();
        let mut messages: Vec<(&'static str, u64)> = names
            .iter()
            .enumerate()
            .map(|(k, n)| (*n, stats.get(k)))
            .collect();
        messages.push(("Cancel", stats.cancels));
        Ok(Outcome {
            t: until,
            balls,
            events: counts,
            engine_stats: vec![
                ("batches", stats.batches as f64),
                ("messages_delivered", stats.delivered as f64),
                ("pending_at_end", self.exec.pending_len() as f64),
            ],
            messages,
        })
    }
}
