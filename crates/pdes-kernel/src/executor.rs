//! One interface for every executor: a caller sets a model up on the [`Sequential`] executor,
//! on [`TimeWarp`] or on [`Conservative`], then runs and reads it the same way, whichever it chose.

use crate::conservative::{Conservative, ConservativeStats};
use crate::sequential::{Sequential, Sink};
use crate::time_warp::threads::TimeWarp;
use crate::time_warp::{RoundRecord, TwStats};
use crate::{Interrupt, MessageStats, Model};

/// Why a run stopped early.
#[derive(Debug, thiserror::Error)]
pub enum ExecError<E> {
    /// The sink returned an error (the run stops at the first).
    #[error("{0}")]
    Sink(E),
    /// The executor failed: out of its memory budget, or a model bug in a committed batch.
    #[error("{0}")]
    Failed(String),
}

/// Runs a model's objects: every executor offers this, so that a caller can hold any of them
/// as `Box<dyn Executor<M, E>>`, `E` being its sink's error.
pub trait Executor<M: Model, E> {
    /// The model.
    fn model(&self) -> &M;

    /// Every object's committed state.
    fn states(&self) -> &[M::State];

    /// Committed message statistics.
    fn stats(&self) -> &MessageStats;

    /// Messages waiting, cancelled ones not yet discarded included.
    fn pending_len(&self) -> usize;

    /// Time Warp's own statistics, where the executor is Time Warp.
    fn tw_stats(&self) -> Option<TwStats> {
        None
    }

    /// The conservative executor's own statistics, where the executor is that one.
    fn conservative_stats(&self) -> Option<ConservativeStats> {
        None
    }

    /// Time Warp's record of every GVT round, when it keeps one
    /// ([`TwConfig::record_rounds`](crate::time_warp::TwConfig::record_rounds)).
    fn round_records(&self) -> &[RoundRecord] {
        &[]
    }

    /// Whether the sink reads the states just after each batch (the default); an executor that
    /// keeps states apart, as Time Warp does, runs faster when it need not gather them.
    fn observe_states(&mut self, on: bool) {
        let _ = on;
    }

    /// Ends later runs early, cleanly, once `interrupt` is raised (see [`crate::interrupt`]).
    fn stop_on(&mut self, interrupt: Interrupt);

    /// Runs every batch with time at most `until`, passing each output, with the states just
    /// after its batch, to `sink` in the sequential order; stops at the sink's first error.
    /// Returns the time the run ended at: `until`, or an earlier one an interrupt chose, every
    /// batch up to it run and none after it.
    fn run(&mut self, until: f64, sink: &mut Sink<'_, M, E>) -> Result<f64, ExecError<E>>;

    /// Frees the executor's memory (Time Warp's on each worker's own thread).
    fn free(self: Box<Self>) {}
}

impl<M: Model, E> Executor<M, E> for Sequential<M> {
    fn model(&self) -> &M {
        Sequential::model(self)
    }

    fn states(&self) -> &[M::State] {
        Sequential::states(self)
    }

    fn stats(&self) -> &MessageStats {
        Sequential::stats(self)
    }

    fn pending_len(&self) -> usize {
        Sequential::pending_len(self)
    }

    fn observe_states(&mut self, on: bool) {
        Sequential::observe_states(self, on);
    }

    fn stop_on(&mut self, interrupt: Interrupt) {
        Sequential::stop_on(self, interrupt);
    }

    fn run(&mut self, until: f64, sink: &mut Sink<'_, M, E>) -> Result<f64, ExecError<E>> {
        Sequential::run(self, until, sink).map_err(ExecError::Sink)
    }
}

impl<M, E> Executor<M, E> for TimeWarp<M>
where
    M: Model + Sync,
    M::Msg: Send,
    M::State: Send + Sync,
    M::Output: Send,
{
    fn model(&self) -> &M {
        TimeWarp::model(self)
    }

    fn states(&self) -> &[M::State] {
        TimeWarp::states(self)
    }

    fn stats(&self) -> &MessageStats {
        TimeWarp::stats(self)
    }

    fn pending_len(&self) -> usize {
        TimeWarp::pending_len(self)
    }

    fn tw_stats(&self) -> Option<TwStats> {
        Some(TimeWarp::tw_stats(self))
    }

    fn round_records(&self) -> &[RoundRecord] {
        TimeWarp::round_records(self)
    }

    fn observe_states(&mut self, on: bool) {
        self.ship_states(on);
    }

    fn stop_on(&mut self, interrupt: Interrupt) {
        TimeWarp::stop_on(self, interrupt);
    }

    fn run(&mut self, until: f64, sink: &mut Sink<'_, M, E>) -> Result<f64, ExecError<E>> {
        TimeWarp::run(self, until, sink)
    }

    fn free(self: Box<Self>) {
        TimeWarp::free(*self);
    }
}

impl<M, E> Executor<M, E> for Conservative<M>
where
    M: Model + Sync,
    M::Msg: Send,
    M::State: Send,
    M::Output: Send,
{
    fn model(&self) -> &M {
        Conservative::model(self)
    }

    fn states(&self) -> &[M::State] {
        Conservative::states(self)
    }

    fn stats(&self) -> &MessageStats {
        Conservative::stats(self)
    }

    fn pending_len(&self) -> usize {
        Conservative::pending_len(self)
    }

    fn conservative_stats(&self) -> Option<ConservativeStats> {
        Some(Conservative::conservative_stats(self))
    }

    fn observe_states(&mut self, on: bool) {
        self.ship_states(on);
    }

    fn stop_on(&mut self, interrupt: Interrupt) {
        Conservative::stop_on(self, interrupt);
    }

    fn run(&mut self, until: f64, sink: &mut Sink<'_, M, E>) -> Result<f64, ExecError<E>> {
        Conservative::run(self, until, sink)
    }
}
