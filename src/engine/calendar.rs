//! The pending-event set of the event-list engine: a calendar queue with one entry per ball.
//!
//! Time is cut into buckets of a fixed width; a ring of buckets covers the near future and an
//! overflow list holds the rest. Only the opened buckets are kept ordered, in a small binary heap
//! indexed by ball, so inserting, moving and removing a ball's event cost O(1) memory touches,
//! however many balls there are (the O(1) queue of G. Paul, J. Comput. Phys. 221, 2007). A
//! tournament tree over a million balls costs some twenty cache misses per update instead.
//!
//! A bucket is half a cache line holding the balls of up to six entries, with more
//! chained to it in chunks of the same size, and an entry is removed lazily: moving a ball's
//! event only forgets the entry it had (the ball's [`Place`] no longer names it), and the dead
//! entry is dropped when its bucket comes up. The calendar reads a ball's own record (its place
//! and time) only when the ball's bucket is opened, and to break a tie in time; the heap and the
//! overflow list keep the times of their entries.
//!
//! At a million balls the buckets and the balls' records are far apart in memory, and the queue
//! is laid out so that no trip there stalls the engine:
//! - a new entry is written into its bucket a few insertions later, once the bucket's line,
//!   asked for at once, has arrived (an entry due in a bucket being opened is written first);
//! - buckets are asked for a few buckets before they are opened, and opened one or two buckets
//!   ahead of the events being run; each ball found in one is announced at three successive
//!   events ([`Entries::opened`], [`Entries::approaching`], [`Entries::imminent`]), and its
//!   entry is checked only at the second, so that its record, then the records its event will
//!   read, then the records those lead to are loaded before they are needed.
//!
//! The order is exactly the virtual-time order: a bucket holds events by time only, and the heap
//! orders the opened buckets by full [`Key`], so ties within an instant come out as DESIGN.md
//! says whatever the bucket width.

use crate::vtime::Key;
use pdes_kernel::prefetch::prefetch;
use std::cmp::Ordering;
use std::collections::VecDeque;

const NIL: u32 = u32::MAX;

/// Insertions a new entry waits before it is written into its bucket.
const WRITE_DELAY: usize = 8;

/// Entries the heap holds before no further bucket is opened ahead of time.
const AHEAD: usize = 8;

/// Buckets between the one being opened and the one asked for.
const PREFETCH_BUCKETS: i64 = 4;

/// A ring larger than this many bytes is taken to be out of cache.
const FAR_BYTES: usize = 64 << 10;

/// Entries per chunk (half a cache line).
const PER_CHUNK: usize = 6;

/// Entries (live or dead) a bucket should receive: most buckets then fit in their first chunk.
/// The width is set again when the rate of insertions makes it stray out of [`FEW`, `MANY`].
const TARGET: f64 = 3.0;
const FEW: f64 = 0.75;
const MANY: f64 = 6.0;

/// Ring places from this index on name entries not yet written into their buckets.
const WAITING: u32 = 1 << 29;

/// Where a ball's entry is, packed in one word the caller keeps with the ball: not queued, in
/// the heap at an index, in a ring bucket at an entry (chunk and position, or a mark while it
/// waits to be written), or in the overflow list at an index.
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

    fn ring(entry: u32) -> Place {
        Place(RING | entry)
    }

    fn overflow(k: usize) -> Place {
        Place(OVERFLOW | k as u32)
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
    /// An entry of ball `i` was found in a bucket being opened: its record will be read at the
    /// next event (a hint to start loading it).
    fn opened(&self, _i: u32) {}
    /// Ball `i`'s event comes up in a few events, and its record is at hand (a hint to start
    /// loading what its event will read).
    fn approaching(&self, _i: u32) {}
    /// The next event after [`Entries::approaching`]: what that asked for is at hand (a hint to
    /// start loading what it leads to, such as the balls in the cells it asked for).
    fn imminent(&self, _i: u32) {}
}

