//! The conservative executor: workers on threads that run, in lockstep windows, only batches
//! that nothing can still precede (YAWNS: Nicol, "The cost of conservative synchronization in
//! parallel discrete event simulations", JACM 1993).
//!
//! ```text
//!  round k:  every worker reports the earliest time it holds or has just mailed ──► barrier
//!            F = the least report;  window = [F, F + lookahead)
//!            each worker runs its own batches of the window in order, mails what it sends
//!            to other workers' objects, and the next round begins
//! ```
//!
//! A model that declares a positive lookahead L ([`Model::lookahead`]) promises that a batch at
//! t sends nothing before t + L. No message of the simulation is earlier than F, so no batch
//! of the window can send anything into it: every worker runs its share of the window as
//! final, with no state saved and nothing to undo, and the run commits exactly the sequential
//! executor's batches, in the same order per object. The sink sees every output in the
//! sequential order, at the end of its window.
//!
//! The calling thread is worker 0, so a run uses one thread per worker and no more. Workers
//! wait for one another at a spinning barrier once per window; a window holds about
//! (events per unit of time) × L batches, so the executor pays where that is large against the
//! number of workers. A model with no lookahead is refused: use Time Warp.

mod part;
mod sync;

use crate::executor::ExecError;
use crate::sequential::Sink;
use crate::spin_barrier::{PoisonOnPanic, SpinBarrier};
use crate::time_warp::ObjectMap;
use crate::{Interrupt, MessageStats, Model, VTime};
use part::{Done, Home, Mail, Part, Window};
use sync::{Boxes, Reports, Round, FAILED, INTERRUPTED};

/// The conservative executor's settings.
#[derive(Clone, Debug)]
pub struct ConservativeConfig {
    /// Worker threads, the calling thread among them.
    pub workers: usize,
    /// Seed of chaos mode: arrivals shuffled and workers paused at random, to show that the
    /// answer does not depend on timing.
    pub chaos: Option<u64>,
}

impl Default for ConservativeConfig {
    fn default() -> Self {
        ConservativeConfig {
            workers: std::thread::available_parallelism().map_or(1, |n| n.get()),
            chaos: None,
        }
    }
}

/// Why the conservative executor refuses a model.
#[derive(Debug, thiserror::Error)]
pub enum Refused {
    /// The model declares no positive lookahead: a window would hold nothing that is safe.
    #[error(
        "the conservative executor needs a model with a positive lookahead (this one declares \
         {0}): run it on the sequential kernel or on Time Warp"
    )]
    NoLookahead(f64),
}

/// What a conservative run did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ConservativeStats {
    /// Worker threads.
    pub workers: usize,
    /// Windows run (rounds of the barrier).
    pub windows: u64,
    /// Batches each worker ran.
    pub batches: Vec<u64>,
    /// Messages that went from one worker to another.
    pub remote_messages: u64,
    /// The model's lookahead: the width of every window.
    pub lookahead: f64,
}

/// Runs a model's objects on worker threads in windows of its lookahead; the same interface
/// and the same committed results as the sequential executor.
pub struct Conservative<M: Model> {
    model: M,
    parts: Vec<Part<M>>,
    homes: Vec<Home>,
    /// The states the sink and [`Conservative::states`] see.
    view: Vec<M::State>,
    stats: MessageStats,
    windows: u64,
    /// Whether the sink reads the states just after each batch.
    ship: bool,
    interrupt: Option<Interrupt>,
}

/// What the workers share during one run.
struct Shared<'a, M: Model> {
    model: &'a M,
    homes: &'a [Home],
    workers: usize,
    barrier: SpinBarrier,
    reports: Reports,
    mail: Boxes<Mail<M::Time, M::Msg>>,
    done: Boxes<Vec<Done<M>>>,
    until: f64,
    lookahead: f64,
    ship: bool,
    interrupt: Option<&'a Interrupt>,
}

