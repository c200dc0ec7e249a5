//! Invariants checked while a run goes (`poolsim run --check`): no two balls overlap, every ball
//! is on the table or in a pocket, and kinetic energy is conserved where every elasticity is 1.
//!
//! After each event the balls it involved are checked against their neighbours and the cushions;
//! every `n` events (n = the number of balls) the whole table is swept and the energy summed
//! afresh, so the cost stays O(1) per event on average.

use crate::engine::{BallState, Event, Observer, RunError, Table, World};
use crate::physics::kinetic_energy;

/// Largest overlap allowed between two balls, or a ball and a cushion, as a fraction of a radius.
pub const OVERLAP_TOLERANCE: f64 = 1e-9;

/// Positions are known to within a few units in the last place of their coordinates: an overlap
/// below this many machine epsilons of the largest coordinate is rounding, whatever the radius
/// (a ball of radius 10^-6 at x = 400 is placed to 6 × 10^-14, 6 × 10^-8 of its radius).
const POSITION_ULPS: f64 = 16.0;

/// The overlap allowed for a ball of radius `r` at `p`: a fraction of the radius, or the
/// resolution of the position where that is coarser.
fn slack(r: f64, p: crate::geometry::Vec2) -> f64 {
    (OVERLAP_TOLERANCE * r).max(POSITION_ULPS * f64::EPSILON * p.x.abs().max(p.y.abs()))
}

/// Largest relative drift of kinetic energy allowed on an elastic table.
pub const ENERGY_TOLERANCE: f64 = 1e-9;

/// The invariant checker, an [`Observer`].
pub struct Checker {
    energy: Vec<f64>,
    total: f64,
    initial: f64,
    elastic: bool,
    since_sweep: usize,
    /// The largest relative energy drift seen at a sweep.
    pub max_energy_drift: f64,
    /// Full sweeps done.
    pub sweeps: u64,
}

/// Energy a ball carries: on the table, or into its pocket.
fn ball_energy(b: &BallState) -> f64 {
    kinetic_energy(b.mass, b.traj.velocity)
}

impl Checker {
    /// A checker for balls starting in `balls`, on a table whose elasticities are all 1 when
    /// `elastic`.
    pub fn new(balls: &[BallState], elastic: bool) -> Checker {
        let energy: Vec<f64> = balls.iter().map(ball_energy).collect();
        let total = energy.iter().sum();
        Checker {
            energy,
            total,
            initial: total,
            elastic,
            since_sweep: 0,
            max_energy_drift: 0.0,
            sweeps: 0,
        }
    }

    fn check_ball(world: &dyn World, i: u32, t: f64) -> Result<(), RunError> {
        let bi = &world.ball(i);
        if bi.pocket.is_some() {
            return Ok(());
        }
        let table = world.table();
        let p = bi.traj.at(t);
        let mut err = None;
        world.for_each_neighbor(i, &mut |j| {
            let bj = &world.ball(j);
            if err.is_some() || bj.pocket.is_some() {
                return;
            }
            let overlap = bi.radius + bj.radius - table.separation(p, bj.traj.at(t)).norm();
            if overlap > slack(bi.radius.min(bj.radius), p) {
                let (a, b) = (i.min(j), i.max(j));
                err = Some(format!(
                    "t = {t}: Ball-{} and Ball-{} overlap by {overlap:e} ({:e} of a radius)",
                    a + 1,
                    b + 1,
                    overlap / bi.radius.min(bj.radius)
                ));
            }
        });
        if let Some(e) = err {
            return Err(RunError::Violation(e));
        }
        let slack = slack(bi.radius, p);
        // a ball in a periodic box is anywhere in the plane until it is taken back into the box
        let open_plane = table.cushions.is_empty() && table.pockets.is_empty();
        if !open_plane
            && (p.x < table.lo.x - slack
                || p.y < table.lo.y - slack
                || p.x > table.hi.x + slack
                || p.y > table.hi.y + slack)
        {
            return Err(RunError::Violation(format!(
                "t = {t}: Ball-{} at [{}, {}] has left the table",
                i + 1,
                p.x,
                p.y
            )));
        }
        for (k, &(from, to, _)) in table.cushions.iter().enumerate() {
            let l = to - from;
            let len = l.norm();
            let along = (p - from).dot(l) / len;
            let into = (p - from).dot(l.perp_cw()) / len;
            if along >= 0.0 && along <= len && into.abs() < bi.radius - slack {
                return Err(RunError::Violation(format!(
                    "t = {t}: Ball-{} overlaps Cushion-{} by {:e}",
                    i + 1,
                    k + 1,
                    bi.radius - into.abs()
                )));
            }
        }
        Ok(())
    }

