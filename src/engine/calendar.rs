//! The pending-event set of the event-list engine: a calendar queue with one entry per ball.
//!
//! Time is cut into buckets of a fixed width; a ring of buckets covers the near future and an
//! overflow list holds the rest. Only the current bucket is kept ordered, in a small binary heap
//! indexed by ball, so inserting, moving and removing a ball's event cost O(1) memory touches,
//! however many balls there are (the O(1) queue of G. Paul, J. Comput. Phys. 221, 2007). A
//! tournament tree over a million balls costs some twenty cache misses per update instead.
//!
//! The order is exactly the virtual-time order: a bucket holds events by time only, and the heap
//! orders the current bucket by full [`Key`], so ties within an instant come out as DESIGN.md
//! says whatever the bucket width.

use crate::vtime::Key;
use std::cmp::Ordering;

const NIL: u32 = u32::MAX;

/// Where a ball's entry is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    /// Not queued (no event, or an infinite time).
    Nowhere,
    /// In the current bucket's heap, at this index.
    Heap(u32),
    /// In the ring's bucket with this slot.
    Ring(u32),
    /// In the overflow list.
    Overflow,
}

/// A ball's links in its bucket's list and where its entry is: one record, so that queueing a
/// ball touches one cache line of its own.
#[derive(Clone, Copy, Debug)]
struct Link {
    next: u32,
    prev: u32,
    place: Place,
}

/// Where the calendar reads each ball's key: the keys live with the caller, who passes them in.
pub trait Keys {
    /// Ball `i`'s queued key (an infinite time: not queued).
    fn key(&self, i: u32) -> &Key;
}

impl Keys for [Key] {
    #[inline]
    fn key(&self, i: u32) -> &Key {
        &self[i as usize]
    }
}

/// The calendar queue. It stores ball indices and reads their keys through [`Keys`].
#[derive(Clone, Debug)]
pub struct Calendar {
    inv_width: f64,
    mask: u64,
    base: i64,
    head: Vec<u32>,
    overflow: u32,
    in_ring: usize,
    links: Vec<Link>,
    heap: Vec<u32>,
}

impl Calendar {
    /// A calendar for `n` balls, starting at time `start`, whose events are about `mean_gap`
    /// apart in time overall (a bucket is a few mean gaps wide; the ring holds about `n` buckets).
    pub fn new(n: usize, start: f64, mean_gap: f64) -> Calendar {
        let buckets = n.next_power_of_two().clamp(16, 1 << 22);
        let width = if mean_gap.is_finite() && mean_gap > 0.0 {
            4.0 * mean_gap
        } else {
            1.0
        };
        let inv_width = 1.0 / width;
        Calendar {
            inv_width,
            mask: buckets as u64 - 1,
            base: (start * inv_width).floor() as i64,
            head: vec![NIL; buckets],
            overflow: NIL,
            in_ring: 0,
            links: vec![
                Link {
                    next: NIL,
                    prev: NIL,
                    place: Place::Nowhere,
                };
                n
            ],
            heap: Vec::new(),
        }
    }

    #[inline]
    fn bucket(&self, t: f64) -> i64 {
        (t * self.inv_width).floor() as i64
    }

    #[inline]
    fn ring_len(&self) -> i64 {
        self.mask as i64 + 1
    }

    /// Sets ball `i`'s event to `key` (replacing any earlier one). `keys[i]` must already be `key`.
    #[inline]
    pub fn set<K: Keys + ?Sized>(&mut self, keys: &K, i: u32) {
        self.remove(keys, i);
        self.insert(keys, i);
    }

    fn insert<K: Keys + ?Sized>(&mut self, keys: &K, i: u32) {
        let t = keys.key(i).t;
        if !t.is_finite() {
            return;
        }
        let b = self.bucket(t);
        if b <= self.base {
            self.heap_push(keys, i);
        } else if b - self.base < self.ring_len() {
            let slot = (b as u64 & self.mask) as u32;
            let h = self.head[slot as usize];
            self.link(i, h);
            self.head[slot as usize] = i;
            self.links[i as usize].place = Place::Ring(slot);
            self.in_ring += 1;
        } else {
            let h = self.overflow;
            self.link(i, h);
            self.overflow = i;
            self.links[i as usize].place = Place::Overflow;
        }
    }

    #[inline]
    fn link(&mut self, i: u32, h: u32) {
        self.links[i as usize].next = h;
        self.links[i as usize].prev = NIL;
        if h != NIL {
            self.links[h as usize].prev = i;
        }
    }

    fn unlink(&mut self, i: u32) -> bool {
        let (p, n) = (self.links[i as usize].prev, self.links[i as usize].next);
        if n != NIL {
            self.links[n as usize].prev = p;
        }
        if p != NIL {
            self.links[p as usize].next = n;
            false
        } else {
            true // i was the head
        }
    }

    fn remove<K: Keys + ?Sized>(&mut self, keys: &K, i: u32) {
        match self.links[i as usize].place {
            Place::Nowhere => {}
            Place::Heap(k) => self.heap_remove(keys, k as usize),
            Place::Ring(slot) => {
                if self.unlink(i) {
                    self.head[slot as usize] = self.links[i as usize].next;
                }
                self.in_ring -= 1;
            }
            Place::Overflow => {
                if self.unlink(i) {
                    self.overflow = self.links[i as usize].next;
                }
            }
        }
        self.links[i as usize].place = Place::Nowhere;
    }

