//! What travels between workers, what the collector receives, and the [`Fabric`] that carries
//! them: the transport and reductions of one process's threads or of MPI ranks.

use super::config::TwStats;
use super::floor::Floor;
use crate::{Handle, MessageStats, Model, Pending, Time, VTime};

/// One unit of transport between workers.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "T: Time, Msg: serde::Serialize",
    deserialize = "T: Time, Msg: serde::de::DeserializeOwned"
))]
pub enum Op<T, Msg> {
    /// A message.
    Msg {
        /// Its transport name.
        uid: u64,
        /// The message.
        p: Pending<T, Msg>,
    },
    /// The anti-message of `uid`.
    Anti {
        /// The message it annuls.
        uid: u64,
        /// Its receiver.
        to: u32,
        /// Its time.
        time: VTime<T>,
    },
    /// A model cancellation (`sign` 1) or the undoing of one (`sign` -1), by the batch of
    /// object `by` at `at`. It can change only batches after that one, which is all the place
    /// it needs: the message's own place is later still.
    Cancel {
        /// The cancelled message.
        h: Handle,
        /// The time of the cancelling batch.
        at: VTime<T>,
        /// The cancelling object.
        by: u32,
        /// 1 to cancel, -1 to undo.
        sign: i8,
    },
    /// A model cancellation by a batch that ran as final: it can never be undone, so the
    /// message is gone for good, as an anti-message makes it.
    Retract {
        /// The cancelled message.
        h: Handle,
        /// The time of the cancelling batch.
        at: VTime<T>,
        /// The cancelling object.
        by: u32,
    },
}

/// The ops of model `M`.
pub type OpOf<M> = Op<<M as Model>::Time, <M as Model>::Msg>;

impl<T: Time, Msg> Op<T, Msg> {
    /// The receiving object.
    pub fn to(&self) -> u32 {
        match self {
            Op::Msg { p, .. } => p.to,
            Op::Anti { to, .. } => *to,
            Op::Cancel { h, .. } | Op::Retract { h, .. } => h.to,
        }
    }

    /// The first batch the op may change, as a virtual time and an object: the message's own
    /// place, or the place just after the batch that cancelled it.
    pub fn place(&self) -> (&VTime<T>, u32) {
        match self {
            Op::Msg { p, .. } => (&p.time, p.to),
            Op::Anti { time, to, .. } => (time, *to),
            Op::Cancel { at, by, .. } | Op::Retract { at, by, .. } => (at, by + 1),
        }
    }

    /// [`Op::place`] as a floor.
    pub fn floor(&self) -> Floor {
        let (time, to) = self.place();
        Floor::of(time, to)
    }

    /// The smallest floor of `ops` ([`Floor::INFINITY`] for none).
    pub fn lowest(ops: &[Op<T, Msg>]) -> Floor {
        ops.iter().map(Op::floor).fold(Floor::INFINITY, Floor::min)
    }
}

/// The values a GVT round reduces over all workers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reduction {
    /// Ops sent minus ops received (summed).
    pub in_flight: i64,
    /// The first batch that may still change (minimum).
    pub floor: Floor,
    /// Workers asked to stop (summed).
    pub stop: u64,
    /// Workers whose heaps hold so many marked messages that they want them swept (summed):
    /// all workers sweep in the same round, so that none waits at the next round for another
    /// to finish its sweep.
    pub sweep: u64,
    /// The cause of an [`Interrupt`](crate::Interrupt) a worker saw raised, 0 for none
    /// (maximum): every rank learns of it, and raises its own.
    pub interrupt: u64,
    /// The latest time of a batch any worker has run, rolled back or not (maximum): where an
    /// interrupted run ends, since no worker holds anything beyond it.
    pub latest: f64,
}

impl Reduction {
    /// Combines two workers' values.
    pub fn combine(self, o: Reduction) -> Reduction {
        Reduction {
            in_flight: self.in_flight + o.in_flight,
            floor: self.floor.min(o.floor),
            stop: self.stop + o.stop,
            sweep: self.sweep + o.sweep,
            interrupt: self.interrupt.max(o.interrupt),
            latest: self.latest.max(o.latest),
        }
    }
}

/// One committed batch as the collector needs it.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "T: Time, S: serde::Serialize, O: serde::Serialize",
    deserialize = "T: Time, S: serde::de::DeserializeOwned, O: serde::de::DeserializeOwned"
))]
pub struct Committed<T, S, O> {
    /// Its virtual time.
    pub time: VTime<T>,
    /// The object that ran it.
    pub obj: u32,
    /// The object's state after it, if the model's sinks observe the object.
    pub state: Option<S>,
    /// What it reported.
    pub output: Vec<O>,
    /// The time of each output, for a batch that ran its object's own events on past its
    /// time ([`Ctx::may_run`](crate::Ctx::may_run)); empty when all are at its time.
    pub times: Vec<VTime<T>>,
}

/// A committed batch of model `M`.
pub type CommittedOf<M> = Committed<<M as Model>::Time, <M as Model>::State, <M as Model>::Output>;

