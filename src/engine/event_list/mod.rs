//! The event-list engine (thesis fig. 2): the reference every other engine must reproduce.
//!
//! Each ball keeps only its own earliest predicted event (another ball, a fixed object, or leaving
//! its grid cell), and a calendar queue over the balls yields the earliest of all in O(1).
//! When ball `i` changes velocity its counter goes up; an event whose partner's counter moved on is
//! stale, and popping it merely recomputes its owner's next event. An event therefore costs a
//! bounded number of pair tests (the 3 × 3 cells around each ball involved) and O(1) queue
//! work, never O(N).
//!
//! Order: events run by their virtual-time [`Key`]. A prediction is a pure function of the two
//! trajectories and the keys at which they were fixed, so the order of simultaneous and
//! instantaneous events is exactly the canonical one of DESIGN.md whichever ball discovers them.
//!
//! Memory: at a million balls every record an event touches is a trip to main memory, so the
//! layout serves the access pattern. What a neighbour's prediction reads is one cache line per
//! ball (`Slot`); what only the ball itself reads is two more (`Own`, which also holds the
//! ball's place in the calendar); neighbours are gathered and prefetched before the pair tests,
//! and a ball's records are prefetched when its calendar bucket opens, a few events ahead.
//!
//! A periodic box (the `periodic` submodule) folds the same grid onto a torus.
//!
//! Why one event per ball is enough: for any pair whose next contact is at key `X`, the ball of
//! the pair that last recomputed its events did so with both current trajectories and kept an
//! event no later than `X`; if that event is popped stale, the ball recomputes and keeps one no
//! later than `X` again. So the earliest valid event is never missed.

use super::calendar::{Calendar, Entries, Place};
use super::grid::Grid;
use super::{
    BallState, Event, EventCounts, EventKind, Fixed, Frame, InstantCap, Observer, Outcome,
    RunError, Span, Table, World,
};
use crate::geometry::{PeriodicBox, Trajectory, Vec2};
use crate::growth::Growth;
use crate::physics::{self, Contact};
use crate::scenario::{BallSpec, Scenario};
use crate::thermostat::{Bath, Thermostat};
use crate::vtime::{pair, Key, Pair, DISPLAY, REVERSAL};
use pdes_kernel::prefetch::{prefetch, prefetch_all};
use pdes_kernel::Interrupt;
use smallvec::SmallVec;
use std::cmp::Ordering;

mod bath;
mod growing;
mod periodic;

/// The pair code that marks a ball leaving its cell: sorts after every physical event of its
/// instant (a crossing changes no trajectory, so its place within the instant does not matter).
const CELL_CROSSING: Pair = u64::MAX;

/// A ball's earliest predicted physical event (or the best candidate so far while predicting).
#[derive(Clone, Debug)]
struct Best {
    key: Key,
    partner: Partner,
}

impl Best {
    fn none() -> Best {
        Best {
            key: Key::at(f64::INFINITY, 0),
            partner: Partner::Nothing,
        }
    }
}

/// What a ball's next event is with.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Partner {
    /// Nothing: the ball is in a pocket, or nothing will ever happen to it.
    Nothing,
    /// Another ball, with that ball's counter when the event was predicted.
    Ball(u32, u32),
    /// A fixed object (global index).
    Fixed(u32),
    /// The ball comes back out of the pocket (global index) it dropped into, after a reversal.
    Return(u32),
}

/// The hot part of a ball's state, one cache line: what a neighbour's prediction reads.
#[derive(Clone, Copy, Debug)]
#[repr(align(64))]
struct Slot {
    /// Trajectory since the last velocity change (for a pocketed ball: its crossing of the line).
    traj: Trajectory,
    /// Radius.
    radius: f64,
    /// When the centre next leaves its grid cell (infinite: never).
    cross_t: f64,
    /// Goes up at every velocity change: events predicted with an older value are stale.
    counter: u32,
    /// The grid cell of the centre; `NOT_ON_TABLE` once pocketed.
    cell: u32,
}

const NOT_ON_TABLE: u32 = u32::MAX;

/// The balls in the 3 × 3 cells around a ball.
type Near = SmallVec<[u32; 48]>;

/// In a periodic box, the translation (whole sides) that brings each of [`Near`]'s balls to its
/// image next to the ball; empty in a walled box.
type Shifts = SmallVec<[Vec2; 48]>;

