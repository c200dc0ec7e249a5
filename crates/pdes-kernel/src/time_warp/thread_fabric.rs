//! The threads of one process as a Time Warp [`Fabric`]: shared inboxes, published floors and a
//! barrier for the reductions.

use super::{Bounds, Chunk, Fabric, Floor, Op, Reduction};
use crate::spin_barrier::SpinBarrier;
use crate::{Model, Time};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Mutex};

/// The identity of [`Reduction::combine`].
pub const NOTHING: Reduction = Reduction {
    in_flight: 0,
    floor: Floor::INFINITY,
    stop: 0,
    sweep: 0,
    interrupt: 0,
    latest: f64::NEG_INFINITY,
};

/// Reductions among the threads of one process: three rotating slots and a barrier that
/// spins. A round comes every few hundred microseconds on a busy run (10^5 disks in 2
/// regions: 11,000 rounds in 1.9 s), and with a barrier that puts its threads to sleep every
/// round cost a wake-up through the system's scheduler.
pub struct ThreadReduce {
    barrier: SpinBarrier,
    slots: Mutex<[Reduction; 3]>,
    calls: Vec<AtomicU64>,
}

impl ThreadReduce {
    /// Reductions among `n` threads, numbered 0 to `n - 1`.
    pub fn new(n: usize) -> ThreadReduce {
        ThreadReduce {
            barrier: SpinBarrier::new(n),
            slots: Mutex::new([NOTHING; 3]),
            calls: (0..n).map(|_| AtomicU64::new(0)).collect(),
        }
    }

    /// A thread has gone for good (it panicked): every reduction, now and later, returns at
    /// once with a stop request.
    pub fn poison(&self) {
        self.barrier.poison();
    }

    /// Combines `local` with every other thread's value of the same call.
    pub fn reduce(&self, me: usize, local: Reduction) -> Reduction {
        // call k adds into slot k % 3; after its barrier every thread has read slot (k - 1) % 3,
        // which the leader then clears for call k + 2
        let k = (self.calls[me].fetch_add(1, Ordering::Relaxed) % 3) as usize;
        {
            let mut s = self.slots.lock().expect("no thread panicked");
            s[k] = s[k].combine(local);
        }
        if self.barrier.wait().is_err() {
            // a worker panicked: the others stop, and the panic reaches the caller
            return Reduction { stop: 1, ..NOTHING };
        }
        let mut s = self.slots.lock().expect("no thread panicked");
        let r = s[k];
        // every thread has read slot k - 1 before it arrived here: any one may clear it
        s[(k + 2) % 3] = NOTHING;
        r
    }
}

/// A worker's inbox and what bounds it, on cache lines of its own: its worker writes it every
/// few batches, and a neighbour's writes would otherwise take the line away from under it.
#[repr(align(128))]
struct Slot<T, Msg> {
    /// Ops sent to it, not taken yet; whoever changes `floors` holds this lock.
    inbox: Mutex<Vec<Op<T, Msg>>>,
    /// Whether the inbox may hold ops: its worker takes the lock only then.
    full: AtomicBool,
    /// Its floors, readable without the lock.
    floors: Floors,
}

/// Words of one floor.
const WORDS: usize = super::floor::DEPTH + 3;

/// A worker's two floors behind a sequence lock, so that the other workers read them without
/// taking its lock: the inbox's floor, below every op in the inbox, and the worker's own, below
/// everything it holds or has yet to send (its published floor, lowered to the inbox's when it
/// takes the inbox). One writer at a time, the holder of the inbox lock.
struct Floors {
    /// Twice the changes so far, plus one while a change is being written: a reading of every
    /// slot saw one instant if no count moved while it read.
    seq: AtomicU64,
    /// The worker's floor, then the inbox's, as words.
    words: [AtomicU64; 2 * WORDS],
}

