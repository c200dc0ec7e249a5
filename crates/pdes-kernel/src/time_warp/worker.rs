//! One worker: its objects, their pending messages and uncommitted batches; the loop that runs
//! them optimistically, rolls back, commits and takes part in GVT rounds.

use super::config::{
    TwConfig, TwStats, DEFAULT_BURST, MAX_CASCADE_DEPTH, PURE_BURST, THREADS_GVT_INTERVAL,
};
use super::fabric::*;
use super::floor::Floor;
use super::log::{Chain, Log};
use super::marks::{Mark, Marks};
use super::threads;
use super::window::AutoWindow;
use crate::prefetch::{prefetch, prefetch_all};
use crate::queue::{Queue, Ranked};
use crate::{
    uid, Ctx, Envelope, Handle, Horizon, Interrupt, MessageStats, Model, Pending, Saving, Time,
    VTime, RESERVED_PER_OBJECT, STATE_CLASSES,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// A message waiting in a worker's heap, with its transport name.
struct Item<T, Msg> {
    uid: u64,
    p: Pending<T, Msg>,
}

impl<T: Time, Msg> Item<T, Msg> {
    /// The delivery order; two sends of one message (the second after a rollback) by uid.
    fn order(&self, o: &Self) -> Ordering {
        self.p.order(&o.p).then(self.uid.cmp(&o.uid))
    }

    /// What a batch keeps of it: its name, and the envelope the model reads.
    fn into_input(self) -> (Input, Envelope<Msg>) {
        let input = Input {
            uid: self.uid,
            priority: self.p.priority,
            retractable: self.p.retractable,
        };
        (input, self.p.env)
    }
}

impl Input {
    /// The message again, as it waited for the batch of `to` at `time` (undone by a rollback).
    fn into_item<T: Time, Msg>(self, env: Envelope<Msg>, time: &VTime<T>, to: u32) -> Item<T, Msg> {
        let p = Pending {
            time: time.clone(),
            to,
            priority: self.priority,
            retractable: self.retractable,
            env,
        };
        Item { uid: self.uid, p }
    }
}

impl<T: Time, Msg> PartialEq for Item<T, Msg> {
    fn eq(&self, o: &Self) -> bool {
        self.order(o) == Ordering::Equal
    }
}

impl<T: Time, Msg> Eq for Item<T, Msg> {}

impl<T: Time, Msg> PartialOrd for Item<T, Msg> {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl<T: Time, Msg> Ord for Item<T, Msg> {
    fn cmp(&self, o: &Self) -> Ordering {
        o.order(self)
    }
}

impl<T: Time, Msg> Ranked for Item<T, Msg> {
    fn rank(&self) -> [u64; 4] {
        // the heap's order is the delivery order reversed
        self.p.rank(self.uid).map(|x| !x)
    }
    fn same_instant(&self, o: &Self) -> bool {
        self.p.time.key == o.p.time.key
    }
    fn lead(&self) -> u64 {
        !self.p.lead()
    }
}

/// A message an uncommitted batch sent, as its sender remembers it to annul it.
#[derive(Clone, Debug)]
struct Sent<T> {
    uid: u64,
    to: u32,
    time: VTime<T>,
}

/// What a batch keeps of each message it handled, besides the envelope, to put it back.
struct Input {
    uid: u64,
    priority: u8,
    retractable: bool,
}

/// Vectors of finished batches, kept for the next ones: a worker runs millions of batches, and
/// each would otherwise allocate and free the same few small vectors.
struct Spare<T, Msg, State, Undo> {
    /// Saved states freed by commits and rollbacks, by [`Model::state_class`]: a batch's state
    /// is saved into one of its kind with `clone_from`, which reuses the buffers the state
    /// holds instead of allocating.
    states: [Vec<State>; STATE_CLASSES],
    /// Journals of objects saved incrementally ([`Saving::Incremental`]).
    journals: Vec<Vec<Undo>>,
    inputs: Vec<Vec<Input>>,
    batches: Vec<Vec<Envelope<Msg>>>,
    sent: Vec<Vec<(Sent<T>, u16)>>,
    cancels: Vec<Vec<Handle>>,
    /// What the model's handler sends, emptied after every batch.
    pending: Vec<Pending<T, Msg>>,
    /// Cancellations and retractions a batch makes, emptied after every batch (its messages go
    /// out as it files them).
    ops: Vec<Op<T, Msg>>,
}

/// Vectors of each kind kept at most.
const SPARE: usize = 4096;
/// Saved states of each kind kept at most: as many as the uncommitted batches of a worker that
/// runs ahead (two GVT intervals on threads), so that a worker saves states without allocating.
const SPARE_STATES: usize = 4096;

impl<T: Time, Msg, State, Undo> Default for Spare<T, Msg, State, Undo> {
    fn default() -> Self {
        Spare {
            states: Default::default(),
            journals: Vec::new(),
            inputs: Vec::new(),
            batches: Vec::new(),
            sent: Vec::new(),
            cancels: Vec::new(),
            pending: Vec::new(),
            ops: Vec::new(),
        }
    }
}

/// A spare vector, or a new one.
#[inline(always)]
fn take<T>(pool: &mut Vec<Vec<T>>) -> Vec<T> {
    pool.pop().unwrap_or_default()
}

/// Whether the message of `h` is still to come after the batch at `time` that cancels it:
/// sent (not dropped as a send into the past) and not before that batch's instant. A model
/// cancels only messages still to come, so a message of the same instant is taken to be.
fn still_to_come<T: Time>(h: &Handle, time: &VTime<T>) -> bool {
    h.uid != 0 && h.t >= time.t()
}

/// A time no later than the message of `h`, cancelled by the batch of object `by` at `at`, and
/// after every batch before that one's place: the start of the message's instant, or within the
/// cancelling batch's instant the first time its message can have (a handle keeps only the
/// simulation time). A message to an object below `by` comes at a later time than `at`.
fn not_before<T: Time>(h: &Handle, at: VTime<T>, by: u32) -> VTime<T> {
    if h.t > at.t() {
        VTime::start(h.t)
    } else if h.to < by {
        at.next_gen()
    } else {
        at
    }
}

/// Keeps `v`, emptied, for another batch.
#[inline(always)]
fn give<T>(pool: &mut Vec<Vec<T>>, mut v: Vec<T>) {
    if pool.len() < SPARE && v.capacity() > 0 {
        v.clear();
        pool.push(v);
    }
}

/// A worker asks for a sweep of the heaps when marked messages are over half of its heap
/// ([`Reduction::sweep`]).
const ASK_SWEEP: usize = 2;
/// A worker joins a sweep another asked for when they are over a quarter of its heap.
const JOIN_SWEEP: usize = 4;

/// What undoes a batch's changes to its object's state ([`Model::saving`]).
enum Saved<M: Model> {
    /// The whole state before the batch, and its kind ([`Model::state_class`]).
    Copy(u8, M::State),
    /// The old values the handler recorded, oldest first, and what puts one back.
    Journal(Vec<M::Undo>, fn(&mut M::State, M::Undo)),
}

/// What a batch that ran its object's own events on ([`Ctx::may_run`]) adds to its record:
/// boxed, so that a batch that did not pays nothing for it.
struct Span<T> {
    /// The last of its object's own events it ran.
    end: VTime<T>,
    /// The time of each output ([`Ctx::output_times`]; empty when all are at its time).
    output_times: Vec<VTime<T>>,
    /// Where each of its object's own events it ran on to starts in its journal
    /// ([`Ctx::marks`]).
    marks: Vec<(VTime<T>, usize)>,
}

/// A batch an object ran that is not committed yet.
struct Done<M: Model> {
    time: VTime<M::Time>,
    /// What it ran past its time, if anything.
    span: Option<Box<Span<M::Time>>>,
    /// What restores the object's state before it.
    saved: Saved<M>,
    pre_seq: u64,
    /// The messages it handled: their names, and the envelopes the model saw.
    inputs: Vec<Input>,
    batch: Vec<Envelope<M::Msg>>,
    sent: Vec<(Sent<M::Time>, u16)>,
    /// The messages it cancelled that were still to come.
    cancels: Vec<Handle>,
    cancel_calls: u32,
    output: Vec<M::Output>,
    /// A send into the past it tried: harmless if rolled back, a model bug if committed.
    into_past: Option<String>,
}

impl<M: Model> Done<M> {
    /// The time it reached: its own, or the last of its object's own events it ran on to.
    fn end(&self) -> &VTime<M::Time> {
        reached(&self.time, &self.span)
    }

    /// Whether it was taken in after batches of its object that ran past it
    /// ([`Model::take_in`]): it reached their end without running on.
    fn taken_in(&self) -> bool {
        self.span
            .as_ref()
            .is_some_and(|s| s.marks.is_empty() && s.end > self.time)
    }
}

/// The time a batch at `time` reached: its own, or the end of its `span`.
fn reached<'a, T>(time: &'a VTime<T>, span: &'a Option<Box<Span<T>>>) -> &'a VTime<T> {
    span.as_ref().map_or(time, |s| &s.end)
}

/// What a batch of object `by` keeps of the messages it `sent`, for anti-messages and
/// statistics: the first is named after the object's count `first` of named messages.
fn sent_records<'a, M: Model>(
    model: &'a M,
    by: u32,
    first: u64,
    sent: &'a [Pending<M::Time, M::Msg>],
) -> impl Iterator<Item = (Sent<M::Time>, u16)> + 'a {
    (first + 1..).zip(sent).map(move |(n, p)| {
        let s = Sent {
            uid: uid(by, n),
            to: p.to,
            time: p.time.clone(),
        };
        (s, model.kind(&p.env.msg) as u16)
    })
}

/// The outputs' times of a batch that ran on (none for one that did not: all at its time).
fn output_times<T>(span: Option<Box<Span<T>>>) -> Vec<VTime<T>> {
    span.map(|s| s.output_times).unwrap_or_default()
}

/// What a batch did: for [`Worker::commit_final`] when it ran as final, for
/// [`Worker::log_batch`] when it ran speculatively.
struct Did<'a, M: Model> {
    time: VTime<M::Time>,
    /// What it ran past its time ([`Done::span`]).
    span: Option<Box<Span<M::Time>>>,
    /// The object's count of named messages before it.
    uids: u64,
    /// The object's send sequence before it.
    pre_seq: u64,
    /// Messages it handled.
    delivered: usize,
    cancelled: &'a [Handle],
    output: Vec<M::Output>,
    into_past: Option<String>,
}

/// A batch taken off a worker's queue: every live message for one object at one time.
struct Taken<M: Model> {
    /// The object, and its index on this worker.
    to: u32,
    li: usize,
    /// The messages' names, and the envelopes the model reads.
    inputs: Vec<Input>,
    batch: Vec<Envelope<M::Msg>>,
    /// Whether any of its messages may still be retracted.
    cancellable: bool,
    /// The object of the message after the batch, if any.
    next: Option<u32>,
    /// What restores the object's state before the batch, when it runs speculatively.
    saved: Option<Saved<M>>,
}

