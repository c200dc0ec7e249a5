//! A max-heap of items that orders 16-byte entries, not the items: each entry is an item's
//! lead ([`Ranked::lead`], an integer that never orders two items against their own order) and
//! its slot in a slab. Four children of a node share one cache line, and only entries of equal
//! leads read their items; `dary_heap` compares the elements themselves, so it cannot hold
//! entries that compare through a slab.

use super::queue::Ranked;

/// Children per node.
const D: usize = 4;

/// Items in a slab, greatest first by an index of (lead, slot) entries.
pub struct LedHeap<T> {
    entries: Vec<(u64, u32)>,
    slab: Vec<Option<T>>,
    free: Vec<u32>,
}

impl<T> Default for LedHeap<T> {
    fn default() -> Self {
        LedHeap {
            entries: Vec::new(),
            slab: Vec::new(),
            free: Vec::new(),
        }
    }
}

impl<T: Ranked> LedHeap<T> {
    /// Room for `n` items without growing.
    pub fn with_capacity(n: usize) -> Self {
        LedHeap {
            entries: Vec::with_capacity(n),
            slab: Vec::with_capacity(n),
            free: Vec::new(),
        }
    }

    fn item(&self, slot: u32) -> &T {
        self.slab[slot as usize].as_ref().expect("a held slot")
    }

    /// Whether entry `a` comes before entry `b`.
    #[inline]
    fn above(&self, a: (u64, u32), b: (u64, u32)) -> bool {
        a.0 > b.0 || (a.0 == b.0 && self.item(a.1) > self.item(b.1))
    }

    /// Adds an item.
    pub fn push(&mut self, item: T) {
        let lead = item.lead();
        let slot = match self.free.pop() {
            Some(s) => {
                self.slab[s as usize] = Some(item);
                s
            }
            None => {
                self.slab.push(Some(item));
                u32::try_from(self.slab.len() - 1).expect("fewer than 2^32 items")
            }
        };
        self.entries.push((lead, slot));
        self.sift_up(self.entries.len() - 1);
    }

    /// The greatest item.
    pub fn peek(&self) -> Option<&T> {
        self.entries.first().map(|e| self.item(e.1))
    }

    /// The greatest item's lead, read without the item.
    pub fn peek_lead(&self) -> Option<u64> {
        self.entries.first().map(|e| e.0)
    }

    /// Takes the greatest item.
    pub fn pop(&mut self) -> Option<T> {
        let last = self.entries.pop()?;
        let top = if self.entries.is_empty() {
            last
        } else {
            let top = std::mem::replace(&mut self.entries[0], last);
            self.sift_down(0);
            top
        };
        self.free.push(top.1);
        self.slab[top.1 as usize].take()
    }

    /// Items held.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Keeps only the items `keep` accepts. The slab is read in its own order, not the
    /// entries' (a heap of a million items is far larger than the caches, and the entries
    /// point all over it); the entries then look up only a bit per slot.
    pub fn retain(&mut self, mut keep: impl FnMut(&T) -> bool) {
        let mut dropped = vec![0u64; self.slab.len().div_ceil(64)];
        let free_before = self.free.len();
        for (s, slot) in self.slab.iter_mut().enumerate() {
            if slot.as_ref().is_some_and(|item| !keep(item)) {
                *slot = None;
                self.free.push(s as u32);
                dropped[s / 64] |= 1 << (s % 64);
            }
        }
        if self.free.len() == free_before {
            return;
        }
        self.entries
            .retain(|&(_, s)| dropped[s as usize / 64] & (1 << (s % 64)) == 0);
        // only nodes with children can be out of place
        let n = self.entries.len();
        if n > 1 {
            for i in (0..=(n - 2) / D).rev() {
                self.sift_down(i);
            }
        }
    }

    /// Every item held, in no particular order.
    pub fn iter(&self) -> impl Iterator<Item = &T> {
        self.entries.iter().map(|e| self.item(e.1))
    }

    fn sift_up(&mut self, mut i: usize) {
        let e = self.entries[i];
        while i > 0 {
            let parent = (i - 1) / D;
            if !self.above(e, self.entries[parent]) {
                break;
            }
            self.entries[i] = self.entries[parent];
            i = parent;
        }
        self.entries[i] = e;
    }

    fn sift_down(&mut self, mut i: usize) {
        let n = self.entries.len();
        let e = self.entries[i];
        loop {
            let first = D * i + 1;
            if first >= n {
                break;
            }
            let mut best = first;
            for c in first + 1..(first + D).min(n) {
                if self.above(self.entries[c], self.entries[best]) {
                    best = c;
                }
            }
            if !self.above(self.entries[best], e) {
                break;
            }
            self.entries[i] = self.entries[best];
            i = best;
        }
        self.entries[i] = e;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::queue::tests::At;
    use proptest::prelude::*;

    proptest! {
        /// Pushes, pops and a retain in any mix give what a sorted list of the same items
        /// would.
        #[test]
        fn the_heap_pops_in_order(
            ops in prop::collection::vec((any::<bool>(), 0u8..4, any::<u16>()), 0..300),
            drop_odd in any::<bool>(),
        ) {
            let mut heap = LedHeap::with_capacity(4);
            let mut model: Vec<At> = Vec::new();
            for (i, &(push, a, b)) in ops.iter().enumerate() {
                if push || model.is_empty() {
                    heap.push(At(a, u32::from(b)));
                    model.push(At(a, u32::from(b)));
                } else {
                    model.sort_unstable();
                    prop_assert_eq!(heap.pop(), model.pop());
                }
                if drop_odd && i == ops.len() / 2 {
                    heap.retain(|t| t.1 % 2 == 0);
                    model.retain(|t| t.1 % 2 == 0);
                }
                prop_assert_eq!(heap.len(), model.len());
                prop_assert_eq!(heap.peek(), model.iter().max());
            }
            let mut held: Vec<At> = heap.iter().copied().collect();
            held.sort_unstable();
            model.sort_unstable();
            prop_assert_eq!(&held, &model);
            let drained: Vec<At> = std::iter::from_fn(|| heap.pop()).collect();
            prop_assert_eq!(drained, model.into_iter().rev().collect::<Vec<_>>());
        }
    }
}
