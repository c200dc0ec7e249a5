//! The executors' pending set, in two tiers with the same order. Most messages a batch sends
//! are for the instant being run (zero-delay relays and replies); they go to the instant's tier,
//! later ones to a large heap, and the next message is the smaller of the two tiers' next.
//! Which tier an item is in never changes the order, only the cost.

use super::led_heap::LedHeap;
use super::prefetch::prefetch_all;
use dary_heap::QuaternaryHeap;

/// Run items sorted again with fresh ones however few these are (beyond it, only four per fresh
/// item).
const SORT_TOGETHER: usize = 64;

/// Items sorted by their ranks ([`Ranked`]) rather than compared, from this many on.
const SORT_BY_RANK: usize = 64;

/// An item whose order among the items of one instant a few integers give: the instant's tier
/// sorts its items (a large model's set-up instant may hold millions) comparing these, not the items'
/// keys, which takes a tenth less of the set-up.
pub trait Ranked: Ord {
    /// The integers: for two items of one instant, their ranks compare as the items do.
    fn rank(&self) -> [u64; 4];
    /// Whether `self` and `o` belong to one instant.
    fn same_instant(&self, o: &Self) -> bool;
    /// An integer that never orders two items against their own order: a greater lead means
    /// a greater item, and items of equal leads compare themselves.
    fn lead(&self) -> u64;
}

/// Sorts `v` ascending: by rank when its items are many and of one instant.
fn sort<T: Ranked>(v: &mut [T]) {
    match v.first() {
        Some(first)
            if v.len() >= SORT_BY_RANK
                && u32::try_from(v.len()).is_ok()
                && v.iter().all(|x| x.same_instant(first)) =>
        {
            sort_by_rank(v)
        }
        _ => v.sort_unstable(),
    }
}

/// The smallest and the largest of some first rank words (`(u64::MAX, 0)` for none).
fn span(firsts: impl Iterator<Item = u64>) -> (u64, u64) {
    firsts.fold((u64::MAX, 0), |(lo, hi), w| (lo.min(w), hi.max(w)))
}

/// How many places ahead [`sort_part`] loads the item it will move.
const PERMUTE_AHEAD: usize = 16;

/// Items from which [`sort_by_rank`] first splits them into [`PARTS`] parts by their first rank
/// words: so many items (88 bytes each in a model with small messages) are far larger than the caches.
const SPLIT_FROM: usize = 1 << 15;

/// The parts [`sort_by_rank`] splits many items into (a power of two): each part's items lie
/// together then, and each cursor the split moves items to stays in cache.
const PARTS: usize = 256;

/// Sorts items of one instant (fewer than 2^32) by their ranks. Many items are first split in
/// place into parts by the high bits of their first rank words (an American flag sort: every
/// item is swapped once into the part it belongs to), then each part is sorted on its own, its
/// items now close together ([`sort_part`]). A large model's set-up instant may hold millions of items,
/// whose sort compared in place took a quarter of it.
fn sort_by_rank<T: Ranked>(v: &mut [T]) {
    if v.len() < SPLIT_FROM {
        sort_part(v);
        return;
    }
    let (lo, hi) = span(v.iter().map(|x| x.rank()[0]));
    if hi == lo {
        sort_part(v);
        return;
    }
    let bits = u64::BITS - (hi - lo).leading_zeros();
    let shift = bits.saturating_sub(PARTS.trailing_zeros());
    let part = |x: &T| ((x.rank()[0] - lo) >> shift) as usize;
    let mut ends = [0usize; PARTS];
    for x in v.iter() {
        ends[part(x)] += 1;
    }
    let mut next = [0usize; PARTS];
    let mut sum = 0;
    for (n, e) in next.iter_mut().zip(ends.iter_mut()) {
        *n = sum;
        sum += *e;
        *e = sum;
    }
    for b in 0..PARTS {
        while next[b] < ends[b] {
            let to = part(&v[next[b]]);
            if to != b {
                v.swap(next[b], next[to]);
            }
            next[to] += 1;
            // the part's next place, for the next item that goes there (too many parts fill
            // at once for the processor to see them as streams)
            if let Some(x) = v.get(next[to]) {
                prefetch_all(x);
            }
        }
    }
    let mut start = 0;
    for end in ends {
        sort_part(&mut v[start..end]);
        start = end;
    }
}

