//! The runs: each gas once on the event-list engine (its physics) and once per setting on the
//! objects engine (its messages), indexed by number of balls and setting.

use super::{settings, ExperimentError, Plan, Progress, Setting, RADIUS, SPEED_MAX};
use crate::engine::{Event, EventKind, Ignore, Observer, RunError, World};
use crate::model::pool::NvDelay;
use crate::run::{execute, EngineKind, FixedNews, RunConfig, SectorChoice};
use crate::scenario::builtin::{self, Params};
use crate::scenario::Scenario;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// One objects-engine run.
#[derive(Clone, Debug, Serialize)]
pub struct RunRecord {
    /// Number of balls.
    pub balls: usize,
    /// Scenario seed.
    pub seed: u64,
    /// `none` or `KxK`.
    pub setting: String,
    /// Sectors per side (none for the non-sectored engine).
    pub sectors_per_side: Option<u32>,
    /// Mean balls per sector, `N / k²`.
    pub balls_per_sector: Option<f64>,
    /// Messages sent by type, and `total`: the six types the thesis counts.
    pub messages: BTreeMap<String, u64>,
    /// Wall-clock seconds of the run (setup included): the median of the plan's repetitions.
    pub wall_seconds: f64,
    /// Physical events executed.
    pub events: u64,
    /// Hash of the final state (equal digests: bit-identical final states).
    pub digest: String,
}

impl RunRecord {
    /// The total of the six message types the thesis counts.
    pub(super) fn total(&self) -> f64 {
        self.msg("total")
    }

    /// Messages of one type (or `total`), 0 if none were sent.
    pub(super) fn msg(&self, name: &str) -> f64 {
        self.messages.get(name).copied().unwrap_or(0) as f64
    }
}

/// The physics of one gas, from the event-list engine (the same for every engine).
#[derive(Clone, Debug, Serialize)]
pub struct PhysicsRecord {
    /// Number of balls.
    pub balls: usize,
    /// Scenario seed.
    pub seed: u64,
    /// Table side (length units).
    pub table_side: f64,
    /// Total free path: Σ over balls of speed × time, between time 0 and the end (length).
    pub free_path: f64,
    /// Ball–ball collisions.
    pub ball_ball: u64,
    /// Ball–cushion bounces.
    pub ball_cushion: u64,
    /// Ball velocity changes: two per ball–ball collision, one per bounce.
    pub velocity_changes: u64,
    /// The event-list engine's final-state digest.
    pub digest: String,
}

/// Adds up the free path of every ball from the events and the world state after each.
struct FreePath {
    /// Per ball: the speed since its last change, and that change's time.
    last: Vec<(f64, f64)>,
    path: f64,
    ball_ball: u64,
    ball_cushion: u64,
    changes: u64,
}

impl FreePath {
    fn new(s: &Scenario) -> FreePath {
        FreePath {
            last: s.balls.iter().map(|b| (b.velocity.norm(), 0.0)).collect(),
            path: 0.0,
            ball_ball: 0,
            ball_cushion: 0,
            changes: 0,
        }
    }

    fn advance(&mut self, i: u32, t: f64, world: &dyn World) {
        let (v, t0) = self.last[i as usize];
        self.path += v * (t - t0);
        self.last[i as usize] = (world.ball(i).velocity().norm(), t);
    }

    /// The path up to `until`.
    fn finish(&self, until: f64) -> f64 {
        self.path
            + self
                .last
                .iter()
                .map(|&(v, t0)| v * (until - t0))
                .sum::<f64>()
    }
}

impl Observer for FreePath {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        self.advance(ev.a, ev.t, world);
        self.changes += 1;
        match ev.kind {
            EventKind::BallBall => {
                self.advance(ev.b, ev.t, world);
                self.ball_ball += 1;
                self.changes += 1;
            }
            EventKind::BallCushion => self.ball_cushion += 1,
            EventKind::BallCorner | EventKind::BallPocket => {}
        }
        Ok(())
    }
}

/// The thesis gas of `n` balls with this seed.
fn gas(n: usize, seed: u64) -> Result<Scenario, ExperimentError> {
    builtin::build(
        "gas",
        &Params {
            balls: Some(n),
            seed: Some(seed),
            radius: Some(RADIUS),
            speed_max: Some(SPEED_MAX),
            ..Params::default()
        },
    )
    .map_err(|invalid| ExperimentError::Gas {
        balls: n,
        seed,
        invalid,
    })
}

