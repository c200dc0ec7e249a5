//! A generic message-passing discrete-event kernel: objects that exchange timestamped messages,
//! run in order by the [`sequential`] executor, optimistically in parallel by [`time_warp`]
//! (threads; MPI ranks behind the `mpi` feature), or in parallel windows of the model's
//! lookahead by [`conservative`] (threads). [`phold`], the standard benchmark of parallel
//! discrete-event simulators, is its benchmark model and example.
//!
//! ```text
//!            send / send_now / send_at                 batch of one key
//!  object ─────────────────────────────► pending set ────────────────────► object.handle()
//!     ▲          cancel(handle) retracts ─┘   (ordered by VTime, receiver,          │
//!     └──────────────────────────────────────  priority, sender, sequence)  ◄───────┘
//! ```
//!
//! A model is a set of objects, each with a state and a behaviour. An object touches nothing but
//! its own state and the messages it is given; every effect on the rest of the simulation is a
//! message. The kernel runs an object once per virtual time at which it has messages, with all of
//! them as one batch ordered by message priority, then sender, then the sender's
//! send sequence: never by address or hash order.
//!
//! Virtual time ([`VTime`]) is the model's own [`Time`] and a generation: a message sent with
//! zero delay while handling `(k, g)` arrives at `(k, g + 1)`, after the batch that sent it and
//! before every later time; a message sent to an explicit time arrives there with generation 0.
//! No message may go into the receiver's past.
//!
//! States are `Clone` and kept small so an optimistic executor can save and restore them; each
//! object's send counter (which names its messages) lives beside its state for the same reason.

#![warn(missing_docs)]

pub mod conservative;
pub mod digest;
pub mod executor;
pub mod interrupt;
mod led_heap;
pub mod phold;
pub mod prefetch;
pub mod queue;
pub mod sequential;
mod spin_barrier;
pub mod time;
pub mod time_warp;

pub use executor::{ExecError, Executor};
pub use interrupt::Interrupt;
pub use time::{PlainTime, Time, VTime};

/// Pending messages an executor reserves room for per object (address space only until used,
/// so that a pending set that grows to that size never copies itself into fresh pages): a
/// relay model's set-up instant may hold about 25 per object.
pub const RESERVED_PER_OBJECT: usize = 32;

use serde::de::DeserializeOwned;
use serde::Serialize;
use std::cmp::Ordering;
use std::fmt::Debug;

/// Names a sent message so that its sender can cancel it: the sender and its send sequence,
/// which alone tell handles apart, and what an optimistic executor needs to reach the message
/// (its receiver, its simulation time, its transport name), so that no executor has to keep a
/// record of every send for the cancellations that may come.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct Handle {
    /// The sending object.
    pub from: u32,
    /// The receiving object.
    pub to: u32,
    /// The sender's sequence number of the send.
    pub seq: u64,
    /// Time Warp's transport name of the message (0 under the sequential executor, and for a
    /// send into the past that was dropped).
    pub uid: u64,
    /// The message's simulation time.
    pub t: f64,
}

impl PartialEq for Handle {
    fn eq(&self, o: &Self) -> bool {
        (self.from, self.seq) == (o.from, o.seq)
    }
}

impl Eq for Handle {}

impl std::hash::Hash for Handle {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        self.from.hash(h);
        self.seq.hash(h);
    }
}

/// Names two messages a batch sent at one time, one right after the other, the first to the
/// sender itself and the second to `other` (an event both objects take part in): what tells
/// their handles apart, in 24 bytes where the two handles take 80, for states that keep many.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct SentTwo {
    /// The first message's send sequence (the second's is the next).
    seq: u64,
    /// The first message's transport name (the second's is the next), or 0 if unnamed.
    uid: u64,
    /// Their simulation time.
    t: f64,
}

impl SentTwo {
    /// The handles of the two messages object `from` sent: to itself, and to `other`.
    pub fn handles(&self, from: u32, other: u32) -> [Handle; 2] {
        let h = Handle {
            from,
            to: from,
            seq: self.seq,
            uid: self.uid,
            t: self.t,
        };
        let next = Handle {
            to: other,
            seq: self.seq + 1,
            uid: if self.uid == 0 { 0 } else { self.uid + 1 },
            ..h
        };
        [h, next]
    }
}

/// A message as delivered: its payload, its sender and its name.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Envelope<M> {
    /// The sending object.
    pub from: u32,
    /// The sender's send sequence number.
    pub seq: u64,
    /// The payload.
    pub msg: M,
}