/// One object (a logical process) on its worker.
struct Lp<M: Model> {
    id: u32,
    /// Its state; `None` between runs while the executor's collector holds it.
    state: Option<M::State>,
    seq: u64,
    uids: u64,
    /// Its uncommitted batches in its worker's log.
    history: Chain,
    /// Whether it is in its worker's list of objects with uncommitted batches.
    active: bool,
    /// For an object that runs ahead ([`Model::runs_ahead`]): the times of the messages
    /// pushed for it, earliest first, those of its batches run and of cancelled messages
    /// included until its batches pass them (they can only end its spans sooner).
    waiting: Option<BinaryHeap<Reverse<VTime<M::Time>>>>,
    /// Whether its latest batch was cut back ([`Worker::cut`]) and waits to be ended anew
    /// ([`Model::cut`]).
    cut: bool,
    /// Batches it had taken in after batches that ran past them, undone for a message later
    /// than they are, latest first: taken in again as they were ([`Worker::retake`]).
    retakes: Vec<Late<M>>,
}

/// A batch taken in after batches that ran past it, undone for a later message
/// ([`Lp::retakes`]).
struct Late<M: Model> {
    time: VTime<M::Time>,
    inputs: Vec<Input>,
    batch: Vec<Envelope<M::Msg>>,
}

/// Where each object lives: its worker and its index there.
#[derive(Clone, Debug)]
pub struct Placement {
    place: Vec<(u32, u32)>,
    workers: usize,
}

impl Placement {
    /// The placement of objects given each one's worker.
    pub fn new(worker_of: &[u32], workers: usize) -> Placement {
        let mut counts = vec![0u32; workers];
        let place = worker_of
            .iter()
            .map(|&w| {
                let k = counts[w as usize];
                counts[w as usize] += 1;
                (w, k)
            })
            .collect();
        Placement { place, workers }
    }

    /// The worker of object `o`.
    pub fn worker(&self, o: u32) -> usize {
        self.place[o as usize].0 as usize
    }

    fn local(&self, o: u32) -> usize {
        self.place[o as usize].1 as usize
    }

    /// Starts loading where object `o` lives.
    fn prefetch(&self, o: u32) {
        prefetch(&self.place[o as usize]);
    }

    /// Number of workers.
    pub fn workers(&self) -> usize {
        self.workers
    }
}

/// Chaos mode's state.
struct Chaos<T, Msg> {
    rng: ChaCha8Rng,
    /// Ops held back, with the iteration that releases each.
    held: Vec<(u64, Op<T, Msg>)>,
}

/// One worker: its objects, its messages, its outboxes.
pub struct Worker<M: Model> {
    index: usize,
    placement: std::sync::Arc<Placement>,
    lps: Vec<Lp<M>>,
    /// Live and marked messages not handled yet.
    heap: Queue<Item<M::Time, M::Msg>>,
    /// Anti-messages and cancellations, and cancelled messages set aside.
    marks: Marks<M::Time, M::Msg>,
    /// The key of the batch run last: messages for it go to the pending set's instant tier.
    current: M::Time,
    /// Ops for this worker's objects.
    local_ops: Vec<Op<M::Time, M::Msg>>,
    /// Vectors for the next batches.
    spare: Spare<M::Time, M::Msg, M::State, M::Undo>,
    outbox: Vec<Vec<Op<M::Time, M::Msg>>>,
    /// Chaos mode: its random stream and the ops it holds back.
    chaos: Option<Chaos<M::Time, M::Msg>>,
    iteration: u64,
    sent_ops: i64,
    received_ops: i64,
    uncommitted: usize,
    gvt: Floor,
    /// The optimism window when none is set.
    auto_window: AutoWindow,
    round: u64,
    stats: TwStats,
    committed_stats: MessageStats,
    /// Memory samples (uncommitted batches plus messages held) after each GVT round.
    samples: Vec<u64>,
    /// A failure found while committing; the run stops at the next GVT round.
    fault: Option<String>,
    /// Local objects with uncommitted batches (fossil collection visits only these).
    active: Vec<u32>,
    /// Uncommitted batches in the order they ran (committed early from the front), held in
    /// the log itself: a box per record cost an allocation and a free per undoable batch.
    log: Log<Done<M>>,
    /// The floor this worker published last (with final batches only).
    published: Floor,
    /// Whether batches may run as final ([`TwConfig::final_batches`]).
    final_ok: bool,
    /// The model's least delay of a message ([`Model::lookahead`]).
    lookahead: f64,
    /// When the worker started its latest run.
    started: Option<std::time::Instant>,
    /// The latest time of a batch this worker has run, rolled back or not.
    latest: f64,
    /// Where its latest run ended: the run's end, or the earlier time an interrupt chose.
    pub ended_at: f64,
    /// Batches in a burst ([`TwConfig::burst`], at most a GVT interval).
    burst_len: u32,
    /// Whether the collector wants observed objects' states.
    ship: bool,
    /// Below every op another worker may still send here, as last found (lowered by every op
    /// this worker sends away since).
    final_bound: Floor,
    /// Below every message and anti-message another worker may still send here, likewise.
    message_bound: Floor,
    /// Batches to wait before asking the fabric for a new bound after a failed try.
    bound_wait: u32,
    /// Workers of this process, whose slots each try reads (all workers but under MPI).
    workers_here: u32,
    /// The last batch run as final: no message or anti-message may come at or before it.
    final_floor: Floor,
    /// The last batch run as final below every op another worker may send: no op at all, a
    /// cancellation included, may come at or before it.
    cancel_floor: Floor,
    /// The latest batch run optimistically: no uncommitted batch is later.
    high: Option<VTime<M::Time>>,
    /// Below every op in the outboxes.
    outbox_floor: Floor,
    /// Whether some object here runs ahead ([`Model::runs_ahead`]).
    runs_ahead: bool,
    /// Local objects whose latest batch was cut back, to be ended anew before anything else.
    cuts: Vec<u32>,
    /// Local objects with batches to take in again ([`Lp::retakes`]), before anything else.
    retaking: Vec<u32>,
    /// What the collector needs of committed batches, until the chunk of the first GVT round
    /// that passes them: the collector puts out a round's batches after the round before's,
    /// and a batch run as final may be later than one another worker commits a round after.
    to_ship: Vec<Committed<M::Time, M::State, M::Output>>,
}

/// What may end a worker's run early: another worker's failure, or an interrupt.
#[derive(Clone, Copy)]
pub struct Halt<'a> {
    /// Raised when a worker failed or the sink returned an error: stop at the next round.
    pub failed: &'a std::sync::atomic::AtomicBool,
    /// Raised to end the run cleanly at a time every worker agrees on.
    pub interrupt: Option<&'a Interrupt>,
}

/// Why a worker stopped early.
#[derive(Clone, Debug, PartialEq)]
pub enum Stop {
    /// Another worker or the collector asked to stop.
    Asked,
    /// This worker failed: out of its memory budget, or a model bug committed.
    Failed(String),
}

/// Why a state is there: the executor gives the workers their objects' states before they
/// run, and takes them back only after.
const HELD: &str = "a worker holds its objects' states while it runs";

/// The state of an object of a worker that runs.
fn held<S>(state: &mut Option<S>) -> &mut S {
    state.as_mut().expect(HELD)
}

impl<M: Model> Worker<M> {
    /// A worker for the objects `ids` (those `placement` gives it), without their states:
    /// it gets them with [`Worker::give_states`] before it runs.
    pub fn new(
        index: usize,
        placement: std::sync::Arc<Placement>,
        ids: Vec<u32>,
        chaos: Option<u64>,
    ) -> Worker<M> {
        let workers = placement.workers();
        let n_objects = ids.len();
        Worker {
            index,
            lps: ids
                .into_iter()
                .map(|id| Lp {
                    id,
                    state: None,
                    seq: 0,
                    uids: 0,
                    history: Chain::EMPTY,
                    active: false,
                    waiting: None,
                    cut: false,
                    retakes: Vec::new(),
                })
                .collect(),
            placement,
            heap: Queue::with_capacity(RESERVED_PER_OBJECT * n_objects),
            marks: Marks::default(),
            current: M::Time::start(f64::NEG_INFINITY),
            local_ops: Vec::new(),
            spare: Spare::default(),
            outbox: (0..workers).map(|_| Vec::new()).collect(),
            chaos: chaos.map(|s| Chaos {
                rng: ChaCha8Rng::seed_from_u64(s ^ (index as u64).wrapping_mul(0x9e37_79b9)),
                held: Vec::new(),
            }),
            iteration: 0,
            sent_ops: 0,
            received_ops: 0,
            uncommitted: 0,
            gvt: Floor::NEG_INFINITY,
            auto_window: AutoWindow::new(),
            round: 0,
            stats: TwStats {
                workers: 1,
                ranks: 1,
                ..Default::default()
            },
            committed_stats: MessageStats::default(),
            samples: Vec::new(),
            fault: None,
            active: Vec::new(),
            log: Log::default(),
            published: Floor::NEG_INFINITY,
            final_ok: false,
            lookahead: 0.0,
            started: None,
            latest: f64::NEG_INFINITY,
            ended_at: f64::NEG_INFINITY,
            burst_len: DEFAULT_BURST,
            ship: false,
            final_bound: Floor::NEG_INFINITY,
            message_bound: Floor::NEG_INFINITY,
            bound_wait: 0,
            workers_here: workers as u32,
            final_floor: Floor::NEG_INFINITY,
            cancel_floor: Floor::NEG_INFINITY,
            high: None,
            outbox_floor: Floor::INFINITY,
            runs_ahead: false,
            cuts: Vec::new(),
            retaking: Vec::new(),
            to_ship: Vec::new(),
        }
    }

    /// Runs every object's `init` at `start`; its sends are routed like any others (flush
    /// them with [`Worker::take_outbox`]). Init sends are committed at once.
    pub fn init(&mut self, model: &M, start: &VTime<M::Time>) {
        for lp in &mut self.lps {
            if model.runs_ahead(lp.id) {
                lp.waiting = Some(BinaryHeap::new());
                self.runs_ahead = true;
            }
        }
        for k in 0..self.lps.len() {
            let lp = &mut self.lps[k];
            let (id, first) = (lp.id, lp.uids);
            let mut ctx = Ctx::new(model, start.clone(), id, &mut lp.seq).named(&mut lp.uids);
            model.init(&mut ctx, id, held(&mut lp.state));
            let sent = ctx.sent;
            assert!(ctx.cancelled.is_empty(), "init may not cancel");
            for (n, p) in (first + 1..).zip(sent) {
                self.committed_stats.count(model.kind(&p.env.msg));
                self.send(uid(id, n), p);
            }
        }
        self.drain_local();
    }

