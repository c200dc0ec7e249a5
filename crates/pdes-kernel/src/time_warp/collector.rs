//! The collector: committed batches of every worker, merged into one order for the sink.
//!
//! Workers hand over, after each GVT round, the batches they committed. A batch that ran its
//! object's own events on past its time ([`Ctx::may_run`](crate::Ctx::may_run)) commits only
//! once GVT passes the last of them, a round or more after batches of other objects that come
//! between its events; its outputs carry their own times. The collector holds every output
//! until no worker can still commit an earlier one ([`Chunk::open`]) and hands them to the sink
//! in the order of their times, a state shipped with a batch just before its outputs.

use super::{Chunk, Committed, Floor, RoundRecord, TwStats};
use crate::executor::ExecError;
use crate::sequential::Sink;
use crate::{MessageStats, Model, Time, VTime};
use std::collections::binary_heap::PeekMut;
use std::collections::{BTreeMap, BinaryHeap};

/// A model's chunk of committed batches.
pub(super) type ChunkOf<M> = Chunk<<M as Model>::Time, <M as Model>::State, <M as Model>::Output>;

/// A committed batch whose observed state and outputs still wait for their turn at the sink,
/// in its own order: the state first, then the outputs, each at its time.
struct Open<M: Model> {
    /// Its time: the state's, and that of every output without a time of its own.
    time: VTime<M::Time>,
    /// The object's state after it, when observed; boxed, as a state may be far larger than
    /// the rest.
    state: Option<Box<M::State>>,
    /// Its outputs still to go.
    output: std::vec::IntoIter<M::Output>,
    /// Their times, when the batch ran on past its own ([`Committed::times`]).
    times: std::vec::IntoIter<VTime<M::Time>>,
}

impl<M: Model> Open<M> {
    /// A batch's items in their order: sorted by time, when the model emitted them otherwise.
    fn of(c: Committed<M::Time, M::State, M::Output>) -> Open<M> {
        let (mut output, mut times) = (c.output, c.times);
        if times.windows(2).any(|w| w[1] < w[0]) {
            times.resize(output.len(), c.time.clone());
            let mut pairs: Vec<_> = times.into_iter().zip(output).collect();
            pairs.sort_by(|a, b| a.0.cmp(&b.0));
            (times, output) = pairs.into_iter().unzip();
        }
        Open {
            time: c.time,
            state: c.state.map(Box::new),
            output: output.into_iter(),
            times: times.into_iter(),
        }
    }

    /// The time of its next item, if any; the item is then the one [`Open::take`] gives.
    fn next_time(&mut self) -> Option<VTime<M::Time>> {
        if self.state.is_some() {
            return Some(self.time.clone());
        }
        (self.output.len() > 0).then(|| self.times.next().unwrap_or_else(|| self.time.clone()))
    }

    /// Its next item.
    fn take(&mut self) -> Item<M> {
        match self.state.take() {
            Some(state) => Item::State(state),
            None => Item::Output(self.output.next().expect("an output left")),
        }
    }
}

/// The batch whose next item is the earliest held: at the top of the collector's heap.
struct Head<T> {
    /// Its next item's time.
    time: VTime<T>,
    obj: u32,
    /// The batch's place among those held: batches of one object at one time keep their order.
    seq: u64,
    /// Where the batch is kept ([`Collector::open`]).
    slot: usize,
}

impl<T: Time> Head<T> {
    fn order(&self, o: &Self) -> std::cmp::Ordering {
        (self.time.cmp(&o.time))
            .then(self.obj.cmp(&o.obj))
            .then(self.seq.cmp(&o.seq))
    }
}

impl<T: Time> PartialEq for Head<T> {
    fn eq(&self, o: &Self) -> bool {
        self.order(o).is_eq()
    }
}

impl<T: Time> Eq for Head<T> {}

impl<T: Time> PartialOrd for Head<T> {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}

/// The earliest first, for a max-heap.
impl<T: Time> Ord for Head<T> {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        o.order(self)
    }
}

/// What an [`Open`] batch hands the sink next.
enum Item<M: Model> {
    /// The object's state after the batch.
    State(Box<M::State>),
    /// An output.
    Output(M::Output),
}

/// Committed batches of one round from every worker, merged and fed to the sink.
pub struct Collector<M: Model> {
    states: Vec<M::State>,
    /// Whether workers ship observed states with their batches; when not, the sink is shown no
    /// states during the run (an empty slice), only the final ones after it.
    pub(super) shipped: bool,
    rounds: BTreeMap<u64, Vec<ChunkOf<M>>>,
    next_round: u64,
    /// Batches of rounds through whose outputs and states wait, as a worker may still commit
    /// an earlier output: each at its next item's time, the earliest on top. One heap entry
    /// per batch, not per item: its outputs are in order already.
    held: BinaryHeap<Head<M::Time>>,
    /// The batches held, by slot; `None` for a free slot.
    open: Vec<Option<Open<M>>>,
    /// Free slots of `open`.
    free: Vec<usize>,
    /// Batches held so far.
    seq: u64,
    /// Workers' final states, held until every round before them has gone to the sink: a
    /// worker's last chunk can arrive before another worker's chunk of their last round.
    finals: Vec<(u32, M::State)>,
    /// Workers whose last chunk of this run has arrived.
    lasts: usize,
    /// Statistics of the workers' last chunks.
    pub stats: TwStats,
    /// Committed message statistics (summed over runs).
    pub messages: MessageStats,
    /// Live messages left at the end.
    pub pending: u64,
    /// The records of the rounds so far, when it keeps them ([`TwConfig::record_rounds`](super::TwConfig::record_rounds)).
    pub records: Option<Vec<RoundRecord>>,
}