/// The most kinds of state [`Model::state_class`] tells apart.
pub const STATE_CLASSES: usize = 4;

/// How an optimistic executor keeps what it needs to undo one of an object's batches
/// ([`Model::saving`]).
pub enum Saving<S, U> {
    /// A copy of the whole state before every batch that may be undone (Jefferson 1985): no
    /// work for the model, a copy's worth of work for the executor.
    Copy,
    /// Only the old values the handler records with [`Ctx::save`] before it changes them
    /// (incremental state saving): a rollback hands the batch's records to `restore`, latest
    /// first, and each puts its bits back. For objects with large states of which a batch
    /// changes little. Restoring saved values, never undoing arithmetic, keeps every result
    /// bit-identical.
    Incremental {
        /// Puts one record's old values back into the state.
        restore: fn(&mut S, U),
    },
}

/// A simulation model for the kernel: message and state types and the objects' behaviour.
pub trait Model {
    /// The model's virtual time ([`PlainTime`] unless it orders the events of an instant
    /// itself).
    type Time: Time;
    /// Message payloads (serializable, so that Time Warp can carry them between ranks).
    type Msg: Clone + Debug + Serialize + DeserializeOwned;
    /// One object's state.
    type State: Clone + Serialize + DeserializeOwned;
    /// What objects report as they go (physical events, drawings): committed output.
    type Output: Serialize + DeserializeOwned;
    /// A record of old values, written by [`Ctx::save`] before a batch changes them, for
    /// objects saved incrementally ([`Model::saving`]); `()` for a model whose states are
    /// copied whole.
    type Undo: Clone + Send;

    /// Names of the message types, indexed by [`Model::kind`], for the statistics.
    fn kind_names(&self) -> &'static [&'static str];
    /// The type index of a message.
    fn kind(&self, msg: &Self::Msg) -> usize;
    /// Priority inside a batch: lower runs first.
    fn priority(&self, msg: &Self::Msg) -> u8;
    /// Whether output sinks read object `obj`'s state while the run goes on (an executor that
    /// keeps states apart, as Time Warp does, ships only these to its collector).
    fn observed(&self, obj: u32) -> bool {
        let _ = obj;
        true
    }
    /// Which of [`STATE_CLASSES`] kinds of state object `obj` holds: Time Warp saves an object's
    /// state into a freed saved state of its own kind, whose buffers then fit without
    /// allocating (see [`Clone::clone_from`]).
    fn state_class(&self, obj: u32) -> usize {
        let _ = obj;
        0
    }
    /// How an optimistic executor saves object `obj`'s state before a batch it may undo: a
    /// copy (the default) or the records the handler writes ([`Saving::Incremental`]). The
    /// answer must not change over a run.
    fn saving(&self, obj: u32) -> Saving<Self::State, Self::Undo> {
        let _ = obj;
        Saving::Copy
    }
    /// The least delay of every message: each message a batch sends comes at or after the
    /// batch's simulation time plus this, as `f64` addition rounds it (a time computed as
    /// `now + delay` with `delay >= lookahead` does). Time Warp runs a batch as final when no
    /// other worker can still send it anything before it, so a positive lookahead lets far
    /// more batches run without saving state. A send that breaks it is a model bug: the
    /// sequential executor panics, Time Warp stops with an error if the batch commits. 0 (the
    /// default) promises nothing beyond sends going forward.
    fn lookahead(&self) -> f64 {
        0.0
    }
    /// Whether object `obj`'s batches may run its own events on past their time
    /// ([`Ctx::may_run`]) under Time Warp, which then keeps the times of the messages waiting
    /// for the object to tell it how far. The answer must not change over a run.
    fn runs_ahead(&self, obj: u32) -> bool {
        let _ = obj;
        false
    }
    /// Ends anew a batch of object `me` that ran its own events on ([`Ctx::may_run`]) and that
    /// Time Warp has cut back to before one of them, because a message came for the object
    /// there: `state` is as the batch left it before that event, `ctx.now()` is the last event
    /// it kept (or its own time), and the handler sends (and cancels) what the batch would
    /// have had it stopped there; it emits nothing. Only for objects that run ahead
    /// ([`Model::runs_ahead`]).
    fn cut(&self, ctx: &mut Ctx<'_, Self>, me: u32, state: &mut Self::State) {
        let _ = (ctx, me, state);
    }
    /// Whether `msg`, coming for an object whose latest batch ran its own events on past the
    /// message's time, may wait for its turn and be offered to [`Model::take_in`] then,
    /// instead of cutting that batch back at once. Asked of objects saved incrementally
    /// ([`Saving::Incremental`]) that run ahead ([`Model::runs_ahead`]), under Time Warp.
    fn may_take_in(msg: &Self::Msg) -> bool
    where
        Self: Sized,
    {
        let _ = msg;
        false
    }
    /// Takes `batch`, at `ctx.now()`, into object `me` after its latest batches, which ran
    /// its own events on to `ctx.reached()`, past the batch's time (only batches whose
    /// messages all [`Model::may_take_in`]). The model answers true when that gives the state
    /// that handling the batch in its turn and then running those events would have given:
    /// the batch changes nothing they read or did, and its effects start after
    /// `ctx.reached()`; it then sends (after `ctx.reached()`) and cancels what that would
    /// have, and emits nothing. It answers false when it cannot tell: the executor then puts
    /// back what the call saved in its journal ([`Ctx::journal`]; the call must save every
    /// change), drops what it sent and cancelled, cuts the object back to before the batch,
    /// and runs the batch in its turn.
    ///
    /// A batch taken in is undone with the batches it followed. If a message later than the
    /// batch undoes it (and cuts them back), the executor offers it `again`, right after the
    /// cut: the events it follows are then those it followed before, up to that message, and
    /// the model must take it in without checking them anew (what they touched since may
    /// have been undone without a trace), checking only its own effects against the time
    /// reached.
    fn take_in(
        &self,
        ctx: &mut Ctx<'_, Self>,
        me: u32,
        state: &mut Self::State,
        batch: &[Envelope<Self::Msg>],
        again: bool,
    ) -> bool {
        let _ = (ctx, me, state, batch, again);
        false
    }
    /// Sets object `me` up at the start time; it may send messages.
    fn init(&self, ctx: &mut Ctx<'_, Self>, me: u32, state: &mut Self::State);
    /// Runs object `me` over one batch of messages, all with the virtual time `ctx.now()`.
    fn handle(
        &self,
        ctx: &mut Ctx<'_, Self>,
        me: u32,
        state: &mut Self::State,
        batch: &[Envelope<Self::Msg>],
    );
}

