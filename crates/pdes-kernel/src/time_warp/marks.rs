//! What a worker knows of its messages besides the messages themselves. A message is in one
//! place at a time: on its way, in the worker's heap, in the batch that handled it, or set aside
//! here while cancelled. Anti-messages and model cancellations are marks on its uid that the
//! worker reads when the message reaches the top of its heap, as the sequential executor reads
//! its set of cancelled handles: most messages are never marked, and cost no lookup by name.

use super::super::{Pending, Time};
use rustc_hash::{FxHashMap, FxHashSet};
use smallvec::SmallVec;

/// Model cancellations of one message, minus their undoing.
struct Cancels {
    /// The message's simulation time: once GVT passes it, nothing can revive or cancel it.
    t: f64,
    /// Net cancellations by the simulation time of the cancelling batch (never zero).
    by: SmallVec<[(f64, i32); 1]>,
}

impl Cancels {
    /// Whether a batch before `gvt` cancelled the message (committed: for good).
    fn committed(&self, gvt: f64) -> bool {
        self.by.iter().any(|&(at, n)| n > 0 && at < gvt)
    }
}

/// How a message stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    /// To be delivered.
    Live,
    /// Its anti-message came: it is gone for good.
    Annulled,
    /// Cancelled by its sender: set aside until the cancellation is undone or committed.
    Cancelled,
}

/// The marks of one worker's messages.
pub struct Marks<T, Msg> {
    /// Anti-messages whose message has not been dropped yet (it is in the heap or on its way).
    annulled: FxHashSet<u64>,
    /// Retractions (cancellations by batches run as final) likewise: kept apart because they
    /// name only messages their sender may cancel, so that the many others need no lookup.
    retracted: FxHashSet<u64>,
    /// Model cancellations, by the uid of the cancelled message.
    cancels: FxHashMap<u64, Cancels>,
    /// Cancelled messages taken off the heap, by uid: undoing the cancellation brings them back.
    dead: FxHashMap<u64, Pending<T, Msg>>,
    /// Size of `cancels` and `dead` past which fossil collection sweeps them (amortized: twice
    /// what is left after each sweep).
    sweep_at: usize,
}

impl<T: Time, Msg> Default for Marks<T, Msg> {
    fn default() -> Self {
        Marks {
            annulled: FxHashSet::default(),
            retracted: FxHashSet::default(),
            cancels: FxHashMap::default(),
            dead: FxHashMap::default(),
            sweep_at: 1024,
        }
    }
}

impl<T: Time, Msg> Marks<T, Msg> {
    /// How message `uid` stands (`retractable`: whether its sender may cancel it).
    #[inline]
    pub fn of(&self, uid: u64, retractable: bool) -> Mark {
        if !self.annulled.is_empty() && self.annulled.contains(&uid) {
            Mark::Annulled
        } else if !retractable {
            Mark::Live
        } else if !self.retracted.is_empty() && self.retracted.contains(&uid) {
            Mark::Annulled
        } else if self.cancelled(uid) {
            Mark::Cancelled
        } else {
            Mark::Live
        }
    }

    /// Whether a model cancellation of `uid` stands.
    #[inline]
    pub fn cancelled(&self, uid: u64) -> bool {
        !self.cancels.is_empty() && self.cancels.contains_key(&uid)
    }

    /// Takes a message that is not live off the heap's hands: an annulled one is dropped (its
    /// anti-message is spent), a cancelled one set aside, or dropped too if a batch before
    /// `gvt` cancelled it (committed: for good).
    pub fn set_aside(&mut self, uid: u64, p: Pending<T, Msg>, mark: Mark, gvt: f64) {
        match mark {
            Mark::Annulled => self.unmark(uid),
            Mark::Cancelled => {
                if self.cancels.get(&uid).is_some_and(|c| c.committed(gvt)) {
                    self.cancels.remove(&uid);
                } else {
                    self.dead.insert(uid, p);
                }
            }
            Mark::Live => unreachable!("a live message is delivered, not set aside"),
        }
    }

