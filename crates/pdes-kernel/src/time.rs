//! Virtual time as the model chooses it, and what the executors need of it.
//!
//! A model picks its own time type ([`Model::Time`](super::Model::Time)): [`PlainTime`] (a
//! simulation time alone) for most models, or a richer one that orders the events of one instant
//! (a lexicographic key, say). The kernel wraps it in a [`VTime`] with a generation, so that a
//! message sent with zero delay ([`Ctx::send_now`](super::Ctx::send_now)) arrives after the batch
//! that sent it and before every later time. Messages of equal virtual time are ordered by the
//! kernel itself: receiver, priority, sender, the sender's send sequence.

use serde::de::DeserializeOwned;
use serde::Serialize;
use std::cmp::Ordering;
use std::fmt::Debug;

/// How many words of a time's tie-break ([`Time::tie_words`]) a GVT floor keeps: a deeper time
/// is cut to its first words, which sorts before the whole time and only makes GVT cautious.
pub const TIE_WORDS: usize = 4;

/// What the executors need of a model's time: a total order, the simulation time it stands
/// for, the earliest time at a given simulation time, and a fixed-size encoding of its order
/// within one simulation time (for GVT reductions across threads and MPI ranks).
pub trait Time: Clone + Ord + Debug + Send + Sync + Serialize + DeserializeOwned + 'static {
    /// The earliest time at simulation time `t`: before every other time at `t`.
    fn start(t: f64) -> Self;

    /// The simulation time (for `until`, the optimism window and GVT reports).
    fn t(&self) -> f64;

    /// How many zero-delay steps led to this time, for the cap on an instant that does not end
    /// ([`MAX_CASCADE_DEPTH`](super::time_warp::MAX_CASCADE_DEPTH)); 0 where the time cannot
    /// tell.
    fn depth(&self) -> usize {
        0
    }

    /// Writes the words that order this time among the times of its simulation time (compared
    /// as slices: a prefix sorts first) into `out`, at most [`TIE_WORDS`] of them, and returns
    /// how many there are in all (more than [`TIE_WORDS`] when cut). For two times `a` and `b`
    /// with `a.t() == b.t()`, `a.cmp(b)` must equal the comparison of their whole word lists.
    fn tie_words(&self, out: &mut [u64; TIE_WORDS]) -> usize {
        let _ = out;
        0
    }
}

/// The time as an integer that orders as `f64::total_cmp` orders times.
#[inline]
pub fn time_bits(t: f64) -> u64 {
    let b = t.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | 1 << 63
    }
}

/// A plain simulation time: messages at one time are ordered by the kernel's own tie-break
/// (receiver, priority, sender, send sequence), so a run is deterministic without the model
/// saying more.
#[derive(Clone, Copy, Debug, Serialize, serde::Deserialize)]
pub struct PlainTime(pub f64);

impl PartialEq for PlainTime {
    fn eq(&self, o: &Self) -> bool {
        self.0.total_cmp(&o.0).is_eq()
    }
}

impl Eq for PlainTime {}

impl PartialOrd for PlainTime {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for PlainTime {
    #[inline]
    fn cmp(&self, o: &Self) -> Ordering {
        self.0.total_cmp(&o.0)
    }
}

impl Time for PlainTime {
    fn start(t: f64) -> Self {
        PlainTime(t)
    }

    #[inline]
    fn t(&self) -> f64 {
        self.0
    }
}

/// Virtual time as the kernel orders it: the model's time and the generation of zero-delay
/// sends within it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(bound = "T: Time")]
pub struct VTime<T> {
    /// The model's time.
    pub key: T,
    /// How many zero-delay hops after `key` this is.
    pub gen: u32,
}

impl<T: Time> VTime<T> {
    /// The model's time `key`, generation 0.
    #[inline]
    pub fn at(key: T) -> VTime<T> {
        VTime { key, gen: 0 }
    }

    /// The earliest virtual time at simulation time `t`.
    pub fn start(t: f64) -> VTime<T> {
        VTime::at(T::start(t))
    }

    /// The time a zero-delay message sent now arrives.
    #[inline]
    pub fn next_gen(&self) -> VTime<T> {
        VTime {
            key: self.key.clone(),
            gen: self.gen + 1,
        }
    }

    /// Simulation time.
    #[inline]
    pub fn t(&self) -> f64 {
        self.key.t()
    }
}

impl<T: Time> PartialOrd for VTime<T> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl<T: Time> Ord for VTime<T> {
    #[inline]
    fn cmp(&self, other: &Self) -> Ordering {
        self.key
            .cmp(&other.key)
            .then_with(|| self.gen.cmp(&other.gen))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn time_bits_order_as_total_cmp(a in any::<f64>(), b in any::<f64>()) {
            prop_assert_eq!(time_bits(a).cmp(&time_bits(b)), a.total_cmp(&b));
        }
    }

    #[test]
    fn time_bits_order_signed_zeros_and_infinities() {
        let bits = [
            f64::NEG_INFINITY,
            -1.0,
            -0.0,
            0.0,
            1e-300,
            1.0,
            f64::INFINITY,
        ]
        .map(time_bits);
        assert!(bits.windows(2).all(|w| w[0] < w[1]), "{bits:?}");
    }

    #[test]
    fn a_zero_delay_send_arrives_after_its_batch_and_before_later_times() {
        let now = VTime::at(PlainTime(1.0));
        let next = now.next_gen();
        assert!(now < next && next < VTime::start(1.0 + 1e-12));
        assert_eq!(next.t(), 1.0);
    }
}