/// What a worker hands the collector after a GVT round.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "T: Time, S: serde::Serialize, O: serde::Serialize",
    deserialize = "T: Time, S: serde::de::DeserializeOwned, O: serde::de::DeserializeOwned"
))]
pub struct Chunk<T, S, O> {
    /// The worker.
    pub worker: usize,
    /// The round.
    pub round: u64,
    /// Batches committed in this round that carry output or observed states, in any order.
    pub batches: Vec<Committed<T, S, O>>,
    /// Set on the worker's last chunk of a run: its statistics.
    pub last: Option<(TwStats, MessageStats, u64)>,
    /// On the last chunk of a run that ended well, from a worker whose collector runs in
    /// another process: the worker's objects' final states. (Workers beside their collector
    /// hand theirs over in place: [`Worker::hand_back_states`](super::Worker::hand_back_states).)
    pub finals: Vec<(u32, S)>,
    /// Set when the worker stopped on an error.
    pub error: Option<String>,
    /// Where the worker stood after this round.
    pub progress: Progress,
    /// Below every output the worker may still commit: GVT, or the start of an uncommitted
    /// batch that ran on past it. The collector holds back later outputs until every
    /// worker's floor has passed them.
    pub open: Floor,
}

/// One worker's counts after a GVT round, from the start of the run: what
/// [`RoundRecord`](super::RoundRecord)s keep.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Progress {
    /// GVT's simulation time after the round.
    pub gvt: f64,
    /// Seconds since the worker started the run.
    pub wall_s: f64,
    /// Batches committed.
    pub committed: u64,
    /// Batches run, rolled-back ones included.
    pub processed: u64,
    /// Batches undone.
    pub rolled_back: u64,
    /// Batches run as final.
    pub final_batches: u64,
    /// Rollbacks.
    pub rollbacks: u64,
    /// Remote messages sent.
    pub remote_messages: u64,
}

/// What other workers may still send one worker, as [`Fabric::peers_floor`] reads it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Below every op: the other workers' floors and every op waiting in an inbox.
    pub any: Floor,
    /// Below every message and anti-message, cancellations aside: a worker standing at a
    /// floor sends those only from the floor's next generation on
    /// ([`Floor::next_generation`]), or from the model's lookahead past it
    /// ([`Floor::later_by`]), and ops waiting for the asking worker come where they are.
    pub messages: Floor,
}

impl Bounds {
    /// The bounds of a worker whose peers' floors (their own and their inboxes') are at
    /// least `others` and whose own inbox's floor is `mine`, in a model whose messages come at
    /// least `lookahead` after the batches that send them.
    pub fn of_peers(others: Floor, mine: Floor, lookahead: f64) -> Bounds {
        Bounds {
            any: others.min(mine),
            messages: others.later_by(lookahead).min(mine),
        }
    }
}

/// How workers reach each other: delivery of ops, reductions and the collector.
pub trait Fabric<M: Model>: Sync {
    /// Sends ops to worker `to`.
    fn send(&self, from: usize, to: usize, ops: Vec<Op<M::Time, M::Msg>>);
    /// Appends every op that has arrived for worker `me`.
    fn recv(&self, me: usize, into: &mut Vec<Op<M::Time, M::Msg>>);
    /// Reduces `local` over every worker; all workers call it the same number of times.
    fn reduce(&self, me: usize, local: Reduction) -> Reduction;
    /// A worker of this process panicked: the others must not wait for it in a reduction
    /// (they stop instead, and the panic reaches the caller).
    fn abandon(&self) {}
    /// Hands a chunk of committed batches to the collector.
    fn commit(&self, chunk: Chunk<M::Time, M::State, M::Output>);
    /// Whether workers publish floors here and [`Fabric::peers_floor`] can answer: without,
    /// no batch runs as final.
    fn shares_floors(&self) -> bool {
        false
    }
    /// Publishes a floor below everything worker `me` holds or has yet to send (taking ops
    /// from its inbox lowers it to theirs).
    fn publish(&self, _me: usize, _floor: Floor) {}
    /// Floors below what other workers may still send worker `me`, when the fabric can tell:
    /// the published floors and the ops waiting in inboxes of its process, read at one instant
    /// (across ranks, with the bound the last complete round gave, read after them), in a
    /// model whose messages come at least `lookahead` after the batches that send them.
    fn peers_floor(&self, _me: usize, _lookahead: f64) -> Option<Bounds> {
        None
    }
    /// Whether worker `me`, with `done` GVT rounds behind it, starts a round now: when it is
    /// due one itself (`due`), or, where workers share a trigger, when another asked for one.
    /// A shared trigger brings the workers to a round together, so that one that runs its
    /// batches faster (final ones) does not wait there for the others to run as many.
    fn round_due(&self, _me: usize, _done: u64, due: bool) -> bool {
        due
    }
    /// Whether the collector runs in this process, where the workers hand it their final
    /// states in place after the run instead of copying them into their last chunks.
    fn collector_is_local(&self) -> bool {
        true
    }
}