impl Floors {
    fn new(own: Floor, inbox: Floor) -> Floors {
        let f = Floors {
            seq: AtomicU64::new(0),
            words: std::array::from_fn(|_| AtomicU64::new(0)),
        };
        f.write(own, inbox);
        f
    }

    /// Sets both floors; the caller holds the slot's inbox lock.
    fn write(&self, own: Floor, inbox: Floor) {
        let s = self.seq.load(Ordering::Relaxed);
        self.seq.store(s + 1, Ordering::Relaxed);
        std::sync::atomic::fence(Ordering::Release);
        for (w, v) in self
            .words
            .iter()
            .zip(own.to_words().into_iter().chain(inbox.to_words()))
        {
            w.store(v, Ordering::Relaxed);
        }
        self.seq.store(s + 2, Ordering::Release);
    }

    /// Both floors, as the holder of the inbox lock (the only writer) reads them.
    fn current(&self) -> (Floor, Floor) {
        let w: [u64; 2 * WORDS] = std::array::from_fn(|i| self.words[i].load(Ordering::Relaxed));
        (
            Floor::from_words(&w[..WORDS]),
            Floor::from_words(&w[WORDS..]),
        )
    }

    /// The change count and both floors, or `None` if a change was being written meanwhile.
    fn read(&self) -> Option<(u64, Floor, Floor)> {
        let s = self.seq.load(Ordering::Acquire);
        if s % 2 == 1 {
            return None;
        }
        let w: [u64; 2 * WORDS] = std::array::from_fn(|i| self.words[i].load(Ordering::Relaxed));
        std::sync::atomic::fence(Ordering::Acquire);
        (self.seq.load(Ordering::Relaxed) == s).then(|| {
            let (own, inbox) = (
                Floor::from_words(&w[..WORDS]),
                Floor::from_words(&w[WORDS..]),
            );
            (s, own, inbox)
        })
    }
}

/// The inboxes of one process's workers and the floors that bound them, shared by the threads
/// fabric and, within each rank, the MPI one.
pub(super) struct Slots<T, Msg> {
    slots: Vec<Slot<T, Msg>>,
}

impl<T: Time, Msg> Slots<T, Msg> {
    /// Empty inboxes for `n` workers, whose floors know nothing yet.
    pub(super) fn new(n: usize) -> Self {
        Slots {
            slots: (0..n)
                .map(|_| Slot {
                    inbox: Mutex::new(Vec::new()),
                    full: AtomicBool::new(false),
                    floors: Floors::new(Floor::NEG_INFINITY, Floor::INFINITY),
                })
                .collect(),
        }
    }

    /// Puts `ops` in worker `k`'s inbox, its floor lowered to theirs.
    pub(super) fn send(&self, k: usize, mut ops: Vec<Op<T, Msg>>) {
        let floor = Op::lowest(&ops);
        let slot = &self.slots[k];
        let mut inbox = slot.inbox.lock().expect("no thread panicked");
        if inbox.is_empty() {
            std::mem::swap(&mut *inbox, &mut ops);
        } else {
            inbox.append(&mut ops);
        }
        let (own, waiting) = slot.floors.current();
        slot.floors.write(own, waiting.min(floor));
        slot.full.store(true, Ordering::Release);
    }

    /// Moves worker `k`'s inbox into `into`; the worker's own floor takes the inbox's over.
    pub(super) fn recv(&self, k: usize, into: &mut Vec<Op<T, Msg>>) {
        let slot = &self.slots[k];
        // ops sent since this worker looked are taken at its next look
        if !slot.full.load(Ordering::Acquire) {
            return;
        }
        let mut inbox = slot.inbox.lock().expect("no thread panicked");
        slot.full.store(false, Ordering::Relaxed);
        if inbox.is_empty() {
            return;
        }
        if into.is_empty() {
            std::mem::swap(&mut *inbox, into);
        } else {
            into.append(&mut inbox);
        }
        let (own, waiting) = slot.floors.current();
        slot.floors.write(own.min(waiting), Floor::INFINITY);
    }

