//! One region's state and its event-list algorithm: the balls whose centres it holds, the
//! ghosts its neighbours keep it told of, a cell grid over its strip and a queue with one
//! entry per ball.
//!
//! A region runs, for its own balls, exactly what the event-list engine runs: each ball keeps
//! its earliest predicted event (another ball, a fixed object, or leaving its cell), and a
//! popped event whose partner changed course since is stale and only recomputed. A ghost is a
//! neighbour's ball near the border: the region predicts its contacts with its own balls (both
//! regions then run such a collision, each for its own ball, from the same two trajectories),
//! and follows it from cell to cell, but leaves everything else it meets to its owner, who
//! sends its new course.

use super::{Ghost, News, RegionEvent, Shape};
use crate::engine::calendar::{Calendar, Entries, Place};
use crate::engine::grid::Grid;
use crate::engine::{BallState, Event, EventKind, Fixed};
use crate::geometry::Trajectory;
use crate::physics::{self, Contact};
use crate::vtime::{pair, Key};
use rustc_hash::FxHashMap;
use std::cmp::Ordering;
use std::sync::Arc;

/// The pair code of a ball leaving its cell: after every physical event of its instant.
const CELL_CROSSING: u64 = u64::MAX;

/// The cell of a ball that is on no cell: pocketed, or a free record.
const NOWHERE: u32 = u32::MAX;

/// What a ball's earliest predicted event is with.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Partner {
    /// Nothing ever: pocketed, or alone.
    Nothing,
    /// A ball (local index) and its counter when the event was predicted.
    Ball(u32, u32),
    /// A fixed object (global index).
    Fixed(u32),
}

/// A ball as a region knows it: one of its own, or a ghost.
#[derive(Clone, Debug)]
pub struct Known {
    /// Its global index.
    pub(super) gid: u32,
    /// Its trajectory since it last turned (for a pocketed ball: where it dropped in).
    pub(super) traj: Trajectory,
    /// Radius.
    pub(super) radius: f64,
    /// Mass.
    pub(super) mass: f64,
    /// The key of the event that fixed its trajectory.
    pub(super) fixed_at: Key,
    /// The region that owns it.
    pub(super) owner: u32,
    /// The pocket it dropped into.
    pub(super) pocket: Option<u32>,
    /// Goes up at every change of course, and when the record is freed: events predicted
    /// with an older value are stale.
    counter: u32,
    /// Its grid cell ([`NOWHERE`] off the grid).
    cell: u32,
    /// When its centre next leaves the cell, and the cell it enters.
    cross: (f64, u32),
    /// Its earliest physical event and its partner.
    phys: (Key, Partner),
    /// The key it is queued at.
    queued: Key,
    /// Where its entry is in the calendar.
    place: Place,
}

/// What the calendar sees of a region's records.
struct Queued<'a> {
    balls: &'a mut [Known],
}

impl Entries for Queued<'_> {
    #[inline]
    fn key(&self, i: u32) -> &Key {
        &self.balls[i as usize].queued
    }
    #[inline]
    fn place(&self, i: u32) -> Place {
        self.balls[i as usize].place
    }
    #[inline]
    fn set_place(&mut self, i: u32, place: Place) {
        self.balls[i as usize].place = place;
    }
    #[inline]
    fn opened(&self, i: u32) {
        pdes_kernel::prefetch::prefetch_all(&self.balls[i as usize]);
    }
}

/// The old value of one part of a region, recorded before a batch changes it, so that Time
/// Warp can put it back ([`Region::restore`]).
#[derive(Clone, Debug)]
pub enum Undo {
    /// Record `0` was this (with its cell and queued key).
    Ball(u32, Box<Known>),
    /// Record `0` was added at the end.
    Grew(u32),
    /// Ball `0`'s local index was this.
    Local(u32, Option<u32>),
    /// A freed index was added to the free list.
    Freed,
    /// This freed index was taken from the free list.
    Reused(u32),
    /// The pending wake-up was this.
    Wake(Option<(Key, pdes_kernel::Handle)>),
}

