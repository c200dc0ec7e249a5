//! One worker's share of a conservative run: its objects, their pending messages, and the run
//! of one window over them.

use super::sync::{Boxes, FAILED};
use crate::prefetch::{prefetch, prefetch_all};
use crate::queue::Queue;
use crate::sequential::{pop_live, sweep_cancelled, take_rest_of_batch, Item};
use crate::{Ctx, Envelope, Handle, MessageStats, Model, Pending, VTime, RESERVED_PER_OBJECT};
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rustc_hash::FxHashSet;

/// Where an object lives: its worker and its index among that worker's objects.
#[derive(Clone, Copy, Debug)]
pub struct Home {
    /// The worker.
    pub worker: u32,
    /// The index among the worker's objects.
    pub local: u32,
}

/// What one worker sends another between two windows.
pub struct Mail<T, M> {
    /// Messages, in the order they were sent.
    pub msgs: Vec<Pending<T, M>>,
    /// Messages retracted, sent after every message of the same box.
    pub cancels: Vec<Handle>,
}

impl<T, M> Default for Mail<T, M> {
    fn default() -> Self {
        Mail {
            msgs: Vec::new(),
            cancels: Vec::new(),
        }
    }
}

/// A batch that produced output: what the sink is shown, in the sequential order.
pub struct Done<M: Model> {
    /// The batch's virtual time.
    pub time: VTime<M::Time>,
    /// Its object.
    pub obj: u32,
    /// The object's state after the batch, when the sink reads states and the model observes
    /// the object.
    pub state: Option<M::State>,
    /// What the batch reported.
    pub output: Vec<M::Output>,
}

/// The bounds of one window: batches before `end` (the earliest time of the round plus the
/// lookahead) and not after `until` run.
#[derive(Clone, Copy, Debug)]
pub struct Window {
    /// No batch at or after this time runs in the window.
    pub end: f64,
    /// No batch after this time runs at all.
    pub until: f64,
}

/// One worker's objects and messages.
pub struct Part<M: Model> {
    /// This worker's number.
    pub me: u32,
    /// Its objects' numbers, by local index.
    pub objs: Vec<u32>,
    /// Its objects' states, by local index.
    pub states: Vec<M::State>,
    seqs: Vec<u64>,
    pending: Queue<Item<M::Time, M::Msg>>,
    cancelled: FxHashSet<Handle>,
    /// Committed message statistics of its objects (everything it runs is committed).
    pub stats: MessageStats,
    /// Messages and cancels for each other worker, sent in the window being run.
    outbox: Vec<Mail<M::Time, M::Msg>>,
    /// The earliest time among the messages in the outboxes.
    out_earliest: f64,
    /// Batches of the window that produced output.
    pub done: Vec<Done<M>>,
    /// The time of the last batch run.
    pub last: f64,
    /// Why the run must stop: a model bug in a batch.
    pub error: Option<String>,
    /// Messages that arrived from other workers.
    pub received: u64,
    /// Shakes the order of arrivals and the timing of the workers (chaos mode).
    chaos: Option<Pcg64Mcg>,
    batch: Vec<Envelope<M::Msg>>,
    sent: Vec<Pending<M::Time, M::Msg>>,
    retracted: Vec<Handle>,
    spare: Mail<M::Time, M::Msg>,
}

impl<M: Model> Part<M> {
    /// Worker `me`'s share: the objects `objs` with their states, among `workers` workers.
    pub fn new(
        me: u32,
        objs: Vec<u32>,
        states: Vec<M::State>,
        workers: usize,
        chaos: Option<u64>,
    ) -> Part<M> {
        let n = objs.len();
        Part {
            me,
            objs,
            states,
            seqs: vec![0; n],
            pending: Queue::with_capacity(RESERVED_PER_OBJECT * n),
            cancelled: FxHashSet::default(),
            stats: MessageStats::default(),
            outbox: (0..workers).map(|_| Mail::default()).collect(),
            out_earliest: f64::INFINITY,
            done: Vec::new(),
            last: f64::NEG_INFINITY,
            error: None,
            received: 0,
            chaos: chaos.map(|s| Pcg64Mcg::seed_from_u64(s ^ (u64::from(me) << 32))),
            batch: Vec::new(),
            sent: Vec::new(),
            retracted: Vec::new(),
            spare: Mail::default(),
        }
    }

