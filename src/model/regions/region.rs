//! One region's state: the balls whose cells it holds, the ghosts its neighbours keep it told
//! of, a cell grid over its strip and a calendar with one entry per ball; and how Time Warp
//! saves and restores it, by the old values of what each batch changes.
//!
//! Its events (the event-list algorithm over these records) are in the `events` module.

use super::events::CELL_CROSSING;
use super::{Ghost, News, RegionEvent, Shape};
use crate::engine::calendar::{Calendar, Entries, Place};
use crate::engine::grid::Grid;
use crate::engine::BallState;
use crate::geometry::Trajectory;
use crate::vtime::Key;
use pdes_kernel::prefetch::{prefetch, prefetch_all};
use pdes_kernel::Handle;
use rustc_hash::FxHashMap;
use std::sync::Arc;

/// The cell of a ball that is on no cell: pocketed, or a free record.
pub(super) const NOWHERE: u32 = u32::MAX;

/// What a ball's earliest predicted event is with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Partner {
    /// Nothing ever: pocketed, or alone.
    Nothing,
    /// A ball (local index) and its counter when the event was predicted.
    Ball(u32, u32),
    /// A fixed object (global index).
    Fixed(u32),
}

/// What a neighbour's prediction reads of a ball: one cache line.
#[derive(Clone, Copy, Debug)]
#[repr(align(64))]
pub struct Slot {
    /// Its trajectory since it last turned (for a pocketed ball: where it dropped in).
    pub(super) traj: Trajectory,
    /// Radius.
    pub(super) radius: f64,
    /// Goes up at every change of course, and when the record is freed: events predicted
    /// with an older value are stale.
    pub(super) counter: u32,
    /// Its grid cell ([`NOWHERE`] off the grid).
    pub(super) cell: u32,
    /// Its global index.
    pub(super) gid: u32,
    /// The region that owns it.
    pub(super) owner: u32,
}

/// The rest of a ball's record, read when the ball itself is handled.
#[derive(Clone, Debug)]
pub struct Cold {
    /// Mass.
    pub(super) mass: f64,
    /// The key of the event that fixed its trajectory.
    pub(super) fixed_at: Key,
    /// The pocket it dropped into.
    pub(super) pocket: Option<u32>,
    /// When its centre next leaves the cell, and the cell it enters.
    pub(super) cross: (f64, u32),
    /// Its earliest physical event and its partner.
    pub(super) phys: (Key, Partner),
    /// The key it is queued at.
    pub(super) queued: Key,
    /// Where its entry is in the calendar.
    pub(super) place: Place,
    /// When it last changed grid columns, or was placed in one.
    pub(super) column_since: f64,
    /// The stretch of the batch being run in which its old value was kept last (0: none
    /// since it was last put back): beside the rest of the record, which the event has
    /// loaded already, and not in an array of its own, which cost a cache miss per event.
    kept: u32,
}

/// The old value of one part of a region, recorded before a batch changes it, so that Time
/// Warp can put it back ([`Region::restore`]).
// a record's old value is kept inline: boxing it would cost an allocation per ball an
// event changes
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum Undo {
    /// Record `0` was this (with its cell and queued key).
    Ball(u32, Slot, Cold),
    /// Record `0` was added at the end.
    Grew(u32),
    /// Ball `0`'s local index was this.
    Local(u32, Option<u32>),
    /// A freed index was added to the free list.
    Freed,
    /// This freed index was taken from the free list.
    Reused(u32),
    /// The pending wake-up was this.
    Wake(Option<(Key, Handle)>),
}

/// What the calendar sees of a region's records, and the grid whose cells it prefetches.
pub(super) struct Queued<'a> {
    slots: &'a [Slot],
    cold: &'a mut [Cold],
    grid: &'a Grid,
    /// The cells' stamps ([`Region::touch`]) while the batch keeps old values: the event will
    /// stamp the cells of its balls.
    stamps: Option<&'a [f64]>,
}