impl<M: Model> Collector<M> {
    /// A collector starting from the objects' initial states.
    pub fn new(states: Vec<M::State>) -> Collector<M> {
        Collector {
            states,
            shipped: true,
            rounds: BTreeMap::new(),
            next_round: 1,
            held: BinaryHeap::new(),
            open: Vec::new(),
            free: Vec::new(),
            seq: 0,
            finals: Vec::new(),
            lasts: 0,
            stats: TwStats::default(),
            messages: MessageStats::default(),
            pending: 0,
            records: None,
        }
    }

    /// Takes one chunk and runs every round it completes through `sink`; the first failure
    /// (the sink's error, or a worker's) goes to `failed`, and output stops there.
    pub fn take<E>(
        &mut self,
        model: &M,
        workers: usize,
        chunk: Chunk<M::Time, M::State, M::Output>,
        sink: &mut Sink<'_, M, E>,
        failed: &mut Option<ExecError<E>>,
    ) {
        if let Some((stats, messages, pending)) = &chunk.last {
            self.stats.add(stats);
            self.messages.add(messages);
            self.pending += pending;
            self.finals.extend(chunk.finals);
            self.lasts += 1;
            if let (Some(e), None) = (&chunk.error, &failed) {
                *failed = Some(ExecError::Failed(e.clone()));
            }
            self.settle(model, workers, sink, failed);
            return;
        }
        self.rounds.entry(chunk.round).or_default().push(chunk);
        while self
            .rounds
            .get(&self.next_round)
            .is_some_and(|v| v.len() == workers)
        {
            let chunks = self.rounds.remove(&self.next_round).expect("a round");
            if let Some(records) = &mut self.records {
                records.push(RoundRecord::of(self.next_round, &chunks));
            }
            self.next_round += 1;
            if failed.is_some() {
                continue;
            }
            let open = chunks.iter().fold(Floor::INFINITY, |f, c| f.min(c.open));
            for batch in chunks.into_iter().flat_map(|c| c.batches) {
                self.hold(batch);
            }
            self.release(model, &open, sink, failed);
        }
        self.settle(model, workers, sink, failed);
    }

    /// Holds a committed batch's state and outputs, each at its time.
    fn hold(&mut self, c: Committed<M::Time, M::State, M::Output>) {
        let obj = c.obj;
        let mut batch = Open::of(c);
        let Some(time) = batch.next_time() else {
            return;
        };
        let slot = match self.free.pop() {
            Some(k) => {
                self.open[k] = Some(batch);
                k
            }
            None => {
                self.open.push(Some(batch));
                self.open.len() - 1
            }
        };
        let seq = self.seq;
        self.seq += 1;
        self.held.push(Head {
            time,
            obj,
            seq,
            slot,
        });
    }

    /// Hands the sink, in order, every held output and state that `open` has passed.
    fn release<E>(
        &mut self,
        model: &M,
        open: &Floor,
        sink: &mut Sink<'_, M, E>,
        failed: &mut Option<ExecError<E>>,
    ) {
        while let Some(mut top) = self.held.peek_mut() {
            if !open.passed(&top.time, top.obj) {
                break;
            }
            let (obj, slot) = (top.obj as usize, top.slot);
            let batch = self.open[slot].as_mut().expect("a held batch");
            let item = batch.take();
            match batch.next_time() {
                // the batch goes down the heap to its next item's place
                Some(time) => top.time = time,
                None => {
                    PeekMut::pop(top);
                    self.open[slot] = None;
                    self.free.push(slot);
                }
            }
            if failed.is_some() {
                continue;
            }
            match item {
                Item::State(state) => self.states[obj] = *state,
                Item::Output(o) => {
                    let states: &[M::State] = if self.shipped { &self.states } else { &[] };
                    if let Err(e) = sink(model, states, o) {
                        *failed = Some(ExecError::Sink(e));
                    }
                }
            }
        }
    }

    /// Once every worker has sent its last chunk and every round is through: hands the sink
    /// what is still held (nothing is left to come before it) and takes the final states.
    fn settle<E>(
        &mut self,
        model: &M,
        workers: usize,
        sink: &mut Sink<'_, M, E>,
        failed: &mut Option<ExecError<E>>,
    ) {
        if self.lasts == workers && self.rounds.is_empty() {
            self.release(model, &Floor::INFINITY, sink, failed);
            for (id, state) in self.finals.drain(..) {
                self.states[id as usize] = state;
            }
        }
    }

