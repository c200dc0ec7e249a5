//! The sequential executor: one pending set ([`Queue`]), batches run strictly in order.

use super::prefetch::{prefetch, prefetch_all};
use super::queue::{Queue, Ranked};
use super::{
    Ctx, Envelope, Handle, Horizon, MessageStats, Model, Pending, Time, VTime, RESERVED_PER_OBJECT,
};
use crate::Interrupt;
use rustc_hash::FxHashSet;
use std::cmp::Ordering;

/// Receives each output with the model and the states just after the batch that produced it.
pub type Sink<'a, M, E> =
    dyn FnMut(&M, &[<M as Model>::State], <M as Model>::Output) -> Result<(), E> + 'a;

/// A pending message ordered for a min-heap.
pub(crate) struct Item<T, M>(pub(crate) Pending<T, M>);

impl<T: Time, M> PartialEq for Item<T, M> {
    fn eq(&self, o: &Self) -> bool {
        self.0.order(&o.0) == Ordering::Equal
    }
}

impl<T: Time, M> Eq for Item<T, M> {}

impl<T: Time, M> PartialOrd for Item<T, M> {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl<T: Time, M> Ord for Item<T, M> {
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.order(&self.0)
    }
}

impl<T: Time, M> Ranked for Item<T, M> {
    fn rank(&self) -> [u64; 4] {
        self.0.rank(0).map(|x| !x)
    }
    fn same_instant(&self, o: &Self) -> bool {
        self.0.time.key == o.0.time.key
    }
    fn lead(&self) -> u64 {
        !self.0.lead()
    }
}

/// Pops the next message of `pending` that is not among the `cancelled` (which forgets it).
#[inline]
pub(crate) fn pop_live<T: Time, M>(
    pending: &mut Queue<Item<T, M>>,
    cancelled: &mut FxHashSet<Handle>,
) -> Option<Pending<T, M>> {
    while let Some(Item(p)) = pending.pop() {
        if !(p.retractable && cancelled.remove(&p.handle())) {
            return Some(p);
        }
    }
    None
}

/// Moves every further live message of `pending` to `to` at `time` into `batch`: the rest of
/// the batch whose first message was just taken.
#[inline]
pub(crate) fn take_rest_of_batch<T: Time, M>(
    pending: &mut Queue<Item<T, M>>,
    cancelled: &mut FxHashSet<Handle>,
    time: &VTime<T>,
    to: u32,
    batch: &mut Vec<Envelope<M>>,
) {
    while let Some(Item(p)) = pending.peek() {
        if p.to != to || p.time != *time {
            break;
        }
        let Some(p) = pop_live(pending, cancelled) else {
            break;
        };
        if p.to != to || p.time != *time {
            pending.push(Item(p), false);
            break;
        }
        batch.push(p.env);
    }
}

/// Drops cancelled messages from `pending` once they are half of it, so that memory follows
/// the live messages (a cancelled message may lie far in the future); what is left in
/// `cancelled` names messages already delivered, which no longer matter. Amortized O(1) per
/// cancellation.
pub(crate) fn sweep_cancelled<T: Time, M>(
    pending: &mut Queue<Item<T, M>>,
    cancelled: &mut FxHashSet<Handle>,
) {
    if cancelled.len() > 1024 && 2 * cancelled.len() > pending.len() {
        let dead = &*cancelled;
        pending.retain(|Item(p)| !(p.retractable && dead.contains(&p.handle())));
        cancelled.clear();
    }
}

/// Runs a model's objects one batch at a time in virtual-time order.
pub struct Sequential<M: Model> {
    model: M,
    states: Vec<M::State>,
    seqs: Vec<u64>,
    pending: Queue<Item<M::Time, M::Msg>>,
    cancelled: FxHashSet<Handle>,
    stats: MessageStats,
    now: Option<VTime<M::Time>>,
    /// Buffers kept from batch to batch: the batch, and what it sent and cancelled.
    batch: Vec<Envelope<M::Msg>>,
    sent: Vec<Pending<M::Time, M::Msg>>,
    retracted: Vec<Handle>,
    /// Asks the run to end early.
    interrupt: Option<Interrupt>,
    /// Whether the sink reads the states after each batch: a batch then runs no events of its
    /// object's own beyond its time ([`Ctx::may_run`]).
    observed: bool,
}

