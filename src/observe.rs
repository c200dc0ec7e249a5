//! Observables of a hard-disk run, exact for event-driven dynamics: the pressure from the
//! collision virial and from the impulse on the cushions, the compressibility factor, the
//! temperature and the collision rate, each averaged over blocks of time with its standard error.
//!
//! Between events nothing changes but positions, so every time integral is a sum over the
//! intervals between events, and every impulse is a velocity change an event made:
//!
//! ```text
//!   kT      = <K> / N                        (two degrees of freedom: K = N kT)
//!   P A     = N kT + (1 / 2T) Σ_ball-ball r_ab · Δp_a      (virial theorem; Allen & Tildesley 2017, 2.4)
//!   P_walls = Σ_bounces |Δp| / (T L)         (L: the cushions' length)
//!   Z       = P A / (N kT),   ν = 2 C / (N T) (collisions per ball and unit time)
//! ```
//!
//! with `r_ab` the centres' separation at contact, `Δp_a` ball a's change of momentum, `C` the
//! ball–ball collisions in time `T` and `A` the table's box. On a walled table the centres stay
//! a radius inside the cushions: on a rectangle of sides `Lx`, `Ly` with disks of one radius
//! `r`, both pressures are the force per unit length on the rectangle the centres touch,
//! `P Lx Ly / ((Lx − 2r)(Ly − 2r))` and, per side, `P_walls L / (L − 2r)`, and neither is the
//! bulk pressure of an unbounded fluid. In equilibrium with Maxwell velocities and equal masses,
//! each collision's virial averages to `σ m √(π kT / m)`, so that
//! `Z − 1 = (√π / 4) ν σ √(m / kT)` (the test `tests/observables.rs` checks both).
//!
//! The run from `from` on is cut into blocks of `every` time units (a last, shorter block is
//! left out); a figure's `error` is the standard error of its block means (Flyvbjerg and
//! Petersen 1989: blocks longer than the correlation time make them independent).

use crate::engine::{Event, EventKind, Observer, RunError, World};
use crate::geometry::Vec2;
use crate::scenario::Scenario;

/// One figure: the mean of the block values and its standard error (0 with one block).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Estimate {
    /// The mean over the blocks.
    pub mean: f64,
    /// The standard error of that mean: the blocks' standard deviation over √(blocks − 1).
    pub error: f64,
}

impl Estimate {
    /// The mean and standard error of `values`.
    pub fn of(values: &[f64]) -> Estimate {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n.max(1.0);
        if values.len() < 2 {
            return Estimate { mean, error: 0.0 };
        }
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        Estimate {
            mean,
            error: (var / n).sqrt(),
        }
    }
}

/// What the observables came to (the summary's `observables`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Observed {
    /// The time the blocks start at.
    pub from: f64,
    /// The length of each block.
    pub every: f64,
    /// Whole blocks averaged.
    pub blocks: usize,
    /// Balls on the table at the start.
    pub balls: usize,
    /// The table's box area.
    pub area: f64,
    /// The temperature: mean kinetic energy per ball (k = 1).
    pub kt: Estimate,
    /// Ball–ball collisions per ball and unit time.
    pub collision_rate: Estimate,
    /// Pressure from the collision virial over the box area.
    pub pressure: Estimate,
    /// The compressibility factor P A / (N kT), from the virial.
    pub z: Estimate,
    /// Force per unit length on the cushions (their momentum per unit time and length).
    pub pressure_walls: Estimate,
    /// Each whole block's figures in time order: the time series the estimates average.
    pub series: Vec<BlockFigures>,
}

/// One block's figures (see [`Observed`] for each).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BlockFigures {
    /// The block's end.
    pub end: f64,
    /// The temperature.
    pub kt: f64,
    /// Ball–ball collisions per ball and unit time.
    pub collision_rate: f64,
    /// Pressure from the collision virial.
    pub pressure: f64,
    /// The compressibility factor.
    pub z: f64,
    /// Force per unit length on the cushions.
    pub pressure_walls: f64,
}

/// Why blocks cannot be observed over a run: each message reads after the name of the setting
/// it is about ([`ObserveError::is_about_every`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ObserveError {
    /// The block length is not a positive number.
    #[error("must be a positive number, got {0}")]
    Every(f64),
    /// The first block does not lie within the run.
    #[error(
        "the first block, from {from} to {to}, must lie within the run, from {start} to {until}"
    )]
    From {
        /// Where the first block starts.
        from: f64,
        /// Where it ends.
        to: f64,
        /// The run's start.
        start: f64,
        /// The run's end.
        until: f64,
    },
}

impl ObserveError {
    /// Whether the error is about the block length (else about where the blocks start).
    pub fn is_about_every(&self) -> bool {
        matches!(self, ObserveError::Every(_))
    }
}

/// One block's sums.
#[derive(Clone, Copy, Debug, Default)]
struct Block {
    kinetic_time: f64,
    virial: f64,
    wall_impulse: f64,
    collisions: u64,
}

/// Accumulates the observables over a run: an [`Observer`] to chain with the others.
pub struct Observables {
    from: f64,
    every: f64,
    /// Each ball's velocity and mass as of its last event.
    velocity: Vec<Vec2>,
    mass: Vec<f64>,
    kinetic: f64,
    /// The time up to which `kinetic` has been integrated.
    now: f64,
    block: Block,
    blocks: Vec<Block>,
    balls: usize,
    area: f64,
    cushion_length: f64,
}

