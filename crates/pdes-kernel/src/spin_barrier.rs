//! A barrier for the threads of one process that spins, then yields, instead of sleeping: the
//! executors meet at one every few tens of microseconds, and a thread put to sleep takes about
//! as long to wake. A thread that panics opens it for good, so that the others return.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Spins this many times before yielding the core, while a barrier waits: a window of PHOLD
/// or a GVT round lasts tens of microseconds, and a sleeping thread takes about as long to wake.
const SPINS_BEFORE_YIELD: u32 = 4096;

/// A worker's thread ended by a panic: the others stop waiting for it.
#[derive(Debug)]
pub struct Poisoned;

/// A barrier that spins (then yields) instead of sleeping, and that a panicking worker opens
/// for good, so that the others return instead of waiting forever.
pub struct SpinBarrier {
    parties: usize,
    arrived: AtomicUsize,
    generation: AtomicUsize,
    poisoned: AtomicBool,
}

impl SpinBarrier {
    /// A barrier for `parties` threads.
    pub fn new(parties: usize) -> SpinBarrier {
        SpinBarrier {
            parties,
            arrived: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
            poisoned: AtomicBool::new(false),
        }
    }

    /// Waits until every party has arrived. What each party wrote before arriving is seen by
    /// every party after it returns.
    pub fn wait(&self) -> Result<(), Poisoned> {
        if self.poisoned.load(Ordering::Relaxed) {
            return Err(Poisoned);
        }
        let generation = self.generation.load(Ordering::Acquire);
        if self.arrived.fetch_add(1, Ordering::AcqRel) + 1 == self.parties {
            self.arrived.store(0, Ordering::Relaxed);
            self.generation.store(generation + 1, Ordering::Release);
            return Ok(());
        }
        let mut spins = 0u32;
        while self.generation.load(Ordering::Acquire) == generation {
            if self.poisoned.load(Ordering::Relaxed) {
                return Err(Poisoned);
            }
            if spins < SPINS_BEFORE_YIELD {
                spins += 1;
                std::hint::spin_loop();
            } else {
                std::thread::yield_now();
            }
        }
        Ok(())
    }

    /// Opens the barrier for good: every wait, now and later, returns [`Poisoned`].
    pub fn poison(&self) {
        self.poisoned.store(true, Ordering::Relaxed);
    }
}

/// Poisons a barrier when the thread holding it unwinds from a panic.
pub struct PoisonOnPanic<'a>(pub &'a SpinBarrier);

impl Drop for PoisonOnPanic<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.poison();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panicking_party_releases_the_others() {
        let barrier = SpinBarrier::new(2);
        let result = std::thread::scope(|s| {
            let waiter = s.spawn(|| barrier.wait());
            let _ = s
                .spawn(|| {
                    let _guard = PoisonOnPanic(&barrier);
                    panic!("a model bug");
                })
                .join();
            waiter.join().unwrap()
        });
        assert!(result.is_err());
        assert!(barrier.wait().is_err(), "poisoned for good");
    }
}
