//! GVT as a place in the order of batches, not only a simulation time.
//!
//! Batches run in the order (virtual time, receiver). A GVT that is only a simulation time can
//! commit nothing of the instant it stands in, and an instant can be long: a model whose every
//! object announces itself to its neighbours at the start, who relay it on, runs some hundred
//! thousand batches at t = 0 with 10^5 objects, which would all wait uncommitted (with their saved states and
//! messages) until the instant ended. A [`Floor`] is the smallest (virtual time, receiver) of any
//! message still to be handled: every later send goes strictly forward in virtual time, so no
//! batch before the floor can change any more, whatever its time.
//!
//! It has a fixed size so that reductions carry it as plain words (threads, and MPI as seven
//! 64-bit integers): a time whose tie-break is longer than [`DEPTH`] words is cut to its first
//! words, which sorts before the whole time, so the cut only makes GVT more cautious.

use super::super::time::{Time, VTime, TIE_WORDS};
use std::cmp::Ordering;

/// The words of a time's tie-break ([`Time::tie_words`]) a floor keeps.
pub const DEPTH: usize = TIE_WORDS;

/// A lower bound on the (virtual time, receiver) of every batch that may still change.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Floor {
    /// Simulation time.
    pub t: f64,
    path: [u64; DEPTH],
    len: u8,
    gen: u32,
    to: u32,
}

impl Floor {
    /// Above every batch: nothing is left to run.
    pub const INFINITY: Floor = Floor::start(f64::INFINITY);
    /// Below every batch: nothing is known yet.
    pub const NEG_INFINITY: Floor = Floor::start(f64::NEG_INFINITY);

    /// The start of the instant `t`: before every batch at `t`.
    pub const fn start(t: f64) -> Floor {
        Floor {
            t,
            path: [0; DEPTH],
            len: 0,
            gen: 0,
            to: 0,
        }
    }

    /// The place of the batch of object `to` at `time`, or just before it when its time's
    /// tie-break is longer than [`TIE_WORDS`](crate::time::TIE_WORDS) words.
    pub fn of<T: Time>(time: &VTime<T>, to: u32) -> Floor {
        let mut f = Floor::start(time.t());
        let n = time.key.tie_words(&mut f.path);
        let kept = n.min(DEPTH);
        f.path[kept..].fill(0);
        f.len = kept as u8;
        if kept == n {
            f.gen = time.gen;
            f.to = to;
        }
        f
    }

    /// Whether the batch of object `to` at `time` comes before this floor (and is final).
    #[inline]
    pub fn passed<T: Time>(&self, time: &VTime<T>, to: u32) -> bool {
        self.cmp_with(time, to).is_gt()
    }

    /// Whether the batch of object `to` at `time` comes at or before this floor.
    #[inline]
    pub fn reaches<T: Time>(&self, time: &VTime<T>, to: u32) -> bool {
        self.cmp_with(time, to).is_ge()
    }

    /// How this floor compares with the place of the batch of object `to` at `time`.
    fn cmp_with<T: Time>(&self, time: &VTime<T>, to: u32) -> Ordering {
        self.t.total_cmp(&time.t()).then_with(|| {
            let mut words = [0u64; DEPTH];
            let n = time.key.tie_words(&mut words);
            let kept = n.min(DEPTH);
            // a time cut to its first words sorts after a floor of those words alone
            let cut = if n > DEPTH {
                Ordering::Less
            } else {
                Ordering::Equal
            };
            self.path[..usize::from(self.len)]
                .cmp(&words[..kept])
                .then(cut)
                .then(self.gen.cmp(&time.gen))
                .then(self.to.cmp(&to))
        })
    }

    /// How this floor compares with another.
    fn cmp_floor(&self, o: &Floor) -> Ordering {
        self.t
            .total_cmp(&o.t)
            .then_with(|| self.path[..usize::from(self.len)].cmp(&o.path[..usize::from(o.len)]))
            .then(self.gen.cmp(&o.gen))
            .then(self.to.cmp(&o.to))
    }

