//! Property tests of polygon sectors (thesis 5.1): sector entry and departure times of a moving disk
//! against a brute-force oracle that samples the trajectory densely, for convex and non-convex
//! polygons; grid layouts, layout validation and adjacency.

use poolsim::geometry::{Trajectory, Vec2};
use poolsim::polygon::{
    adjacency, departure_time, entry_time, grid, touch_intervals, touches, validate_layout, Polygon,
};
use proptest::prelude::*;
use std::f64::consts::TAU;

/// Samples of the trajectory the oracle looks at.
const STEPS: usize = 20_000;

// ---------------------------------------------------------------------------------------------
// The oracle: its own point-in-polygon and segment distance, nothing from the library.

fn seg_dist(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.norm2()).clamp(0.0, 1.0);
    (p - (a + t * ab)).norm()
}

fn inside(pts: &[Vec2], p: Vec2) -> bool {
    let mut c = false;
    for k in 0..pts.len() {
        let (a, b) = (pts[k], pts[(k + 1) % pts.len()]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if p.x < x {
                c = !c;
            }
        }
    }
    c
}

/// Distance from `p` to the closed polygon (0 inside).
fn dist(pts: &[Vec2], p: Vec2) -> f64 {
    if inside(pts, p) {
        return 0.0;
    }
    (0..pts.len())
        .map(|k| seg_dist(p, pts[k], pts[(k + 1) % pts.len()]))
        .fold(f64::INFINITY, f64::min)
}

/// What the oracle sees at one sample: touching, not touching, or too close to call.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Seen {
    In,
    Out,
    Edge,
}

/// A polygon, a trajectory, a radius, and the window `[after, end]` outside of which (after `end`)
/// the disk can no longer touch the polygon.
#[derive(Clone, Debug)]
struct Case {
    pts: Vec<Vec2>,
    poly: Polygon,
    traj: Trajectory,
    r: f64,
    after: f64,
    end: f64,
    /// Distances within this of `r` are too close to call (relative 1e-9 of the coordinates).
    tol: f64,
}

impl Case {
    fn times(&self) -> impl Iterator<Item = f64> + '_ {
        (0..=STEPS).map(|k| self.after + (self.end - self.after) * (k as f64 / STEPS as f64))
    }

    fn dt(&self) -> f64 {
        (self.end - self.after) / STEPS as f64
    }

    fn d(&self, t: f64) -> f64 {
        dist(&self.pts, self.traj.at(t))
    }

    fn seen(&self, t: f64) -> Seen {
        let d = self.d(t);
        if (d - self.r).abs() <= self.tol {
            Seen::Edge
        } else if d < self.r {
            Seen::In
        } else {
            Seen::Out
        }
    }

    fn samples(&self) -> Vec<(f64, Seen)> {
        self.times().map(|t| (t, self.seen(t))).collect()
    }

    /// Whether the function's contact `[a, b]` fits between two samples, so the oracle could not
    /// see it; it must still be a real contact.
    fn unseen_graze(&self, a: f64, b: f64) -> bool {
        let dt = self.dt();
        let ka = ((a - self.after) / dt).floor();
        let kb = ((b - self.after) / dt).floor();
        ka == kb && self.d(0.5 * (a + b)) <= self.r + self.tol
    }
}

// ---------------------------------------------------------------------------------------------
// Strategies

fn sorted_angles(n: std::ops::Range<usize>) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(0.0..TAU, n).prop_filter_map("angles too close", |mut a| {
        a.sort_by(f64::total_cmp);
        let n = a.len();
        let ok = (0..n).all(|k| {
            let next = if k + 1 < n { a[k + 1] } else { a[0] + TAU };
            next - a[k] > 0.05
        });
        ok.then_some(a)
    })
}