/// Up to six entries of a bucket in half a cache line, and the chunk with its further entries.
/// An entry is only a ball: its time is read from the ball's record, which is loaded anyway to
/// check the entry.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
struct Chunk {
    ball: [u32; PER_CHUNK],
    len: u32,
    more: u32,
}

const EMPTY: Chunk = Chunk {
    ball: [0; PER_CHUNK],
    len: 0,
    more: NIL,
};

/// A heap entry: an event's time and its ball.
#[derive(Clone, Copy, Debug)]
struct Item {
    t: f64,
    ball: u32,
}

/// An entry waiting to be written into its bucket.
#[derive(Clone, Copy, Debug)]
struct Waiting {
    ball: u32,
    slot: u32,
    /// The ball's place while it waits.
    mark: u32,
}

/// The calendar queue. It stores ball indices (with their times in the heap and the overflow
/// list), and reaches the balls' records through [`Entries`] for their places and times.
#[derive(Clone, Debug)]
pub struct Calendar {
    inv_width: f64,
    mask: u64,
    /// The last opened bucket: every live entry of it and of earlier buckets is in the heap.
    base: i64,
    /// The ring's buckets (the first `mask + 1` chunks), then chunks chained to them.
    chunks: Vec<Chunk>,
    /// The first free chained chunk (linked through `more`).
    free: u32,
    /// Live entries in the ring.
    in_ring: usize,
    overflow: Vec<(f64, u32)>,
    heap: Vec<Item>,
    /// Entries not yet written into their buckets, oldest first.
    waiting: VecDeque<Waiting>,
    /// Whether the ring is too large for the cache, so that entries wait before they are
    /// written and opened buckets before they are sorted (in cache, waiting costs more than
    /// it saves).
    far: bool,
    /// Counter of the marks of waiting entries.
    marks: u32,
    /// The entries of bucket `base`, opened but not yet sorted into live and dead: ball and
    /// entry.
    staged: Vec<(u32, u32)>,
    /// Balls announced as approaching at the last call of [`Calendar::first`].
    approached: Vec<u32>,
    /// The chained chunks of bucket `base`, freed once it is sorted.
    staged_chunks: Vec<u32>,
    /// Calls to [`Calendar::first`] and insertions since the rate was last measured, and the
    /// earliest time then.
    calls: u64,
    sets: u64,
    since: f64,
}

impl Calendar {
    /// A calendar for `n` balls, starting at time `start`, whose events are about `mean_gap`
    /// apart in time overall (a bucket is three mean gaps wide; the ring holds `2n` to `4n`
    /// buckets: its memory is a large share of the engine's, and `n` to `2n` ran 8 % slower at
    /// 10^6 disks).
    pub fn new(n: usize, start: f64, mean_gap: f64) -> Calendar {
        let buckets = (2 * n).next_power_of_two().clamp(16, 1 << 23);
        let width = if mean_gap.is_finite() && mean_gap > 0.0 {
            TARGET * mean_gap
        } else {
            1.0
        };
        let inv_width = 1.0 / width;
        Calendar {
            inv_width,
            mask: buckets as u64 - 1,
            base: (start * inv_width).floor() as i64,
            chunks: {
                // room for chained chunks from the start: growing the ring's vector later
                // would hold two copies of it at once
                let mut chunks = Vec::with_capacity(buckets + buckets / 8 + 16);
                chunks.resize(buckets, EMPTY);
                chunks
            },
            free: NIL,
            in_ring: 0,
            overflow: Vec::new(),
            heap: Vec::new(),
            waiting: VecDeque::with_capacity(WRITE_DELAY + 1),
            far: buckets * std::mem::size_of::<Chunk>() > FAR_BYTES,
            marks: 0,
            staged: Vec::new(),
            staged_chunks: Vec::new(),
            approached: Vec::new(),
            calls: 0,
            sets: 0,
            since: start,
        }
    }