/// A region: its balls and ghosts, its grid and its queue.
#[derive(Clone)]
pub struct Region {
    /// Where the region lies and who its neighbours are.
    shape: Arc<Shape>,
    /// Balls and ghosts by local index (freed records are reused).
    pub(super) balls: Vec<Known>,
    /// Local index by global index.
    local: FxHashMap<u32, u32>,
    /// Freed local indices.
    free: Vec<u32>,
    grid: Grid,
    /// Every ball's queued event.
    queue: Calendar,
    /// The time of the batch being run.
    now: f64,
    /// The wake-up message the region sent itself, if it is still to come: its key and handle.
    wake: Option<(Key, pdes_kernel::Handle)>,
    /// Whether the batch being run keeps the old values of what it changes.
    journaling: bool,
    /// Old values kept in the batch being run, oldest first.
    journal: Vec<Undo>,
    /// Records whose old values the batch being run has kept.
    kept: Vec<u32>,
}

/// What one event of a region produced: the physical event to report (if this region reports
/// it) and the news its neighbours must hear, in order.
#[derive(Default)]
pub(super) struct Done {
    pub(super) event: Option<RegionEvent>,
    pub(super) news: Vec<(u32, News)>,
}

impl Region {
    /// An empty region of `shape` with room for `n` balls.
    pub(super) fn new(shape: Arc<Shape>, n: usize, start: f64) -> Region {
        let grid = Grid::with_dims(&shape.table, n, shape.rmax, (shape.columns, shape.rows));
        Region {
            shape,
            balls: Vec::with_capacity(n),
            local: FxHashMap::default(),
            free: Vec::new(),
            grid,
            queue: Calendar::heap_only(start),
            now: start,
            wake: None,
            journaling: false,
            journal: Vec::new(),
            kept: Vec::new(),
        }
    }

    /// Starts a batch: whether it keeps the old values of what it changes.
    pub(super) fn begin(&mut self, journaling: bool) {
        self.journaling = journaling;
        self.kept.clear();
    }

