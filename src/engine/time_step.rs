//! The time-step engine (thesis fig. 1): the baseline the thesis argues against.
//!
//! Every step of length `dt` moves every ball, then looks for balls that overlap a pocket line,
//! a cushion, a corner or another ball and resolves those contacts with the same physics as the
//! exact engines. It can only notice a contact after it has happened, so it reports what that
//! costs: how deep balls overlapped when a contact was found (as a fraction of a radius), how late
//! it was found (time since the exact contact, solved backwards from the overlap), and the pairs
//! it found overlapping while already separating (passed through, or still tangled from a
//! previous step) — beside its cost in steps and pair tests (2.1: `O(n T / Δt)` with a cell grid).

use super::grid::Grid;
use super::{
    BallState, Event, EventCounts, EventKind, Observer, Outcome, RunError, Span, Table, World,
};
use crate::geometry::{Trajectory, Vec2};
use crate::physics;
use crate::scenario::Scenario;
use pdes_kernel::Interrupt;

/// Options of the time-step engine.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// The time step.
    pub dt: f64,
    /// Start time and reversal (a step ends exactly at the reversal).
    pub span: Span,
}

/// What the time-step engine got wrong and what it cost.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stats {
    /// Steps taken.
    pub steps: u64,
    /// Ball pairs and ball–fixed pairs tested.
    pub pair_tests: u64,
    /// Contacts found (events).
    pub contacts: u64,
    /// Deepest overlap at detection, as a fraction of the smaller radius.
    pub max_overlap: f64,
    /// Sum of detection delays (time since the exact contact).
    pub total_lateness: f64,
    /// Largest detection delay.
    pub max_lateness: f64,
    /// Ball pairs found overlapping while moving apart.
    pub overlapping_separating: u64,
}

/// The time-step engine over one scenario.
pub struct TimeStep {
    table: Table,
    balls: Vec<BallState>,
    grid: Grid,
    dt: f64,
    t: f64,
    start: f64,
    /// Whole steps of `dt` taken since the start.
    steps_done: u64,
    reverse_at: Option<f64>,
    /// Balls to come back out of their pocket after the reversal: (time, ball, pocket id).
    returns: Vec<(f64, u32, u32)>,
    stats: Stats,
    /// Ends runs early, at the end of the step that saw it raised.
    interrupt: Option<Interrupt>,
}

impl TimeStep {
    /// Sets up the engine at `opts.span.start` for a validated scenario; `dt` must be positive.
    pub fn new(s: &Scenario, opts: Options) -> TimeStep {
        let table = Table::new(s);
        let balls = BallState::initial(s, opts.span.start);
        let rmax = balls.iter().map(|b| b.radius).fold(0.0, f64::max);
        let centres: Vec<_> = balls.iter().map(|b| b.traj.position).collect();
        let mut grid = Grid::new(&table, &centres, rmax, 2.0 * rmax);
        for (i, b) in balls.iter().enumerate() {
            grid.insert_at(i as u32, b.traj.position);
        }
        TimeStep {
            table,
            balls,
            grid,
            dt: opts.dt,
            t: opts.span.start,
            start: opts.span.start,
            steps_done: 0,
            reverse_at: opts.span.reverse_at,
            returns: Vec::new(),
            stats: Stats::default(),
            interrupt: None,
        }
    }

