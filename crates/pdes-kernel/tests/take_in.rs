//! Messages taken in after a span ([`Model::take_in`]): objects that run their own ticks on
//! past their batches' times hear notes from each other, take in those that change nothing a
//! tick reads and refuse the others. Time Warp must commit the sequential executor's run bit
//! for bit, with notes taken in, refused, undone and taken in again under chaos.

use pdes_kernel::sequential::Sequential;
use pdes_kernel::time_warp::threads::TimeWarp;
use pdes_kernel::time_warp::{ObjectMap, TwConfig, TwStats};
use pdes_kernel::{Ctx, Envelope, Handle, Model, PlainTime, Saving, VTime};
use std::sync::atomic::{AtomicU64, Ordering};

/// Objects that tick on their own and pass notes.
struct Clocks {
    objects: u32,
    /// Notes offered again after a later message undid them.
    again: AtomicU64,
}

/// A message: to the object itself, run the ticks from here; or a note from another.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
enum Msg {
    Wake,
    /// An even note adds to the tally, which no tick reads; an odd one mixes into the value,
    /// which every tick reads.
    Note(u64),
}

/// One object: the value its ticks mix, the tally of even notes, its ticks so far, the time
/// of its next tick, and its pending wake-up.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
struct Clock {
    value: u64,
    tally: u64,
    ticks: u64,
    next: f64,
    #[serde(skip)]
    wake: Option<Handle>,
}

/// A clock's old state, saved before a change.
#[derive(Clone, Debug)]
struct Undo(Clock);

fn restore(clock: &mut Clock, undo: Undo) {
    *clock = undo.0;
}

/// SplitMix64's finaliser: a well-mixed word from `x`.
fn mix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Clocks {
    fn clocks(&self) -> Vec<Clock> {
        (0..self.objects)
            .map(|i| Clock {
                value: mix(u64::from(i)),
                tally: 0,
                ticks: 0,
                next: 0.01 * f64::from(i % 7 + 1),
                wake: None,
            })
            .collect()
    }

    /// Runs object `me`'s tick at `t`: mixes the value, reports every fifth tick, sets the
    /// next tick, and tells whether it has a note to send (to whom, and what).
    fn tick(
        &self,
        ctx: &mut Ctx<'_, Self>,
        me: u32,
        clock: &mut Clock,
        t: f64,
    ) -> Option<(u32, u64)> {
        clock.ticks += 1;
        clock.value = mix(clock.value ^ clock.ticks);
        if clock.ticks.is_multiple_of(5) {
            ctx.emit_at(VTime::at(PlainTime(t)), (me, clock.ticks, clock.value));
        }
        clock.next = t + 0.004 * ((clock.value % 5) + 1) as f64;
        clock.value.is_multiple_of(4).then(|| {
            let to = ((clock.value >> 8) % u64::from(self.objects)) as u32;
            (to, clock.value >> 40)
        })
    }

    /// Sends the clock its wake-up at its next tick.
    fn schedule(&self, ctx: &mut Ctx<'_, Self>, me: u32, clock: &mut Clock) {
        ctx.save(|| Undo(clock.clone()));
        let h = ctx.send_at(me, VTime::at(PlainTime(clock.next)), Msg::Wake);
        clock.wake = Some(h);
    }
}

impl Model for Clocks {
    type Time = PlainTime;
    type Msg = Msg;
    type State = Clock;
    type Output = (u32, u64, u64);
    type Undo = Undo;

