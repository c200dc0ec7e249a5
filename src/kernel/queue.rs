//! The executors' pending set: two heaps with the same order. Most messages a batch sends are
//! for the instant being run (zero-delay relays and replies); they go to a small heap that
//! stays in cache, later ones to a large one, and the next message is the smaller of the two
//! tops. Which heap an item is in never changes the order, only the cost.

use dary_heap::QuaternaryHeap;

/// Pending items, greatest first (as `BinaryHeap`: the executors reverse their order).
pub struct Queue<T: Ord> {
    instant: QuaternaryHeap<T>,
    later: QuaternaryHeap<T>,
}

impl<T: Ord> Default for Queue<T> {
    fn default() -> Self {
        Queue {
            instant: QuaternaryHeap::new(),
            later: QuaternaryHeap::new(),
        }
    }
}

impl<T: Ord> Queue<T> {
    /// Adds an item, to the small heap if it belongs to the instant being run.
    pub fn push(&mut self, item: T, in_instant: bool) {
        if in_instant {
            self.instant.push(item);
        } else {
            self.later.push(item);
        }
    }

    /// Whether the next item is the large heap's.
    fn later_first(&self) -> bool {
        match (self.instant.peek(), self.later.peek()) {
            (Some(a), Some(b)) => b > a,
            (Some(_), None) => false,
            (None, _) => true,
        }
    }

    /// The next item.
    pub fn peek(&self) -> Option<&T> {
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
        /// Whatever heap each item goes to, they come out greatest first.
        #[test]
        fn pops_in_order_whichever_heap(items in prop::collection::vec((0u32..50, any::<bool>()), 0..200)) {
            let mut q = Queue::default();
            for &(v, instant) in &items {
                q.push(v, instant);
            }
            prop_assert_eq!(q.len(), items.len());
            let mut want: Vec<u32> = items.iter().map(|&(v, _)| v).collect();
            want.sort_unstable_by(|a, b| b.cmp(a));
            let mut got = Vec::new();
            while let Some(v) = q.pop() {
                got.push(v);
            }
            prop_assert_eq!(got, want);
            prop_assert!(q.is_empty());
        }
    }
}
