//! A worker's uncommitted batches, in one log in the order they ran, each object's chained
//! oldest to latest. Written at its end and mostly committed from its front soon after, the log
//! stays in cache; a log per object scattered a worker's records over as many buffers, each
//! cold when its object ran again.

use std::collections::VecDeque;

/// No record.
const NONE: u64 = u64::MAX;

/// One object's records in a [`Log`]: its oldest and its latest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Chain {
    first: u64,
    last: u64,
}

impl Chain {
    /// An object with no records.
    pub const EMPTY: Chain = Chain {
        first: NONE,
        last: NONE,
    };

    /// Whether the object has no records.
    pub fn is_empty(&self) -> bool {
        self.first == NONE
    }
}

/// A record and its neighbours in its object's chain, or the hole a record taken out left.
struct Entry<T> {
    owner: u32,
    prev: u64,
    next: u64,
    item: Option<T>,
}

/// Records of many objects in the order they were pushed; each object's are taken from either
/// end of its chain.
pub struct Log<T> {
    ring: VecDeque<Entry<T>>,
    /// The number of the ring's front entry (records are numbered in push order from 0).
    base: u64,
    live: usize,
}

impl<T> Default for Log<T> {
    fn default() -> Self {
        Log {
            ring: VecDeque::new(),
            base: 0,
            live: 0,
        }
    }
}

impl<T> Log<T> {
    fn entry(&self, n: u64) -> &Entry<T> {
        &self.ring[(n - self.base) as usize]
    }

    fn entry_mut(&mut self, n: u64) -> &mut Entry<T> {
        &mut self.ring[(n - self.base) as usize]
    }

    /// Records held.
    pub fn len(&self) -> usize {
        self.live
    }

    /// Slots from the oldest record to the newest: the records, and the holes between them
    /// that records taken from the middle left.
    pub fn slots(&self) -> usize {
        self.ring.len()
    }

    /// Appends `item` as the latest record of object `owner`, whose chain is `chain`.
    pub fn push(&mut self, chain: &mut Chain, owner: u32, item: T) {
        let n = self.base + self.ring.len() as u64;
        self.ring.push_back(Entry {
            owner,
            prev: chain.last,
            next: NONE,
            item: Some(item),
        });
        if chain.last == NONE {
            chain.first = n;
        } else {
            self.entry_mut(chain.last).next = n;
        }
        chain.last = n;
        self.live += 1;
    }

    /// The latest record of `chain`.
    pub fn last(&self, chain: &Chain) -> Option<&T> {
        (chain.last != NONE).then(|| self.entry(chain.last).item.as_ref().expect("live"))
    }

    /// The latest record of `chain`, to change.
    pub fn last_mut(&mut self, chain: &Chain) -> Option<&mut T> {
        (chain.last != NONE).then(|| self.entry_mut(chain.last).item.as_mut().expect("live"))
    }

    /// The oldest record of `chain`.
    pub fn first(&self, chain: &Chain) -> Option<&T> {
        (chain.first != NONE).then(|| self.entry(chain.first).item.as_ref().expect("live"))
    }

    /// The record after the oldest of `chain`.
    pub fn second(&self, chain: &Chain) -> Option<&T> {
        if chain.first == NONE {
            return None;
        }
        let next = self.entry(chain.first).next;
        (next != NONE).then(|| self.entry(next).item.as_ref().expect("live"))
    }

