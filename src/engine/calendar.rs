//! The pending-event set of the event-list engine: a calendar queue with one entry per ball.
//!
//! Time is cut into buckets of a fixed width; a ring of buckets covers the near future and an
//! overflow list holds the rest. Only the opened buckets are kept ordered, in a small binary heap
//! indexed by ball, so inserting, moving and removing a ball's event cost O(1) memory touches,
//! however many balls there are (the O(1) queue of G. Paul, J. Comput. Phys. 221, 2007). A
//! tournament tree over a million balls costs some twenty cache misses per update instead.
//!
//! Buckets are singly linked lists of small nodes that carry their event's time, and an entry is
//! removed lazily: moving a ball's event only forgets the node it had (the ball's place, kept
//! here in one compact array, no longer names it), and the dead node is dropped when its bucket
//! comes up. So the calendar never reads a ball's own record, except to break a tie in time.
//!
//! At a million balls the ring's heads and the balls' records are far apart in memory, and the
//! queue is laid out so that no trip there stalls the engine:
//! - a new node is linked into its bucket a few insertions later, once the bucket's head, asked
//!   for at once, has arrived (a node due in a bucket being opened is linked first);
//! - buckets are opened one or two ahead of the events being run, and each ball found there is
//!   announced twice to the caller ([`Entries::opened`], [`Entries::approaching`]), so that its
//!   records and then the records its event will read are loaded before it comes up.
//!
//! The order is exactly the virtual-time order: a bucket holds events by time only, and the heap
//! orders the opened buckets by full [`Key`], so ties within an instant come out as DESIGN.md
//! says whatever the bucket width.

use super::prefetch::prefetch;
use crate::vtime::Key;
use std::cmp::Ordering;
use std::collections::VecDeque;

const NIL: u32 = u32::MAX;

/// Insertions a new node waits before it is linked into its bucket.
const LINK_DELAY: usize = 8;

/// Entries the heap holds before no further bucket is opened ahead of time.
const AHEAD: usize = 8;

/// Where a ball's entry is, packed in one word the caller keeps with the ball: not queued, in
/// the heap at an index, or in a ring bucket or the overflow list at a node.
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

/// What the calendar reads and writes in the caller's per-ball records, and the hints it gives.
pub trait Entries {
    /// Ball `i`'s queued key (an infinite time: not queued).
    fn key(&self, i: u32) -> &Key;
    /// Where ball `i`'s entry is.
    fn place(&self, i: u32) -> Place;
    /// Records where ball `i`'s entry is.
    fn set_place(&mut self, i: u32, place: Place);
    /// A node of ball `i` was found in a bucket being opened: its record will be read at the
    /// next event (a hint to start loading it).
    fn opened(&self, _i: u32) {}
    /// Ball `i`'s event comes up in a few events, and its record is at hand (a hint to start
    /// loading what its event will read).
    fn approaching(&self, _i: u32) {}
}

/// A bucket list node: an event's time, its ball and the next node.
#[derive(Clone, Copy, Debug)]
struct Node {
    t: f64,
    ball: u32,
    next: u32,
}

/// A heap entry: an event's time and its ball.
#[derive(Clone, Copy, Debug)]
struct Item {
    t: f64,
    ball: u32,
}

