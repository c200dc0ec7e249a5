//! A region's events: the event-list algorithm over its records.
//!
//! A region runs, for its own balls, exactly what the event-list engine runs: each ball keeps
//! its earliest predicted event (another ball, a fixed object, or leaving its cell), and a
//! popped event whose partner changed course since is stale and only recomputed. A ghost is a
//! neighbour's ball near the border: the region predicts its contacts with its own balls (both
//! regions then run such a collision, each for its own ball, from the same two trajectories),
//! and follows it from cell to cell, but leaves everything else it meets to its owner, who
//! sends its new course.

use super::region::{Partner, Region, Slot, Undo, NOWHERE};
use super::{News, RegionEvent};
use crate::engine::{Event, EventKind, Fixed};
use crate::geometry::{Trajectory, Vec2};
use crate::physics::{self, Contact};
use crate::vtime::{pair, Key};
use pdes_kernel::prefetch::prefetch;
use smallvec::SmallVec;
use std::cmp::Ordering;

/// The pair code of a ball leaving its cell: after every physical event of its instant.
pub(super) const CELL_CROSSING: u64 = u64::MAX;

/// The most queued events one batch runs: the batch's reports wait in memory until it ends, and
/// an interrupt is seen between batches.
const SPAN: usize = 4096;

/// The balls a prediction tests.
type Near = SmallVec<[u32; 48]>;

impl Region {
    /// The earliest contact of ball `i` (slot `a`) with ball `j` offered to `best`.
    #[inline]
    fn offer_ball(&self, i: u32, a: &Slot, j: u32, best: &mut (Key, Partner)) {
        let b = &self.slots[j as usize];
        let contact = if a.gid < b.gid {
            physics::ball_ball_contact(&a.traj, a.radius, &b.traj, b.radius)
        } else {
            physics::ball_ball_contact(&b.traj, b.radius, &a.traj, a.radius)
        };
        let p = pair(a.gid, b.gid);
        let key = match contact {
            Contact::Never => return,
            Contact::At(t) => {
                if best.0.cmp_at(t, p) != Ordering::Greater {
                    return;
                }
                Key::at(t, p)
            }
            Contact::Immediate => {
                let (fi, fj) = (
                    &self.cold[i as usize].fixed_at,
                    &self.cold[j as usize].fixed_at,
                );
                fi.max(fj).child(p)
            }
        };
        if key < best.0 {
            *best = (key, Partner::Ball(j, b.counter));
        }
    }

    /// The earliest contact of ball `i` with the fixed objects near its cell offered to `best`.
    fn offer_fixed(&self, i: u32, best: &mut (Key, Partner)) {
        let s = &self.slots[i as usize];
        for &f in self.grid.fixed_near(s.cell) {
            let p = pair(s.gid, f);
            let key = match self.shape.table.contact(f, &s.traj, s.radius) {
                Contact::Never => continue,
                Contact::At(t) => {
                    if best.0.cmp_at(t, p) != Ordering::Greater {
                        continue;
                    }
                    Key::at(t, p)
                }
                Contact::Immediate => self.cold[i as usize].fixed_at.child(p),
            };
            if key < best.0 {
                *best = (key, Partner::Fixed(f));
            }
        }
    }

    /// Offers record `i` its contacts with each of `near` (and, for a ball of the region, the
    /// fixed objects near it) on top of `best`, then sets its cell exit and queues it.
    fn settle_best(&mut self, i: u32, near: &[u32], mut best: (Key, Partner)) {
        // copied once: the pair tests read it for every neighbour
        let a = self.slots[i as usize];
        if a.cell != NOWHERE {
            for &j in near {
                self.offer_ball(i, &a, j, &mut best);
            }
            if self.mine(i) {
                self.offer_fixed(i, &mut best);
            }
        }
        self.cold[i as usize].phys = best;
        self.set_exit(i);
        self.requeue(i);
    }