/// The rest of a ball's state, read only when the ball itself is handled (never by a neighbour's
/// prediction): two cache lines, so handling a ball costs few trips to memory.
#[derive(Clone, Debug)]
#[repr(align(64))]
struct Own {
    /// Its earliest physical event.
    phys: Best,
    /// Its queued key: the earlier of its physical event and its cell crossing.
    queued: Key,
    /// The key at which its trajectory was fixed.
    fixed_at: Key,
    /// Mass.
    mass: f64,
    /// The cell its centre enters at the slot's `cross_t`.
    cross_cell: u32,
    /// Where its queued key is in the calendar.
    place: Place,
}

/// What the calendar sees of the balls: their own records, and their slots and cells to
/// prefetch.
struct Queued<'a> {
    own: &'a mut [Own],
    slots: &'a [Slot],
    grid: &'a Grid,
}

impl Entries for Queued<'_> {
    #[inline]
    fn key(&self, i: u32) -> &Key {
        &self.own[i as usize].queued
    }
    #[inline]
    fn place(&self, i: u32) -> Place {
        self.own[i as usize].place
    }
    #[inline]
    fn set_place(&mut self, i: u32, place: Place) {
        self.own[i as usize].place = place;
    }
    /// The ball's record is read at the next event: start loading it, and its slot.
    #[inline]
    fn opened(&self, i: u32) {
        prefetch_all(&self.own[i as usize]);
        prefetch(&self.slots[i as usize]);
    }
    /// Its records have arrived: start loading the slots and cells its event will read.
    #[inline]
    fn approaching(&self, i: u32) {
        let own = &self.own[i as usize];
        if own.queued.path[..] == [CELL_CROSSING] {
            self.grid.prefetch_near(own.cross_cell);
        } else if let Partner::Ball(j, _) = own.phys.partner {
            prefetch(&self.slots[j as usize]);
            prefetch_all(&self.own[j as usize]);
            self.grid.prefetch_near(self.slots[i as usize].cell);
        }
    }
    /// The cells have arrived: start loading the slots of the balls in them.
    #[inline]
    fn imminent(&self, i: u32) {
        let own = &self.own[i as usize];
        let cell = self.slots[i as usize].cell;
        if cell == NOT_ON_TABLE {
            return;
        }
        if own.queued.path[..] == [CELL_CROSSING] {
            self.grid
                .for_each_entering(cell, own.cross_cell, |j| prefetch(&self.slots[j as usize]));
        } else if let Partner::Ball(j, _) = own.phys.partner {
            self.grid
                .for_each_near(cell, |k| prefetch(&self.slots[k as usize]));
            self.grid.prefetch_near(self.slots[j as usize].cell);
        }
    }
}

/// Counters an event-list run reports beside its events.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stats {
    /// Ball–ball and ball–fixed contact predictions computed.
    pub predictions: u64,
    /// Popped events whose partner had changed since they were predicted.
    pub stale: u64,
    /// Balls leaving a grid cell.
    pub cell_crossings: u64,
    /// Times the grid was laid out anew, finer where a cluster formed or coarser where one
    /// spread out.
    pub grid_layouts: u64,
    /// The deepest cascade of instantaneous collisions seen (1 = none).
    pub max_depth: usize,
}

/// The event-list engine over one scenario.
pub struct EventList {
    table: Table,
    slots: Vec<Slot>,
    own: Vec<Own>,
    pocket: Vec<Option<u32>>,
    queue: Calendar,
    grid: Grid,
    now: f64,
    /// The key of the reversal still to come, if any.
    reversal: Option<Key>,
    /// Start, reversal and frame times.
    span: Span,
    /// Frames drawn so far.
    frames: u64,
    stats: Stats,
    /// Stops an instant that never ends.
    instant: InstantCap,
    /// Ends runs early, after the instant of the event that saw it raised.
    interrupt: Option<Interrupt>,
    /// Cell crossings still to come before the grid's layout is looked at again.
    look_in: u64,
    /// The periodic box, if the table is one.
    period: Option<PeriodicBox>,
    /// In a periodic box, the whole sides along x and y to add to each ball's trajectory for its
    /// unwrapped position (how far it has travelled across the box); empty in a walled box.
    unwrap: Vec<(f64, f64)>,
    /// In a periodic box, the inverses of its sides (zero in a walled box).
    inverse_size: Vec2,
    /// How the disks grow, in a compression (the `growing` submodule); `None`: they do not.
    growth: Option<Growth>,
    /// The time the grid's cells stop holding the grown disks: runs end there at the latest.
    grown_until: f64,
    /// The thermostat's kicks, if it has one.
    bath: Option<Bath>,
}

