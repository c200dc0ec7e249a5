//! Time Warp's settings, its limits, and the statistics it reports.

/// The deepest time ([`Time::depth`](crate::Time::depth): a cascade of zero-delay steps at one instant) Time Warp
/// runs: its GVT does not tell times apart past a few words of their tie-break, so an instant
/// this deep cannot commit, and one that never ends would fill memory.
pub const MAX_CASCADE_DEPTH: usize = 1_000;

/// Batches between GVT rounds in one process, unless set.
pub const THREADS_GVT_INTERVAL: u32 = 2048;

/// Batches between GVT rounds across MPI ranks, unless set: ops for another rank travel only
/// at rounds, so the interval is also their delay, and a long one makes stragglers. On 2 ranks
/// on loopback (1 worker each; a hard-disk gas relayed through sectors), 2,048 against 256: 400
/// disks, efficiency 0.37 against 0.67 and 0.18 s against 0.09; 9,801 disks to t = 2, 0.97
/// against 0.99 and 0.94 s against 0.67; 10^5 disks to t = 0.2, the same (0.98 s).
pub const ACROSS_RANKS_GVT_INTERVAL: u32 = 256;

/// Time Warp's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwConfig {
    /// Worker threads (per rank under MPI).
    pub workers: usize,
    /// Seed of chaos mode: deliveries delayed and reordered at random to force rollbacks.
    pub chaos: Option<u64>,
    /// Batches a worker runs between GVT rounds; `None` for the default of where it runs
    /// ([`TwConfig::interval`]).
    pub gvt_interval: Option<u32>,
    /// Optimism window: no batch later than GVT plus this (simulation time), or the least floor
    /// the workers publish plus this where they publish floors; `None` adapts it
    /// to the GVT progress of one batch per message waiting on the worker (1,024 to 8,192
    /// batches) at the recent rate, narrowed while many batches roll back.
    pub window: Option<f64>,
    /// Uncommitted batches a worker may hold before it rolls its furthest objects back and
    /// runs only batches at GVT; past four times this, the run stops with an error.
    pub max_uncommitted: usize,
    /// Whether a batch before every op the other workers may still send runs as final: without
    /// saving its object's state, committed at once (see [`Fabric::peers_floor`](super::Fabric::peers_floor)).
    pub final_batches: bool,
    /// Batches a worker runs between looks at its inbox and publications of its floor;
    /// `None` for [`DEFAULT_BURST`] (or [`PURE_BURST`] without final batches); never more than
    /// the GVT interval.
    pub burst: Option<u32>,
    /// Whether the collector keeps a [`RoundRecord`] of every GVT round
    /// ([`TimeWarp::round_records`](super::threads::TimeWarp::round_records)).
    pub record_rounds: bool,
}

/// What every worker had done by the end of one GVT round (kept with
/// [`TwConfig::record_rounds`]): statistics over time.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RoundRecord {
    /// The round, from 1.
    pub round: u64,
    /// GVT's simulation time after it.
    pub gvt: f64,
    /// Seconds since the run started, as the slowest worker to reach the round saw it.
    pub wall_s: f64,
    /// Each worker's counts from the start of the run, in worker order.
    pub workers: Vec<super::Progress>,
}

impl RoundRecord {
    /// The record of round `round` from every worker's chunk of it.
    pub fn of<T, S, O>(round: u64, chunks: &[super::Chunk<T, S, O>]) -> RoundRecord {
        let mut workers: Vec<(usize, super::Progress)> =
            chunks.iter().map(|c| (c.worker, c.progress)).collect();
        workers.sort_by_key(|&(w, _)| w);
        let workers: Vec<super::Progress> = workers.into_iter().map(|(_, p)| p).collect();
        RoundRecord {
            round,
            gvt: workers.first().map_or(f64::NAN, |p| p.gvt),
            wall_s: workers.iter().map(|p| p.wall_s).fold(0.0, f64::max),
            workers,
        }
    }
}

/// Batches a worker runs between looks at its inbox, with final batches on. Each look and each
/// publication of the worker's floor moves cache lines between cores: PHOLD at 16,384 objects
/// on 16 workers took 0.41 s with 128 against 0.55 s with 8 (0.48 s with 32, 0.43 s with 512);
/// on 2 workers 128 and 8 are within a few per cent, and the 10^5-disk gas is the same with
/// either.
pub const DEFAULT_BURST: u32 = 128;
/// Batches a worker runs between looks at its inbox when no batch runs as final.
pub const PURE_BURST: u32 = 64;