impl<M: Model> Conservative<M> {
    /// Sets the model's objects up on `cfg.workers` workers placed by `map`, and runs every
    /// object's `init` at `start` (in object order). Refuses a model without lookahead.
    pub fn new(
        model: M,
        states: Vec<M::State>,
        start: VTime<M::Time>,
        map: &ObjectMap,
        cfg: ConservativeConfig,
    ) -> Result<Conservative<M>, Refused> {
        let lookahead = model.lookahead();
        if lookahead.is_nan() || lookahead <= 0.0 {
            return Err(Refused::NoLookahead(lookahead));
        }
        let workers = cfg.workers.max(1);
        let of = map.workers_of(states.len(), workers);
        let mut objs: Vec<Vec<u32>> = vec![Vec::new(); workers];
        let mut homes = Vec::with_capacity(states.len());
        for (o, &w) in of.iter().enumerate() {
            let local = objs[w as usize].len() as u32;
            objs[w as usize].push(o as u32);
            homes.push(Home { worker: w, local });
        }
        let view = states.clone();
        let mut shares: Vec<Vec<M::State>> =
            objs.iter().map(|v| Vec::with_capacity(v.len())).collect();
        for (s, &w) in states.into_iter().zip(&of) {
            shares[w as usize].push(s);
        }
        let mut parts: Vec<Part<M>> = objs
            .into_iter()
            .zip(shares)
            .enumerate()
            .map(|(w, (o, s))| Part::new(w as u32, o, s, workers, cfg.chaos))
            .collect();
        for part in &mut parts {
            part.init(&model, &homes, &start);
        }
        let mut c = Conservative {
            model,
            parts,
            homes,
            view,
            stats: MessageStats::default(),
            windows: 0,
            ship: true,
            interrupt: None,
        };
        c.stats = c.total_stats();
        Ok(c)
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// Every object's state at the end of the last run.
    pub fn states(&self) -> &[M::State] {
        &self.view
    }

    /// Message statistics so far.
    pub fn stats(&self) -> &MessageStats {
        &self.stats
    }

    /// Messages waiting (cancelled ones not yet discarded included; mail between workers is
    /// delivered before a run returns).
    pub fn pending_len(&self) -> usize {
        self.parts.iter().map(Part::pending_len).sum()
    }

    /// What the runs so far did.
    pub fn conservative_stats(&self) -> ConservativeStats {
        ConservativeStats {
            workers: self.parts.len(),
            windows: self.windows,
            batches: self.parts.iter().map(|p| p.stats.batches).collect(),
            remote_messages: self.parts.iter().map(|p| p.received).sum(),
            lookahead: self.model.lookahead(),
        }
    }

    /// Whether the sink reads the states just after each batch (the default); when not, it is
    /// shown the states as they were at the start of the run, and the run ships no copies.
    pub fn ship_states(&mut self, on: bool) {
        self.ship = on;
    }

    /// Ends later runs early once `interrupt` is raised: at the time of the last batch any
    /// worker ran, every batch up to it run.
    pub fn stop_on(&mut self, interrupt: Interrupt) {
        self.interrupt = Some(interrupt);
    }

    fn total_stats(&self) -> MessageStats {
        let mut all = MessageStats::default();
        for p in &self.parts {
            all.add(&p.stats);
        }
        all
    }

    /// Runs every batch with time at most `until` on the workers; the sink sees each output,
    /// with the states just after its batch, in the sequential order. Returns the time the run
    /// ended at: `until`, or the time of the last batch run where an interrupt ended it.
    pub fn run<E>(&mut self, until: f64, sink: &mut Sink<'_, M, E>) -> Result<f64, ExecError<E>>
    where
        M: Sync,
        M::Msg: Send,
        M::State: Send,
        M::Output: Send,
    {
        let shared = Shared {
            model: &self.model,
            homes: &self.homes,
            workers: self.parts.len(),
            barrier: SpinBarrier::new(self.parts.len()),
            reports: Reports::new(self.parts.len()),
            mail: Boxes::new(self.parts.len()),
            done: Boxes::new(self.parts.len()),
            until,
            lookahead: self.model.lookahead(),
            ship: self.ship,
            interrupt: self.interrupt.as_ref(),
        };
        let view = &mut self.view;
        let (first, others) = self.parts.split_first_mut().expect("one worker at least");
        let (end, windows) = std::thread::scope(|s| {
            let others: Vec<_> = others
                .iter_mut()
                .map(|part| {
                    let shared = &shared;
                    s.spawn(move || {
                        let _guard = PoisonOnPanic(&shared.barrier);
                        let _ = work::<M, std::convert::Infallible>(part, shared, &mut |_| Ok(()));
                    })
                })
                .collect();
            let _guard = PoisonOnPanic(&shared.barrier);
            let mut show = |round| show(&shared, view, round, sink);
            let mine = work(first, &shared, &mut show);
            for h in others {
                // a worker's panic (a model bug) reaches the caller as itself
                if let Err(payload) = h.join() {
                    std::panic::resume_unwind(payload);
                }
            }
            mine
        });
        self.windows += windows;
        self.stats = self.total_stats();
        for part in &self.parts {
            for (&o, s) in part.objs.iter().zip(&part.states) {
                self.view[o as usize].clone_from(s);
            }
        }
        if let Some(e) = self.parts.iter().find_map(|p| p.error.clone()) {
            return Err(ExecError::Failed(e));
        }
        end
    }
}

/// One worker's run: rounds of report, barrier, mail and window until the run ends. `show`
/// takes the outputs of a round's window (worker 0's, which feeds the sink); it returns the
/// window count and the time the run ended at, or the sink's error.
fn work<M: Model, E>(
    part: &mut Part<M>,
    sh: &Shared<'_, M>,
    show: &mut dyn FnMut(u64) -> Result<(), E>,
) -> (Result<f64, ExecError<E>>, u64) {
    let workers = sh.workers;
    let mut failed: Option<E> = None;
    let mut round = 0u64;
    loop {
        part.post(&sh.mail, round);
        sh.done
            .get(round, part.me as usize, part.me as usize)
            .append(&mut part.done);
        let mut flags = part.flags();
        if sh.interrupt.is_some_and(Interrupt::raised) {
            flags |= INTERRUPTED;
        }
        if failed.is_some() {
            flags |= FAILED;
        }
        sh.reports
            .write(round, part.me as usize, part.earliest(), part.last, flags);
        if sh.barrier.wait().is_err() {
            return (Ok(sh.until), round);
        }
        let all: Round = sh.reports.read(round);
        part.collect(&sh.mail, round, workers);
        if failed.is_none() {
            if let Err(e) = show(round) {
                failed = Some(e);
            }
        }
        if let Some(end) = ending(&all, sh.until) {
            return match failed {
                Some(e) => (Err(ExecError::Sink(e)), round),
                None => (Ok(end), round),
            };
        }
        let window = Window {
            end: all.earliest + sh.lookahead,
            until: sh.until,
        };
        part.run_window(sh.model, sh.homes, window, sh.ship);
        round += 1;
    }
}

/// Where the run ends after a round with these reports, if it does: at `until` when nothing
/// is left to run before it, at the last batch run when a worker failed or an interrupt came
/// (once a batch has run, as the sequential executor does).
fn ending(all: &Round, until: f64) -> Option<f64> {
    let interrupted = all.flags & INTERRUPTED != 0 && all.last > f64::NEG_INFINITY;
    if interrupted || all.flags & FAILED != 0 {
        return Some(all.last.min(until));
    }
    (all.earliest > until).then_some(until)
}

/// Feeds the sink every output of round `round`'s window, in the sequential order: by batch
/// time, then object.
fn show<M: Model, E>(
    sh: &Shared<'_, M>,
    view: &mut [M::State],
    round: u64,
    sink: &mut Sink<'_, M, E>,
) -> Result<(), E> {
    let workers = sh.workers;
    let mut done: Vec<Done<M>> = Vec::new();
    for w in 0..workers {
        done.append(&mut sh.done.get(round, w, w));
    }
    done.sort_by(|a, b| a.time.cmp(&b.time).then(a.obj.cmp(&b.obj)));
    for d in done {
        if let Some(state) = d.state {
            view[d.obj as usize] = state;
        }
        for o in d.output {
            sink(sh.model, view, o)?;
        }
    }
    Ok(())
}