/// Points on a circle in angle order: a convex polygon.
fn convex() -> impl Strategy<Value = Vec<Vec2>> {
    (
        sorted_angles(3..10),
        -5.0..5.0f64,
        -5.0..5.0f64,
        2.0..10.0f64,
    )
        .prop_map(|(angles, cx, cy, rad)| {
            angles
                .iter()
                .map(|a| Vec2::new(cx + rad * a.cos(), cy + rad * a.sin()))
                .collect()
        })
}

/// Points at random distances in angle order: a star-shaped, usually non-convex polygon.
fn star() -> impl Strategy<Value = Vec<Vec2>> {
    (sorted_angles(3..14), -5.0..5.0f64, -5.0..5.0f64)
        .prop_flat_map(|(angles, cx, cy)| {
            let n = angles.len();
            (
                Just(angles),
                Just(cx),
                Just(cy),
                prop::collection::vec(1.0..10.0f64, n),
            )
        })
        .prop_map(|(angles, cx, cy, radii)| {
            angles
                .iter()
                .zip(&radii)
                .map(|(a, rad)| Vec2::new(cx + rad * a.cos(), cy + rad * a.sin()))
                .collect()
        })
}

/// An L: a rectangle with a corner cut out, axis-aligned or turned.
fn l_shape() -> impl Strategy<Value = Vec<Vec2>> {
    (
        2.0..15.0f64,
        2.0..15.0f64,
        0.2..0.8f64,
        0.2..0.8f64,
        prop_oneof![Just(0.0), 0.0..TAU],
        -8.0..2.0f64,
        -8.0..2.0f64,
    )
        .prop_map(|(w, h, fa, fb, rot, ox, oy)| {
            let (a, b) = (fa * h, fb * w);
            let (c, s) = if rot == 0.0 {
                (1.0, 0.0)
            } else {
                (rot.cos(), rot.sin())
            };
            [(0.0, 0.0), (w, 0.0), (w, a), (b, a), (b, h), (0.0, h)]
                .iter()
                .map(|&(x, y)| Vec2::new(ox + c * x - s * y, oy + s * x + c * y))
                .collect()
        })
}

/// A comb: teeth standing on a base, axis-aligned or turned; a straight path across the teeth
/// touches it several times.
fn comb() -> impl Strategy<Value = Vec<Vec2>> {
    (
        2usize..6,
        0.5..4.0f64,
        0.5..6.0f64,
        0.5..3.0f64,
        1.0..10.0f64,
        prop_oneof![Just(0.0), 0.0..TAU],
        (-10.0..0.0f64, -10.0..0.0f64),
    )
        .prop_map(|(k, wt, wg, hb, ht, rot, (ox, oy))| {
            let width = k as f64 * wt + (k - 1) as f64 * wg;
            let top = hb + ht;
            let mut pts = vec![(0.0, 0.0), (width, 0.0)];
            for i in (0..k).rev() {
                let xl = i as f64 * (wt + wg);
                pts.push((xl + wt, top));
                pts.push((xl, top));
                if i > 0 {
                    pts.push((xl, hb));
                    pts.push((xl - wg, hb));
                }
            }
            let (c, s) = if rot == 0.0 {
                (1.0, 0.0)
            } else {
                (rot.cos(), rot.sin())
            };
            pts.iter()
                .map(|&(x, y)| Vec2::new(ox + c * x - s * y, oy + s * x + c * y))
                .collect()
        })
}

/// An axis-aligned rectangle, like a grid sector.
fn rectangle() -> impl Strategy<Value = Vec<Vec2>> {
    (-10.0..0.0f64, -10.0..0.0f64, 1.0..12.0f64, 1.0..12.0f64).prop_map(|(x, y, w, h)| {
        vec![
            Vec2::new(x, y),
            Vec2::new(x + w, y),
            Vec2::new(x + w, y + h),
            Vec2::new(x, y + h),
        ]
    })
}

