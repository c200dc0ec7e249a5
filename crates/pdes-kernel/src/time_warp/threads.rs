//! The Time Warp executor: one thread per worker of this process (beside the ranks of others
//! under MPI) while the calling thread collects committed batches and feeds them, in order, to
//! the sink.

use super::collector::{ChunkOf, Collector};
use super::thread_fabric::ThreadFabric;
use super::{Fabric, Halt, ObjectMap, Op, Placement, RoundRecord, TwConfig, TwStats, Worker};
use crate::executor::ExecError;
use crate::sequential::Sink;
use crate::{Interrupt, MessageStats, Model, VTime};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{mpsc, Arc};

/// How long the collector sleeps between looks at the chunks the workers sent.
const COLLECTOR_NAP: std::time::Duration = std::time::Duration::from_millis(10);

/// Counts a worker's thread as ended, and wakes the collector, when the thread ends; by a
/// panic too, and then the other workers stop waiting for it.
struct WorkerEnd<'a> {
    count: &'a AtomicUsize,
    collector: &'a std::thread::Thread,
    /// Tells the fabric that this worker is gone ([`Fabric::abandon`]).
    abandon: &'a dyn Fn(),
}

impl Drop for WorkerEnd<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            (self.abandon)();
        }
        self.count.fetch_add(1, Ordering::Release);
        self.collector.unpark();
    }
}

/// The Time Warp executor: worker threads, and across MPI ranks where MPI is running (cargo
/// feature `mpi`); the same interface as the sequential executor.
pub struct TimeWarp<M: Model> {
    model: M,
    workers: Vec<Worker<M>>,
    cfg: TwConfig,
    collector: Collector<M>,
    ranks: usize,
    /// Whether the objects' `init`s have run (on the workers, at the first run).
    started: bool,
    /// Start of the run being set up: where the objects start.
    start: VTime<M::Time>,
    /// Where the last run ended (at first, where the objects started).
    now: f64,
    /// Asks runs to end early.
    interrupt: Option<Interrupt>,
}

/// This process's MPI rank and the number of ranks; `(0, 1)` without MPI.
pub fn place() -> (usize, usize) {
    #[cfg(feature = "mpi")]
    {
        super::mpi::place()
    }
    #[cfg(not(feature = "mpi"))]
    {
        (0, 1)
    }
}

/// Whether this process collects the run's results: always on threads, rank 0 under MPI (the
/// other ranks write nothing and hold their objects' initial states at the end).
pub fn collects_results() -> bool {
    place().0 == 0
}

/// Workers in all (every rank's) for `cfg`.
pub fn total_workers(cfg: &TwConfig) -> usize {
    cfg.workers.max(1) * place().1
}