    /// The counters so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    fn note_lateness(&mut self, overlap_fraction: f64, late: f64) {
        self.stats.contacts += 1;
        self.stats.max_overlap = self.stats.max_overlap.max(overlap_fraction);
        self.stats.total_lateness += late;
        self.stats.max_lateness = self.stats.max_lateness.max(late);
    }

    fn set_velocity(&mut self, i: u32, v: Vec2) {
        self.balls[i as usize].traj.velocity = v;
    }

    fn emit(
        &self,
        kind: EventKind,
        a: u32,
        b: u32,
        counts: &mut EventCounts,
        obs: &mut dyn Observer,
    ) -> Result<(), RunError> {
        counts.add(kind);
        obs.on_event(
            &Event {
                t: self.t,
                kind,
                a,
                b,
            },
            self,
        )
    }

    /// Turns every ball around now (thesis 4.6); a pocketed ball is set to come back out at the
    /// mirror image of the time it dropped in.
    fn reverse(&mut self) {
        let now = self.t;
        for (i, b) in self.balls.iter_mut().enumerate() {
            b.traj.velocity = -b.traj.velocity;
            if let Some(k) = b.pocket {
                let f = self.table.fixed_id(super::Fixed::Pocket(k));
                self.returns.push((2.0 * now - b.traj.t0, i as u32, f));
            }
        }
        self.reverse_at = None;
    }

    /// Brings back out of their pockets the balls due by now, where they would be by now.
    fn bring_back(
        &mut self,
        counts: &mut EventCounts,
        obs: &mut dyn Observer,
    ) -> Result<(), RunError> {
        let now = self.t;
        let due: Vec<(f64, u32, u32)> = self
            .returns
            .iter()
            .copied()
            .filter(|r| r.0 <= now)
            .collect();
        self.returns.retain(|r| r.0 > now);
        for (back, i, f) in due {
            let b = &mut self.balls[i as usize];
            b.pocket = None;
            b.traj = Trajectory {
                position: b.traj.position + (now - back) * b.traj.velocity,
                velocity: b.traj.velocity,
                t0: now,
            };
            self.grid.insert_at(i, b.traj.position);
            self.emit(EventKind::BallPocket, i, f, counts, obs)?;
        }
        Ok(())
    }

    /// Contacts of ball `i` with fixed objects at the end of a step.
    fn fixed_contacts(
        &mut self,
        i: u32,
        counts: &mut EventCounts,
        obs: &mut dyn Observer,
    ) -> Result<(), RunError> {
        let Some(cell) = self.grid.cell_of(i) else {
            return Ok(());
        };
        let fixed: Vec<u32> = self.grid.fixed_near(cell).to_vec();
        for f in fixed {
            self.stats.pair_tests += 1;
            let b = self.balls[i as usize];
            if b.pocket.is_some() {
                return Ok(());
            }
            let p = b.traj.position;
            let v = b.traj.velocity;
            match self.table.fixed(f) {
                super::Fixed::Pocket(k) => {
                    let (from, to) = self.table.pockets[k as usize];
                    let start = p - self.dt * v;
                    let l = to - from;
                    let side0 = (start - from).cross(l);
                    let side1 = (p - from).cross(l);
                    // crossed out of the table side (cross > 0 is the right of from → to)
                    let along = (p - from).dot(l) / l.norm2();
                    if side0 >= 0.0 && side1 < 0.0 && (0.0..=1.0).contains(&along) {
                        let late = -side1 / (side0 - side1) * self.dt;
                        self.note_lateness(0.0, late);
                        self.balls[i as usize].pocket = Some(k);
                        self.grid.remove(i);
                        self.emit(EventKind::BallPocket, i, f, counts, obs)?;
                        return Ok(());
                    }
                }
                super::Fixed::Cushion(k) => {
                    let (from, to, _) = self.table.cushions[k as usize];
                    let l = to - from;
                    let n = (1.0 / l.norm()) * l.perp_cw();
                    let d = (p - from).dot(n);
                    let along = (p - from).dot(l) / l.norm2();
                    let vn = v.dot(n);
                    if d < b.radius && d > -b.radius && vn < 0.0 && (0.0..=1.0).contains(&along) {
                        let over = b.radius - d;
                        self.note_lateness(over / b.radius, over / -vn);
                        let nv = self.table.bounce(f, p, v).unwrap_or(v);
                        self.set_velocity(i, nv);
                        self.emit(EventKind::BallCushion, i, f, counts, obs)?;
                    }
                }
                super::Fixed::Corner(k) => {
                    let c = self.table.corners[k as usize].0;
                    let dp = c - p;
                    let closing = dp.dot(v) > 0.0;
                    if dp.norm2() < b.radius * b.radius && closing {
                        let late = backwards_contact(dp, -v, b.radius);
                        self.note_lateness((b.radius - dp.norm()) / b.radius, late);
                        let nv = self.table.bounce(f, p, v).unwrap_or(v);
                        self.set_velocity(i, nv);
                        self.emit(EventKind::BallCorner, i, f, counts, obs)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// Ends later runs early once `interrupt` is raised: at the end of the step that saw it.
    pub fn stop_on(&mut self, interrupt: Interrupt) {
        self.interrupt = Some(interrupt);
    }

    /// Runs until `until` in steps of `dt`, reporting each contact it finds to `obs` (or to the
    /// end of the step in which an interrupt came).
    pub fn run(&mut self, until: f64, obs: &mut dyn Observer) -> Result<Outcome, RunError> {
        let mut counts = EventCounts::default();
        let n = self.balls.len() as u32;
        while self.t < until {
            let step = self.advance_clock(until);
            self.stats.steps += 1;
            self.move_balls(step);
            for i in 0..n {
                self.fixed_contacts(i, &mut counts, obs)?;
            }
            for i in 0..n {
                self.ball_contacts(i, &mut counts, obs)?;
            }
            self.bring_back(&mut counts, obs)?;
            if self.reverse_at == Some(self.t) {
                self.reverse();
            }
            if self.interrupt.as_ref().is_some_and(Interrupt::raised) {
                return Ok(self.outcome(self.t, counts));
            }
        }
        Ok(self.outcome(until, counts))
    }

    /// Moves the clock to the end of the next step and returns the step's length. Steps end on
    /// the grid start + k dt (no drift from adding dt up), or at the stop (`until` or the
    /// reversal); a grid point within a hair of the stop is the stop, so no sliver step follows.
    fn advance_clock(&mut self, until: f64) -> f64 {
        let stop = match self.reverse_at {
            Some(r) if r > self.t && r < until => r,
            _ => until,
        };
        let prev = self.t;
        let next = self.start + (self.steps_done + 1) as f64 * self.dt;
        if next <= stop + 1e-9 * self.dt {
            self.steps_done += 1;
            self.t = next.min(stop);
        } else {
            self.t = stop;
        }
        self.t - prev
    }

    /// Moves every ball on the table by `step` and files it in its new cell.
    fn move_balls(&mut self, step: f64) {
        for i in 0..self.balls.len() as u32 {
            let b = &mut self.balls[i as usize];
            if b.pocket.is_some() {
                continue;
            }
            b.traj = Trajectory {
                position: b.traj.position + step * b.traj.velocity,
                velocity: b.traj.velocity,
                t0: self.t,
            };
            self.grid.move_to(i, b.traj.position);
        }
    }

    /// Ball `i` against the higher-numbered balls near it, in order: each pair found
    /// overlapping and closing collides now.
    fn ball_contacts(
        &mut self,
        i: u32,
        counts: &mut EventCounts,
        obs: &mut dyn Observer,
    ) -> Result<(), RunError> {
        let Some(cell) = self.grid.cell_of(i) else {
            return Ok(());
        };
        let mut near = Vec::new();
        self.grid.for_each_near(cell, |j| {
            if j > i {
                near.push(j)
            }
        });
        near.sort_unstable();
        for j in near {
            self.stats.pair_tests += 1;
            let (a, b) = (self.balls[i as usize], self.balls[j as usize]);
            let sigma = a.radius + b.radius;
            let dp = b.traj.position - a.traj.position;
            let dv = b.traj.velocity - a.traj.velocity;
            if dp.norm2() >= sigma * sigma {
                continue;
            }
            if dp.dot(dv) >= 0.0 {
                self.stats.overlapping_separating += 1;
                continue;
            }
            let late = backwards_contact(dp, dv, sigma);
            self.note_lateness((sigma - dp.norm()) / a.radius.min(b.radius), late);
            let (va, vb) = physics::ball_ball_velocities(
                a.traj.position,
                a.traj.velocity,
                a.mass,
                b.traj.position,
                b.traj.velocity,
                b.mass,
            );
            self.set_velocity(i, va);
            self.set_velocity(j, vb);
            self.emit(EventKind::BallBall, i, j, counts, obs)?;
        }
        Ok(())
    }

    /// The state at the end of a run to `until`, with the events counted and the statistics.
    fn outcome(&self, until: f64, events: EventCounts) -> Outcome {
        let s = self.stats;
        let mean_late = if s.contacts > 0 {
            s.total_lateness / s.contacts as f64
        } else {
            0.0
        };
        Outcome {
            t: self.t.max(until),
            balls: self.balls.clone(),
            events,
            engine_stats: vec![
                ("dt", self.dt),
                ("steps", s.steps as f64),
                ("pair_tests", s.pair_tests as f64),
                ("max_overlap_fraction_of_radius", s.max_overlap),
                ("mean_detection_delay", mean_late),
                ("max_detection_delay", s.max_lateness),
                (
                    "overlapping_separating_pairs",
                    s.overlapping_separating as f64,
                ),
            ],
            messages: Vec::new(),
        }
    }
}

/// How long ago two disks at separation `dp` (overlapping: `|dp| < sigma`), closing at relative
/// velocity `dv`, first touched: the positive root of `|dp − τ dv| = sigma`, in stable form.
fn backwards_contact(dp: Vec2, dv: Vec2, sigma: f64) -> f64 {
    let a = dv.norm2();
    if a == 0.0 {
        return 0.0;
    }
    let b = dp.dot(dv);
    let c = dp.norm2() - sigma * sigma;
    let s = (b * b - a * c).max(0.0).sqrt();
    if s - b > 0.0 {
        -c / (s - b)
    } else {
        0.0
    }
}

impl World for TimeStep {
    fn table(&self) -> &Table {
        &self.table
    }

    fn n_balls(&self) -> usize {
        self.balls.len()
    }

    fn ball(&self, i: u32) -> BallState {
        self.balls[i as usize]
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backwards_contact_inverts_forward_motion() {
        // touching at separation 2 along x, then closing at speed 1 for 0.25
        let dp = Vec2::new(1.75, 0.0);
        let dv = Vec2::new(-1.0, 0.0);
        assert!((backwards_contact(dp, dv, 2.0) - 0.25).abs() < 1e-12);
    }
}