fn polygon() -> impl Strategy<Value = (Vec<Vec2>, Polygon)> {
    (
        prop_oneof![
            1 => convex(),
            2 => star(),
            1 => l_shape(),
            2 => comb(),
            1 => rectangle(),
        ],
        any::<bool>(),
    )
        .prop_filter_map("not a simple polygon", |(mut pts, reverse)| {
            if reverse {
                pts.reverse();
            }
            let poly = Polygon::new(pts.clone()).ok()?;
            Some((pts, poly))
        })
}

fn case() -> impl Strategy<Value = Case> {
    (
        polygon(),
        (-30.0..30.0f64, -30.0..30.0f64),
        // aim at a point of the polygon's box (most cases), or go along an axis, or anywhere
        prop_oneof![
            2 => (0.0..1.0f64, 0.0..1.0f64).prop_map(Some),
            1 => Just(None),
        ],
        prop_oneof![
            (0.0..TAU).prop_map(|a| (a.cos(), a.sin())),
            prop::sample::select(vec![(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)]),
        ],
        5.0..80.0f64,
        -3.0..3.0f64,
        prop_oneof![Just(0.0), 0.0..4.0f64],
        -1.0..0.3f64,
    )
        .prop_map(|((pts, poly), (x, y), aim, dir, speed, t0, r, after)| {
            let (c, s) = match (aim, dir) {
                (Some((fx, fy)), _) => {
                    let (lo, hi) = poly.bounds();
                    let target = Vec2::new(lo.x + fx * (hi.x - lo.x), lo.y + fy * (hi.y - lo.y));
                    let d = target - Vec2::new(x, y);
                    let n = d.norm().max(1e-9);
                    (d.x / n, d.y / n)
                }
                (None, dir) => dir,
            };
            let traj = Trajectory {
                position: Vec2::new(x, y),
                velocity: Vec2::new(speed * c, speed * s),
                t0,
            };
            let after = t0 + after;
            let (lo, hi) = poly.bounds();
            let centre = 0.5 * (lo + hi);
            let reach = 0.5 * (hi - lo).norm() + r + 1.0;
            let end = after + ((traj.at(after) - centre).norm() + reach) / speed;
            let scale = pts
                .iter()
                .chain([traj.position].iter())
                .map(|p| p.x.abs().max(p.y.abs()))
                .fold(r, f64::max)
                .max(1.0);
            Case {
                pts,
                poly,
                traj,
                r,
                after,
                end,
                tol: 1e-9 * scale,
            }
        })
}

