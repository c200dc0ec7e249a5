//! A worker's received, uncommitted messages: records in a slab. A message between two objects
//! of the same worker (most of them) gets its slot when it is sent, and its sender, its heap
//! item and the batch that takes it keep that slot: no lookup by name. Only a message from
//! another worker, whose anti-message or cancellation arrives by uid alone, is also filed in a
//! map from uid to slot.

use super::super::Pending;
use rustc_hash::FxHashMap;
use smallvec::SmallVec;

/// A message received and not yet committed.
pub struct Entry<Msg> {
    /// The message's uid (`FREE` in a free slot).
    uid: u64,
    /// Whether the map names it.
    filed: bool,
    /// Positives minus anti-messages: 1 when the message is here and not annulled.
    pub pos: i8,
    /// Model cancellations minus their undoing, by the time of the cancelling batch.
    pub cancels: SmallVec<[(f64, i32); 1]>,
    /// The message, while `pos` is 1.
    pub p: Option<Pending<Msg>>,
    /// Whether a batch not rolled back has handled it.
    pub processed: bool,
}

/// The uid of a free slot (a uid's counter part starts at 1, so no uid is all ones).
const FREE: u64 = u64::MAX;

impl<Msg> Entry<Msg> {
    /// Here, not annulled and not cancelled.
    pub fn live(&self) -> bool {
        self.pos == 1 && self.cancels.is_empty()
    }

    /// Counts a cancellation by a batch at `at` (`sign` 1) or its undoing (-1).
    pub fn cancel(&mut self, at: f64, sign: i8) {
        match self
            .cancels
            .iter()
            .position(|c| c.0.to_bits() == at.to_bits())
        {
            Some(k) => {
                self.cancels[k].1 += i32::from(sign);
                if self.cancels[k].1 == 0 {
                    self.cancels.swap_remove(k);
                }
            }
            None => self.cancels.push((at, i32::from(sign))),
        }
    }

    /// Whether it is dead for good once GVT is `gvt`: here and cancelled by a committed batch.
    pub fn dead_for_good(&self, gvt: f64) -> bool {
        self.pos == 1 && self.cancels.iter().any(|&(at, n)| n > 0 && at < gvt)
    }

    /// Whether nothing is left to count: no positive, no anti-message, no cancellation.
    pub fn empty(&self) -> bool {
        self.pos == 0 && self.cancels.is_empty()
    }
}

/// Where a message's record is: its slot, checked against its uid (slots are reused).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ref {
    /// The message's uid.
    pub uid: u64,
    /// Its slot.
    pub slot: u32,
}

/// The records of one worker's messages.
pub struct Entries<Msg> {
    slab: Vec<Entry<Msg>>,
    free: Vec<u32>,
    filed: FxHashMap<u64, u32>,
}

impl<Msg> Default for Entries<Msg> {
    fn default() -> Self {
        Entries {
            slab: Vec::new(),
            free: Vec::new(),
            filed: FxHashMap::default(),
        }
    }
}

impl<Msg> Entries<Msg> {
    /// Room for `n` records without growing (address space, not touched until used: a growing
    /// slab copies itself into fresh pages, each a fault and a zeroing).
    pub fn with_capacity(n: usize) -> Entries<Msg> {
        Entries {
            slab: Vec::with_capacity(n),
            ..Entries::default()
        }
    }

    /// Messages held.
    pub fn len(&self) -> usize {
        self.slab.len() - self.free.len()
    }

    /// A new, empty record for `uid`, not filed in the map: for a message sent on this worker.
    pub fn reserve(&mut self, uid: u64) -> Ref {
        let fresh = Entry {
            uid,
            filed: false,
            pos: 0,
            cancels: SmallVec::new(),
            p: None,
            processed: false,
        };
        let slot = match self.free.pop() {
            Some(s) => {
                self.slab[s as usize] = fresh;
                s
            }
            None => {
                self.slab.push(fresh);
                (self.slab.len() - 1) as u32
            }
        };
        Ref { uid, slot }
    }

    /// The record of `uid`: at `slot` when the sender knows it and it is still held, else the
    /// one the map names, else a new one filed in the map.
    pub fn open(&mut self, uid: u64, slot: Option<u32>) -> Ref {
        if let Some(s) = slot {
            if self.slab.get(s as usize).is_some_and(|e| e.uid == uid) {
                return Ref { uid, slot: s };
            }
        }
        if let Some(&s) = self.filed.get(&uid) {
            return Ref { uid, slot: s };
        }
        let r = self.reserve(uid);
        self.slab[r.slot as usize].filed = true;
        self.filed.insert(uid, r.slot);
        r
    }

    /// The record `r` names, if it is still held.
    pub fn at(&self, r: Ref) -> Option<&Entry<Msg>> {
        self.slab.get(r.slot as usize).filter(|e| e.uid == r.uid)
    }

    /// The record `r` names, if it is still held, to change.
    pub fn at_mut(&mut self, r: Ref) -> Option<&mut Entry<Msg>> {
        self.slab
            .get_mut(r.slot as usize)
            .filter(|e| e.uid == r.uid)
    }

    /// Frees the record `r` names, if it is still held.
    pub fn remove(&mut self, r: Ref) {
        let Some(e) = self.at_mut(r) else { return };
        let filed = e.filed;
        e.uid = FREE;
        e.p = None;
        e.cancels = SmallVec::new();
        if filed {
            self.filed.remove(&r.uid);
        }
        self.free.push(r.slot);
    }

    /// Every record held.
    pub fn iter(&self) -> impl Iterator<Item = &Entry<Msg>> {
        self.slab.iter().filter(|e| e.uid != FREE)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reused_slot_does_not_answer_for_its_old_uid() {
        let mut e: Entries<u8> = Entries::default();
        let a = e.reserve(7);
        e.at_mut(a).unwrap().pos = 1;
        e.remove(a);
        assert!(e.at(a).is_none());
        let b = e.reserve(9);
        assert_eq!(b.slot, a.slot, "the slot is reused");
        assert!(
            e.at(a).is_none(),
            "the old reference names another message now"
        );
        assert!(e.at(b).is_some());
        assert_eq!((e.len(), e.iter().count()), (1, 1));
        // a stale slot for uid 7 falls back to the map: a new record
        let c = e.open(7, Some(a.slot));
        assert_ne!(c.slot, a.slot);
        assert_eq!(e.open(7, None), c, "filed: found again by uid alone");
    }

    #[test]
    fn a_message_from_elsewhere_is_found_by_uid() {
        let mut e: Entries<u8> = Entries::default();
        let a = e.open(3, None);
        e.at_mut(a).unwrap().pos = -1; // its anti-message came first
        let b = e.open(3, None);
        assert_eq!(a, b);
        assert_eq!(e.at(b).unwrap().pos, -1);
        e.remove(b);
        assert_eq!(e.len(), 0);
        let c = e.open(3, None);
        assert_eq!(
            e.at(c).unwrap().pos,
            0,
            "a fresh record once the old one is freed"
        );
    }
}
