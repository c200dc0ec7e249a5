//! The pending-event set of the event-list engine: a calendar queue with one entry per ball.
//!
//! Time is cut into buckets of a fixed width; a ring of buckets covers the near future and an
//! overflow list holds the rest. Only the current bucket is kept ordered, in a small binary heap
//! indexed by ball, so inserting, moving and removing a ball's event cost O(1) memory touches,
//! however many balls there are (the O(1) queue of G. Paul, J. Comput. Phys. 221, 2007). A
//! tournament tree over a million balls costs some twenty cache misses per update instead.
//!
//! Buckets are singly linked lists of small nodes, and an entry is removed lazily: moving a ball's
//! event only forgets the node it had (the ball's [`Place`] no longer names it), and the dead node
//! is dropped when its bucket comes up. So queueing a ball touches its own record, the bucket's
//! head and a recycled node, and never another ball's record.
//!
//! The order is exactly the virtual-time order: a bucket holds events by time only, and the heap
//! orders the current bucket by full [`Key`], so ties within an instant come out as DESIGN.md
//! says whatever the bucket width.

use crate::vtime::Key;
use std::cmp::Ordering;

const NIL: u32 = u32::MAX;

/// Where a ball's entry is, packed in one word the caller keeps with the ball: not queued, in
/// the current bucket's heap at an index, or in a ring bucket or the overflow list at a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Place(u32);

const TAG: u32 = 3 << 30;
const HEAP: u32 = 1 << 30;
const RING: u32 = 2 << 30;
const OVERFLOW: u32 = 3 << 30;

impl Place {
    /// Not queued (no event, or an infinite time).
    pub const NOWHERE: Place = Place(0);

    fn heap(k: usize) -> Place {
        Place(HEAP | k as u32)
    }

    fn ring(node: u32) -> Place {
        Place(RING | node)
    }

    fn overflow(node: u32) -> Place {
        Place(OVERFLOW | node)
    }

    fn tag(self) -> u32 {
        self.0 & TAG
    }

    fn index(self) -> u32 {
        self.0 & !TAG
    }
}

/// What the calendar reads and writes in the caller's per-ball records.
pub trait Entries {
    /// Ball `i`'s queued key (an infinite time: not queued).
    fn key(&self, i: u32) -> &Key;
    /// Where ball `i`'s entry is.
    fn place(&self, i: u32) -> Place;
    /// Records where ball `i`'s entry is.
    fn set_place(&mut self, i: u32, place: Place);
    /// Ball `i`'s bucket has just been opened: its event comes up soon (a hint for prefetching).
    fn opened(&self, _i: u32) {}
}

/// A bucket list node: a ball and the next node.
#[derive(Clone, Copy, Debug)]
struct Node {
    ball: u32,
    next: u32,
}

/// The calendar queue. It stores ball indices and reaches their keys through [`Entries`].
#[derive(Clone, Debug)]
pub struct Calendar {
    inv_width: f64,
    mask: u64,
    base: i64,
    head: Vec<u32>,
    overflow: u32,
    /// Live entries in the ring.
    in_ring: usize,
    nodes: Vec<Node>,
    /// The first recycled node (linked through `next`).
    free: u32,
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
            nodes: Vec::with_capacity(n),
            free: NIL,
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

    /// Sets ball `i`'s event to its current key (replacing any earlier one).
    #[inline]
    pub fn set<E: Entries + ?Sized>(&mut self, e: &mut E, i: u32) {
        self.remove(e, i);
        self.insert(e, i);
    }

    fn insert<E: Entries + ?Sized>(&mut self, e: &mut E, i: u32) {
        let t = e.key(i).t;
        if !t.is_finite() {
            return;
        }
        let b = self.bucket(t);
        if b <= self.base {
            self.heap_push(e, i);
        } else if b - self.base < self.ring_len() {
            let slot = (b as u64 & self.mask) as usize;
            let node = self.node(i, self.head[slot]);
            self.head[slot] = node;
            e.set_place(i, Place::ring(node));
            self.in_ring += 1;
        } else {
            let node = self.node(i, self.overflow);
            self.overflow = node;
            e.set_place(i, Place::overflow(node));
        }
    }

    /// A node for ball `i` in front of `next`, recycled where one is free.
    #[inline]
    fn node(&mut self, ball: u32, next: u32) -> u32 {
        let node = Node { ball, next };
        if self.free == NIL {
            self.nodes.push(node);
            let k = self.nodes.len() as u32 - 1;
            assert!(k < HEAP, "calendar nodes exhausted");
            k
        } else {
            let k = self.free;
            self.free = self.nodes[k as usize].next;
            self.nodes[k as usize] = node;
            k
        }
    }