/// A message waiting to be delivered.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "T: Time, M: Serialize",
    deserialize = "T: Time, M: DeserializeOwned"
))]
pub struct Pending<T, M> {
    /// When it arrives.
    pub time: VTime<T>,
    /// The receiving object.
    pub to: u32,
    /// Its priority in the receiver's batch.
    pub priority: u8,
    /// Whether its sender may cancel it (sent with [`Ctx::send_at`]); a relay is never looked up
    /// among the cancellations.
    pub retractable: bool,
    /// Sender, sequence and payload.
    pub env: Envelope<M>,
}

impl<T: Time, M> Pending<T, M> {
    /// The delivery order: time, receiver, priority, sender, sequence.
    pub fn order(&self, o: &Self) -> Ordering {
        self.time
            .cmp(&o.time)
            .then(self.to.cmp(&o.to))
            .then(self.priority.cmp(&o.priority))
            .then(self.env.from.cmp(&o.env.from))
            .then(self.env.seq.cmp(&o.env.seq))
    }

    /// The time as an integer that orders messages of different times as [`Pending::order`]
    /// does (the lead of a pending set's entry, [`queue::Ranked::lead`]).
    #[inline]
    pub fn lead(&self) -> u64 {
        time::time_bits(self.time.t())
    }

    /// Integers that order messages of one key as [`Pending::order`] does, then by `uid`:
    /// generation and receiver, priority and sender, sequence, `uid`.
    pub fn rank(&self, uid: u64) -> [u64; 4] {
        [
            u64::from(self.time.gen) << 32 | u64::from(self.to),
            u64::from(self.priority) << 32 | u64::from(self.env.from),
            self.env.seq,
            uid,
        ]
    }

    /// This message's handle (with no transport name).
    pub fn handle(&self) -> Handle {
        Handle {
            from: self.env.from,
            to: self.to,
            seq: self.env.seq,
            uid: 0,
            t: self.time.t(),
        }
    }
}

/// The transport name of the `n`-th message object `from` sent (counting from 1, rolled-back
/// sends included, dropped sends into the past not), unique over a run.
pub fn uid(from: u32, n: u64) -> u64 {
    (u64::from(from) << 40) | n
}

