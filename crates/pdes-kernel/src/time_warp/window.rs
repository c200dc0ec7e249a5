//! The optimism window: how far past GVT a worker may run when no window is set, and how
//! rollbacks narrow a window that is set.

use super::config::TwStats;

/// Batches' worth of GVT progress the optimism window spans when none is set, for a worker
/// with `pending` messages waiting: one per message, at least 1,024 and at most 8,192.
///
/// Too narrow, and workers run out of work under the window and ask for rounds (on 16 cores,
/// on 16 workers: a hard-disk gas of 10^5 disks took 1,100-1,400 rounds and 0.40-0.48 s at 1,024, 350-590 rounds
/// and 0.37-0.44 s at 4,096 or 8,192; PHOLD with 16,384 objects 0.42-0.60 s at 1,024, 0.27-0.32
/// s at 8,192); too wide, and a small model runs far ahead only to roll back (a gas of 36 disks
/// on 2 workers of a 2-core machine, before the scale of [`AutoWindow`]: median efficiency 0.25
/// at 1,024, 0.12-0.14 at 4,096-8,192).
pub(super) fn window_span(pending: usize) -> f64 {
    (pending as f64).clamp(1024.0, 8192.0)
}

/// The optimism window when none is set (no `--tw-window`), in simulation time: GVT's progress
/// over [`window_span`] of this worker's batches, at the rate per batch seen since the window
/// last changed, times a scale that rollbacks narrow.
///
/// A rate per batch, not one round's advance: a worker out of work under the window asks for a
/// round at once, so a window of 4x the last advance collapsed on 12-16 workers, rounds coming
/// ever more often and each moving GVT ever less (on 16 cores, 14,000 rounds where 300-900
/// did, and 2-4x the time). The scale halves when a quarter or more of the worker's batches since
/// the last change were rolled back, down to 1/16, and doubles back to 1 when fewer were. An
/// event that a batch ran on to ([`Ctx::may_run`](crate::Ctx::may_run)) counts as a batch, and
/// as a batch rolled back when a cut or a rollback undoes it. With
/// the scale and the samples, a gas of 36 disks on 2 workers of a 2-core machine ran at median
/// efficiencies of 0.42 (relayed) and 0.44 (not) over 10 runs, against 0.21 and 0.27 without;
/// 9,801 disks on 8 and 16 workers sharing its 2 cores at 0.78 and 0.61-0.63, against 0.68
/// and 0.34 (the window of 4x the advance: 0.90 and 0.83, in 1,400-3,000 rounds).
///
/// A window that is set (`--tw-window`, or the regions engine's own) is multiplied by the same
/// scale: 2,000 balls driven into a cluster on the border of 2 regions on 2 workers (the
/// `implosion` built-in) ran 6.1 s instead of 58.8 s, 78,000 batches rolled back instead of
/// 1.7 million; a gas whose workers seldom roll back keeps its window whole.
pub(super) struct AutoWindow {
    /// The window; infinite until GVT first moves.
    pub(super) width: f64,
    /// What multiplies the window: 1, halved by rollbacks down to [`Self::MIN_SCALE`].
    pub(super) scale: f64,
    /// The worker's processed and rolled-back batches when the window last changed, and GVT's
    /// progress since.
    pub(super) processed: u64,
    pub(super) rolled_back: u64,
    pub(super) moved: f64,
}

impl AutoWindow {
    /// The smallest scale.
    const MIN_SCALE: f64 = 1.0 / 16.0;
    /// The fewest batches the worker runs between two changes of the window: a worker that
    /// ran only a few in a round (held off its core, say) would see a rate per batch far too
    /// high.
    const SAMPLE: u64 = 256;

    pub(super) fn new() -> Self {
        AutoWindow {
            width: f64::INFINITY,
            scale: 1.0,
            processed: 0,
            rolled_back: 0,
            moved: 0.0,
        }
    }

    /// Adapts the window after a round that moved GVT by `advance` (zero if it did not, or
    /// was not finite), with `pending` messages waiting on the worker and its counts in
    /// `stats`, once the worker has run [`Self::SAMPLE`] batches since the last change; the
    /// width grows at most twofold a change.
    pub(super) fn after_round(&mut self, advance: f64, pending: usize, stats: &TwStats) {
        self.moved += advance;
        // an event a batch ran on to counts as a batch of its own
        let (processed, rolled_back) = (
            stats.processed + stats.ran_on,
            stats.rolled_back + stats.ran_on_undone,
        );
        let ran = processed - self.processed;
        if ran < Self::SAMPLE {
            return;
        }
        let undone = rolled_back - self.rolled_back;
        self.scale = if 4 * undone >= ran {
            (self.scale / 2.0).max(Self::MIN_SCALE)
        } else {
            (self.scale * 2.0).min(1.0)
        };
        if self.moved > 0.0 {
            let span = window_span(pending) * self.scale;
            self.width = (self.moved / ran as f64 * span).min(2.0 * self.width);
        }
        (self.processed, self.rolled_back, self.moved) = (processed, rolled_back, 0.0);
    }
}