    /// Takes the ops waiting for workers `to` (uncounted: the caller delivers them itself,
    /// or a fabric counts them).
    pub fn take_outbox(&mut self, to: std::ops::Range<usize>) -> Vec<(usize, Vec<OpOf<M>>)> {
        let mut out = Vec::new();
        for (w, ops) in self.outbox.iter_mut().enumerate() {
            if to.contains(&w) && !ops.is_empty() {
                out.push((w, std::mem::take(ops)));
            }
        }
        out
    }

    /// Accepts ops handed over outside a fabric (at set-up).
    pub fn accept(&mut self, ops: Vec<Op<M::Time, M::Msg>>) {
        for op in ops {
            self.apply(op);
        }
        self.drain_local();
    }

    /// Messages waiting (not handled) on this worker, as the sequential executor counts them:
    /// annulled and cancelled ones not yet discarded included. (Telling them apart would take
    /// a look-up per message, 20 ms at the end of a run of 10^5 objects.)
    pub fn pending_len(&self) -> usize {
        self.heap.len() + self.marks.set_aside_len()
    }

    /// This worker's objects, in the order it holds them.
    pub fn ids(&self) -> impl Iterator<Item = u32> + '_ {
        self.lps.iter().map(|lp| lp.id)
    }

    /// Whether the worker holds its objects' states.
    pub fn holds_states(&self) -> bool {
        self.lps.iter().all(|lp| lp.state.is_some())
    }

    /// Gives each of this worker's objects its state, `state(id)`.
    pub fn give_states(&mut self, mut state: impl FnMut(u32) -> M::State) {
        for lp in &mut self.lps {
            lp.state = Some(state(lp.id));
        }
    }

    /// Hands each of this worker's objects' states to `take(id, state)`, moving it rather
    /// than copying it: after a run, the collector beside the workers takes the final states
    /// this way, and the worker gets them back with [`Worker::give_states`] before it runs
    /// again.
    pub fn hand_back_states(&mut self, mut take: impl FnMut(u32, M::State)) {
        for lp in &mut self.lps {
            if let Some(state) = lp.state.take() {
                take(lp.id, state);
            }
        }
    }

    /// Memory samples (uncommitted batches plus held messages) after each GVT round.
    pub fn samples(&self) -> &[u64] {
        &self.samples
    }

    /// Sends an op on its way.
    fn route(&mut self, op: Op<M::Time, M::Msg>) {
        let w = self.placement.worker(op.to());
        if let Op::Anti { .. } = op {
            self.stats.anti_messages += 1;
        }
        if w == self.index {
            self.local_ops.push(op);
        } else {
            let f = op.floor();
            self.outbox_floor = self.outbox_floor.min(f);
            self.final_bound = self.final_bound.min(f);
            self.message_bound = self.message_bound.min(f);
            self.outbox[w].push(op);
        }
    }

    fn drain_local(&mut self) {
        while let Some(op) = self.local_ops.pop() {
            self.apply(op);
        }
    }

    /// Applies one op, rolling its receiver back if the op changes what the receiver's past
    /// should have seen.
    fn apply(&mut self, op: Op<M::Time, M::Msg>) {
        let (to, (time, obj)) = (op.to(), op.place());
        // a cancellation may come before a batch of messages no one can cancel run as final
        let floor = match op {
            Op::Msg { .. } | Op::Anti { .. } => &self.final_floor,
            Op::Cancel { .. } | Op::Retract { .. } => &self.cancel_floor,
        };
        if floor.reaches(time, obj) {
            let kind = match op {
                Op::Msg { .. } => "a message",
                Op::Anti { .. } => "an anti-message",
                Op::Cancel { .. } => "a cancellation",
                Op::Retract { .. } => "a retraction",
            };
            self.fault.get_or_insert(format!(
                "time warp: {kind} for object {to} at t = {} came after a later batch ran as final",
                time.t()
            ));
        }
        let li = self.placement.local(to);
        match op {
            Op::Msg { uid, p } => {
                if !self.marks.arrives(uid, p.retractable) {
                    return; // its anti-message or retraction came first
                }
                if p.retractable && self.marks.cancelled(uid) {
                    self.marks.set_aside(uid, p, Mark::Cancelled, self.gvt.t);
                    return;
                }
                self.arrives(li, &p);
                self.push(Item { uid, p });
            }
            Op::Anti { uid, time, .. } => {
                // a cancelled message was handled by no batch that stands
                let unseen = self.marks.cancelled(uid);
                if !self.marks.annul(uid) && !unseen {
                    self.undo_from(li, &time);
                }
            }
            Op::Retract { h, at, by } => self.retract(h, &at, by),
            Op::Cancel { h, at, by, sign } => {
                let (changed, back) = self.marks.cancel(h.uid, h.t, at.t(), sign);
                if changed && h.to != by {
                    self.undo_handling(li, &not_before(&h, at, by));
                }
                if let Some(p) = back {
                    self.push(Item { uid: h.uid, p });
                }
            }
        }
        self.note_entries();
    }

    /// A retraction of a message of this worker by the batch of `by` at `at` (the canceller
    /// itself never handled its message, which comes after the batch that cancels it).
    fn retract(&mut self, h: Handle, at: &VTime<M::Time>, by: u32) {
        let unseen = self.marks.cancelled(h.uid);
        // with no batch uncommitted, no batch handled it
        if !self.marks.retract(h.uid) && !unseen && h.to != by && self.high.is_some() {
            let li = self.placement.local(h.to);
            self.undo_handling(li, &not_before(&h, at.clone(), by));
        }
    }

    /// Rolls local object `li` back if it may have handled a message at `time` that is gone:
    /// the message is back in the heap after this, and its mark drops it there.
    fn undo_handling(&mut self, li: usize, time: &VTime<M::Time>) {
        if self.ran_past(li, time) {
            self.rollback(li, time);
        }
    }

    /// Puts a message in the heap, in the instant's tier if it is for the key being run.
    #[inline(always)]
    fn push(&mut self, it: Item<M::Time, M::Msg>) {
        let in_instant = it.p.time.key == self.current;
        self.note_waiting(it.p.to, &it.p.time);
        self.heap.push(it, in_instant);
    }

    /// Notes a message for object `to` at `time` among those waiting for it, if it runs ahead.
    #[inline(always)]
    fn note_waiting(&mut self, to: u32, time: &VTime<M::Time>) {
        if self.runs_ahead {
            let li = self.placement.local(to);
            if let Some(w) = &mut self.lps[li].waiting {
                w.push(Reverse(time.clone()));
            }
        }
    }

    /// How far a batch of local object `li` at `time` may run its object's own events on
    /// ([`Ctx::may_run`]): before the next message waiting for it, and not past `limit`; a
    /// batch run as final, moreover, only before every message waiting here and every op
    /// another worker may still send. None for an object that does not run ahead, or when the
    /// collector reads states.
    fn horizon(
        &mut self,
        li: usize,
        time: &VTime<M::Time>,
        limit: f64,
        run_final: bool,
    ) -> Option<Horizon<M::Time>> {
        if self.ship {
            return None;
        }
        let waiting = self.lps[li].waiting.as_mut()?;
        while waiting.peek().is_some_and(|Reverse(t)| t <= time) {
            waiting.pop();
        }
        let mut before = waiting.peek().map(|Reverse(t)| t.clone());
        let mut until = limit;
        if run_final {
            if let Some(top) = self.heap.peek() {
                if before.as_ref().is_none_or(|b| top.p.time < *b) {
                    before = Some(top.p.time.clone());
                }
            }
            until = until.min(self.final_bound.t.next_down());
        }
        Some(Horizon { before, until })
    }

    /// Undoes every batch of local object `li` that reached `time` or later.
    fn rollback(&mut self, li: usize, time: &VTime<M::Time>) {
        self.stats.rollbacks += 1;
        self.release_retakes(li, time);
        while self.last_reached(li).is_some_and(|t| t >= time) {
            self.undo_last(li, time);
        }
    }

    /// Puts the messages of local object `li`'s batches to take in again at `time` or later
    /// back in the heap: a message at `time` undoes the object back before them.
    fn release_retakes(&mut self, li: usize, time: &VTime<M::Time>) {
        let lp = &mut self.lps[li];
        if lp.retakes.iter().all(|l| l.time < *time) {
            return;
        }
        let (to, retakes) = (lp.id, std::mem::take(&mut lp.retakes));
        for late in retakes {
            if late.time < *time {
                self.lps[li].retakes.push(late);
            } else {
                self.put_back(to, &late.time, late.inputs, late.batch);
            }
        }
    }

    /// Puts the messages of a batch of object `to` at `time` back in the heap.
    fn put_back(
        &mut self,
        to: u32,
        time: &VTime<M::Time>,
        mut inputs: Vec<Input>,
        mut batch: Vec<Envelope<M::Msg>>,
    ) {
        for (i, env) in inputs.drain(..).zip(batch.drain(..)) {
            self.note_waiting(to, time);
            self.heap.push(i.into_item(env, time, to), false);
        }
        give(&mut self.spare.inputs, inputs);
        give(&mut self.spare.batches, batch);
    }

    /// Readies local object `li` for message `p` that has just come for it: rolls it back if
    /// it ran past the message, unless the message may wait to be taken in after the batch
    /// that did ([`Worker::may_take_in`]).
    #[inline(always)]
    fn arrives(&mut self, li: usize, p: &Pending<M::Time, M::Msg>) {
        if self.ran_past(li, &p.time) && !self.may_take_in(li, p) {
            self.straggler(li, &p.time);
        }
    }

    /// Whether message `p` for local object `li`, which ran past it, may wait for its turn to
    /// be taken in after the object's latest batch ([`Model::take_in`]) instead of cutting it
    /// back: the model allows it for the message, and the batches that reached its time are
    /// journaled ([`Worker::late_ok`]).
    fn may_take_in(&self, li: usize, p: &Pending<M::Time, M::Msg>) -> bool {
        M::may_take_in(&p.env.msg) && self.late_ok(li, &p.time)
    }

    /// Whether a batch at `time` of local object `li`, which ran past it, may be taken in
    /// after its latest batch: the collector does not read states (which it would see out of
    /// order), every uncommitted batch of the object that reached `time` is journaled, none
    /// is at `time` itself (a batch at that time must run again with it), and none taken in
    /// so is later (the model checks what the batch would change against the events run past
    /// it, not against batches taken in).
    fn late_ok(&self, li: usize, time: &VTime<M::Time>) -> bool {
        !self.ship
            && (self.log.newest_first(&self.lps[li].history))
                .take_while(|d| d.end() >= time)
                .all(|d| {
                    let later_taken_in = d.time > *time && d.taken_in();
                    d.time != *time && !later_taken_in && matches!(d.saved, Saved::Journal(..))
                })
    }

    /// Undoes every uncommitted batch of local object `li` at `time` or later, and every one
    /// taken in after a batch that reached `time`: one of them may have handled a message at
    /// `time` that is gone. A batch before `time` that ran its own events on past it stands:
    /// it ran before the message came (which then cut it back, or waited to be taken in after
    /// it), so no event of it saw the message.
    fn undo_from(&mut self, li: usize, time: &VTime<M::Time>) {
        let undone = |d: &Done<M>| *d.end() >= *time && (d.time >= *time || d.taken_in());
        self.release_retakes(li, time);
        if (self.log.last(&self.lps[li].history)).is_some_and(undone) {
            self.stats.rollbacks += 1;
            while (self.log.last(&self.lps[li].history)).is_some_and(undone) {
                self.undo_last(li, time);
            }
        }
    }

    /// Rolls local object `li` back for a message that came for it at `time`, after it ran
    /// past it: a batch that ran its object's own events on across `time` is cut back to the
    /// last of them before it ([`Worker::cut`]), every later batch undone (a batch taken in
    /// after it among them).
    fn straggler(&mut self, li: usize, time: &VTime<M::Time>) {
        self.stats.rollbacks += 1;
        self.release_retakes(li, time);
        while let Some(d) = self.log.last(&self.lps[li].history) {
            if *d.end() < *time {
                return;
            }
            let marked = d.span.as_ref().is_some_and(|s| !s.marks.is_empty());
            if d.time < *time && marked && matches!(d.saved, Saved::Journal(..)) {
                return self.cut(li, time);
            }
            self.undo_last(li, time);
        }
    }

    /// Undoes local object `li`'s latest uncommitted batch for a message at `time`: restores
    /// the state before it, puts its messages back, and annuls what it sent and cancelled. A
    /// batch taken in before `time` after batches that ran past it is taken in again instead
    /// ([`Worker::retake`]): handled in its turn, it could undo events of theirs before
    /// `time`, and what they sent, below this worker's floor.
    fn undo_last(&mut self, li: usize, time: &VTime<M::Time>) {
        let lp = &mut self.lps[li];
        let d = self.log.pop_last(&mut lp.history).expect("a batch to undo");
        let retake = d.taken_in() && d.time < *time;
        lp.cut = false;
        self.uncommitted -= 1;
        self.stats.rolled_back += 1;
        let end = d.end().clone();
        self.stats.ran_on_undone += d.span.as_ref().map_or(0, |s| s.marks.len()) as u64;
        match d.saved {
            Saved::Copy(class, pre_state) => {
                let undone = std::mem::replace(held(&mut lp.state), pre_state);
                self.give_state(class, undone);
            }
            Saved::Journal(mut journal, restore) => {
                while let Some(undo) = journal.pop() {
                    restore(held(&mut lp.state), undo);
                }
                give(&mut self.spare.journals, journal);
            }
        }
        let lp = &mut self.lps[li];
        lp.seq = d.pre_seq;
        let to = lp.id;
        if retake {
            if lp.retakes.is_empty() {
                self.retaking.push(li as u32);
            }
            let (time, inputs, batch) = (d.time, d.inputs, d.batch);
            lp.retakes.push(Late {
                time,
                inputs,
                batch,
            });
        } else {
            self.put_back(to, &d.time, d.inputs, d.batch);
        }
        let (mut sent, mut cancels) = (d.sent, d.cancels);
        self.annul(to, &end, &mut sent, &mut cancels);
        give(&mut self.spare.sent, sent);
        give(&mut self.spare.cancels, cancels);
    }

    /// Annuls what a batch of object `by` that reached `end` sent (anti-messages) and
    /// cancelled (cancellations withdrawn), emptying both.
    fn annul(
        &mut self,
        by: u32,
        end: &VTime<M::Time>,
        sent: &mut Vec<(Sent<M::Time>, u16)>,
        cancels: &mut Vec<Handle>,
    ) {
        for (s, _) in sent.drain(..) {
            let op = Op::Anti {
                uid: s.uid,
                to: s.to,
                time: s.time,
            };
            self.route(op);
        }
        for h in cancels.drain(..) {
            let op = Op::Cancel {
                h,
                at: end.clone(),
                by,
                sign: -1,
            };
            self.route(op);
        }
    }

    /// Cuts local object `li`'s latest batch, which ran its own events on across `time`, back
    /// to before the first of them at or after `time`: restores the journal from that
    /// event's mark on, drops those events' outputs and annuls what the batch sent and
    /// cancelled at its end. The batch stays, ending at the last event it keeps; the model
    /// ends it anew ([`Worker::resume_cuts`]) before anything else runs.
    fn cut(&mut self, li: usize, time: &VTime<M::Time>) {
        self.stats.cuts += 1;
        let lp = &mut self.lps[li];
        let d = self.log.last_mut(&lp.history).expect("a batch to cut");
        let span = d.span.as_mut().expect("only a batch that ran on is cut");
        let m = span.marks.partition_point(|(t, _)| t < time);
        let Saved::Journal(journal, restore) = &mut d.saved else {
            unreachable!("only a journaled batch is cut");
        };
        let from = span.marks[m].1;
        while journal.len() > from {
            restore(held(&mut lp.state), journal.pop().expect("a record"));
        }
        self.stats.ran_on_undone += (span.marks.len() - m) as u64;
        let end = std::mem::replace(
            &mut span.end,
            match m {
                0 => d.time.clone(),
                _ => span.marks[m - 1].0.clone(),
            },
        );
        span.marks.truncate(m);
        if !span.output_times.is_empty() {
            let kept = span.output_times.partition_point(|t| t < time);
            d.output.truncate(kept);
            span.output_times.truncate(kept);
        }
        lp.seq = d.pre_seq;
        d.cancel_calls = 0;
        d.into_past = None;
        let (mut sent, mut cancels) = (std::mem::take(&mut d.sent), std::mem::take(&mut d.cancels));
        if !lp.cut {
            lp.cut = true;
            self.cuts.push(li as u32);
        }
        let by = lp.id;
        self.annul(by, &end, &mut sent, &mut cancels);
        let d = self
            .log
            .last_mut(&self.lps[li].history)
            .expect("the batch cut");
        (d.sent, d.cancels) = (sent, cancels);
    }

    /// Ends anew, by the model ([`Model::cut`]), every batch cut back since the last call,
    /// and sends what it sends then.
    fn resume_cuts(&mut self, model: &M) {
        while !self.cuts.is_empty() || !self.retaking.is_empty() {
            self.resume_cuts_once(model);
            self.drain_local();
            self.retake(model);
        }
    }

    /// Takes in again, oldest first, the batches undone for a later message that had been
    /// taken in after batches that ran past them ([`Lp::retakes`]), once their objects' cuts
    /// are ended anew: the batches they follow are what they followed then, cut back, so the
    /// model need not check those again ([`Model::take_in`]). A batch whose object no longer
    /// runs past it waits in the heap for its turn.
    fn retake(&mut self, model: &M) {
        while let Some(li) = self.retaking.pop() {
            let li = li as usize;
            while let Some(late) = self.lps[li].retakes.pop() {
                if !self.ran_past(li, &late.time) {
                    let to = self.lps[li].id;
                    self.put_back(to, &late.time, late.inputs, late.batch);
                    continue;
                }
                let taken = Taken {
                    to: self.lps[li].id,
                    li,
                    inputs: late.inputs,
                    batch: late.batch,
                    cancellable: false,
                    next: None,
                    saved: None,
                };
                self.take_late(model, late.time, taken, true);
            }
        }
        self.drain_local();
    }

    /// Ends anew the batches cut back so far ([`Worker::resume_cuts`]).
    fn resume_cuts_once(&mut self, model: &M) {
        while let Some(li) = self.cuts.pop() {
            let li = li as usize;
            let lp = &mut self.lps[li];
            if !std::mem::take(&mut lp.cut) {
                continue; // undone whole since
            }
            let d = self.log.last_mut(&lp.history).expect("the batch cut");
            let end = d.end().clone();
            let Saved::Journal(journal, _) = &mut d.saved else {
                unreachable!("only a journaled batch is cut");
            };
            let (id, first) = (lp.id, lp.uids);
            let mut ctx = Ctx::speculative(model, end.clone(), id, &mut lp.seq)
                .named(&mut lp.uids)
                .journaled(journal);
            ctx.sent = std::mem::take(&mut self.spare.pending);
            model.cut(&mut ctx, id, held(&mut lp.state));
            assert!(ctx.output.is_empty(), "a cut batch's end emits nothing");
            let (mut sent, cancelled) = (ctx.sent, ctx.cancelled);
            d.into_past = ctx.into_past;
            d.cancel_calls = cancelled.len() as u32;
            d.sent.extend(sent_records(model, id, first, &sent));
            d.cancels
                .extend(cancelled.iter().filter(|h| still_to_come(h, &end)));
            let cancels = d.cancels.clone();
            for h in cancels {
                let op = Op::Cancel {
                    h,
                    at: end.clone(),
                    by: id,
                    sign: 1,
                };
                self.route(op);
            }
            for (n, p) in (first + 1..).zip(sent.drain(..)) {
                self.send(uid(id, n), p);
            }
            self.spare.pending = sent;
        }
    }

    /// What will restore the state of object `id` (local `li`) if its next batch is rolled
    /// back: a copy, with its kind ([`Model::state_class`]) for [`Worker::give_state`], or an
    /// empty journal for the handler's records ([`Saving::Incremental`]).
    fn save_state(&mut self, model: &M, id: u32, li: usize) -> Saved<M> {
        if let Saving::Incremental { restore } = model.saving(id) {
            return Saved::Journal(take(&mut self.spare.journals), restore);
        }
        let class = model.state_class(id).min(STATE_CLASSES - 1);
        let state = self.lps[li].state.as_ref().expect(HELD);
        let copy = match self.spare.states[class].pop() {
            Some(mut saved) => {
                saved.clone_from(state);
                saved
            }
            None => state.clone(),
        };
        Saved::Copy(class as u8, copy)
    }

    /// Frees what restored a committed batch's state, for later batches to reuse.
    fn give_saved(&mut self, saved: Saved<M>) {
        match saved {
            Saved::Copy(class, state) => self.give_state(class, state),
            Saved::Journal(journal, _) => give(&mut self.spare.journals, journal),
        }
    }

    /// Keeps a saved state no batch needs any more, for [`Worker::save_state`] to reuse.
    fn give_state(&mut self, class: u8, state: M::State) {
        let spare = &mut self.spare.states[usize::from(class)];
        if spare.len() < SPARE_STATES {
            spare.push(state);
        }
    }

    /// The smallest time of a live message waiting here (marked ones taken off the heap).
    #[inline(always)]
    fn next_time(&mut self) -> Option<f64> {
        loop {
            let top = self.heap.peek()?;
            let mark = self.marks.of(top.uid, top.p.retractable);
            if mark == Mark::Live {
                return Some(top.p.time.t());
            }
            let it = self.heap.pop().expect("a top");
            self.marks.set_aside(it.uid, it.p, mark, self.gvt.t);
        }
    }

    /// Whether the batch of `to` at `time` may run as final, by the bounds last found: as
    /// `Some(true)` when every op another worker may still send comes after it, as
    /// `Some(false)` when every message does and no op can change the batch anyway, because
    /// none of its messages can be cancelled (`cancellable` false).
    fn final_by_bounds(&self, time: &VTime<M::Time>, to: u32, cancellable: bool) -> Option<bool> {
        if self.final_bound.passed(time, to) {
            Some(true)
        } else if !cancellable && self.message_bound.passed(time, to) {
            Some(false)
        } else {
            None
        }
    }

    /// Whether the batch of `to` at `time` may run as final ([`Worker::final_by_bounds`]): no
    /// op (or, for a batch of messages no one can cancel, no message) another worker may still
    /// send, none this worker holds back (chaos) and none waiting in its outboxes comes at or
    /// before it. Asks the fabric again only when the last bounds do not answer and a few
    /// batches have passed since the last try.
    fn may_run_final<F: Fabric<M>>(
        &mut self,
        fabric: &F,
        time: &VTime<M::Time>,
        to: u32,
        cancellable: bool,
    ) -> Option<bool> {
        if let Some(by) = self.final_by_bounds(time, to, cancellable) {
            return Some(by);
        }
        if self.bound_wait > 0 {
            self.bound_wait -= 1;
            return None;
        }
        self.refresh_bounds(fabric);
        let by = self.final_by_bounds(time, to, cancellable);
        if by.is_none() {
            // each try reads every worker's slot of this process twice
            self.bound_wait = self.workers_here - 1;
        }
        by
    }

    /// Reads the bounds below what other workers may still send here afresh
    /// ([`Fabric::peers_floor`]), where the fabric tells them.
    fn refresh_bounds<F: Fabric<M>>(&mut self, fabric: &F) {
        if let Some(peers) = fabric.peers_floor(self.index, self.lookahead) {
            let mut own = self.outbox_floor;
            if let Some(c) = &self.chaos {
                for (_, op) in &c.held {
                    own = own.min(op.floor());
                }
            }
            self.final_bound = peers.any.min(own);
            self.message_bound = peers.messages.min(own);
        }
    }

    /// Runs the next batch if its time is at most `limit` (and, when `final_only`, if it may
    /// run as final); false when there is none.
    #[inline(always)]
    fn step<F: Fabric<M>>(&mut self, model: &M, fabric: &F, limit: f64, final_only: bool) -> bool {
        if !self.cuts.is_empty() || !self.retaking.is_empty() {
            self.resume_cuts(model);
        }
        match self.next_time() {
            Some(t) if t <= limit => {}
            _ => return false,
        }
        if final_only && !self.head_may_run_final(fabric) {
            return false;
        }
        let (time, mut taken) = self.take_batch();
        // only an object that runs ahead has batches that waited behind its span
        if self.runs_ahead && self.ran_past(taken.li, &time) {
            self.take_late(model, time, taken, false);
            return true;
        }
        let run_final = self.settle_final(model, fabric, &time, &mut taken);
        // the next batch's object, most likely (a local one: its message is here): where it
        // lives now, and its record once the handler has run (not at once: the record's place
        // is itself a load, and the step would wait for it)
        if let Some(next) = taken.next {
            self.placement.prefetch(next);
        }
        // a batch run as final saves nothing, and asks nothing of the model for it
        if !run_final {
            taken.saved = Some(self.save_state(model, taken.to, taken.li));
        }
        self.check_depth(&time, taken.to, run_final);
        let (to, li, next) = (taken.to, taken.li, taken.next);
        let horizon = self
            .runs_ahead
            .then(|| self.horizon(li, &time, limit, run_final))
            .flatten();
        let lp = &mut self.lps[li];
        let (pre_seq, first) = (lp.seq, lp.uids);
        let mut ctx = Ctx::speculative(model, time.clone(), to, &mut lp.seq).named(&mut lp.uids);
        if let Some(Saved::Journal(journal, _)) = &mut taken.saved {
            ctx = ctx.journaled(journal);
        }
        if let Some(h) = horizon {
            ctx = ctx.with_horizon(h);
        }
        ctx.sent = std::mem::take(&mut self.spare.pending);
        model.handle(&mut ctx, to, held(&mut lp.state), &taken.batch);
        let (mut sent, cancelled, output) = (ctx.sent, ctx.cancelled, ctx.output);
        let into_past = ctx.into_past;
        let span = (ctx.reached.is_some() || !ctx.output_times.is_empty()).then(|| {
            Box::new(Span {
                end: ctx.reached.unwrap_or_else(|| time.clone()),
                output_times: ctx.output_times,
                marks: ctx.marks,
            })
        });
        self.stats.ran_on += span.as_ref().map_or(0, |s| s.marks.len()) as u64;
        self.latest = self.latest.max(reached(&time, &span).t());
        self.stats.processed += 1;
        let mut ops = std::mem::take(&mut self.spare.ops);
        let did = Did {
            time,
            span,
            uids: first,
            pre_seq,
            delivered: taken.batch.len(),
            cancelled: &cancelled,
            output,
            into_past,
        };
        if run_final {
            self.stats.final_batches += 1;
            give(&mut self.spare.batches, std::mem::take(&mut taken.batch));
            give(&mut self.spare.inputs, std::mem::take(&mut taken.inputs));
            self.commit_final(model, li, did, &mut sent, &mut ops);
        } else {
            self.log_batch(model, taken, did, &mut sent, &mut ops);
        }
        if let Some(next) = next {
            prefetch_all(&self.lps[self.placement.local(next)]);
        }
        self.spare.pending = sent;
        self.route_all(ops);
        true
    }

    /// Routes the ops a batch made, then the local ones they lead to.
    #[inline(always)]
    fn route_all(&mut self, mut ops: Vec<Op<M::Time, M::Msg>>) {
        for op in ops.drain(..) {
            self.route(op);
        }
        self.spare.ops = ops;
        self.drain_local();
    }

    /// Runs a batch that waited for its turn after its object's latest batch ran past it
    /// ([`Worker::may_take_in`]), or one to take in `again` ([`Worker::retake`]): the model
    /// takes it in after that batch if it can ([`Model::take_in`]), and it is filed as
    /// reaching as far; if not, what the model saved is put back, the object is cut back to
    /// before the batch, and the batch waits in the heap again for its turn.
    fn take_late(&mut self, model: &M, time: VTime<M::Time>, mut taken: Taken<M>, again: bool) {
        let (to, li) = (taken.to, taken.li);
        let offered = taken.batch.iter().all(|e| M::may_take_in(&e.msg)) && self.late_ok(li, &time);
        if offered {
            let end = self.last_reached(li).expect("a batch ran past").clone();
            let Saved::Journal(mut journal, restore) = self.save_state(model, to, li) else {
                unreachable!("a journaled object's batch saves a journal");
            };
            let lp = &mut self.lps[li];
            let (pre_seq, first) = (lp.seq, lp.uids);
            let mut ctx = Ctx::speculative(model, time.clone(), to, &mut lp.seq)
                .named(&mut lp.uids)
                .journaled(&mut journal);
            ctx.reached = Some(end.clone());
            ctx.sent = std::mem::take(&mut self.spare.pending);
            let taken_in = model.take_in(&mut ctx, to, held(&mut lp.state), &taken.batch, again);
            debug_assert!(taken_in || !again, "a batch taken in again is taken in");
            let (mut sent, cancelled, output) = (ctx.sent, ctx.cancelled, ctx.output);
            let into_past = ctx.into_past;
            if taken_in {
                assert!(output.is_empty(), "a batch taken in emits nothing");
                self.stats.taken_in += 1;
                self.stats.processed += 1;
                taken.saved = Some(Saved::Journal(journal, restore));
                let span = Some(Box::new(Span {
                    end,
                    output_times: Vec::new(),
                    marks: Vec::new(),
                }));
                let mut ops = std::mem::take(&mut self.spare.ops);
                let did = Did {
                    time,
                    span,
                    uids: first,
                    pre_seq,
                    delivered: taken.batch.len(),
                    cancelled: &cancelled,
                    output,
                    into_past,
                };
                self.log_batch(model, taken, did, &mut sent, &mut ops);
                self.spare.pending = sent;
                self.route_all(ops);
                return;
            }
            while let Some(undo) = journal.pop() {
                restore(held(&mut lp.state), undo);
            }
            give(&mut self.spare.journals, journal);
            (lp.seq, lp.uids) = (pre_seq, first);
            sent.clear();
            self.spare.pending = sent;
        }
        self.stats.take_in_refused += 1;
        self.straggler(li, &time);
        self.put_back(to, &time, taken.inputs, taken.batch);
    }

    /// Whether the batch at the head of the queue may run as final. The first batch left at
    /// the last GVT round runs regardless: no floor ever passes a key deeper than it keeps.
    fn head_may_run_final<F: Fabric<M>>(&mut self, fabric: &F) -> bool {
        let top = self.heap.peek().expect("a valid top");
        let (time, to) = (top.p.time.clone(), top.p.to);
        Floor::of(&time, to) <= self.gvt || self.may_run_final(fabric, &time, to, true).is_some()
    }

    /// Takes the next batch off the queue, with its time: every live message for the head's
    /// object at the head's time (messages marked as cancelled or retracted are set aside).
    #[inline(always)]
    fn take_batch(&mut self) -> (VTime<M::Time>, Taken<M>) {
        let head = self.heap.pop().expect("a valid top");
        let (time, to) = (head.p.time.clone(), head.p.to);
        if self.current != time.key {
            self.current = time.key.clone();
        }
        let li = self.placement.local(to);
        debug_assert!(
            self.last_reached(li).is_none_or(|t| *t < time) || self.may_take_in(li, &head.p),
            "batches run in order, or wait to be taken in"
        );
        let mut inputs = take(&mut self.spare.inputs);
        let mut batch = take(&mut self.spare.batches);
        let mut cancellable = head.p.retractable;
        let (input, env) = head.into_input();
        inputs.push(input);
        batch.push(env);
        // the object of the message after the batch: its record loads while the batch runs
        let mut next = None;
        while let Some(top) = self.heap.peek() {
            if top.p.time != time || top.p.to != to {
                next = Some(top.p.to);
                break;
            }
            let it = self.heap.pop().expect("a top");
            match self.marks.of(it.uid, it.p.retractable) {
                Mark::Live => {
                    cancellable |= it.p.retractable;
                    let (input, env) = it.into_input();
                    inputs.push(input);
                    batch.push(env);
                }
                mark => self.marks.set_aside(it.uid, it.p, mark, self.gvt.t),
            }
        }
        let taken = Taken {
            to,
            li,
            inputs,
            batch,
            cancellable,
            next,
            saved: None,
        };
        (time, taken)
    }

    /// Whether the batch runs as final. A batch before everything still to come is final, and
    /// so are the object's earlier ones: this commits those, and the batch then runs without
    /// saving the state (unless a key deeper than a floor keeps left batches of the instant
    /// uncommitted).
    #[inline(always)]
    fn settle_final<F: Fabric<M>>(
        &mut self,
        model: &M,
        fabric: &F,
        time: &VTime<M::Time>,
        taken: &mut Taken<M>,
    ) -> bool {
        let (to, li) = (taken.to, taken.li);
        let by = if self.final_ok {
            self.may_run_final(fabric, time, to, taken.cancellable)
        } else {
            None
        };
        if by.is_none() {
            return false;
        }
        let here = Floor::of(time, to);
        self.commit_front(model, li, &here);
        if !self.lps[li].history.is_empty() {
            return false;
        }
        self.final_floor = here;
        if by == Some(true) {
            self.cancel_floor = here;
        } else {
            self.stats.final_uncancellable += 1;
        }
        // a batch run as final is never put back, so it keeps no names of its messages
        taken.inputs.clear();
        true
    }

    /// Stops the run with a fault when a cascade of zero-delay events at `time` grows deeper
    /// than GVT can pass (it would pile up batches until memory ran out). A cascade run on a
    /// state still to be rolled back may be wrong, and is stopped by the bound on uncommitted
    /// batches instead, until GVT reaches it.
    #[inline(always)]
    fn check_depth(&mut self, time: &VTime<M::Time>, to: u32, run_final: bool) {
        if time.key.depth() > MAX_CASCADE_DEPTH && (run_final || Floor::of(time, to) <= self.gvt) {
            self.fault.get_or_insert(format!(
                "a cascade of zero-delay events at t = {} is over {MAX_CASCADE_DEPTH} steps deep \
                 and does not end (the model keeps scheduling events at that instant)",
                time.t()
            ));
        }
    }

    /// Files a batch run speculatively in its object's history, with its saved state, what it
    /// sent and what it cancelled (to be undone by a rollback), and sends its messages.
    #[inline(always)]
    fn log_batch(
        &mut self,
        model: &M,
        taken: Taken<M>,
        did: Did<'_, M>,
        sent: &mut Vec<Pending<M::Time, M::Msg>>,
        ops: &mut Vec<Op<M::Time, M::Msg>>,
    ) {
        let end = reached(&did.time, &did.span).clone();
        let (to, li, time) = (taken.to, taken.li, did.time);
        let mut sent_recs = take(&mut self.spare.sent);
        sent_recs.extend(sent_records(model, to, did.uids, sent));
        let mut cancels = if did.cancelled.is_empty() {
            Vec::new()
        } else {
            take(&mut self.spare.cancels)
        };
        cancels.extend(did.cancelled.iter().filter(|h| still_to_come(h, &end)));
        for &h in &cancels {
            ops.push(Op::Cancel {
                h,
                at: end.clone(),
                by: to,
                sign: 1,
            });
        }
        let lp = &mut self.lps[li];
        if !lp.active {
            lp.active = true;
            self.active.push(li as u32);
        }
        if self.high.as_ref().is_none_or(|h| *h < end) {
            self.high = Some(end.clone());
        }
        let done = Done {
            time,
            span: did.span,
            saved: taken.saved.expect("saved: the batch is not final"),
            pre_seq: did.pre_seq,
            inputs: taken.inputs,
            batch: taken.batch,
            sent: sent_recs,
            cancels,
            cancel_calls: did.cancelled.len() as u32,
            output: did.output,
            into_past: did.into_past,
        };
        self.log.push(&mut lp.history, li as u32, done);
        self.uncommitted += 1;
        self.stats.peak_uncommitted = self.stats.peak_uncommitted.max(self.uncommitted as u64);
        for (n, p) in (did.uids + 1..).zip(sent.drain(..)) {
            self.send(uid(to, n), p);
        }
    }

    /// Commits a batch that ran as final at once, keeping no record of it: counts it, sends
    /// its messages, and turns its cancellations into retractions, pushed to `ops`.
    #[inline(always)]
    fn commit_final(
        &mut self,
        model: &M,
        li: usize,
        did: Did<'_, M>,
        sent: &mut Vec<Pending<M::Time, M::Msg>>,
        ops: &mut Vec<Op<M::Time, M::Msg>>,
    ) {
        self.count_committed(did.into_past, did.delivered, did.cancelled.len());
        let id = self.lps[li].id;
        for (n, p) in (did.uids + 1..).zip(sent.drain(..)) {
            self.committed_stats.count(model.kind(&p.env.msg));
            self.send(uid(id, n), p);
        }
        // a committed cancellation is final: one of a message here is marked at once
        for h in did.cancelled.iter().filter(|h| still_to_come(h, &did.time)) {
            if self.placement.worker(h.to) == self.index {
                self.retract(*h, &did.time, id);
            } else {
                ops.push(Op::Retract {
                    h: *h,
                    at: did.time.clone(),
                    by: id,
                });
            }
        }
        let state = (self.ship && model.observed(id))
            .then(|| self.lps[li].state.as_ref().expect(HELD).clone());
        let times = output_times(did.span);
        self.keep_for_collector(did.time, id, state, did.output, times);
    }

    /// Sends a message a batch (or `init`) of this worker has just made. On this worker it goes
    /// straight to the heap: no mark can name it yet, and its receiver needs rolling back only
    /// if it ran ahead of it, which [`Worker::ran_past`] tells at a glance for most messages.
    #[inline(always)]
    fn send(&mut self, uid: u64, p: Pending<M::Time, M::Msg>) {
        self.stats.messages += 1;
        let w = self.placement.worker(p.to);
        if w != self.index {
            self.stats.remote_messages += 1;
            self.route(Op::Msg { uid, p });
            return;
        }
        debug_assert!(!self.final_floor.reaches(&p.time, p.to), "sends go forward");
        let li = self.placement.local(p.to);
        self.arrives(li, &p);
        self.push(Item { uid, p });
        self.note_entries();
    }

    /// With every batch committed, no message can be a straggler: [`Worker::ran_past`] answers
    /// at once again.
    fn forget_high(&mut self) {
        if self.uncommitted == 0 {
            self.high = None;
        }
    }

    /// Uncommitted batches as memory holds them: the slots of the log from the oldest to the
    /// newest, those that batches committed out of order left empty included (an old batch far
    /// ahead of GVT keeps them all; the memory budget counts them, so that rolling it back
    /// frees them).
    fn held(&self) -> usize {
        self.log.slots()
    }

    /// The time local object `li`'s latest uncommitted batch reached ([`Done::end`]).
    fn last_reached(&self, li: usize) -> Option<&VTime<M::Time>> {
        self.log.last(&self.lps[li].history).map(|d| d.end())
    }

    /// Whether local object `li` ran a batch at `time` or later that is not committed yet.
    fn ran_past(&self, li: usize, time: &VTime<M::Time>) -> bool {
        // no batch ran past the latest one run: most messages are later than it
        self.high.as_ref().is_some_and(|h| h >= time)
            && self.last_reached(li).is_some_and(|t| t >= time)
    }

    /// Notes how many messages this worker holds, for the summary's peak.
    fn note_entries(&mut self) {
        let held = self.heap.len() + self.marks.set_aside_len();
        self.stats.peak_entries = self.stats.peak_entries.max(held as u64);
    }

    /// Rolls back every object that ran past the next message here, to free saved states, when
    /// that message is later than GVT's instant.
    fn artificial_rollback(&mut self) {
        // batches of GVT's own instant cannot be committed yet: they are needed, not optimism
        if self.next_time().is_none_or(|t| t <= self.gvt.t) {
            return;
        }
        let top = self.heap.peek().expect("a valid top");
        let (t, first) = (top.p.time.clone(), top.p.to);
        // only batches after the next one in (time, object) order: the others' floor of this
        // worker, published before, may be that next batch, and what is undone goes back below
        // it (an object before the top's at its time already ran there, in order)
        let after = t.next_gen();
        for li in 0..self.lps.len() {
            let from = if self.lps[li].id < first { &after } else { &t };
            if self.last_reached(li).is_some_and(|x| x >= from) {
                self.stats.artificial_rollbacks += 1;
                self.rollback(li, from);
            }
        }
        self.drain_local();
    }

    /// Takes what arrived; in chaos mode holds it back a few iterations and shuffles it.
    fn receive<F: Fabric<M>>(&mut self, fabric: &F, buf: &mut Vec<Op<M::Time, M::Msg>>) {
        fabric.recv(self.index, buf);
        self.received_ops += buf.len() as i64;
        match &mut self.chaos {
            None => {
                for op in buf.drain(..) {
                    self.apply(op);
                }
            }
            Some(Chaos { rng, held }) => {
                for op in buf.drain(..) {
                    let delay = rng.gen_range(0..4u64);
                    held.push((self.iteration + delay, op));
                }
                let now = self.iteration;
                let mut due: Vec<Op<M::Time, M::Msg>> = Vec::new();
                let mut k = 0;
                while k < held.len() {
                    if held[k].0 <= now {
                        due.push(held.swap_remove(k).1);
                    } else {
                        k += 1;
                    }
                }
                for i in (1..due.len()).rev() {
                    let j = rng.gen_range(0..=i);
                    due.swap(i, j);
                }
                for op in due {
                    self.apply(op);
                }
            }
        }
        self.drain_local();
    }

    /// Sends the outboxes' ops, then publishes this worker's floor (the ops' inboxes cover
    /// them from there).
    fn flush<F: Fabric<M>>(&mut self, model: &M, fabric: &F) {
        // a batch cut back sends again before this worker's floor is read
        self.resume_cuts(model);
        for (w, ops) in self.take_outbox(0..self.outbox.len()) {
            self.sent_ops += ops.len() as i64;
            fabric.send(self.index, w, ops);
        }
        self.outbox_floor = Floor::INFINITY;
        if self.final_ok {
            let floor = self.local_min();
            // the slot holds this floor already, or a lower one (taking the inbox lowers it)
            if floor != self.published {
                fabric.publish(self.index, floor);
                self.published = floor;
            }
        }
    }

    /// Where the optimism window starts: GVT, or, where the workers publish their floors, the
    /// least of them read now (nothing any worker holds or may still send comes before it), so
    /// that the window moves on with the slowest worker between GVT rounds.
    fn window_base<F: Fabric<M>>(&mut self, fabric: &F) -> f64 {
        if !self.final_ok {
            return self.gvt.t;
        }
        self.refresh_bounds(fabric);
        let floor = self.final_bound.min(self.local_min());
        floor.t.max(self.gvt.t)
    }

    /// The first batch this worker's unhandled messages and held ops may still change.
    fn local_min(&mut self) -> Floor {
        let mut m = match self.next_time() {
            Some(_) => {
                let top = self.heap.peek().expect("a valid top");
                Floor::of(&top.p.time, top.p.to)
            }
            None => Floor::INFINITY,
        };
        if let Some(c) = &self.chaos {
            for (_, op) in &c.held {
                // a held cancellation keeps GVT below its batch (its floor), so that fossil
                // collection cannot take the message it counts on for cancelled for good
                m = m.min(op.floor());
            }
        }
        m
    }

    /// Whether the heap's marked messages are more than a `1 / share` of it (and more than a
    /// few): the test for asking for a sweep ([`ASK_SWEEP`]) and for joining one ([`JOIN_SWEEP`]).
    fn heap_marked_over(&self, share: usize) -> bool {
        self.marks.pending_marks() > self.heap.len() / share + 1024
    }

    /// A GVT round: returns the reduction over all workers, whose floor is GVT (every batch
    /// before it is final).
    fn gvt_round<F: Fabric<M>>(
        &mut self,
        model: &M,
        fabric: &F,
        stop: bool,
        interrupt: usize,
    ) -> Result<Reduction, Stop> {
        let mut buf = Vec::new();
        loop {
            self.receive(fabric, &mut buf);
            self.flush(model, fabric);
            let local = Reduction {
                in_flight: self.sent_ops - self.received_ops,
                floor: self.local_min(),
                stop: u64::from(stop),
                sweep: u64::from(self.heap_marked_over(ASK_SWEEP)),
                interrupt: interrupt as u64,
                latest: self.latest,
            };
            let g = fabric.reduce(self.index, local);
            if g.stop > 0 {
                return Err(Stop::Asked);
            }
            if g.in_flight == 0 {
                self.stats.gvt_rounds += 1;
                return Ok(g);
            }
        }
    }

    /// Commits one optimistic batch of local object `li`: counts it and its sends, frees its
    /// records, and keeps for the collector what its sinks see (`state` is the object's state
    /// after it, when observed).
    fn commit(&mut self, li: usize, mut d: Done<M>, state: Option<M::State>) {
        self.count_committed(d.into_past.take(), d.batch.len(), d.cancel_calls as usize);
        // its cancellations are final now: those of messages here become retractions
        for h in &d.cancels {
            if self.placement.worker(h.to) == self.index {
                self.marks.promote(h.uid, d.time.t());
            }
        }
        for (_, kind) in d.sent.drain(..) {
            self.committed_stats.count(usize::from(kind));
        }
        give(&mut self.spare.sent, d.sent);
        give(&mut self.spare.inputs, d.inputs);
        give(&mut self.spare.batches, d.batch);
        give(&mut self.spare.cancels, d.cancels);
        self.give_saved(d.saved);
        let times = output_times(d.span);
        self.keep_for_collector(d.time, self.lps[li].id, state, d.output, times);
    }

    /// Counts a committed batch that handled `delivered` messages and made `cancels`
    /// cancellations; a send into the past it tried is now a model bug.
    #[inline(always)]
    fn count_committed(&mut self, into_past: Option<String>, delivered: usize, cancels: usize) {
        if let Some(what) = into_past {
            self.fault
                .get_or_insert(format!("model bug in a committed batch: {what}"));
        }
        self.stats.committed += 1;
        let cs = &mut self.committed_stats;
        cs.batches += 1;
        cs.delivered += delivered as u64;
        cs.cancels += cancels as u64;
    }

    /// Keeps what the collector needs of a committed batch of object `obj`: only what its
    /// sinks see.
    fn keep_for_collector(
        &mut self,
        time: VTime<M::Time>,
        obj: u32,
        state: Option<M::State>,
        output: Vec<M::Output>,
        times: Vec<VTime<M::Time>>,
    ) {
        if state.is_some() || !output.is_empty() {
            self.to_ship.push(Committed {
                time,
                obj,
                state,
                output,
                times,
            });
        }
    }

    /// Commits the batches of local object `li` that `floor` passed, oldest first.
    #[inline(always)]
    fn commit_front(&mut self, model: &M, li: usize, floor: &Floor) {
        // most objects have nothing uncommitted when they run a final batch
        if self.lps[li].history.is_empty() {
            return;
        }
        let observed = self.ship && model.observed(self.lps[li].id);
        loop {
            let lp = &self.lps[li];
            if !self
                .log
                .first(&lp.history)
                .is_some_and(|d| floor.passed(d.end(), lp.id))
            {
                break;
            }
            let state = observed.then(|| self.state_after_first(li));
            let d = self
                .log
                .pop_first(&mut self.lps[li].history)
                .expect("a batch to commit");
            self.uncommitted -= 1;
            self.commit(li, d, state);
        }
    }

    /// The state of local object `li` after its oldest uncommitted batch: the copy saved
    /// before the next one, or the state now with the records of every later batch undone,
    /// latest first.
    fn state_after_first(&self, li: usize) -> M::State {
        let lp = &self.lps[li];
        if let Some(Saved::Copy(_, state)) = self.log.second(&lp.history).map(|d| &d.saved) {
            return state.clone();
        }
        let mut state = lp.state.as_ref().expect(HELD).clone();
        for d in self.log.after_first_newest_first(&lp.history) {
            match &d.saved {
                Saved::Copy(_, before) => state.clone_from(before),
                Saved::Journal(journal, restore) => {
                    for undo in journal.iter().rev() {
                        restore(&mut state, undo.clone());
                    }
                }
            }
        }
        state
    }

    /// Commits optimistic batches, oldest run first, that nothing can undo any more: before
    /// every op the other workers may still send and before this worker's own next batch.
    fn commit_early(&mut self, model: &M) {
        if !self.final_ok || self.log.len() == 0 {
            return;
        }
        // the floor just published is this worker's own next batch; the ops it flushed are
        // still under `final_bound`
        let bound = self.final_bound.min(self.published);
        let before = self.uncommitted;
        // the log's front is the oldest batch of its object
        while let Some((li, d)) = self.log.front() {
            let li = li as usize;
            if !bound.passed(d.end(), self.lps[li].id) {
                break;
            }
            self.commit_front(model, li, &bound);
        }
        self.stats.committed_early += (before - self.uncommitted) as u64;
        self.forget_high();
    }

    /// Commits every batch before `gvt`: frees its saved state and messages, and returns what
    /// the collector needs of every batch committed so far that `gvt` passed (output, and
    /// observed states when the collector wants them), in no particular order. With `sweep`
    /// (some worker wants its heap swept this round) drops the marked messages that are gone
    /// for good from the heap, if they are a fair share of it.
    fn fossil_collect(
        &mut self,
        model: &M,
        gvt: Floor,
        sweep: bool,
    ) -> Vec<Committed<M::Time, M::State, M::Output>> {
        let mut still = Vec::with_capacity(self.active.len());
        for k in 0..self.active.len() {
            let li = self.active[k] as usize;
            self.commit_front(model, li, &gvt);
            let lp = &mut self.lps[li];
            if lp.history.is_empty() {
                lp.active = false;
            } else {
                still.push(li as u32);
            }
        }
        self.active = still;
        // a batch run as final may come after one another worker commits only in a later round
        let (out, later) = std::mem::take(&mut self.to_ship)
            .into_iter()
            .partition(|c| gvt.passed(&c.time, c.obj));
        self.to_ship = later;
        self.marks.collect(gvt.t);
        // marked messages wait in the heap for their time; drop those that are gone for good
        // when the marks outnumber the rest on some worker (this one's too, then), or are a
        // quarter of the heap here: a sweep of a large heap takes tens of milliseconds, which
        // the others would otherwise spend waiting at the next round
        if sweep && self.heap_marked_over(JOIN_SWEEP) {
            let marks = &mut self.marks;
            self.heap
                .retain(|it| marks.keeps(it.uid, it.p.retractable, gvt.t));
        }
        let held = self.heap.len() + self.marks.set_aside_len();
        self.samples.push((self.uncommitted + held) as u64);
        self.forget_high();
        out
    }

    /// Runs this worker until GVT passes `until` (every batch at or before it committed) or
    /// the run is stopped; hands committed batches to the fabric's collector each round, with
    /// the observed objects' states when `ship`.
    pub fn run<F: Fabric<M>>(
        &mut self,
        model: &M,
        fabric: &F,
        cfg: &TwConfig,
        until: f64,
        ship: bool,
        halt: Halt<'_>,
    ) -> Result<(), Stop> {
        let mut until = until;
        let mut buf = Vec::new();
        let mut since = 0u32;
        self.lookahead = model.lookahead();
        self.started = Some(std::time::Instant::now());
        let (interval, ahead) = self.prepare(model, fabric, cfg, ship);
        // other ranks' floors are known only from the last round
        let idle_asks = !self.final_ok || threads::place().1 > 1;
        let result = loop {
            self.iteration += 1;
            self.receive(fabric, &mut buf);
            // a window set is narrowed by rollbacks as the adaptive one is
            let width = match cfg.window {
                Some(w) => w * self.auto_window.scale,
                None => self.auto_window.width,
            };
            let window = self.window_base(fabric) + width;
            let (ran, held_back) = self.burst(model, fabric, cfg, until.min(window), ahead);
            self.flush(model, fabric);
            self.commit_early(model);
            since += ran.max(1);
            // with nothing to run below its window, a worker asks for a round to move the
            // window on, unless the window moves with the floors its peers publish anyway
            if ran == 0 && !held_back && idle_asks {
                since = interval;
            }
            if ran == 0 && self.chaos.is_none() {
                std::thread::yield_now();
            }
            let over = self.held() > cfg.max_uncommitted.saturating_mul(4);
            if over || self.fault.is_some() {
                since = interval;
            }
            // chaos keeps each worker to its own count: the lockstep of the old rounds damps the
            // rollback echoes that its delays provoke, which otherwise may run for seconds
            let due = since >= interval;
            let go = match self.chaos {
                Some(_) => due,
                None => fabric.round_due(self.index, self.round, due),
            };
            if !go {
                continue;
            }
            since = 0;
            let asked = halt.failed.load(std::sync::atomic::Ordering::Relaxed);
            let cause = halt.interrupt.and_then(Interrupt::cause).unwrap_or(0);
            match self.gvt_round(model, fabric, asked || over || self.fault.is_some(), cause) {
                Err(s) => break Err(self.why_stopped(s, over, cfg)),
                Ok(g) => {
                    // every worker ends at the same time: nobody has run a batch after it
                    if g.interrupt > 0 {
                        until = until.min(g.latest.max(self.gvt.t));
                        // every rank's caller learns why its run ended early
                        if let Some(i) = halt.interrupt {
                            i.raise(g.interrupt as usize);
                        }
                    }
                    self.advance_gvt(model, fabric, g.floor, g.sweep > 0);
                    if g.floor.t > until {
                        break Ok(());
                    }
                }
            }
        };
        self.ended_at = until;
        self.finish(fabric, &result);
        result
    }

    /// Sets the worker up for a run on `fabric`: the GVT interval in batches, and the number
    /// of uncommitted batches past which it runs only final ones.
    fn prepare<F: Fabric<M>>(
        &mut self,
        model: &M,
        fabric: &F,
        cfg: &TwConfig,
        ship: bool,
    ) -> (u32, usize) {
        let ranks = threads::place().1;
        let interval = cfg.interval(ranks);
        // across ranks at least as many as at the threads' default interval, though rounds come
        // more often there: a worker held back waits for a round, and a round across ranks is a
        // collective of them all (held back past 512 batches, 2 ranks with a gas of 10^5 disks
        // to t = 1 ran 7 % more rounds)
        let ahead = 2 * if ranks > 1 {
            interval.max(THREADS_GVT_INTERVAL)
        } else {
            interval
        } as usize;
        self.ship = ship;
        let burst = if cfg.final_batches {
            DEFAULT_BURST
        } else {
            PURE_BURST
        };
        // a round comes no later than the interval asks
        self.burst_len = cfg.burst.unwrap_or(burst).clamp(1, interval);
        self.workers_here = (self.placement.workers() / ranks).max(1) as u32;
        // this run's fabric knows nothing of this worker yet: its first flush publishes
        self.published = Floor::NEG_INFINITY;
        self.final_ok = cfg.final_batches && fabric.shares_floors();
        self.flush(model, fabric);
        (interval, ahead)
    }

    /// Runs a burst of batches up to `limit`: how many ran, and whether the worker was held
    /// back to final batches (more than `ahead` uncommitted).
    #[inline(always)]
    fn burst<F: Fabric<M>>(
        &mut self,
        model: &M,
        fabric: &F,
        cfg: &TwConfig,
        mut limit: f64,
        ahead: usize,
    ) -> (u32, bool) {
        let burst = match &mut self.chaos {
            Some(c) => c.rng.gen_range(1..64u32),
            None => self.burst_len,
        };
        let mut ran = 0;
        let mut held_back = false;
        while ran < burst {
            if self.held() > cfg.max_uncommitted {
                if self.held() > cfg.max_uncommitted.saturating_mul(4) {
                    break;
                }
                self.artificial_rollback();
                limit = limit.min(self.gvt.t);
            }
            // far ahead of GVT: only batches that cannot be undone, until a round (another
            // worker's, or this one's own once it has waited a round's worth) commits
            held_back = self.final_ok && self.uncommitted > ahead;
            if !self.step(model, fabric, limit, held_back) {
                break;
            }
            ran += 1;
        }
        (ran, held_back)
    }

    /// Why the run stops after a GVT round that ended it: a fault of this worker, its memory
    /// budget overrun (`over`), or what the round said.
    fn why_stopped(&mut self, round: Stop, over: bool, cfg: &TwConfig) -> Stop {
        if let Some(fault) = self.fault.take() {
            return Stop::Failed(fault);
        }
        if !over {
            return round;
        }
        Stop::Failed(format!(
            "time warp: worker {} holds {} uncommitted batches, over 4 x its budget of {} \
             (raise --tw-memory or narrow --tw-window)",
            self.index,
            self.held(),
            cfg.max_uncommitted
        ))
    }

    /// A GVT round reached `gvt`: the window adapts, batches before it are committed and
    /// handed to the collector (after a sweep of cancelled messages when `sweep`).
    fn advance_gvt<F: Fabric<M>>(&mut self, model: &M, fabric: &F, gvt: Floor, sweep: bool) {
        // a batch that ran on past GVT and was rolled back waits below it again; its rerun
        // sends nothing before the message that rolled it back, which GVT did not pass
        // ([`Ctx::may_run`]), so GVT stays where it was
        let gvt = gvt.max(self.gvt);
        let moved = if self.gvt.t.is_finite() && gvt.t.is_finite() {
            gvt.t - self.gvt.t
        } else {
            0.0
        };
        self.auto_window
            .after_round(moved, self.heap.len(), &self.stats);
        self.gvt = gvt;
        let batches = self.fossil_collect(model, gvt, sweep);
        self.round += 1;
        let open = self.open_floor();
        fabric.commit(Chunk {
            worker: self.index,
            round: self.round,
            batches,
            last: None,
            finals: Vec::new(),
            error: None,
            progress: self.progress(),
            open,
        });
    }

    /// Below every output this worker may still commit ([`Chunk::open`]): GVT, the start of
    /// its objects' oldest uncommitted batches (one may have run on past GVT), and its next
    /// message (a batch rolled back may wait below GVT to run again).
    fn open_floor(&mut self) -> Floor {
        let mut open = self.gvt.min(self.local_min());
        if self.runs_ahead {
            for &li in &self.active {
                let lp = &self.lps[li as usize];
                if let Some(d) = self.log.first(&lp.history) {
                    open = open.min(Floor::of(&d.time, lp.id));
                }
            }
        }
        open
    }

    /// The worker's counts so far, for the collector's records of rounds.
    fn progress(&self) -> Progress {
        let s = &self.stats;
        Progress {
            gvt: self.gvt.t,
            wall_s: self.started.map_or(0.0, |t| t.elapsed().as_secs_f64()),
            committed: s.committed,
            processed: s.processed,
            rolled_back: s.rolled_back,
            final_batches: s.final_batches,
            rollbacks: s.rollbacks,
            remote_messages: s.remote_messages,
        }
    }

    /// The worker's last word to the collector: its statistics, the error that stopped it,
    /// and, where the collector is on another rank, its objects' final states.
    fn finish<F: Fabric<M>>(&mut self, fabric: &F, result: &Result<(), Stop>) {
        let error = match result {
            Err(Stop::Failed(m)) => Some(m.clone()),
            _ => None,
        };
        let n = self.samples.len();
        let max = |r: std::ops::Range<usize>| self.samples[r].iter().copied().max().unwrap_or(0);
        self.stats.held_early = max(n / 10..n / 2);
        self.stats.held_late = max(n / 2..n);
        let finals = if result.is_ok() && !fabric.collector_is_local() {
            self.lps
                .iter()
                .map(|lp| (lp.id, lp.state.as_ref().expect(HELD).clone()))
                .collect()
        } else {
            Vec::new()
        };
        fabric.commit(Chunk {
            worker: self.index,
            round: u64::MAX,
            batches: Vec::new(),
            last: Some((
                self.stats.clone(),
                std::mem::take(&mut self.committed_stats),
                self.pending_len() as u64,
            )),
            finals,
            error,
            progress: self.progress(),
            open: Floor::INFINITY,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::super::config::ACROSS_RANKS_GVT_INTERVAL;
    use super::super::window::window_span;
    use super::*;
    use crate::PlainTime;

    fn handle(to: u32, t: f64) -> Handle {
        Handle {
            from: 5,
            to,
            seq: 1,
            uid: uid(5, 1),
            t,
        }
    }

    #[test]
    fn the_gvt_interval_defaults_by_where_it_runs() {
        let c = TwConfig::default();
        assert_eq!(
            (c.interval(1), c.interval(2)),
            (THREADS_GVT_INTERVAL, ACROSS_RANKS_GVT_INTERVAL)
        );
        let set = TwConfig {
            gvt_interval: Some(7),
            ..c
        };
        assert_eq!((set.interval(1), set.interval(3)), (7, 7));
    }

    #[test]
    fn the_optimism_window_follows_the_rate_of_progress_not_the_rounds() {
        let stats = |processed, rolled_back| TwStats {
            processed,
            rolled_back,
            ..TwStats::default()
        };
        // one round after 1024 batches or 16 rounds after 64 each: the same window
        let mut one = AutoWindow::new();
        one.after_round(0.016, 10, &stats(1024, 0));
        let mut many = AutoWindow::new();
        many.after_round(0.016, 10, &stats(1024, 0));
        for k in 1..=16 {
            many.after_round(0.001, 10, &stats(1024 + 64 * k, 0));
        }
        assert!((one.width - 0.016).abs() < 1e-12, "{}", one.width);
        assert!((many.width - one.width).abs() < 1e-12, "{}", many.width);
        // it narrows at once where progress slows, and widens at most twofold a round
        one.after_round(0.0016, 10, &stats(2048, 0));
        assert!((one.width - 0.0016).abs() < 1e-12);
        one.after_round(1.0, 10, &stats(3072, 0));
        assert!((one.width - 0.0032).abs() < 1e-12);
        // a worker that ran few batches keeps its window until it has run enough to tell the
        // rate; a sample in which GVT did not move leaves the width
        let mut slow = AutoWindow::new();
        slow.after_round(0.5, 10, &stats(100, 0));
        assert_eq!(slow.width, f64::INFINITY);
        slow.after_round(0.5, 10, &stats(256, 0));
        assert_eq!(slow.width, 4.0);
        slow.after_round(0.0, 10, &stats(1024, 0));
        assert_eq!(slow.width, 4.0);
        // the span: one batch per pending message, within bounds
        let spans = [10, 5000, 100_000].map(window_span);
        assert_eq!(spans, [1024.0, 5000.0, 8192.0]);
    }

    #[test]
    fn rollbacks_narrow_the_optimism_window_and_their_absence_widens_it_back() {
        let mut w = AutoWindow::new();
        let (mut processed, mut rolled_back) = (0, 0);
        let mut round = |w: &mut AutoWindow, ran: u64, undone: u64| {
            processed += ran;
            rolled_back += undone;
            let stats = TwStats {
                processed,
                rolled_back,
                ..TwStats::default()
            };
            w.after_round(1.0, 2048, &stats);
            w.scale
        };
        // a quarter rolled back halves the scale, down to 1/16; less doubles it back to 1
        let scales: Vec<f64> = [300, 250, 400, 1000, 1000, 100, 0, 0, 0, 0]
            .into_iter()
            .map(|undone| round(&mut w, 1000, undone))
            .collect();
        assert_eq!(
            scales,
            [0.5, 0.25, 0.125, 0.0625, 0.0625, 0.125, 0.25, 0.5, 1.0, 1.0]
        );
        // the width follows: 1,000 batches moved GVT by 1, the span is 2,048
        assert!((w.width - 2.048).abs() < 1e-12, "{}", w.width);
    }

    #[test]
    fn a_cancelled_message_is_still_to_come_from_the_cancelling_instant_on() {
        let at = VTime::<PlainTime>::start(2.0).next_gen();
        assert!(still_to_come(&handle(3, 2.5), &at));
        assert!(
            still_to_come(&handle(3, 2.0), &at),
            "its own instant: taken at its word"
        );
        assert!(
            !still_to_come(&handle(3, 1.5), &at),
            "delivered in an earlier instant"
        );
        let dropped = Handle {
            uid: 0,
            ..handle(3, 2.5)
        };
        assert!(
            !still_to_come(&dropped, &at),
            "a send into the past was never sent"
        );
    }

    #[test]
    fn a_receiver_rolls_back_from_no_earlier_than_the_cancellations_place() {
        let at = VTime::<PlainTime>::start(2.0).next_gen();
        // a later instant: from its start
        assert_eq!(
            not_before(&handle(3, 2.5), at.clone(), 5),
            VTime::start(2.5)
        );
        // the same instant, an object after the canceller: from the cancelling batch's time
        assert_eq!(not_before(&handle(7, 2.0), at.clone(), 5), at);
        // an object before the canceller: its message comes at a later time than the batch
        let after = not_before(&handle(3, 2.0), at.clone(), 5);
        assert!(after > at);
        assert!(
            Floor::of(&after, 0) >= Floor::of(&at, 6),
            "past the op's place"
        );
    }
}
