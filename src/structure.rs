//! Structure and transport observed at a run's sample times (`poolsim run --observe
//! gr,msd,psi6 --sample-every DT`): the pair correlation function g(r) averaged over the
//! samples, the mean squared displacement from the first sample, and the hexatic order ψ6 of
//! each sample.
//!
//! - **g(r)**: every pair of disks on the table closer than `r_max`, counted in `bins` shells
//!   and divided by what an ideal gas of the same density would put there. In a periodic box
//!   every disk is a reference and distances are to the nearest image (`r_max` at most half the
//!   shorter side); on a walled table only disks at least `r_max` inside the table's box are
//!   references, so that every shell around them lies inside it.
//! - **MSD**: the mean over the disks of `|r(t) − r(t₀)|²`, `t₀` the first sample's time, with
//!   positions unwrapped by the samples' images in a periodic box (a wall bounds it otherwise).
//! - **ψ6**: each disk's `(1/6) Σ exp(6iθ)` over its six nearest neighbours (nearest images in
//!   a periodic box), and the magnitude of their mean.
//!
//! Neighbours are found in a cell list built afresh at each sample, so a sample costs O(N).

use crate::engine::{Event, Frame, Observer, RunError, Table, World};
use crate::geometry::{PeriodicBox, Vec2};

/// Which structural observables to take.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wanted {
    /// The pair correlation function.
    pub gr: bool,
    /// The mean squared displacement.
    pub msd: bool,
    /// The hexatic order.
    pub psi6: bool,
}

impl Wanted {
    /// Parses a comma-separated list of `gr`, `msd`, `psi6` (and `pressure`, which the block
    /// observables give and which is accepted and left to them).
    pub fn parse(list: &[String]) -> Result<Wanted, String> {
        let mut w = Wanted::default();
        for name in list {
            match name.trim() {
                "gr" => w.gr = true,
                "msd" => w.msd = true,
                "psi6" => w.psi6 = true,
                "pressure" => {}
                other => {
                    return Err(format!(
                        "--observe: gr, msd, psi6 or pressure, comma separated; got {other:?}"
                    ))
                }
            }
        }
        Ok(w)
    }
}

/// g(r): the shells' centres and the values there.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PairCorrelation {
    /// The shells' centres.
    pub r: Vec<f64>,
    /// g at each.
    pub g: Vec<f64>,
    /// Samples averaged.
    pub samples: usize,
}

/// A quantity at each sample time.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Series {
    /// The sample times (for the MSD, since the first sample).
    pub t: Vec<f64>,
    /// The values.
    pub value: Vec<f64>,
}

/// What the structural observables came to (the summary's `structure`).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StructureFigures {
    /// g(r), averaged over the samples.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gr: Option<PairCorrelation>,
    /// The mean squared displacement since the first sample.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub msd: Option<Series>,
    /// |⟨ψ6⟩| at each sample.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub psi6: Option<Series>,
}

/// Takes the structural observables at each frame from `from` on: an [`Observer`].
pub struct Structure {
    wanted: Wanted,
    from: f64,
    r_max: f64,
    counts: Vec<f64>,
    /// Reference disks and density summed over the samples, for g's normalisation.
    norm: f64,
    gr_samples: usize,
    first: Option<(f64, Vec<Vec2>)>,
    msd: Series,
    psi6: Series,
}

/// Shells of g(r).
const BINS: usize = 100;

impl Structure {
    /// The observables `wanted` of a run on `table` from `from` on, g(r) out to `r_max`
    /// (checked: positive, and at most half a periodic box's shorter side).
    pub fn new(wanted: Wanted, table: &Table, from: f64, r_max: f64) -> Result<Structure, String> {
        let size = table.hi - table.lo;
        if !(r_max.is_finite() && r_max > 0.0) {
            return Err(format!("--gr-max: must be a positive number, got {r_max}"));
        }
        if table.period.is_some() && r_max > size.x.min(size.y) / 2.0 {
            return Err(format!(
                "--gr-max: at most half the periodic box's shorter side, {}, got {r_max}",
                size.x.min(size.y) / 2.0
            ));
        }
        Ok(Structure {
            wanted,
            from,
            r_max,
            counts: vec![0.0; BINS],
            norm: 0.0,
            gr_samples: 0,
            first: None,
            msd: Series {
                t: Vec::new(),
                value: Vec::new(),
            },
            psi6: Series {
                t: Vec::new(),
                value: Vec::new(),
            },
        })
    }

