//! What a run hands to Python: its events as columns, its samples, its final state.

use numpy::{PyArray1, PyArrayMethods};
use poolsim::engine::{
    BallState, Event, EventKind, Fixed, Frame, Observer, RunError, Table, World,
};
use poolsim::observe::{Observables, Observed};
use poolsim::run::Report;
use poolsim::scenario::Scenario;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// Events as columns: time, kind (index into the kind names), the ball, and the other object's
/// index within its own kind (ball, cushion, pocket or corner).
#[derive(Default)]
pub struct Columns {
    /// Times.
    pub t: Vec<f64>,
    /// Kinds, as indices of `EventKind::ALL`.
    pub kind: Vec<u8>,
    /// The ball.
    pub a: Vec<u32>,
    /// The other object, numbered within its kind.
    pub b: Vec<u32>,
}

impl Columns {
    /// Adds one event, its other object numbered within its kind on `table`.
    pub fn push(&mut self, ev: &Event, table: &Table) {
        let b = match ev.kind {
            EventKind::BallBall => ev.b,
            _ => match table.fixed(ev.b) {
                Fixed::Cushion(k) | Fixed::Pocket(k) | Fixed::Corner(k) => k,
            },
        };
        let kind = EventKind::ALL
            .iter()
            .position(|k| *k == ev.kind)
            .unwrap_or(0);
        self.t.push(ev.t);
        self.kind.push(kind as u8);
        self.a.push(ev.a);
        self.b.push(b);
    }

    /// Events held.
    pub fn len(&self) -> usize {
        self.t.len()
    }
}

/// Every ball at one time: positions and velocities as flat (x, y) pairs.
pub struct Snapshot {
    t: f64,
    position: Vec<f64>,
    velocity: Vec<f64>,
    radius: Vec<f64>,
    mass: Vec<f64>,
    pocket: Vec<i32>,
    /// In a periodic box, each ball's image (pairs of whole sides); empty else.
    image: Vec<i64>,
}

impl Snapshot {
    /// The balls fixed at `t`, with their images in a periodic box (`images`, empty else).
    pub fn of(t: f64, balls: &[BallState], images: &[[i64; 2]]) -> Snapshot {
        let mut s = Snapshot {
            t,
            image: images.iter().flatten().copied().collect(),
            position: Vec::with_capacity(2 * balls.len()),
            velocity: Vec::with_capacity(2 * balls.len()),
            radius: Vec::with_capacity(balls.len()),
            mass: Vec::with_capacity(balls.len()),
            pocket: Vec::with_capacity(balls.len()),
        };
        for b in balls {
            let p = if b.pocket.is_some() {
                b.traj.position
            } else {
                b.traj.at(t)
            };
            s.position.extend([p.x, p.y]);
            s.velocity.extend([b.traj.velocity.x, b.traj.velocity.y]);
            s.radius.push(b.radius);
            s.mass.push(b.mass);
            s.pocket.push(b.pocket.map_or(-1, |k| k as i32));
        }
        s
    }

    /// As a dict of arrays.
    pub fn into_dict(self, py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("t", self.t)?;
        d.set_item("position", crate::pairs(py, self.position)?)?;
        d.set_item("velocity", crate::pairs(py, self.velocity)?)?;
        d.set_item("radius", PyArray1::from_vec(py, self.radius))?;
        d.set_item("mass", PyArray1::from_vec(py, self.mass))?;
        d.set_item("pocket", PyArray1::from_vec(py, self.pocket))?;
        if !self.image.is_empty() {
            let n = self.image.len() / 2;
            d.set_item("image", PyArray1::from_vec(py, self.image).reshape([n, 2])?)?;
        }
        Ok(d)
    }
}

/// Collects a whole run: its events (when asked), its samples and its final state.
pub struct Collected {
    table: Table,
    observables: Option<Observables>,
    events: Option<Columns>,
    samples: Vec<Snapshot>,
    last: Option<Snapshot>,
}

impl Collected {
    /// A collector for runs of `scenario`, keeping events or not.
    pub fn new(scenario: &Scenario, events: bool, observables: Option<Observables>) -> Collected {
        Collected {
            table: Table::new(scenario),
            observables,
            events: events.then(Columns::default),
            samples: Vec::new(),
            last: None,
        }
    }

    /// Takes the final state from the run's report; returns what the observables came to.
    pub fn finish(&mut self, report: &Report) -> Option<Observed> {
        self.last = Some(Snapshot::of(report.outcome.t, &report.outcome.balls, &[]));
        self.observables.take().map(|o| o.finish(report.outcome.t))
    }

    /// Everything as a dict for the Python package, with the summary's JSON text.
    pub fn into_dict(self, py: Python<'_>, summary: String) -> PyResult<Bound<'_, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("summary", summary)?;
        match self.events {
            Some(c) => d.set_item("events", crate::columns(py, c)?)?,
            None => d.set_item("events", py.None())?,
        }
        let samples = PyList::empty(py);
        for s in self.samples {
            samples.append(s.into_dict(py)?)?;
        }
        d.set_item("samples", samples)?;
        d.set_item("table", crate::interop::table_dict(py, &self.table)?)?;
        if let Some(last) = self.last {
            d.set_item("final", last.into_dict(py)?)?;
        }
        Ok(d)
    }
}

impl Observer for Collected {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        if let Some(c) = &mut self.events {
            c.push(ev, &self.table);
        }
        match &mut self.observables {
            Some(o) => o.on_event(ev, world),
            None => Ok(()),
        }
    }

    fn on_kick(&mut self, ball: u32, t: f64, world: &dyn World) -> Result<(), RunError> {
        match &mut self.observables {
            Some(o) => o.on_kick(ball, t, world),
            None => Ok(()),
        }
    }

    fn reads_balls(&self) -> bool {
        self.observables.is_some()
    }

    fn on_frame(&mut self, frame: &Frame, _: &Table) -> Result<(), RunError> {
        self.samples
            .push(Snapshot::of(frame.t, &frame.balls, &frame.images));
        Ok(())
    }
}