    /// Below every message a worker standing at this floor may still send: a send is later
    /// than its batch, at least the next generation of the batch's key. A floor cut from a
    /// deeper key, or that may have been, and an infinite one stay as they are.
    pub fn next_generation(self) -> Floor {
        if !self.t.is_finite() || usize::from(self.len) == DEPTH {
            return self;
        }
        Floor {
            gen: self.gen.saturating_add(1),
            to: 0,
            ..self
        }
    }

    /// Below every message a worker standing at this floor may still send when every message
    /// comes at least `lookahead` after the batch that sends it ([`Model::lookahead`](crate::Model::lookahead)): the
    /// start of the instant `t + lookahead` (as `f64` addition rounds it), or the next
    /// generation when that is no later.
    pub fn later_by(self, lookahead: f64) -> Floor {
        let next = self.next_generation();
        if !(lookahead > 0.0 && self.t.is_finite()) {
            return next;
        }
        let start = Floor::start(self.t + lookahead);
        if start > next {
            start
        } else {
            next
        }
    }

    /// The smaller of two floors.
    pub fn min(self, o: Floor) -> Floor {
        if o < self {
            o
        } else {
            self
        }
    }

    /// The larger of two floors.
    pub fn max(self, o: Floor) -> Floor {
        if o > self {
            o
        } else {
            self
        }
    }

    /// The floor as words, for a reduction over MPI.
    pub fn to_words(&self) -> [u64; DEPTH + 3] {
        let mut w = [0u64; DEPTH + 3];
        w[0] = self.t.to_bits();
        w[1..=DEPTH].copy_from_slice(&self.path);
        w[DEPTH + 1] = u64::from(self.len);
        w[DEPTH + 2] = (u64::from(self.gen) << 32) | u64::from(self.to);
        w
    }

    /// The floor [`Floor::to_words`] wrote.
    pub fn from_words(w: &[u64]) -> Floor {
        let mut path = [0u64; DEPTH];
        path.copy_from_slice(&w[1..=DEPTH]);
        Floor {
            t: f64::from_bits(w[0]),
            path,
            len: (w[DEPTH + 1] as u8).min(DEPTH as u8),
            gen: (w[DEPTH + 2] >> 32) as u32,
            to: w[DEPTH + 2] as u32,
        }
    }
}

