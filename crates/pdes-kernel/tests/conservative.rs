//! The conservative executor commits the sequential executor's run: the same outputs in the same
//! order, each with the states just after its batch, the same final states and message counts,
//! on any number of workers and placements, with chaos too; it ends cleanly on an interrupt,
//! refuses a model without lookahead, and stops a model that breaks its rule with an error.

use pdes_kernel::conservative::{Conservative, ConservativeConfig, Refused};
use pdes_kernel::sequential::Sequential;
use pdes_kernel::time_warp::ObjectMap;
use pdes_kernel::{Ctx, Envelope, ExecError, Executor, Handle, Interrupt, Model, PlainTime, VTime};

const OBJECTS: u32 = 48;
const LOOKAHEAD: f64 = 0.25;

/// Objects that pass tokens on after the lookahead plus a whole number of quarters (so that
/// many arrive together), and keep a reminder at another object that they often retract.
struct Tokens {
    /// A lookahead the model declares (0 to be refused).
    lookahead: f64,
    /// Whether reminders are retracted too late for the conservative rule (a model bug there).
    hasty: bool,
}

/// An object's random stream, counts, and its reminder still to come.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct Desk {
    rng: u64,
    handled: u64,
    tokens: u64,
    reminder: Option<Handle>,
}

/// SplitMix64: the next word of a stream.
fn next(rng: &mut u64) -> u64 {
    *rng = rng.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *rng;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Tokens {
    fn at(&self, ctx: &Ctx<'_, Tokens>, quarters: u64) -> VTime<PlainTime> {
        VTime::at(PlainTime(
            ctx.now().t() + LOOKAHEAD + 0.25 * quarters as f64,
        ))
    }

    /// Passes a token on, and now and then (not at the start) moves the reminder.
    fn pass(&self, ctx: &mut Ctx<'_, Tokens>, d: &mut Desk, remind: bool) {
        let r = next(&mut d.rng);
        let to = (r % u64::from(OBJECTS)) as u32;
        let token = self.at(ctx, (r >> 8) % 8);
        ctx.relay_at(to, token, 1);
        if remind && (r >> 20).is_multiple_of(3) {
            if let Some(h) = d.reminder.take() {
                let soon = h.t < ctx.now().t() + LOOKAHEAD;
                if !soon || self.hasty {
                    ctx.cancel(h);
                }
            }
            let other = ((r >> 32) % u64::from(OBJECTS)) as u32;
            let when = self.at(ctx, 1 + (r >> 40) % 12);
            d.reminder = Some(ctx.send_at(other, when, 0));
        }
    }
}

impl Model for Tokens {
    type Time = PlainTime;
    type Msg = u8;
    type State = Desk;
    /// The object, its counts, and the time.
    type Output = (u32, u64, u64, f64);
    type Undo = ();

    fn kind_names(&self) -> &'static [&'static str] {
        &["Reminder", "Token"]
    }
    fn kind(&self, m: &u8) -> usize {
        usize::from(*m)
    }
    fn priority(&self, m: &u8) -> u8 {
        *m
    }
    fn observed(&self, obj: u32) -> bool {
        !obj.is_multiple_of(3)
    }
    fn lookahead(&self) -> f64 {
        self.lookahead
    }
    fn init(&self, ctx: &mut Ctx<'_, Self>, _: u32, d: &mut Desk) {
        for _ in 0..3 {
            self.pass(ctx, d, false);
        }
    }
    fn handle(&self, ctx: &mut Ctx<'_, Self>, me: u32, d: &mut Desk, batch: &[Envelope<u8>]) {
        for m in batch {
            d.handled += 1;
            if m.msg == 1 {
                d.tokens += 1;
                self.pass(ctx, d, true);
            }
        }
        ctx.emit((me, d.handled, d.tokens, ctx.now().t()));
    }
}

fn desks() -> Vec<Desk> {
    (0..u64::from(OBJECTS))
        .map(|i| Desk {
            rng: i * 104_729 + 3,
            handled: 0,
            tokens: 0,
            reminder: None,
        })
        .collect()
}

type Out = (u32, u64, u64, f64);

/// A run to `until` in two stretches, its sink checking that every observed object's state
/// matches the output of its batch; an interrupt is raised after `after` outputs. Returns the
/// end, the outputs, the final states and the message counts.
fn run(
    mut ex: Box<dyn Executor<Tokens, String>>,
    until: f64,
    after: Option<usize>,
) -> (f64, Vec<Out>, Vec<Desk>, pdes_kernel::MessageStats) {
    let interrupt = Interrupt::new();
    ex.stop_on(interrupt.clone());
    let mut seen = Vec::new();
    let mut sink = |m: &Tokens, states: &[Desk], out: Out| -> Result<(), String> {
        let s = &states[out.0 as usize];
        if m.observed(out.0) && (s.handled, s.tokens) != (out.1, out.2) {
            return Err(format!("state of {} shown as {s:?} with {out:?}", out.0));
        }
        seen.push(out);
        if Some(seen.len()) == after {
            interrupt.raise(2);
        }
        Ok(())
    };
    let mid = ex.run(until / 2.0, &mut sink).expect("no error");
    let end = if mid < until / 2.0 {
        mid
    } else {
        ex.run(until, &mut sink).expect("no error")
    };
    (end, seen, ex.states().to_vec(), ex.stats().clone())
}