/// The calendar queue. It stores ball indices and their times, and reaches their keys through
/// [`Entries`] only to break ties.
#[derive(Clone, Debug)]
pub struct Calendar {
    inv_width: f64,
    mask: u64,
    /// The last opened bucket: every entry of it and of earlier buckets is in the heap.
    base: i64,
    head: Vec<u32>,
    overflow: u32,
    /// Live entries in the ring.
    in_ring: usize,
    nodes: Vec<Node>,
    /// The first recycled node (linked through `next`).
    free: u32,
    heap: Vec<Item>,
    /// Ring nodes not yet linked, with their buckets' slots, oldest first.
    unlinked: VecDeque<(u32, u32)>,
    /// The nodes of bucket `base`, opened but not yet sorted into live and dead.
    staged: Vec<u32>,
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
            unlinked: VecDeque::with_capacity(LINK_DELAY + 1),
            staged: Vec::new(),
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
            self.heap_push(e, Item { t, ball: i });
        } else if b - self.base < self.ring_len() {
            let slot = (b as u64 & self.mask) as u32;
            let node = self.node(t, i, NIL);
            e.set_place(i, Place::ring(node));
            self.in_ring += 1;
            if self.unlinked.len() == LINK_DELAY {
                let (n, s) = self.unlinked.pop_front().expect("a full queue");
                self.link(n, s);
            }
            prefetch(&self.head[slot as usize]);
            self.unlinked.push_back((node, slot));
        } else {
            let node = self.node(t, i, self.overflow);
            self.overflow = node;
            e.set_place(i, Place::overflow(node));
        }
    }

    /// Puts node `n` at the front of the bucket at `slot`.
    #[inline]
    fn link(&mut self, n: u32, slot: u32) {
        self.nodes[n as usize].next = self.head[slot as usize];
        self.head[slot as usize] = n;
    }

    /// A node for ball `i` at time `t` in front of `next`, recycled where one is free.
    #[inline]
    fn node(&mut self, t: f64, ball: u32, next: u32) -> u32 {
        let node = Node { t, ball, next };
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

    fn remove<E: Entries + ?Sized>(&mut self, e: &mut E, i: u32) {
        let p = e.place(i);
        match p.tag() {
            HEAP => self.heap_remove(e, p.index() as usize),
            RING => self.in_ring -= 1,
            _ => {}
        }
        e.set_place(i, Place::NOWHERE);
    }

    /// The ball with the earliest key, if any (it stays queued until it is set again).
    #[inline]
    pub fn first<E: Entries + ?Sized>(&mut self, e: &mut E) -> Option<u32> {
        self.sort_staged(e);
        // open buckets ahead while the ring has entries, so that balls are announced early
        while self.heap.len() < AHEAD && (self.heap.is_empty() || self.in_ring > 0) {
            if !self.advance(e) {
                break;
            }
            // the opened bucket waits for the next call unless the heap has nothing before it
            if self
                .heap
                .first()
                .is_none_or(|top| self.bucket(top.t) >= self.base)
            {
                self.sort_staged(e);
            } else {
                break;
            }
        }
        self.heap.first().map(|it| it.ball)
    }

    /// Opens the next bucket (skipping ahead to the overflow list's earliest when the ring is
    /// empty): stages its nodes and announces their balls; false when nothing is queued in the
    /// ring or the overflow list.
    fn advance<E: Entries + ?Sized>(&mut self, e: &mut E) -> bool {
        if self.in_ring == 0 {
            let mut k = self.overflow;
            let mut earliest = i64::MAX;
            while k != NIL {
                let Node { t, ball, next } = self.nodes[k as usize];
                if e.place(ball) == Place::overflow(k) {
                    earliest = earliest.min(self.bucket(t));
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
        let slot = (self.base as u64 & self.mask) as u32;
        let mut k = 0;
        while k < self.unlinked.len() {
            if self.unlinked[k].1 == slot {
                let (n, s) = self.unlinked.remove(k).expect("an index in range");
                self.link(n, s);
            } else {
                k += 1;
            }
        }
        let mut k = self.head[slot as usize];
        self.head[slot as usize] = NIL;
        while k != NIL {
            let Node { ball, next, .. } = self.nodes[k as usize];
            e.opened(ball);
            self.staged.push(k);
            k = next;
        }
        true
    }

    /// Moves the staged nodes' live entries into the heap and recycles the nodes (a node is
    /// recycled only here, so that a staged node cannot be taken for a newer one of its ball).
    fn sort_staged<E: Entries + ?Sized>(&mut self, e: &mut E) {
        for n in std::mem::take(&mut self.staged) {
            let Node { t, ball, .. } = self.nodes[n as usize];
            if e.place(ball) == Place::ring(n) {
                self.in_ring -= 1;
                e.approaching(ball);
                self.heap_push(e, Item { t, ball });
            }
            self.recycle(n);
        }
    }

    fn drop_overflow(&mut self) {
        let mut k = self.overflow;
        self.overflow = NIL;
        while k != NIL {
            let next = self.nodes[k as usize].next;
            self.recycle(k);
            k = next;
        }
    }

    /// Moves the overflow entries that now fall within the ring into it.
    fn pull_overflow<E: Entries + ?Sized>(&mut self, e: &mut E) {
        let mut k = self.overflow;
        self.overflow = NIL;
        while k != NIL {
            let Node { t, ball, next } = self.nodes[k as usize];
            if e.place(ball) != Place::overflow(k) {
                self.recycle(k);
            } else if self.bucket(t) - self.base < self.ring_len() {
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

    /// Whether `a` comes before `b`: by time, and by the full keys on a tie.
    #[inline]
    fn less<E: Entries + ?Sized>(e: &E, a: &Item, b: &Item) -> bool {
        match a.t.total_cmp(&b.t) {
            Ordering::Less => true,
            Ordering::Greater => false,
            Ordering::Equal => e.key(a.ball).path < e.key(b.ball).path,
        }
    }

    fn heap_push<E: Entries + ?Sized>(&mut self, e: &mut E, it: Item) {
        self.heap.push(it);
        let k = self.heap.len() - 1;
        e.set_place(it.ball, Place::heap(k));
        self.sift_up(e, k);
    }

    fn heap_remove<E: Entries + ?Sized>(&mut self, e: &mut E, k: usize) {
        let last = self.heap.pop().expect("the entry is in the heap");
        if k < self.heap.len() {
            self.heap[k] = last;
            e.set_place(last.ball, Place::heap(k));
            let k = self.sift_up(e, k);
            self.sift_down(e, k);
        }
    }

    fn sift_up<E: Entries + ?Sized>(&mut self, e: &mut E, mut k: usize) -> usize {
        while k > 0 {
            let p = (k - 1) / 2;
            if Self::less(e, &self.heap[k], &self.heap[p]) {
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
            if l < self.heap.len() && Self::less(e, &self.heap[l], &self.heap[m]) {
                m = l;
            }
            if r < self.heap.len() && Self::less(e, &self.heap[r], &self.heap[m]) {
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
        e.set_place(self.heap[a].ball, Place::heap(a));
        e.set_place(self.heap[b].ball, Place::heap(b));
    }

    /// Bytes of memory held.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        4 * self.head.len()
            + size_of::<Item>() * self.heap.capacity()
            + size_of::<Node>() * self.nodes.capacity()
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