    /// Readies the collector for another run of the same objects.
    pub(super) fn begin_run(&mut self) {
        self.stats = TwStats::default();
        self.pending = 0;
        self.lasts = 0;
        self.finals.clear();
    }

    /// The committed states.
    pub fn states(&self) -> &[M::State] {
        &self.states
    }

    /// The committed states, for workers to hand theirs over.
    pub(super) fn states_mut(&mut self) -> &mut [M::State] {
        &mut self.states
    }

    /// Takes the committed states away, for the workers to hold while they run; the collector
    /// holds none until [`Collector::put_states`].
    pub(super) fn take_states(&mut self) -> Vec<M::State> {
        std::mem::take(&mut self.states)
    }

    /// Gives the collector the committed states back.
    pub(super) fn put_states(&mut self, states: Vec<M::State>) {
        self.states = states;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Ctx, Envelope, PlainTime};

    /// Objects that report numbers; nothing is ever sent.
    struct Tagged;

    impl Model for Tagged {
        type Time = PlainTime;
        type Msg = ();
        type State = ();
        type Output = u32;
        type Undo = ();

        fn kind_names(&self) -> &'static [&'static str] {
            &["Nothing"]
        }
        fn kind(&self, _: &()) -> usize {
            0
        }
        fn priority(&self, _: &()) -> u8 {
            0
        }
        fn init(&self, _: &mut Ctx<'_, Self>, _: u32, _: &mut ()) {}
        fn handle(&self, _: &mut Ctx<'_, Self>, _: u32, _: &mut (), _: &[Envelope<()>]) {}
    }

    fn chunk(
        worker: usize,
        round: u64,
        batches: Vec<Committed<PlainTime, (), u32>>,
        open: f64,
    ) -> ChunkOf<Tagged> {
        Chunk {
            worker,
            round,
            batches,
            last: None,
            finals: Vec::new(),
            error: None,
            progress: Default::default(),
            open: Floor::start(open),
        }
    }

    fn batch(obj: u32, t: f64, output: Vec<u32>, times: &[f64]) -> Committed<PlainTime, (), u32> {
        Committed {
            time: VTime::start(t),
            obj,
            state: None,
            output,
            times: times.iter().map(|&t| VTime::start(t)).collect(),
        }
    }

    #[test]
    fn outputs_wait_until_no_worker_can_commit_an_earlier_one() {
        let mut c: Collector<Tagged> = Collector::new(vec![(), ()]);
        let seen = std::cell::RefCell::new(Vec::new());
        let mut failed = None;
        let mut sink = |_: &Tagged, _: &[()], n: u32| {
            seen.borrow_mut().push(n);
            Ok::<(), ()>(())
        };
        // worker 1's object ran on from t = 1 past GVT: worker 0's output at t = 2 waits
        let first = batch(0, 2.0, vec![20, 21], &[]);
        c.take(
            &Tagged,
            2,
            chunk(0, 1, vec![first], 3.0),
            &mut sink,
            &mut failed,
        );
        c.take(&Tagged, 2, chunk(1, 1, vec![], 1.0), &mut sink, &mut failed);
        assert!(seen.borrow().is_empty(), "held back: {seen:?}");
        // the batch that ran on commits a round later, its outputs each at their own time
        let span = batch(1, 1.0, vec![10, 25, 30], &[1.0, 2.5, 3.0]);
        c.take(
            &Tagged,
            2,
            chunk(1, 2, vec![span], 4.0),
            &mut sink,
            &mut failed,
        );
        c.take(&Tagged, 2, chunk(0, 2, vec![], 3.5), &mut sink, &mut failed);
        assert_eq!(*seen.borrow(), vec![10, 20, 21, 25, 30]);
        assert!(failed.is_none());
    }

    #[test]
    fn batches_interleave_by_time_and_keep_their_order_at_one_time() {
        let mut c: Collector<Tagged> = Collector::new(vec![(), ()]);
        let seen = std::cell::RefCell::new(Vec::new());
        let mut failed = None;
        let mut sink = |_: &Tagged, _: &[()], n: u32| {
            seen.borrow_mut().push(n);
            Ok::<(), ()>(())
        };
        let batches = vec![
            batch(1, 1.0, vec![10, 30, 50], &[1.0, 3.0, 5.0]),
            batch(0, 2.0, vec![20, 40], &[2.0, 4.0]),
            // the same object and time as an earlier batch: after it
            batch(1, 3.0, vec![31], &[]),
            // emitted out of order: given in the order of their times
            batch(0, 6.0, vec![70, 60], &[7.0, 6.0]),
        ];
        c.take(
            &Tagged,
            1,
            chunk(0, 1, batches, 10.0),
            &mut sink,
            &mut failed,
        );
        assert_eq!(*seen.borrow(), vec![10, 20, 30, 31, 40, 50, 60, 70]);
    }
}
