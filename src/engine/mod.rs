//! Engines: the event-list engine (thesis fig. 2), the reference every other engine is checked
//! against, and the time-step engine (fig. 1), the baseline the thesis argues against.
//!
//! Every engine reads a validated [`Scenario`], turns it into a [`Table`] (the fixed objects and
//! the numbering of all objects) and a vector of [`BallState`]s, and reports each physical event it
//! executes, in execution order, to an [`Observer`]. Engines write no files: sinks do.

pub mod calendar;
pub mod event_list;
pub mod grid;
pub mod objects;
pub mod partition;
pub mod regions;
pub mod time_step;

use crate::checkpoint::Checkpoint;
use crate::geometry::{PeriodicBox, Trajectory, Vec2};
use crate::physics::{self, Contact};
use crate::scenario::Scenario;
use pdes_kernel::Interrupt;

/// What kind of physical event happened; the names are the trace's `kind` strings.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
pub enum EventKind {
    /// Two balls collided.
    BallBall,
    /// A ball bounced off a cushion.
    BallCushion,
    /// A ball bounced off a pocket's corner.
    BallCorner,
    /// A ball's centre crossed a pocket line: the ball dropped in.
    BallPocket,
}

impl EventKind {
    /// Every kind, in the order summaries list them.
    pub const ALL: [EventKind; 4] = [
        EventKind::BallBall,
        EventKind::BallCushion,
        EventKind::BallCorner,
        EventKind::BallPocket,
    ];

    /// The trace name: `ball-ball`, `ball-cushion`, `ball-corner` or `ball-pocket`.
    pub fn name(self) -> &'static str {
        match self {
            EventKind::BallBall => "ball-ball",
            EventKind::BallCushion => "ball-cushion",
            EventKind::BallCorner => "ball-corner",
            EventKind::BallPocket => "ball-pocket",
        }
    }
}

/// One executed physical event. Objects are global indices (see [`Table`]); `a < b` always, and
/// `a` is a ball.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Event {
    /// Simulation time of the event.
    pub t: f64,
    /// What happened.
    pub kind: EventKind,
    /// The lower object index: always a ball.
    pub a: u32,
    /// The higher object index: a ball, cushion, pocket or corner.
    pub b: u32,
}

/// A fixed object of the table, by its index within its own kind (0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Fixed {
    /// Cushion `k` (`Cushion-{k+1}`).
    Cushion(u32),
    /// Pocket `k` (`Pocket-{k+1}`).
    Pocket(u32),
    /// Corner `k` (`Corner-{k+1}`), an end of pocket `k / 2`.
    Corner(u32),
}

/// The fixed objects of a table and the global numbering of every object: balls first
/// (`0..n_balls`), then cushions, pockets and corners, each in scenario order.
#[derive(Clone, Debug)]
pub struct Table {
    /// Number of balls.
    pub n_balls: u32,
    /// Cushion ends and elasticities.
    pub cushions: Vec<(Vec2, Vec2, f64)>,
    /// Pocket line ends.
    pub pockets: Vec<(Vec2, Vec2)>,
    /// Corner positions and elasticities.
    pub corners: Vec<(Vec2, f64)>,
    /// Lower-left corner of the table's bounding box.
    pub lo: Vec2,
    /// Upper-right corner of the table's bounding box.
    pub hi: Vec2,
    /// The periodic box, where the boundary is periodic (`lo` and `hi` are then its corners).
    pub period: Option<PeriodicBox>,
}

impl Table {
    /// Builds the table of a validated scenario.
    pub fn new(s: &Scenario) -> Table {
        let (lo, hi) = s.bounds();
        Table {
            n_balls: s.balls.len() as u32,
            cushions: s
                .cushions
                .iter()
                .map(|c| (c.from, c.to, c.elasticity))
                .collect(),
            pockets: s.pockets.iter().map(|p| (p.from, p.to)).collect(),
            corners: (0..s.corner_count())
                .map(|k| (s.corner_position(k), s.pockets[k / 2].corner_elasticity))
                .collect(),
            lo,
            hi,
            period: s.periodic,
        }
    }

    /// The separation from `p` to `q`: `q - p`, or its nearest image in a periodic box.
    #[inline]
    pub fn separation(&self, p: Vec2, q: Vec2) -> Vec2 {
        match &self.period {
            Some(b) => b.nearest(q - p),
            None => q - p,
        }
    }

    /// Number of fixed objects.
    pub fn n_fixed(&self) -> u32 {
        (self.cushions.len() + self.pockets.len() + self.corners.len()) as u32
    }