fn sequential() -> Box<dyn Executor<Tokens, String>> {
    let model = Tokens {
        lookahead: LOOKAHEAD,
        hasty: false,
    };
    Box::new(Sequential::new(model, desks(), VTime::start(0.0)))
}

fn conservative(
    workers: usize,
    map: &ObjectMap,
    chaos: Option<u64>,
    hasty: bool,
) -> Box<dyn Executor<Tokens, String>> {
    let model = Tokens {
        lookahead: LOOKAHEAD,
        hasty,
    };
    let cfg = ConservativeConfig { workers, chaos };
    Box::new(Conservative::new(model, desks(), VTime::start(0.0), map, cfg).expect("lookahead"))
}

#[test]
fn every_placement_commits_the_sequential_run() {
    let (end, outputs, states, stats) = run(sequential(), 40.0, None);
    assert_eq!(end, 40.0);
    assert!(outputs.len() > 3_000, "{} outputs", outputs.len());
    assert!(stats.cancels > 100, "{} cancels", stats.cancels);
    for workers in [1, 2, 3, 5] {
        for map in [ObjectMap::Block, ObjectMap::RoundRobin] {
            for chaos in [None, Some(7)] {
                let what = format!("{workers} workers, {map:?}, chaos {chaos:?}");
                let got = run(conservative(workers, &map, chaos, false), 40.0, None);
                assert_eq!(got.0, 40.0, "{what}");
                assert!(got.1 == outputs, "{what}: outputs differ");
                assert_eq!(got.2, states, "{what}");
                assert_eq!(got.3, stats, "{what}");
            }
        }
    }
}

#[test]
fn an_interrupt_ends_the_run_where_it_equals_the_sequential_run_cut_there() {
    for workers in [1, 3] {
        let (ended, seen, states, _) = run(
            conservative(workers, &ObjectMap::RoundRobin, None, false),
            40.0,
            Some(500),
        );
        assert!(
            ended < 40.0 && seen.len() >= 500,
            "{workers}: ended at {ended}"
        );
        assert_eq!(ended, seen.last().expect("outputs").3, "{workers}");
        let (_, whole, _, _) = run(sequential(), 40.0, None);
        let cut: Vec<Out> = whole.into_iter().filter(|o| o.3 <= ended).collect();
        assert!(cut == seen, "{workers}: the outputs up to {ended}");
        let (_, _, there, _) = run(sequential(), ended, None);
        assert_eq!(states, there, "{workers}");
    }
}

#[test]
fn a_model_without_lookahead_is_refused() {
    let model = Tokens {
        lookahead: 0.0,
        hasty: false,
    };
    let cfg = ConservativeConfig {
        workers: 2,
        chaos: None,
    };
    let refused = Conservative::new(model, desks(), VTime::start(0.0), &ObjectMap::Block, cfg);
    let Err(e @ Refused::NoLookahead(_)) = refused else {
        panic!("a model without lookahead was taken");
    };
    assert!(e.to_string().contains("positive lookahead"), "{e}");
}

#[test]
fn a_cancel_sooner_than_the_lookahead_across_workers_is_an_error() {
    let mut ex = conservative(2, &ObjectMap::RoundRobin, None, true);
    let err = ex
        .run(40.0, &mut |_, _, _| Ok(()))
        .expect_err("a hasty cancel across workers");
    let ExecError::Failed(why) = err else {
        panic!("not a model bug: {err}");
    };
    assert!(why.contains("sooner than the lookahead"), "{why}");
}

/// A model whose handler panics on one object.
struct Faulty;

impl Model for Faulty {
    type Time = PlainTime;
    type Msg = ();
    type State = ();
    type Output = ();
    type Undo = ();
    fn kind_names(&self) -> &'static [&'static str] {
        &["Tick"]
    }
    fn kind(&self, _: &()) -> usize {
        0
    }
    fn priority(&self, _: &()) -> u8 {
        0
    }
    fn lookahead(&self) -> f64 {
        1.0
    }
    fn init(&self, ctx: &mut Ctx<'_, Self>, me: u32, _: &mut ()) {
        ctx.relay_at(me, VTime::at(PlainTime(1.0 + f64::from(me))), ());
    }
    fn handle(&self, _: &mut Ctx<'_, Self>, me: u32, _: &mut (), _: &[Envelope<()>]) {
        assert!(me != 3, "object 3 is broken");
    }
}

#[test]
#[should_panic(expected = "object 3 is broken")]
fn a_panic_on_a_worker_reaches_the_caller() {
    let cfg = ConservativeConfig {
        workers: 2,
        chaos: None,
    };
    let map = ObjectMap::RoundRobin;
    let mut ex = Conservative::new(Faulty, vec![(); 6], VTime::start(0.0), &map, cfg).unwrap();
    let _ = ex.run(10.0, &mut |_, _, ()| Ok::<(), ()>(()));
}
