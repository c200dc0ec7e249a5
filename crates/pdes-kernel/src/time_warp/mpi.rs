//! Time Warp across MPI ranks (cargo feature `mpi`): each rank runs its workers as threads,
//! and ranks exchange ops and committed chunks in bulk at every reduction of a GVT round.
//!
//! ```text
//!   rank 0: workers 0..N ─┐ intra-rank reduce ─► worker 0 of the rank: all-to-all of parcels,
//!   rank 1: workers N..2N ┘                      then all-reduce of the GVT values (MPI)
//! ```
//!
//! Within a rank, ops go through shared inboxes at once; ops for another rank wait in a
//! parcel until the next reduction, where an `MPI_Alltoallv` delivers every parcel. The
//! reduction's op counting (ROSS's approach) sees ops in parcels as in flight, so GVT is exact
//! whatever the delay. Committed chunks of other ranks travel the same way to rank 0, whose
//! collector feeds the sink. Only the first thread of a rank calls MPI, and never two at once
//! (MPI is initialized with `Threading::Serialized`); no other network layer is involved.
//!
//! Batches run as final across ranks too. A round that ends with nothing in flight gives every
//! rank the others' floors: between two exchanges a rank receives nothing from the others, so
//! nothing it sends until the next one comes before its floor at that round. Below those
//! floors, and below every op this rank has put in a parcel since, no op from another rank can
//! come (the same reasoning as a thread's floor, with a round for an instant). This rests on
//! two facts of the protocol: ops cross ranks only at the exchanges inside reductions, and no
//! worker runs a batch between the first exchange of a round and the round's end (each stays
//! in the round until nothing is in flight). A change to either, such as sending ops between
//! rounds, breaks the bound.

use super::thread_fabric::{Slots, ThreadReduce, NOTHING};
use super::{Bounds, Chunk, Fabric, Floor, Op, Reduction};
use crate::spin_barrier::SpinBarrier;
use crate::{Model, Time};
use mpi::collective::SystemOperation;
use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::sync::{mpsc, Mutex};

/// The smallest of every rank's floor, and of every other rank's than this one's: each rank's
/// words gathered, the minimum taken alike on every rank.
fn all_min(world: &SimpleCommunicator, here: Floor) -> (Floor, Floor) {
    let words = here.to_words();
    let mut all = vec![0u64; words.len() * world.size() as usize];
    world.all_gather_into(&words[..], &mut all[..]);
    let me = world.rank() as usize;
    all.chunks(words.len())
        .map(Floor::from_words)
        .enumerate()
        .fold(
            (Floor::INFINITY, Floor::INFINITY),
            |(all, others), (r, f)| (all.min(f), if r == me { others } else { others.min(f) }),
        )
}

/// What bounds the ops of other ranks for this rank's workers.
struct Far {
    /// The other ranks' smallest floor at the last round that ended with nothing in flight.
    ranks: Floor,
    /// The smallest op this rank's workers put in a parcel since that round.
    parcels: Floor,
}

/// This process's place among the MPI ranks: `(rank, ranks)`, or `(0, 1)` when MPI is not
/// initialized.
pub fn place() -> (usize, usize) {
    if !mpi::environment::is_initialized() || mpi::environment::is_finalized() {
        return (0, 1);
    }
    let world = SimpleCommunicator::world();
    (world.rank() as usize, world.size() as usize)
}

/// What travels between ranks.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(bound(
    serialize = "T: Time, Msg: Serialize, S: Serialize, O: Serialize",
    deserialize = "T: Time, Msg: DeserializeOwned, S: DeserializeOwned, O: DeserializeOwned"
))]
enum Parcel<T, Msg, S, O> {
    /// Ops for global worker `.0`.
    Ops(usize, Vec<Op<T, Msg>>),
    /// A committed chunk for rank 0's collector.
    Chunk(Box<Chunk<T, S, O>>),
}

type ChunkOf<M> = Chunk<<M as Model>::Time, <M as Model>::State, <M as Model>::Output>;

type ParcelOf<M> =
    Parcel<<M as Model>::Time, <M as Model>::Msg, <M as Model>::State, <M as Model>::Output>;