    /// The fixed object with global index `id` (which must not be a ball).
    #[inline]
    pub fn fixed(&self, id: u32) -> Fixed {
        let k = id - self.n_balls;
        let nc = self.cushions.len() as u32;
        let np = self.pockets.len() as u32;
        if k < nc {
            Fixed::Cushion(k)
        } else if k < nc + np {
            Fixed::Pocket(k - nc)
        } else {
            Fixed::Corner(k - nc - np)
        }
    }

    /// The global index of a fixed object.
    pub fn fixed_id(&self, f: Fixed) -> u32 {
        let nc = self.cushions.len() as u32;
        let np = self.pockets.len() as u32;
        self.n_balls
            + match f {
                Fixed::Cushion(k) => k,
                Fixed::Pocket(k) => nc + k,
                Fixed::Corner(k) => nc + np + k,
            }
    }

    /// The name of object `id`: `Ball-3`, `Cushion-1`, `Pocket-2`, `Corner-4`.
    pub fn name(&self, id: u32) -> String {
        if id < self.n_balls {
            return format!("Ball-{}", id + 1);
        }
        match self.fixed(id) {
            Fixed::Cushion(k) => format!("Cushion-{}", k + 1),
            Fixed::Pocket(k) => format!("Pocket-{}", k + 1),
            Fixed::Corner(k) => format!("Corner-{}", k + 1),
        }
    }

    /// When a ball on trajectory `tr` with radius `r` meets fixed object `id`.
    #[inline]
    pub fn contact(&self, id: u32, tr: &Trajectory, r: f64) -> Contact {
        match self.fixed(id) {
            Fixed::Cushion(k) => {
                let (from, to, _) = self.cushions[k as usize];
                physics::ball_face_contact(tr, r, from, to)
            }
            Fixed::Pocket(k) => {
                let (from, to) = self.pockets[k as usize];
                physics::ball_face_contact(tr, 0.0, from, to)
            }
            Fixed::Corner(k) => physics::ball_corner_contact(tr, r, self.corners[k as usize].0),
        }
    }

    /// The kind of event a ball has with fixed object `id`.
    pub fn event_kind(&self, id: u32) -> EventKind {
        match self.fixed(id) {
            Fixed::Cushion(_) => EventKind::BallCushion,
            Fixed::Pocket(_) => EventKind::BallPocket,
            Fixed::Corner(_) => EventKind::BallCorner,
        }
    }

    /// The velocity after a ball at `p` with velocity `v` bounces off fixed object `id`, or `None`
    /// if the object is a pocket (the ball drops in).
    pub fn bounce(&self, id: u32, p: Vec2, v: Vec2) -> Option<Vec2> {
        match self.fixed(id) {
            Fixed::Cushion(k) => {
                let (from, to, e) = self.cushions[k as usize];
                Some(physics::cushion_velocity(v, from, to, e))
            }
            Fixed::Pocket(_) => None,
            Fixed::Corner(k) => {
                let (c, e) = self.corners[k as usize];
                Some(physics::corner_velocity(v, p, c, e))
            }
        }
    }

    /// The squared distance from fixed object `id` to the rectangle `[lo, hi]`.
    pub fn distance2_to_rect(&self, id: u32, lo: Vec2, hi: Vec2) -> f64 {
        use crate::geometry::{rect_distance2, segment_rect_distance2};
        match self.fixed(id) {
            Fixed::Cushion(k) => {
                let (a, b, _) = self.cushions[k as usize];
                segment_rect_distance2(a, b, lo, hi)
            }
            Fixed::Pocket(k) => {
                let (a, b) = self.pockets[k as usize];
                segment_rect_distance2(a, b, lo, hi)
            }
            Fixed::Corner(k) => rect_distance2(self.corners[k as usize].0, lo, hi),
        }
    }

    /// Whether every elasticity on the table is 1, so kinetic energy must be conserved.
    pub fn is_elastic(&self) -> bool {
        self.cushions.iter().all(|c| c.2 == 1.0) && self.corners.iter().all(|c| c.1 == 1.0)
    }
}

/// The state of one ball: its trajectory since its last velocity change, size and mass, and the
/// pocket it dropped into, if any (then `traj` holds where and how it crossed the pocket line).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BallState {
    /// Trajectory since the last velocity change.
    pub traj: Trajectory,
    /// Radius (length).
    pub radius: f64,
    /// Mass.
    pub mass: f64,
    /// The pocket (0-based) the ball dropped into.
    pub pocket: Option<u32>,
}

