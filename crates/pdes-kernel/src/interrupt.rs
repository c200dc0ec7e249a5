//! A request to end a run early and cleanly, shared between whoever asks (a signal handler,
//! another thread) and the executor that honours it.
//!
//! An executor that sees the request ends its run at a time it chooses so that nothing is
//! half done: every batch up to that time runs, none after it, exactly as if the run had been
//! asked to end there. The sequential executor ends at the time of the batch it has just run;
//! Time Warp at the latest batch any worker has run when a GVT round sees the request, since
//! its workers then hold nothing beyond it that would have to be undone.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// A shared flag that asks a run to end early, with a cause (any non-zero number; by the
/// convention of `signal_hook::flag::register_usize`, the number of the signal that raised it).
#[derive(Clone, Debug, Default)]
pub struct Interrupt(Arc<AtomicUsize>);

impl Interrupt {
    /// A flag not raised.
    pub fn new() -> Interrupt {
        Interrupt::default()
    }

    /// Asks the run to end, for `cause` (not 0: 0 means not raised). The first cause stays.
    pub fn raise(&self, cause: usize) {
        assert_ne!(cause, 0, "an interrupt's cause is not 0");
        let _ = self
            .0
            .compare_exchange(0, cause, Ordering::Relaxed, Ordering::Relaxed);
    }

    /// Whether the run was asked to end.
    #[inline]
    pub fn raised(&self) -> bool {
        self.0.load(Ordering::Relaxed) != 0
    }

    /// The cause it was raised for, if it was.
    pub fn cause(&self) -> Option<usize> {
        Some(self.0.load(Ordering::Relaxed)).filter(|&c| c != 0)
    }

    /// The cell behind the flag, for a signal handler to store its cause in (storing 0 leaves
    /// it not raised).
    pub fn cell(&self) -> Arc<AtomicUsize> {
        self.0.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_cause_stays_and_clones_share_the_flag() {
        let i = Interrupt::new();
        let j = i.clone();
        assert!(!j.raised());
        assert_eq!(j.cause(), None);
        i.raise(15);
        i.raise(2);
        assert!(j.raised());
        assert_eq!(j.cause(), Some(15));
        j.cell().store(0, Ordering::Relaxed);
        assert!(!i.raised());
    }
}