    /// Runs every object's `init` at `start`, in object order, and routes what they send.
    pub fn init(&mut self, model: &M, homes: &[Home], start: &VTime<M::Time>) {
        for local in 0..self.objs.len() {
            let obj = self.objs[local];
            let mut ctx = Ctx::new(model, start.clone(), obj, &mut self.seqs[local]);
            model.init(&mut ctx, obj, &mut self.states[local]);
            assert!(ctx.cancelled.is_empty(), "init may not cancel");
            for p in ctx.sent {
                self.stats.count(model.kind(&p.env.msg));
                self.route(p, homes, false);
            }
        }
    }

    /// Keeps a message for one of this worker's objects, or puts it in the outbox of the
    /// receiver's worker.
    fn route(&mut self, p: Pending<M::Time, M::Msg>, homes: &[Home], in_instant: bool) {
        let to = homes[p.to as usize].worker;
        if to == self.me {
            self.pending.push(Item(p), in_instant);
        } else {
            self.out_earliest = self.out_earliest.min(p.time.t());
            self.outbox[to as usize].msgs.push(p);
        }
    }

    /// The earliest time of a message this worker holds or has just sent elsewhere.
    pub fn earliest(&mut self) -> f64 {
        let held = self
            .pending
            .peek()
            .map_or(f64::INFINITY, |Item(p)| p.time.t());
        held.min(self.out_earliest)
    }

    /// Messages held (cancelled ones not yet discarded included).
    pub fn pending_len(&self) -> usize {
        self.pending.len()
    }

    /// Pops the next message that was not cancelled.
    fn pop_live(&mut self) -> Option<Pending<M::Time, M::Msg>> {
        pop_live(&mut self.pending, &mut self.cancelled)
    }

    /// Takes the next batch of the window: every live message of the first pending receiver
    /// and time, if that time is in the window.
    fn next_batch(&mut self, window: Window) -> Option<(VTime<M::Time>, u32)> {
        loop {
            let Item(p) = self.pending.peek()?;
            let t = p.time.t();
            if t >= window.end || t > window.until {
                return None;
            }
            let first = self.pop_live()?;
            if first.time.t() >= window.end || first.time.t() > window.until {
                self.pending.push(Item(first), false);
                continue;
            }
            let (time, to) = (first.time, first.to);
            self.batch.push(first.env);
            let (pending, cancelled) = (&mut self.pending, &mut self.cancelled);
            take_rest_of_batch(pending, cancelled, &time, to, &mut self.batch);
            return Some((time, to));
        }
    }