impl Queued<'_> {
    /// Starts loading cell `c`'s stamp, when the batch stamps (none for [`NOWHERE`]).
    #[inline]
    fn prefetch_stamp(&self, c: u32) {
        if let Some(t) = self.stamps.and_then(|s| s.get(c as usize)) {
            prefetch(t);
        }
    }
}

impl Entries for Queued<'_> {
    #[inline]
    fn key(&self, i: u32) -> &Key {
        &self.cold[i as usize].queued
    }
    #[inline]
    fn place(&self, i: u32) -> Place {
        self.cold[i as usize].place
    }
    #[inline]
    fn set_place(&mut self, i: u32, place: Place) {
        self.cold[i as usize].place = place;
    }
    /// Its records start loading: they will be read at the next event.
    #[inline]
    fn opened(&self, i: u32) {
        prefetch_all(&self.cold[i as usize]);
        prefetch(&self.slots[i as usize]);
    }
    /// Its records have arrived: the partner's records and the cells its event reads start
    /// loading.
    #[inline]
    fn approaching(&self, i: u32) {
        let c = &self.cold[i as usize];
        self.prefetch_stamp(self.slots[i as usize].cell);
        if c.queued.path[..] == [CELL_CROSSING] {
            self.prefetch_stamp(c.cross.1);
            self.grid.prefetch_near(c.cross.1);
        } else if let Partner::Ball(j, _) = c.phys.1 {
            prefetch(&self.slots[j as usize]);
            prefetch_all(&self.cold[j as usize]);
            self.grid.prefetch_near(self.slots[i as usize].cell);
        }
    }
    /// The cells have arrived: the slots of the balls in them start loading.
    #[inline]
    fn imminent(&self, i: u32) {
        let (c, cell) = (&self.cold[i as usize], self.slots[i as usize].cell);
        if cell == NOWHERE {
            return;
        }
        if c.queued.path[..] == [CELL_CROSSING] {
            let slots = self.slots;
            (self.grid).for_each_entering(cell, c.cross.1, |j| prefetch(&slots[j as usize]));
        } else if let Partner::Ball(j, _) = c.phys.1 {
            let slots = self.slots;
            (self.grid).for_each_near(cell, |k| prefetch(&slots[k as usize]));
            self.grid.prefetch_near(self.slots[j as usize].cell);
            self.prefetch_stamp(self.slots[j as usize].cell);
        }
    }
}

/// A region: its balls and ghosts, its grid and its calendar.
#[derive(Clone)]
pub struct Region {
    /// Where the region lies and who its neighbours are.
    pub(super) shape: Arc<Shape>,
    /// Balls and ghosts by local index (freed records are reused): what neighbours read.
    pub(super) slots: Vec<Slot>,
    /// The rest of each record.
    pub(super) cold: Vec<Cold>,
    /// Local index by global index.
    local: FxHashMap<u32, u32>,
    /// Freed local indices.
    free: Vec<u32>,
    pub(super) grid: Grid,
    /// Every ball's queued event.
    queue: Calendar,
    /// The time of the batch being run.
    pub(super) now: f64,
    /// The wake-up message the region sent itself, if it is still to come: its key and handle.
    wake: Option<(Key, Handle)>,
    /// Whether the batch being run keeps the old values of what it changes.
    journaling: bool,
    /// Old values kept in the batch being run, oldest first.
    pub(super) journal: Vec<Undo>,
    /// The stretch of the batch being run: a batch's start, or one of its own events it runs
    /// on to ([`Region::next_stretch`]).
    stretch: u32,
    /// By cell: the latest time a ball there turned, or a ball of the region left or entered
    /// it (while journaling), in events run on or undone since: what [`Region::take_in`]
    /// asks. Not journaled: the stamps of events undone only make it refuse more.
    touched: Vec<f64>,
    /// Whether changes stamp their cells (not while news is taken in).
    touching: bool,
    /// News for the neighbours from the batch being run, in order.
    pub(super) outbox: Vec<(u32, News)>,
    /// Events the batch being run reports, each at its key.
    pub(super) reports: Vec<(Key, RegionEvent)>,
}