impl TwConfig {
    /// Batches between GVT rounds on `ranks` MPI ranks: as set, else
    /// [`THREADS_GVT_INTERVAL`] in one process and [`ACROSS_RANKS_GVT_INTERVAL`] across ranks.
    pub fn interval(&self, ranks: usize) -> u32 {
        self.gvt_interval.unwrap_or(if ranks > 1 {
            ACROSS_RANKS_GVT_INTERVAL
        } else {
            THREADS_GVT_INTERVAL
        })
    }
}

impl Default for TwConfig {
    fn default() -> TwConfig {
        TwConfig {
            workers: 1,
            chaos: None,
            gvt_interval: None,
            window: None,
            max_uncommitted: 1 << 21,
            final_batches: true,
            burst: None,
            record_rounds: false,
        }
    }
}

/// What Time Warp did, summed over workers (the run summary's `time_warp` object).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TwStats {
    /// Workers in all.
    pub workers: u64,
    /// MPI ranks (1 on threads).
    pub ranks: u64,
    /// Batches run, rolled-back ones included.
    pub processed: u64,
    /// Batches committed.
    pub committed: u64,
    /// Of them, batches run as final: before every op another worker could still send, so
    /// without saving state (counted in `processed` too).
    pub final_batches: u64,
    /// Of them, batches run as final only because no message could still reach them: none of
    /// their messages can be cancelled, and every other worker stood at their virtual time or
    /// later, so that its sends come at least a generation after them.
    pub final_uncancellable: u64,
    /// Of the others, batches committed between GVT rounds, as soon as nothing could undo
    /// them any more.
    pub committed_early: u64,
    /// Batches undone by rollbacks.
    pub rolled_back: u64,
    /// Rollbacks (one object rolled back once).
    pub rollbacks: u64,
    /// Of them, rollbacks a worker made itself to free memory.
    pub artificial_rollbacks: u64,
    /// Batches cut back to one of their own events they ran on to ([`Ctx::may_run`](crate::Ctx::may_run)),
    /// for a message that came inside their span, instead of being undone whole.
    pub cuts: u64,
    /// An object's own events that batches ran on to, undone ones included.
    pub ran_on: u64,
    /// Of them, events undone by a cut or a rollback.
    pub ran_on_undone: u64,
    /// Batches taken in after a batch of their object that ran past them
    /// ([`Model::take_in`](crate::Model::take_in)), instead of cutting it back.
    pub taken_in: u64,
    /// Batches the model could not take in that way: their object was cut back for them.
    pub take_in_refused: u64,
    /// Messages sent to an object on another worker.
    pub remote_messages: u64,
    /// Messages sent in all (local and remote, rolled-back sends included).
    pub messages: u64,
    /// Anti-messages sent.
    pub anti_messages: u64,
    /// GVT rounds.
    pub gvt_rounds: u64,
    /// The most uncommitted batches (saved states) one worker held at once.
    pub peak_uncommitted: u64,
    /// The most messages (entries) one worker held at once.
    pub peak_entries: u64,
    /// The most messages plus saved states one worker held after a GVT round, over the first
    /// half of the run's rounds past warm-up (the first tenth).
    pub held_early: u64,
    /// The same over the second half: about `held_early` when fossil collection keeps memory
    /// flat.
    pub held_late: u64,
}

impl TwStats {
    /// Committed over processed batches.
    pub fn efficiency(&self) -> f64 {
        if self.processed == 0 {
            1.0
        } else {
            self.committed as f64 / self.processed as f64
        }
    }

    /// Adds another worker's counts (peaks take the maximum).
    pub fn add(&mut self, o: &TwStats) {
        self.workers += o.workers;
        self.processed += o.processed;
        self.committed += o.committed;
        self.final_batches += o.final_batches;
        self.final_uncancellable += o.final_uncancellable;
        self.committed_early += o.committed_early;
        self.rolled_back += o.rolled_back;
        self.rollbacks += o.rollbacks;
        self.artificial_rollbacks += o.artificial_rollbacks;
        self.cuts += o.cuts;
        self.ran_on += o.ran_on;
        self.ran_on_undone += o.ran_on_undone;
        self.taken_in += o.taken_in;
        self.take_in_refused += o.take_in_refused;
        self.remote_messages += o.remote_messages;
        self.messages += o.messages;
        self.anti_messages += o.anti_messages;
        self.gvt_rounds = self.gvt_rounds.max(o.gvt_rounds);
        self.peak_uncommitted = self.peak_uncommitted.max(o.peak_uncommitted);
        self.peak_entries = self.peak_entries.max(o.peak_entries);
        self.held_early = self.held_early.max(o.held_early);
        self.held_late = self.held_late.max(o.held_late);
    }
}