/// When a run starts, whether every ball is turned around on the way (thesis 4.6), and how often
/// the display is drawn (4.2).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Span {
    /// The time of the scenario's initial positions and velocities.
    pub start: f64,
    /// The time at which every ball reverses its velocity, after every event of that instant;
    /// a ball in a pocket then comes back out at the mirror image of the time it dropped in.
    pub reverse_at: Option<f64>,
    /// Time between frames of the display: frames are drawn at `start`, `start + F`, … (none
    /// when `None`); with a reversal at `r`, on the grid `r + j F` through it instead.
    pub frame_time: Option<f64>,
}

impl Span {
    /// The time of frame `k`. With a reversal at `r`, frames stand at `r + j F` for every whole
    /// `j` from the first at or after `start`, so that each frame at `r + t` has its mirror at
    /// `r - t`; when `start` is a whole number `m` of frame times before `r` (to 1e-9), the
    /// frames at `j = ±m` are `start` and its mirror `2 r - start` exactly.
    pub fn frame(&self, k: u64) -> Option<f64> {
        let f = self.frame_time?;
        let Some(r) = self.reverse_at else {
            return Some(self.start + k as f64 * f);
        };
        let q = r - self.start;
        let whole = Span::whole_frames(q, f);
        let j = whole.map_or((-q / f).ceil(), |m| -m) + k as f64;
        Some(match whole {
            Some(m) if j.abs() == m => r + j.signum() * q,
            _ => r + j * f,
        })
    }

    /// The number of frame times `f` in the span `q`, if it is a whole number (to 1e-9 of it):
    /// then frames on a grid through a reversal reach a start `q` before it exactly.
    pub fn whole_frames(q: f64, f: f64) -> Option<f64> {
        let m = (q / f).round();
        ((q / f - m).abs() <= 1e-9 * m.abs().max(1.0)).then_some(m)
    }
}

impl BallState {
    /// The initial states of a scenario's balls in a run that starts at `start` (each fixed
    /// there, or where a checkpoint says).
    pub fn initial(s: &Scenario, start: f64) -> Vec<BallState> {
        s.balls
            .iter()
            .map(|b| BallState {
                traj: Trajectory {
                    position: b.position,
                    velocity: b.velocity,
                    t0: b.fixed.as_ref().map_or(start, |k| k.t),
                },
                radius: b.radius,
                mass: b.mass,
                pocket: b.pocket,
            })
            .collect()
    }

    /// Position at time `t`: on its trajectory, or where it entered its pocket.
    #[inline]
    pub fn position(&self, t: f64) -> Vec2 {
        if self.pocket.is_some() {
            self.traj.position
        } else {
            self.traj.at(t)
        }
    }

    /// Velocity on the table (zero in a pocket).
    #[inline]
    pub fn velocity(&self) -> Vec2 {
        if self.pocket.is_some() {
            Vec2::ZERO
        } else {
            self.traj.velocity
        }
    }
}

/// A kernel model's messages sent so far, by type name, and the cancellations (`Cancel`).
pub fn message_counts<M: pdes_kernel::Model>(
    model: &M,
    stats: &pdes_kernel::MessageStats,
) -> Vec<(&'static str, u64)> {
    let names = model.kind_names().iter().enumerate();
    let mut counts: Vec<(&'static str, u64)> = names.map(|(k, n)| (*n, stats.get(k))).collect();
    counts.push(("Cancel", stats.cancels));
    counts
}

/// A read-only view of an engine's state between events, for invariant checks.
pub trait World {
    /// The table.
    fn table(&self) -> &Table;
    /// Number of balls.
    fn n_balls(&self) -> usize;
    /// Ball `i`'s current state.
    fn ball(&self, i: u32) -> BallState;
    /// Calls `f` with every ball that might touch ball `i` now (a superset is fine).
    fn for_each_neighbor(&self, i: u32, f: &mut dyn FnMut(u32));
}

/// One frame of the display (thesis 4.2): every ball as it is at time `t`, after every event of
/// that instant.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The frame's time.
    pub t: f64,
    /// Every ball, fixed at `t` (a pocketed ball keeps its entry fix and names its pocket).
    pub balls: Vec<BallState>,
    /// In a periodic box, each ball's image: the whole sides along x and y from its position in
    /// the box to its unwrapped position; empty where the engine keeps none (a walled table).
    pub images: Vec<[i64; 2]>,
}