    /// A calendar of a single bucket, all of it in the heap: for a first pass, before the
    /// spacing of the events is known.
    pub fn heap_only(start: f64) -> Calendar {
        let mut c = Calendar::new(0, start, 1.0);
        c.inv_width = 0.0;
        c.base = 0;
        c
    }

    #[inline]
    fn bucket(&self, t: f64) -> i64 {
        // floor without a call into libm (x86-64 has no rounding instruction by default)
        let x = t * self.inv_width;
        let i = x as i64;
        i - i64::from((i as f64) > x)
    }

    #[inline]
    fn ring_len(&self) -> i64 {
        self.mask as i64 + 1
    }

    #[inline]
    fn slot(&self, b: i64) -> u32 {
        (b as u64 & self.mask) as u32
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
        self.sets += 1;
        let b = self.bucket(t);
        if b <= self.base {
            self.heap_push(e, Item { t, ball: i });
        } else if b - self.base < self.ring_len() {
            let slot = self.slot(b);
            let mark = WAITING | (self.marks & (WAITING - 1));
            self.marks = self.marks.wrapping_add(1);
            e.set_place(i, Place::ring(mark));
            self.in_ring += 1;
            let w = Waiting {
                ball: i,
                slot,
                mark,
            };
            if !self.far {
                self.write(e, w);
                return;
            }
            if self.waiting.len() == WRITE_DELAY {
                let w = self.waiting.pop_front().expect("a full queue");
                self.write(e, w);
            }
            prefetch(&self.chunks[slot as usize]);
            self.waiting.push_back(w);
        } else {
            e.set_place(i, Place::overflow(self.overflow.len()));
            self.overflow.push((t, i));
        }
    }

    /// Writes a waiting entry into its bucket, unless its ball has moved on meanwhile.
    fn write<E: Entries + ?Sized>(&mut self, e: &mut E, w: Waiting) {
        if e.place(w.ball) != Place::ring(w.mark) {
            return;
        }
        let slot = w.slot as usize;
        let mut c = slot;
        if self.chunks[slot].len as usize == PER_CHUNK {
            let more = self.chunks[slot].more;
            c = if more != NIL && (self.chunks[more as usize].len as usize) < PER_CHUNK {
                more as usize
            } else {
                let fresh = self.chain(more);
                self.chunks[slot].more = fresh;
                fresh as usize
            };
        }
        let chunk = &mut self.chunks[c];
        let k = chunk.len as usize;
        chunk.ball[k] = w.ball;
        chunk.len += 1;
        let entry = (c * PER_CHUNK + k) as u32;
        assert!(entry < WAITING, "calendar entries exhausted");
        e.set_place(w.ball, Place::ring(entry));
    }

