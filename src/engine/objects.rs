//! The objects engine (thesis fig. 3 and 14): the pool objects of [`crate::model::pool`], or the
//! sectored ones of [`crate::model::sectored`], run by the sequential kernel executor or by Time
//! Warp. With zero NewVelocity delay it executes exactly the event-list engine's physical events.

use super::{
    partition, BallState, EventCounts, Frame, InstantCap, Observer, Outcome, RunError, Span, Table,
    World,
};
use crate::model::pool::{BallInfo, NvDelay, Pool, PoolOutput, PoolState};
use crate::model::sectored::{Layout, SecState, Sectored};
use crate::scenario::{BallSpec, Scenario};
use pdes_kernel::sequential::{Sequential, Sink};
use pdes_kernel::time_warp::threads::{total_workers, TimeWarp};
use pdes_kernel::time_warp::{ObjectMap, TwConfig, TwStats};
use pdes_kernel::{ExecError, Executor, Interrupt, MessageStats, Model, VTime};

/// The objects engine over one scenario: plain or sectored.
pub enum Objects {
    /// Every ball tells every object (thesis fig. 3).
    Plain(Exec<Pool>),
    /// Sectors relay (thesis fig. 14).
    Sectored(Exec<Sectored>),
}

/// The executor that runs the objects: sequential or Time Warp.
pub type Exec<M> = Box<dyn Executor<M, RunError>>;

/// The sequential executor, or Time Warp with `tw` and the objects' workers `worker_of`.
fn exec<M>(model: M, states: Vec<M::State>, start: f64, tw: Option<(TwConfig, Vec<u32>)>) -> Exec<M>
where
    M: Model + Sync + 'static,
    M::Msg: Send,
    M::State: Send + Sync,
    M::Output: Send,
{
    let start = VTime::start(start);
    match tw {
        None => Box::new(Sequential::new(model, states, start)),
        Some((cfg, worker_of)) => {
            let map = ObjectMap::Given(worker_of);
            Box::new(TimeWarp::new(model, states, start, &map, cfg))
        }
    }
}

/// Runs every batch up to `until`, each output to `sink`, which reads the balls' states only if
/// `reads_balls`; returns the time the run ended at (earlier than `until` if interrupted).
fn run_exec<M: Model>(
    e: &mut Exec<M>,
    until: f64,
    reads_balls: bool,
    sink: &mut Sink<'_, M, RunError>,
) -> Result<f64, RunError> {
    e.observe_states(reads_balls);
    e.run(until, sink).map_err(|e| match e {
        ExecError::Sink(e) => e,
        ExecError::Failed(m) => RunError::TimeWarp(m),
    })
}

/// The ball part of an object's state.
trait BallOf {
    fn ball_info(&self) -> &BallInfo;
}

impl BallOf for PoolState {
    fn ball_info(&self) -> &BallInfo {
        match self {
            PoolState::Ball { info, .. } => info,
            _ => unreachable!("objects below n_balls are balls"),
        }
    }
}

impl BallOf for SecState {
    fn ball_info(&self) -> &BallInfo {
        match self {
            SecState::Ball { info, .. } => info,
            _ => unreachable!("objects below n_balls are balls"),
        }
    }
}

/// A read-only view of the objects' states for observers.
struct View<'a, S> {
    table: &'a Table,
    states: &'a [S],
}

impl<S: BallOf> World for View<'_, S> {
    fn table(&self) -> &Table {
        self.table
    }

    fn n_balls(&self) -> usize {
        self.table.n_balls as usize
    }

    fn ball(&self, i: u32) -> BallState {
        let info = self.states[i as usize].ball_info();
        BallState {
            traj: info.traj,
            radius: info.radius,
            mass: info.mass,
            pocket: info.pocket,
        }
    }

    fn for_each_neighbor(&self, i: u32, f: &mut dyn FnMut(u32)) {
        for j in (0..self.table.n_balls).filter(|&j| j != i) {
            f(j);
        }
    }
}

impl Objects {
    /// Sets the plain objects up at `span.start` (their `init` sends the first NewVelocity
    /// messages), sequential.
    pub fn new(s: &Scenario, delay: NvDelay, span: Span) -> Objects {
        Objects::plain_on(s, delay, span, None)
    }

    /// Sets the plain objects up, sequential or (with `tw`) under Time Warp, the balls in
    /// strips of the table.
    pub fn plain_on(s: &Scenario, delay: NvDelay, span: Span, tw: Option<TwConfig>) -> Objects {
        let (model, states) = Pool::new(s, delay, span);
        let tw = tw.map(|c| {
            let mut w = partition::plain(s, total_workers(&c));
            w.resize(states.len(), 0);
            (c, w)
        });
        Objects::Plain(exec(model, states, span.start, tw))
    }

    /// Sets the sectored objects up at `span.start` over `layout`, sequential.
    pub fn sectored(s: &Scenario, layout: Layout, span: Span) -> Objects {
        Objects::sectored_on(s, layout, span, None)
    }