/// Sorts items of one instant (fewer than 2^32) by their ranks, moving each item once into
/// place. The ranks are read once; where the first words span few values (one generation's
/// items: the first word is generation and receiver), they are counted into buckets, and only
/// each bucket (one receiver's few items) is sorted by the rest.
fn sort_part<T: Ranked>(v: &mut [T]) {
    if v.len() < 2 {
        return;
    }
    let ranks: Vec<[u64; 4]> = v.iter().map(T::rank).collect();
    let (lo, hi) = span(ranks.iter().map(|r| r[0]));
    let mut order: Vec<u32>;
    if hi - lo < 4 * ranks.len() as u64 {
        let mut next = vec![0u32; (hi - lo) as usize + 2];
        for r in &ranks {
            next[(r[0] - lo) as usize + 1] += 1;
        }
        for b in 1..next.len() {
            next[b] += next[b - 1];
        }
        order = vec![0; ranks.len()];
        for (i, r) in ranks.iter().enumerate() {
            let slot = &mut next[(r[0] - lo) as usize];
            order[*slot as usize] = i as u32;
            *slot += 1;
        }
        // each bucket now ends where the next one started
        let mut start = 0;
        for &end in &next[..next.len() - 1] {
            let bucket = &mut order[start..end as usize];
            if bucket.len() > 1 {
                bucket.sort_unstable_by_key(|&i| ranks[i as usize]);
            }
            start = end as usize;
        }
    } else {
        order = (0..ranks.len() as u32).collect();
        order.sort_unstable_by_key(|&i| ranks[i as usize]);
    }
    // the item for place i is at order[i], unless an earlier swap moved it: then follow where
    // it went (as the standard library's `sort_by_cached_key` does)
    for i in 0..order.len() {
        // the items lie scattered and are large: load one a few places ahead of its turn
        if let Some(&ahead) = order.get(i + PERMUTE_AHEAD) {
            prefetch_all(&v[ahead as usize]);
        }
        let mut from = order[i] as usize;
        while from < i {
            from = order[from] as usize;
        }
        order[i] = from as u32;
        v.swap(i, from);
    }
}

/// The instant's items: a sorted run taken from its end, a small heap, and the items pushed
/// since the run was sorted. Within an instant a batch sends only to later generations, so the
/// pushed items are not needed until the run is spent; they are then sorted once. An instant of
/// millions of messages, as a large model's set-up, costs one sort instead of a heap
/// operation each. Items pushed that must come before some of the run go to the heap instead,
/// so that no order of pushes costs more than a heap would.
struct Instant<T: Ranked> {
    /// Greatest last.
    run: Vec<T>,
    side: QuaternaryHeap<T>,
    fresh: Vec<T>,
    /// The index of the greatest fresh item.
    best: Option<usize>,
}

impl<T: Ranked> Default for Instant<T> {
    fn default() -> Self {
        Instant {
            run: Vec::new(),
            side: QuaternaryHeap::new(),
            fresh: Vec::new(),
            best: None,
        }
    }
}

impl<T: Ranked> Instant<T> {
    fn push(&mut self, item: T) {
        if self.best.is_none_or(|b| item > self.fresh[b]) {
            self.best = Some(self.fresh.len());
        }
        self.fresh.push(item);
    }

    /// The greater of the run's and the heap's next items (`None` is below every item).
    fn settled_top(&self) -> Option<&T> {
        self.run.last().max(self.side.peek())
    }

    /// The greatest item held.
    fn top(&self) -> Option<&T> {
        self.settled_top().max(self.best.map(|b| &self.fresh[b]))
    }