    /// Adds ball `j` to `near`, the balls record `i` (of this region if `mine`) must be tested
    /// against, if it must be: a ball of the region meets everything, a ghost only the
    /// region's balls. Its slot starts loading.
    #[inline(always)]
    fn consider(&self, i: u32, mine: bool, j: u32, near: &mut Near) {
        if j != i && (mine || self.mine(j)) {
            prefetch(&self.slots[j as usize]);
            near.push(j);
        }
    }

    /// Recomputes record `i`'s earliest event and cell exit, and queues it.
    pub(super) fn predict(&mut self, i: u32) {
        self.keep(i);
        let cell = self.slots[i as usize].cell;
        let mut near = Near::new();
        if cell != NOWHERE {
            let mine = self.mine(i);
            (self.grid).for_each_near(cell, |j| self.consider(i, mine, j, &mut near));
        }
        let none = (Key::at(f64::INFINITY, 0), Partner::Nothing);
        self.settle_best(i, &near, none);
    }

    /// Predicts when record `i`'s centre leaves its cell, and the cell it enters.
    fn set_exit(&mut self, i: u32) {
        let s = &self.slots[i as usize];
        let exit = if s.cell == NOWHERE {
            None
        } else {
            (self.grid).exit(s.cell, s.traj.position, s.traj.velocity, s.traj.t0)
        };
        let now = self.now;
        self.cold[i as usize].cross = exit.map_or((f64::INFINITY, 0), |(t, c)| (t.max(now), c));
    }

    /// Queues record `i` at the earlier of its physical event and its cell exit.
    fn requeue(&mut self, i: u32) {
        let c = &mut self.cold[i as usize];
        c.queued = if c.phys.0.cmp_at(c.cross.0, CELL_CROSSING) == Ordering::Greater {
            Key::at(c.cross.0, CELL_CROSSING)
        } else {
            c.phys.0.clone()
        };
        self.enqueue(i);
    }

    /// Runs every queued event at `key` (the batch of the region's wake-up at `key`), then
    /// the events after it while `more` allows each one's key (it is shown the region's
    /// journal, where the event's old values will start) and none has had news for a
    /// neighbour. What they report and tell the neighbours goes to the region's reports and
    /// outbox.
    pub(super) fn run_on(&mut self, key: &Key, mut more: impl FnMut(&Key, &mut Vec<Undo>) -> bool) {
        let mut run = 0;
        while let Some(i) = self.first() {
            let k = self.cold[i as usize].queued.clone();
            if k > *key {
                if !self.outbox.is_empty() || run >= SPAN || !more(&k, &mut self.journal) {
                    break;
                }
                self.next_stretch();
            }
            run += 1;
            debug_assert!(k >= *key, "a region's event {k:?} was left behind {key:?}");
            self.now = k.t;
            self.run_one(i, &k);
        }
    }

    /// Runs record `i`'s queued event, at `k`.
    fn run_one(&mut self, i: u32, k: &Key) {
        if k.path[..] == [CELL_CROSSING] {
            return self.cross(i);
        }
        match self.cold[i as usize].phys.1 {
            Partner::Ball(j, seen) if self.slots[j as usize].counter == seen => {
                // two ghosts meet where their owner runs it
                if self.mine(i) || self.mine(j) {
                    self.collide(i, j, k);
                } else {
                    self.predict(i);
                }
            }
            Partner::Fixed(f) => self.hit(i, f, k),
            Partner::Nothing | Partner::Ball(..) => self.predict(i),
        }
    }

    /// Sets record `i` on a new course from `key` on.
    fn turn(&mut self, i: u32, key: &Key, velocity: Vec2) {
        self.keep(i);
        self.touch(self.slots[i as usize].cell);
        let s = &mut self.slots[i as usize];
        s.traj = Trajectory {
            position: s.traj.at(key.t),
            velocity,
            t0: key.t,
        };
        s.counter = s.counter.wrapping_add(1);
        self.cold[i as usize].fixed_at = key.clone();
    }