/// Runs one gas with the event-list engine, measuring its physics.
fn physics(
    s: &Scenario,
    n: usize,
    seed: u64,
    until: f64,
) -> Result<PhysicsRecord, ExperimentError> {
    let mut fp = FreePath::new(s);
    let cfg = RunConfig {
        engine: EngineKind::EventList,
        until,
        check: false,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let report = execute(s, &cfg, &mut fp).map_err(|source| ExperimentError::Physics {
        balls: n,
        seed,
        source,
    })?;
    let (lo, hi) = s.bounds();
    Ok(PhysicsRecord {
        balls: n,
        seed,
        table_side: hi.x - lo.x,
        free_path: fp.finish(until),
        ball_ball: fp.ball_ball,
        ball_cushion: fp.ball_cushion,
        velocity_changes: fp.changes,
        digest: report.summary.final_state_digest.clone(),
    })
}

/// Runs one gas with the objects engine in one setting.
fn objects(
    s: &Scenario,
    n: usize,
    seed: u64,
    setting: Setting,
    until: f64,
    repeats: u32,
) -> Result<RunRecord, ExperimentError> {
    let engine = match setting {
        Setting::NoSectors => EngineKind::Objects {
            delay: NvDelay::Exact,
        },
        // the thesis' message counts: every ball tells every fixed object
        Setting::Grid(k) => EngineKind::Sectored {
            sectors: SectorChoice::Grid(k, k),
            news: FixedNews::Thesis,
        },
    };
    let cfg = RunConfig {
        engine,
        until,
        check: false,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let fail = |source: RunError| ExperimentError::Objects {
        balls: n,
        seed,
        setting: setting.name(),
        source,
    };
    let report = execute(s, &cfg, &mut Ignore).map_err(fail)?;
    let mut walls = vec![report.wall_seconds];
    for _ in 1..repeats.max(1) {
        let again = execute(s, &cfg, &mut Ignore).map_err(fail)?;
        if again.summary.messages != report.summary.messages {
            return Err(ExperimentError::Unrepeatable {
                balls: n,
                seed,
                setting: setting.name(),
            });
        }
        walls.push(again.wall_seconds);
    }
    walls.sort_by(f64::total_cmp);
    let wall = walls[walls.len() / 2];
    let messages = report.summary.messages.by_name();
    Ok(RunRecord {
        balls: n,
        seed,
        setting: setting.name(),
        sectors_per_side: setting.per_side(),
        balls_per_sector: setting.per_side().map(|k| n as f64 / (k * k) as f64),
        messages,
        wall_seconds: wall,
        events: report.outcome.events.total(),
        digest: report.summary.final_state_digest.clone(),
    })
}

/// Mean, sample standard deviation and range of a few numbers.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Stat {
    /// How many numbers.
    pub n: usize,
    /// Their mean.
    pub mean: f64,
    /// Their sample standard deviation (`n − 1`); `None` for fewer than two.
    pub sd: Option<f64>,
    /// The smallest.
    pub min: f64,
    /// The largest.
    pub max: f64,
}

impl Stat {
    /// The statistics of `xs`.
    pub fn of(xs: &[f64]) -> Stat {
        let n = xs.len();
        if n == 0 {
            return Stat::default();
        }
        let mean = xs.iter().sum::<f64>() / n as f64;
        let sd = (n > 1).then(|| {
            (xs.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1) as f64).sqrt()
        });
        Stat {
            n,
            mean,
            sd,
            min: xs.iter().copied().fold(f64::INFINITY, f64::min),
            max: xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        }
    }

    /// `mean ± sd`, rounded to whole numbers.
    pub(super) fn pm(&self) -> String {
        match self.sd {
            Some(sd) => format!("{:.0} ± {:.0}", self.mean, sd),
            None => format!("{:.0}", self.mean),
        }
    }
}

/// Everything the experiment measured, indexed.
pub(super) struct Data {
    pub(super) plan: Plan,
    pub(super) runs: Vec<RunRecord>,
    pub(super) physics: Vec<PhysicsRecord>,
    /// `(balls, setting)` → indices into `runs`, by seed.
    pub(super) cells: BTreeMap<(usize, Setting), Vec<usize>>,
    pub(super) mismatches: Vec<String>,
    pub(super) wall_total: f64,
}