/// Options of the event-list engine.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Minimum grid cell width in ball diameters (at least 1).
    pub cell_diameters: f64,
    /// Start time and reversal.
    pub span: Span,
    /// Andersen's thermostat; `None`: the dynamics conserves energy (on elastic tables).
    pub thermostat: Option<Thermostat>,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            cell_diameters: 1.0,
            span: Span::default(),
            thermostat: None,
        }
    }
}

impl EventList {
    /// Sets up the engine at time 0 for a validated scenario and predicts every ball's first event.
    pub fn new(s: &Scenario, opts: Options) -> EventList {
        EventList::build(s, opts, None)
    }

    /// [`EventList::new`], with the disks growing by `grow.0` until `grow.1` (the grid's cells
    /// are laid out for the disks grown by then).
    fn build(s: &Scenario, opts: Options, grow: Option<(Growth, f64)>) -> EventList {
        let table = Table::new(s);
        let period = table.period;
        let start = opts.span.start;
        let balls = BallState::initial(s, start);
        let n = balls.len();
        let rmax = balls.iter().map(|b| b.radius).fold(0.0, f64::max)
            * grow.map_or(1.0, |(g, until)| g.factor(until));
        let wrap = |p: Vec2| period.map_or(p, |b| b.wrap(p));
        let centres: Vec<_> = balls.iter().map(|b| wrap(b.position(start))).collect();
        let mut grid = Grid::new(
            &table,
            &centres,
            rmax,
            2.0 * rmax * opts.cell_diameters.max(1.0),
        );
        let slots = balls
            .iter()
            .enumerate()
            .map(|(i, b)| {
                // a ball in a pocket (taken up from a checkpoint) is in no cell
                let cell = match b.pocket {
                    Some(_) => NOT_ON_TABLE,
                    None => grid.insert_at(i as u32, centres[i]),
                };
                Slot {
                    traj: b.traj,
                    radius: b.radius,
                    cross_t: f64::INFINITY,
                    counter: 0,
                    cell,
                }
            })
            .collect();
        let mut e = EventList {
            table,
            slots,
            own: s
                .balls
                .iter()
                .zip(&balls)
                .map(|(spec, b)| Own {
                    phys: Best::none(),
                    queued: Key::at(f64::INFINITY, 0),
                    fixed_at: spec.fixed_at(start),
                    mass: b.mass,
                    cross_cell: 0,
                    place: Place::NOWHERE,
                })
                .collect(),
            pocket: balls.iter().map(|b| b.pocket).collect(),
            queue: Calendar::heap_only(start),
            grid,
            now: start,
            reversal: opts.span.reverse_at.map(|t| Key::at(t, REVERSAL)),
            span: opts.span,
            frames: 0,
            stats: Stats::default(),
            interrupt: None,
            instant: InstantCap::new(n),
            look_in: 0,
            period,
            inverse_size: period.map_or(Vec2::ZERO, |b| Vec2::new(1.0 / b.size.x, 1.0 / b.size.y)),
            unwrap: if period.is_some() {
                vec![(0.0, 0.0); n]
            } else {
                Vec::new()
            },
            growth: grow.map(|(g, _)| g),
            grown_until: grow.map_or(f64::INFINITY, |(_, until)| until),
            bath: opts.thermostat.map(|t| Bath::new(t, n as u32, start)),
        };
        e.look_in = e.look_interval();
        // the engine's own records hold the balls now
        drop((balls, centres));
        // First predictions go into a provisional calendar; the real one's bucket width comes
        // from the mean time to each ball's first event (events then come about mean / n apart).
        for i in 0..n as u32 {
            e.predict(i);
        }
        let finite: Vec<f64> = e
            .own
            .iter()
            .map(|o| o.queued.t)
            .filter(|t| t.is_finite())
            .collect();
        let mean = finite.iter().map(|t| t - start).sum::<f64>() / finite.len().max(1) as f64;
        let gap = mean / finite.len().max(1) as f64;
        drop(finite);
        // the provisional calendar goes before the real one comes
        e.queue = Calendar::heap_only(start);
        e.queue = Calendar::new(n, start, gap);
        for i in 0..n as u32 {
            e.own[i as usize].place = Place::NOWHERE;
            let (queue, mut balls) = e.calendar();
            queue.set(&mut balls, i);
        }
        e
    }

