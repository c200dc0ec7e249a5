//! Configurations in and out in the command line's extended XYZ (`poolsim::samples`), so that
//! Python writes and reads exactly what `poolsim run --samples` does.

use crate::value_error;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use poolsim::engine::{BallState, Frame, Table};
use poolsim::geometry::{Trajectory, Vec2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// One frame as Python hands it over: time, positions and velocities `(N, 2)`, radii, masses and
/// pockets (-1 on the table).
type FrameIn<'py> = (
    f64,
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, i32>,
    Option<PyReadonlyArray2<'py, i64>>,
);

/// The frame's balls, fixed at its time.
fn frame_of(f: &FrameIn<'_>) -> PyResult<Frame> {
    let (t, pos, vel, radius, mass, pocket, image) = f;
    let (pos, vel) = (pos.as_array(), vel.as_array());
    let (radius, mass, pocket) = (radius.as_array(), mass.as_array(), pocket.as_array());
    let n = pos.nrows();
    if pos.ncols() != 2
        || vel.dim() != (n, 2)
        || radius.len() != n
        || mass.len() != n
        || pocket.len() != n
    {
        return Err(value_error(
            "a frame needs (N, 2) positions and velocities and N radii, masses and pockets",
        ));
    }
    let balls = (0..n)
        .map(|i| BallState {
            traj: Trajectory {
                position: Vec2::new(pos[(i, 0)], pos[(i, 1)]),
                velocity: Vec2::new(vel[(i, 0)], vel[(i, 1)]),
                t0: *t,
            },
            radius: radius[i],
            mass: mass[i],
            pocket: u32::try_from(pocket[i]).ok(),
        })
        .collect();
    let images = match image {
        None => Vec::new(),
        Some(image) => {
            let image = image.as_array();
            if image.dim() != (n, 2) {
                return Err(value_error("a frame's images must be an (N, 2) array"));
            }
            (0..n).map(|i| [image[(i, 0)], image[(i, 1)]]).collect()
        }
    };
    Ok(Frame {
        t: *t,
        balls,
        images,
    })
}

/// Writes frames as extended XYZ to `path`, the lattice the box from `lo` to `hi` (a periodic
/// box if `periodic`, each frame then with its images).
#[pyfunction]
pub fn write_xyz(
    path: &str,
    frames: Vec<FrameIn<'_>>,
    lo: (f64, f64),
    hi: (f64, f64),
    periodic: bool,
) -> PyResult<()> {
    let table = Table {
        n_balls: 0,
        cushions: Vec::new(),
        pockets: Vec::new(),
        corners: Vec::new(),
        lo: Vec2::new(lo.0, lo.1),
        hi: Vec2::new(hi.0, hi.1),
        period: periodic.then(|| poolsim::geometry::PeriodicBox {
            lo: Vec2::new(lo.0, lo.1),
            size: Vec2::new(hi.0 - lo.0, hi.1 - lo.1),
        }),
    };
    let file = std::fs::File::create(path).map_err(|e| value_error(format!("{path}: {e}")))?;
    let mut out = std::io::BufWriter::new(file);
    for f in &frames {
        poolsim::samples::write_frame(&mut out, &frame_of(f)?, &table)
            .map_err(|e| value_error(format!("{path}: {e}")))?;
    }
    std::io::Write::flush(&mut out).map_err(|e| value_error(format!("{path}: {e}")))
}

/// Reads every frame of an extended XYZ file: a list of dicts `t`, `origin`, `size`, `id`,
/// `position`, `velocity`, `radius`, `mass`.
#[pyfunction]
pub fn read_xyz<'py>(py: Python<'py>, path: &str) -> PyResult<Bound<'py, PyList>> {
    let text = std::fs::read_to_string(path).map_err(|e| value_error(format!("{path}: {e}")))?;
    let samples = poolsim::samples::read(&text).map_err(|e| value_error(format!("{path}:{e}")))?;
    let out = PyList::empty(py);
    for s in samples {
        let d = PyDict::new(py);
        d.set_item("t", s.t)?;
        d.set_item("origin", s.origin)?;
        d.set_item("size", s.size)?;
        d.set_item("periodic", s.periodic)?;
        let flat = |f: &dyn Fn(&poolsim::samples::SampledBall) -> (f64, f64)| -> Vec<f64> {
            s.balls
                .iter()
                .flat_map(|b| {
                    let (x, y) = f(b);
                    [x, y]
                })
                .collect()
        };
        d.set_item("position", crate::pairs(py, flat(&|b| b.position))?)?;
        d.set_item("velocity", crate::pairs(py, flat(&|b| b.velocity))?)?;
        d.set_item(
            "id",
            PyArray1::from_vec(py, s.balls.iter().map(|b| b.id).collect()),
        )?;
        d.set_item(
            "radius",
            PyArray1::from_vec(py, s.balls.iter().map(|b| b.radius).collect()),
        )?;
        d.set_item(
            "mass",
            PyArray1::from_vec(py, s.balls.iter().map(|b| b.mass).collect()),
        )?;
        let image: Vec<i64> = s
            .balls
            .iter()
            .flat_map(|b| [b.image.0, b.image.1])
            .collect();
        d.set_item(
            "image",
            PyArray1::from_vec(py, image).reshape([s.balls.len(), 2])?,
        )?;
        out.append(d)?;
    }
    Ok(out)
}

/// The table's geometry as a dict: `cushions` and `pockets` as `(M, 4)` arrays of segment ends
/// (x0, y0, x1, y1), and the bounding box `lo`, `hi`.
pub fn table_dict<'py>(py: Python<'py>, table: &Table) -> PyResult<Bound<'py, PyDict>> {
    let segments = |v: Vec<(Vec2, Vec2)>| -> PyResult<Bound<'py, PyAny>> {
        let n = v.len();
        let flat: Vec<f64> = v.iter().flat_map(|(a, b)| [a.x, a.y, b.x, b.y]).collect();
        Ok(PyArray1::from_vec(py, flat).reshape([n, 4])?.into_any())
    };
    let d = PyDict::new(py);
    d.set_item(
        "cushions",
        segments(table.cushions.iter().map(|c| (c.0, c.1)).collect())?,
    )?;
    d.set_item("pockets", segments(table.pockets.clone())?)?;
    d.set_item("lo", (table.lo.x, table.lo.y))?;
    d.set_item("hi", (table.hi.x, table.hi.y))?;
    d.set_item("periodic", table.period.is_some())?;
    Ok(d)
}