    /// Sets worker `k`'s own floor.
    pub(super) fn publish(&self, k: usize, floor: Floor) {
        let slot = &self.slots[k];
        let _inbox = slot.inbox.lock().expect("no thread panicked");
        let (_, waiting) = slot.floors.current();
        slot.floors.write(floor, waiting);
    }

    /// For worker `k`: the smallest floor of the other workers and their inboxes, and the floor
    /// of `k`'s own inbox, as they all stood at one instant; `None` if a change was being
    /// written meanwhile.
    pub(super) fn peers(&self, k: usize) -> Option<(Floor, Floor)> {
        // an op is always under some floor: in its sender's until it is in an inbox, in the
        // inbox's until its receiver takes it, and in its receiver's from then on; what waits
        // for another worker reaches `k` only through what that worker does from there
        let (mut changes, mut others, mut mine) = (0u64, Floor::INFINITY, Floor::INFINITY);
        for (w, slot) in self.slots.iter().enumerate() {
            let (seq, own, waiting) = slot.floors.read()?;
            changes += seq;
            if w == k {
                mine = waiting;
            } else {
                others = others.min(own).min(waiting);
            }
        }
        // counts only grow: the same sum on a second reading means no slot changed between
        // its two readings, so all of them held at one instant between the two passes
        let again: u64 = self
            .slots
            .iter()
            .map(|slot| slot.floors.seq.load(Ordering::Acquire))
            .sum();
        (again == changes).then_some((others, mine))
    }
}

/// Workers as threads of this process.
pub struct ThreadFabric<M: Model> {
    slots: Slots<M::Time, M::Msg>,
    reduce: ThreadReduce,
    /// GVT rounds asked for so far (by any worker): every worker with fewer behind it starts one.
    rounds_asked: AtomicU64,
    collector: mpsc::Sender<Chunk<M::Time, M::State, M::Output>>,
}

impl<M: Model> ThreadFabric<M>
where
    M::Msg: Send,
{
    /// A fabric for `n` workers whose committed chunks go to `collector`.
    pub fn new(n: usize, collector: mpsc::Sender<Chunk<M::Time, M::State, M::Output>>) -> Self {
        ThreadFabric {
            slots: Slots::new(n),
            reduce: ThreadReduce::new(n),
            rounds_asked: AtomicU64::new(0),
            collector,
        }
    }
}

impl<M: Model> Fabric<M> for ThreadFabric<M>
where
    M::Msg: Send,
    M::State: Send,
    M::Output: Send,
{
    fn send(&self, _from: usize, to: usize, ops: Vec<Op<M::Time, M::Msg>>) {
        self.slots.send(to, ops);
    }

    fn recv(&self, me: usize, into: &mut Vec<Op<M::Time, M::Msg>>) {
        self.slots.recv(me, into);
    }

    fn reduce(&self, me: usize, local: Reduction) -> Reduction {
        self.reduce.reduce(me, local)
    }

    fn abandon(&self) {
        self.reduce.poison();
    }

    fn commit(&self, chunk: Chunk<M::Time, M::State, M::Output>) {
        // the collector outlives the workers; if it has gone, nobody wants the output
        let _ = self.collector.send(chunk);
    }

    fn shares_floors(&self) -> bool {
        true
    }

    fn round_due(&self, _me: usize, done: u64, due: bool) -> bool {
        if due {
            self.rounds_asked.fetch_max(done + 1, Ordering::Relaxed);
            return true;
        }
        self.rounds_asked.load(Ordering::Relaxed) > done
    }

    fn publish(&self, me: usize, floor: Floor) {
        self.slots.publish(me, floor);
    }

    fn peers_floor(&self, me: usize, lookahead: f64) -> Option<Bounds> {
        self.slots
            .peers(me)
            .map(|(others, mine)| Bounds::of_peers(others, mine, lookahead))
    }
}