// ---------------------------------------------------------------------------------------------
// Entry and departure against the oracle

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Every sample the oracle can call is inside a contact interval exactly when it touches.
    #[test]
    fn touch_intervals_match_dense_sampling(c in case()) {
        let iv = touch_intervals(&c.poly, &c.traj, c.r);
        for w in iv.windows(2) {
            prop_assert!(w[0].1 < w[1].0, "intervals not disjoint and ascending: {iv:?}");
        }
        for (t, seen) in c.samples() {
            let f = iv.iter().any(|&(a, b)| a <= t && t <= b);
            match seen {
                Seen::In => prop_assert!(f, "oracle touches at t = {t}, intervals {iv:?}"),
                Seen::Out => prop_assert!(!f, "oracle apart at t = {t}, intervals {iv:?}"),
                Seen::Edge => {}
            }
        }
    }

    /// The entry time is the oracle's first transition from apart to touching, within a sample.
    #[test]
    fn entry_matches_oracle(c in case()) {
        let got = entry_time(&c.poly, &c.traj, c.r, c.after);
        let samples = c.samples();
        let dt = c.dt();
        match samples[0].1 {
            Seen::Edge => return Ok(()), // touching at `after` is too close to call
            Seen::In => {
                prop_assert_eq!(got, None, "touching at `after` is no entry");
                return Ok(());
            }
            Seen::Out => {}
        }
        let first_not_out = samples.iter().position(|s| s.1 != Seen::Out);
        let first_in = samples.iter().position(|s| s.1 == Seen::In);
        match (got, first_in) {
            (None, None) => {}
            (None, Some(k)) => prop_assert!(false, "no entry, but the oracle touches at {}", samples[k].0),
            (Some(te), first_in) => {
                prop_assert!(te > c.after);
                if let Some(k) = first_in {
                    prop_assert!(te <= samples[k].0 + 1e-9 * dt, "entry {te} after sample {}", samples[k].0);
                }
                let earliest = samples[first_not_out.unwrap_or(STEPS).max(1) - 1].0;
                if te < earliest - 1e-9 * dt {
                    // only a contact shorter than a sample step can hide from the oracle
                    let iv = touch_intervals(&c.poly, &c.traj, c.r);
                    let &(a, b) = iv.iter().find(|iv| iv.0 == te).unwrap();
                    prop_assert!(c.unseen_graze(a, b), "entry {te} long before the oracle's {earliest}");
                }
            }
        }
    }

    /// The departure time is the oracle's last transition from touching to apart, within a sample.
    #[test]
    fn departure_matches_oracle(c in case()) {
        let got = departure_time(&c.poly, &c.traj, c.r, c.after);
        let samples = c.samples();
        let dt = c.dt();
        prop_assert_eq!(samples[STEPS].1, Seen::Out);
        let last_not_out = samples.iter().rposition(|s| s.1 != Seen::Out);
        let last_in = samples.iter().rposition(|s| s.1 == Seen::In);
        match (got, last_in) {
            (None, None) => {}
            (None, Some(k)) => prop_assert!(false, "no departure, but the oracle touches at {}", samples[k].0),
            (Some(td), last_in) => {
                prop_assert!(td >= c.after);
                if let Some(k) = last_in {
                    prop_assert!(td >= samples[k].0 - 1e-9 * dt, "departure {td} before sample {}", samples[k].0);
                }
                let latest = samples[last_not_out.map_or(0, |k| k + 1)].0;
                if td > latest + 1e-9 * dt {
                    let iv = touch_intervals(&c.poly, &c.traj, c.r);
                    let &(a, b) = iv.last().unwrap();
                    prop_assert!(c.unseen_graze(a.max(c.after), b), "departure {td} long after the oracle's {latest}");
                }
            }
        }
    }

    /// At the entry the disk's edge is exactly on the polygon, and it was apart just before (and at
    /// every sample since `after`); at the departure likewise, and it stays apart afterwards.
    #[test]
    fn distance_is_r_at_entry_and_departure(c in case()) {
        let h = 1e-7 * (c.end - c.after);
        let noise = 1e-12 * c.tol / 1e-9;
        if let Some(te) = entry_time(&c.poly, &c.traj, c.r, c.after) {
            let d = c.d(te);
            prop_assert!((d - c.r).abs() <= c.tol, "distance {d} at entry, r = {}", c.r);
            if te - h > c.after {
                let before = c.d(te - h);
                prop_assert!(before > c.r - noise, "distance {before} just before entry, r = {}", c.r);
            }
            for t in c.times().take_while(|&t| t < te) {
                prop_assert!(c.seen(t) != Seen::In, "touching at {t} before the entry {te}");
            }
            prop_assert!(touches(&c.poly, c.traj.at(te), c.r + c.tol));
        }
        if let Some(td) = departure_time(&c.poly, &c.traj, c.r, c.after) {
            let d = c.d(td);
            prop_assert!((d - c.r).abs() <= c.tol, "distance {d} at departure, r = {}", c.r);
            let after = c.d(td + h);
            prop_assert!(after > c.r - noise, "distance {after} just after departure, r = {}", c.r);
            for t in c.times().filter(|&t| t > td) {
                prop_assert!(c.seen(t) != Seen::In, "touching at {t} after the departure {td}");
            }
            // departure never comes before the entry
            if let Some(te) = entry_time(&c.poly, &c.traj, c.r, c.after) {
                prop_assert!(te <= td);
            }
        }
    }

    /// Entry and departure agree with the contact intervals, for any `after`.
    #[test]
    fn entry_and_departure_follow_the_intervals(c in case(), shift in -2.0..2.0f64) {
        let after = c.after + shift;
        let iv = touch_intervals(&c.poly, &c.traj, c.r);
        let touching_now = iv.iter().any(|&(a, b)| a <= after && after <= b);
        let next = iv.iter().find(|&&(a, _)| a > after).map(|iv| iv.0);
        let expected_entry = if touching_now { None } else { next };
        prop_assert_eq!(entry_time(&c.poly, &c.traj, c.r, after), expected_entry);
        let expected_departure = iv.last().map(|iv| iv.1).filter(|&b| b >= after);
        prop_assert_eq!(departure_time(&c.poly, &c.traj, c.r, after), expected_departure);
    }

    /// A disk at rest never enters or departs.
    #[test]
    fn a_resting_disk_neither_enters_nor_departs((_, poly) in polygon(), x in -20.0..20.0f64, y in -20.0..20.0f64, r in 0.0..3.0f64) {
        let traj = Trajectory { position: Vec2::new(x, y), velocity: Vec2::ZERO, t0: 0.0 };
        prop_assert_eq!(entry_time(&poly, &traj, r, 0.0), None);
        prop_assert_eq!(departure_time(&poly, &traj, r, 0.0), None);
        let iv = touch_intervals(&poly, &traj, r);
        prop_assert_eq!(iv.len(), usize::from(touches(&poly, traj.position, r)));
    }

    /// For a grid sector and a ball moving along an axis through its straight side, the entry and
    /// departure are the correctly rounded `t0 + ((edge − p) ∓ r) / v`.
    #[test]
    fn axis_aligned_times_are_correctly_rounded(
        nx in 1u32..8, ny in 1u32..8, i in 0u32..8, j in 0u32..8, frac in 0.01..0.99f64,
        far in 1.0..50.0f64, speed in 0.1..100.0f64, r in 0.0..5.0f64, t0 in -10.0..10.0f64,
        dir in 0u8..4,
    ) {
        let (lo, hi) = (Vec2::new(-3.7, 1.3), Vec2::new(611.1, 287.9));
        let g = grid(lo, hi, nx, ny);
        let sector = &g[((j % ny) * nx + i % nx) as usize];
        let (a, b) = sector.bounds();
        let (p, v, first, last, sign) = match dir {
            0 => (Vec2::new(a.x - r - far, a.y + frac * (b.y - a.y)), Vec2::new(speed, 0.0), a.x, b.x, 1.0),
            1 => (Vec2::new(b.x + r + far, a.y + frac * (b.y - a.y)), Vec2::new(-speed, 0.0), b.x, a.x, -1.0),
            2 => (Vec2::new(a.x + frac * (b.x - a.x), a.y - r - far), Vec2::new(0.0, speed), a.y, b.y, 1.0),
            _ => (Vec2::new(a.x + frac * (b.x - a.x), b.y + r + far), Vec2::new(0.0, -speed), b.y, a.y, -1.0),
        };
        let (pc, vc) = if dir < 2 { (p.x, v.x) } else { (p.y, v.y) };
        let traj = Trajectory { position: p, velocity: v, t0 };
        let entry = t0 + ((first - pc) - sign * r) / vc;
        let departure = t0 + ((last - pc) + sign * r) / vc;
        prop_assert_eq!(entry_time(sector, &traj, r, t0), Some(entry));
        prop_assert_eq!(departure_time(sector, &traj, r, t0), Some(departure));
    }
}