    /// Makes the greatest item the run's or the heap's next: the fresh items are sorted into
    /// the run when it is short or spent, or go to the heap when one of them comes before a long
    /// run's rest.
    fn settle(&mut self) {
        let Some(b) = self.best else { return };
        if self.settled_top().is_some_and(|top| *top >= self.fresh[b]) {
            return;
        }
        if self.run.len() <= SORT_TOGETHER + 4 * self.fresh.len() {
            // a short run (the common case: an instant's last few messages) is sorted again
            // with the fresh items, at a cost bounded by theirs
            self.fresh.append(&mut self.run);
            sort(&mut self.fresh);
            std::mem::swap(&mut self.run, &mut self.fresh);
        } else {
            self.side.extend(self.fresh.drain(..));
        }
        self.best = None;
    }

    fn peek(&mut self) -> Option<&T> {
        self.settle();
        self.settled_top()
    }

    fn pop(&mut self) -> Option<T> {
        self.settle();
        if self.run.last() >= self.side.peek() {
            self.run.pop()
        } else {
            self.side.pop()
        }
    }

    fn len(&self) -> usize {
        self.run.len() + self.side.len() + self.fresh.len()
    }

    fn retain(&mut self, mut keep: impl FnMut(&T) -> bool) {
        self.run.retain(&mut keep);
        self.side.retain(&mut keep);
        self.fresh.retain(&mut keep);
        self.best = (0..self.fresh.len()).max_by(|&i, &j| self.fresh[i].cmp(&self.fresh[j]));
    }
}

/// Pending items, greatest first (as `BinaryHeap`: the executors reverse their order).
pub struct Queue<T: Ranked> {
    instant: Instant<T>,
    later: LedHeap<T>,
    /// Which tier the last [`Queue::peek`] found the next item in, until the items change:
    /// the executors peek at the next item before they take it.
    peeked_later: Option<bool>,
}

impl<T: Ranked> Default for Queue<T> {
    fn default() -> Self {
        Queue {
            instant: Instant::default(),
            later: LedHeap::default(),
            peeked_later: None,
        }
    }
}

impl<T: Ranked> Queue<T> {
    /// Room for `n` items in each tier without growing.
    pub fn with_capacity(n: usize) -> Queue<T> {
        Queue {
            instant: Instant {
                fresh: Vec::with_capacity(n),
                ..Instant::default()
            },
            later: LedHeap::with_capacity(n),
            peeked_later: None,
        }
    }

    /// Adds an item, to the instant's tier if it belongs to the instant being run.
    pub fn push(&mut self, item: T, in_instant: bool) {
        self.peeked_later = None;
        if in_instant {
            self.instant.push(item);
        } else {
            self.later.push(item);
        }
    }

    /// Whether the next item is the large heap's: by the leads alone, unless they are equal
    /// (the heap's next item is then read, and compared).
    fn later_first(&self) -> bool {
        let Some(lead) = self.later.peek_lead() else {
            return false;
        };
        let Some(i) = self.instant.top() else {
            return true;
        };
        match i.lead().cmp(&lead) {
            std::cmp::Ordering::Equal => self.later.peek() > Some(i),
            o => o.is_lt(),
        }
    }

    /// The next item.
    #[inline(always)]
    pub fn peek(&mut self) -> Option<&T> {
        let later = self.later_first();
        self.peeked_later = Some(later);
        if later {
            self.later.peek()
        } else {
            self.instant.peek()
        }
    }

    /// Takes the next item.
    pub fn pop(&mut self) -> Option<T> {
        let later = match self.peeked_later.take() {
            Some(later) => later,
            None => self.later_first(),
        };
        if later {
            self.later.pop()
        } else {
            self.instant.pop()
        }
    }

    /// Items held.
    pub fn len(&self) -> usize {
        self.instant.len() + self.later.len()
    }