/// The workers of this rank, and the way to the others.
pub struct MpiFabric<M: Model> {
    rank: usize,
    ranks: usize,
    per_rank: usize,
    slots: Slots<M::Time, M::Msg>,
    far: Mutex<Far>,
    outgoing: Mutex<Vec<Vec<ParcelOf<M>>>>,
    reduce: ThreadReduce,
    barrier: SpinBarrier,
    result: Mutex<Reduction>,
    collector: Mutex<Option<mpsc::Sender<ChunkOf<M>>>>,
}

impl<M: Model> MpiFabric<M>
where
    M::Msg: Serialize + DeserializeOwned,
    M::State: Serialize + DeserializeOwned,
    M::Output: Serialize + DeserializeOwned,
{
    /// The fabric of rank `rank` of `ranks`, with `per_rank` workers each; rank 0 passes the
    /// collector's channel.
    pub fn new(
        rank: usize,
        ranks: usize,
        per_rank: usize,
        collector: Option<mpsc::Sender<ChunkOf<M>>>,
    ) -> Self {
        MpiFabric {
            rank,
            ranks,
            per_rank,
            slots: Slots::new(per_rank),
            // nothing is known of the others before the first round
            far: Mutex::new(Far {
                ranks: Floor::NEG_INFINITY,
                parcels: Floor::INFINITY,
            }),
            outgoing: Mutex::new((0..ranks).map(|_| Vec::new()).collect()),
            reduce: ThreadReduce::new(per_rank),
            barrier: SpinBarrier::new(per_rank),
            result: Mutex::new(NOTHING),
            collector: Mutex::new(collector),
        }
    }

    fn local(&self, worker: usize) -> Option<usize> {
        (worker / self.per_rank == self.rank).then_some(worker % self.per_rank)
    }

    fn deliver(&self, parcel: ParcelOf<M>) {
        match parcel {
            Parcel::Ops(w, ops) => {
                let k = self.local(w).expect("parcels reach their rank");
                self.slots.send(k, ops);
            }
            Parcel::Chunk(c) => {
                if let Some(tx) = &*self.collector.lock().expect("no thread panicked") {
                    let _ = tx.send(*c);
                }
            }
        }
    }

    /// Delivers every waiting parcel to its rank: one all-to-all of counts, one of bytes. Every
    /// rank must call it the same number of times, from one thread at a time. Returns how many
    /// parcels of ops reached this rank.
    pub fn exchange(&self) -> usize {
        let world = SimpleCommunicator::world();
        let parcels = std::mem::replace(
            &mut *self.outgoing.lock().expect("no thread panicked"),
            (0..self.ranks).map(|_| Vec::new()).collect(),
        );
        // never an empty buffer: two empty vectors share a dangling address, which MPI would
        // take for an in-place exchange
        let mut send: Vec<u8> = Vec::with_capacity(64);
        let mut counts = vec![0i32; self.ranks];
        let mut displs = vec![0i32; self.ranks];
        for (r, ps) in parcels.iter().enumerate() {
            displs[r] = send.len() as i32;
            if !ps.is_empty() {
                bincode::serialize_into(&mut send, ps).expect("parcels serialize");
            }
            counts[r] = send.len() as i32 - displs[r];
        }
        let mut rcounts = vec![0i32; self.ranks];
        world.all_to_all_into(&counts[..], &mut rcounts[..]);
        let mut rdispls = vec![0i32; self.ranks];
        let mut total = 0i32;
        for r in 0..self.ranks {
            rdispls[r] = total;
            total += rcounts[r];
        }
        let mut recv = vec![0u8; (total as usize).max(1)];
        let mut ops = 0;
        world.all_to_all_varcount_into(
            &Partition::new(&send[..], &counts[..], &displs[..]),
            &mut PartitionMut::new(&mut recv[..], &rcounts[..], &rdispls[..]),
        );
        for r in 0..self.ranks {
            if rcounts[r] == 0 {
                continue;
            }
            let bytes = &recv[rdispls[r] as usize..(rdispls[r] + rcounts[r]) as usize];
            let ps: Vec<ParcelOf<M>> = bincode::deserialize(bytes).expect("parcels deserialize");
            for p in ps {
                ops += usize::from(matches!(p, Parcel::Ops(..)));
                self.deliver(p);
            }
        }
        ops
    }

    /// Stops handing chunks to the collector (its channel closes when the last sender goes).
    pub fn close_collector(&self) {
        self.collector.lock().expect("no thread panicked").take();
    }
}