    #[inline]
    fn recycle(&mut self, node: u32) {
        self.nodes[node as usize].next = self.free;
        self.free = node;
    }

    /// Takes ball `i`'s entry out: at once from the heap, lazily from a list.
    fn remove<E: Entries + ?Sized>(&mut self, e: &mut E, i: u32) {
        let p = e.place(i);
        match p.tag() {
            HEAP => self.heap_remove(e, p.index() as usize),
            RING => self.in_ring -= 1,
            _ => {}
        }
        e.set_place(i, Place::NOWHERE);
    }

    /// The ball with the earliest event, or `None` if no ball has one.
    #[inline]
    pub fn first<E: Entries + ?Sized>(&mut self, e: &mut E) -> Option<u32> {
        while self.heap.is_empty() {
            if !self.advance(e) {
                return None;
            }
        }
        Some(self.heap[0])
    }

    /// Moves to the next bucket with entries; false when the calendar is empty.
    fn advance<E: Entries + ?Sized>(&mut self, e: &mut E) -> bool {
        if self.in_ring == 0 {
            // jump straight to the earliest live overflow entry
            let mut k = self.overflow;
            let mut earliest = i64::MAX;
            while k != NIL {
                let Node { ball, next } = self.nodes[k as usize];
                if e.place(ball) == Place::overflow(k) {
                    earliest = earliest.min(self.bucket(e.key(ball).t));
                }
                k = next;
            }
            if earliest == i64::MAX {
                self.drop_overflow();
                return false;
            }
            self.base = earliest - 1;
        }
        self.base += 1;
        if self.base & self.mask as i64 == 0 || self.in_ring == 0 {
            self.pull_overflow(e);
        }
        let slot = (self.base as u64 & self.mask) as usize;
        let mut k = self.head[slot];
        self.head[slot] = NIL;
        while k != NIL {
            let Node { ball, next } = self.nodes[k as usize];
            if e.place(ball) == Place::ring(k) {
                self.in_ring -= 1;
                e.opened(ball);
                self.heap_push(e, ball);
            }
            self.recycle(k);
            k = next;
        }
        true
    }

    /// Recycles every node of the overflow list (all of them dead).
    fn drop_overflow(&mut self) {
        let mut k = self.overflow;
        self.overflow = NIL;
        while k != NIL {
            let next = self.nodes[k as usize].next;
            self.recycle(k);
            k = next;
        }
    }

    /// Moves overflow entries that now fall inside the ring's window into it, and drops dead ones.
    fn pull_overflow<E: Entries + ?Sized>(&mut self, e: &mut E) {
        let mut k = self.overflow;
        self.overflow = NIL;
        while k != NIL {
            let Node { ball, next } = self.nodes[k as usize];
            if e.place(ball) != Place::overflow(k) {
                self.recycle(k);
            } else if self.bucket(e.key(ball).t) - self.base < self.ring_len() {
                self.recycle(k);
                e.set_place(ball, Place::NOWHERE);
                self.insert(e, ball);
            } else {
                self.nodes[k as usize].next = self.overflow;
                self.overflow = k;
            }
            k = next;
        }
    }

    #[inline]
    fn less<E: Entries + ?Sized>(e: &E, a: u32, b: u32) -> bool {
        let (ka, kb) = (e.key(a), e.key(b));
        match ka.t.total_cmp(&kb.t) {
            Ordering::Less => true,
            Ordering::Greater => false,
            Ordering::Equal => ka.path < kb.path,
        }
    }

    fn heap_push<E: Entries + ?Sized>(&mut self, e: &mut E, i: u32) {
        self.heap.push(i);
        let k = self.heap.len() - 1;
        e.set_place(i, Place::heap(k));
        self.sift_up(e, k);
    }

    fn heap_remove<E: Entries + ?Sized>(&mut self, e: &mut E, k: usize) {
        let last = self.heap.pop().expect("the entry is in the heap");
        if k < self.heap.len() {
            self.heap[k] = last;
            e.set_place(last, Place::heap(k));
            let k = self.sift_up(e, k);
            self.sift_down(e, k);
        }
    }

    fn sift_up<E: Entries + ?Sized>(&mut self, e: &mut E, mut k: usize) -> usize {
        while k > 0 {
            let p = (k - 1) / 2;
            if Self::less(e, self.heap[k], self.heap[p]) {
                self.swap(e, k, p);
                k = p;
            } else {
                break;
            }
        }
        k
    }