    /// An empty chained chunk in front of `more`, recycled where one is free.
    fn chain(&mut self, more: u32) -> u32 {
        let chunk = Chunk { more, ..EMPTY };
        if self.free == NIL {
            if self.chunks.len() == self.chunks.capacity() {
                // grow by an eighth of the ring, not by doubling it: chained chunks are few,
                // and the ring may be most of the engine's memory
                self.chunks.reserve_exact(self.ring_len() as usize / 8 + 16);
            }
            self.chunks.push(chunk);
            self.chunks.len() as u32 - 1
        } else {
            let k = self.free;
            self.free = self.chunks[k as usize].more;
            self.chunks[k as usize] = chunk;
            k
        }
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
        for &b in &self.approached {
            e.imminent(b);
        }
        self.approached.clear();
        self.sort_staged(e);
        self.calls += 1;
        if self.calls >= (self.ring_len() as u64 / 16).max(1024) {
            self.measure(e);
        }
        // open buckets ahead while the ring has entries, so that balls are announced early
        let ahead = if self.far { AHEAD } else { 1 };
        while self.heap.len() < ahead && (self.heap.is_empty() || self.in_ring > 0) {
            if !self.advance(e) {
                break;
            }
            // the opened bucket waits for the next call unless the heap has nothing before it
            if !self.far
                || self
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
    /// empty): stages its entries and announces their balls; false when nothing is queued in
    /// the ring or the overflow list.
    fn advance<E: Entries + ?Sized>(&mut self, e: &mut E) -> bool {
        if self.in_ring == 0 {
            let earliest = Self::live_overflow(&self.overflow, e)
                .map(|(t, _)| self.bucket(t))
                .min();
            let Some(earliest) = earliest else {
                self.overflow.clear();
                return false;
            };
            self.base = earliest - 1;
        }
        self.base += 1;
        if self.base & self.mask as i64 == 0 || self.in_ring == 0 {
            self.pull_overflow(e);
        }
        let slot = self.slot(self.base);
        let mut k = 0;
        while k < self.waiting.len() {
            if self.waiting[k].slot == slot {
                let w = self.waiting.remove(k).expect("an index in range");
                self.write(e, w);
            } else {
                k += 1;
            }
        }
        prefetch(&self.chunks[self.slot(self.base + PREFETCH_BUCKETS) as usize]);
        let mut c = slot as usize;
        loop {
            let chunk = self.chunks[c];
            for k in 0..chunk.len as usize {
                if self.far {
                    e.opened(chunk.ball[k]);
                }
                let entry = (c * PER_CHUNK + k) as u32;
                self.staged.push((chunk.ball[k], entry));
            }
            if c != slot as usize {
                self.staged_chunks.push(c as u32);
            }
            if chunk.more == NIL {
                break;
            }
            c = chunk.more as usize;
        }
        self.chunks[slot as usize].len = 0;
        self.chunks[slot as usize].more = NIL;
        true
    }

    /// Measures how many entries a bucket receives at the rate of insertions since the last
    /// measure, and sets the width again if that strays too far from [`TARGET`].
    fn measure<E: Entries + ?Sized>(&mut self, e: &mut E) {
        let Some(now) = self.heap.first().map(|it| it.t) else {
            return;
        };
        let dt = now - self.since;
        if dt > 0.0 && self.sets > 0 && self.inv_width > 0.0 {
            let per_bucket = self.sets as f64 / (dt * self.inv_width);
            if !(FEW..=MANY).contains(&per_bucket) {
                self.rebuild(e, TARGET / per_bucket);
            }
        }
        self.calls = 0;
        self.sets = 0;
        self.since = now;
    }

    /// Sets the bucket width to `factor` times what it is and queues the ring's and the
    /// overflow list's live entries again (the heap keeps its own: the opened time stays
    /// opened). Called with nothing staged.
    fn rebuild<E: Entries + ?Sized>(&mut self, e: &mut E, factor: f64) {
        while let Some(w) = self.waiting.pop_front() {
            self.write(e, w);
        }
        let mut live = Vec::with_capacity(self.in_ring + self.overflow.len());
        for (c, chunk) in self.chunks.iter().enumerate() {
            for k in 0..chunk.len as usize {
                let ball = chunk.ball[k];
                if e.place(ball) == Place::ring((c * PER_CHUNK + k) as u32) {
                    live.push(ball);
                }
            }
        }
        live.extend(Self::live_overflow(&self.overflow, e).map(|(_, ball)| ball));
        // everything before the end of bucket `base` is opened, and stays so
        let opened_until = (self.base + 1) as f64 / self.inv_width;
        self.inv_width /= factor.clamp(1.0 / 64.0, 64.0);
        self.base = self.bucket(opened_until);
        self.chunks.truncate(self.ring_len() as usize);
        self.chunks.fill(EMPTY);
        self.free = NIL;
        self.overflow.clear();
        self.in_ring = 0;
        for ball in live {
            e.set_place(ball, Place::NOWHERE);
            self.insert(e, ball);
        }
    }

    /// Moves the staged entries that are still live into the heap, and frees the staged
    /// chunks (only here, so that a staged entry cannot be taken for a newer one).
    fn sort_staged<E: Entries + ?Sized>(&mut self, e: &mut E) {
        let mut staged = std::mem::take(&mut self.staged);
        for &(ball, entry) in &staged {
            if e.place(ball) == Place::ring(entry) {
                let t = e.key(ball).t;
                self.in_ring -= 1;
                if self.far {
                    e.approaching(ball);
                    self.approached.push(ball);
                }
                self.heap_push(e, Item { t, ball });
            }
        }
        staged.clear();
        self.staged = staged;
        for k in 0..self.staged_chunks.len() {
            let c = self.staged_chunks[k];
            self.chunks[c as usize].more = self.free;
            self.free = c;
        }
        self.staged_chunks.clear();
    }

    /// The entries of an overflow list that are still their balls' (time and ball).
    fn live_overflow<'a, E: Entries + ?Sized>(
        overflow: &'a [(f64, u32)],
        e: &'a E,
    ) -> impl Iterator<Item = (f64, u32)> + 'a {
        overflow
            .iter()
            .enumerate()
            .filter(move |&(k, &(_, ball))| e.place(ball) == Place::overflow(k))
            .map(|(_, &entry)| entry)
    }