    /// What the samples came to.
    pub fn finish(self) -> StructureFigures {
        let width = self.r_max / BINS as f64;
        let gr = self.wanted.gr.then(|| {
            let r: Vec<f64> = (0..BINS).map(|k| (k as f64 + 0.5) * width).collect();
            let g = (0..BINS)
                .map(|k| {
                    let (a, b) = (k as f64 * width, (k + 1) as f64 * width);
                    let shell = std::f64::consts::PI * (b * b - a * a);
                    if self.norm > 0.0 {
                        self.counts[k] / (self.norm * shell)
                    } else {
                        0.0
                    }
                })
                .collect();
            PairCorrelation {
                r,
                g,
                samples: self.gr_samples,
            }
        });
        StructureFigures {
            gr,
            msd: self.wanted.msd.then_some(self.msd),
            psi6: self.wanted.psi6.then_some(self.psi6),
        }
    }

    /// Adds one sample's pairs to g(r).
    fn add_pairs(&mut self, cells: &Cells, table: &Table) {
        let density = cells.points.len() as f64 / cells.area;
        let lo = table.lo;
        let hi = table.hi;
        let mut refs = 0usize;
        let inv = BINS as f64 / self.r_max;
        for (i, &p) in cells.points.iter().enumerate() {
            let inside = table.period.is_some()
                || (p.x - lo.x >= self.r_max
                    && hi.x - p.x >= self.r_max
                    && p.y - lo.y >= self.r_max
                    && hi.y - p.y >= self.r_max);
            if !inside {
                continue;
            }
            refs += 1;
            cells.around(i, self.r_max, |_, d| {
                let r = d.norm();
                if r < self.r_max {
                    self.counts[((r * inv) as usize).min(BINS - 1)] += 1.0;
                }
            });
        }
        self.norm += refs as f64 * density;
        self.gr_samples += 1;
    }
}

impl Observer for Structure {
    fn on_event(&mut self, _: &Event, _: &dyn World) -> Result<(), RunError> {
        Ok(())
    }

    fn reads_balls(&self) -> bool {
        false
    }

    fn on_frame(&mut self, frame: &Frame, table: &Table) -> Result<(), RunError> {
        if frame.t < self.from {
            return Ok(());
        }
        let on: Vec<usize> = (0..frame.balls.len())
            .filter(|&i| frame.balls[i].pocket.is_none())
            .collect();
        let points: Vec<Vec2> = on
            .iter()
            .map(|&i| frame.balls[i].position(frame.t))
            .collect();
        if self.wanted.msd {
            let unwrapped: Vec<Vec2> = match &table.period {
                Some(b) => on
                    .iter()
                    .zip(&points)
                    .map(|(&i, &p)| {
                        let [x, y] = frame.images.get(i).copied().unwrap_or([0, 0]);
                        p + b.shift((x as f64, y as f64))
                    })
                    .collect(),
                None => points.clone(),
            };
            let (t0, first) = self.first.get_or_insert((frame.t, unwrapped.clone()));
            let n = first.len().min(unwrapped.len()).max(1);
            let sum: f64 = first
                .iter()
                .zip(&unwrapped)
                .map(|(a, b)| (*b - *a).norm2())
                .sum();
            self.msd.t.push(frame.t - *t0);
            self.msd.value.push(sum / n as f64);
        }
        if self.wanted.gr || self.wanted.psi6 {
            let cells = Cells::new(points, table, self.r_max);
            if self.wanted.gr {
                self.add_pairs(&cells, table);
            }
            if self.wanted.psi6 {
                self.psi6.t.push(frame.t);
                self.psi6.value.push(cells.hexatic());
            }
        }
        Ok(())
    }
}

