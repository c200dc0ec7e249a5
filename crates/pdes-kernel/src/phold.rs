//! PHOLD, the standard synthetic benchmark of parallel discrete-event simulators (Fujimoto 1990;
//! ROSS's `models/phold`), as a kernel model.
//!
//! ```text
//!   object i ──(one message per event, after lookahead + Exp(mean))──► object j
//!            j in another partition with probability `remote`, else in i's own
//! ```
//!
//! Each of `objects` objects starts with `events_per_object` messages to itself. Handling a
//! message sends exactly one new one, so the message population stays constant. Every object
//! draws from its own seeded random stream, kept in its state, so a run is the same whatever
//! executes it. The stream is a 128-bit PCG (O'Neill 2014): an object's state is 32 bytes, in
//! the range of ROSS's and ROOT-Sim's PHOLD objects, so that saving one costs what it costs
//! them.

use crate::conservative::{Conservative, ConservativeConfig, ConservativeStats, Refused};
use crate::digest::fnv_hex;
use crate::sequential::Sequential;
use crate::time_warp::threads::TimeWarp;
use crate::time_warp::{ObjectMap, RoundRecord, TwConfig, TwStats};
use crate::{Ctx, Envelope, ExecError, Executor, Model, PlainTime, VTime};
use rand::{Rng, RngCore, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::convert::Infallible;

/// PHOLD's parameters.
#[derive(Clone, Debug)]
pub struct PholdConfig {
    /// Number of objects.
    pub objects: u32,
    /// Messages each object starts with.
    pub events_per_object: u32,
    /// Probability that a message goes to another partition.
    pub remote: f64,
    /// Number of partitions (the workers of a parallel run), objects split in equal blocks.
    pub partitions: u32,
    /// Minimum delay of every message.
    pub lookahead: f64,
    /// Mean of the exponential part of the delay.
    pub mean: f64,
    /// Seed of every object's random stream.
    pub seed: u64,
}

/// One PHOLD object: its random stream and its counts.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct PholdState {
    rng: Pcg64Mcg,
    sends: u64,
    /// Messages handled.
    pub handled: u64,
}

/// The PHOLD model.
pub struct Phold {
    cfg: PholdConfig,
}

impl Phold {
    /// The model and every object's initial state.
    pub fn new(cfg: PholdConfig) -> (Phold, Vec<PholdState>) {
        let states = (0..cfg.objects)
            .map(|i| PholdState {
                rng: Pcg64Mcg::seed_from_u64(
                    cfg.seed ^ (u64::from(i) << 20).wrapping_mul(0x9e37_79b9),
                ),
                sends: 0,
                handled: 0,
            })
            .collect();
        (Phold { cfg }, states)
    }

    /// The partition of object `i`.
    pub fn partition(&self, i: u32) -> u32 {
        (u64::from(i) * u64::from(self.cfg.partitions) / u64::from(self.cfg.objects)) as u32
    }

    /// The objects of partition `p`: a contiguous block.
    fn block(&self, p: u32) -> (u32, u32) {
        let n = u64::from(self.cfg.objects);
        let k = u64::from(self.cfg.partitions);
        let lo = (u64::from(p) * n).div_ceil(k) as u32;
        let hi = ((u64::from(p) + 1) * n).div_ceil(k) as u32;
        (lo, hi)
    }

    /// Draws the receiver and delay of one message from object `me`.
    fn draw(&self, me: u32, rng: &mut Pcg64Mcg) -> (u32, f64) {
        let own = self.partition(me);
        let p = if self.cfg.partitions > 1 && rng.gen_bool(self.cfg.remote.clamp(0.0, 1.0)) {
            let other = rng.gen_range(0..self.cfg.partitions - 1);
            if other >= own {
                other + 1
            } else {
                other
            }
        } else {
            own
        };
        let (lo, hi) = self.block(p);
        let to = rng.gen_range(lo..hi.max(lo + 1));
        let u: f64 = rng.gen_range(f64::EPSILON..1.0);
        (to, self.cfg.lookahead - self.cfg.mean * u.ln())
    }

