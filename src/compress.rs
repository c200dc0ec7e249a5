//! Lubachevsky-Stillinger compression (Lubachevsky and Stillinger 1990): the disks of a periodic
//! box grow while they move, event-driven and exact (see [`crate::growth`]), until they cover a
//! target area fraction or jam.
//!
//! The compression runs in cycles. Each cycle is an event-list run of growing disks over the
//! state the last one left, about `cycle_collisions` collisions per disk long; after it a
//! thermostat scales every velocity so that the temperature is `kt` again (growing disks gain
//! kinetic energy at every collision), and the cycle's reduced pressure `Z = P A / (N kT)` is
//! taken from the collision virial with the cycle's mean temperature. The growth rate is the
//! smallest disk's diameter gained per unit time, in units where `kT = m = 1` (so it is the ratio
//! of the growth speed to the thermal speed `√(kT / m)`); every diameter grows in proportion, so
//! the ratios of the sizes stay those of the start.
//!
//! A packing is *jammed* once the cycle's reduced pressure passes `max_pressure` (10¹² by
//! default, as in Donev, Torquato and Stillinger 2005): the gaps between the disks of its rigid
//! network are then about `σ / Z`, and the collision rate diverges with `Z`.

use crate::check::Checker;
use crate::engine::event_list::{EventList, Options};
use crate::engine::{BallState, RunError, Span};
use crate::growth::Growth;
use crate::observe::Observables;
use crate::run::Checked;
use crate::scenario::{BallSpec, Scenario};
use pdes_kernel::Interrupt;
use std::f64::consts::PI;

/// How to compress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CompressConfig {
    /// The smallest disk's diameter gained per unit time (positive), with `kT = m = 1`.
    pub rate: f64,
    /// Stop once the disks cover this area fraction; `None`: compress until jammed.
    pub target: Option<f64>,
    /// Jammed once a cycle's reduced pressure passes this.
    pub max_pressure: f64,
    /// Ball-ball collisions per disk in a cycle, between two thermostat rescalings.
    pub cycle_collisions: f64,
    /// The temperature the thermostat restores after each cycle (and the start is scaled to).
    pub kt: f64,
    /// Check every event for overlaps (`--check`).
    pub check: bool,
}

impl Default for CompressConfig {
    fn default() -> CompressConfig {
        CompressConfig {
            rate: 0.01,
            target: None,
            max_pressure: 1e12,
            cycle_collisions: 2.0,
            kt: 1.0,
            check: false,
        }
    }
}

/// Why a compression ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ending {
    /// The disks cover the target area fraction.
    Target,
    /// A cycle's reduced pressure passed the jamming threshold.
    Jammed,
    /// The interrupt was raised: the state is the one the last event left.
    Interrupted,
}

/// One cycle's figures.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Cycle {
    /// The time at the cycle's end.
    pub t: f64,
    /// The area fraction at its end.
    pub area_fraction: f64,
    /// Its reduced pressure `P A / (N kT)` from the collision virial.
    pub z: f64,
    /// Its mean temperature, before the thermostat.
    pub kt: f64,
    /// Ball-ball collisions in it.
    pub collisions: u64,
}

/// What a compression came to.
#[derive(Clone, Debug)]
pub struct Compressed {
    /// The final configuration as a start: positions in the box, velocities at the
    /// temperature `kt`, the grown radii.
    pub scenario: Scenario,
    /// The compression's duration.
    pub t: f64,
    /// Why it ended.
    pub ending: Ending,
    /// Every whole cycle, in order.
    pub cycles: Vec<Cycle>,
}

impl Compressed {
    /// The area fraction reached.
    pub fn area_fraction(&self) -> f64 {
        area_fraction(&self.scenario)
    }

    /// The last whole cycle's reduced pressure (`NaN` if none ended).
    pub fn z(&self) -> f64 {
        self.cycles.last().map_or(f64::NAN, |c| c.z)
    }

    /// Ball-ball collisions over the whole compression's whole cycles.
    pub fn collisions(&self) -> u64 {
        self.cycles.iter().map(|c| c.collisions).sum()
    }
}

/// Why a compression cannot start.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CompressError {
    /// The start is not in a periodic box.
    #[error("compress: the start must be in a periodic box (--boundary periodic, or [box] boundary = \"periodic\")")]
    NotPeriodic,
    /// A setting is out of its range.
    #[error("compress: {flag}: {why}")]
    Setting {
        /// The flag.
        flag: &'static str,
        /// What is wrong.
        why: String,
    },
}

/// The fraction of the periodic box that the disks of `s` cover.
pub fn area_fraction(s: &Scenario) -> f64 {
    let covered: f64 = s.balls.iter().map(|b| PI * b.radius * b.radius).sum();
    let (lo, hi) = s.bounds();
    covered / ((hi.x - lo.x) * (hi.y - lo.y))
}

impl CompressConfig {
    /// Checks the settings against the start `s`.
    pub fn check(&self, s: &Scenario) -> Result<(), CompressError> {
        let bad = |flag, why: String| Err(CompressError::Setting { flag, why });
        if s.periodic.is_none() {
            return Err(CompressError::NotPeriodic);
        }
        if !(self.rate.is_finite() && self.rate > 0.0) {
            return bad(
                "--rate",
                format!("must be a positive number, got {}", self.rate),
            );
        }
        let now = area_fraction(s);
        if let Some(t) = self.target {
            if !(t.is_finite() && t > now && t < 1.0) {
                return bad(
                    "--target",
                    format!("must lie above the start's area fraction {now} and below 1, got {t}"),
                );
            }
        }
        if !(self.max_pressure.is_finite() && self.max_pressure > 1.0) {
            return bad(
                "--max-pressure",
                format!("must be a number above 1, got {}", self.max_pressure),
            );
        }
        if !(self.cycle_collisions.is_finite() && self.cycle_collisions > 0.0) {
            return bad(
                "--cycle-collisions",
                format!("must be a positive number, got {}", self.cycle_collisions),
            );
        }
        if !(self.kt.is_finite() && self.kt > 0.0) {
            return bad(
                "--temperature",
                format!("must be a positive number, got {}", self.kt),
            );
        }
        if s.balls.iter().all(|b| b.velocity.norm2() == 0.0) {
            return bad(
                "--temperature",
                "the start's disks are all at rest: the thermostat has nothing to scale".into(),
            );
        }
        Ok(())
    }
}