impl<M: Model> Sequential<M> {
    /// Sets up the model's objects with their initial states and runs every object's `init` at
    /// virtual time `start` (in object order).
    pub fn new(model: M, states: Vec<M::State>, start: VTime<M::Time>) -> Sequential<M> {
        let reserved = RESERVED_PER_OBJECT * states.len();
        let mut s = Sequential {
            seqs: vec![0; states.len()],
            model,
            states,
            pending: Queue::with_capacity(reserved),
            cancelled: FxHashSet::default(),
            stats: MessageStats::default(),
            now: None,
            batch: Vec::new(),
            sent: Vec::new(),
            retracted: Vec::new(),
            interrupt: None,
            observed: true,
        };
        for me in 0..s.states.len() as u32 {
            let mut ctx = Ctx::new(&s.model, start.clone(), me, &mut s.seqs[me as usize]);
            s.model.init(&mut ctx, me, &mut s.states[me as usize]);
            let (sent, cancelled) = (ctx.sent, ctx.cancelled);
            assert!(cancelled.is_empty(), "init may not cancel");
            for p in sent {
                s.stats.count(s.model.kind(&p.env.msg));
                s.pending.push(Item(p), false);
            }
        }
        s
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// Every object's state.
    pub fn states(&self) -> &[M::State] {
        &self.states
    }

    /// Message statistics so far.
    pub fn stats(&self) -> &MessageStats {
        &self.stats
    }

    /// The virtual time of the last batch run.
    pub fn now(&self) -> Option<&VTime<M::Time>> {
        self.now.as_ref()
    }

    /// Messages waiting (cancelled ones not yet discarded included).
    pub fn pending_len(&self) -> usize {
        self.pending.len()
    }

    /// Pops the next message that was not cancelled.
    fn pop_live(&mut self) -> Option<Pending<M::Time, M::Msg>> {
        pop_live(&mut self.pending, &mut self.cancelled)
    }

    /// Drops cancelled messages from the pending set once they are half of it
    /// ([`sweep_cancelled`]).
    fn sweep_cancelled(&mut self) {
        sweep_cancelled(&mut self.pending, &mut self.cancelled);
    }

    /// Whether an interrupt asks the run to end.
    #[inline]
    fn interrupted(&self) -> bool {
        self.interrupt.as_ref().is_some_and(Interrupt::raised)
    }

    /// Ends later runs early once `interrupt` is raised: at the time of the batch run last, every
    /// other batch at that time run too.
    pub fn stop_on(&mut self, interrupt: Interrupt) {
        self.interrupt = Some(interrupt);
    }

    /// Whether the sink reads the states just after each batch (the default). When it does
    /// not, a batch may run its object's own events on to the next message ([`Ctx::may_run`]).
    pub fn observe_states(&mut self, on: bool) {
        self.observed = on;
    }

    /// Runs every batch with time at most `until`, passing each output, with the states after
    /// the batch that produced it, to `sink`; stops at the first error the sink returns.
    /// Returns the time the run ended at: `until`, or an earlier one where an interrupt
    /// ([`Sequential::stop_on`]) ended it, every batch up to that time run.
    pub fn run<E>(&mut self, until: f64, sink: &mut Sink<'_, M, E>) -> Result<f64, E> {
        let mut until = until;
        loop {
            if let Some(now) = self.now.as_ref().filter(|_| self.interrupted()) {
                until = until.min(now.t());
            }
            match self.pending.peek() {
                Some(Item(p)) if p.time.t() <= until => {}
                _ => return Ok(until),
            }
            let Some(first) = self.pop_live() else {
                return Ok(until);
            };
            if first.time.t() > until {
                self.pending.push(Item(first), false);
                return Ok(until);
            }
            let (time, to) = (first.time, first.to);
            let mut batch = std::mem::take(&mut self.batch);
            batch.push(first.env);
            take_rest_of_batch(
                &mut self.pending,
                &mut self.cancelled,
                &time,
                to,
                &mut batch,
            );
            // the next batch's object, most likely: its state loads while this batch runs
            if let Some(Item(next)) = self.pending.peek() {
                let o = next.to as usize;
                prefetch_all(&self.states[o]);
                prefetch(&self.seqs[o]);
            }
            self.stats.batches += 1;
            self.stats.delivered += batch.len() as u64;
            let mut ctx = Ctx::new(&self.model, time.clone(), to, &mut self.seqs[to as usize]);
            if !self.observed {
                let before = self.pending.peek().map(|Item(p)| p.time.clone());
                ctx = ctx.with_horizon(Horizon { before, until });
            }
            ctx.sent = std::mem::take(&mut self.sent);
            ctx.cancelled = std::mem::take(&mut self.retracted);
            self.model
                .handle(&mut ctx, to, &mut self.states[to as usize], &batch);
            batch.clear();
            self.batch = batch;
            let (mut sent, mut cancelled, output) = (ctx.sent, ctx.cancelled, ctx.output);
            let time = ctx.reached.unwrap_or(time);
            for h in cancelled.drain(..) {
                self.stats.cancels += 1;
                self.cancelled.insert(h);
            }
            self.sweep_cancelled();
            for p in sent.drain(..) {
                self.stats.count(self.model.kind(&p.env.msg));
                let in_instant = p.time.key == time.key;
                self.pending.push(Item(p), in_instant);
            }
            (self.sent, self.retracted) = (sent, cancelled);
            self.now = Some(time);
            for o in output {
                sink(&self.model, &self.states, o)?;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PlainTime;

    /// One object that, every unit of time, schedules a far-future reminder and cancels the
    /// previous one: a pending set that kept cancelled messages would grow with every step.
    struct Forgetful;

    impl Model for Forgetful {
        type Time = PlainTime;
        type Msg = bool;
        type State = Option<Handle>;
        type Output = ();
        type Undo = ();

        fn kind_names(&self) -> &'static [&'static str] {
            &["Tick"]
        }
        fn kind(&self, _: &bool) -> usize {
            0
        }
        fn priority(&self, _: &bool) -> u8 {
            0
        }
        fn init(&self, ctx: &mut Ctx<'_, Self>, me: u32, _: &mut Option<Handle>) {
            ctx.send_at(me, VTime::start(1.0), true);
        }
        fn handle(
            &self,
            ctx: &mut Ctx<'_, Self>,
            me: u32,
            reminder: &mut Option<Handle>,
            _: &[Envelope<bool>],
        ) {
            let t = ctx.now().t();
            if let Some(h) = reminder.take() {
                ctx.cancel(h);
            }
            *reminder = Some(ctx.send_at(me, VTime::start(t + 1e6), false));
            ctx.send_at(me, VTime::start(t + 1.0), true);
        }
    }

    /// Object 0 ticks at every whole time, each tick an event of its own that needs no
    /// message; object 1 sends it a message at 2.5. Ticks are reported with their times.
    struct Ticker;

    impl Model for Ticker {
        type Time = PlainTime;
        type Msg = ();
        type State = f64;
        type Output = f64;
        type Undo = ();

        fn kind_names(&self) -> &'static [&'static str] {
            &["Poke"]
        }
        fn kind(&self, _: &()) -> usize {
            0
        }
        fn priority(&self, _: &()) -> u8 {
            0
        }
        fn init(&self, ctx: &mut Ctx<'_, Self>, me: u32, _: &mut f64) {
            let t = if me == 0 { 1.0 } else { 2.5 };
            ctx.send_at(me, VTime::start(t), ());
        }
        fn handle(&self, ctx: &mut Ctx<'_, Self>, me: u32, next: &mut f64, _: &[Envelope<()>]) {
            let now = ctx.now().t();
            if me == 1 {
                return ctx.send_now(0, ());
            }
            if now < *next {
                // the poke: its time reported, the next tick still to come
                return ctx.emit(-now);
            }
            ctx.emit(now);
            *next = now + 1.0;
            while ctx.may_run(&VTime::start(*next)) {
                ctx.emit(*next);
                ctx.reach(VTime::start(*next));
                *next += 1.0;
            }
            ctx.send_at(0, VTime::start(*next), ());
        }
    }

    #[test]
    fn a_batch_runs_its_own_events_on_to_the_next_message_only_when_unobserved() {
        for observed in [true, false] {
            let mut s = Sequential::new(Ticker, vec![1.0, 0.0], VTime::start(0.0));
            s.observe_states(observed);
            let mut out = Vec::new();
            s.run(5.0, &mut |_, _, t| {
                out.push(t);
                Ok::<(), ()>(())
            })
            .unwrap();
            assert_eq!(out, [1.0, 2.0, -2.5, 3.0, 4.0, 5.0], "observed {observed}");
            let batches = if observed { 7 } else { 4 };
            assert_eq!(s.stats().batches, batches, "observed {observed}");
        }
    }

    #[test]
    fn cancelled_messages_do_not_pile_up() {
        let mut s = Sequential::new(Forgetful, vec![None], VTime::start(0.0));
        s.run(20_000.0, &mut |_, _, ()| Ok::<(), ()>(())).unwrap();
        assert_eq!(s.stats().batches, 20_000);
        assert_eq!(s.stats().cancels, 19_999);
        // one tick and one live reminder, plus at most twice the sweep threshold of dead ones
        assert!(
            s.pending_len() <= 2 + 2 * 1024,
            "{} pending",
            s.pending_len()
        );
    }
}