    /// Checks the balls an engine ended with (`balls`, fixed at `t`): the last sweep, which
    /// catches what no event showed (a ball that tunnels through a cushion has no event at all).
    pub fn sweep_final(
        &mut self,
        table: &Table,
        balls: &[BallState],
        t: f64,
    ) -> Result<(), RunError> {
        self.sweep(&Snapshot::new(table, balls, t), t)
    }

    /// Checks the whole table at time `t` and the energy sum.
    pub fn sweep(&mut self, world: &dyn World, t: f64) -> Result<(), RunError> {
        self.sweeps += 1;
        self.since_sweep = 0;
        for i in 0..world.n_balls() as u32 {
            Self::check_ball(world, i, t)?;
            self.energy[i as usize] = ball_energy(&world.ball(i));
        }
        self.total = self.energy.iter().sum();
        self.check_energy(t)
    }

    fn check_energy(&mut self, t: f64) -> Result<(), RunError> {
        if !self.elastic || self.initial == 0.0 {
            return Ok(());
        }
        let drift = ((self.total - self.initial) / self.initial).abs();
        self.max_energy_drift = self.max_energy_drift.max(drift);
        if drift > ENERGY_TOLERANCE {
            return Err(RunError::Violation(format!(
                "t = {t}: kinetic energy {} differs from the initial {} by {drift:e} relative",
                self.total, self.initial
            )));
        }
        Ok(())
    }
}

impl Observer for Checker {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        let n_balls = world.n_balls();
        for i in [ev.a, ev.b] {
            if (i as usize) < n_balls {
                Self::check_ball(world, i, ev.t)?;
                let e = ball_energy(&world.ball(i));
                self.total += e - self.energy[i as usize];
                self.energy[i as usize] = e;
            }
        }
        self.check_energy(ev.t)?;
        self.since_sweep += 1;
        if self.since_sweep >= n_balls.max(1) {
            self.sweep(world, ev.t)?;
        }
        Ok(())
    }

    /// The kicked ball's energy is taken up (a run with a thermostat is checked as inelastic:
    /// energy is not conserved).
    fn on_kick(&mut self, ball: u32, _t: f64, world: &dyn World) -> Result<(), RunError> {
        let e = ball_energy(&world.ball(ball));
        self.total += e - self.energy[ball as usize];
        self.energy[ball as usize] = e;
        Ok(())
    }
}

/// Balls at one time on a table, as a [`World`]; neighbours found by sorting on x.
struct Snapshot<'a> {
    table: &'a Table,
    balls: &'a [BallState],
    /// Ball indices on the table, by the x of their centre at the snapshot's time.
    by_x: Vec<(f64, u32)>,
    reach: f64,
    t: f64,
}

impl<'a> Snapshot<'a> {
    fn new(table: &'a Table, balls: &'a [BallState], t: f64) -> Snapshot<'a> {
        let mut by_x: Vec<(f64, u32)> = (0..balls.len() as u32)
            .filter(|&i| balls[i as usize].pocket.is_none())
            .map(|i| (Self::x(table, &balls[i as usize], t), i))
            .collect();
        by_x.sort_by(|a, b| a.0.total_cmp(&b.0));
        let reach = 2.0 * balls.iter().map(|b| b.radius).fold(0.0, f64::max);
        Snapshot {
            table,
            balls,
            by_x,
            reach,
            t,
        }
    }
}

impl Snapshot<'_> {
    /// The x of ball `b`'s centre at `t`, taken into the box if the table is periodic.
    fn x(table: &Table, b: &BallState, t: f64) -> f64 {
        let p = b.traj.at(t);
        table.period.map_or(p, |period| period.wrap(p)).x
    }
}

impl World for Snapshot<'_> {
    fn table(&self) -> &Table {
        self.table
    }

    fn n_balls(&self) -> usize {
        self.balls.len()
    }

    fn ball(&self, i: u32) -> BallState {
        self.balls[i as usize]
    }

    fn for_each_neighbor(&self, i: u32, f: &mut dyn FnMut(u32)) {
        let x = Self::x(self.table, &self.balls[i as usize], self.t);
        // in a periodic box the neighbours near one side include those near the other
        let three;
        let sides: &[f64] = match &self.table.period {
            Some(b) => {
                three = [-b.size.x, 0.0, b.size.x];
                &three
            }
            None => &[0.0],
        };
        for &side in sides {
            let x = x + side;
            let from = self.by_x.partition_point(|e| e.0 < x - self.reach);
            for &(xj, j) in &self.by_x[from..] {
                if xj > x + self.reach {
                    break;
                }
                if j != i {
                    f(j);
                }
            }
        }
    }
}