impl Region {
    /// An empty region of `shape`.
    pub(super) fn new(shape: Arc<Shape>, start: f64) -> Region {
        let grid = Grid::with_dims(&shape.table, 0, shape.rmax, (shape.columns, shape.rows));
        let cells = (shape.columns * shape.rows) as usize;
        Region {
            shape,
            slots: Vec::new(),
            cold: Vec::new(),
            local: FxHashMap::default(),
            free: Vec::new(),
            grid,
            queue: Calendar::heap_only(start),
            now: start,
            wake: None,
            journaling: false,
            journal: Vec::new(),
            stretch: 0,
            touched: vec![f64::NEG_INFINITY; cells],
            touching: true,
            outbox: Vec::new(),
            reports: Vec::new(),
        }
    }

    /// Makes room for `n` more records.
    pub(super) fn reserve(&mut self, n: usize) {
        self.slots.reserve_exact(n);
        self.cold.reserve_exact(n);
        self.local.reserve(n);
    }

    /// Grid columns of its strip.
    pub fn strip_columns(&self) -> u32 {
        self.shape.columns - 2
    }

    /// Balls it owns, pocketed ones included.
    pub fn owned(&self) -> usize {
        let me = self.shape.me;
        (self.local.values())
            .filter(|&&i| self.slots[i as usize].owner == me)
            .count()
    }

    /// About how many news a second come to the region: each ghost turns or crosses a cell
    /// about once per cell width it travels, so its speed over a cell's width, summed.
    pub fn news_rate(&self) -> f64 {
        let me = self.shape.me;
        let width = self.grid.cell_size().x;
        (self.local.values())
            .map(|&i| &self.slots[i as usize])
            .filter(|s| s.owner != me && s.cell != NOWHERE)
            .map(|s| s.traj.velocity.norm() / width)
            .sum()
    }

    /// Ball `gid`'s state as last fixed, if this region owns it.
    pub fn ball(&self, gid: u32) -> Option<BallState> {
        let i = *self.local.get(&gid)? as usize;
        let (s, c) = (&self.slots[i], &self.cold[i]);
        (s.owner == self.shape.me).then_some(BallState {
            traj: s.traj,
            radius: s.radius,
            mass: c.mass,
            pocket: c.pocket,
        })
    }

    /// Whether this region owns record `i`.
    #[inline]
    pub(super) fn mine(&self, i: u32) -> bool {
        self.slots[i as usize].owner == self.shape.me
    }

    /// Starts a batch that keeps the old values of what it changes in `journal` (the
    /// executor's, swapped in until [`Region::end`]), or keeps none.
    pub(super) fn begin(&mut self, journal: Option<&mut Vec<Undo>>) {
        self.next_stretch();
        self.journaling = journal.is_some();
        if let Some(j) = journal {
            std::mem::swap(&mut self.journal, j);
        }
    }

    /// Ends a batch: gives the executor's journal back, with the old values it kept.
    pub(super) fn end(&mut self, journal: Option<&mut Vec<Undo>>) {
        if let Some(j) = journal.filter(|_| self.journaling) {
            std::mem::swap(&mut self.journal, j);
        }
        self.journaling = false;
    }

    /// Keeps `undo` if the batch keeps old values.
    #[inline]
    fn log(&mut self, undo: impl FnOnce(&Region) -> Undo) {
        if self.journaling {
            let u = undo(self);
            self.journal.push(u);
        }
    }

    /// Starts a stretch of the batch: records are kept anew from here, so that the executor
    /// can undo the batch back to this point alone.
    pub(super) fn next_stretch(&mut self) {
        self.stretch = self.stretch.wrapping_add(1).max(1);
        if self.stretch == 1 {
            self.cold.iter_mut().for_each(|c| c.kept = 0);
        }
    }

    /// Keeps record `i` as it is, once per stretch of a batch, before the batch changes it.
    #[inline]
    pub(super) fn keep(&mut self, i: u32) {
        if !self.journaling {
            return;
        }
        let k = i as usize;
        if self.cold[k].kept != self.stretch {
            self.cold[k].kept = self.stretch;
            let (s, c) = (self.slots[k], self.cold[k].clone());
            self.journal.push(Undo::Ball(i, s, c));
        }
    }