    /// Balls `i` and `j` collide at `key`.
    fn collide(&mut self, i: u32, j: u32, key: &Key) {
        let (a, b) = if self.slots[i as usize].gid < self.slots[j as usize].gid {
            (i, j)
        } else {
            (j, i)
        };
        let (sa, sb) = (self.slots[a as usize], self.slots[b as usize]);
        let (ma, mb) = (self.cold[a as usize].mass, self.cold[b as usize].mass);
        let (va, vb) = physics::ball_ball_velocities(
            sa.traj.at(key.t),
            sa.traj.velocity,
            ma,
            sb.traj.at(key.t),
            sb.traj.velocity,
            mb,
        );
        // the region that runs it last (the higher index) reports it, so that both balls have
        // their new courses when an observer looks
        if sa.owner.max(sb.owner) == self.shape.me {
            let event = Event {
                t: key.t,
                kind: EventKind::BallBall,
                a: sa.gid,
                b: sb.gid,
            };
            let across = sa.owner != sb.owner;
            self.reports.push((
                key.clone(),
                RegionEvent {
                    event,
                    across,
                    region: self.shape.me,
                },
            ));
        }
        self.turn(a, key, va);
        self.turn(b, key, vb);
        self.predict(a);
        self.predict(b);
        self.tell_course(a, sb.owner);
        self.tell_course(b, sa.owner);
    }

    /// Ball `i` hits fixed object `f` at `key`: it bounces, or drops into a pocket.
    fn hit(&mut self, i: u32, f: u32, key: &Key) {
        let s = self.slots[i as usize];
        let table = &self.shape.table;
        let event = Event {
            t: key.t,
            kind: table.event_kind(f),
            a: s.gid,
            b: f,
        };
        self.reports.push((
            key.clone(),
            RegionEvent {
                event,
                across: false,
                region: self.shape.me,
            },
        ));
        let column = self.grid.column(s.cell);
        match table.bounce(f, s.traj.at(key.t), s.traj.velocity) {
            Some(v) => {
                self.turn(i, key, v);
                self.predict(i);
                self.tell_course(i, self.shape.me);
            }
            None => {
                let Fixed::Pocket(k) = table.fixed(f) else {
                    unreachable!("only pockets swallow balls")
                };
                self.turn(i, key, s.traj.velocity);
                self.unplace(i);
                self.cold[i as usize].pocket = Some(k);
                for n in self.shape.facing(column) {
                    self.outbox.push((n, News::Leave(s.gid)));
                }
            }
        }
    }

    /// Tells the neighbours that see ball `i` of its new course, if it is this region's and
    /// the neighbour did not run the event itself (its partner's owner `shared`).
    fn tell_course(&mut self, i: u32, shared: u32) {
        if !self.mine(i) {
            return;
        }
        let column = self.grid.column(self.slots[i as usize].cell);
        for n in self.shape.facing(column) {
            if n != shared {
                let g = self.ghost_of(i);
                self.outbox.push((n, News::Update(g)));
            }
        }
    }

    /// Record `i`'s centre leaves its cell: it moves on in the grid, and a ball of this region
    /// that comes near a border, leaves it, or crosses it changes who must hear of it. Only
    /// the balls of the cells that come into its 3 × 3 block are new candidates, unless it
    /// changed hands.
    fn cross(&mut self, i: u32) {
        self.keep(i);
        let (from, to) = (self.slots[i as usize].cell, self.cold[i as usize].cross.1);
        self.grid.remove_from(i, from);
        self.grid.insert(i, to);
        if self.mine(i) {
            self.touch(from);
            self.touch(to);
        }
        self.slots[i as usize].cell = to;
        if self.grid.column(from) != self.grid.column(to) {
            self.cold[i as usize].column_since = self.now;
        }
        if self.mine(i) && self.tell_crossing(i, from, to) {
            return self.predict(i);
        }
        let (mut near, mine) = (Near::new(), self.mine(i));
        (self.grid).for_each_entering(from, to, |j| self.consider(i, mine, j, &mut near));
        let best = std::mem::replace(
            &mut self.cold[i as usize].phys,
            (Key::at(f64::INFINITY, 0), Partner::Nothing),
        );
        self.settle_best(i, &near, best);
    }