/// Points in square cells over a table's box; separations go to the nearest image in a periodic
/// box.
struct Cells {
    points: Vec<Vec2>,
    lo: Vec2,
    size: Vec2,
    period: Option<PeriodicBox>,
    side: f64,
    nx: usize,
    ny: usize,
    /// The points of each cell, by cell.
    members: Vec<Vec<u32>>,
    area: f64,
}

impl Cells {
    /// `points` in cells about `reach` wide (no more than 4 N cells).
    fn new(points: Vec<Vec2>, table: &Table, reach: f64) -> Cells {
        let size = table.hi - table.lo;
        let most = (4 * points.len()).max(16) as f64;
        let side = reach.max((size.x * size.y / most).sqrt());
        let nx = ((size.x / side).floor() as usize).max(1);
        let ny = ((size.y / side).floor() as usize).max(1);
        let mut members = vec![Vec::new(); nx * ny];
        let mut c = Cells {
            points,
            lo: table.lo,
            size,
            period: table.period,
            side: (size.x / nx as f64).min(size.y / ny as f64),
            nx,
            ny,
            members: Vec::new(),
            area: size.x * size.y,
        };
        for (i, &p) in c.points.iter().enumerate() {
            let (x, y) = c.cell(p);
            members[y * nx + x].push(i as u32);
        }
        c.members = members;
        c
    }

    fn cell(&self, p: Vec2) -> (usize, usize) {
        let f = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
        (
            f((p.x - self.lo.x) / self.size.x * self.nx as f64, self.nx),
            f((p.y - self.lo.y) / self.size.y * self.ny as f64, self.ny),
        )
    }

    /// Calls `f(j, d)` for every other point `j` whose cell lies within `reach` of point `i`'s
    /// cell, `d` the separation from `i` to it (to its nearest image in a periodic box).
    fn around(&self, i: usize, reach: f64, mut f: impl FnMut(u32, Vec2)) {
        let p = self.points[i];
        let (cx, cy) = self.cell(p);
        let k = (reach / self.side).ceil() as i64;
        // the cells along one axis: a window of 2k + 1 around the point's own, or, where that
        // would wrap onto itself in a periodic box, every cell once
        let span = |c: usize, n: usize| -> Vec<usize> {
            let n = n as i64;
            if self.period.is_some() && 2 * k + 1 >= n {
                (0..n as usize).collect()
            } else {
                (c as i64 - k..=c as i64 + k)
                    .filter_map(|x| {
                        if self.period.is_some() {
                            Some(x.rem_euclid(n) as usize)
                        } else {
                            (0..n).contains(&x).then_some(x as usize)
                        }
                    })
                    .collect()
            }
        };
        let xs = span(cx, self.nx);
        for y in span(cy, self.ny) {
            for &x in &xs {
                for &j in &self.members[y * self.nx + x] {
                    if j as usize != i {
                        let d = self.points[j as usize] - p;
                        f(j, self.period.map_or(d, |b| b.nearest(d)));
                    }
                }
            }
        }
    }