    /// Whether none is held.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Keeps only the items `keep` accepts.
    pub fn retain(&mut self, mut keep: impl FnMut(&T) -> bool) {
        self.peeked_later = None;
        self.instant.retain(&mut keep);
        self.later.retain(&mut keep);
    }

    /// Every item held, in no particular order.
    pub fn iter(&self) -> impl Iterator<Item = &T> {
        let i = &self.instant;
        i.run
            .iter()
            .chain(i.side.iter())
            .chain(i.fresh.iter())
            .chain(self.later.iter())
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use proptest::prelude::*;

    impl Ranked for u32 {
        fn rank(&self) -> [u64; 4] {
            [u64::from(*self), 0, 0, 0]
        }
        fn same_instant(&self, _: &Self) -> bool {
            true
        }
        fn lead(&self) -> u64 {
            u64::from(*self)
        }
    }

    /// An item of instant `.0`, ordered by `.1` within it.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
    pub(crate) struct At(pub u8, pub u32);

    impl Ranked for At {
        fn rank(&self) -> [u64; 4] {
            [0, u64::from(self.1 >> 16), 0, u64::from(self.1 & 0xffff)]
        }
        fn same_instant(&self, o: &Self) -> bool {
            self.0 == o.0
        }
        fn lead(&self) -> u64 {
            u64::from(self.0)
        }
    }

    proptest! {
        /// Many items of one instant are sorted by rank, of several by comparison: either way
        /// they come out in order.
        #[test]
        fn many_items_come_out_in_order(
            values in prop::collection::vec(any::<u32>(), SORT_BY_RANK..3 * SORT_BY_RANK),
            other_instant in any::<bool>(),
        ) {
            let mut q = Queue::default();
            let mut items: Vec<At> = values.iter().map(|&v| At(1, v)).collect();
            if other_instant {
                items[0].0 = 0;
            }
            for &it in &items {
                q.push(it, true);
            }
            items.sort_unstable_by(|a, b| b.cmp(a));
            let got: Vec<At> = std::iter::from_fn(|| q.pop()).collect();
            prop_assert_eq!(got, items);
        }
    }

    /// An item of one instant whose first rank word is `.0`: few values of it sort by buckets,
    /// many by comparing the ranks.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
    struct Dense(u16, u32);

    impl Ranked for Dense {
        fn rank(&self) -> [u64; 4] {
            [u64::from(self.0), 0, u64::from(self.1), 0]
        }
        fn same_instant(&self, _: &Self) -> bool {
            true
        }
        fn lead(&self) -> u64 {
            0
        }
    }

    proptest! {
        /// Ranks whose first words are dense (bucketed) or sparse (compared) sort the same.
        #[test]
        fn ranks_sort_as_the_items_do(
            items in prop::collection::vec((any::<u16>(), 0u32..8), SORT_BY_RANK..4 * SORT_BY_RANK),
            dense in any::<bool>(),
        ) {
            let mut v: Vec<Dense> = items
                .iter()
                .map(|&(a, b)| Dense(if dense { a % 40 } else { a }, b))
                .collect();
            let mut want = v.clone();
            want.sort_unstable();
            sort(&mut v);
            prop_assert_eq!(v, want);
        }
    }

    /// So many items that they are split into parts first: with first words spread wide
    /// (sparse within each part) and narrow (bucketed), and with parts left empty.
    #[test]
    fn many_items_split_into_parts_sort_as_the_items_do() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        for spread in [u16::MAX, 4000, 3] {
            let mut v: Vec<Dense> = (0..SPLIT_FROM + 999)
                .map(|_| Dense(rng.gen_range(0..=spread), rng.gen_range(0..50)))
                .collect();
            let mut want = v.clone();
            want.sort_unstable();
            sort(&mut v);
            assert_eq!(v, want, "first words up to {spread}");
        }
    }

