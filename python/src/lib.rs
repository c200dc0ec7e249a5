//! `poolsim._native`: the Rust side of the Python package. It runs scenarios and PHOLD with the
//! interpreter's lock released, and hands results over as numpy arrays that own the run's
//! buffers (no copy). The Python package (`python/poolsim/`) wraps these functions in a typed,
//! documented API; this module's signatures are its contract with them.

mod collect;
mod compress;
mod interop;
mod stream;

use collect::{Collected, Columns};
use numpy::{PyArray1, PyArrayMethods};
use poolsim::engine::{EventKind, Span};
use poolsim::model::layout::FixedNews;
use poolsim::model::pool::NvDelay;
use poolsim::observe::Observables;
use poolsim::run::{execute, EngineKind, RunConfig, SectorChoice};
use poolsim::scenario::builtin::Params;
use poolsim::scenario::Scenario;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// What a run is asked to do: every keyword of the Python package's `run` and `stream`, as
/// one dict with every key present.
#[derive(Clone, Debug, FromPyObject)]
#[pyo3(from_item_all)]
pub struct Ask {
    toml: Option<String>,
    until: Option<f64>,
    engine: String,
    dt: Option<f64>,
    workers: Option<usize>,
    sectors: Option<(u32, u32)>,
    auto_sectors: bool,
    check: bool,
    sample_every: Option<f64>,
    observe_every: Option<f64>,
    observe_from: Option<f64>,
    events: bool,
    balls: Option<usize>,
    seed: Option<u64>,
    area_fraction: Option<f64>,
    radius: Option<f64>,
    speed_max: Option<f64>,
    lattice: Option<String>,
    temperature: Option<f64>,
    mixture: Option<(f64, f64)>,
    boundary: Option<String>,
    thermostat: Option<f64>,
    thermostat_rate: Option<f64>,
    thermostat_seed: Option<u64>,
}

impl Ask {
    /// The scenario and the run's settings, checked.
    pub fn prepare(&self, spec: &str) -> PyResult<(Scenario, RunConfig)> {
        use poolsim::scenario::builtin::{Boundary, Lattice, Mixture};
        let boundary = match self.boundary.as_deref() {
            None => None,
            Some("walled") => Some(Boundary::Walled),
            Some("periodic") => Some(Boundary::Periodic),
            Some(other) => {
                return Err(value_error(format!(
                    "boundary: walled or periodic, got {other:?}"
                )))
            }
        };
        let lattice = match self.lattice.as_deref() {
            None => None,
            Some("triangular") => Some(Lattice::Triangular),
            Some("square") => Some(Lattice::Square),
            Some("random") => Some(Lattice::Random),
            Some(other) => {
                return Err(value_error(format!(
                    "lattice: triangular, square or random, got {other:?}"
                )))
            }
        };
        let params = Params {
            balls: self.balls,
            seed: self.seed,
            area_fraction: self.area_fraction,
            radius: self.radius,
            speed_max: self.speed_max,
            lattice,
            temperature: self.temperature,
            mixture: self.mixture.map(|(large, ratio)| Mixture { large, ratio }),
            boundary,
        };
        let scenario = scenario_of(spec, self.toml.as_deref(), &params)?;
        let cfg = config_of(self, &scenario)?;
        Ok((scenario, cfg))
    }
}

/// A `ValueError` with the library's one-line message.
pub fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// The scenario: TOML text when given, else a built-in name or a TOML file's path, with the
/// generators' parameters.
fn scenario_of(spec: &str, toml: Option<&str>, params: &Params) -> PyResult<Scenario> {
    match toml {
        Some(text) => poolsim::scenario::toml::parse(text, spec).map_err(value_error),
        None => poolsim::scenario::load(spec, params).map_err(value_error),
    }
}