    /// |⟨ψ6⟩| over the points, each over its six nearest neighbours (the search widens until
    /// six are found or it covers the box).
    fn hexatic(&self) -> f64 {
        let n = self.points.len();
        if n < 7 {
            return 0.0;
        }
        let (mut re, mut im) = (0.0, 0.0);
        let widest = self.size.x.max(self.size.y);
        for i in 0..n {
            let mut reach = 1.5 * self.side;
            let near = loop {
                let mut near: Vec<(f64, Vec2)> = Vec::with_capacity(16);
                self.around(i, reach, |_, d| near.push((d.norm2(), d)));
                near.sort_by(|a, b| a.0.total_cmp(&b.0));
                // the sixth is certain once it lies within the reach searched all round
                if near.len() >= 6 && near[5].0.sqrt() <= reach - self.side || reach > widest {
                    break near;
                }
                reach *= 2.0;
            };
            let (mut a, mut b) = (0.0, 0.0);
            for &(_, d) in near.iter().take(6) {
                let theta = 6.0 * d.y.atan2(d.x);
                a += theta.cos();
                b += theta.sin();
            }
            re += a / 6.0;
            im += b / 6.0;
        }
        (re * re + im * im).sqrt() / n as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::BallState;
    use crate::geometry::Trajectory;

    fn table(side: f64, periodic: bool) -> Table {
        Table {
            n_balls: 0,
            cushions: Vec::new(),
            pockets: Vec::new(),
            corners: Vec::new(),
            lo: Vec2::ZERO,
            hi: Vec2::new(side, side),
            period: periodic.then_some(PeriodicBox {
                lo: Vec2::ZERO,
                size: Vec2::new(side, side),
            }),
        }
    }

    fn frame(t: f64, points: &[Vec2], images: Vec<[i64; 2]>) -> Frame {
        Frame {
            t,
            balls: points
                .iter()
                .map(|&p| BallState {
                    traj: Trajectory {
                        position: p,
                        velocity: Vec2::ZERO,
                        t0: t,
                    },
                    radius: 0.1,
                    mass: 1.0,
                    pocket: None,
                })
                .collect(),
            images,
        }
    }

    #[test]
    fn a_triangular_lattice_has_full_hexatic_order_and_its_shells_in_g() {
        // 12 x 12 sites of a triangular lattice do not tile a square, so take a rectangle's
        // worth of rows inside a large walled box: the interior sites have six neighbours
        let mut pts = Vec::new();
        for j in 0..20 {
            for i in 0..20 {
                let x = 10.0 + i as f64 + if j % 2 == 1 { 0.5 } else { 0.0 };
                pts.push(Vec2::new(x, 10.0 + j as f64 * 3f64.sqrt() / 2.0));
            }
        }
        let t = table(40.0, false);
        let w = Wanted {
            gr: true,
            msd: false,
            psi6: true,
        };
        let mut s = Structure::new(w, &t, 0.0, 3.0).unwrap();
        s.on_frame(&frame(0.0, &pts, Vec::new()), &t).unwrap();
        let f = s.finish();
        let psi = f.psi6.unwrap().value[0];
        // edge sites pull it below 1; most are interior
        assert!(psi > 0.8, "psi6 {psi}");
        let gr = f.gr.unwrap();
        // no pair closer than the spacing, a peak at it
        let k1 = gr.r.iter().position(|&r| r > 0.98).unwrap();
        assert!(gr.g[..k1 - 1].iter().all(|&g| g == 0.0));
        assert!(gr.g[k1 - 1..k1 + 2].iter().any(|&g| g > 3.0));
    }

    #[test]
    fn uniform_points_in_a_periodic_box_have_g_near_one_and_msd_unwraps() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let side = 30.0;
        let pts: Vec<Vec2> = (0..4000)
            .map(|_| Vec2::new(rng.gen_range(0.0..side), rng.gen_range(0.0..side)))
            .collect();
        let t = table(side, true);
        let w = Wanted {
            gr: true,
            msd: true,
            psi6: true,
        };
        let mut s = Structure::new(w, &t, 0.0, 5.0).unwrap();
        s.on_frame(&frame(0.0, &pts, vec![[0, 0]; pts.len()]), &t)
            .unwrap();
        // every point one side further along x, in the same place in the box
        s.on_frame(&frame(1.0, &pts, vec![[1, 0]; pts.len()]), &t)
            .unwrap();
        let f = s.finish();
        let gr = f.gr.unwrap();
        let mean: f64 = gr.g[20..].iter().sum::<f64>() / (gr.g.len() - 20) as f64;
        assert!((mean - 1.0).abs() < 0.02, "g {mean}");
        assert_eq!(gr.samples, 2);
        let msd = f.msd.unwrap();
        assert_eq!(msd.t, vec![0.0, 1.0]);
        assert_eq!(msd.value[0], 0.0);
        assert!((msd.value[1] - side * side).abs() < 1e-9);
        // random points have no hexatic order to speak of
        assert!(f.psi6.unwrap().value.iter().all(|&p| p < 0.05));
        assert!(Structure::new(w, &t, 0.0, 16.0).is_err());
        assert!(Wanted::parse(&["gr".into(), "nope".into()]).is_err());
    }
}
