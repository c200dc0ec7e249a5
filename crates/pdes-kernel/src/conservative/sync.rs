//! What the conservative executor's workers share besides their spinning barrier
//! ([`crate::spin_barrier`]): each worker's report of a round, and the mail between windows. Every shared record is kept twice, by the parity of the
//! round, so that a worker that runs ahead into the next window never writes what a slower one
//! is still reading.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// Flag of a [`Report`]: an interrupt asks the run to end.
pub const INTERRUPTED: u64 = 1;
/// Flag of a [`Report`]: the worker failed (a model bug), or the sink did.
pub const FAILED: u64 = 2;

/// One worker's report of a round, on a cache line of its own.
#[repr(align(128))]
#[derive(Default)]
pub struct Report {
    /// Bits of the earliest time the worker holds or has just sent elsewhere (`f64::INFINITY`
    /// when none).
    earliest: AtomicU64,
    /// Bits of the time of the last batch the worker ran (`f64::NEG_INFINITY` before any).
    last: AtomicU64,
    /// [`INTERRUPTED`] and [`FAILED`].
    flags: AtomicU64,
}

/// What every worker learns from the reports of a round.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Round {
    /// The earliest time any message of the simulation may still be delivered at.
    pub earliest: f64,
    /// The time of the last batch any worker ran.
    pub last: f64,
    /// The union of the workers' flags.
    pub flags: u64,
}

/// Every worker's report, twice over (by the round's parity).
pub struct Reports {
    slots: [Vec<Report>; 2],
}

impl Reports {
    /// Reports for `workers` workers.
    pub fn new(workers: usize) -> Reports {
        let slots = || (0..workers).map(|_| Report::default()).collect();
        Reports {
            slots: [slots(), slots()],
        }
    }

    /// Worker `w`'s report of round `round`: written before the round's barrier.
    pub fn write(&self, round: u64, w: usize, earliest: f64, last: f64, flags: u64) {
        let r = &self.slots[(round % 2) as usize][w];
        r.earliest.store(earliest.to_bits(), Ordering::Relaxed);
        r.last.store(last.to_bits(), Ordering::Relaxed);
        r.flags.store(flags, Ordering::Relaxed);
    }

    /// Every worker's reports of round `round` together: read after the round's barrier.
    pub fn read(&self, round: u64) -> Round {
        let mut all = Round {
            earliest: f64::INFINITY,
            last: f64::NEG_INFINITY,
            flags: 0,
        };
        for r in &self.slots[(round % 2) as usize] {
            all.earliest = all
                .earliest
                .min(f64::from_bits(r.earliest.load(Ordering::Relaxed)));
            all.last = all.last.max(f64::from_bits(r.last.load(Ordering::Relaxed)));
            all.flags |= r.flags.load(Ordering::Relaxed);
        }
        all
    }
}

/// Mail boxes between every pair of workers, twice over (by the round's parity): the sender
/// fills its box to a worker before the round's barrier, the receiver empties it after.
pub struct Boxes<T> {
    workers: usize,
    boxes: [Vec<Mutex<T>>; 2],
}

impl<T: Default> Boxes<T> {
    /// Empty boxes between `workers` workers.
    pub fn new(workers: usize) -> Boxes<T> {
        let boxes = || (0..workers * workers).map(|_| Mutex::default()).collect();
        Boxes {
            workers,
            boxes: [boxes(), boxes()],
        }
    }

    /// The box from worker `from` to worker `to` of round `round`.
    pub fn get(&self, round: u64, from: usize, to: usize) -> std::sync::MutexGuard<'_, T> {
        let b = &self.boxes[(round % 2) as usize][from * self.workers + to];
        // a worker that panicked while holding a box poisons the barrier too, and the run ends
        b.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spin_barrier::SpinBarrier;

    #[test]
    fn a_barrier_orders_what_was_written_before_it() {
        let barrier = SpinBarrier::new(3);
        let reports = Reports::new(3);
        std::thread::scope(|s| {
            for w in 0..3 {
                let (barrier, reports) = (&barrier, &reports);
                s.spawn(move || {
                    for round in 0..200u64 {
                        let t = (round * 10 + w as u64) as f64;
                        reports.write(round, w, t, t, u64::from(w == 2 && round == 150));
                        barrier.wait().unwrap();
                        let all = reports.read(round);
                        assert_eq!(all.earliest, (round * 10) as f64);
                        assert_eq!(all.last, (round * 10 + 2) as f64);
                        assert_eq!(all.flags, u64::from(round == 150));
                    }
                });
            }
        });
    }
}