/// The engine the call names, with its settings.
fn engine_of(ask: &Ask) -> PyResult<EngineKind> {
    let sectors = match (ask.sectors, ask.auto_sectors) {
        (Some((nx, ny)), _) if nx > 0 && ny > 0 => Some(SectorChoice::Grid(nx, ny)),
        (Some(_), _) => return Err(value_error("sectors: both counts must be at least 1")),
        (None, true) => Some(SectorChoice::Auto),
        (None, false) => None,
    };
    let refuse = |what: &str| {
        Err(value_error(format!(
            "{what}: the {} engine does not take it",
            ask.engine
        )))
    };
    if ask.dt.is_some() && ask.engine != "time-step" {
        return refuse("dt");
    }
    if ask.workers.is_some() && !matches!(ask.engine.as_str(), "time-warp" | "regions") {
        return refuse("workers");
    }
    Ok(match ask.engine.as_str() {
        "event-list" | "time-step" if sectors.is_some() => return refuse("sectors"),
        "event-list" => EngineKind::EventList,
        "time-step" => match ask.dt {
            Some(dt) if dt.is_finite() && dt > 0.0 => EngineKind::TimeStep { dt },
            Some(dt) => {
                return Err(value_error(format!(
                    "dt: must be a positive number, got {dt}"
                )))
            }
            None => return Err(value_error("dt: the time-step engine needs a time step")),
        },
        "objects" => match sectors {
            None => EngineKind::Objects {
                delay: NvDelay::Exact,
            },
            Some(sectors) => EngineKind::Sectored {
                sectors,
                news: FixedNews::Near,
            },
        },
        "time-warp" => {
            let mut tw = pdes_kernel::time_warp::TwConfig::default();
            match ask.workers {
                Some(w) if (1..=1024).contains(&w) => tw.workers = w,
                Some(w) => return Err(value_error(format!("workers: must be 1 to 1024, got {w}"))),
                None => {}
            }
            EngineKind::TimeWarp {
                tw,
                delay: NvDelay::Exact,
                sectors,
                news: FixedNews::Near,
            }
        }
        "regions" if sectors.is_some() => return refuse("sectors"),
        "regions" => {
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            let workers = match ask.workers {
                Some(w) if (1..=1024).contains(&w) => w,
                Some(w) => return Err(value_error(format!("workers: must be 1 to 1024, got {w}"))),
                None => cores,
            };
            // one region per worker; one worker runs them on the sequential executor
            let tw = (workers > 1).then(|| pdes_kernel::time_warp::TwConfig {
                workers,
                ..Default::default()
            });
            EngineKind::Regions {
                count: workers as u32,
                tw,
            }
        }
        other => {
            return Err(value_error(format!(
                "engine: one of event-list, time-step, objects, time-warp, regions; got {other:?}"
            )))
        }
    })
}

/// The run's settings, checked.
fn config_of(ask: &Ask, scenario: &Scenario) -> PyResult<RunConfig> {
    let engine = engine_of(ask)?;
    if let EngineKind::Sectored { sectors, .. }
    | EngineKind::TimeWarp {
        sectors: Some(sectors),
        ..
    } = engine
    {
        poolsim::run::sector_layout(scenario, sectors)
            .map_err(|e| value_error(format!("sectors: {e}")))?;
    }
    let until = ask.until.unwrap_or(scenario.until);
    if !until.is_finite() || until < 0.0 {
        return Err(value_error(format!(
            "until: must be a finite number not below 0, got {until}"
        )));
    }
    if let Some(dt) = ask.sample_every.filter(|d| !(d.is_finite() && *d > 0.0)) {
        return Err(value_error(format!(
            "sample_every: must be a positive number, got {dt}"
        )));
    }
    Ok(RunConfig {
        engine,
        until,
        check: ask.check,
        span: Span {
            frame_time: ask.sample_every,
            ..Span::default()
        },
        interrupt: None,
        checkpoint_every: None,
        thermostat: thermostat_of(ask)?,
    })
}

/// Andersen's thermostat, if `thermostat` asks for one (`thermostat_rate` default 0.1,
/// `thermostat_seed` default 1).
fn thermostat_of(ask: &Ask) -> PyResult<Option<poolsim::thermostat::Thermostat>> {
    let Some(kt) = ask.thermostat else {
        if ask.thermostat_rate.is_some() || ask.thermostat_seed.is_some() {
            return Err(value_error(
                "thermostat_rate, thermostat_seed: need thermostat=kT",
            ));
        }
        return Ok(None);
    };
    let t = poolsim::thermostat::Thermostat {
        kt,
        rate: ask.thermostat_rate.unwrap_or(0.1),
        seed: ask.thermostat_seed.unwrap_or(1),
    };
    t.check().map_err(|e| {
        value_error(
            e.replacen("--thermostat-rate", "thermostat_rate", 1)
                .replacen("--thermostat", "thermostat", 1),
        )
    })?;
    Ok(Some(t))
}