    fn sift_down<E: Entries + ?Sized>(&mut self, e: &mut E, mut k: usize) {
        loop {
            let (l, r) = (2 * k + 1, 2 * k + 2);
            let mut m = k;
            if l < self.heap.len() && Self::less(e, self.heap[l], self.heap[m]) {
                m = l;
            }
            if r < self.heap.len() && Self::less(e, self.heap[r], self.heap[m]) {
                m = r;
            }
            if m == k {
                return;
            }
            self.swap(e, k, m);
            k = m;
        }
    }

    #[inline]
    fn swap<E: Entries + ?Sized>(&mut self, e: &mut E, a: usize, b: usize) {
        self.heap.swap(a, b);
        e.set_place(self.heap[a], Place::heap(a));
        e.set_place(self.heap[b], Place::heap(b));
    }

    /// Bytes of memory held.
    pub fn memory_bytes(&self) -> usize {
        4 * (self.head.len() + self.heap.capacity())
            + std::mem::size_of::<Node>() * self.nodes.capacity()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vtime::pair;
    use proptest::prelude::*;

    /// Keys and places in plain vectors.
    struct Plain {
        keys: Vec<Key>,
        places: Vec<Place>,
    }

    impl Entries for Plain {
        fn key(&self, i: u32) -> &Key {
            &self.keys[i as usize]
        }
        fn place(&self, i: u32) -> Place {
            self.places[i as usize]
        }
        fn set_place(&mut self, i: u32, place: Place) {
            self.places[i as usize] = place;
        }
    }

    proptest! {
        /// Any sequence of sets and pops yields balls in exact key order, like a sorted list,
        /// and dead nodes are recycled: the pool never outgrows the sets made.
        #[test]
        fn pops_in_key_order(
            n in 1usize..40,
            ops in proptest::collection::vec((0u32..40, 0.0..50.0f64, 0u32..3, any::<bool>()), 1..300),
            gap in 0.01..10.0f64,
        ) {
            let mut e = Plain {
                keys: (0..n).map(|_| Key::at(f64::INFINITY, 0)).collect(),
                places: vec![Place::NOWHERE; n],
            };
            let mut cal = Calendar::new(n, 0.0, gap);
            let mut now = 0.0f64;
            let mut sets = 0;
            for (i, dt, tie, pop) in ops {
                let i = i % n as u32;
                if pop {
                    let want = (0..n as u32)
                        .filter(|&b| e.keys[b as usize].t.is_finite())
                        .min_by(|&a, &b| e.keys[a as usize].cmp(&e.keys[b as usize]));
                    let got = cal.first(&mut e);
                    prop_assert_eq!(
                        got.map(|g| e.keys[g as usize].clone()),
                        want.map(|w| e.keys[w as usize].clone())
                    );
                    if let Some(g) = got {
                        now = e.keys[g as usize].t;
                        e.keys[g as usize] = Key::at(f64::INFINITY, 0);
                        cal.set(&mut e, g);
                    }
                } else {
                    // times never go before the last popped one, as in a simulation
                    let t = if tie == 0 { now } else { now + (dt * tie as f64).round() / 4.0 };
                    e.keys[i as usize] = Key::at(t, pair(i, 100 + tie));
                    cal.set(&mut e, i);
                    sets += 1;
                }
            }
            prop_assert!(cal.nodes.len() <= sets);
        }
    }

    /// Moving the same events again and again while time advances keeps the node pool at the
    /// size of the live entries plus the dead ones of one ring revolution, not the sets made.
    #[test]
    fn dead_nodes_are_recycled() {
        let n = 64;
        let mut e = Plain {
            keys: (0..n).map(|i| Key::at(1.0 + i as f64, 0)).collect(),
            places: vec![Place::NOWHERE; n],
        };
        let mut cal = Calendar::new(n, 0.0, 1.0 / n as f64);
        for i in 0..n as u32 {
            cal.set(&mut e, i);
        }
        for _ in 0..100_000 {
            let g = cal.first(&mut e).expect("every ball is queued");
            let t = e.keys[g as usize].t;
            // the popped ball and a neighbour are rescheduled a little later
            for b in [g, (g + 1) % n as u32] {
                e.keys[b as usize] = Key::at(t + 0.5 + f64::from(b) / n as f64, 0);
                cal.set(&mut e, b);
            }
        }
        assert!(cal.nodes.len() < 4 * n, "{} nodes", cal.nodes.len());
    }
}