    /// Sets the sectored objects up, sequential or (with `tw`) under Time Warp, each sector and
    /// the balls that start in it on one worker; Time Warp builds the model on as many threads
    /// as it has workers here.
    pub fn sectored_on(s: &Scenario, layout: Layout, span: Span, tw: Option<TwConfig>) -> Objects {
        let threads = tw.as_ref().map_or(1, |c| c.workers.max(1));
        let tw = tw.map(|c| {
            let w = partition::sectored(s, &layout, total_workers(&c));
            (c, w)
        });
        let (model, states) = Sectored::new(s, layout, span, threads);
        Objects::Sectored(exec(model, states, span.start, tw))
    }

    /// Message statistics so far.
    pub fn stats(&self) -> &MessageStats {
        match self {
            Objects::Plain(e) => e.stats(),
            Objects::Sectored(e) => e.stats(),
        }
    }

    /// Frees the engine: under Time Warp each worker's memory on a thread of its own, else as
    /// a drop does.
    pub fn free(self) {
        match self {
            Objects::Plain(e) => e.free(),
            Objects::Sectored(e) => e.free(),
        }
    }

    /// Time Warp's statistics, when it runs the objects.
    pub fn tw_stats(&self) -> Option<TwStats> {
        match self {
            Objects::Plain(e) => e.tw_stats(),
            Objects::Sectored(e) => e.tw_stats(),
        }
    }

    /// Every ball as a run that takes this one up must start it: its trajectory as last fixed,
    /// with the key that fixed it, and its pocket (the committed states, after a run).
    pub fn balls_to_take_up(&self) -> Vec<BallSpec> {
        match self {
            Objects::Plain(e) => take_up(e, e.model().table().n_balls),
            Objects::Sectored(e) => take_up(e, e.model().table().n_balls),
        }
    }

    /// Ends later runs early, at a time when every event up to it has happened, once
    /// `interrupt` is raised.
    pub fn stop_on(&mut self, interrupt: Interrupt) {
        match self {
            Objects::Plain(e) => e.stop_on(interrupt),
            Objects::Sectored(e) => e.stop_on(interrupt),
        }
    }

    /// Runs every batch up to time `until`, reporting each physical event to `obs`.
    pub fn run(&mut self, until: f64, obs: &mut dyn Observer) -> Result<Outcome, RunError> {
        match self {
            Objects::Plain(e) => run_plain(e, until, obs),
            Objects::Sectored(e) => {
                let mut counts = EventCounts::default();
                let mut instant = InstantCap::new(e.model().table().n_balls as usize);
                let ended = run_exec(
                    e,
                    until,
                    obs.reads_balls(),
                    &mut |model: &Sectored, states, ev| {
                        instant.count(&ev)?;
                        counts.add(ev.kind);
                        let view = View {
                            table: model.table(),
                            states,
                        };
                        obs.on_event(&ev, &view)
                    },
                )?;
                Ok(outcome(e, e.model().table(), ended, counts))
            }
        }
    }
}

/// The balls of either model's committed states, as a run taking this one up starts them.
fn take_up<M>(e: &Exec<M>, n_balls: u32) -> Vec<BallSpec>
where
    M: Model,
    M::State: BallOf,
{
    e.states()[..n_balls as usize]
        .iter()
        .map(|s| {
            let b = s.ball_info();
            BallSpec::taken_up(&b.traj, b.radius, b.mass, &b.fixed, b.pocket)
        })
        .collect()
}

/// The end of a run of either model: balls at `until` and the message counts.
fn outcome<M>(e: &Exec<M>, table: &Table, until: f64, counts: EventCounts) -> Outcome
where
    M: Model,
    M::State: BallOf,
{
    let view = View {
        table,
        states: e.states(),
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
    let stats = e.stats();
    let messages = super::message_counts(e.model(), stats);
    Outcome {
        t: until,
        balls,
        events: counts,
        engine_stats: vec![
            ("batches", stats.batches as f64),
            ("messages_delivered", stats.delivered as f64),
            ("pending_at_end", e.pending_len() as f64),
        ],
        messages,
    }
}

/// Runs the plain objects, assembling the Projector's frames.
fn run_plain(
    exec: &mut Exec<Pool>,
    until: f64,
    obs: &mut dyn Observer,
) -> Result<Outcome, RunError> {
    {
        let mut counts = EventCounts::default();
        let n = exec.model().table().n_balls as usize;
        // A frame is complete when every ball has drawn itself for it.
        let mut frame: Option<Frame> = None;
        let mut instant = InstantCap::new(n);
        let ended = run_exec(
            exec,
            until,
            obs.reads_balls(),
            &mut |model: &Pool, states, out| match out {
                PoolOutput::Event(ev) => {
                    instant.count(&ev)?;
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
                        images: Vec::new(),
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
            },
        )?;
        Ok(outcome(exec, exec.model().table(), ended, counts))
    }
}