    fn kind_names(&self) -> &'static [&'static str] {
        &["Wake", "Note"]
    }
    fn kind(&self, msg: &Msg) -> usize {
        match msg {
            Msg::Wake => 0,
            Msg::Note(_) => 1,
        }
    }
    fn priority(&self, _: &Msg) -> u8 {
        0
    }
    fn saving(&self, _: u32) -> Saving<Clock, Undo> {
        Saving::Incremental { restore }
    }
    fn runs_ahead(&self, _: u32) -> bool {
        true
    }
    fn init(&self, ctx: &mut Ctx<'_, Self>, me: u32, clock: &mut Clock) {
        self.schedule(ctx, me, clock);
    }
    fn handle(&self, ctx: &mut Ctx<'_, Self>, me: u32, clock: &mut Clock, batch: &[Envelope<Msg>]) {
        ctx.save(|| Undo(clock.clone()));
        let mut woken = false;
        for env in batch {
            match env.msg {
                Msg::Wake => woken = true,
                Msg::Note(n) if n.is_multiple_of(2) => clock.tally = clock.tally.wrapping_add(n),
                Msg::Note(n) => clock.value ^= n,
            }
        }
        if !woken {
            return;
        }
        // ticks run on until one has a note to send: it is sent at the time reached
        let mut t = ctx.now().t();
        let mut note = self.tick(ctx, me, clock, t);
        while note.is_none() {
            let at = VTime::at(PlainTime(clock.next));
            if !ctx.may_run(&at) {
                break;
            }
            ctx.reach(at);
            ctx.save(|| Undo(clock.clone()));
            t = clock.next;
            note = self.tick(ctx, me, clock, t);
        }
        if let Some((to, n)) = note {
            let at = VTime::at(PlainTime(t + 0.001 + 0.002 * (n % 3) as f64));
            ctx.send_at(to, at, Msg::Note(n));
        }
        self.schedule(ctx, me, clock);
    }
    fn cut(&self, ctx: &mut Ctx<'_, Self>, me: u32, clock: &mut Clock) {
        // the ticks kept sent nothing: only the wake-up for the next one is missing
        self.schedule(ctx, me, clock);
    }
    fn may_take_in(msg: &Msg) -> bool {
        matches!(msg, Msg::Note(_))
    }
    fn take_in(
        &self,
        ctx: &mut Ctx<'_, Self>,
        _: u32,
        clock: &mut Clock,
        batch: &[Envelope<Msg>],
        again: bool,
    ) -> bool {
        if again {
            self.again.fetch_add(1, Ordering::Relaxed);
        }
        // an even note changes only the tally, which no tick read; an odd one changes the
        // value the ticks run past it read
        if batch
            .iter()
            .any(|e| matches!(e.msg, Msg::Note(n) if n % 2 == 1))
        {
            return false;
        }
        ctx.save(|| Undo(clock.clone()));
        for env in batch {
            if let Msg::Note(n) = env.msg {
                clock.tally = clock.tally.wrapping_add(n);
            }
        }
        true
    }
}

/// What a run committed: its outputs and the final states; with Time Warp's counts, and how
/// many notes were offered again.
type Run = (Vec<(u32, u64, u64)>, Vec<(u64, u64, u64)>, TwStats, u64);

/// Runs 24 clocks to `until` on the sequential executor, or on Time Warp with `workers`.
fn run(workers: Option<TwConfig>, until: f64) -> Run {
    let model = Clocks {
        objects: 24,
        again: AtomicU64::new(0),
    };
    let clocks = model.clocks();
    let mut seen = Vec::new();
    let mut sink = |_: &Clocks, _: &[Clock], out: (u32, u64, u64)| -> Result<(), ()> {
        seen.push(out);
        Ok(())
    };
    let start = VTime::start(0.0);
    let (finals, stats, again) = match workers {
        None => {
            let mut ex = Sequential::new(model, clocks, start);
            ex.observe_states(false);
            ex.run(until, &mut sink).unwrap();
            (ex.states().to_vec(), TwStats::default(), 0)
        }
        Some(cfg) => {
            let mut ex = TimeWarp::new(model, clocks, start, &ObjectMap::RoundRobin, cfg);
            // a sink that reads no states lets batches run on, and notes wait to be taken in
            ex.ship_states(false);
            ex.run(until, &mut sink).unwrap();
            let again = ex.model().again.load(Ordering::Relaxed);
            (ex.states().to_vec(), ex.tw_stats(), again)
        }
    };
    let finals = finals.iter().map(|c| (c.value, c.tally, c.ticks)).collect();
    (seen, finals, stats, again)
}

#[test]
fn notes_taken_in_after_a_span_commit_the_sequential_run() {
    let (want_out, want_states, ..) = run(None, 20.0);
    assert!(want_out.len() > 1000, "{} outputs", want_out.len());
    let (mut taken_in, mut refused, mut again) = (0, 0, 0);
    for workers in [1usize, 2, 3] {
        for chaos in [None, Some(5), Some(17)] {
            let cfg = TwConfig {
                workers,
                chaos,
                gvt_interval: Some(64),
                ..Default::default()
            };
            let (out, states, st, offered_again) = run(Some(cfg), 20.0);
            let what = format!("{workers} workers, chaos {chaos:?}");
            assert_eq!(states, want_states, "{what}: final states");
            assert!(out == want_out, "{what}: outputs differ");
            taken_in += st.taken_in;
            refused += st.take_in_refused;
            again += offered_again;
        }
    }
    // every way is taken, many times
    assert!(
        taken_in > 100 && refused > 100,
        "{taken_in} taken in, {refused} refused"
    );
    assert!(again > 10, "{again} notes offered again");
}