/// What one batch did, handed back to the executor: messages sent, sends retracted, output.
pub struct Ctx<'a, M: Model + ?Sized> {
    model: &'a M,
    now: VTime<M::Time>,
    me: u32,
    seq: &'a mut u64,
    /// The object's count of named messages, when the executor names them (Time Warp).
    uids: Option<&'a mut u64>,
    /// Messages sent by this batch.
    pub sent: Vec<Pending<M::Time, M::Msg>>,
    /// Handles this batch cancelled.
    pub cancelled: Vec<Handle>,
    /// Output this batch produced.
    pub output: Vec<M::Output>,
    /// The time of each output, when the batch ran its object's own events on
    /// ([`Ctx::emit_at`]): empty while every output is at the batch's time.
    pub output_times: Vec<VTime<M::Time>>,
    /// Where [`Ctx::save`] writes, when the executor keeps the batch's old values.
    journal: Option<&'a mut Vec<M::Undo>>,
    /// Set by an optimistic executor: a batch may run on a state that a rollback will undo.
    speculative: bool,
    /// A send into the past this speculative batch tried (and that was dropped), or one sooner
    /// than the model's lookahead: a model bug if the batch commits.
    pub into_past: Option<String>,
    /// How far the batch may run the object's own events past its time, when the executor
    /// lets it ([`Ctx::may_run`]).
    horizon: Option<Horizon<M::Time>>,
    /// The time of the last of its own events the batch ran ([`Ctx::reach`]).
    pub reached: Option<VTime<M::Time>>,
    /// Where each of its own events the batch ran on to starts in the journal, when it keeps
    /// one: the event's time and the journal's length before it ([`Ctx::reach`]). An
    /// optimistic executor undoes the batch back to one of them.
    pub marks: Vec<(VTime<M::Time>, usize)>,
}

/// How far a batch may run its object's own events: before the first message still to come
/// to any object, and not after the run's end.
#[derive(Clone, Debug)]
pub struct Horizon<T> {
    /// The first message still to come (none: no message is waiting).
    pub before: Option<VTime<T>>,
    /// The run's end.
    pub until: f64,
}