impl Observables {
    /// Observables of a run of `scenario` that starts at `start`, in blocks of `every` from
    /// `from`.
    pub fn new(scenario: &Scenario, start: f64, from: f64, every: f64) -> Observables {
        let velocity: Vec<Vec2> = scenario.balls.iter().map(|b| b.velocity).collect();
        let mass: Vec<f64> = scenario.balls.iter().map(|b| b.mass).collect();
        let kinetic = velocity
            .iter()
            .zip(&mass)
            .map(|(v, m)| 0.5 * m * v.norm2())
            .sum();
        let (lo, hi) = scenario.bounds();
        Observables {
            from,
            every,
            velocity,
            mass,
            kinetic,
            now: start,
            block: Block::default(),
            blocks: Vec::new(),
            balls: scenario.balls.len(),
            area: (hi.x - lo.x) * (hi.y - lo.y),
            cushion_length: scenario
                .cushions
                .iter()
                .map(|c| (c.to - c.from).norm())
                .sum(),
        }
    }

    /// Observables of a run of `scenario` from `start` to `until`, in blocks of `every` from
    /// `from` (default: the start), refused unless at least one whole block fits.
    pub fn over(
        scenario: &Scenario,
        (start, until): (f64, f64),
        from: Option<f64>,
        every: f64,
    ) -> Result<Observables, ObserveError> {
        let from = from.unwrap_or(start);
        if !(every.is_finite() && every > 0.0) {
            return Err(ObserveError::Every(every));
        }
        if !(from.is_finite() && from >= start && from + every <= until) {
            return Err(ObserveError::From {
                from,
                to: from + every,
                start,
                until,
            });
        }
        Ok(Observables::new(scenario, start, from, every))
    }

    /// The end of the block being summed.
    fn block_end(&self) -> f64 {
        self.from + self.every * (self.blocks.len() + 1) as f64
    }

    /// Integrates the kinetic energy up to `t`, closing every block that ends by then.
    fn advance(&mut self, t: f64) {
        while t >= self.block_end() {
            let end = self.block_end();
            self.block.kinetic_time += self.kinetic * (end - self.now.max(self.from));
            self.blocks.push(std::mem::take(&mut self.block));
            self.now = end;
        }
        if t > self.from {
            self.block.kinetic_time += self.kinetic * (t - self.now.max(self.from));
        }
        self.now = self.now.max(t);
    }

    /// Ball `i`'s change of momentum at this event, and its new velocity kept.
    fn kick(&mut self, i: u32, world: &dyn World) -> Vec2 {
        self.kick_to(i, world.ball(i).velocity())
    }

    /// Ball `i`'s change of momentum to the velocity `after`, which is kept.
    #[inline]
    fn kick_to(&mut self, i: u32, after: Vec2) -> Vec2 {
        let k = i as usize;
        let dp = self.mass[k] * (after - self.velocity[k]);
        self.kinetic += 0.5 * self.mass[k] * (after.norm2() - self.velocity[k].norm2());
        self.velocity[k] = after;
        dp
    }

    /// What the whole blocks came to.
    pub fn finish(mut self, until: f64) -> Observed {
        self.advance(until);
        let (n, area, t) = (self.balls as f64, self.area, self.every);
        let series: Vec<BlockFigures> = self
            .blocks
            .iter()
            .enumerate()
            .map(|(k, b)| {
                let kt = b.kinetic_time / t / n;
                BlockFigures {
                    end: self.from + t * (k + 1) as f64,
                    kt,
                    collision_rate: 2.0 * b.collisions as f64 / (n * t),
                    pressure: (n * kt + b.virial / (2.0 * t)) / area,
                    z: 1.0 + b.virial / (2.0 * t * n * kt),
                    pressure_walls: b.wall_impulse / (t * self.cushion_length),
                }
            })
            .collect();
        let each = |f: fn(&BlockFigures) -> f64| -> Estimate {
            Estimate::of(&series.iter().map(f).collect::<Vec<_>>())
        };
        Observed {
            from: self.from,
            every: self.every,
            blocks: self.blocks.len(),
            balls: self.balls,
            area,
            kt: each(|b| b.kt),
            collision_rate: each(|b| b.collision_rate),
            pressure: each(|b| b.pressure),
            z: each(|b| b.z),
            pressure_walls: each(|b| b.pressure_walls),
            series,
        }
    }
}

impl Observer for Observables {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        self.advance(ev.t);
        let counted = ev.t >= self.from;
        match ev.kind {
            EventKind::BallBall => {
                // each ball read once: its new velocity and its place at the contact
                let (a, b) = (world.ball(ev.a), world.ball(ev.b));
                let dp = self.kick_to(ev.a, a.velocity());
                self.kick_to(ev.b, b.velocity());
                let (pa, pb) = (a.position(ev.t), b.position(ev.t));
                // from b to a, the nearest image in a periodic box
                let r = world.table().separation(pb, pa);
                if counted {
                    self.block.virial += r.dot(dp);
                    self.block.collisions += 1;
                }
            }
            EventKind::BallCushion => {
                let dp = self.kick(ev.a, world);
                if counted {
                    self.block.wall_impulse += dp.norm();
                }
            }
            EventKind::BallCorner | EventKind::BallPocket => {
                self.kick(ev.a, world);
            }
        }
        Ok(())
    }

    /// The thermostat's kick changes the kinetic energy, and no pressure: it is not a force
    /// between the disks.
    fn on_kick(&mut self, ball: u32, t: f64, world: &dyn World) -> Result<(), RunError> {
        self.advance(t);
        self.kick(ball, world);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimates_are_means_with_standard_errors() {
        let e = Estimate::of(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(e.mean, 2.5);
        // sd = sqrt(5/3), error = sd / 2
        assert!((e.error - (5.0f64 / 3.0).sqrt() / 2.0).abs() < 1e-15);
        assert_eq!(Estimate::of(&[7.0]).error, 0.0);
    }
}