// ---------------------------------------------------------------------------------------------
// Layouts

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A grid covers its box exactly, numbered from the bottom left along x first, and is a valid
    /// layout; every point of the box lies in a sector.
    #[test]
    fn grid_covers_and_validates(
        x in -1000.0..1000.0f64, y in -1000.0..1000.0f64, w in 0.1..2000.0f64, h in 0.1..2000.0f64,
        nx in 1u32..30, ny in 1u32..30, probes in prop::collection::vec((0.0..=1.0f64, 0.0..=1.0f64), 20),
    ) {
        let (lo, hi) = (Vec2::new(x, y), Vec2::new(x + w, y + h));
        let g = grid(lo, hi, nx, ny);
        prop_assert_eq!(g.len(), (nx * ny) as usize);
        prop_assert!(validate_layout(&g, lo, hi).is_ok(), "{:?}", validate_layout(&g, lo, hi));
        prop_assert_eq!(g[0].bounds().0, lo);
        prop_assert_eq!(g.last().unwrap().bounds().1, hi);
        prop_assert_eq!(g[(nx - 1) as usize].bounds().1.x, hi.x);
        prop_assert_eq!(g[(nx - 1) as usize].bounds().0.y, lo.y);
        let total: f64 = g.iter().map(Polygon::area).sum();
        prop_assert!((total - w * h).abs() <= 1e-9 * w * h);
        for (fx, fy) in probes {
            let p = Vec2::new(x + fx * w, y + fy * h);
            prop_assert!(g.iter().any(|s| s.contains(p)), "{p:?} in no sector");
        }
        // neighbours along x share bit-identical edges
        for s in 0..g.len() {
            if !(s as u32 + 1).is_multiple_of(nx) {
                prop_assert_eq!(g[s].bounds().1.x, g[s + 1].bounds().0.x);
            }
        }
    }

    /// Taking a sector away, shrinking one, or growing one into its neighbour is rejected with a
    /// message that names what is wrong.
    #[test]
    fn gaps_and_overlaps_are_rejected(nx in 2u32..12, ny in 2u32..12, pick in 0usize..1000, f in 0.05..0.95f64) {
        let (lo, hi) = (Vec2::new(0.0, 0.0), Vec2::new(1200.0, 600.0));
        let g = grid(lo, hi, nx, ny);
        let k = pick % g.len();
        let mut missing = g.clone();
        missing.remove(k);
        let e = validate_layout(&missing, lo, hi).unwrap_err().to_string();
        prop_assert!(e.starts_with("the sectors leave ") && e.ends_with(" of the table's area uncovered"), "{e}");
        // shrink sector k from its top edge
        let (a, b) = g[k].bounds();
        let top = a.y + f * (b.y - a.y);
        let mut shrunk = g.clone();
        shrunk[k] = Polygon::new(vec![a, Vec2::new(b.x, a.y), Vec2::new(b.x, top), Vec2::new(a.x, top)]).unwrap();
        let e = validate_layout(&shrunk, lo, hi).unwrap_err().to_string();
        prop_assert!(e.contains("uncovered"), "{e}");
        // grow sector k into its right (or left) neighbour
        let col = k as u32 % nx;
        let mut grown = g.clone();
        let other = if col + 1 < nx {
            let (_, nb) = g[k + 1].bounds();
            let x = b.x + f * (nb.x - b.x);
            grown[k] = Polygon::new(vec![a, Vec2::new(x, a.y), Vec2::new(x, b.y), Vec2::new(a.x, b.y)]).unwrap();
            k + 1
        } else {
            let (na, _) = g[k - 1].bounds();
            let x = a.x - f * (a.x - na.x);
            grown[k] = Polygon::new(vec![Vec2::new(x, a.y), Vec2::new(b.x, a.y), b, Vec2::new(x, b.y)]).unwrap();
            k - 1
        };
        let e = validate_layout(&grown, lo, hi).unwrap_err().to_string();
        prop_assert_eq!(
            e,
            format!("sectors.polygon[{}] overlaps sectors.polygon[{}]", k.min(other) + 1, k.max(other) + 1)
        );
    }

    /// A grid with every cell cut along a diagonal (either one) is a valid layout, and its
    /// adjacency is the brute-force one.
    #[test]
    fn triangulated_grid_is_valid(nx in 1u32..7, ny in 1u32..7, cuts in prop::collection::vec(any::<bool>(), 49), clockwise in any::<bool>()) {
        let (lo, hi) = (Vec2::new(-2.0, -1.0), Vec2::new(3.1, 1.7));
        let mut tris = Vec::new();
        for (k, cell) in grid(lo, hi, nx, ny).iter().enumerate() {
            let [a, b, c, d] = [cell.points[0], cell.points[1], cell.points[2], cell.points[3]];
            let (t1, t2) = if cuts[k] { (vec![a, b, c], vec![a, c, d]) } else { (vec![a, b, d], vec![b, c, d]) };
            for mut t in [t1, t2] {
                if clockwise {
                    t.reverse();
                }
                tris.push(Polygon::new(t).unwrap());
            }
        }
        prop_assert!(validate_layout(&tris, lo, hi).is_ok(), "{:?}", validate_layout(&tris, lo, hi));
        let adj = adjacency(&tris, 1e-9);
        for i in 0..tris.len() {
            let brute: Vec<u32> = (0..tris.len())
                .filter(|&j| j != i && boundaries_meet(&tris[i], &tris[j]))
                .map(|j| j as u32)
                .collect();
            prop_assert_eq!(&adj[i], &brute, "neighbours of triangle {}", i);
        }
        // a triangle overlapping its cell's partner is caught
        let mut bad = tris.clone();
        let cell = &grid(lo, hi, nx, ny)[0];
        bad.push(Polygon::new(vec![cell.points[0], cell.points[1], cell.points[2]]).unwrap());
        bad.push(Polygon::new(vec![cell.points[1], cell.points[2], cell.points[3]]).unwrap());
        let e = validate_layout(&bad, lo, hi).unwrap_err().to_string();
        prop_assert!(e.contains("overlaps"), "{}", e);
    }
}

