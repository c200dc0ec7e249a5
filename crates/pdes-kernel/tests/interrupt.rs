//! An interrupt ends a run early and cleanly: the run ends at a time of its choosing, with
//! every output up to that time delivered and none after it, and final states equal to those
//! of a run asked to end there, on the sequential executor and under Time Warp alike.

use pdes_kernel::sequential::Sequential;
use pdes_kernel::time_warp::threads::TimeWarp;
use pdes_kernel::time_warp::{ObjectMap, TwConfig};
use pdes_kernel::{Ctx, Envelope, Executor, Interrupt, Model, PlainTime, VTime};

const OBJECTS: u32 = 64;

/// Objects that count what they handle and pass each message on to a random object.
struct Relay;

/// An object's random stream and count.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct Count {
    rng: u64,
    handled: u64,
}

/// SplitMix64: the next word of a stream.
fn next(rng: &mut u64) -> u64 {
    *rng = rng.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *rng;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Relay {
    /// Sends one message on: mostly after a random delay, sometimes at once.
    fn forward(&self, ctx: &mut Ctx<'_, Relay>, c: &mut Count) {
        let r = next(&mut c.rng);
        let to = (r % u64::from(OBJECTS)) as u32;
        if r >> 61 == 0 {
            ctx.send_now(to, ());
        } else {
            let delay = 0.01 + ((r >> 11) as f64) / ((1u64 << 53) as f64);
            let at = ctx.now().t() + delay;
            ctx.send_at(to, VTime::at(PlainTime(at)), ());
        }
    }
}

impl Model for Relay {
    type Time = PlainTime;
    type Msg = ();
    type State = Count;
    /// The object, its count, and the time.
    type Output = (u32, u64, f64);
    type Undo = ();

    fn kind_names(&self) -> &'static [&'static str] {
        &["Pass"]
    }
    fn kind(&self, _: &()) -> usize {
        0
    }
    fn priority(&self, _: &()) -> u8 {
        0
    }
    fn init(&self, ctx: &mut Ctx<'_, Self>, _: u32, c: &mut Count) {
        for _ in 0..3 {
            self.forward(ctx, c);
        }
    }
    fn handle(&self, ctx: &mut Ctx<'_, Self>, me: u32, c: &mut Count, batch: &[Envelope<()>]) {
        for _ in batch {
            c.handled += 1;
            ctx.emit((me, c.handled, ctx.now().t()));
            self.forward(ctx, c);
        }
    }
}

fn counts() -> Vec<Count> {
    (0..u64::from(OBJECTS))
        .map(|i| Count {
            rng: i * 7919 + 1,
            handled: 0,
        })
        .collect()
}

fn executor(tw: Option<TwConfig>) -> Box<dyn Executor<Relay, ()>> {
    let start = VTime::start(0.0);
    match tw {
        None => Box::new(Sequential::new(Relay, counts(), start)),
        Some(cfg) => Box::new(TimeWarp::new(
            Relay,
            counts(),
            start,
            &ObjectMap::RoundRobin,
            cfg,
        )),
    }
}

/// A run to `until` whose sink raises an interrupt after `after` outputs (never with `None`):
/// the time it ended at, its outputs and its final states.
fn run(
    tw: Option<TwConfig>,
    until: f64,
    after: Option<usize>,
) -> (f64, Vec<(u32, u64, f64)>, Vec<Count>) {
    let mut ex = executor(tw);
    let interrupt = Interrupt::new();
    ex.stop_on(interrupt.clone());
    let mut seen = Vec::new();
    let mut sink = |_: &Relay, _: &[Count], out: (u32, u64, f64)| -> Result<(), ()> {
        seen.push(out);
        if Some(seen.len()) == after {
            interrupt.raise(2);
        }
        Ok(())
    };
    let ended = ex.run(until, &mut sink).expect("no sink error");
    let states = ex.states().to_vec();
    (ended, seen, states)
}

/// The interrupted run equals the uninterrupted one cut at the time it ended.
fn check_cut(what: &str, got: (f64, Vec<(u32, u64, f64)>, Vec<Count>), until: f64, after: usize) {
    let (ended, seen, states) = got;
    assert!(seen.len() >= after, "{what}: {} outputs", seen.len());
    assert!(
        ended < until && ended >= seen[after - 1].2,
        "{what}: ended at {ended}, the interrupt came at {}",
        seen[after - 1].2
    );
    let (whole_end, whole, _) = run(None, until, None);
    assert_eq!(whole_end, until);
    let cut: Vec<_> = whole.into_iter().filter(|o| o.2 <= ended).collect();
    assert!(
        seen == cut,
        "{what}: outputs differ from the run cut at {ended}"
    );
    let (_, _, to_there) = run(None, ended, None);
    assert!(
        states == to_there,
        "{what}: final states differ from a run to {ended}"
    );
}

#[test]
fn an_interrupted_sequential_run_ends_at_its_last_batch() {
    let (ended, seen, states) = run(None, 50.0, Some(5_000));
    assert_eq!(ended, seen[4_999].2, "it ends at the batch run last");
    check_cut("sequential", (ended, seen, states), 50.0, 5_000);
}

#[test]
fn an_interrupted_time_warp_run_ends_where_every_worker_agrees() {
    for workers in [1usize, 2, 3] {
        for chaos in [None, Some(5)] {
            let cfg = TwConfig {
                workers,
                chaos,
                gvt_interval: Some(64),
                ..Default::default()
            };
            let what = format!("{workers} workers, chaos {chaos:?}");
            let got = run(Some(cfg), 200.0, Some(5_000));
            check_cut(&what, got, 200.0, 5_000);
        }
    }
}

#[test]
fn a_run_never_interrupted_ends_at_its_end() {
    let want = run(None, 10.0, None);
    let cfg = TwConfig {
        workers: 2,
        ..Default::default()
    };
    let got = run(Some(cfg), 10.0, None);
    assert_eq!(got.0, 10.0);
    assert!(got == want, "Time Warp and sequential runs differ");
}
