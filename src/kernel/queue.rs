//! The executors' pending set, in two tiers with the same order. Most messages a batch sends
//! are for the instant being run (zero-delay relays and replies); they go to the instant's tier,
//! later ones to a large heap, and the next message is the smaller of the two tiers' next.
//! Which tier an item is in never changes the order, only the cost.

use dary_heap::QuaternaryHeap;

/// The instant's items: a sorted run taken from its end, and the items pushed since it was
/// sorted. Within an instant a batch sends only to later generations, so a push almost never
/// comes before the run's next item; the fresh items are sorted once, when the run is spent
/// (or, if one of them must come first, with it). An instant of millions of messages, as
/// the sectored gas's set-up, then costs one sort instead of a heap operation each.
struct Instant<T: Ord> {
    /// Greatest last: the next item is `run.last()`.
    run: Vec<T>,
    fresh: Vec<T>,
    /// The index of the greatest fresh item.
    best: Option<usize>,
}

impl<T: Ord> Default for Instant<T> {
    fn default() -> Self {
        Instant {
            run: Vec::new(),
            fresh: Vec::new(),
            best: None,
        }
    }
}

impl<T: Ord> Instant<T> {
    fn push(&mut self, item: T) {
        if self.best.is_none_or(|b| item > self.fresh[b]) {
            self.best = Some(self.fresh.len());
        }
        self.fresh.push(item);
    }

    /// Makes `run.last()` the greatest item held.
    fn settle(&mut self) {
        let Some(b) = self.best else { return };
        if self.run.last().is_some_and(|last| *last >= self.fresh[b]) {
            return;
        }
        // the run's items are few (an instant's last generation) or already in order: one
        // unstable sort of both, which allocates nothing
        self.fresh.append(&mut self.run);
        self.fresh.sort_unstable();
        std::mem::swap(&mut self.run, &mut self.fresh);
        self.best = None;
    }

    fn peek(&mut self) -> Option<&T> {
        self.settle();
        self.run.last()
    }

    fn pop(&mut self) -> Option<T> {
        self.settle();
        self.run.pop()
    }

    fn len(&self) -> usize {
        self.run.len() + self.fresh.len()
    }

    fn retain(&mut self, mut keep: impl FnMut(&T) -> bool) {
        self.run.retain(&mut keep);
        self.fresh.retain(&mut keep);
        self.best = (0..self.fresh.len()).max_by(|&i, &j| self.fresh[i].cmp(&self.fresh[j]));
    }
}

/// Pending items, greatest first (as `BinaryHeap`: the executors reverse their order).
pub struct Queue<T: Ord> {
    instant: Instant<T>,
    later: QuaternaryHeap<T>,
}

impl<T: Ord> Default for Queue<T> {
    fn default() -> Self {
        Queue {
            instant: Instant::default(),
            later: QuaternaryHeap::new(),
        }
    }
}

impl<T: Ord> Queue<T> {
    /// Room for `n` items in each tier without growing.
    pub fn with_capacity(n: usize) -> Queue<T> {
        Queue {
            instant: Instant {
                fresh: Vec::with_capacity(n),
                ..Instant::default()
            },
            later: QuaternaryHeap::with_capacity(n),
        }
    }

    /// Adds an item, to the instant's tier if it belongs to the instant being run.
    pub fn push(&mut self, item: T, in_instant: bool) {
        if in_instant {
            self.instant.push(item);
        } else {
            self.later.push(item);
        }
    }

    /// Whether the next item is the large heap's.
    fn later_first(&mut self) -> bool {
        match (self.instant.peek(), self.later.peek()) {
            (Some(a), Some(b)) => b > a,
            (Some(_), None) => false,
            (None, _) => true,
        }
    }

    /// The next item.
    pub fn peek(&mut self) -> Option<&T> {
        if self.later_first() {
            self.later.peek()
        } else {
            self.instant.peek()
        }
    }

    /// Takes the next item.
    pub fn pop(&mut self) -> Option<T> {
        if self.later_first() {
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
        self.instant.retain(&mut keep);
        self.later.retain(&mut keep);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Whatever tier each item goes to, and however pushes and pops interleave, every pop
        /// takes the greatest item held.
        #[test]
        fn pops_in_order_whichever_tier(
            ops in prop::collection::vec((0u32..50, any::<bool>(), 0u8..3), 0..300),
        ) {
            let mut q = Queue::default();
            let mut held: Vec<u32> = Vec::new();
            for &(v, instant, pops) in &ops {
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
}