    /// The ball with the earliest event, or `None` if no ball has one.
    #[inline]
    pub fn first<K: Keys + ?Sized>(&mut self, keys: &K) -> Option<u32> {
        while self.heap.is_empty() {
            if !self.advance(keys) {
                return None;
            }
        }
        Some(self.heap[0])
    }

    /// Moves to the next bucket with entries; false when the calendar is empty.
    fn advance<K: Keys + ?Sized>(&mut self, keys: &K) -> bool {
        if self.in_ring == 0 {
            // jump straight to the earliest overflow entry
            let mut j = self.overflow;
            let mut earliest = i64::MAX;
            while j != NIL {
                earliest = earliest.min(self.bucket(keys.key(j).t));
                j = self.links[j as usize].next;
            }
            if earliest == i64::MAX {
                return false;
            }
            self.base = earliest - 1;
        }
        self.base += 1;
        if self.base & self.mask as i64 == 0 || self.in_ring == 0 {
            self.pull_overflow(keys);
        }
        let slot = (self.base as u64 & self.mask) as usize;
        let mut j = self.head[slot];
        self.head[slot] = NIL;
        while j != NIL {
            let n = self.links[j as usize].next;
            self.in_ring -= 1;
            self.links[j as usize].place = Place::Nowhere;
            self.heap_push(keys, j);
            j = n;
        }
        true
    }

    /// Moves overflow entries that now fall inside the ring's window into it.
    fn pull_overflow<K: Keys + ?Sized>(&mut self, keys: &K) {
        let mut j = self.overflow;
        while j != NIL {
            let n = self.links[j as usize].next;
            if self.bucket(keys.key(j).t) - self.base < self.ring_len() {
                self.remove(keys, j);
                self.insert(keys, j);
            }
            j = n;
        }
    }

    #[inline]
    fn less<K: Keys + ?Sized>(keys: &K, a: u32, b: u32) -> bool {
        let (ka, kb) = (keys.key(a), keys.key(b));
        match ka.t.total_cmp(&kb.t) {
            Ordering::Less => true,
            Ordering::Greater => false,
            Ordering::Equal => ka.path < kb.path,
        }
    }

    fn heap_push<K: Keys + ?Sized>(&mut self, keys: &K, i: u32) {
        self.heap.push(i);
        let k = self.heap.len() - 1;
        self.links[i as usize].place = Place::Heap(k as u32);
        self.sift_up(keys, k);
    }

    fn heap_remove<K: Keys + ?Sized>(&mut self, keys: &K, k: usize) {
        let last = self.heap.pop().expect("the entry is in the heap");
        if k < self.heap.len() {
            self.heap[k] = last;
            self.links[last as usize].place = Place::Heap(k as u32);
            let k = self.sift_up(keys, k);
            self.sift_down(keys, k);
        }
    }

    fn sift_up<K: Keys + ?Sized>(&mut self, keys: &K, mut k: usize) -> usize {
        while k > 0 {
            let p = (k - 1) / 2;
            if Self::less(keys, self.heap[k], self.heap[p]) {
                self.swap(k, p);
                k = p;
            } else {
                break;
            }
        }
        k
    }

    fn sift_down<K: Keys + ?Sized>(&mut self, keys: &K, mut k: usize) {
        loop {
            let (l, r) = (2 * k + 1, 2 * k + 2);
            let mut m = k;
            if l < self.heap.len() && Self::less(keys, self.heap[l], self.heap[m]) {
                m = l;
            }
            if r < self.heap.len() && Self::less(keys, self.heap[r], self.heap[m]) {
                m = r;
            }
            if m == k {
                return;
            }
            self.swap(k, m);
            k = m;
        }
    }

    #[inline]
    fn swap(&mut self, a: usize, b: usize) {
        self.heap.swap(a, b);
        self.links[self.heap[a] as usize].place = Place::Heap(a as u32);
        self.links[self.heap[b] as usize].place = Place::Heap(b as u32);
    }

    /// Bytes of memory held.
    pub fn memory_bytes(&self) -> usize {
        4 * (self.head.len() + self.heap.capacity())
            + std::mem::size_of::<Link>() * self.links.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vtime::pair;
    use proptest::prelude::*;

    proptest! {
        /// Any sequence of sets and pops yields balls in exact key order, like a sorted list.
        #[test]
        fn pops_in_key_order(
            n in 1usize..40,
            ops in proptest::collection::vec((0u32..40, 0.0..50.0f64, 0u32..3, any::<bool>()), 1..300),
            gap in 0.01..10.0f64,
        ) {
            let mut keys: Vec<Key> = (0..n).map(|_| Key::at(f64::INFINITY, 0)).collect();
            let mut cal = Calendar::new(n, 0.0, gap);
            let mut now = 0.0f64;
            for (i, dt, tie, pop) in ops {
                let i = i % n as u32;
                if pop {
                    let want = (0..n as u32)
                        .filter(|&b| keys[b as usize].t.is_finite())
                        .min_by(|&a, &b| keys[a as usize].cmp(&keys[b as usize]));
                    let got = cal.first(&keys[..]);
                    prop_assert_eq!(
                        got.map(|g| keys[g as usize].clone()),
                        want.map(|w| keys[w as usize].clone())
                    );
                    if let Some(g) = got {
                        now = keys[g as usize].t;
                        keys[g as usize] = Key::at(f64::INFINITY, 0);
                        cal.set(&keys[..], g);
                    }
                } else {
                    // times never go before the last popped one, as in a simulation
                    let t = if tie == 0 { now } else { now + (dt * tie as f64).round() / 4.0 };
                    keys[i as usize] = Key::at(t, pair(i, 100 + tie));
                    cal.set(&keys[..], i);
                }
            }
        }
    }
}