    /// The table.
    pub fn table(&self) -> &Table {
        &self.table
    }

    /// The grid's cells along x and y in its present layout.
    pub fn grid_dims(&self) -> (u32, u32) {
        self.grid.dims()
    }

    /// The engine's counters so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// The calendar, and what it sees of the balls.
    fn calendar(&mut self) -> (&mut Calendar, Queued<'_>) {
        let balls = Queued {
            own: &mut self.own,
            slots: &self.slots,
            grid: &self.grid,
        };
        (&mut self.queue, balls)
    }

    /// Bytes of memory held by the engine's own tables (not counting the scenario).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        let n = self.slots.len();
        n * (size_of::<Slot>() + size_of::<Own>() + size_of::<Option<u32>>())
            + self.queue.memory_bytes()
            + self.grid.memory_bytes()
    }

    /// Offers the contact of ball `i` (slot `b`) with ball `j` to `best`.
    #[inline]
    fn offer_ball(&self, i: u32, b: &Slot, j: u32, best: &mut Best) {
        let o = &self.slots[j as usize];
        let contact = if i < j {
            physics::ball_ball_contact(&b.traj, b.radius, &o.traj, o.radius)
        } else {
            physics::ball_ball_contact(&o.traj, o.radius, &b.traj, b.radius)
        };
        self.offer_contact(i, j, o.counter, contact, best);
    }

    /// Offers the contact of ball `i` (slot `b`) with the image of ball `j` that `shift` moves
    /// next to it, in a periodic box, to `best`.
    #[inline]
    fn offer_image(&self, i: u32, b: &Slot, j: u32, shift: Vec2, best: &mut Best) {
        let o = &self.slots[j as usize];
        let contact = if i < j {
            physics::ball_ball_contact_across(&b.traj, b.radius, &o.traj, o.radius, shift)
        } else {
            physics::ball_ball_contact_across(&o.traj, o.radius, &b.traj, b.radius, -shift)
        };
        self.offer_contact(i, j, o.counter, contact, best);
    }

    /// Offers `contact`, of ball `i` with ball `j` whose counter is `counter`, to `best`.
    #[inline(always)]
    fn offer_contact(&self, i: u32, j: u32, counter: u32, contact: Contact, best: &mut Best) {
        let p = pair(i, j);
        match contact {
            Contact::Never => {}
            Contact::At(t) => {
                if best.key.cmp_at(t, p) == Ordering::Greater {
                    best.key = Key::at(t, p);
                    best.partner = Partner::Ball(j, counter);
                }
            }
            Contact::Immediate => {
                let (fi, fj) = (
                    &self.own[i as usize].fixed_at,
                    &self.own[j as usize].fixed_at,
                );
                let key = fi.max(fj).child(p);
                if key < best.key {
                    best.key = key;
                    best.partner = Partner::Ball(j, counter);
                }
            }
        }
    }

    /// Offers the contacts of ball `i` (slot `b`) with each of `near` to `best`, with the images
    /// `shifts` moves them to in a periodic box.
    #[inline]
    fn offer_balls(&self, i: u32, b: &Slot, near: &[u32], shifts: &[Vec2], best: &mut Best) {
        if self.period.is_none() {
            for &j in near {
                self.offer_ball(i, b, j, best);
            }
        } else if let Some(growth) = self.growth {
            for (&j, &shift) in near.iter().zip(shifts) {
                self.offer_grown(i, b, j, shift, growth, best);
            }
        } else {
            for (&j, &shift) in near.iter().zip(shifts) {
                self.offer_image(i, b, j, shift, best);
            }
        }
    }

    /// Offers the contacts of ball `i` with the fixed objects near cell `cell` to `best`.
    fn offer_fixed(&self, i: u32, b: &Slot, cell: u32, best: &mut Best) -> u64 {
        let near = self.grid.fixed_near(cell);
        for &f in near {
            let p = pair(i, f);
            match self.table.contact(f, &b.traj, b.radius) {
                Contact::Never => {}
                Contact::At(t) => {
                    if best.key.cmp_at(t, p) == Ordering::Greater {
                        best.key = Key::at(t, p);
                        best.partner = Partner::Fixed(f);
                    }
                }
                Contact::Immediate => {
                    let key = self.own[i as usize].fixed_at.child(p);
                    if key < best.key {
                        best.key = key;
                        best.partner = Partner::Fixed(f);
                    }
                }
            }
        }
        near.len() as u64
    }

    /// Recomputes ball `i`'s earliest physical event and its next cell crossing from scratch.
    fn predict(&mut self, i: u32) {
        let (mut near, mut shifts) = (Near::new(), Shifts::new());
        self.gather(i, &mut near, &mut shifts);
        self.predict_among(i, &near, &shifts);
    }

    /// The balls near ball `i` (none once pocketed), with a request to load their slots: gathered
    /// ahead of the pair tests so that the trips to memory overlap instead of following one
    /// another.
    fn gather(&self, i: u32, near: &mut Near, shifts: &mut Shifts) {
        if self.period.is_some() {
            return self.gather_images(i, near, shifts);
        }
        let cell = self.slots[i as usize].cell;
        if cell != NOT_ON_TABLE {
            self.grid.for_each_near(cell, |j| {
                if j != i {
                    prefetch(&self.slots[j as usize]);
                    near.push(j);
                }
            });
        }
    }

    /// [`EventList::predict`] with ball `i`'s neighbours already gathered.
    fn predict_among(&mut self, i: u32, near: &[u32], shifts: &[Vec2]) {
        let b = self.slots[i as usize];
        let mut best = Best::none();
        if b.cell != NOT_ON_TABLE {
            self.offer_balls(i, &b, near, shifts, &mut best);
            let tests = near.len() as u64 + self.offer_fixed(i, &b, b.cell, &mut best);
            self.stats.predictions += tests;
        }
        self.own[i as usize].phys = best;
        self.set_exit(i);
        self.requeue(i);
    }

    /// Ball `i`'s centre moves into cell `to`: only the balls of the cells that come into its
    /// 3 × 3 block are new candidates; its physical prediction otherwise stands.
    fn cross(&mut self, i: u32, to: u32) {
        let from = self.slots[i as usize].cell;
        let (mut near, mut shifts) = (Near::new(), Shifts::new());
        if self.period.is_some() {
            self.entering_images(i, (from, to), &mut near, &mut shifts);
        } else {
            self.grid.for_each_entering(from, to, |j| {
                prefetch(&self.slots[j as usize]);
                near.push(j);
            });
        }
        // copied before the cell is stored: a read of the whole slot right after a store into
        // it would wait for that store (and every store before it) to reach the cache
        let mut b = self.slots[i as usize];
        b.cell = to;
        self.grid.remove_from(i, from);
        self.grid.insert(i, to);
        self.slots[i as usize].cell = to;
        let mut best = std::mem::replace(&mut self.own[i as usize].phys, Best::none());
        self.offer_balls(i, &b, &near, &shifts, &mut best);
        let tests = near.len() as u64 + self.offer_fixed(i, &b, to, &mut best);
        self.stats.predictions += tests;
        self.own[i as usize].phys = best;
        self.set_exit(i);
        self.requeue(i);
    }

    /// Lays the grid out anew if the balls' spread asks for finer cells (a cluster formed) or
    /// coarser ones (it spread out), and then predicts every ball on the table anew in it. Its
    /// cost, linear in the number of balls, is paid at most once per crowding or once per
    /// [`EventList::look_interval`] crossings.
    #[cold]
    fn adapt_grid(&mut self) {
        let on_table: Vec<u32> = (0..self.slots.len() as u32)
            .filter(|&i| self.slots[i as usize].cell != NOT_ON_TABLE)
            .collect();
        let wrap = |p: Vec2| self.period.map_or(p, |b| b.wrap(p));
        let centres: Vec<Vec2> = on_table
            .iter()
            .map(|&i| wrap(self.slots[i as usize].traj.at(self.now)))
            .collect();
        if let Some(grid) = self.grid.relaid(&self.table, &centres) {
            self.grid = grid;
            self.stats.grid_layouts += 1;
            for (&i, &p) in on_table.iter().zip(&centres) {
                self.slots[i as usize].cell = self.grid.insert_at(i, p);
            }
            for &i in &on_table {
                self.predict(i);
            }
        }
        self.look_in = self.look_interval();
    }

    /// Cell crossings between two looks at whether a coarser layout suits the balls: never if
    /// the grid is at its coarsest, else as many as there are balls (at least 1024), so that the
    /// looks cost a bounded share of the crossings.
    fn look_interval(&self) -> u64 {
        if self.grid.is_coarsest() {
            u64::MAX
        } else {
            self.slots.len().max(1024) as u64
        }
    }

    /// Predicts when ball `i`'s centre leaves its cell, and which cell it enters.
    fn set_exit(&mut self, i: u32) {
        let position = match self.period {
            Some(period) if self.slots[i as usize].cell != NOT_ON_TABLE => {
                let out = self.sides_out(i, self.now);
                self.slots[i as usize].traj.position - period.shift(out)
            }
            _ => self.slots[i as usize].traj.position,
        };
        let b = &mut self.slots[i as usize];
        let exit = if b.cell == NOT_ON_TABLE {
            None
        } else {
            self.grid.exit(b.cell, position, b.traj.velocity, b.traj.t0)
        };
        match exit {
            Some((t, c)) => {
                b.cross_t = t.max(self.now);
                self.own[i as usize].cross_cell = c;
            }
            None => b.cross_t = f64::INFINITY,
        }
    }

    /// Queues ball `i` at the earlier of its physical event and its cell crossing.
    fn requeue(&mut self, i: u32) {
        let t = self.slots[i as usize].cross_t;
        let phys = &self.own[i as usize].phys.key;
        self.own[i as usize].queued = if phys.cmp_at(t, CELL_CROSSING) == Ordering::Greater {
            Key::at(t, CELL_CROSSING)
        } else {
            phys.clone()
        };
        let (queue, mut balls) = self.calendar();
        queue.set(&mut balls, i);
    }

    fn set_velocity(&mut self, i: u32, key: &Key, velocity: Vec2) {
        let mut position = self.slots[i as usize].traj.at(key.t);
        if self.period.is_some() {
            position = self.rebased(i, position, key.t);
        }
        let b = &mut self.slots[i as usize];
        b.traj = Trajectory {
            position,
            velocity,
            t0: key.t,
        };
        b.counter = b.counter.wrapping_add(1);
        self.own[i as usize].fixed_at = key.clone();
    }

    /// Ends later runs early once `interrupt` is raised: at the time of the event that saw it,
    /// every other event of that instant run too.
    pub fn stop_on(&mut self, interrupt: Interrupt) {
        self.interrupt = Some(interrupt);
    }

    /// Runs until the next event would come after `until`, reporting each event to `obs`, and
    /// returns the state at `until` (or at the earlier time an interrupt ended the run).
    pub fn run(&mut self, until: f64, obs: &mut dyn Observer) -> Result<Outcome, RunError> {
        self.run_for(until, u64::MAX, obs)
    }

    /// Like [`EventList::run`], but stops after `max_events` physical events (the state is then
    /// reported at the time of the last one).
    pub fn run_for(
        &mut self,
        until: f64,
        max_events: u64,
        obs: &mut dyn Observer,
    ) -> Result<Outcome, RunError> {
        let mut counts = EventCounts::default();
        let mut until = until.min(self.grown_until);
        loop {
            if counts.total() >= max_events {
                until = self.now;
                break;
            }
            let (queue, mut balls) = self.calendar();
            let first = queue.first(&mut balls);
            if self.interlude(first, until, obs)? {
                continue;
            }
            let Some(i) = first else {
                break;
            };
            let key = self.own[i as usize].queued.clone();
            if key.t > until {
                break;
            }
            self.now = key.t;
            if key.path[..] == [CELL_CROSSING] {
                self.stats.cell_crossings += 1;
                self.cross(i, self.own[i as usize].cross_cell);
                self.look_in -= 1;
                if self.look_in == 0 || self.grid.is_crowded() {
                    self.adapt_grid();
                }
                continue;
            }
            let (kind, a, b) = match self.own[i as usize].phys.partner {
                Partner::Nothing => break,
                Partner::Return(f) => (self.come_back(i, &key), i, f),
                Partner::Ball(j, seen) if self.slots[j as usize].counter != seen => {
                    self.stats.stale += 1;
                    self.predict(i);
                    continue;
                }
                Partner::Ball(j, _) => self.collide(i, j, &key),
                Partner::Fixed(f) => (self.hit(i, f, &key), i, f),
            };
            self.emit(&key, kind, a, b, &mut counts, obs)?;
            // the rest of this instant happens too: the state at `now` is then complete
            if self.interrupt.as_ref().is_some_and(Interrupt::raised) {
                until = until.min(self.now);
            }
        }
        self.now = self.now.max(until);
        Ok(self.outcome(until, counts))
    }

    /// What comes before the first queued event (`first`) if anything does by `until`: the
    /// reversal, or a frame, which it then carries out. Whether it did.
    #[inline]
    fn interlude(
        &mut self,
        first: Option<u32>,
        until: f64,
        obs: &mut dyn Observer,
    ) -> Result<bool, RunError> {
        if self.bath_first(first, until) {
            self.kick(obs)?;
            return Ok(true);
        }
        if let Some(r) = &self.reversal {
            let before = first.is_none_or(|i| *r < self.own[i as usize].queued);
            if before && r.t <= until {
                let r = self.reversal.take().expect("checked above");
                self.reverse(&r);
                return Ok(true);
            }
        }
        if let Some(f) = self.span.frame(self.frames) {
            let frame = Key::at(f, DISPLAY);
            let before = first.is_none_or(|i| frame < self.own[i as usize].queued)
                && self.reversal.as_ref().is_none_or(|r| frame < *r);
            if before && f <= until {
                self.frames += 1;
                let frame = Frame {
                    t: f,
                    balls: self.state_at(f),
                    images: self.images_at(f),
                };
                obs.on_frame(&frame, &self.table)?;
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Pocketed ball `i` comes back out at `key` (after a reversal). The event's kind.
    #[inline]
    fn come_back(&mut self, i: u32, key: &Key) -> EventKind {
        let b = &mut self.slots[i as usize];
        let cell = self.grid.insert_at(i, b.traj.position);
        b.cell = cell;
        b.counter = b.counter.wrapping_add(1);
        self.pocket[i as usize] = None;
        self.own[i as usize].fixed_at = key.clone();
        self.predict(i);
        EventKind::BallPocket
    }

    /// Balls `i` and `j` collide at `key`: both take their new velocities and predict their next
    /// events among their neighbours. The event, its balls in order.
    #[inline]
    fn collide(&mut self, i: u32, j: u32, key: &Key) -> (EventKind, u32, u32) {
        let (a, b) = (i.min(j), i.max(j));
        let (sa, sb) = (self.slots[a as usize], self.slots[b as usize]);
        prefetch(&self.own[j as usize]);
        self.grid.prefetch_near(sa.cell);
        self.grid.prefetch_near(sb.cell);
        let (pa, mut pb) = (sa.traj.at(key.t), sb.traj.at(key.t));
        if let Some(period) = &self.period {
            // the image of b that touches a
            pb = pb + period.shift(period.images(pa - pb));
        }
        let (ma, mb) = (self.own[a as usize].mass, self.own[b as usize].mass);
        let (va, vb) = match self.growth {
            None => {
                physics::ball_ball_velocities(pa, sa.traj.velocity, ma, pb, sb.traj.velocity, mb)
            }
            Some(g) => g.velocities(
                (pa, sa.traj.velocity, ma, sa.radius),
                (pb, sb.traj.velocity, mb, sb.radius),
            ),
        };
        self.set_velocity(a, key, va);
        self.set_velocity(b, key, vb);
        let (mut near_a, mut shifts_a) = (Near::new(), Shifts::new());
        let (mut near_b, mut shifts_b) = (Near::new(), Shifts::new());
        self.gather(a, &mut near_a, &mut shifts_a);
        self.gather(b, &mut near_b, &mut shifts_b);
        self.predict_among(a, &near_a, &shifts_a);
        self.predict_among(b, &near_b, &shifts_b);
        (EventKind::BallBall, a, b)
    }

    /// Ball `i` hits fixed object `f` at `key`: it bounces, or drops into a pocket and leaves the
    /// grid. The event's kind.
    #[inline]
    fn hit(&mut self, i: u32, f: u32, key: &Key) -> EventKind {
        let b = self.slots[i as usize];
        let p = b.traj.at(key.t);
        match self.table.bounce(f, p, b.traj.velocity) {
            Some(v) => self.set_velocity(i, key, v),
            None => {
                self.set_velocity(i, key, b.traj.velocity);
                let Fixed::Pocket(k) = self.table.fixed(f) else {
                    unreachable!("only pockets swallow balls")
                };
                self.pocket[i as usize] = Some(k);
                self.grid.remove(i);
                self.slots[i as usize].cell = NOT_ON_TABLE;
            }
        }
        self.predict(i);
        self.table.event_kind(f)
    }

    /// The state at `until`, with the events counted and the engine's statistics.
    fn outcome(&self, until: f64, events: EventCounts) -> Outcome {
        Outcome {
            t: until,
            balls: self.state_at(until),
            events,
            engine_stats: vec![
                ("predictions", self.stats.predictions as f64),
                ("stale_events", self.stats.stale as f64),
                ("cell_crossings", self.stats.cell_crossings as f64),
                ("grid_layouts", self.stats.grid_layouts as f64),
                ("max_cascade_depth", self.stats.max_depth as f64),
            ],
            messages: Vec::new(),
        }
    }

    /// Turns every ball around at the reversal key `r` (thesis 4.6): balls on the table reverse
    /// their velocity where they are; a ball in a pocket is set to come back out at the mirror
    /// image of the time it dropped in, with its entry velocity reversed.
    fn reverse(&mut self, r: &Key) {
        self.now = r.t;
        let n = self.slots.len() as u32;
        for i in 0..n {
            match self.pocket[i as usize] {
                None => {
                    let velocity = -self.slots[i as usize].traj.velocity;
                    self.set_velocity(i, r, velocity);
                }
                Some(k) => {
                    let b = &mut self.slots[i as usize];
                    let back = 2.0 * r.t - b.traj.t0;
                    b.traj = Trajectory {
                        position: b.traj.position,
                        velocity: -b.traj.velocity,
                        t0: back,
                    };
                    let f = self.table.fixed_id(Fixed::Pocket(k));
                    self.own[i as usize].phys = Best {
                        key: crate::model::pool::return_key(r, back, pair(i, f)),
                        partner: Partner::Return(f),
                    };
                    self.requeue(i);
                }
            }
        }
        for i in 0..n {
            if self.pocket[i as usize].is_none() {
                self.predict(i);
            }
        }
    }

    fn emit(
        &mut self,
        key: &Key,
        kind: EventKind,
        a: u32,
        b: u32,
        counts: &mut EventCounts,
        obs: &mut dyn Observer,
    ) -> Result<(), RunError> {
        counts.add(kind);
        self.stats.max_depth = self.stats.max_depth.max(key.depth());
        let ev = Event {
            t: key.t,
            kind,
            a,
            b,
        };
        self.instant.count(&ev)?;
        obs.on_event(&ev, self)
    }

    /// Every ball as a run that takes this one up must start it: its trajectory as last fixed,
    /// with the key that fixed it, and its pocket.
    pub fn balls_to_take_up(&self) -> Vec<BallSpec> {
        (0..self.slots.len())
            .map(|i| {
                let (slot, own) = (&self.slots[i], &self.own[i]);
                debug_assert_eq!(slot.traj.t0, own.fixed_at.t, "fixed when it turned");
                BallSpec::taken_up(
                    &slot.traj,
                    slot.radius,
                    own.mass,
                    &own.fixed_at,
                    self.pocket[i],
                )
            })
            .collect()
    }

    /// Every ball's state fixed at time `t` (not before the last event).
    pub fn state_at(&self, t: f64) -> Vec<BallState> {
        (0..self.slots.len() as u32)
            .map(|i| {
                let mut b = self.ball(i);
                b.radius = self.radius_at(i, t);
                if b.pocket.is_none() {
                    b.traj = Trajectory {
                        position: self.period.map_or(b.traj.at(t), |p| p.wrap(b.traj.at(t))),
                        velocity: b.traj.velocity,
                        t0: t,
                    };
                }
                b
            })
            .collect()
    }
}

impl World for EventList {
    fn table(&self) -> &Table {
        &self.table
    }

    fn n_balls(&self) -> usize {
        self.slots.len()
    }

    fn ball(&self, i: u32) -> BallState {
        let s = &self.slots[i as usize];
        BallState {
            traj: s.traj,
            radius: self.radius_at(i, self.now),
            mass: self.own[i as usize].mass,
            pocket: self.pocket[i as usize],
        }
    }

    fn for_each_neighbor(&self, i: u32, f: &mut dyn FnMut(u32)) {
        let c = self.slots[i as usize].cell;
        if c != NOT_ON_TABLE {
            self.grid.for_each_near(c, |j| {
                if j != i {
                    f(j)
                }
            });
        }
    }
}
