//! The event-list engine (thesis fig. 2): the reference every other engine must reproduce.
//!
//! Each ball keeps only its own earliest predicted event (another ball, a fixed object, or leaving
//! its grid cell), and a tournament tree over the balls yields the earliest of all in O(log N).
//! When ball `i` changes velocity its counter goes up; an event whose partner's counter moved on is
//! stale, and popping it merely recomputes its owner's next event. An event therefore costs a
//! bounded number of pair tests (the 3 × 3 cells around each ball involved) and O(log N) tree
//! work, never O(N).
//!
//! Order: events run by their virtual-time [`Key`]. A prediction is a pure function of the two
//! trajectories and the keys at which they were fixed, so the order of simultaneous and
//! instantaneous events is exactly the canonical one of DESIGN.md whichever ball discovers them.
//!
//! Why one event per ball is enough: for any pair whose next contact is at key `X`, the ball of
//! the pair that last recomputed its events did so with both current trajectories and kept an
//! event no later than `X`; if that event is popped stale, the ball recomputes and keeps one no
//! later than `X` again. So the earliest valid event is never missed.

use super::grid::Grid;
use super::{BallState, Event, EventCounts, EventKind, Observer, Outcome, RunError, Table, World};
use crate::geometry::Trajectory;
use crate::physics::{self, Contact};
use crate::scenario::Scenario;
use crate::vtime::{pair, Key, Pair};
use std::cmp::Ordering;

/// The pair code that marks a ball leaving its cell: sorts after every physical event of its
/// instant (a crossing changes no trajectory, so its place within the instant does not matter).
const CELL_CROSSING: Pair = u64::MAX;

/// The most events one instant may hold before the run stops with [`RunError::Cascade`].
pub const MAX_EVENTS_PER_INSTANT: u64 = 10_000_000;

/// What a ball's next event is with.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Partner {
    /// Nothing: the ball is in a pocket, or nothing will ever happen to it.
    Nothing,
    /// Another ball, with that ball's counter when the event was predicted.
    Ball(u32, u32),
    /// A fixed object (global index).
    Fixed(u32),
    /// The ball's centre enters this grid cell.
    Cell(u32),
}

#[derive(Clone, Debug)]
struct Next {
    key: Key,
    partner: Partner,
}

/// A complete binary tree over the balls' next-event times: each inner node holds the ball whose
/// event is earliest below it.
#[derive(Clone, Debug)]
struct Tournament {
    leaves: usize,
    node: Vec<u32>,
}

impl Tournament {
    fn new(n: usize) -> Tournament {
        let leaves = n.next_power_of_two().max(1);
        Tournament {
            leaves,
            node: vec![u32::MAX; 2 * leaves],
        }
    }

    #[inline]
    fn earlier(next: &[Next], a: u32, b: u32) -> u32 {
        if b == u32::MAX {
            return a;
        }
        if a == u32::MAX {
            return b;
        }
        let (ka, kb) = (&next[a as usize].key, &next[b as usize].key);
        match ka.t.total_cmp(&kb.t) {
            Ordering::Less => a,
            Ordering::Greater => b,
            Ordering::Equal => {
                if ka.path <= kb.path {
                    a
                } else {
                    b
                }
            }
        }
    }

    #[inline]
    fn update(&mut self, next: &[Next], i: u32) {
        let mut k = self.leaves + i as usize;
        self.node[k] = i;
        while k > 1 {
            k /= 2;
            self.node[k] = Self::earlier(next, self.node[2 * k], self.node[2 * k + 1]);
        }
    }

    fn build(&mut self, next: &[Next]) {
        for (i, _) in next.iter().enumerate() {
            self.node[self.leaves + i] = i as u32;
        }
        for k in (1..self.leaves).rev() {
            self.node[k] = Self::earlier(next, self.node[2 * k], self.node[2 * k + 1]);
        }
    }

    #[inline]
    fn top(&self) -> u32 {
        self.node[1]
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
    /// The deepest cascade of instantaneous collisions seen (1 = none).
    pub max_depth: usize,
}

/// The event-list engine over one scenario.
pub struct EventList {
    table: Table,
    balls: Vec<BallState>,
    fixed_at: Vec<Key>,
    counter: Vec<u32>,
    next: Vec<Next>,
    tree: Tournament,
    grid: Grid,
    now: f64,
    stats: Stats,
}

/// Options of the event-list engine.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// Minimum grid cell width in ball diameters (at least 1).
    pub cell_diameters: f64,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            cell_diameters: 1.0,
        }
    }
}