/// What every engine offers once set up: run on to a time, reporting each physical event to an
/// observer. [`crate::run::build_engine`] makes the one a run asks for.
pub trait Engine {
    /// Runs until the next event would come after `until`, reporting each event to `obs`, and
    /// returns the state at `until`.
    fn run(&mut self, until: f64, obs: &mut dyn Observer) -> Result<Outcome, RunError>;

    /// Ends later runs early, cleanly, once `interrupt` is raised: at a time of the engine's
    /// choosing (the event or step that saw it, or where Time Warp's workers agree) with every
    /// event up to it reported and the state at it returned.
    fn stop_on(&mut self, interrupt: Interrupt);

    /// Every ball as a run that takes this one up exactly must start it (its trajectory as
    /// last fixed, with the key that fixed it, and its pocket); `None` where the engine cannot
    /// be taken up exactly (the time-step engine, whose state is its grid of steps).
    fn balls_to_take_up(&self) -> Option<Vec<crate::scenario::BallSpec>> {
        None
    }

    /// Time Warp's statistics, where Time Warp runs the engine.
    fn tw_stats(&self) -> Option<pdes_kernel::time_warp::TwStats> {
        None
    }
    /// The regions engine's layout and traffic (other engines: `None`).
    fn regions(&self) -> Option<crate::summary::RegionsSummary> {
        None
    }

    /// Frees the engine's memory (Time Warp's on each worker's own thread).
    fn free(self: Box<Self>) {}
}

impl Engine for event_list::EventList {
    fn run(&mut self, until: f64, obs: &mut dyn Observer) -> Result<Outcome, RunError> {
        event_list::EventList::run(self, until, obs)
    }

    fn stop_on(&mut self, interrupt: Interrupt) {
        event_list::EventList::stop_on(self, interrupt);
    }

    fn balls_to_take_up(&self) -> Option<Vec<crate::scenario::BallSpec>> {
        Some(event_list::EventList::balls_to_take_up(self))
    }
}

impl Engine for time_step::TimeStep {
    fn run(&mut self, until: f64, obs: &mut dyn Observer) -> Result<Outcome, RunError> {
        time_step::TimeStep::run(self, until, obs)
    }

    fn stop_on(&mut self, interrupt: Interrupt) {
        time_step::TimeStep::stop_on(self, interrupt);
    }
}

impl Engine for objects::Objects {
    fn run(&mut self, until: f64, obs: &mut dyn Observer) -> Result<Outcome, RunError> {
        objects::Objects::run(self, until, obs)
    }

    fn stop_on(&mut self, interrupt: Interrupt) {
        objects::Objects::stop_on(self, interrupt);
    }

    fn balls_to_take_up(&self) -> Option<Vec<crate::scenario::BallSpec>> {
        Some(objects::Objects::balls_to_take_up(self))
    }

    fn tw_stats(&self) -> Option<pdes_kernel::time_warp::TwStats> {
        objects::Objects::tw_stats(self)
    }

    fn free(self: Box<Self>) {
        objects::Objects::free(*self);
    }
}

/// Receives every executed physical event, in execution order, with the state just after it,
/// and the frames of the display when the run makes them.
pub trait Observer {
    /// Called after each event; an error stops the run.
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError>;

    /// Whether `on_event` reads balls from the world (its table aside). An executor that keeps
    /// the balls' states on other threads (Time Warp) ships them only when some observer does.
    fn reads_balls(&self) -> bool {
        true
    }

    /// Called with the run's complete state at each checkpoint
    /// ([`crate::run::RunConfig::checkpoint_every`]); an error stops the run.
    fn on_checkpoint(&mut self, _checkpoint: Checkpoint) -> Result<(), RunError> {
        Ok(())
    }

    /// Called with each frame, in time order, when the run was asked for frames.
    fn on_frame(&mut self, _frame: &Frame, _table: &Table) -> Result<(), RunError> {
        Ok(())
    }

    /// Called after the thermostat gave `ball` a new velocity at `t`: not a physical event
    /// (the trace does not list it), but observers that follow velocities take it up here.
    fn on_kick(&mut self, _ball: u32, _t: f64, _world: &dyn World) -> Result<(), RunError> {
        Ok(())
    }
}

/// An observer that ignores everything.
pub struct Ignore;

impl Observer for Ignore {
    fn on_event(&mut self, _: &Event, _: &dyn World) -> Result<(), RunError> {
        Ok(())
    }

    fn reads_balls(&self) -> bool {
        false
    }
}