/// The most a cycle lets every radius grow by: the cells of its grid are laid out for the
/// grown disks, and a new cycle lays them out afresh.
const MOST_GROWTH_PER_CYCLE: f64 = 1.05;

/// Compresses `start` (a periodic box) by `cfg`, reporting each cycle to `progress`; stops early
/// when `interrupt` is raised.
pub fn compress(
    start: &Scenario,
    cfg: &CompressConfig,
    interrupt: Option<&Interrupt>,
    progress: &mut dyn FnMut(&Cycle),
) -> Result<Compressed, RunError> {
    cfg.check(start)
        .map_err(|e| RunError::Input(e.to_string()))?;
    let mut state = thermalised(start, &BallState::initial(start, 0.0), cfg.kt);
    let n = state.balls.len() as f64;
    let mut t = 0.0;
    let mut cycles = Vec::new();
    // a first guess at the cycle's length: a tenth of the smallest diameter at thermal speed
    let mut dt = 0.1 * smallest_diameter(&state) / cfg.kt.sqrt();
    let ending = loop {
        let sigma = smallest_diameter(&state);
        let growth = Growth {
            rate: cfg.rate / sigma,
            from: 0.0,
        };
        let most = dt.min((MOST_GROWTH_PER_CYCLE - 1.0) / growth.rate);
        // the time to the target, if it comes within this cycle
        let to_target = cfg
            .target
            .map(|target| ((target / area_fraction(&state)).sqrt() - 1.0) / growth.rate)
            .filter(|&to| to <= most);
        let length = to_target.unwrap_or(most);
        let (balls, reached, cycle) = run_cycle(&state, cfg, growth, length, interrupt)?;
        state = thermalised(&state, &balls, cfg.kt);
        t += reached;
        let Some(mut cycle) = cycle else {
            break Ending::Interrupted;
        };
        cycle.t = t;
        cycle.area_fraction = area_fraction(&state);
        progress(&cycle);
        cycles.push(cycle);
        if to_target.is_some() {
            break Ending::Target;
        }
        // a cycle too short to move the clock is as jammed as a pressure past the threshold
        if cycle.z >= cfg.max_pressure || t + length == t {
            break Ending::Jammed;
        }
        // aim the next cycle at its share of collisions, changing its length by at most 2x
        let want = cfg.cycle_collisions * n / 2.0;
        dt = length * (want / (cycle.collisions.max(1) as f64)).clamp(0.5, 2.0);
    };
    Ok(Compressed {
        scenario: state,
        t,
        ending,
        cycles,
    })
}

/// One cycle: the event list with growing disks over `state` for `length`. The balls at its
/// end, the time reached, and its figures (`None` if the interrupt cut it short).
fn run_cycle(
    state: &Scenario,
    cfg: &CompressConfig,
    growth: Growth,
    length: f64,
    interrupt: Option<&Interrupt>,
) -> Result<(Vec<BallState>, f64, Option<Cycle>), RunError> {
    let opts = Options {
        span: Span::default(),
        ..Options::default()
    };
    let mut engine = EventList::growing(state, opts, growth, length)?;
    if let Some(i) = interrupt {
        engine.stop_on(i.clone());
    }
    let mut observed = Observables::new(state, 0.0, 0.0, length);
    let mut sinks = Checked {
        checker: cfg
            .check
            .then(|| Checker::new(&BallState::initial(state, 0.0), false)),
        user: &mut observed,
    };
    let outcome = engine.run(length, &mut sinks)?;
    if let Some(c) = sinks.checker.as_mut() {
        c.sweep(&engine, outcome.t)?;
    }
    let whole = outcome.t >= length;
    let figures = observed.finish(outcome.t);
    let cycle = (whole && figures.blocks == 1).then(|| Cycle {
        t: 0.0,
        area_fraction: 0.0,
        z: figures.z.mean,
        kt: figures.kt.mean,
        collisions: outcome.events.get(crate::engine::EventKind::BallBall),
    });
    Ok((outcome.balls, outcome.t, cycle))
}

/// The smallest diameter among `s`'s disks.
fn smallest_diameter(s: &Scenario) -> f64 {
    2.0 * s
        .balls
        .iter()
        .map(|b| b.radius)
        .fold(f64::INFINITY, f64::min)
}

/// `template` with the disks `balls` (positions, velocities and radii at one time), every
/// velocity scaled so that the mean kinetic energy per disk is `kt`.
fn thermalised(template: &Scenario, balls: &[BallState], kt: f64) -> Scenario {
    let kinetic: f64 = balls
        .iter()
        .map(|b| 0.5 * b.mass * b.velocity().norm2())
        .sum();
    let scale = (kt * balls.len() as f64 / kinetic).sqrt();
    let mut s = template.clone();
    s.balls = balls
        .iter()
        .zip(&template.balls)
        .map(|(b, old)| BallSpec {
            colour: old.colour.clone(),
            label: old.label.clone(),
            ..BallSpec::moving(b.traj.position, scale * b.velocity(), b.radius, b.mass)
        })
        .collect();
    s
}