impl<M> TimeWarp<M>
where
    M: Model + Sync,
    M::Msg: Send,
    M::State: Send + Sync,
    M::Output: Send,
{
    /// Places the objects on the workers of every rank as `map` says (the [`total_workers`]
    /// workers numbered rank by rank), to start at `start`: the first run gives this rank's
    /// workers their objects' states and runs the objects' `init`s.
    pub fn new(
        model: M,
        states: Vec<M::State>,
        start: VTime<M::Time>,
        map: &ObjectMap,
        cfg: TwConfig,
    ) -> TimeWarp<M> {
        let (rank, ranks) = place();
        let per = cfg.workers.max(1);
        let worker_of = map.workers_of(states.len(), per * ranks);
        let placement = Arc::new(Placement::new(&worker_of, per * ranks));
        let mine = rank * per..(rank + 1) * per;
        // the collector keeps every object's state until the first run gives this rank's
        // workers theirs and runs their `init`s
        let mut ids: Vec<Vec<u32>> = (0..per).map(|_| Vec::new()).collect();
        for o in 0..states.len() as u32 {
            let w = placement.worker(o);
            if mine.contains(&w) {
                ids[w - mine.start].push(o);
            }
        }
        let workers = ids
            .into_iter()
            .enumerate()
            .map(|(k, ids)| Worker::new(mine.start + k, placement.clone(), ids, cfg.chaos))
            .collect();
        let mut collector = Collector::new(states);
        collector.records = cfg.record_rounds.then(Vec::new);
        TimeWarp {
            model,
            workers,
            cfg,
            collector,
            ranks,
            started: false,
            now: start.t(),
            start,
            interrupt: None,
        }
    }

    /// Gives the workers their objects' states, each on its own thread, and runs the objects'
    /// `init`s there before the first run. The states move from the collector when `moved`
    /// (one process, and a collector that needs none during the run); otherwise the workers
    /// get copies, and the collector holds every object twice.
    fn hand_out(&mut self, moved: bool) {
        if self.workers.iter().all(Worker::holds_states) {
            return;
        }
        let mut states: Vec<Option<M::State>> = if moved {
            self.collector.take_states().into_iter().map(Some).collect()
        } else {
            Vec::new()
        };
        let copies = self.collector.states();
        let (model, start, init) = (&self.model, &self.start, !self.started);
        // each worker's states in the order it holds its objects; none where they are copied
        let parts: Vec<Vec<M::State>> = (self.workers.iter())
            .map(|w| {
                w.ids()
                    .filter(|_| moved)
                    .map(|o| states[o as usize].take().expect("one owner"))
                    .collect()
            })
            .collect();
        std::thread::scope(|scope| {
            for (w, part) in self.workers.iter_mut().zip(parts) {
                scope.spawn(move || {
                    let mut part = part.into_iter();
                    w.give_states(|o| part.next().unwrap_or_else(|| copies[o as usize].clone()));
                    if init {
                        w.init(model, start);
                    }
                });
            }
        });
        if init {
            self.deliver_init_mail();
        }
        self.started = true;
    }

    /// Delivers the `init`s' sends to this rank's workers; those for other ranks wait in
    /// outboxes for the first run's fabric.
    fn deliver_init_mail(&mut self) {
        let per = self.workers.len();
        let first = place().0 * per;
        let mut mail: Vec<Vec<Op<M::Time, M::Msg>>> = (0..per).map(|_| Vec::new()).collect();
        for w in &mut self.workers {
            for (to, ops) in w.take_outbox(first..first + per) {
                mail[to - first].extend(ops);
            }
        }
        for (w, ops) in self.workers.iter_mut().zip(mail) {
            w.accept(ops);
        }
    }

    /// Takes the workers' final states back into the collector, by move.
    fn hand_back(&mut self) {
        if self.collector.states().is_empty() {
            let n = self.workers.iter().map(|w| w.ids().count()).sum();
            let mut states: Vec<Option<M::State>> = (0..n).map(|_| None).collect();
            for w in &mut self.workers {
                w.hand_back_states(|o, state| states[o as usize] = Some(state));
            }
            let states = states.into_iter().map(|s| s.expect("one owner")).collect();
            self.collector.put_states(states);
        } else {
            let held = self.collector.states_mut();
            for w in &mut self.workers {
                w.hand_back_states(|o, state| held[o as usize] = state);
            }
        }
    }

    /// Frees the workers' objects, messages and records, each on its own thread: the thread
    /// that allocated most of them, and a large run holds hundreds of megabytes.
    pub fn free(mut self) {
        if self.ranks == 1 && self.started {
            self.hand_out(true);
        }
        let workers = std::mem::take(&mut self.workers);
        std::thread::scope(|scope| {
            for w in workers {
                scope.spawn(move || drop(w));
            }
        });
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// Every object's committed state (on rank 0 under MPI).
    pub fn states(&self) -> &[M::State] {
        self.collector.states()
    }

    /// Committed message statistics (on rank 0 under MPI).
    pub fn stats(&self) -> &MessageStats {
        &self.collector.messages
    }

    /// Time Warp's own statistics (every rank's, on rank 0 under MPI).
    pub fn tw_stats(&self) -> TwStats {
        let mut s = self.collector.stats.clone();
        s.ranks = self.ranks as u64;
        s
    }

    /// Messages waiting, marked ones not yet discarded included (every rank's, on rank 0 under
    /// MPI).
    pub fn pending_len(&self) -> usize {
        self.collector.pending as usize
    }

    /// A record of every GVT round of the runs so far, with [`TwConfig::record_rounds`] (on
    /// rank 0 under MPI; empty without).
    pub fn round_records(&self) -> &[RoundRecord] {
        self.collector.records.as_deref().unwrap_or(&[])
    }

    /// Every worker's memory samples (uncommitted batches plus held messages) per GVT round.
    pub fn memory_samples(&self) -> Vec<Vec<u64>> {
        self.workers.iter().map(|w| w.samples().to_vec()).collect()
    }

    /// Whether the workers ship every committed state of an observed object to the collector
    /// (the default), so that the sink can read the states just after each batch. A sink that
    /// reads none runs faster without: it is then shown an empty slice of states during the
    /// run, and [`TimeWarp::states`] holds the final states after it.
    pub fn ship_states(&mut self, on: bool) {
        self.collector.shipped = on;
    }

    /// Ends later runs early once `interrupt` is raised on any rank: at the first GVT round
    /// that sees it, every worker agrees to end at the latest batch any of them has run.
    pub fn stop_on(&mut self, interrupt: Interrupt) {
        self.interrupt = Some(interrupt);
    }

    /// Runs every batch with time at most `until` optimistically on the workers; the sink sees
    /// each output, with the committed states just after its batch, in the sequential order
    /// (on rank 0 only, under MPI). Returns the time the run ended at: `until`, or an earlier
    /// one where an interrupt ([`TimeWarp::stop_on`]) ended it, every batch up to it run.
    pub fn run<E>(&mut self, until: f64, sink: &mut Sink<'_, M, E>) -> Result<f64, ExecError<E>> {
        // the collector keeps a copy where it shows the sink states or takes other ranks'
        self.hand_out(self.ranks == 1 && !self.collector.shipped);
        let (tx, rx) = mpsc::channel();
        let mut failed: Option<ExecError<E>> = None;
        self.collector.begin_run();
        if self.ranks == 1 {
            let fabric = ThreadFabric::<M>::new(self.workers.len(), tx);
            self.drive(&fabric, &rx, until, sink, &mut failed);
        } else {
            #[cfg(feature = "mpi")]
            {
                let rank = place().0;
                let fabric = super::mpi::MpiFabric::<M>::new(
                    rank,
                    self.ranks,
                    self.workers.len(),
                    (rank == 0).then_some(tx),
                );
                self.drive(&fabric, &rx, until, sink, &mut failed);
                // the last chunks of other ranks are still in parcels: one more exchange
                fabric.exchange();
                fabric.close_collector();
                let total = self.workers.len() * self.ranks;
                for chunk in rx.try_iter() {
                    self.collector
                        .take(&self.model, total, chunk, sink, &mut failed);
                }
            }
        }
        // the workers of the collecting process hand their final states over (and where
        // they moved from it, after a failed run too)
        if collects_results() && (failed.is_none() || self.collector.states().is_empty()) {
            self.hand_back();
        }
        if let Some(e) = failed {
            return Err(e);
        }
        // every worker of every rank ended at the same time; with none, the run ends at once
        let ended = self
            .workers
            .iter()
            .map(|w| w.ended_at)
            .fold(until, f64::min);
        self.now = ended.max(self.now);
        Ok(self.now)
    }

    /// Runs the workers on `fabric` until they stop, collecting what reaches `rx` meanwhile.
    fn drive<F: Fabric<M>, E>(
        &mut self,
        fabric: &F,
        rx: &mpsc::Receiver<ChunkOf<M>>,
        until: f64,
        sink: &mut Sink<'_, M, E>,
        failed: &mut Option<ExecError<E>>,
    ) {
        let total = self.workers.len() * self.ranks;
        let workers_here = self.workers.len();
        let stop = AtomicBool::new(false);
        let TimeWarp {
            model,
            workers,
            cfg,
            collector,
            interrupt,
            ..
        } = self;
        let model: &M = model;
        // the collector wakes every few milliseconds, and when the last worker ends: woken by
        // every chunk, it took a worker's core twice per GVT round on a machine with as many
        // cores as workers (2 workers with a gas of 10^5 disks to t = 0.5: median ratios 0.95-1.00 in
        // three sets of 10 pairs)
        let (finished, main) = (AtomicUsize::new(0), std::thread::current());
        std::thread::scope(|scope| {
            let mut handles = Vec::with_capacity(workers.len());
            for w in workers.iter_mut() {
                let (cfg, ship) = (&*cfg, collector.shipped);
                let halt = Halt {
                    failed: &stop,
                    interrupt: interrupt.as_ref(),
                };
                let (finished, main) = (&finished, &main);
                handles.push(scope.spawn(move || {
                    let abandon = || fabric.abandon();
                    let _end = WorkerEnd {
                        count: finished,
                        collector: main,
                        abandon: &abandon,
                    };
                    w.run(model, fabric, cfg, until, ship, halt)
                }));
            }
            loop {
                // read before the drain: every chunk of a worker counted as ended is in the
                // channel by then, so the drain after the last count leaves none behind
                let done = finished.load(Ordering::Acquire) == workers_here;
                for chunk in rx.try_iter() {
                    collector.take(model, total, chunk, sink, failed);
                }
                if failed.is_some() {
                    stop.store(true, Ordering::Relaxed);
                }
                if done {
                    break;
                }
                std::thread::park_timeout(COLLECTOR_NAP);
            }
            // a worker's panic reaches the caller as it was raised
            for h in handles {
                if let Err(panic) = h.join() {
                    std::panic::resume_unwind(panic);
                }
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::super::thread_fabric::{ThreadReduce, NOTHING};
    use super::super::{Bounds, Chunk, Floor, Reduction};
    use super::*;
    use crate::time_warp::Committed;
    use crate::PlainTime;
    use crate::{Ctx, Envelope};

    /// Objects whose state is a number; nothing is ever sent.
    struct Numbers;

    impl Model for Numbers {
        type Time = PlainTime;
        type Msg = ();
        type State = u32;
        type Output = ();
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
        fn init(&self, _: &mut Ctx<'_, Self>, _: u32, _: &mut u32) {}
        fn handle(&self, _: &mut Ctx<'_, Self>, _: u32, _: &mut u32, _: &[Envelope<()>]) {}
    }

    fn chunk(
        worker: usize,
        round: u64,
        batches: Vec<Committed<PlainTime, u32, ()>>,
    ) -> Chunk<PlainTime, u32, ()> {
        Chunk {
            worker,
            round,
            batches,
            last: None,
            finals: Vec::new(),
            error: None,
            progress: Default::default(),
            open: Floor::INFINITY,
        }
    }

    /// A worker's last chunk of a run, with its objects' final states.
    fn last_chunk(worker: usize, finals: Vec<(u32, u32)>) -> Chunk<PlainTime, u32, ()> {
        Chunk {
            last: Some((TwStats::default(), MessageStats::default(), 0)),
            finals,
            ..chunk(worker, u64::MAX, Vec::new())
        }
    }

    fn at(t: f64) -> VTime<PlainTime> {
        VTime::start(t)
    }

    #[test]
    fn a_round_one_worker_is_due_brings_every_worker() {
        let (tx, _rx) = mpsc::channel();
        let f: ThreadFabric<Numbers> = ThreadFabric::new(3, tx);
        assert!(!f.round_due(1, 0, false), "nobody asked yet");
        assert!(f.round_due(0, 0, true));
        assert!(f.round_due(1, 0, false) && f.round_due(2, 0, false));
        // once a worker has had that round, it waits for the next one asked
        assert!(!f.round_due(1, 1, false));
        assert!(f.round_due(2, 1, true));
        assert!(f.round_due(0, 1, false) && !f.round_due(0, 2, false));
    }

    #[test]
    fn every_worker_hears_of_a_sweep_one_of_them_wants() {
        let reduce = ThreadReduce::new(3);
        let wants = [0u64, 1, 0];
        let heard: Vec<Reduction> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..3)
                .map(|me| {
                    let reduce = &reduce;
                    s.spawn(move || {
                        // two rounds: the second, in which nobody wants one, says so
                        let first = reduce.reduce(
                            me,
                            Reduction {
                                sweep: wants[me],
                                floor: Floor::start(me as f64),
                                ..NOTHING
                            },
                        );
                        let second = reduce.reduce(me, NOTHING);
                        assert_eq!(second.sweep, 0, "a sweep is asked for one round");
                        first
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        for r in heard {
            assert_eq!(r.sweep, 1);
            assert_eq!(r.floor, Floor::start(0.0));
        }
    }

    #[test]
    fn a_floor_covers_what_workers_hold_and_what_waits_in_inboxes() {
        let (tx, _rx) = mpsc::channel();
        let f: ThreadFabric<Numbers> = ThreadFabric::new(3, tx);
        assert!(Fabric::shares_floors(&f));
        let any = |me| f.peers_floor(me, 0.0).map(|b| b.any);
        let messages = |me| f.peers_floor(me, 0.0).map(|b| b.messages);
        // a worker that has published nothing covers nothing
        assert_eq!(any(0), Some(Floor::NEG_INFINITY));
        f.publish(0, Floor::start(9.0));
        f.publish(1, Floor::start(5.0));
        f.publish(2, Floor::start(7.0));
        assert_eq!(any(0), Some(Floor::start(5.0)));
        // messages come a generation after the lowest floor at the earliest
        let next = Floor::start(5.0).next_generation();
        assert_eq!(messages(0), Some(next));
        // or, in a model with a lookahead, at the lowest floor plus the lookahead
        let ahead = f.peers_floor(0, 0.25).expect("floors");
        assert_eq!(
            (ahead.any, ahead.messages),
            (Floor::start(5.0), Floor::start(5.25))
        );
        assert!(next > Floor::start(5.0) && !next.passed(&at(5.0).next_gen(), 0));
        assert_eq!(
            any(1),
            Some(Floor::start(7.0)),
            "a worker's own floor is not its bound"
        );
        // worker 1 sends worker 2 an op at t = 3, then moves on: the inbox holds the bound down
        let anti = |t: f64| Op::Anti {
            uid: 1,
            to: 9,
            time: at(t),
        };
        f.send(1, 2, vec![anti(3.0)]);
        f.publish(1, Floor::start(8.0));
        assert_eq!(any(0), Some(Floor::of(&at(3.0), 9)));
        assert_eq!(messages(0), Some(Floor::of(&at(3.0), 9).next_generation()));
        // worker 2 takes it: its own floor drops to the op's until it publishes again
        let mut got = Vec::new();
        f.recv(2, &mut got);
        assert_eq!(got.len(), 1);
        assert_eq!(any(0), Some(Floor::of(&at(3.0), 9)));
        f.publish(2, Floor::start(6.0));
        assert_eq!(any(0), Some(Floor::start(6.0)));
        // an op waiting for the asking worker itself bounds it too
        f.send(2, 0, vec![anti(4.0)]);
        assert_eq!(any(0), Some(Floor::of(&at(4.0), 9)));
        assert_eq!(
            messages(0),
            Some(Floor::of(&at(4.0), 9)),
            "an op waiting for the asking worker bounds it where it is"
        );
        // with a lookahead, it still does
        let ahead = f.peers_floor(0, 0.5).expect("floors");
        assert_eq!(ahead.messages, Floor::of(&at(4.0), 9));
        // for another worker, the op waiting for worker 0 moves by the lookahead: worker 0
        // sends from its time plus the lookahead on
        let ahead = f.peers_floor(2, 0.5).expect("floors");
        assert_eq!(ahead.any, Floor::of(&at(4.0), 9));
        assert_eq!(ahead.messages, Floor::start(4.5));
    }

    /// The threads' fabric, but claiming that nothing can ever come: every batch runs final.
    struct Liar<M: Model>(ThreadFabric<M>);

    impl<M: Model> Fabric<M> for Liar<M>
    where
        M::Msg: Send,
        M::State: Send,
        M::Output: Send,
    {
        fn send(&self, from: usize, to: usize, ops: Vec<Op<M::Time, M::Msg>>) {
            self.0.send(from, to, ops);
        }
        fn recv(&self, me: usize, into: &mut Vec<Op<M::Time, M::Msg>>) {
            self.0.recv(me, into);
        }
        fn reduce(&self, me: usize, local: Reduction) -> Reduction {
            self.0.reduce(me, local)
        }
        fn commit(&self, chunk: Chunk<M::Time, M::State, M::Output>) {
            self.0.commit(chunk);
        }
        fn shares_floors(&self) -> bool {
            true
        }
        fn peers_floor(&self, _: usize, _: f64) -> Option<Bounds> {
            Some(Bounds {
                any: Floor::INFINITY,
                messages: Floor::INFINITY,
            })
        }
    }

    #[test]
    fn an_op_below_a_final_batch_stops_the_run() {
        use crate::phold::{Phold, PholdConfig};
        let cfg = PholdConfig {
            objects: 96,
            events_per_object: 4,
            remote: 0.3,
            partitions: 2,
            lookahead: 0.0,
            mean: 1.0,
            seed: 11,
        };
        let (model, states) = Phold::new(cfg);
        let worker_of: Vec<u32> = (0..96).map(|o| model.partition(o)).collect();
        let tw_cfg = TwConfig {
            workers: 2,
            chaos: Some(5),
            ..TwConfig::default()
        };
        let mut tw = TimeWarp::new(model, states, at(0.0), &ObjectMap::Given(worker_of), tw_cfg);
        let (tx, rx) = mpsc::channel();
        let liar = Liar(ThreadFabric::new(2, tx));
        let mut failed: Option<ExecError<()>> = None;
        tw.hand_out(true);
        tw.drive(&liar, &rx, 30.0, &mut |_, _, _| Ok(()), &mut failed);
        match failed {
            Some(ExecError::Failed(m)) => assert!(m.contains("ran as final"), "{m}"),
            other => panic!("a lying fabric went unnoticed: {other:?}"),
        }
    }

    #[test]
    fn final_states_wait_for_the_last_round() {
        let mut c: Collector<Numbers> = Collector::new(vec![0, 0]);
        let mut seen = Vec::new();
        let mut failed = None;
        let mut sink = |_: &Numbers, states: &[u32], (): ()| {
            seen.push(states.to_vec());
            Ok::<(), ()>(())
        };
        let at = |obj, state: u32, output| Committed {
            time: VTime::start(1.0),
            obj,
            state: Some(state),
            output,
            times: Vec::new(),
        };
        // worker 0 commits object 0's batch in round 1 and finishes (object 0 ends at 9) before
        // worker 1's chunk of round 1, whose batch of object 1 reports an output, arrives
        c.take(
            &Numbers,
            2,
            chunk(0, 1, vec![at(0, 5, vec![])]),
            &mut sink,
            &mut failed,
        );
        c.take(
            &Numbers,
            2,
            last_chunk(0, vec![(0, 9)]),
            &mut sink,
            &mut failed,
        );
        c.take(
            &Numbers,
            2,
            chunk(1, 1, vec![at(1, 7, vec![()])]),
            &mut sink,
            &mut failed,
        );
        c.take(
            &Numbers,
            2,
            last_chunk(1, vec![(1, 8)]),
            &mut sink,
            &mut failed,
        );
        assert!(failed.is_none());
        assert_eq!(
            seen,
            vec![vec![5, 7]],
            "the output saw the states of its round"
        );
        assert_eq!(c.states(), &[9, 8], "and the final states came after it");
    }

    #[test]
    fn a_run_taken_up_again_ends_where_one_run_ends() {
        use crate::phold::{Phold, PholdConfig};
        use crate::sequential::Sequential;
        let cfg = PholdConfig {
            objects: 64,
            events_per_object: 4,
            remote: 0.3,
            partitions: 2,
            lookahead: 0.0,
            mean: 1.0,
            seed: 3,
        };
        let (model, states) = Phold::new(cfg.clone());
        let mut seq = Sequential::new(model, states, at(0.0));
        seq.run::<()>(20.0, &mut |_, _, _| Ok(())).unwrap();
        let (model, states) = Phold::new(cfg);
        let worker_of: Vec<u32> = (0..64).map(|o| model.partition(o)).collect();
        let tw_cfg = TwConfig {
            workers: 2,
            ..TwConfig::default()
        };
        let mut tw = TimeWarp::new(model, states, at(0.0), &ObjectMap::Given(worker_of), tw_cfg);
        tw.run::<()>(7.0, &mut |_, _, _| Ok(())).unwrap();
        let halfway: Vec<u64> = tw.states().iter().map(|s| s.handled).collect();
        assert!(halfway.iter().sum::<u64>() > 0, "the first leg ran");
        // the workers handed their states to the collector and take them back to go on
        tw.run::<()>(20.0, &mut |_, _, _| Ok(())).unwrap();
        let json = |s| serde_json::to_string(s).unwrap();
        assert_eq!(json(seq.states()), json(tw.states()));
        let handled: Vec<u64> = tw.states().iter().map(|s| s.handled).collect();
        assert_ne!(halfway, handled, "the second leg ran");
    }

    /// Objects on alternating workers that pass tokens on with zero delay through the
    /// generations of instant 0. In the first generation each also leaves a message that can be
    /// cancelled for an object of the other worker, two generations later, and wakes itself for
    /// that generation, where a third of them cancel theirs: cancellations of messages of the
    /// cancelling batch's own virtual time, beside batches of messages no one can cancel, which
    /// run as final against the other workers' next generation.
    struct Relay;

    const RELAYS: u32 = 48;

    impl Model for Relay {
        type Time = PlainTime;
        type Msg = u64;
        type State = (u64, Option<crate::Handle>);
        type Output = ();
        type Undo = ();

        fn kind_names(&self) -> &'static [&'static str] {
            &["Pass"]
        }
        fn kind(&self, _: &u64) -> usize {
            0
        }
        fn priority(&self, _: &u64) -> u8 {
            0
        }
        fn init(&self, ctx: &mut Ctx<'_, Self>, me: u32, _: &mut Self::State) {
            ctx.send_now((me + 1) % RELAYS, u64::from(me));
        }
        fn handle(
            &self,
            ctx: &mut Ctx<'_, Self>,
            me: u32,
            state: &mut Self::State,
            batch: &[Envelope<u64>],
        ) {
            for e in batch {
                state.0 = state
                    .0
                    .wrapping_mul(31)
                    .wrapping_add(e.msg ^ u64::from(e.from));
            }
            let now = ctx.now().clone();
            if now.gen == 1 {
                let later = VTime {
                    key: now.key,
                    gen: 3,
                };
                // to a higher-numbered object of the other worker, so that its batch of
                // generation 3 comes after this object's
                let to = (me + 3).min(RELAYS - 1 - me % 2);
                state.1 = Some(ctx.send_at(to, later, 1000 + u64::from(me)));
            }
            if now.gen == 2 {
                ctx.send_now(me, 0);
            }
            if now.gen == 3 && me.is_multiple_of(3) {
                if let Some(h) = state.1.take() {
                    ctx.cancel(h);
                }
            }
            if now.gen < 6 {
                ctx.send_now((me * 5 + 1) % RELAYS, state.0 & 0xffff);
            }
        }
    }

    #[test]
    fn cancellations_within_an_instant_beside_batches_run_as_final_by_generation() {
        use crate::sequential::Sequential;
        let states = vec![(0, None); RELAYS as usize];
        let mut seq = Sequential::new(Relay, states.clone(), at(0.0));
        seq.run::<()>(1.0, &mut |_, _, _| Ok(())).unwrap();
        let want: Vec<u64> = seq.states().iter().map(|s| s.0).collect();
        for workers in [2, 3] {
            for chaos in [None, Some(7), Some(8)] {
                let cfg = TwConfig {
                    workers: workers as usize,
                    chaos,
                    ..TwConfig::default()
                };
                let map = ObjectMap::RoundRobin;
                let mut tw = TimeWarp::new(Relay, states.clone(), at(0.0), &map, cfg);
                tw.run::<()>(1.0, &mut |_, _, _| Ok(())).unwrap();
                let got: Vec<u64> = tw.states().iter().map(|s| s.0).collect();
                let what = format!("{workers} workers, chaos {chaos:?}");
                assert_eq!(got, want, "{what}");
                assert_eq!(tw.stats(), seq.stats(), "{what}");
                assert_eq!(tw.tw_stats().committed, seq.stats().batches, "{what}");
            }
        }
    }

    /// Objects that each wake themselves every unit of time; object 3's handler panics at
    /// time 5, while the other worker goes on.
    struct Faulty;

    impl Model for Faulty {
        type Time = PlainTime;
        type Msg = ();
        type State = u32;
        type Output = ();
        type Undo = ();

        fn kind_names(&self) -> &'static [&'static str] {
            &["Tick"]
        }
        fn kind(&self, _: &()) -> usize {
            0
        }
        fn priority(&self, _: &()) -> u8 {
            0
        }
        fn init(&self, ctx: &mut Ctx<'_, Self>, me: u32, _: &mut u32) {
            ctx.relay_at(me, at(1.0), ());
        }
        fn handle(&self, ctx: &mut Ctx<'_, Self>, me: u32, n: &mut u32, _: &[Envelope<()>]) {
            *n += 1;
            assert!(me != 3 || *n < 5, "object 3 is broken");
            ctx.relay_at(me, at(f64::from(*n) + 1.0), ());
        }
    }

    #[test]
    #[should_panic(expected = "object 3 is broken")]
    fn a_panic_on_a_worker_reaches_the_caller_instead_of_stopping_the_others() {
        let cfg = TwConfig {
            workers: 2,
            gvt_interval: Some(1),
            ..TwConfig::default()
        };
        let map = ObjectMap::RoundRobin;
        let mut tw = TimeWarp::new(Faulty, vec![0; 6], at(0.0), &map, cfg);
        let _ = tw.run::<()>(1e6, &mut |_, _, _| Ok(()));
    }
}