    /// Runs every batch of the window, in order. Stops at the first model bug, which it keeps
    /// in `error`.
    pub fn run_window(&mut self, model: &M, homes: &[Home], window: Window, ship: bool) {
        while let Some((time, obj)) = self.next_batch(window) {
            let local = homes[obj as usize].local as usize;
            if let Some(Item(next)) = self.pending.peek() {
                let l = homes[next.to as usize].local as usize;
                if let Some(s) = self.states.get(l) {
                    prefetch_all(s);
                    prefetch(&self.seqs[l]);
                }
            }
            self.stats.batches += 1;
            self.stats.delivered += self.batch.len() as u64;
            let mut ctx = Ctx::speculative(model, time.clone(), obj, &mut self.seqs[local]);
            ctx.sent = std::mem::take(&mut self.sent);
            ctx.cancelled = std::mem::take(&mut self.retracted);
            model.handle(&mut ctx, obj, &mut self.states[local], &self.batch);
            self.batch.clear();
            let (mut sent, mut cancelled, output) = (ctx.sent, ctx.cancelled, ctx.output);
            if let Some(bug) = ctx.into_past {
                self.error.get_or_insert(bug);
            }
            for h in cancelled.drain(..) {
                self.retract(h, homes, window, time.t());
            }
            self.sweep_cancelled();
            for p in sent.drain(..) {
                self.stats.count(model.kind(&p.env.msg));
                let in_instant = p.time.key == time.key;
                self.route(p, homes, in_instant);
            }
            (self.sent, self.retracted) = (sent, cancelled);
            self.last = time.t();
            if !output.is_empty() {
                let state = (ship && model.observed(obj)).then(|| self.states[local].clone());
                self.done.push(Done {
                    time,
                    obj,
                    state,
                    output,
                });
            }
            if self.error.is_some() {
                return;
            }
            self.shake();
        }
    }

    /// Retracts a message sent earlier: here, or by mail to its receiver's worker, which must
    /// not have run it yet (it lies at or after the window's end).
    fn retract(&mut self, h: Handle, homes: &[Home], window: Window, now: f64) {
        self.stats.cancels += 1;
        let to = homes[h.to as usize].worker;
        if to == self.me {
            self.cancelled.insert(h);
        } else if h.t < window.end {
            self.error.get_or_insert(format!(
                "object {} cancelled at t = {now} its message to object {} at t = {}, sooner \
                 than the lookahead after the window (the conservative executor takes only \
                 cancels of messages at least the lookahead ahead)",
                h.from, h.to, h.t
            ));
        } else {
            self.outbox[to as usize].cancels.push(h);
        }
    }

    /// Drops cancelled messages from the pending set once they are half of it (as the
    /// sequential executor does).
    fn sweep_cancelled(&mut self) {
        sweep_cancelled(&mut self.pending, &mut self.cancelled);
    }

    /// In chaos mode, now and then gives the core away, so that the workers' windows end in
    /// every order.
    fn shake(&mut self) {
        if let Some(rng) = &mut self.chaos {
            if rng.gen_ratio(1, 64) {
                std::thread::yield_now();
            }
        }
    }

    /// Puts the window's outgoing mail into the boxes of round `round`.
    pub fn post(&mut self, boxes: &Boxes<Mail<M::Time, M::Msg>>, round: u64) {
        for (to, mail) in self.outbox.iter_mut().enumerate() {
            if mail.msgs.is_empty() && mail.cancels.is_empty() {
                continue;
            }
            let mut b = boxes.get(round, self.me as usize, to);
            b.msgs.append(&mut mail.msgs);
            b.cancels.append(&mut mail.cancels);
        }
        self.out_earliest = f64::INFINITY;
    }

    /// Takes the mail of round `round` from every other worker: messages first, then the
    /// cancels of messages sent in earlier windows or in the same one.
    pub fn collect(&mut self, boxes: &Boxes<Mail<M::Time, M::Msg>>, round: u64, workers: usize) {
        let me = self.me as usize;
        for from in (0..workers).filter(|&w| w != me) {
            {
                let mut b = boxes.get(round, from, me);
                std::mem::swap(&mut *b, &mut self.spare);
            }
            if let Some(rng) = &mut self.chaos {
                self.spare.msgs.shuffle(rng);
            }
            self.received += self.spare.msgs.len() as u64;
            for p in self.spare.msgs.drain(..) {
                self.pending.push(Item(p), false);
            }
            self.cancelled.extend(self.spare.cancels.drain(..));
        }
        self.sweep_cancelled();
    }

    /// This worker's flags for its report: [`FAILED`] after a model bug.
    pub fn flags(&self) -> u64 {
        if self.error.is_some() {
            FAILED
        } else {
            0
        }
    }
}