    /// The news of ball `i` of this region moving from cell `from` to `to`: whether it went
    /// over to a neighbour (and is a ghost here now).
    fn tell_crossing(&mut self, i: u32, from: u32, to: u32) -> bool {
        let (was, is) = (self.grid.column(from), self.grid.column(to));
        let gid = self.slots[i as usize].gid;
        if let Some(n) = self.shape.beyond(is) {
            // into the neighbour's strip: its ball now, and a ghost here
            self.slots[i as usize].owner = n;
            let g = self.ghost_of(i);
            self.outbox.push((n, News::Hand(g)));
            for m in self.shape.facing(was).filter(|&m| m != n) {
                self.outbox.push((m, News::Leave(gid)));
            }
            return true;
        }
        for n in self.shape.facing(is) {
            if !self.shape.facing(was).any(|m| m == n) {
                let g = self.ghost_of(i);
                self.outbox.push((n, News::Enter(g)));
            }
        }
        for n in self.shape.facing(was) {
            if !self.shape.facing(is).any(|m| m == n) {
                self.outbox.push((n, News::Leave(gid)));
            }
        }
        false
    }

    /// Takes in news from neighbour `from` at key `at` after the region ran its own events on
    /// to `reached`, past it, if that leaves the region as hearing it at `at` would have. It
    /// does when (unless asked `again`) a ghost's record has not changed columns since `at`,
    /// no ball turned and no ball of the region changed cells after `at` in the 3 × 3 blocks
    /// of cells around the record and around the ball's new cell, and the ball's new first
    /// event comes after `reached`. The events run since then met nothing the news changes,
    /// and the ball's new course meets nothing before `reached`: a prediction that read the
    /// old course only finds a stale event later, as in the event list. False if not; what
    /// it changed is in the journal then, to be put back.
    pub(super) fn take_in(
        &mut self,
        from: u32,
        news: &News,
        at: &Key,
        reached: &Key,
        again: bool,
    ) -> bool {
        let gid = match news {
            News::Enter(g) | News::Update(g) | News::Hand(g) => g.gid,
            News::Leave(gid) => *gid,
        };
        let old = self.local_of(gid).map(|i| i as usize);
        // news of a ghost places it in the column its record is in: the one it was in then (a
        // ball handed over goes to the border column)
        let placed = !matches!(news, News::Hand(_));
        let moved = placed && old.is_some_and(|i| self.cold[i].column_since >= at.t);
        let old = old.map(|i| self.slots[i].cell);
        if !again && (moved || old.is_some_and(|c| self.touched_near(c, at.t))) {
            return false;
        }
        // what the news changes stamps nothing: the executor takes in no earlier news after it
        self.set_touching(false);
        self.hear(from, news, at.t);
        self.set_touching(true);
        let Some(i) = self.local_of(gid) else {
            return true; // forgotten
        };
        let cell = self.slots[i as usize].cell;
        let touched = !again && self.touched_near(cell, at.t);
        cell == NOWHERE || (!touched && self.cold[i as usize].queued > *reached)
    }

    /// Takes in news from neighbour `from` at time `now`.
    pub(super) fn hear(&mut self, from: u32, news: &News, now: f64) {
        self.now = now;
        match news {
            News::Enter(g) | News::Update(g) => {
                if g.pocket.is_some() {
                    return self.forget(g.gid);
                }
                let column = self.local_of(g.gid).and_then(|i| {
                    let c = self.slots[i as usize].cell;
                    (c != NOWHERE).then(|| self.grid.column(c))
                });
                let i = self.admit(g, from, column);
                self.predict(i);
            }
            News::Leave(gid) => self.forget(*gid),
            News::Hand(g) => {
                let column = self.shape.border_facing(from);
                let i = self.admit(g, self.shape.me, Some(column));
                self.predict(i);
            }
        }
    }
}