    /// Moves the overflow entries that now fall within the ring into it.
    fn pull_overflow<E: Entries + ?Sized>(&mut self, e: &mut E) {
        let old = std::mem::take(&mut self.overflow);
        let live: Vec<(f64, u32)> = Self::live_overflow(&old, e).collect();
        for (t, ball) in live {
            if self.bucket(t) - self.base < self.ring_len() {
                e.set_place(ball, Place::NOWHERE);
                self.insert(e, ball);
            } else {
                e.set_place(ball, Place::overflow(self.overflow.len()));
                self.overflow.push((t, ball));
            }
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
        size_of::<Chunk>() * self.chunks.capacity()
            + size_of::<(f64, u32)>() * self.overflow.capacity()
            + size_of::<Item>() * self.heap.capacity()
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
        /// and chained chunks never outnumber the sets made.
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
            prop_assert!(cal.chunks.len() <= cal.ring_len() as usize + sets);
        }
    }

    /// Moving the same events again and again while time advances keeps the chained chunks
    /// fewer than the balls, not growing with the sets made.
    #[test]
    fn chained_chunks_are_recycled() {
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
        let chained = cal.chunks.len() - cal.ring_len() as usize;
        assert!(chained < n, "{chained} chained chunks");
    }

    /// A calendar set up with a mean gap far from the true one finds its width again, and
    /// still yields events in exact key order before and after.
    #[test]
    fn width_adapts_to_the_traffic() {
        for wrong in [1e-3, 1e3] {
            let n = 256;
            let mut rng = 12345u64;
            let mut next = move || {
                rng = rng
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (rng >> 11) as f64 / (1u64 << 53) as f64
            };
            let mut e = Plain {
                keys: (0..n)
                    .map(|i| Key::at(next() * 2.0, pair(i as u32, 1000)))
                    .collect(),
                places: vec![Place::NOWHERE; n],
            };
            // the true mean gap is about 1 / n
            let mut cal = Calendar::new(n, 0.0, wrong / n as f64);
            let before = cal.inv_width;
            for i in 0..n as u32 {
                cal.set(&mut e, i);
            }
            for _ in 0..200_000 {
                let want = (0..n as u32)
                    .min_by(|&a, &b| e.keys[a as usize].cmp(&e.keys[b as usize]))
                    .expect("balls");
                let got = cal.first(&mut e).expect("every ball is queued");
                assert_eq!(e.keys[got as usize], e.keys[want as usize]);
                let t = e.keys[got as usize].t + next() * 2.0;
                e.keys[got as usize] = Key::at(t, pair(got, 1000));
                cal.set(&mut e, got);
            }
            let ratio = cal.inv_width / before;
            assert!(
                if wrong > 1.0 {
                    ratio > 10.0
                } else {
                    ratio < 0.1
                },
                "width ratio {ratio}"
            );
        }
    }
}