impl Data {
    /// The runs of a cell, by seed.
    pub(super) fn cell(&self, n: usize, s: Setting) -> Vec<&RunRecord> {
        self.cells
            .get(&(n, s))
            .map(|v| v.iter().map(|&i| &self.runs[i]).collect())
            .unwrap_or_default()
    }

    /// Statistics of `f` over the seeds of a cell.
    pub(super) fn stat(&self, n: usize, s: Setting, f: impl Fn(&RunRecord) -> f64) -> Option<Stat> {
        let xs: Vec<f64> = self.cell(n, s).into_iter().map(f).collect();
        (!xs.is_empty()).then(|| Stat::of(&xs))
    }

    /// Statistics of the total messages over the seeds of a cell.
    pub(super) fn total(&self, n: usize, s: Setting) -> Option<Stat> {
        self.stat(n, s, RunRecord::total)
    }

    /// The physics of the gases of `n` balls, by seed.
    pub(super) fn phys(&self, n: usize) -> Vec<&PhysicsRecord> {
        self.physics.iter().filter(|p| p.balls == n).collect()
    }

    /// Statistics of `f` over the physics of the gases of `n` balls.
    pub(super) fn phys_stat(&self, n: usize, f: impl Fn(&PhysicsRecord) -> f64) -> Stat {
        let xs: Vec<f64> = self.phys(n).into_iter().map(f).collect();
        Stat::of(&xs)
    }

    /// The number of balls tables 8 and 9 describe: 36 if run, else the largest.
    pub(super) fn focus(&self) -> usize {
        if self.plan.balls.contains(&36) {
            36
        } else {
            *self.plan.balls.last().expect("a plan has balls")
        }
    }

    /// The sectored setting with the fewest mean messages for `n`, with its mean.
    pub(super) fn best_sectored(&self, n: usize) -> Option<(Setting, f64)> {
        settings(n)
            .into_iter()
            .filter(|s| *s != Setting::NoSectors)
            .filter_map(|s| self.total(n, s).map(|t| (s, t.mean)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// `V T` in table widths (mean free path per ball over the table side) and `m` (velocity
    /// changes), averaged over seeds: the chapter 7 parameters of our gas of `n` balls.
    pub(super) fn model_params(&self, n: usize) -> (f64, f64) {
        let ph = self.phys(n);
        if ph.is_empty() {
            return (0.0, 0.0);
        }
        let k = ph.len() as f64;
        let vt = ph
            .iter()
            .map(|p| p.free_path / n as f64 / p.table_side)
            .sum::<f64>()
            / k;
        let m = ph.iter().map(|p| p.velocity_changes as f64).sum::<f64>() / k;
        (vt, m)
    }
}

/// Runs every cell of the plan, telling `progress` how far it has come.
pub(super) fn measure(
    plan: &Plan,
    progress: &mut dyn FnMut(Progress),
) -> Result<Data, ExperimentError> {
    let start = Instant::now();
    let total: u64 = plan
        .balls
        .iter()
        .map(|&n| (settings(n).len() as u64 + 1) * plan.seeds)
        .sum();
    progress(Progress::Start(total));
    let mut runs = Vec::new();
    let mut physics_runs = Vec::new();
    let mut cells: BTreeMap<(usize, Setting), Vec<usize>> = BTreeMap::new();
    let mut mismatches = Vec::new();
    for &n in &plan.balls {
        for seed in 1..=plan.seeds {
            let s = gas(n, seed)?;
            progress(Progress::Cell { balls: n, seed });
            let ph = physics(&s, n, seed, plan.until)?;
            progress(Progress::RunDone);
            for setting in settings(n) {
                let r = objects(&s, n, seed, setting, plan.until, plan.timing_repeats)?;
                if r.digest != ph.digest {
                    mismatches.push(format!(
                        "{n} balls, seed {seed}, sectors {}: final state {} differs from the \
                         event-list engine's {}",
                        setting.name(),
                        r.digest,
                        ph.digest
                    ));
                }
                cells.entry((n, setting)).or_default().push(runs.len());
                runs.push(r);
                progress(Progress::RunDone);
            }
            physics_runs.push(ph);
        }
    }
    progress(Progress::Finished);
    Ok(Data {
        plan: plan.clone(),
        runs,
        physics: physics_runs,
        cells,
        mismatches,
        wall_total: start.elapsed().as_secs_f64(),
    })
}