/// A flat vector of pairs as an `(n, 2)` array, without a copy.
pub fn pairs<'py>(py: Python<'py>, flat: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
    let n = flat.len() / 2;
    Ok(PyArray1::from_vec(py, flat).reshape([n, 2])?.into_any())
}

/// Event columns as a dict of arrays.
pub fn columns<'py>(py: Python<'py>, c: Columns) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("t", PyArray1::from_vec(py, c.t))?;
    d.set_item("kind", PyArray1::from_vec(py, c.kind))?;
    d.set_item("a", PyArray1::from_vec(py, c.a))?;
    d.set_item("b", PyArray1::from_vec(py, c.b))?;
    Ok(d)
}

/// Runs a scenario to its end with the interpreter's lock released. Returns a dict: `summary`
/// (the command line's `--json`, as text), `events` (columns `t`, `kind`, `a`, `b`, or `None`
/// when `ask.events` is false), `final` (`t`, `position`, `velocity`, `radius`, `mass`,
/// `pocket`, -1 for a ball on the table), `samples` (a list of dicts like `final`).
#[pyfunction]
fn run<'py>(py: Python<'py>, scenario: &str, ask: Ask) -> PyResult<Bound<'py, PyDict>> {
    let (summary, got) = py.detach(|| -> PyResult<(String, Collected)> {
        let (scenario, cfg) = ask.prepare(scenario)?;
        let observables = observables(&ask, &scenario, &cfg)?;
        let mut got = Collected::new(&scenario, ask.events, observables);
        let mut report = execute(&scenario, &cfg, &mut got).map_err(value_error)?;
        report.summary.observables = got.finish(&report);
        let summary = serde_json::to_string(&report.summary).map_err(value_error)?;
        Ok((summary, got))
    })?;
    got.into_dict(py, summary)
}

/// The observables `observe_every` and `observe_from` ask for, checked against the run.
fn observables(ask: &Ask, scenario: &Scenario, cfg: &RunConfig) -> PyResult<Option<Observables>> {
    let Some(every) = ask.observe_every else {
        return match ask.observe_from {
            Some(_) => Err(value_error("observe_from: needs observe_every")),
            None => Ok(None),
        };
    };
    Observables::over(scenario, (0.0, cfg.until), ask.observe_from, every)
        .map(Some)
        .map_err(|e| {
            let name = if e.is_about_every() {
                "observe_every"
            } else {
                "observe_from"
            };
            value_error(format!("{name}: {e}"))
        })
}

/// The trace names of the event kinds, indexed by the `kind` column.
#[pyfunction]
fn event_kinds() -> Vec<&'static str> {
    EventKind::ALL.iter().map(|k| k.name()).collect()
}

/// The built-in scenarios: (name, description) pairs.
#[pyfunction]
fn builtins() -> Vec<(&'static str, String)> {
    poolsim::scenario::builtin::list()
}

/// Runs PHOLD on the sequential kernel, Time Warp or the conservative executor, with the lock
/// released; returns the report as JSON text.
#[pyfunction]
#[pyo3(signature = (*, objects=1024, events_per_object=16, remote=0.1, lookahead=0.1, mean=1.0,
    seed=1, end=100.0, engine="objects".to_string(), workers=None, partitions=None))]