    fn send(&self, ctx: &mut Ctx<'_, Phold>, me: u32, state: &mut PholdState) {
        let (to, delay) = self.draw(me, &mut state.rng);
        state.sends += 1;
        let t = ctx.now().t() + delay;
        // never cancelled: a relay, which Time Warp need not look up among cancellations
        ctx.relay_at(to, VTime::at(PlainTime(t)), ());
    }
}

impl Model for Phold {
    type Time = PlainTime;
    type Msg = ();
    type State = PholdState;
    type Output = ();
    type Undo = ();

    fn kind_names(&self) -> &'static [&'static str] {
        &["Event"]
    }

    fn kind(&self, _: &()) -> usize {
        0
    }

    fn priority(&self, _: &()) -> u8 {
        0
    }

    fn observed(&self, _: u32) -> bool {
        false
    }

    fn lookahead(&self) -> f64 {
        self.cfg.lookahead
    }

    fn init(&self, ctx: &mut Ctx<'_, Phold>, me: u32, state: &mut PholdState) {
        for _ in 0..self.cfg.events_per_object {
            self.send(ctx, me, state);
        }
    }

    fn handle(
        &self,
        ctx: &mut Ctx<'_, Phold>,
        me: u32,
        state: &mut PholdState,
        batch: &[Envelope<()>],
    ) {
        for _ in batch {
            state.handled += 1;
            self.send(ctx, me, state);
        }
    }
}

/// ROSS's published PHOLD record per core, in committed events per second: 504 billion events
/// per second on 1,966,080 Blue Gene/Q cores (Barnes, Carothers, Jefferson and LaPre, "Warp
/// speed: executing Time Warp on 1,966,080 cores", PADS 2013), the reference that PHOLD figures
/// are set beside.
pub const ROSS_EVENTS_PER_SECOND_PER_CORE: f64 = 504e9 / 1_966_080.0;

/// What a PHOLD run did.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PholdReport {
    /// Objects.
    pub objects: u32,
    /// Messages each object started with.
    pub events_per_object: u32,
    /// Remote probability.
    pub remote: f64,
    /// Partitions.
    pub partitions: u32,
    /// End time.
    pub end: f64,
    /// Executor: `objects` (sequential), `time-warp` or `conservative`.
    pub engine: &'static str,
    /// Events (messages handled) committed.
    pub committed: u64,
    /// Seconds spent running (setup included).
    pub wall_seconds: f64,
    /// Committed events per second.
    pub events_per_second: f64,
    /// Committed events per second per core: over every worker of every rank under Time Warp,
    /// over the one thread of the sequential kernel (set beside
    /// [`ROSS_EVENTS_PER_SECOND_PER_CORE`]).
    pub events_per_second_per_core: f64,
    /// Hash of every object's final counts and random stream position: equal digests, equal runs.
    pub final_state_digest: String,
    /// Time Warp's statistics, under Time Warp.
    pub time_warp: Option<TwStats>,
    /// The conservative executor's statistics, under it.
    pub conservative: Option<ConservativeStats>,
    /// Seconds the sequential kernel took for the same model in the same invocation, when the
    /// caller ran it as a baseline ([`PholdReport::against`]).
    pub sequential_wall_seconds: Option<f64>,
    /// The sequential kernel's time over this run's: the speed-up of a parallel run.
    pub speedup: Option<f64>,
    /// Time Warp's record of every GVT round, when [`TwConfig::record_rounds`] asked for it
    /// (not part of the JSON report).
    #[serde(skip)]
    pub rounds: Vec<RoundRecord>,
}

impl PholdReport {
    /// This report with its speed-up over `sequential`, a run of the same model on the
    /// sequential kernel.
    pub fn against(mut self, sequential: &PholdReport) -> PholdReport {
        self.sequential_wall_seconds = Some(sequential.wall_seconds);
        self.speedup = Some(sequential.wall_seconds / self.wall_seconds.max(1e-9));
        self
    }
}