    /// Spends the anti-message or retraction of a message dropped.
    fn unmark(&mut self, uid: u64) {
        if !self.annulled.remove(&uid) {
            self.retracted.remove(&uid);
        }
    }

    /// A message arriving: false if its anti-message or retraction came first (both are then
    /// spent).
    pub fn arrives(&mut self, uid: u64, retractable: bool) -> bool {
        let annulled = !self.annulled.is_empty() && self.annulled.remove(&uid);
        let retracted = retractable && !self.retracted.is_empty() && self.retracted.remove(&uid);
        !(annulled || retracted)
    }

    /// An anti-message: drops its message if it is set aside here, else marks it, to be dropped
    /// when it reaches the top of the heap or arrives. True when it was set aside (no batch can
    /// have handled it).
    pub fn annul(&mut self, uid: u64) -> bool {
        if self.dead.remove(&uid).is_some() {
            return true;
        }
        self.annulled.insert(uid);
        false
    }

    /// A retraction: as [`Marks::annul`], for a message its sender may cancel.
    pub fn retract(&mut self, uid: u64) -> bool {
        if !self.dead.is_empty() && self.dead.remove(&uid).is_some() {
            return true;
        }
        self.retracted.insert(uid);
        false
    }

    /// Counts a cancellation of message `uid` (at simulation time `t`) by a batch at `at`
    /// (`sign` 1) or its undoing (-1). Returns whether the message's standing changed
    /// (cancelled or not), and the message if the cancellation no longer stands and the
    /// message was set aside.
    pub fn cancel(
        &mut self,
        uid: u64,
        t: f64,
        at: f64,
        sign: i8,
    ) -> (bool, Option<Pending<T, Msg>>) {
        use std::collections::hash_map::Entry;
        let c = match self.cancels.entry(uid) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => {
                e.insert(Cancels {
                    t,
                    by: smallvec::smallvec![(at, i32::from(sign))],
                });
                return (true, None);
            }
        };
        match c.by.iter().position(|b| b.0.to_bits() == at.to_bits()) {
            Some(k) => {
                c.by[k].1 += i32::from(sign);
                if c.by[k].1 == 0 {
                    c.by.swap_remove(k);
                }
            }
            None => c.by.push((at, i32::from(sign))),
        }
        if c.by.is_empty() {
            self.cancels.remove(&uid);
            return (true, self.dead.remove(&uid));
        }
        (false, None)
    }

    /// Makes the cancellation of message `uid` by a batch at simulation time `at` final, as that
    /// batch commits: it can no longer be undone, so the message is gone for good. Its count
    /// leaves the cancellations (whose table stays as small as the uncommitted batches' share)
    /// for a retraction, or the message is dropped at once if it was set aside. Nothing is left
    /// to do if the cancellation's entry has gone: its message is already dropped.
    pub fn promote(&mut self, uid: u64, at: f64) {
        let Some(c) = self.cancels.get_mut(&uid) else {
            return;
        };
        if let Some(k) = c.by.iter().position(|b| b.0.to_bits() == at.to_bits()) {
            c.by[k].1 -= 1;
            if c.by[k].1 == 0 {
                c.by.swap_remove(k);
            }
        }
        if c.by.is_empty() {
            self.cancels.remove(&uid);
        }
        if self.dead.remove(&uid).is_none() {
            self.retracted.insert(uid);
        }
    }

    /// Cancelled messages set aside.
    pub fn set_aside_len(&self) -> usize {
        self.dead.len()
    }

    /// Marks waiting for messages still in the heap or on their way.
    pub fn pending_marks(&self) -> usize {
        self.annulled.len() + self.retracted.len() + self.cancels.len()
    }

    /// Whether a heap item stays: drops (and unmarks) an annulled message, and a cancelled one
    /// whose cancellation a batch before `gvt` made (committed: it can no longer be undone).
    pub fn keeps(&mut self, uid: u64, retractable: bool, gvt: f64) -> bool {
        match self.of(uid, retractable) {
            Mark::Live => true,
            Mark::Annulled => {
                self.unmark(uid);
                false
            }
            Mark::Cancelled => {
                if self.cancels.get(&uid).is_some_and(|c| c.committed(gvt)) {
                    self.cancels.remove(&uid);
                    false
                } else {
                    true
                }
            }
        }
    }

    /// Fossil collection: frees cancelled messages that nothing can revive any more (before
    /// GVT, or cancelled by a committed batch) and the marks of messages before GVT (every
    /// message before it has left the heap, and none is on its way), once they are many.
    pub fn collect(&mut self, gvt: f64) {
        if self.cancels.len() + self.dead.len() <= self.sweep_at {
            return;
        }
        let cancels = &mut self.cancels;
        self.dead.retain(|uid, p| {
            let gone = p.time.t() < gvt || cancels.get(uid).is_some_and(|c| c.committed(gvt));
            if gone {
                cancels.remove(uid);
            }
            !gone
        });
        cancels.retain(|_, c| c.t >= gvt);
        self.sweep_at = (2 * (self.cancels.len() + self.dead.len())).max(1024);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::PlainTime;
    use crate::{Envelope, VTime};

    fn msg(t: f64) -> Pending<PlainTime, u8> {
        Pending {
            time: VTime::start(t),
            to: 0,
            priority: 0,
            retractable: true,
            env: Envelope {
                from: 1,
                seq: 1,
                msg: 0,
            },
        }
    }

    #[test]
    fn an_anti_message_meets_its_message_in_either_order() {
        let mut m: Marks<PlainTime, u8> = Marks::default();
        assert_eq!(m.of(7, true), Mark::Live);
        // the anti-message first: the message is dropped as it arrives
        assert!(!m.annul(7));
        assert_eq!(m.of(7, false), Mark::Annulled);
        assert!(!m.arrives(7, false));
        assert_eq!(m.of(7, true), Mark::Live);
        // the message first, in the heap: it is dropped when it reaches the top
        assert!(m.arrives(8, true));
        m.annul(8);
        m.set_aside(8, msg(1.0), Mark::Annulled, 0.0);
        assert_eq!(m.pending_marks(), 0);
    }

    #[test]
    fn a_retraction_names_only_a_message_its_sender_may_cancel() {
        let mut m: Marks<PlainTime, u8> = Marks::default();
        assert!(!m.retract(5));
        assert_eq!(m.of(5, true), Mark::Annulled);
        // a relay is never retracted, so its lookups skip the retractions
        assert_eq!(m.of(5, false), Mark::Live);
        assert!(!m.arrives(5, true), "retracted before it came");
        assert_eq!((m.of(5, true), m.pending_marks()), (Mark::Live, 0));
        // a message set aside as cancelled is dropped at once
        m.cancel(6, 2.0, 1.0, 1);
        m.set_aside(6, msg(2.0), Mark::Cancelled, 0.0);
        assert!(m.retract(6));
        assert_eq!(m.set_aside_len(), 0);
        // one in the heap is dropped when it reaches the top, which spends the mark (message
        // 6's cancellation waits for fossil collection)
        m.retract(7);
        assert_eq!(m.pending_marks(), 2);
        assert!(!m.keeps(7, true, 0.0));
        assert_eq!(m.pending_marks(), 1);
    }

    #[test]
    fn a_cancellation_undone_brings_its_message_back() {
        let mut m: Marks<PlainTime, u8> = Marks::default();
        assert!(matches!(m.cancel(3, 2.0, 1.0, 1), (true, None)));
        assert_eq!(m.of(3, true), Mark::Cancelled);
        assert_eq!(m.of(3, false), Mark::Live, "a relay is never cancelled");
        m.set_aside(3, msg(2.0), Mark::Cancelled, 0.0);
        assert_eq!(m.set_aside_len(), 1);
        let (changed, back) = m.cancel(3, 2.0, 1.0, -1);
        assert!(changed);
        assert_eq!(back.expect("set aside, and live again").time.t(), 2.0);
        assert_eq!((m.of(3, true), m.set_aside_len()), (Mark::Live, 0));
        // an undoing that arrives before its cancellation cancels until they meet
        assert!(matches!(m.cancel(4, 2.0, 1.0, -1), (true, None)));
        assert_eq!(m.of(4, true), Mark::Cancelled);
        // a second cancellation by another batch changes nothing until both are undone
        assert!(matches!(m.cancel(4, 2.0, 1.5, 1), (false, None)));
        assert!(matches!(m.cancel(4, 2.0, 1.5, -1), (false, None)));
        assert!(matches!(m.cancel(4, 2.0, 1.0, 1), (true, None)));
        assert_eq!(m.of(4, true), Mark::Live);
    }

    #[test]
    fn a_committed_cancellation_is_a_retraction() {
        let mut m: Marks<PlainTime, u8> = Marks::default();
        // in the heap: the cancellation's entry goes, and the message is dropped at the top
        m.cancel(3, 2.0, 1.0, 1);
        m.promote(3, 1.0);
        assert_eq!(m.of(3, true), Mark::Annulled);
        assert_eq!(m.pending_marks(), 1);
        assert!(!m.keeps(3, true, 0.0));
        assert_eq!(m.pending_marks(), 0);
        // set aside: dropped at once, and the other cancellation's undoing brings nothing back
        m.cancel(4, 2.0, 1.0, 1);
        m.cancel(4, 2.0, 1.5, 1);
        m.set_aside(4, msg(2.0), Mark::Cancelled, 0.0);
        m.promote(4, 1.0);
        assert_eq!(m.set_aside_len(), 0);
        assert!(matches!(m.cancel(4, 2.0, 1.5, -1), (true, None)));
        assert_eq!(m.pending_marks(), 0);
        // a message already dropped leaves no mark behind
        m.promote(5, 1.0);
        assert_eq!(m.pending_marks(), 0);
    }

    #[test]
    fn fossil_collection_frees_what_nothing_can_revive() {
        let mut m: Marks<PlainTime, u8> = Marks {
            sweep_at: 0,
            ..Marks::default()
        };
        m.cancel(1, 5.0, 1.0, 1);
        m.set_aside(1, msg(5.0), Mark::Cancelled, 0.0);
        m.cancel(2, 5.0, 3.0, 1);
        m.set_aside(2, msg(5.0), Mark::Cancelled, 0.0);
        // GVT 2: message 1's cancellation is committed, message 2's may still be undone
        m.collect(2.0);
        assert_eq!(m.set_aside_len(), 1);
        assert_eq!(m.of(2, true), Mark::Cancelled);
        // one whose cancellation is committed when it leaves the heap is dropped at once
        m.cancel(5, 6.0, 1.0, 1);
        m.set_aside(5, msg(6.0), Mark::Cancelled, 2.0);
        assert_eq!((m.set_aside_len(), m.of(5, true)), (1, Mark::Live));
        // a cancelled message still in the heap stays until its cancellation is committed
        m.cancel(9, 5.0, 3.0, 1);
        assert!(
            m.keeps(9, true, 2.0),
            "its cancellation may still be undone"
        );
        assert!(!m.keeps(9, true, 4.0));
        assert_eq!(m.of(9, true), Mark::Live, "dropped, and unmarked");
        // past the messages' time, nothing is left
        m.sweep_at = 0;
        m.collect(6.0);
        assert_eq!((m.set_aside_len(), m.pending_marks()), (0, 0));
    }
}