    /// The records of `chain` after its oldest, latest first.
    pub fn after_first_newest_first<'a>(&'a self, chain: &Chain) -> impl Iterator<Item = &'a T> {
        self.back_from(chain.last, chain.first)
    }

    /// The records of `chain`, latest first.
    pub fn newest_first<'a>(&'a self, chain: &Chain) -> impl Iterator<Item = &'a T> {
        self.back_from(chain.last, NONE)
    }

    /// The records of a chain from record `n` back to record `stop`, `stop` left out.
    fn back_from(&self, mut n: u64, stop: u64) -> impl Iterator<Item = &T> {
        std::iter::from_fn(move || {
            if n == stop || n == NONE {
                return None;
            }
            let e = self.entry(n);
            n = e.prev;
            Some(e.item.as_ref().expect("live"))
        })
    }

    /// Takes the latest record of `chain`.
    pub fn pop_last(&mut self, chain: &mut Chain) -> Option<T> {
        (chain.last != NONE).then(|| self.unlink(chain, chain.last))
    }

    /// Takes the oldest record of `chain`.
    pub fn pop_first(&mut self, chain: &mut Chain) -> Option<T> {
        (chain.first != NONE).then(|| self.unlink(chain, chain.first))
    }

    /// Takes record `n` out of `chain`, leaving a hole.
    fn unlink(&mut self, chain: &mut Chain, n: u64) -> T {
        let e = self.entry_mut(n);
        let (item, prev, next) = (e.item.take().expect("live"), e.prev, e.next);
        if prev == NONE {
            chain.first = next;
        } else {
            self.entry_mut(prev).next = next;
        }
        if next == NONE {
            chain.last = prev;
        } else {
            self.entry_mut(next).prev = prev;
        }
        self.taken();
        item
    }

    /// The oldest record held, and its object.
    pub fn front(&self) -> Option<(u32, &T)> {
        let e = self.ring.front()?;
        Some((e.owner, e.item.as_ref().expect("holes are trimmed")))
    }

    /// Drops the holes at both ends, so that the front is a record.
    fn taken(&mut self) {
        self.live -= 1;
        while self.ring.front().is_some_and(|e| e.item.is_none()) {
            self.ring.pop_front();
            self.base += 1;
        }
        while self.ring.back().is_some_and(|e| e.item.is_none()) {
            self.ring.pop_back();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_object_takes_its_records_from_either_end() {
        let mut log: Log<u32> = Log::default();
        let (mut a, mut b) = (Chain::EMPTY, Chain::EMPTY);
        for k in 0..4 {
            log.push(&mut a, 0, 10 + k);
            log.push(&mut b, 1, 20 + k);
        }
        assert_eq!((log.len(), log.front()), (8, Some((0, &10))));
        assert_eq!(
            (log.first(&a), log.second(&a), log.last(&a)),
            (Some(&10), Some(&11), Some(&13))
        );
        // a rollback of b's latest, a commit of a's oldest
        assert_eq!(log.pop_last(&mut b), Some(23));
        assert_eq!(log.pop_first(&mut a), Some(10));
        assert_eq!(log.front(), Some((1, &20)));
        assert_eq!(log.last(&b), Some(&22));
        let later: Vec<u32> = log.after_first_newest_first(&b).copied().collect();
        assert_eq!(later, [22, 21]);
        // a's oldest left a hole at the front, trimmed; b's latest one at the back, trimmed
        assert_eq!((log.len(), log.slots()), (6, 6));
        assert_eq!(log.pop_first(&mut a), Some(11));
        assert_eq!(
            (log.len(), log.slots()),
            (5, 6),
            "a hole in the middle stays"
        );
        // taking every record leaves nothing, from whichever end
        assert_eq!(log.pop_first(&mut b), Some(20));
        assert_eq!(
            log.front(),
            Some((1, &21)),
            "the hole after 20 is trimmed too"
        );
        for want in [13, 12] {
            assert_eq!(log.pop_last(&mut a), Some(want));
        }
        assert!(a.is_empty() && log.first(&a).is_none() && log.pop_last(&mut a).is_none());
        assert_eq!(log.front(), Some((1, &21)));
        assert_eq!(
            (log.pop_first(&mut b), log.pop_first(&mut b)),
            (Some(21), Some(22))
        );
        assert!(b.is_empty());
        assert_eq!((log.len(), log.ring.len()), (0, 0));
        // numbering goes on after the log emptied
        log.push(&mut a, 0, 30);
        assert_eq!((log.first(&a), log.last(&a)), (Some(&30), Some(&30)));
    }
}