#[allow(clippy::too_many_arguments)]
fn phold(
    py: Python<'_>,
    objects: u32,
    events_per_object: u32,
    remote: f64,
    lookahead: f64,
    mean: f64,
    seed: u64,
    end: f64,
    engine: String,
    workers: Option<usize>,
    partitions: Option<u32>,
) -> PyResult<String> {
    use pdes_kernel::conservative::ConservativeConfig;
    use pdes_kernel::phold::{PholdConfig, PholdExecutor};
    use pdes_kernel::time_warp::{ObjectMap, TwConfig};
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let w = workers.unwrap_or(cores).clamp(1, 1024);
    let executor = match engine.as_str() {
        "objects" => PholdExecutor::Sequential,
        "time-warp" => PholdExecutor::TimeWarp(
            TwConfig {
                workers: w,
                ..TwConfig::default()
            },
            ObjectMap::Block,
        ),
        "conservative" => PholdExecutor::Conservative(
            ConservativeConfig {
                workers: w,
                chaos: None,
            },
            ObjectMap::Block,
        ),
        other => {
            return Err(value_error(format!(
                "engine: one of objects, time-warp, conservative; got {other:?}"
            )))
        }
    };
    let partitions = partitions.unwrap_or(match executor {
        PholdExecutor::Sequential => 2,
        _ => w as u32,
    });
    check_phold(
        objects,
        events_per_object,
        remote,
        lookahead,
        mean,
        end,
        partitions,
    )?;
    let cfg = PholdConfig {
        objects,
        events_per_object,
        remote,
        partitions,
        lookahead,
        mean,
        seed,
    };
    py.detach(|| {
        let report = pdes_kernel::phold::run_with(cfg, end, executor).map_err(value_error)?;
        serde_json::to_string(&report).map_err(value_error)
    })
}

/// Refuses PHOLD values it cannot run with, naming the argument.
fn check_phold(
    objects: u32,
    events_per_object: u32,
    remote: f64,
    lookahead: f64,
    mean: f64,
    end: f64,
    partitions: u32,
) -> PyResult<()> {
    let fail = |what: String| Err(value_error(what));
    if objects == 0 || events_per_object == 0 {
        return fail("objects, events_per_object: must be at least 1".into());
    }
    if u64::from(objects) * u64::from(events_per_object) > 10_000_000 {
        return fail("objects x events_per_object: at most 10,000,000 events in flight".into());
    }
    if !(0.0..=1.0).contains(&remote) {
        return fail(format!("remote: must lie in [0, 1], got {remote}"));
    }
    if !(lookahead.is_finite() && lookahead >= 0.0) {
        return fail(format!("lookahead: must not be negative, got {lookahead}"));
    }
    for (name, v) in [("mean", mean), ("end", end)] {
        if !(v.is_finite() && v > 0.0) {
            return fail(format!("{name}: must be a positive number, got {v}"));
        }
    }
    if partitions == 0 || partitions > objects {
        return fail(format!(
            "partitions: must be from 1 to objects ({objects}), got {partitions}"
        ));
    }
    Ok(())
}

/// Runs one of the command line's experiments (`poolsim experiment`), writing its tables,
/// figures, data and report into `out`, with the lock released.
#[pyfunction]
#[pyo3(signature = (which, out, *, quick=false, seeds=None, balls=None, font=None))]
fn experiment(
    py: Python<'_>,
    which: &str,
    out: std::path::PathBuf,
    quick: bool,
    seeds: Option<u64>,
    balls: Option<Vec<usize>>,
    font: Option<std::path::PathBuf>,
) -> PyResult<()> {
    use poolsim::experiment::{ExperimentOptions, Which};
    let which = match which {
        "thesis" => Which::Thesis,
        "reversal" => Which::Reversal,
        "eos" => Which::Eos,
        "jamming" => Which::Jamming,
        other => {
            return Err(value_error(format!(
                "which: thesis, reversal, eos or jamming, got {other:?}"
            )))
        }
    };
    let options = ExperimentOptions {
        which,
        out,
        seeds,
        balls,
        quick,
        font,
        area_fractions: None,
        rates: None,
    };
    py.detach(|| poolsim::experiment::run(&options, &mut |_| {}).map_err(value_error))
}

/// The module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(event_kinds, m)?)?;
    m.add_function(wrap_pyfunction!(builtins, m)?)?;
    m.add_function(wrap_pyfunction!(phold, m)?)?;
    m.add_function(wrap_pyfunction!(experiment, m)?)?;
    m.add_function(wrap_pyfunction!(compress::compress, m)?)?;
    m.add_function(wrap_pyfunction!(stream::stream, m)?)?;
    m.add_class::<stream::Stream>()?;
    m.add_function(wrap_pyfunction!(interop::write_xyz, m)?)?;
    m.add_function(wrap_pyfunction!(interop::read_xyz, m)?)?;
    Ok(())
}
