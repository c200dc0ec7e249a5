//! A closed queueing network on the kernel alone: the model a PDES researcher would write first.
//!
//! ```text
//!            Arrive (after an exponential transit)
//!   station i ─────────────────────────────────────► station j (chosen at random)
//!      │  ▲
//!      └──┘ Done (to itself, after an exponential service time, while jobs wait)
//! ```
//!
//! `STATIONS` single-server stations share `JOBS` jobs that never leave. A station serves its
//! queue in arrival order; when a service ends it sends the job to a random station, which it
//! reaches after a transit delay. Every station draws from its own seeded random stream, kept in
//! its state, so the run is the same whatever executes it.
//!
//! The example runs the network on the sequential executor and on Time Warp with 2 workers,
//! prints what each did, and asserts that both end in the same states (digests equal), with the
//! same number of events. Run it with `cargo run --release -p pdes-kernel --example queueing`.

use pdes_kernel::digest::fnv_hex;
use pdes_kernel::sequential::Sequential;
use pdes_kernel::time_warp::threads::TimeWarp;
use pdes_kernel::time_warp::{ObjectMap, TwConfig};
use pdes_kernel::{Ctx, Envelope, Model, PlainTime, VTime};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use std::convert::Infallible;

/// Stations in the network.
const STATIONS: u32 = 256;
/// Jobs in the network (they start spread over the stations).
const JOBS: u32 = 2048;
/// Mean service time (time units).
const SERVICE: f64 = 1.0;
/// Mean transit time between stations (time units).
const TRANSIT: f64 = 0.5;
/// End of the run (time units).
const UNTIL: f64 = 200.0;

/// What a station receives.
#[derive(Clone, Debug, Serialize, Deserialize)]
enum Msg {
    /// A job arrives from another station (or from the start).
    Arrive,
    /// The job in service is done.
    Done,
}

/// One station: its queue and its counts.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct Station {
    rng: ChaCha8Rng,
    /// Jobs here, the one in service included.
    queue: u32,
    /// Services completed.
    served: u64,
    /// Sum over completed services of the jobs left waiting behind them (a queue-length
    /// statistic).
    waiting: u64,
}

/// The network's parameters.
struct Network;

impl Network {
    /// Exponential with mean `mean`, from the station's own stream.
    fn exp(rng: &mut ChaCha8Rng, mean: f64) -> f64 {
        let u: f64 = rng.gen_range(f64::EPSILON..1.0);
        -mean * u.ln()
    }

    /// Starts a service at station `me` now.
    fn start_service(ctx: &mut Ctx<'_, Network>, me: u32, s: &mut Station) {
        let t = ctx.now().t() + Self::exp(&mut s.rng, SERVICE);
        ctx.send_at(me, VTime::at(PlainTime(t)), Msg::Done);
    }
}

impl Model for Network {
    type Time = PlainTime;
    type Msg = Msg;
    type State = Station;
    type Output = ();
    type Undo = ();

    fn kind_names(&self) -> &'static [&'static str] {
        &["Arrive", "Done"]
    }

    fn kind(&self, m: &Msg) -> usize {
        match m {
            Msg::Arrive => 0,
            Msg::Done => 1,
        }
    }

    fn priority(&self, m: &Msg) -> u8 {
        // a service that ends as a job arrives frees the server first
        match m {
            Msg::Done => 0,
            Msg::Arrive => 1,
        }
    }

    fn init(&self, ctx: &mut Ctx<'_, Network>, me: u32, _: &mut Station) {
        // job k starts at station k mod STATIONS
        for _ in (me..JOBS).step_by(STATIONS as usize) {
            ctx.send_now(me, Msg::Arrive);
        }
    }

    fn handle(
        &self,
        ctx: &mut Ctx<'_, Network>,
        me: u32,
        s: &mut Station,
        batch: &[Envelope<Msg>],
    ) {
        for e in batch {
            match e.msg {
                Msg::Done => {
                    s.queue -= 1;
                    s.served += 1;
                    s.waiting += u64::from(s.queue);
                    let to = s.rng.gen_range(0..STATIONS);
                    let t = ctx.now().t() + Self::exp(&mut s.rng, TRANSIT);
                    ctx.send_at(to, VTime::at(PlainTime(t)), Msg::Arrive);
                    if s.queue > 0 {
                        Self::start_service(ctx, me, s);
                    }
                }
                Msg::Arrive => {
                    s.queue += 1;
                    if s.queue == 1 {
                        Self::start_service(ctx, me, s);
                    }
                }
            }
        }
    }
}

/// Every station at the start.
fn stations() -> Vec<Station> {
    (0..STATIONS)
        .map(|i| Station {
            rng: ChaCha8Rng::seed_from_u64(
                0x5eed ^ u64::from(i).wrapping_mul(0x9e37_79b9_7f4a_7c15),
            ),
            queue: 0,
            served: 0,
            waiting: 0,
        })
        .collect()
}

/// A digest of the stations' states: equal digests, equal runs.
fn digest(states: &[Station]) -> String {
    fnv_hex(states.iter().flat_map(|s| {
        [
            u64::from(s.queue),
            s.served,
            s.waiting,
            s.rng.get_word_pos() as u64,
        ]
    }))
}

fn main() {
    let never = |_: &Network, _: &[Station], _: ()| -> Result<(), Infallible> { Ok(()) };

    let clock = std::time::Instant::now();
    let mut seq = Sequential::new(Network, stations(), VTime::start(0.0));
    let Ok(_) = seq.run(UNTIL, &mut { never });
    let seq_seconds = clock.elapsed().as_secs_f64();
    let (seq_digest, seq_events) = (digest(seq.states()), seq.stats().delivered);

    let clock = std::time::Instant::now();
    let cfg = TwConfig {
        workers: 2,
        ..TwConfig::default()
    };
    let map = ObjectMap::Block;
    let mut tw = TimeWarp::new(Network, stations(), VTime::start(0.0), &map, cfg);
    if tw.run(UNTIL, &mut { never }).is_err() {
        panic!("Time Warp failed");
    }
    let tw_seconds = clock.elapsed().as_secs_f64();
    let (tw_digest, tw_events) = (digest(tw.states()), tw.stats().delivered);
    let stats = tw.tw_stats();
    tw.free();

    let served: u64 = seq.states().iter().map(|s| s.served).sum();
    let waiting: u64 = seq.states().iter().map(|s| s.waiting).sum();
    println!(
        "{STATIONS} stations, {JOBS} jobs, to t = {UNTIL}: {served} services, \
         {:.2} jobs waiting behind a finished service on average",
        waiting as f64 / served.max(1) as f64
    );
    println!("sequential:         {seq_events} events in {seq_seconds:.3} s, digest {seq_digest}");
    println!(
        "Time Warp, 2 workers: {tw_events} events in {tw_seconds:.3} s, digest {tw_digest} \
         (efficiency {:.2}, {} rollbacks)",
        stats.efficiency(),
        stats.rollbacks
    );
    assert_eq!(
        seq_digest, tw_digest,
        "Time Warp ends in the sequential run's states"
    );
    assert_eq!(seq_events, tw_events, "and runs the same events");
    assert!(served > u64::from(JOBS), "the jobs circulate");
}
