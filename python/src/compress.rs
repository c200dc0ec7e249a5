//! `poolsim.compress`: Lubachevsky-Stillinger compression from Python, with the lock released.

use crate::collect::Snapshot;
use crate::{value_error, Ask};
use numpy::PyArray1;
use poolsim::compress::{compress as grow, CompressConfig, Ending};
use poolsim::engine::{BallState, Table};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Compresses the start `scenario` (with `ask`'s generator parameters; `ask.check` checks every
/// event) by `(rate, target, max_pressure, cycle_collisions)`. Returns a dict: `ending`
/// (`"target"`, `"jammed"`), `t`, `final` (the packing, a state dict at t = 0), `table`, and
/// `cycles` (arrays `t`, `area_fraction`, `z`, `kt`, `collisions`).
#[pyfunction]
#[pyo3(signature = (scenario, ask, rate, target, max_pressure, cycle_collisions))]
pub fn compress<'py>(
    py: Python<'py>,
    scenario: &str,
    ask: Ask,
    rate: f64,
    target: Option<f64>,
    max_pressure: f64,
    cycle_collisions: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (start, _) = ask.prepare(scenario)?;
    let cfg = CompressConfig {
        rate,
        target,
        max_pressure,
        cycle_collisions,
        check: ask.check,
        ..CompressConfig::default()
    };
    let done = py
        .detach(|| grow(&start, &cfg, None, &mut |_| {}))
        .map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item(
        "ending",
        match done.ending {
            Ending::Target => "target",
            Ending::Jammed => "jammed",
            Ending::Interrupted => "interrupted",
        },
    )?;
    d.set_item("t", done.t)?;
    let balls = BallState::initial(&done.scenario, 0.0);
    d.set_item("final", Snapshot::of(0.0, &balls, &[]).into_dict(py)?)?;
    let table = Table::new(&done.scenario);
    d.set_item("table", crate::interop::table_dict(py, &table)?)?;
    let cycles = PyDict::new(py);
    let column = |f: fn(&poolsim::compress::Cycle) -> f64| -> Vec<f64> {
        done.cycles.iter().map(f).collect()
    };
    cycles.set_item("t", PyArray1::from_vec(py, column(|c| c.t)))?;
    cycles.set_item(
        "area_fraction",
        PyArray1::from_vec(py, column(|c| c.area_fraction)),
    )?;
    cycles.set_item("z", PyArray1::from_vec(py, column(|c| c.z)))?;
    cycles.set_item("kt", PyArray1::from_vec(py, column(|c| c.kt)))?;
    let collisions: Vec<u64> = done.cycles.iter().map(|c| c.collisions).collect();
    cycles.set_item("collisions", PyArray1::from_vec(py, collisions))?;
    d.set_item("cycles", cycles)?;
    Ok(d)
}