/// Brute force: do two triangles' boundaries share a point (exactly, for grid-made coordinates)?
fn boundaries_meet(a: &Polygon, b: &Polygon) -> bool {
    let edges = |p: &Polygon| -> Vec<(Vec2, Vec2)> {
        (0..p.points.len())
            .map(|k| (p.points[k], p.points[(k + 1) % p.points.len()]))
            .collect()
    };
    edges(a).iter().any(|&(p, q)| {
        edges(b).iter().any(|&(c, d)| {
            seg_dist(p, c, d) <= 1e-9
                || seg_dist(q, c, d) <= 1e-9
                || seg_dist(c, p, q) <= 1e-9
                || seg_dist(d, p, q) <= 1e-9
                || crosses(p, q, c, d)
        })
    })
}

fn crosses(p: Vec2, q: Vec2, c: Vec2, d: Vec2) -> bool {
    let o = |a: Vec2, b: Vec2, x: Vec2| (b - a).cross(x - a);
    o(p, q, c) * o(p, q, d) < 0.0 && o(c, d, p) * o(c, d, q) < 0.0
}

#[test]
fn adjacency_of_a_3x3_grid() {
    let g = grid(Vec2::new(0.0, 0.0), Vec2::new(900.0, 900.0), 3, 3);
    let adj = adjacency(&g, 1e-6);
    assert_eq!(adj[4].len(), 8, "the centre sector");
    for corner in [0, 2, 6, 8] {
        assert_eq!(adj[corner].len(), 3, "corner sector {corner}");
    }
    for side in [1, 3, 5, 7] {
        assert_eq!(adj[side].len(), 5, "side sector {side}");
    }
    assert_eq!(adj[0], vec![1, 3, 4]);
    assert_eq!(adj[4], vec![0, 1, 2, 3, 5, 6, 7, 8]);
}