impl EventList {
    /// Sets up the engine at time 0 for a validated scenario and predicts every ball's first event.
    pub fn new(s: &Scenario, opts: Options) -> EventList {
        let table = Table::new(s);
        let balls = BallState::initial(s);
        let n = balls.len();
        let rmax = balls.iter().map(|b| b.radius).fold(0.0, f64::max);
        let mut grid = Grid::new(&table, n, rmax, 2.0 * rmax * opts.cell_diameters.max(1.0));
        for (i, b) in balls.iter().enumerate() {
            grid.insert(i as u32, grid.cell_at(b.traj.position));
        }
        let idle = Next {
            key: Key::at(f64::INFINITY, 0),
            partner: Partner::Nothing,
        };
        let mut e = EventList {
            table,
            balls,
            fixed_at: vec![Key::start(0.0); n],
            counter: vec![0; n],
            next: vec![idle; n],
            tree: Tournament::new(n),
            grid,
            now: 0.0,
            stats: Stats::default(),
        };
        for i in 0..n as u32 {
            e.next[i as usize] = e.predict(i);
        }
        e.tree.build(&e.next);
        e
    }

    /// The table.
    pub fn table(&self) -> &Table {
        &self.table
    }

    /// The engine's counters so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Bytes of memory held by the engine's own tables (not counting the scenario).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        let n = self.balls.len();
        n * (size_of::<BallState>() + size_of::<Key>() + 4 + size_of::<Next>())
            + self.tree.node.len() * 4
            + self.grid.memory_bytes()
    }

    /// The earliest event of ball `i` from its current trajectory.
    fn predict(&mut self, i: u32) -> Next {
        let b = self.balls[i as usize];
        if b.pocket.is_some() {
            return Next {
                key: Key::at(f64::INFINITY, 0),
                partner: Partner::Nothing,
            };
        }
        let Some(cell) = self.grid.cell_of(i) else {
            unreachable!("a ball on the table is always in a cell")
        };
        let mut best = match self
            .grid
            .exit(cell, b.traj.position, b.traj.velocity, b.traj.t0)
        {
            Some((t, c)) => Next {
                key: Key::at(t.max(self.now), CELL_CROSSING),
                partner: Partner::Cell(c),
            },
            None => Next {
                key: Key::at(f64::INFINITY, 0),
                partner: Partner::Nothing,
            },
        };
        let mut tests = 0u64;
        let (balls, fixed_at, counter) = (&self.balls, &self.fixed_at, &self.counter);
        self.grid.for_each_near(cell, |j| {
            if j == i {
                return;
            }
            tests += 1;
            let o = &balls[j as usize];
            let contact = if i < j {
                physics::ball_ball_contact(&b.traj, b.radius, &o.traj, o.radius)
            } else {
                physics::ball_ball_contact(&o.traj, o.radius, &b.traj, b.radius)
            };
            let p = pair(i, j);
            match contact {
                Contact::Never => {}
                Contact::At(t) => {
                    if best.key.cmp_at(t, p) == Ordering::Greater {
                        best.key = Key::at(t, p);
                        best.partner = Partner::Ball(j, counter[j as usize]);
                    }
                }
                Contact::Immediate => {
                    let parent = fixed_at[i as usize].clone().max(fixed_at[j as usize].clone());
                    let key = parent.child(p);
                    if key < best.key {
                        best.key = key;
                        best.partner = Partner::Ball(j, counter[j as usize]);
                    }
                }
            }
        });
        for &f in self.grid.fixed_near(cell) {
            tests += 1;
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
                    let key = self.fixed_at[i as usize].child(p);
                    if key < best.key {
                        best.key = key;
                        best.partner = Partner::Fixed(f);
                    }
                }
            }
        }
        self.stats.predictions += tests;
        best
    }

    fn repredict(&mut self, i: u32) {
        self.next[i as usize] = self.predict(i);
        self.tree.update(&self.next, i);
    }

    fn set_velocity(&mut self, i: u32, key: &Key, velocity: crate::geometry::Vec2) {
        let b = &mut self.balls[i as usize];
        b.traj = Trajectory {
            position: b.traj.at(key.t),
            velocity,
            t0: key.t,
        };
        self.fixed_at[i as usize] = key.clone();
        self.counter[i as usize] = self.counter[i as usize].wrapping_add(1);
    }

    /// Runs until the next event would come after `until`, reporting each event to `obs`, and
    /// returns the state at `until`.
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
        let mut instant = (f64::NAN, 0u64);
        let mut until = until;
        loop {
            if counts.total() >= max_events {
                until = self.now;
                break;
            }
            let i = self.tree.top();
            if i == u32::MAX {
                break;
            }
            let key = self.next[i as usize].key.clone();
            if !(key.t <= until) {
                break;
            }
            self.now = key.t;
            match self.next[i as usize].partner {
                Partner::Nothing => break,
                Partner::Cell(c) => {
                    self.stats.cell_crossings += 1;
                    self.grid.remove(i);
                    self.grid.insert(i, c);
                    self.repredict(i);
                    continue;
                }
                Partner::Ball(j, seen) if self.counter[j as usize] != seen => {
                    self.stats.stale += 1;
                    self.repredict(i);
                    continue;
                }
                Partner::Ball(j, _) => {
                    let (a, b) = (i.min(j), i.max(j));
                    let (ba, bb) = (self.balls[a as usize], self.balls[b as usize]);
                    let (va, vb) = physics::ball_ball_velocities(
                        ba.traj.at(key.t),
                        ba.traj.velocity,
                        ba.mass,
                        bb.traj.at(key.t),
                        bb.traj.velocity,
                        bb.mass,
                    );
                    self.set_velocity(a, &key, va);
                    self.set_velocity(b, &key, vb);
                    self.repredict(a);
                    self.repredict(b);
                    self.emit(&key, EventKind::BallBall, a, b, &mut counts, obs)?;
                }
                Partner::Fixed(f) => {
                    let b = self.balls[i as usize];
                    let p = b.traj.at(key.t);
                    match self.table.bounce(f, p, b.traj.velocity) {
                        Some(v) => self.set_velocity(i, &key, v),
                        None => {
                            self.set_velocity(i, &key, b.traj.velocity);
                            let crate::engine::Fixed::Pocket(k) = self.table.fixed(f) else {
                                unreachable!("only pockets swallow balls")
                            };
                            self.balls[i as usize].pocket = Some(k);
                            self.grid.remove(i);
                        }
                    }
                    self.repredict(i);
                    let kind = self.table.event_kind(f);
                    self.emit(&key, kind, i, f, &mut counts, obs)?;
                }
            }
            if instant.0 == key.t {
                instant.1 += 1;
                if instant.1 > MAX_EVENTS_PER_INSTANT {
                    return Err(RunError::Cascade {
                        t: key.t,
                        events: MAX_EVENTS_PER_INSTANT,
                    });
                }
            } else {
                instant = (key.t, 1);
            }
        }
        self.now = self.now.max(until);
        Ok(Outcome {
            t: until,
            balls: self.state_at(until),
            events: counts,
            engine_stats: vec![
                ("predictions", self.stats.predictions as f64),
                ("stale_events", self.stats.stale as f64),
                ("cell_crossings", self.stats.cell_crossings as f64),
                ("max_cascade_depth", self.stats.max_depth as f64),
            ],
        })
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
        obs.on_event(&Event { t: key.t, kind, a, b }, self)
    }

    /// Every ball's state fixed at time `t` (not before the last event).
    pub fn state_at(&self, t: f64) -> Vec<BallState> {
        self.balls
            .iter()
            .map(|b| {
                let mut b = *b;
                if b.pocket.is_none() {
                    b.traj = Trajectory {
                        position: b.traj.at(t),
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

    fn balls(&self) -> &[BallState] {
        &self.balls
    }

    fn for_each_neighbor(&self, i: u32, f: &mut dyn FnMut(u32)) {
        if let Some(c) = self.grid.cell_of(i) {
            self.grid.for_each_near(c, |j| {
                if j != i {
                    f(j)
                }
            });
        }
    }
}
