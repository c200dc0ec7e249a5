//! The Time Warp executor (Jefferson 1985): the kernel's objects run
//! optimistically in parallel and commit exactly the sequential executor's batches.
//!
//! ```text
//!   worker 0                         worker 1
//!   ┌───────────────────────┐  ops   ┌───────────────────────┐
//!   │ objects (LPs): state; │ ─────► │ heap of messages not  │
//!   │ log of uncommitted    │ ◄───── │ handled yet; marks by │
//!   │ batches, saved states │        │ uid: anti, cancelled  │
//!   └───────────┬───────────┘        └───────────┬───────────┘
//!               └──── GVT round (reduce) ────────┘──► committed chunks ─► collector ─► sink
//! ```
//!
//! Each worker owns a set of objects and runs, one batch at a time, the lowest virtual time it
//! holds, without waiting for the others. A message that arrives in an object's past (a
//! straggler) rolls that object back: its saved states are restored (copy state saving) and
//! everything the undone batches sent is retracted by anti-messages (aggressive cancellation).
//!
//! Transport names every message by a `uid` that is never reused (the sender's object index and
//! a counter that is not rolled back). A message is in one place at a time: on its way, in its
//! worker's heap, in the batch that handled it (a rollback puts it back in the heap), or set
//! aside while cancelled. An anti-message, or a model-level cancellation (`Ctx::cancel`) and its
//! undoing, is a mark on the uid that the worker reads when the message reaches the top of its
//! heap or arrives, whatever the order of arrival (`marks.rs`); most messages are never marked,
//! and the sequential executor's cost per message is one heap item too. Every change of
//! liveness in an object's past rolls the object back to it.
//!
//! A model cancels only messages still to come after the cancelling batch (the kernel's
//! contract, [`Ctx::cancel`](crate::Ctx::cancel)). A handle keeps the message's simulation time, not its key: a
//! cancellation of a message of an earlier instant does nothing, and one of the cancelling
//! batch's own instant is taken at its word.
//!
//! A batch that comes before every op any other worker may still send its worker is final
//! already: it runs without saving its object's state and commits at once (with the object's
//! earlier batches), its output waiting for the first GVT round that passes it. Workers on
//! threads publish floors for this ([`Fabric::peers_floor`]); across MPI ranks, each GVT round
//! that ends with nothing in flight tells every rank the others' floors (the `mpi` module).
//! Running such safe events without optimistic bookkeeping is the idea of protocols that mix
//! conservative and optimistic execution event by event (Jha and Bagrodia, "A unified framework
//! for conservative and optimistic distributed simulation", PADS 1994; Jefferson and Barnes,
//! "Virtual Time III", ACM TOMACS 32(4), 2022). With one worker every batch is final.
//!
//! GVT (global virtual time) is found in synchronous rounds, as ROSS does: workers stop
//! processing, drain their inboxes until a reduction says every op sent has been received,
//! then reduce the first (virtual time, receiver) they still hold a message for, a [`Floor`]:
//! batches before it are committed, within an instant too:
//! their output goes, in (virtual time, object) order, to the collector, and their saved states
//! are freed (fossil collection). The transport and the reductions are a [`Fabric`]: threads
//! ([`threads`]) or MPI ranks.
//!
//! On threads, a round starts when any worker has run a GVT interval of batches, for all of
//! them at once ([`Fabric::round_due`]): a worker that runs mostly final batches, which cost
//! less, would otherwise wait at every round for the others to run as many. What bounds a
//! worker that runs ahead instead is its count of uncommitted batches: past two intervals'
//! worth (across ranks, at least two of the threads' default interval) it runs only final
//! batches until a round commits some.

#[cfg(feature = "mpi")]
pub mod mpi;
pub mod thread_fabric;
pub mod threads;

mod collector;
mod config;
mod fabric;
mod floor;
mod log;
mod map;
mod marks;
mod window;
mod worker;

pub use collector::Collector;
pub use config::{
    RoundRecord, TwConfig, TwStats, ACROSS_RANKS_GVT_INTERVAL, DEFAULT_BURST, MAX_CASCADE_DEPTH,
    PURE_BURST, THREADS_GVT_INTERVAL,
};
pub use fabric::{Bounds, Chunk, Committed, CommittedOf, Fabric, Op, OpOf, Progress, Reduction};
pub use floor::Floor;
pub use map::ObjectMap;
pub use worker::{Halt, Placement, Stop, Worker};