#[test]
fn adjacency_and_validation_of_a_300x300_grid() {
    // 90,000 sectors: quadratic work would take minutes
    let n = 300u32;
    let (lo, hi) = (Vec2::new(0.0, 0.0), Vec2::new(3000.0, 1500.0));
    let g = grid(lo, hi, n, n);
    let start = std::time::Instant::now();
    let adj = adjacency(&g, 1e-6);
    validate_layout(&g, lo, hi).unwrap();
    let elapsed = start.elapsed();
    for (k, list) in adj.iter().enumerate() {
        let (i, j) = (k as u32 % n, k as u32 / n);
        let edge = |c: u32| c == 0 || c == n - 1;
        let expected = match (edge(i), edge(j)) {
            (true, true) => 3,
            (true, false) | (false, true) => 5,
            (false, false) => 8,
        };
        assert_eq!(list.len(), expected, "sector {k}");
        for &m in list {
            let (mi, mj) = (m % n, m / n);
            assert!(mi.abs_diff(i) <= 1 && mj.abs_diff(j) <= 1);
        }
    }
    assert!(elapsed.as_secs() < 60, "took {elapsed:?}");
}

#[test]
fn non_grid_layouts() {
    let (lo, hi) = (Vec2::new(0.0, 0.0), Vec2::new(4.0, 4.0));
    // an L around a square
    let l = Polygon::new(vec![
        Vec2::new(0.0, 0.0),
        Vec2::new(4.0, 0.0),
        Vec2::new(4.0, 1.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(1.0, 4.0),
        Vec2::new(0.0, 4.0),
    ])
    .unwrap();
    let sq = Polygon::new(vec![
        Vec2::new(1.0, 1.0),
        Vec2::new(1.0, 4.0),
        Vec2::new(4.0, 4.0),
        Vec2::new(4.0, 1.0),
    ])
    .unwrap();
    validate_layout(&[l.clone(), sq.clone()], lo, hi).unwrap();
    assert_eq!(
        adjacency(&[l.clone(), sq.clone()], 0.0),
        vec![vec![1], vec![0]]
    );
    // a square too big overlaps the L
    let big = Polygon::new(vec![
        Vec2::new(0.5, 0.5),
        Vec2::new(4.0, 0.5),
        Vec2::new(4.0, 4.0),
        Vec2::new(0.5, 4.0),
    ])
    .unwrap();
    assert_eq!(
        validate_layout(&[l.clone(), big], lo, hi)
            .unwrap_err()
            .to_string(),
        "sectors.polygon[1] overlaps sectors.polygon[2]"
    );
    // T-junctions: a left half against two right quarters
    let rect = |x0: f64, y0: f64, x1: f64, y1: f64| {
        Polygon::new(vec![
            Vec2::new(x0, y0),
            Vec2::new(x1, y0),
            Vec2::new(x1, y1),
            Vec2::new(x0, y1),
        ])
        .unwrap()
    };
    let t = [
        rect(0.0, 0.0, 2.0, 4.0),
        rect(2.0, 0.0, 4.0, 2.0),
        rect(2.0, 2.0, 4.0, 4.0),
    ];
    validate_layout(&t, lo, hi).unwrap();
    assert_eq!(adjacency(&t, 0.0), vec![vec![1, 2], vec![0, 2], vec![0, 1]]);
    // a sector nested inside another
    let nested = [rect(0.0, 0.0, 4.0, 4.0), rect(1.0, 1.0, 2.0, 2.0)];
    assert_eq!(
        validate_layout(&nested, lo, hi).unwrap_err().to_string(),
        "sectors.polygon[1] overlaps sectors.polygon[2]"
    );
    // shared edges that differ by rounding are fine
    let third = 4.0 / 3.0;
    let wobbly = [
        rect(0.0, 0.0, third, 4.0),
        rect(third * (1.0 + 1e-15), 0.0, 4.0, 4.0),
    ];
    validate_layout(&wobbly, lo, hi).unwrap();
    // a sector reaching off the table
    let e = validate_layout(&[rect(0.0, 0.0, 4.0, 4.5)], lo, hi)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("sectors.polygon[1] reaches outside the table"),
        "{e}"
    );
}
