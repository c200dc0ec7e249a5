//! Virtual time: the lexicographic key that orders every event, simultaneous ones included.
//!
//! A key is a time and a path of object pairs. An event predicted for a later time `t'` between
//! objects `a < b` gets `(t', [(a, b)])`. A collision found to be immediate (the two objects
//! already touch and close, thesis 5.3) while the instant of key `k` is being processed gets `k`
//! with its own pair appended. Keys compare by time, then by path, element by element, a path
//! sorting before every path that extends it. So the consequences of an event run right after it
//! and before every other event of the same instant, in a fixed order: an instant is always
//! processed as one deterministic serial sequence of pairwise collisions (DESIGN.md, "Virtual
//! time"), which is what thesis tables 1–3 ask for and what the thesis' own system could not do.
//!
//! The key of an immediate collision depends only on the keys at which the two trajectories were
//! last fixed (the later of the two, extended by the pair), so every engine that holds the same
//! trajectories computes the same key, however it found the collision.

use pdes_kernel::time::{Time, TIE_WORDS};
use smallvec::SmallVec;
use std::cmp::Ordering;

/// Two object indices, the lower in the high 32 bits, packed so that pairs compare as
/// `(lower, higher)` tuples.
pub type Pair = u64;

/// The pair code of a kick of the thermostat (`crate::thermostat`): after every physical
/// event of its instant (its instants are random, so it shares one with none in practice).
pub const BATH: Pair = u64::MAX - 4;

/// The pair code of a reversal of every ball (thesis 4.6): it runs after every physical event of
/// its instant.
pub const REVERSAL: Pair = u64::MAX - 3;

/// The pair code of a ball leaving a sector (thesis 5.1): after every physical event and the
/// reversal of its instant, so that membership is never given up early. (Entries use the empty
/// path, before everything of their instant.)
pub const DEPARTURE: Pair = u64::MAX - 2;

/// The pair code of a frame of the display (thesis 4.2): after the reversal, if any, so that a
/// frame shows the state after everything at its time.
pub const DISPLAY: Pair = u64::MAX - 1;

/// Packs the pair of objects `a` and `b` (in either order) in canonical order.
#[inline]
pub fn pair(a: u32, b: u32) -> Pair {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    (u64::from(lo) << 32) | u64::from(hi)
}

/// Unpacks a pair into `(lower, higher)`.
#[inline]
pub fn unpair(p: Pair) -> (u32, u32) {
    ((p >> 32) as u32, p as u32)
}

/// A point of virtual time: a time and the path of pairs that orders events within an instant.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct Key {
    /// Simulation time.
    pub t: f64,
    /// The pair of the event, preceded by the pairs of the cascade that led to it.
    pub path: SmallVec<[Pair; 2]>,
}

/// Copies the path as one block: `SmallVec`'s own `clone` collects it item by item, and the
/// executors copy a key for nearly every message.
impl Clone for Key {
    #[inline]
    fn clone(&self) -> Self {
        Key {
            t: self.t,
            path: SmallVec::from_slice(&self.path),
        }
    }

    #[inline]
    fn clone_from(&mut self, source: &Self) {
        self.t = source.t;
        self.path.clear();
        self.path.extend_from_slice(&source.path);
    }
}

impl Key {
    /// The key before every event: time `t0` with an empty path (initial trajectories).
    pub fn start(t0: f64) -> Key {
        Key {
            t: t0,
            path: SmallVec::new(),
        }
    }

    /// The key of an event predicted for time `t` between the objects of `p`.
    #[inline]
    pub fn at(t: f64, p: Pair) -> Key {
        let mut path = SmallVec::new();
        path.push(p);
        Key { t, path }
    }

    /// The key of an immediate event between the objects of `p`, found while processing `self`.
    #[inline]
    pub fn child(&self, p: Pair) -> Key {
        let mut path = self.path.clone();
        path.push(p);
        Key { t: self.t, path }
    }

    /// How many cascade steps deep this key is (1 for an ordinary predicted event).
    pub fn depth(&self) -> usize {
        self.path.len()
    }

    /// Compares with the key `(t, [p])` without building it.
    #[inline]
    pub fn cmp_at(&self, t: f64, p: Pair) -> Ordering {
        match self.t.total_cmp(&t) {
            Ordering::Equal => self.path.as_slice().cmp(&[p][..]),
            o => o,
        }
    }
}

/// Keys as the kernel's virtual time: the path of pairs breaks the ties of an instant.
impl Time for Key {
    fn start(t: f64) -> Key {
        Key::start(t)
    }

    #[inline]
    fn t(&self) -> f64 {
        self.t
    }

    fn depth(&self) -> usize {
        Key::depth(self)
    }

    #[inline]
    fn tie_words(&self, out: &mut [u64; TIE_WORDS]) -> usize {
        let kept = self.path.len().min(TIE_WORDS);
        out[..kept].copy_from_slice(&self.path[..kept]);
        self.path.len()
    }
}

impl PartialEq for Key {
    /// Equal times, then equal paths pair by pair: most paths are one or two pairs long, too
    /// short to be worth a call to `memcmp` (the executors compare keys at every message).
    #[inline]
    fn eq(&self, o: &Self) -> bool {
        self.t == o.t
            && self.path.len() == o.path.len()
            && self.path.iter().zip(o.path.iter()).all(|(a, b)| a == b)
    }
}

impl Eq for Key {}

impl PartialOrd for Key {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Key {
    #[inline]
    fn cmp(&self, other: &Self) -> Ordering {
        match self.t.total_cmp(&other.t) {
            Ordering::Equal => self.path.as_slice().cmp(other.path.as_slice()),
            o => o,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_key_cloned_into_another_equals_its_source() {
        let short = Key::at(1.5, pair(1, 2));
        let long = short.child(pair(2, 3)).child(pair(3, 4)).child(pair(4, 5));
        for (from, into) in [(&short, &long), (&long, &short), (&long, &long)] {
            let mut copy = into.clone();
            copy.clone_from(from);
            assert_eq!(copy, *from);
            assert_eq!(copy.path.as_slice(), from.path.as_slice());
            assert_eq!(from.clone(), *from);
        }
    }

    #[test]
    fn pairs_are_canonical() {
        assert_eq!(pair(3, 1), pair(1, 3));
        assert_eq!(unpair(pair(7, 2)), (2, 7));
        assert!(pair(1, 9) < pair(2, 3));
    }

    #[test]
    fn children_run_after_parent_and_before_the_rest_of_the_instant() {
        let k12 = Key::at(1.0, pair(1, 2));
        let k23 = Key::at(1.0, pair(2, 3));
        let child = k12.child(pair(2, 3));
        let grandchild = child.child(pair(1, 2));
        assert!(k12 < child && child < grandchild && grandchild < k23);
        assert!(Key::at(0.5, pair(8, 9)) < k12);
        assert!(Key::start(1.0) < k12);
        assert_eq!(k23.cmp_at(1.0, pair(2, 3)), Ordering::Equal);
        assert_eq!(child.cmp_at(1.0, pair(2, 3)), Ordering::Less);
    }
}