    /// Stamps cell `c` (if any) with the time of the event being run: a ball there turned, or
    /// one of the region's balls left or entered it ([`Region::touched_near`]).
    #[inline]
    pub(super) fn touch(&mut self, c: u32) {
        if self.touching && self.journaling && c != NOWHERE {
            let t = &mut self.touched[c as usize];
            *t = t.max(self.now);
        }
    }

    /// Whether an event at `t` or later stamped a cell of the 3 × 3 block around cell `c`
    /// (never for a record on no cell).
    pub(super) fn touched_near(&self, c: u32, t: f64) -> bool {
        c != NOWHERE && (self.grid.cells_near(c)).any(|k| self.touched[k as usize] >= t)
    }

    /// Sets whether changes stamp their cells.
    pub(super) fn set_touching(&mut self, on: bool) {
        self.touching = on;
    }

    /// The pending wake-up.
    pub(super) fn wake(&self) -> Option<&(Key, Handle)> {
        self.wake.as_ref()
    }

    /// Sets the pending wake-up.
    pub(super) fn set_wake(&mut self, wake: Option<(Key, Handle)>) {
        self.log(|r| Undo::Wake(r.wake.clone()));
        self.wake = wake;
    }

    /// Puts back one old value (Time Warp's rollback, latest first).
    pub fn restore(&mut self, undo: Undo) {
        match undo {
            Undo::Ball(i, slot, cold) => {
                self.unqueue(i);
                let cur = self.slots[i as usize].cell;
                if cur != NOWHERE {
                    self.grid.remove_from(i, cur);
                }
                if slot.cell != NOWHERE {
                    self.grid.insert(i, slot.cell);
                }
                self.slots[i as usize] = slot;
                self.cold[i as usize] = Cold {
                    place: Place::NOWHERE,
                    kept: 0,
                    ..cold
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

    /// The record with the earliest queued event, if any.
    pub(super) fn first(&mut self) -> Option<u32> {
        let (queue, mut entries) = self.calendar();
        queue.first(&mut entries)
    }

    /// The key of its earliest queued event, if any.
    pub(super) fn first_key(&mut self) -> Option<&Key> {
        let i = self.first()?;
        Some(&self.cold[i as usize].queued)
    }

    /// The calendar, and what it sees of the records.
    fn calendar(&mut self) -> (&mut Calendar, Queued<'_>) {
        let entries = Queued {
            slots: &self.slots,
            cold: &mut self.cold,
            grid: &self.grid,
            stamps: (self.journaling && self.touching).then_some(&self.touched[..]),
        };
        (&mut self.queue, entries)
    }

    /// Takes record `i` out of the calendar.
    fn unqueue(&mut self, i: u32) {
        self.cold[i as usize].queued = Key::at(f64::INFINITY, 0);
        let (queue, mut entries) = self.calendar();
        queue.set(&mut entries, i);
    }

    /// Puts record `i` into the calendar at its queued key.
    pub(super) fn enqueue(&mut self, i: u32) {
        let (queue, mut entries) = self.calendar();
        queue.set(&mut entries, i);
    }

    /// Lays the calendar out for the region's balls, once their first events are predicted:
    /// its buckets as wide as three of the mean gaps between them.
    pub(super) fn settle(&mut self, start: f64) {
        let times: Vec<f64> = (self.cold.iter())
            .map(|c| c.queued.t)
            .filter(|t| t.is_finite())
            .collect();
        let n = times.len().max(1) as f64;
        let gap = times.iter().map(|t| t - start).sum::<f64>() / n / n;
        self.queue = Calendar::heap_only(start);
        self.queue = Calendar::new(self.slots.len(), start, gap);
        for i in 0..self.slots.len() as u32 {
            self.cold[i as usize].place = Place::NOWHERE;
            self.enqueue(i);
        }
    }

    /// Takes ball or ghost `g` in, owned by `owner`, in the cell of its centre now (or in
    /// column `column` of this region's grid), without predicting anything.
    pub(super) fn admit(&mut self, g: &Ghost, owner: u32, column: Option<u32>) -> u32 {
        let i = match self.local.get(&g.gid) {
            Some(&i) => {
                self.unplace(i);
                i
            }
            None => self.fresh(g.gid),
        };
        self.keep(i);
        let never = Key::at(f64::INFINITY, 0);
        let counter = self.slots[i as usize].counter.wrapping_add(1);
        let mut cell = NOWHERE;
        if g.pocket.is_none() {
            let p = g.traj.at(self.now);
            cell = match column {
                Some(cx) => self.grid.insert_in_column(i, cx, p),
                None => self.grid.insert_at(i, p),
            };
        }
        self.slots[i as usize] = Slot {
            traj: g.traj,
            radius: g.radius,
            counter,
            cell,
            gid: g.gid,
            owner,
        };
        self.cold[i as usize] = Cold {
            mass: g.mass,
            fixed_at: g.fixed_at.clone(),
            pocket: g.pocket,
            cross: (f64::INFINITY, 0),
            phys: (never.clone(), Partner::Nothing),
            queued: never,
            place: Place::NOWHERE,
            column_since: self.now,
            kept: self.cold[i as usize].kept,
        };
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
                let i = self.slots.len() as u32;
                self.log(|_| Undo::Grew(i));
                let never = Key::at(f64::INFINITY, 0);
                self.slots.push(Slot {
                    traj: Trajectory {
                        position: Default::default(),
                        velocity: Default::default(),
                        t0: 0.0,
                    },
                    radius: 0.0,
                    counter: 0,
                    cell: NOWHERE,
                    gid,
                    owner: u32::MAX,
                });
                self.cold.push(Cold {
                    mass: 0.0,
                    fixed_at: never.clone(),
                    pocket: None,
                    cross: (f64::INFINITY, 0),
                    phys: (never.clone(), Partner::Nothing),
                    queued: never,
                    place: Place::NOWHERE,
                    column_since: f64::NEG_INFINITY,
                    kept: 0,
                });
                self.grid.hold_balls(self.slots.len());
                i
            }
        };
        self.log(|r| Undo::Local(gid, r.local.get(&gid).copied()));
        self.local.insert(gid, i);
        i
    }

    /// Takes record `i` off its cell and out of the calendar.
    pub(super) fn unplace(&mut self, i: u32) {
        self.keep(i);
        let s = &mut self.slots[i as usize];
        if s.cell != NOWHERE {
            self.grid.remove_from(i, s.cell);
            s.cell = NOWHERE;
        }
        self.unqueue(i);
    }

    /// Forgets ghost `gid` (it went out of reach).
    pub(super) fn forget(&mut self, gid: u32) {
        if let Some(&i) = self.local.get(&gid) {
            self.log(|_| Undo::Local(gid, Some(i)));
            self.local.remove(&gid);
            self.unplace(i);
            let s = &mut self.slots[i as usize];
            s.counter = s.counter.wrapping_add(1);
            s.owner = u32::MAX;
            self.log(|_| Undo::Freed);
            self.free.push(i);
        }
    }

    /// The local index of ball `gid`, if the region knows it.
    pub(super) fn local_of(&self, gid: u32) -> Option<u32> {
        self.local.get(&gid).copied()
    }

    /// Record `i` as news for a neighbour.
    /// The balls it owns, as their neighbours would hear of them.
    pub(super) fn owned_balls(&self) -> Vec<Ghost> {
        let me = self.shape.me;
        let mut balls: Vec<Ghost> = (self.local.values())
            .filter(|&&i| self.slots[i as usize].owner == me)
            .map(|&i| self.ghost_of(i))
            .collect();
        balls.sort_by_key(|g| g.gid);
        balls
    }

    pub(super) fn ghost_of(&self, i: u32) -> Ghost {
        let (s, c) = (&self.slots[i as usize], &self.cold[i as usize]);
        Ghost {
            gid: s.gid,
            traj: s.traj,
            radius: s.radius,
            mass: c.mass,
            fixed_at: c.fixed_at.clone(),
            pocket: c.pocket,
        }
    }
}