    /// Ends a batch: the old values it kept, oldest first.
    pub(super) fn end(&mut self) -> std::vec::Drain<'_, Undo> {
        self.journaling = false;
        self.journal.drain(..)
    }

    /// Keeps `undo` if the batch keeps old values.
    #[inline]
    fn log(&mut self, undo: impl FnOnce(&Region) -> Undo) {
        if self.journaling {
            let u = undo(self);
            self.journal.push(u);
        }
    }

    /// Keeps record `i` as it is, once per batch, before the batch changes it.
    #[inline]
    fn keep(&mut self, i: u32) {
        if self.journaling && !self.kept.contains(&i) {
            self.kept.push(i);
            let old = Box::new(self.balls[i as usize].clone());
            self.journal.push(Undo::Ball(i, old));
        }
    }

    /// The pending wake-up.
    pub(super) fn wake(&self) -> Option<&(Key, pdes_kernel::Handle)> {
        self.wake.as_ref()
    }

    /// Sets the pending wake-up.
    pub(super) fn set_wake(&mut self, wake: Option<(Key, pdes_kernel::Handle)>) {
        self.log(|r| Undo::Wake(r.wake.clone()));
        self.wake = wake;
    }

    /// Puts back one old value (Time Warp's rollback, latest first).
    pub fn restore(&mut self, undo: Undo) {
        match undo {
            Undo::Ball(i, old) => {
                self.unqueue(i);
                let cur = &self.balls[i as usize];
                if cur.cell != NOWHERE {
                    self.grid.remove_from(i, cur.cell);
                }
                if old.cell != NOWHERE {
                    self.grid.insert(i, old.cell);
                }
                self.balls[i as usize] = Known {
                    place: Place::NOWHERE,
                    ..*old
                };
                self.enqueue(i);
            }
            // the record stays (the calendar may still name it), free for reuse
            Undo::Grew(i) => self.free.push(i),
            Undo::Local(gid, old) => {
                match old {
                    Some(i) => self.local.insert(gid, i),
                    None => self.local.remove(&gid),
                };
            }
            Undo::Freed => {
                self.free.pop();
            }
            Undo::Reused(i) => self.free.push(i),
            Undo::Wake(w) => self.wake = w,
        }
    }

    /// The region's index.
    pub fn index(&self) -> u32 {
        self.shape.me
    }

    /// Grid columns of its strip.
    pub fn strip_columns(&self) -> u32 {
        self.shape.columns - 2
    }

    /// Balls it owns, pocketed ones included.
    pub fn owned(&self) -> usize {
        let me = self.shape.me;
        (self.local.values())
            .filter(|&&i| self.balls[i as usize].owner == me)
            .count()
    }

    /// Ball `gid`'s state as last fixed, if this region owns it.
    pub fn ball(&self, gid: u32) -> Option<BallState> {
        let b = &self.balls[*self.local.get(&gid)? as usize];
        (b.owner == self.shape.me).then_some(BallState {
            traj: b.traj,
            radius: b.radius,
            mass: b.mass,
            pocket: b.pocket,
        })
    }

    /// The record with the earliest queued event, if any.
    fn first(&mut self) -> Option<u32> {
        let (queue, mut entries) = self.calendar();
        queue.first(&mut entries)
    }

    /// The key of its earliest queued event, if any.
    pub(super) fn first_key(&mut self) -> Option<&Key> {
        let i = self.first()?;
        Some(&self.balls[i as usize].queued)
    }

    /// The calendar, and what it sees of the records.
    fn calendar(&mut self) -> (&mut Calendar, Queued<'_>) {
        let entries = Queued {
            balls: &mut self.balls,
        };
        (&mut self.queue, entries)
    }

    /// Takes record `i` out of the calendar.
    fn unqueue(&mut self, i: u32) {
        self.balls[i as usize].queued = Key::at(f64::INFINITY, 0);
        let (queue, mut entries) = self.calendar();
        queue.set(&mut entries, i);
    }

    /// Puts record `i` into the calendar at its queued key.
    fn enqueue(&mut self, i: u32) {
        let (queue, mut entries) = self.calendar();
        queue.set(&mut entries, i);
    }

    /// Lays the calendar out for the region's balls, once their first events are predicted:
    /// its buckets as wide as three of the mean gaps between them.
    pub(super) fn settle(&mut self, start: f64) {
        let times: Vec<f64> = (self.balls.iter())
            .map(|b| b.queued.t)
            .filter(|t| t.is_finite())
            .collect();
        let n = times.len().max(1) as f64;
        let gap = times.iter().map(|t| t - start).sum::<f64>() / n / n;
        self.queue = Calendar::heap_only(start);
        self.queue = Calendar::new(self.balls.len(), start, gap);
        for i in 0..self.balls.len() as u32 {
            self.balls[i as usize].place = Place::NOWHERE;
            self.enqueue(i);
        }
    }

    /// Takes ball or ghost `g` in, in the cell of its centre at `now` (or in column `column`
    /// of this region's grid), without predicting anything.
    pub(super) fn admit(&mut self, g: &Ghost, owner: u32, column: Option<u32>) -> u32 {
        let i = match self.local.get(&g.gid) {
            Some(&i) => {
                self.unplace(i);
                i
            }
            None => self.fresh(g.gid),
        };
        self.keep(i);
        let counter = self.balls[i as usize].counter.wrapping_add(1);
        let key = Key::at(f64::INFINITY, 0);
        self.balls[i as usize] = Known {
            gid: g.gid,
            traj: g.traj,
            radius: g.radius,
            mass: g.mass,
            fixed_at: g.fixed_at.clone(),
            owner,
            pocket: g.pocket,
            counter,
            cell: NOWHERE,
            cross: (f64::INFINITY, 0),
            phys: (key.clone(), Partner::Nothing),
            queued: key,
            place: Place::NOWHERE,
        };
        if g.pocket.is_none() {
            let p = g.traj.at(self.now);
            self.balls[i as usize].cell = match column {
                Some(cx) => self.grid.insert_in_column(i, cx, p),
                None => self.grid.insert_at(i, p),
            };
        }
        i
    }

    /// A local index for ball `gid`, new or reused.
    fn fresh(&mut self, gid: u32) -> u32 {
        let i = match self.free.pop() {
            Some(i) => {
                self.log(|_| Undo::Reused(i));
                i
            }
            None => {
                let i = self.balls.len() as u32;
                self.log(|_| Undo::Grew(i));
                self.balls.push(Known {
                    gid,
                    traj: Trajectory {
                        position: Default::default(),
                        velocity: Default::default(),
                        t0: 0.0,
                    },
                    radius: 0.0,
                    mass: 0.0,
                    fixed_at: Key::at(0.0, 0),
                    owner: 0,
                    pocket: None,
                    counter: 0,
                    cell: NOWHERE,
                    cross: (f64::INFINITY, 0),
                    phys: (Key::at(f64::INFINITY, 0), Partner::Nothing),
                    queued: Key::at(f64::INFINITY, 0),
                    place: Place::NOWHERE,
                });
                self.grid.hold_balls(self.balls.len());
                i
            }
        };
        self.log(|r| Undo::Local(gid, r.local.get(&gid).copied()));
        self.local.insert(gid, i);
        i
    }

    /// Takes record `i` off its cell and out of the queue.
    fn unplace(&mut self, i: u32) {
        self.keep(i);
        let b = &mut self.balls[i as usize];
        if b.cell != NOWHERE {
            self.grid.remove_from(i, b.cell);
            b.cell = NOWHERE;
        }
        self.unqueue(i);
    }

    /// Forgets ghost `gid` (it went out of reach).
    fn forget(&mut self, gid: u32) {
        if let Some(&i) = self.local.get(&gid) {
            self.log(|_| Undo::Local(gid, Some(i)));
            self.local.remove(&gid);
            self.unplace(i);
            let b = &mut self.balls[i as usize];
            b.counter = b.counter.wrapping_add(1);
            self.log(|_| Undo::Freed);
            self.free.push(i);
        }
    }

    /// Whether this region owns record `i`.
    #[inline]
    fn mine(&self, i: u32) -> bool {
        self.balls[i as usize].owner == self.shape.me
    }

    /// The earliest contact of ball `i` with ball `j` offered to `best`.
    fn offer_ball(&self, i: u32, j: u32, best: &mut (Key, Partner)) {
        let (a, b) = (&self.balls[i as usize], &self.balls[j as usize]);
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
            Contact::Immediate => a.fixed_at.clone().max(b.fixed_at.clone()).child(p),
        };
        if key < best.0 {
            *best = (key, Partner::Ball(j, b.counter));
        }
    }

    /// The earliest contact of ball `i` with the fixed objects near its cell offered to `best`.
    fn offer_fixed(&self, i: u32, best: &mut (Key, Partner)) {
        let b = &self.balls[i as usize];
        for &f in self.grid.fixed_near(b.cell) {
            let p = pair(b.gid, f);
            let key = match self.shape.table.contact(f, &b.traj, b.radius) {
                Contact::Never => continue,
                Contact::At(t) => {
                    if best.0.cmp_at(t, p) != Ordering::Greater {
                        continue;
                    }
                    Key::at(t, p)
                }
                Contact::Immediate => b.fixed_at.child(p),
            };
            if key < best.0 {
                *best = (key, Partner::Fixed(f));
            }
        }
    }

    /// Recomputes record `i`'s earliest event and cell exit, and queues it. A ball of this
    /// region meets everything near it; a ghost only this region's balls.
    pub(super) fn predict(&mut self, i: u32) {
        self.keep(i);
        let mut best = (Key::at(f64::INFINITY, 0), Partner::Nothing);
        let cell = self.balls[i as usize].cell;
        if cell != NOWHERE {
            let mine = self.mine(i);
            let mut near = smallvec::SmallVec::<[u32; 48]>::new();
            self.grid.for_each_near(cell, |j| {
                if j != i && (mine || self.mine(j)) {
                    near.push(j);
                }
            });
            for &j in &near {
                self.offer_ball(i, j, &mut best);
            }
            if mine {
                self.offer_fixed(i, &mut best);
            }
        }
        let b = &self.balls[i as usize];
        let exit = if cell == NOWHERE {
            None
        } else {
            self.grid
                .exit(cell, b.traj.position, b.traj.velocity, b.traj.t0)
        };
        let now = self.now;
        let b = &mut self.balls[i as usize];
        b.phys = best;
        b.cross = exit.map_or((f64::INFINITY, 0), |(t, c)| (t.max(now), c));
        self.requeue(i);
    }

    /// Queues record `i` at the earlier of its physical event and its cell exit.
    fn requeue(&mut self, i: u32) {
        let b = &mut self.balls[i as usize];
        let key = if b.phys.0.cmp_at(b.cross.0, CELL_CROSSING) == Ordering::Greater {
            Key::at(b.cross.0, CELL_CROSSING)
        } else {
            b.phys.0.clone()
        };
        b.queued = key;
        self.enqueue(i);
    }

    /// Runs every queued event at `key`: the batch of the region's wake-up at `key`.
    pub(super) fn run_due(&mut self, key: &Key, done: &mut Vec<Done>) {
        self.now = key.t;
        while let Some(i) = self.first() {
            let k = self.balls[i as usize].queued.clone();
            if k > *key {
                break;
            }
            debug_assert!(k == *key, "a region's event {k:?} was left behind {key:?}");
            if k.path[..] == [CELL_CROSSING] {
                let out = self.cross(i);
                done.push(out);
                continue;
            }
            match self.balls[i as usize].phys.1 {
                Partner::Nothing => {
                    self.predict(i);
                }
                Partner::Ball(j, seen) if self.balls[j as usize].counter != seen => {
                    self.predict(i);
                }
                Partner::Ball(j, _) => done.push(self.collide(i, j, &k)),
                Partner::Fixed(f) => done.push(self.hit(i, f, &k)),
            }
        }
    }

    /// Sets record `i` on a new course from `key` on.
    fn turn(&mut self, i: u32, key: &Key, velocity: crate::geometry::Vec2) {
        self.keep(i);
        let b = &mut self.balls[i as usize];
        b.traj = Trajectory {
            position: b.traj.at(key.t),
            velocity,
            t0: key.t,
        };
        b.counter = b.counter.wrapping_add(1);
        b.fixed_at = key.clone();
    }

    /// Balls `i` and `j` collide at `key`.
    fn collide(&mut self, i: u32, j: u32, key: &Key) -> Done {
        let (a, b) = if self.balls[i as usize].gid < self.balls[j as usize].gid {
            (i, j)
        } else {
            (j, i)
        };
        let (ka, kb) = (&self.balls[a as usize], &self.balls[b as usize]);
        let (va, vb) = physics::ball_ball_velocities(
            ka.traj.at(key.t),
            ka.traj.velocity,
            ka.mass,
            kb.traj.at(key.t),
            kb.traj.velocity,
            kb.mass,
        );
        let event = Event {
            t: key.t,
            kind: EventKind::BallBall,
            a: ka.gid,
            b: kb.gid,
        };
        // the region that runs it last (the higher index) reports it, so that both balls have
        // their new courses when an observer looks
        let reporter = ka.owner.max(kb.owner);
        let across = ka.owner != kb.owner;
        self.turn(a, key, va);
        self.turn(b, key, vb);
        self.predict(a);
        self.predict(b);
        let mut done = Done {
            event: (reporter == self.shape.me).then_some(RegionEvent { event, across }),
            news: Vec::new(),
        };
        let (oa, ob) = (self.balls[a as usize].owner, self.balls[b as usize].owner);
        self.tell_course(a, ob, &mut done.news);
        self.tell_course(b, oa, &mut done.news);
        done
    }

    /// Ball `i` hits fixed object `f` at `key`: it bounces, or drops into a pocket.
    fn hit(&mut self, i: u32, f: u32, key: &Key) -> Done {
        let b = &self.balls[i as usize];
        let table = &self.shape.table;
        let event = Event {
            t: key.t,
            kind: table.event_kind(f),
            a: b.gid,
            b: f,
        };
        let mut done = Done {
            event: Some(RegionEvent {
                event,
                across: false,
            }),
            news: Vec::new(),
        };
        let column = self.grid.column(b.cell);
        match table.bounce(f, b.traj.at(key.t), b.traj.velocity) {
            Some(v) => {
                self.turn(i, key, v);
                self.predict(i);
                self.tell_course(i, self.shape.me, &mut done.news);
            }
            None => {
                let v = b.traj.velocity;
                let Fixed::Pocket(k) = table.fixed(f) else {
                    unreachable!("only pockets swallow balls")
                };
                self.turn(i, key, v);
                self.unplace(i);
                self.balls[i as usize].pocket = Some(k);
                let gid = self.balls[i as usize].gid;
                for n in self.shape.facing(column) {
                    done.news.push((n, News::Leave(gid)));
                }
            }
        }
        done
    }

    /// Tells the neighbours that see ball `i` of its new course, if it is this region's and
    /// the neighbour did not run the event itself (its partner's owner `shared`).
    fn tell_course(&self, i: u32, shared: u32, news: &mut Vec<(u32, News)>) {
        if !self.mine(i) {
            return;
        }
        let column = self.grid.column(self.balls[i as usize].cell);
        for n in self.shape.facing(column) {
            if n != shared {
                news.push((n, News::Update(self.ghost_of(i))));
            }
        }
    }

    /// Record `i` as news for a neighbour.
    pub(super) fn ghost_of(&self, i: u32) -> Ghost {
        let b = &self.balls[i as usize];
        Ghost {
            gid: b.gid,
            traj: b.traj,
            radius: b.radius,
            mass: b.mass,
            fixed_at: b.fixed_at.clone(),
            pocket: b.pocket,
        }
    }

    /// Record `i`'s centre leaves its cell: it moves on in the grid, and a ball of this region
    /// that comes near a border, leaves it, or crosses it changes who must hear of it.
    fn cross(&mut self, i: u32) -> Done {
        self.keep(i);
        let b = &self.balls[i as usize];
        let (from, to) = (b.cell, b.cross.1);
        self.grid.remove_from(i, from);
        self.grid.insert(i, to);
        self.balls[i as usize].cell = to;
        let mut done = Done::default();
        if self.mine(i) {
            let (was, is) = (self.grid.column(from), self.grid.column(to));
            let gid = self.balls[i as usize].gid;
            if let Some(n) = self.shape.beyond(is) {
                // into the neighbour's strip: its ball now, and a ghost here
                self.balls[i as usize].owner = n;
                done.news.push((n, News::Hand(self.ghost_of(i))));
                for m in self.shape.facing(was) {
                    if m != n {
                        done.news.push((m, News::Leave(gid)));
                    }
                }
            } else {
                let (before, after) = (self.shape.facing(was), self.shape.facing(is));
                for &n in &after {
                    if !before.contains(&n) {
                        done.news.push((n, News::Enter(self.ghost_of(i))));
                    }
                }
                for &n in &before {
                    if !after.contains(&n) {
                        done.news.push((n, News::Leave(gid)));
                    }
                }
            }
        }
        self.predict(i);
        done
    }

    /// Takes in news from a neighbour at time `now`.
    pub(super) fn hear(&mut self, from: u32, news: &News, now: f64) {
        self.now = now;
        match news {
            News::Enter(g) | News::Update(g) => {
                let column = self.local.get(&g.gid).and_then(|&i| {
                    let c = self.balls[i as usize].cell;
                    (c != NOWHERE).then(|| self.grid.column(c))
                });
                if g.pocket.is_some() {
                    self.forget(g.gid);
                    return;
                }
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