impl<'a, M: Model + ?Sized> Ctx<'a, M> {
    /// A context for object `me` at `now`, with its send counter.
    pub fn new(model: &'a M, now: VTime<M::Time>, me: u32, seq: &'a mut u64) -> Ctx<'a, M> {
        Ctx {
            model,
            now,
            me,
            seq,
            uids: None,
            sent: Vec::new(),
            cancelled: Vec::new(),
            output: Vec::new(),
            output_times: Vec::new(),
            journal: None,
            speculative: false,
            into_past: None,
            horizon: None,
            reached: None,
            marks: Vec::new(),
        }
    }

    /// Lets the batch run its object's own events up to `horizon` ([`Ctx::may_run`]): for an
    /// executor that runs every batch in order and whose sink does not read states between
    /// outputs.
    pub fn with_horizon(mut self, horizon: Horizon<M::Time>) -> Ctx<'a, M> {
        self.horizon = Some(horizon);
        self
    }

    /// Whether the batch may go on to run one of its object's own events (one that needs no
    /// message to happen, such as the next event of a region's queue) at `time`, after the
    /// batch's own: only where the executor allows it, before every message still to come and
    /// every message this batch sent (its reply may come at once), and not after the run's
    /// end. The handler then says how far it got with [`Ctx::reach`]. Under any other
    /// executor, never: each such event waits for a batch of its own.
    ///
    /// The events a batch runs on must send nothing but at its end: the model stops at the
    /// first event with something to send and sends after [`Ctx::reach`] (a send is then at
    /// or after the time reached). Time Warp relies on it: a batch rolled back for a message
    /// inside its span runs again up to that message, and that shorter run sends nothing a
    /// receiver could have seen, even one that has committed past the batch's start.
    pub fn may_run(&self, time: &VTime<M::Time>) -> bool {
        let Some(h) = &self.horizon else {
            return false;
        };
        *time > self.now
            && time.t() <= h.until
            && h.before.as_ref().is_none_or(|b| time < b)
            && self.sent.iter().all(|p| *time < p.time)
    }

    /// Records that the batch runs its object's own event at `time` next, as [`Ctx::may_run`]
    /// allowed: the executor's clock moves on there. A model that keeps a journal calls it
    /// before the event's first record (and before its first change), so that the executor
    /// can undo the batch back to this event alone.
    pub fn reach(&mut self, time: VTime<M::Time>) {
        debug_assert!(self.may_run(&time), "ran past the horizon");
        if let Some(j) = &self.journal {
            self.marks.push((time.clone(), j.len()));
        }
        self.reached = Some(time);
    }

    /// The time the batch has reached: its own, or the last of its object's own events it ran
    /// ([`Ctx::reach`]).
    pub fn reached(&self) -> &VTime<M::Time> {
        self.reached.as_ref().unwrap_or(&self.now)
    }

    /// A context for a batch that may run on an inconsistent state (Time Warp): a send into
    /// the past is dropped and recorded in `into_past` instead of panicking, for the executor
    /// to report if the batch is ever committed.
    pub fn speculative(model: &'a M, now: VTime<M::Time>, me: u32, seq: &'a mut u64) -> Ctx<'a, M> {
        Ctx {
            speculative: true,
            ..Ctx::new(model, now, me, seq)
        }
    }

    /// Names every message this context sends, counting with the object's `uids`: the k-th
    /// message of the batch gets [`uid`]`(me, count before the batch + k)`, and its handle
    /// carries the name. A send into the past, dropped, takes no name (its handle's is 0).
    pub fn named(mut self, uids: &'a mut u64) -> Ctx<'a, M> {
        self.uids = Some(uids);
        self
    }

    /// Keeps the old values that [`Ctx::save`] records in `journal` (an optimistic executor's
    /// batch of an object saved incrementally).
    pub fn journaled(mut self, journal: &'a mut Vec<M::Undo>) -> Ctx<'a, M> {
        self.journal = Some(journal);
        self
    }

    /// Records old values of the state, made by `undo`, before the handler changes them: an
    /// object saved incrementally ([`Model::saving`]) must save everything a batch changes
    /// before changing it, and its rollback restores the records, latest first. `undo` runs
    /// only when the executor keeps the record (not on the sequential executor, nor for a
    /// batch that can no longer be undone), so saving costs nothing there.
    #[inline]
    pub fn save(&mut self, undo: impl FnOnce() -> M::Undo) {
        if let Some(journal) = self.journal.as_deref_mut() {
            journal.push(undo());
        }
    }

    /// Whether [`Ctx::save`] keeps its records in this batch.
    pub fn saves(&self) -> bool {
        self.journal.is_some()
    }

    /// The records of old values this batch keeps, when it keeps them: for a model that
    /// writes many records and would rather push them itself (or swap in a vector it filled)
    /// than hand each to [`Ctx::save`]. The same rules hold: every record before the change it
    /// undoes, in the order of the changes.
    pub fn journal(&mut self) -> Option<&mut Vec<M::Undo>> {
        self.journal.as_deref_mut()
    }

    /// The object handling the batch.
    pub fn me(&self) -> u32 {
        self.me
    }

    /// The virtual time of the batch being handled.
    pub fn now(&self) -> &VTime<M::Time> {
        &self.now
    }

    /// Sends `msg` to `to` at virtual time `time`, which must not be before now; the handle
    /// returned lets the sender cancel it.
    ///
    /// # Panics
    /// If `time` is not after now: a model bug, a message into the past (in a speculative
    /// batch the message is dropped and the batch marked instead).
    pub fn send_at(&mut self, to: u32, time: VTime<M::Time>, msg: M::Msg) -> Handle {
        self.post(to, time, msg, true)
    }

    /// Sends `mine` to this object and then `theirs` to `other`, both at `time`, as
    /// [`Ctx::send_at`] does; their name cancels them ([`Ctx::cancel_two`]).
    pub fn send_two(
        &mut self,
        other: u32,
        time: VTime<M::Time>,
        mine: M::Msg,
        theirs: M::Msg,
    ) -> SentTwo {
        let t = time.t();
        let first = self.send_at(self.me, time.clone(), mine);
        let second = self.send_at(other, time, theirs);
        let two = SentTwo {
            seq: first.seq,
            uid: first.uid,
            t,
        };
        debug_assert!(
            two.handles(self.me, other)
                .iter()
                .zip([first, second])
                .all(|(a, b)| (a.to, a.seq, a.uid, a.t) == (b.to, b.seq, b.uid, b.t)),
            "the two handles are consecutive"
        );
        two
    }

    /// Sends `msg` to `to` at `time`, as [`Ctx::send_at`], as a message that is never cancelled
    /// (a relay of news that stays true), so that the
    /// executor need not look it up among the cancellations.
    pub fn relay_at(&mut self, to: u32, time: VTime<M::Time>, msg: M::Msg) {
        self.post(to, time, msg, false);
    }

    /// Sends `msg` to `to` with zero delay, never to be cancelled: it arrives after this batch,
    /// within the same key.
    pub fn send_now(&mut self, to: u32, msg: M::Msg) {
        let time = self.reached().next_gen();
        self.relay_at(to, time, msg);
    }

    fn post(&mut self, to: u32, time: VTime<M::Time>, msg: M::Msg, retractable: bool) -> Handle {
        *self.seq += 1;
        let mut h = Handle {
            from: self.me,
            to,
            seq: *self.seq,
            uid: 0,
            t: time.t(),
        };
        if time <= *self.reached() {
            let what = format!(
                "object {} sent a message into the past: {:?} at {:?}",
                self.me,
                time,
                self.reached()
            );
            assert!(self.speculative, "{what}");
            self.into_past.get_or_insert(what);
            return h;
        }
        let lookahead = self.model.lookahead();
        if lookahead > 0.0 && time.t() < self.now.t() + lookahead {
            let what = format!(
                "object {} sent a message at t = {}, sooner than the model's lookahead {} after \
                 its batch at t = {}",
                self.me,
                time.t(),
                lookahead,
                self.now.t()
            );
            assert!(self.speculative, "{what}");
            self.into_past.get_or_insert(what);
        }
        if let Some(n) = self.uids.as_deref_mut() {
            *n += 1;
            h.uid = uid(self.me, *n);
        }
        let env = Envelope {
            from: self.me,
            seq: h.seq,
            msg,
        };
        self.sent.push(Pending {
            time,
            to,
            priority: self.model.priority(&env.msg),
            retractable,
            env,
        });
        h
    }

    /// Retracts a message this object sent (one cancel message), which must still be to
    /// come after this batch: the executors do not check that a message was not delivered
    /// already (Time Warp ignores a message of an earlier instant, and takes one of this
    /// batch's instant to be still to come).
    pub fn cancel(&mut self, h: Handle) {
        self.cancelled.push(h);
    }

    /// Retracts both messages this object sent to itself and `other` ([`Ctx::send_two`]), as
    /// [`Ctx::cancel`] does.
    pub fn cancel_two(&mut self, two: SentTwo, other: u32) {
        self.cancelled.extend(two.handles(self.me, other));
    }

    /// Reports output (a physical event, a drawing).
    pub fn emit(&mut self, out: M::Output) {
        if !self.output_times.is_empty() {
            self.output_times.push(self.now.clone());
        }
        self.output.push(out);
    }

    /// Makes room for `n` more outputs, each at a time of its own ([`Ctx::emit_at`]): a batch
    /// that knows how many it reports spares its vectors their growth.
    pub fn reserve_output(&mut self, n: usize) {
        self.output.reserve(n);
        self.output_times.reserve(n);
    }

    /// Reports output of one of the object's own events the batch ran on to, at `time`
    /// ([`Ctx::may_run`]): executors that hold outputs back order them by these times.
    pub fn emit_at(&mut self, time: VTime<M::Time>, out: M::Output) {
        if time != self.now || !self.output_times.is_empty() {
            // the outputs before the first at another time were at the batch's
            self.output_times
                .resize(self.output.len(), self.now.clone());
            self.output_times.push(time);
        }
        self.output.push(out);
    }
}

/// Message counts by type, as sent, and cancellations.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct MessageStats {
    /// Sent messages by type index.
    pub sent: Vec<u64>,
    /// Messages retracted by `cancel` (each one cancel message).
    pub cancels: u64,
    /// Batches run (object activations).
    pub batches: u64,
    /// Messages delivered.
    pub delivered: u64,
}

impl MessageStats {
    /// Counts a sent message of type `kind`.
    pub fn count(&mut self, kind: usize) {
        if self.sent.len() <= kind {
            self.sent.resize(kind + 1, 0);
        }
        self.sent[kind] += 1;
    }

    /// Adds another executor's counts.
    pub fn add(&mut self, o: &MessageStats) {
        for (k, &n) in o.sent.iter().enumerate() {
            if self.sent.len() <= k {
                self.sent.resize(k + 1, 0);
            }
            self.sent[k] += n;
        }
        self.cancels += o.cancels;
        self.batches += o.batches;
        self.delivered += o.delivered;
    }

    /// The count of type `kind`.
    pub fn get(&self, kind: usize) -> u64 {
        self.sent.get(kind).copied().unwrap_or(0)
    }
}