/// Why a PHOLD run failed.
#[derive(Debug, thiserror::Error)]
pub enum PholdError {
    /// The executor failed (Time Warp out of its memory budget).
    #[error(transparent)]
    Exec(#[from] ExecError<Infallible>),
    /// The conservative executor refused the model (no lookahead).
    #[error(transparent)]
    Refused(#[from] Refused),
}

/// Which executor runs PHOLD, and how a parallel one places the objects on its workers
/// ([`ObjectMap::Block`] puts each partition on one worker when the partitions match the
/// workers).
#[derive(Clone, Debug)]
pub enum PholdExecutor {
    /// The sequential kernel.
    Sequential,
    /// Time Warp.
    TimeWarp(TwConfig, ObjectMap),
    /// The conservative executor (refused at lookahead 0).
    Conservative(ConservativeConfig, ObjectMap),
}

/// Runs PHOLD up to time `end`, sequentially or (with `tw`) under Time Warp, one partition per
/// worker when the partitions match the workers. Fails only when Time Warp does (its memory
/// budget).
pub fn run(cfg: PholdConfig, end: f64, tw: Option<TwConfig>) -> Result<PholdReport, PholdError> {
    let executor = match tw {
        None => PholdExecutor::Sequential,
        Some(c) => PholdExecutor::TimeWarp(c, ObjectMap::Block),
    };
    run_with(cfg, end, executor)
}

/// Runs PHOLD up to time `end` on `executor`.
pub fn run_with(
    cfg: PholdConfig,
    end: f64,
    executor: PholdExecutor,
) -> Result<PholdReport, PholdError> {
    let start = std::time::Instant::now();
    let (objects, events_per_object, remote, partitions) = (
        cfg.objects,
        cfg.events_per_object,
        cfg.remote,
        cfg.partitions,
    );
    let (model, states) = Phold::new(cfg);
    let t0 = VTime::start(0.0);
    let never = |_: &Phold, _: &[PholdState], _: ()| -> Result<(), Infallible> { Ok(()) };
    let (mut ex, engine): (Box<dyn Executor<Phold, Infallible>>, _) = match executor {
        PholdExecutor::Sequential => (Box::new(Sequential::new(model, states, t0)), "objects"),
        PholdExecutor::TimeWarp(c, map) => (
            Box::new(TimeWarp::new(model, states, t0, &map, c)),
            "time-warp",
        ),
        PholdExecutor::Conservative(c, map) => (
            Box::new(Conservative::new(model, states, t0, &map, c)?),
            "conservative",
        ),
    };
    ex.run(end, &mut { never })?;
    let (stats, finals, time_warp) = (ex.stats().clone(), ex.states().to_vec(), ex.tw_stats());
    let conservative = ex.conservative_stats();
    let rounds = ex.round_records().to_vec();
    ex.free();
    let wall = start.elapsed().as_secs_f64();
    let committed = stats.delivered;
    let events_per_second = committed as f64 / wall.max(1e-9);
    let cores = match (&time_warp, &conservative) {
        (Some(t), _) => t.workers.max(1),
        (_, Some(c)) => c.workers.max(1) as u64,
        _ => 1,
    };
    Ok(PholdReport {
        objects,
        events_per_object,
        remote,
        partitions,
        end,
        engine,
        committed,
        wall_seconds: wall,
        events_per_second,
        events_per_second_per_core: events_per_second / cores as f64,
        final_state_digest: fnv_hex(
            finals
                .iter()
                .flat_map(|s| [s.handled, s.sends, s.rng.clone().next_u64()]),
        ),
        time_warp,
        conservative,
        sequential_wall_seconds: None,
        speedup: None,
        rounds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg(partitions: u32, remote: f64) -> PholdConfig {
        PholdConfig {
            objects: 64,
            events_per_object: 4,
            remote,
            partitions,
            lookahead: 0.1,
            mean: 1.0,
            seed: 5,
        }
    }

    fn run(c: PholdConfig, end: f64) -> (u64, Vec<u64>, usize) {
        let (model, states) = Phold::new(c);
        let mut ex = Sequential::new(model, states, VTime::start(0.0));
        ex.run::<()>(end, &mut |_, _, _| Ok(())).unwrap();
        let handled: Vec<u64> = ex.states().iter().map(|s| s.handled).collect();
        (ex.stats().delivered, handled, ex.pending_len())
    }

    #[test]
    fn population_is_constant_and_runs_repeat() {
        let (delivered, handled, pending) = run(cfg(4, 0.5), 20.0);
        assert_eq!(pending, 64 * 4, "one message sent per message handled");
        assert_eq!(delivered, handled.iter().sum::<u64>());
        // about objects * events / mean-delay * end events
        assert!(
            delivered > 64 * 4 * 10 && delivered < 64 * 4 * 25,
            "{delivered}"
        );
        assert_eq!(run(cfg(4, 0.5), 20.0).1, handled);
    }

    #[test]
    fn remote_fraction_is_respected() {
        let (model, _) = Phold::new(cfg(4, 0.25));
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        let n = 20_000;
        let remote = (0..n)
            .filter(|_| {
                let (to, d) = model.draw(3, &mut rng);
                assert!(d >= 0.1);
                model.partition(to) != model.partition(3)
            })
            .count();
        let frac = remote as f64 / f64::from(n);
        assert!((frac - 0.25).abs() < 0.02, "{frac}");
        // one partition: nothing is remote
        let (model, _) = Phold::new(cfg(1, 0.9));
        assert!((0..1000).all(|_| model.partition(model.draw(3, &mut rng).0) == 0));
    }

    /// A PHOLD that promises more lookahead than its delays keep.
    struct Hasty(Phold);

    impl Model for Hasty {
        type Time = PlainTime;
        type Msg = ();
        type State = PholdState;
        type Output = ();
        type Undo = ();
        fn kind_names(&self) -> &'static [&'static str] {
            self.0.kind_names()
        }
        fn kind(&self, m: &()) -> usize {
            self.0.kind(m)
        }
        fn priority(&self, m: &()) -> u8 {
            self.0.priority(m)
        }
        fn lookahead(&self) -> f64 {
            2.0
        }
        fn init(&self, ctx: &mut Ctx<'_, Hasty>, _: u32, _: &mut PholdState) {
            let at = VTime::at(PlainTime(ctx.now().t() + 1.0));
            ctx.relay_at(0, at, ());
        }
        fn handle(&self, _: &mut Ctx<'_, Hasty>, _: u32, _: &mut PholdState, _: &[Envelope<()>]) {}
    }

    #[test]
    #[should_panic(expected = "sooner than the model's lookahead 2")]
    fn a_send_sooner_than_the_lookahead_is_a_model_bug() {
        let (model, states) = Phold::new(cfg(1, 0.0));
        let _ = Sequential::new(Hasty(model), states, VTime::start(0.0));
    }
}

#[cfg(test)]
mod time_warp_tests {
    use super::*;

    fn cfg(partitions: u32) -> PholdConfig {
        PholdConfig {
            objects: 96,
            events_per_object: 4,
            remote: 0.3,
            partitions,
            lookahead: 0.0,
            mean: 1.0,
            seed: 11,
        }
    }

    #[test]
    fn time_warp_commits_the_sequential_run() {
        for (workers, lookahead) in [(1usize, 0.0), (2, 0.0), (3, 0.0), (2, 0.3), (3, 0.3)] {
            for chaos in [None, Some(7)] {
                let c = PholdConfig {
                    lookahead,
                    ..cfg(workers as u32)
                };
                let (model, states) = Phold::new(c.clone());
                let mut seq = Sequential::new(model, states, VTime::start(0.0));
                seq.run::<()>(30.0, &mut |_, _, _| Ok(())).unwrap();
                let (model, states) = Phold::new(c);
                let worker_of: Vec<u32> = (0..96).map(|o| model.partition(o)).collect();
                let tw_cfg = TwConfig {
                    workers,
                    chaos,
                    gvt_interval: Some(64),
                    ..Default::default()
                };
                let mut tw = TimeWarp::new(
                    model,
                    states,
                    VTime::start(0.0),
                    &ObjectMap::Given(worker_of),
                    tw_cfg,
                );
                tw.run::<()>(30.0, &mut |_, _, _| Ok(())).unwrap();
                let a: Vec<(u64, u64)> =
                    seq.states().iter().map(|s| (s.handled, s.sends)).collect();
                let b: Vec<(u64, u64)> = tw.states().iter().map(|s| (s.handled, s.sends)).collect();
                let what = format!("workers {workers} lookahead {lookahead} chaos {chaos:?}");
                assert_eq!(a, b, "{what}");
                assert_eq!(seq.stats(), tw.stats(), "{what}");
                let st = tw.tw_stats();
                assert_eq!(st.committed, seq.stats().batches);
                eprintln!("workers {workers} chaos {chaos:?}: {st:?}");
            }
        }
    }
}