    proptest! {
        /// Whatever tier each item goes to, and however pushes, peeks and pops interleave,
        /// every pop takes the greatest item held.
        #[test]
        fn pops_in_order_whichever_tier(
            ops in prop::collection::vec((0u32..50, any::<bool>(), 0u8..3, any::<bool>()), 0..300),
        ) {
            let mut q = Queue::default();
            let mut held: Vec<u32> = Vec::new();
            for &(v, instant, pops, peek_first) in &ops {
                if peek_first {
                    // a peek before a push must not decide the pop after it
                    prop_assert_eq!(q.peek().copied(), held.iter().copied().max());
                }
                q.push(v, instant);
                held.push(v);
                for _ in 0..pops {
                    let want = held.iter().copied().max();
                    if let Some(w) = want {
                        let k = held.iter().position(|&h| h == w).expect("held");
                        held.swap_remove(k);
                    }
                    prop_assert_eq!(q.peek().copied(), want);
                    prop_assert_eq!(q.pop(), want);
                    prop_assert_eq!(q.len(), held.len());
                }
            }
            held.sort_unstable_by(|a, b| b.cmp(a));
            let mut got = Vec::new();
            while let Some(v) = q.pop() {
                got.push(v);
            }
            prop_assert_eq!(got, held);
            prop_assert!(q.is_empty());
        }

        /// `retain` keeps exactly the accepted items, in order, in both tiers.
        #[test]
        fn retain_keeps_the_order(
            items in prop::collection::vec((0u32..50, any::<bool>()), 0..200),
            pops in 0usize..20,
        ) {
            let mut q = Queue::default();
            for &(v, instant) in &items {
                q.push(v, instant);
            }
            let mut left: Vec<u32> = items.iter().map(|&(v, _)| v).collect();
            left.sort_unstable_by(|a, b| b.cmp(a));
            for _ in 0..pops.min(left.len()) {
                prop_assert_eq!(q.pop(), Some(left.remove(0)));
            }
            q.retain(|v| v % 3 != 0);
            left.retain(|v| v % 3 != 0);
            let got: Vec<u32> = std::iter::from_fn(|| q.pop()).collect();
            prop_assert_eq!(got, left);
        }
    }

    thread_local! {
        static COMPARISONS: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
    }

    /// A number that counts its comparisons.
    #[derive(PartialEq, Eq)]
    struct Counted(u32);

    impl PartialOrd for Counted {
        fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
            Some(self.cmp(o))
        }
    }

    impl Ord for Counted {
        fn cmp(&self, o: &Self) -> std::cmp::Ordering {
            COMPARISONS.with(|c| c.set(c.get() + 1));
            self.0.cmp(&o.0)
        }
    }

    /// Compared, never ranked: the counts are of comparisons.
    impl Ranked for Counted {
        fn rank(&self) -> [u64; 4] {
            unreachable!("never of one instant")
        }
        fn same_instant(&self, _: &Self) -> bool {
            false
        }
        fn lead(&self) -> u64 {
            0
        }
    }

    /// One instant of n items where every batch pushes items that come before the rest of the
    /// run (the receivers of each batch's sends interleave with the earlier ones): the cost stays
    /// O(n log n) comparisons, as a heap's would, never a sort of the whole run per batch.
    #[test]
    fn pushes_before_the_run_cost_no_more_than_a_heap() {
        let n = 1u32 << 14;
        let mut q = Queue::default();
        COMPARISONS.with(|c| c.set(0));
        // a first batch fills the run; each later pop is followed by pushes that precede the
        // rest of the run (greater, as the executors reverse the delivery order)
        for k in 0..64 {
            q.push(Counted(k), true);
        }
        let mut next = 64;
        let mut popped = 0;
        while let Some(Counted(_)) = q.pop() {
            popped += 1;
            if next < n {
                for _ in 0..4 {
                    q.push(Counted(n + next), true);
                    next += 1;
                }
            }
        }
        assert_eq!(popped, n);
        let per_item = COMPARISONS.with(|c| c.get()) as f64 / f64::from(n);
        assert!(
            per_item < 4.0 * f64::from(n).log2(),
            "{per_item} comparisons per item"
        );
    }
}