impl<O: Observer + ?Sized> Observer for &mut O {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        (**self).on_event(ev, world)
    }

    fn reads_balls(&self) -> bool {
        (**self).reads_balls()
    }

    fn on_frame(&mut self, frame: &Frame, table: &Table) -> Result<(), RunError> {
        (**self).on_frame(frame, table)
    }

    fn on_kick(&mut self, ball: u32, t: f64, world: &dyn World) -> Result<(), RunError> {
        (**self).on_kick(ball, t, world)
    }

    fn on_checkpoint(&mut self, checkpoint: Checkpoint) -> Result<(), RunError> {
        (**self).on_checkpoint(checkpoint)
    }
}

/// Why a run stopped before its end time.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum RunError {
    /// An invariant was violated (`--check`): what, where and when.
    #[error("check failed: {0}")]
    Violation(String),
    /// One instant had more events than the cap: a cascade that does not end.
    #[error(
        "{events} events at the single instant t = {t}: a cascade of instantaneous collisions \
         that does not end (a ball wedged between cushions or balls?)"
    )]
    Cascade {
        /// The instant.
        t: f64,
        /// Events processed at it.
        events: u64,
    },
    /// An observer's output failed (a trace file could not be written).
    #[error("output failed: {0}")]
    Output(String),
    /// The run was asked for something the input does not allow.
    #[error("{0}")]
    Input(String),
    /// The sector layout asked for is unusable.
    #[error(transparent)]
    Layout(#[from] crate::run::SectorLayoutError),
    /// Time Warp failed: out of its memory budget, or a model bug committed.
    #[error("{0}")]
    TimeWarp(String),
}

/// Counts the physical events of the current instant and stops a run whose instant never ends,
/// such as a ball wedged between two cushions exactly a diameter apart, which bounces at one time
/// forever. Each event of a cascade lengthens its key, so a chain must be stopped early: the
/// cap is 1,000 events of one ball in one instant (a ball of a racked break takes part in a few),
/// and 20,000 events plus 100 per ball in all.
pub struct InstantCap {
    t: f64,
    events: u64,
    cap: u64,
    n_balls: u32,
    /// Events of each ball in this instant, kept only while the instant has more than one.
    per_ball: rustc_hash::FxHashMap<u32, u32>,
}

/// The most events one ball may take part in within one instant.
const MAX_BALL_EVENTS_PER_INSTANT: u32 = 1_000;

impl InstantCap {
    /// The cap for a table of `n_balls` balls.
    pub fn new(n_balls: usize) -> InstantCap {
        InstantCap {
            t: f64::NAN,
            events: 0,
            cap: 20_000 + 100 * n_balls as u64,
            n_balls: n_balls as u32,
            per_ball: Default::default(),
        }
    }

    /// Counts event `ev`; an error once its instant holds more than the cap.
    pub fn count(&mut self, ev: &Event) -> Result<(), RunError> {
        if ev.t != self.t {
            (self.t, self.events) = (ev.t, 1);
            if !self.per_ball.is_empty() {
                self.per_ball.clear();
            }
            return Ok(());
        }
        self.events += 1;
        let mut over = self.events > self.cap;
        for ball in [ev.a, ev.b] {
            if ball < self.n_balls {
                let n = self.per_ball.entry(ball).or_insert(1);
                *n += 1;
                over |= *n > MAX_BALL_EVENTS_PER_INSTANT;
            }
        }
        if over {
            return Err(RunError::Cascade {
                t: ev.t,
                events: self.events,
            });
        }
        Ok(())
    }
}

/// Counts of executed events by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EventCounts {
    /// Counts indexed like [`EventKind::ALL`].
    pub by_kind: [u64; 4],
}

impl EventCounts {
    /// Adds one event of `kind`.
    #[inline]
    pub fn add(&mut self, kind: EventKind) {
        self.by_kind[kind as usize] += 1;
    }

    /// The count of `kind`.
    pub fn get(&self, kind: EventKind) -> u64 {
        self.by_kind[kind as usize]
    }

    /// All events.
    pub fn total(&self) -> u64 {
        self.by_kind.iter().sum()
    }
}

/// The end of a run: the balls at the end time and what the engine counted.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The end time.
    pub t: f64,
    /// Every ball's state, fixed at `t` (balls in pockets keep their entry fix).
    pub balls: Vec<BallState>,
    /// Executed physical events by kind.
    pub events: EventCounts,
    /// Engine-specific counters, by name, for the run summary.
    pub engine_stats: Vec<(&'static str, f64)>,
    /// Messages sent, by thesis type (empty for engines that send none).
    pub messages: Vec<(&'static str, u64)>,
}