impl PartialOrd for Floor {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp_floor(o))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A time with a tie-break of any length: a simulation time and words compared in turn.
    #[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
    struct PathTime {
        t: f64,
        path: Vec<u64>,
    }

    impl PartialEq for PathTime {
        fn eq(&self, o: &Self) -> bool {
            self.cmp(o).is_eq()
        }
    }

    impl Eq for PathTime {}

    impl PartialOrd for PathTime {
        fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
            Some(self.cmp(o))
        }
    }

    impl Ord for PathTime {
        fn cmp(&self, o: &Self) -> Ordering {
            self.t.total_cmp(&o.t).then_with(|| self.path.cmp(&o.path))
        }
    }

    impl Time for PathTime {
        fn start(t: f64) -> Self {
            PathTime { t, path: vec![] }
        }
        fn t(&self) -> f64 {
            self.t
        }
        fn tie_words(&self, out: &mut [u64; TIE_WORDS]) -> usize {
            let kept = self.path.len().min(TIE_WORDS);
            out[..kept].copy_from_slice(&self.path[..kept]);
            self.path.len()
        }
    }

    /// Stands for an event between objects `a` and `b`.
    fn pair(a: u32, b: u32) -> u64 {
        u64::from(a) << 32 | u64::from(b)
    }

    fn vtime(t: f64, path: &[u64], gen: u32) -> VTime<PathTime> {
        VTime {
            key: PathTime {
                t,
                path: path.to_vec(),
            },
            gen,
        }
    }

    #[test]
    fn batches_of_an_instant_pass_one_by_one() {
        let k = vtime(0.0, &[], 2);
        let f = Floor::of(&k, 7);
        assert!(f.passed(&k, 6));
        assert!(!f.passed(&k, 7));
        assert!(f.passed(&vtime(0.0, &[], 1), 9));
        assert!(!f.passed(&vtime(0.0, &[pair(1, 2)], 0), 0));
        assert!(Floor::start(0.0).passed(&vtime(-1.0, &[], 0), 5));
        assert!(!Floor::start(0.0).passed(&vtime(0.0, &[], 0), 0));
        assert!(Floor::INFINITY.passed(&vtime(1e300, &[], 0), 0));
        assert!(!Floor::NEG_INFINITY.passed(&vtime(-1e300, &[], 0), 0));
    }

    #[test]
    fn a_lookahead_moves_the_floor_of_messages_to_the_start_of_a_later_instant() {
        let f = Floor::of(&vtime(2.0, &[pair(1, 2)], 3), 7);
        assert_eq!(f.later_by(0.0), f.next_generation());
        assert_eq!(f.later_by(0.5), Floor::start(2.5));
        // a message at exactly t + lookahead may come: nothing at that instant is passed
        assert!(!f.later_by(0.5).passed(&vtime(2.5, &[], 0), 0));
        assert!(f.later_by(0.5).passed(&vtime(2.4999, &[], 0), 0));
        // a lookahead lost in rounding leaves the next generation
        let big = Floor::start(1e20);
        assert_eq!(big.later_by(1e-9), big.next_generation());
        assert_eq!(Floor::INFINITY.later_by(1.0), Floor::INFINITY);
    }

    #[test]
    fn deep_keys_are_cut_to_a_floor_below_them() {
        let path: Vec<u64> = (1..=6).map(|k| pair(k, k + 1)).collect();
        let deep = vtime(3.0, &path, 5);
        let f = Floor::of(&deep, 9);
        assert!(!f.passed(&deep, 9));
        assert!(!f.passed(&deep, 0));
        let mut deeper = path.clone();
        deeper.push(pair(8, 9));
        let shallow = vtime(3.0, &path[..DEPTH], 5);
        let g = Floor::of(&shallow, 9);
        assert!(!g.passed(&vtime(3.0, &deeper, 0), 0));
        assert_eq!(&f.path[..usize::from(f.len)], &path[..DEPTH]);
        assert!(f.passed(&vtime(3.0, &path[..DEPTH - 1], 9), 9));
    }

    #[test]
    fn the_next_generation_is_below_every_later_virtual_time() {
        let f = Floor::of(&vtime(2.0, &[pair(1, 2)], 3), 7);
        let g = f.next_generation();
        assert!(!g.passed(&vtime(2.0, &[pair(1, 2)], 4), 0));
        assert!(g.passed(&vtime(2.0, &[pair(1, 2)], 3), u32::MAX));
        let deep: Vec<u64> = (1..=6).map(|k| pair(k, k + 1)).collect();
        let cut = Floor::of(&vtime(2.0, &deep, 3), 7);
        assert_eq!(cut.next_generation(), cut);
        assert_eq!(Floor::INFINITY.next_generation(), Floor::INFINITY);
    }

    fn arb_vtime() -> impl Strategy<Value = VTime<PathTime>> {
        (-2i32..3, prop::collection::vec(0u64..4, 0..7), 0u32..3)
            .prop_map(|(t, path, gen)| vtime(f64::from(t), &path, gen))
    }

    proptest! {
        /// A floor never passes a batch that is not before the batch it was taken from, and
        /// passes every batch before it when its key is short enough to be kept whole.
        #[test]
        fn floors_order_like_batches(a in arb_vtime(), ta in 0u32..3, b in arb_vtime(), tb in 0u32..3) {
            let f = Floor::of(&a, ta);
            let before = (&b, tb) < (&a, ta);
            if f.passed(&b, tb) {
                prop_assert!(before);
            }
            if a.key.path.len() <= DEPTH && b.key.path.len() <= DEPTH {
                prop_assert_eq!(f.passed(&b, tb), before);
            }
            prop_assert_eq!(Floor::from_words(&f.to_words()), f);
            // every virtual time after `a` is at or past the floor's next generation
            if b > a {
                prop_assert!(!f.next_generation().passed(&b, tb));
            }
        }
    }
}