impl<M: Model> Fabric<M> for MpiFabric<M>
where
    M::Msg: Serialize + DeserializeOwned + Send,
    M::State: Serialize + DeserializeOwned + Send,
    M::Output: Serialize + DeserializeOwned + Send,
{
    fn send(&self, _from: usize, to: usize, ops: Vec<Op<M::Time, M::Msg>>) {
        match self.local(to) {
            Some(k) => self.slots.send(k, ops),
            None => {
                // under a floor the others read before the sender publishes its own higher one
                let floor = Op::lowest(&ops);
                let mut far = self.far.lock().expect("no thread panicked");
                far.parcels = far.parcels.min(floor);
                drop(far);
                self.outgoing.lock().expect("no thread panicked")[to / self.per_rank]
                    .push(Parcel::Ops(to, ops));
            }
        }
    }

    fn recv(&self, me: usize, into: &mut Vec<Op<M::Time, M::Msg>>) {
        let k = self.local(me).expect("a worker of this rank");
        self.slots.recv(k, into);
    }

    fn abandon(&self) {
        self.reduce.poison();
        self.barrier.poison();
    }

    fn shares_floors(&self) -> bool {
        true
    }

    fn publish(&self, me: usize, floor: Floor) {
        let k = self.local(me).expect("a worker of this rank");
        self.slots.publish(k, floor);
    }

    fn peers_floor(&self, me: usize, lookahead: f64) -> Option<Bounds> {
        let k = self.local(me).expect("a worker of this rank");
        let (others, mine) = self.slots.peers(k)?;
        // read after the workers' floors: a parcel's op is under the far floor before its
        // sender raises its own
        let far = {
            let f = self.far.lock().expect("no thread panicked");
            f.ranks.min(f.parcels)
        };
        // what the other ranks send comes from their floors, or from ops sent them, on
        let peers = Bounds::of_peers(others, mine, lookahead);
        Some(Bounds {
            any: peers.any.min(far),
            messages: peers.messages.min(far.later_by(lookahead)),
        })
    }

    fn reduce(&self, me: usize, local: Reduction) -> Reduction {
        let k = self.local(me).expect("a worker of this rank");
        let here = self.reduce.reduce(k, local);
        if k == 0 {
            let delivered = self.exchange();
            let world = SimpleCommunicator::world();
            let mut g = here;
            world.all_reduce_into(&here.in_flight, &mut g.in_flight, SystemOperation::sum());
            let others;
            (g.floor, others) = all_min(&world, here.floor);
            if g.in_flight == 0 {
                assert_eq!(delivered, 0, "a round with nothing in flight moves no ops");
                // every op sent is in its receiver's floor now, the parcels' ones included
                *self.far.lock().expect("no thread panicked") = Far {
                    ranks: others,
                    parcels: Floor::INFINITY,
                };
            }
            // stop requests and sweep requests in one reduction
            let mut flags = [0u64; 2];
            world.all_reduce_into(
                &[here.stop, here.sweep][..],
                &mut flags[..],
                SystemOperation::sum(),
            );
            (g.stop, g.sweep) = (flags[0], flags[1]);
            world.all_reduce_into(&here.interrupt, &mut g.interrupt, SystemOperation::max());
            world.all_reduce_into(&here.latest, &mut g.latest, SystemOperation::max());
            *self.result.lock().expect("no thread panicked") = g;
        }
        if self.barrier.wait().is_err() {
            // a worker of this rank panicked: the others stop, and the panic reaches the caller
            return Reduction { stop: 1, ..NOTHING };
        }
        *self.result.lock().expect("no thread panicked")
    }

    fn collector_is_local(&self) -> bool {
        self.rank == 0
    }

    fn commit(&self, chunk: Chunk<M::Time, M::State, M::Output>) {
        if self.rank == 0 {
            self.deliver(Parcel::Chunk(Box::new(chunk)));
        } else {
            self.outgoing.lock().expect("no thread panicked")[0]
                .push(Parcel::Chunk(Box::new(chunk)));
        }
    }
}
