//! Sectors of any polygon shape (thesis ch. 5 and 5.1): pure plane geometry, no engine code.
//!
//! The thesis keeps a sector's perimeter as the list of its corners, which makes the sectored
//! algorithm work for any polygon, not only for a grid of rectangles. This module holds:
//!
//! - [`Polygon`]: a simple polygon (validated by [`Polygon::new`]) with area, containment,
//!   bounding box and distance;
//! - [`grid`]: the common layout of `nx` × `ny` equal rectangles;
//! - [`validate_layout`]: do the sectors tile the table, with no gap and no overlap?
//! - [`adjacency`]: which sectors a ball can pass between (sharing an edge or only a corner);
//! - [`entry_time`], [`departure_time`], [`touch_intervals`], [`touches`]: when a disk moving on a
//!   straight [`Trajectory`] starts and stops touching a sector (thesis 5.1).
//!
//! ## Touching, entry and departure
//!
//! A disk of radius `r` *touches* a polygon when the distance from its centre to the closed polygon
//! (zero inside) is at most `r`: its centre lies in the polygon dilated by `r`, a rounded polygon
//! whose sides are the edges pushed out by `r` and whose corners are circular arcs of radius `r`
//! around the vertices. The dilated polygon is the polygon itself together with one capsule (the set
//! within `r` of a segment) per edge. Along a straight line a capsule is met in one interval of
//! time: the times the centre is within `r` of the edge's line and within the edge's extent,
//! together with the times it is within `r` of either end (a circle-crossing quadratic, solved in
//! the cancellation-free form of [`crate::physics`]). The union of these intervals misses only the
//! times the centre is deep inside the polygon; such a stretch is a gap between two intervals whose
//! midpoint lies inside the polygon, and a point-in-polygon test at that midpoint fills it exactly.
//!
//! The thesis schedules the departure at the latest and the entry at the earliest perimeter crossing
//! (5.1). For a convex sector the touching times form one interval; a straight path may leave and
//! re-enter a non-convex sector, and then the entry is the first start and the departure the last
//! end: a sector keeps knowing a ball from its first contact to its last along one trajectory.
//! (DESIGN.md: membership may be conservative, never short.)
//!
//! For an edge parallel to an axis the crossing of an offset line is computed from one subtraction
//! and one division, `τ = (±r − (p − a)·n) / (v·n)` with `n` exactly a unit axis vector, so grid
//! sectors get correctly rounded times.

use crate::geometry::{segment_distance2, Trajectory, Vec2};
use smallvec::SmallVec;

/// A sector's perimeter: a simple polygon given by its corners in order, either orientation, and
/// implicitly closed (the last corner joins the first).
///
/// Build it with [`Polygon::new`], which checks it; the fields stay public so that callers that
/// know their polygon is good (as [`grid`] does) can build it directly.
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    /// The corners in order (length), clockwise or counter-clockwise, without repeating the first.
    pub points: Vec<Vec2>,
}

impl Polygon {
    /// Checks and builds a polygon: at least three points, all finite, no point repeated by its
    /// successor, not all on one line, and no two edges touching except neighbours at their shared
    /// corner (a simple polygon). A closing point equal to the first, as in the thesis' corner lists
    /// (5.1: "the first corner repeats at the end"), is dropped. Points are counted from 1 in the
    /// messages.
    pub fn new(points: Vec<Vec2>) -> Result<Polygon, PolygonError> {
        let mut points = points;
        if points.len() >= 2 && points.first() == points.last() {
            points.pop();
        }
        let poly = Polygon { points };
        poly.check()?;
        Ok(poly)
    }

    /// The checks of [`Polygon::new`] on an already built polygon.
    fn check(&self) -> Result<(), PolygonError> {
        let pts = &self.points;
        let n = pts.len();
        if n < 3 {
            return Err(PolygonError::TooFewPoints { count: n });
        }
        for (k, &p) in pts.iter().enumerate() {
            if !p.is_finite() {
                return Err(PolygonError::NotFinite {
                    point: k + 1,
                    at: p,
                });
            }
        }
        for k in 0..n {
            let (p, q) = (pts[k], pts[(k + 1) % n]);
            if p == q {
                return Err(PolygonError::Repeated {
                    point: k + 1,
                    next: (k + 1) % n + 1,
                    at: p,
                });
            }
        }
        if pts.iter().all(|&c| orient(pts[0], pts[1], c) == 0) {
            return Err(PolygonError::Collinear);
        }
        if let Some((i, j)) = self.self_intersection() {
            return Err(if j == (i + 1) % n {
                PolygonError::TurnsBack { point: j + 1 }
            } else {
                PolygonError::EdgesMeet {
                    first: i + 1,
                    second: j + 1,
                }
            });
        }
        if self.signed_area() == 0.0 {
            return Err(PolygonError::ZeroArea);
        }
        Ok(())
    }

    /// The first pair of edges `(i, j)` (0-based, edge `k` from point `k` to the next) that meet
    /// where they should not: non-neighbours that touch at all, or neighbours that fold back along
    /// each other. Exact predicates; edges are swept in order of their left end.
    fn self_intersection(&self) -> Option<(usize, usize)> {
        let pts = &self.points;
        let n = pts.len();
        let edge = |k: usize| (pts[k], pts[(k + 1) % n]);
        // neighbours: only a fold back along the shared corner is wrong
        for i in 0..n {
            let (a, b) = edge(i);
            let c = edge((i + 1) % n).1;
            if orient(a, b, c) == 0 && (b - a).dot(c - b) < 0.0 {
                return Some((i, (i + 1) % n));
            }
        }
        let mut order: Vec<usize> = (0..n).collect();
        let xmin = |k: usize| {
            let (a, b) = edge(k);
            a.x.min(b.x)
        };
        order.sort_by(|&i, &j| xmin(i).total_cmp(&xmin(j)));
        let mut found: Option<(usize, usize)> = None;
        for (oi, &i) in order.iter().enumerate() {
            let (a, b) = edge(i);
            let xmax = a.x.max(b.x);
            for &j in &order[oi + 1..] {
                if xmin(j) > xmax {
                    break;
                }
                let (lo, hi) = (i.min(j), i.max(j));
                if hi == lo + 1 || (lo == 0 && hi == n - 1) {
                    continue; // neighbours, checked above
                }
                let (c, d) = edge(j);
                if segments_intersect(a, b, c, d) && found.is_none_or(|f| (lo, hi) < f) {
                    found = Some((lo, hi));
                }
            }
        }
        found
    }

    /// The signed area (length²): positive when the corners run counter-clockwise.
    pub fn signed_area(&self) -> f64 {
        let pts = &self.points;
        let Some(&o) = pts.first() else {
            return 0.0;
        };
        let mut twice = 0.0;
        for k in 1..pts.len().saturating_sub(1) {
            twice += (pts[k] - o).cross(pts[k + 1] - o);
        }
        0.5 * twice
    }

    /// The area (length²), whatever the orientation.
    pub fn area(&self) -> f64 {
        self.signed_area().abs()
    }

    /// The length of the perimeter (length).
    pub fn perimeter(&self) -> f64 {
        self.edges().map(|(a, b)| (b - a).norm()).sum()
    }

    /// The edges as `(from, to)` pairs, the last one closing the polygon.
    pub fn edges(&self) -> impl Iterator<Item = (Vec2, Vec2)> + '_ {
        let n = self.points.len();
        (0..n).map(move |k| (self.points[k], self.points[(k + 1) % n]))
    }

    /// Whether the point `p` lies in the closed polygon: the boundary counts as inside. Exact: a
    /// winding number from exact orientation tests.
    pub fn contains(&self, p: Vec2) -> bool {
        let mut winding = 0i32;
        for (a, b) in self.edges() {
            let in_box = p.x >= a.x.min(b.x)
                && p.x <= a.x.max(b.x)
                && p.y >= a.y.min(b.y)
                && p.y <= a.y.max(b.y);
            let mut o = None;
            if in_box {
                let s = orient(a, b, p);
                if s == 0 {
                    return true; // on this edge
                }
                o = Some(s);
            }
            if a.y <= p.y {
                if b.y > p.y && o.unwrap_or_else(|| orient(a, b, p)) > 0 {
                    winding += 1;
                }
            } else if b.y <= p.y && o.unwrap_or_else(|| orient(a, b, p)) < 0 {
                winding -= 1;
            }
        }
        winding != 0
    }

    /// The lower-left and upper-right corners of the smallest axis-aligned box around the polygon.
    pub fn bounds(&self) -> (Vec2, Vec2) {
        let mut lo = Vec2::new(f64::INFINITY, f64::INFINITY);
        let mut hi = Vec2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in &self.points {
            lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        (lo, hi)
    }

    /// The squared distance (length²) from `p` to the closed polygon: zero inside or on the
    /// boundary, else the squared distance to the nearest edge.
    pub fn distance2_to_point(&self, p: Vec2) -> f64 {
        if self.contains(p) {
            return 0.0;
        }
        self.boundary_distance2(p)
    }

    /// The squared distance (length²) from the segment `a`–`b` to the closed polygon: zero when
    /// they meet.
    pub fn distance2_to_segment(&self, a: Vec2, b: Vec2) -> f64 {
        if self.contains(a) || self.contains(b) {
            return 0.0;
        }
        self.edges()
            .map(|(c, d)| segment_segment_distance2(a, b, c, d))
            .fold(f64::INFINITY, f64::min)
    }

    /// The squared distance from `p` to the nearest edge.
    fn boundary_distance2(&self, p: Vec2) -> f64 {
        self.edges()
            .map(|(a, b)| segment_distance2(p, a, b))
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether the corners run counter-clockwise.
    fn is_ccw(&self) -> bool {
        self.signed_area() > 0.0
    }
}

/// The sectors of an `nx` × `ny` grid of equal rectangles over `[lo, hi]` (the thesis' plate 7 and
/// chapter 6 layouts). They are numbered row by row from the bottom left, along x first: index
/// `j · nx + i` is column `i` (from the left), row `j` (from the bottom), so `Sector-1` is the
/// bottom-left one. Neighbours share bit-identical edges, and the outer edges are exactly `lo` and
/// `hi`. Each rectangle runs counter-clockwise from its lower-left corner. Needs `lo < hi` in both
/// coordinates; a zero count gives no sectors.
pub fn grid(lo: Vec2, hi: Vec2, nx: u32, ny: u32) -> Vec<Polygon> {
    let cuts = |a: f64, b: f64, n: u32| -> Vec<f64> {
        (0..=n)
            .map(|i| {
                if i == 0 {
                    a
                } else if i == n {
                    b
                } else {
                    a + (b - a) * f64::from(i) / f64::from(n)
                }
            })
            .collect()
    };
    if nx == 0 || ny == 0 {
        return Vec::new();
    }
    let xs = cuts(lo.x, hi.x, nx);
    let ys = cuts(lo.y, hi.y, ny);
    let mut out = Vec::with_capacity(nx as usize * ny as usize);
    for j in 0..ny as usize {
        for i in 0..nx as usize {
            out.push(Polygon {
                points: vec![
                    Vec2::new(xs[i], ys[j]),
                    Vec2::new(xs[i + 1], ys[j]),
                    Vec2::new(xs[i + 1], ys[j + 1]),
                    Vec2::new(xs[i], ys[j + 1]),
                ],
            });
        }
    }
    out
}

/// Why a list of points is not a simple polygon ([`Polygon::new`]). Points and edges are counted
/// from 1, edge `k` running from point `k` to the next.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PolygonError {
    /// Fewer than three points.
    #[error("a polygon needs at least 3 distinct points, got {count}")]
    TooFewPoints {
        /// How many points there are.
        count: usize,
    },
    /// A coordinate is infinite or not a number.
    #[error("point {point} must be two finite numbers, got [{}, {}]", .at.x, .at.y)]
    NotFinite {
        /// Which point.
        point: usize,
        /// Its coordinates.
        at: Vec2,
    },
    /// A point repeats its predecessor.
    #[error("points {point} and {next} are the same point [{}, {}]", .at.x, .at.y)]
    Repeated {
        /// The first of the two.
        point: usize,
        /// The one after it (1 when `point` is the last).
        next: usize,
        /// Where they both are.
        at: Vec2,
    },
    /// Every point lies on one line.
    #[error("has zero area: all its points lie on one line")]
    Collinear,
    /// Two neighbouring edges fold back along each other.
    #[error("turns back on itself at point {point} (the polygon must not intersect itself)")]
    TurnsBack {
        /// The corner where the boundary folds back.
        point: usize,
    },
    /// Two edges that are not neighbours touch.
    #[error(
        "edges {first} and {second} meet (the polygon must not intersect itself; edge k runs \
         from point k to the next)"
    )]
    EdgesMeet {
        /// The lower-numbered edge.
        first: usize,
        /// The other edge.
        second: usize,
    },
    /// The signed area is zero.
    #[error("has zero area")]
    ZeroArea,
}

/// Why polygons do not tile a table's box ([`validate_layout`]). Polygons are counted from 1, as
/// `sectors.polygon[k]` in a scenario file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LayoutError {
    /// The table's box is empty, inverted or not finite.
    #[error("the table's box [{}, {}] .. [{}, {}] has no area", .lo.x, .lo.y, .hi.x, .hi.y)]
    NoArea {
        /// The box's lower-left corner.
        lo: Vec2,
        /// Its upper-right corner.
        hi: Vec2,
    },
    /// The list of polygons is empty.
    #[error("there are no sectors: they leave all of the table's area uncovered")]
    NoSectors,
    /// A polygon is not a simple polygon.
    #[error("sectors.polygon[{index}] {source}")]
    Polygon {
        /// Which polygon.
        index: usize,
        /// What is wrong with it.
        #[source]
        source: PolygonError,
    },
    /// A polygon has a corner outside the table's box.
    #[error(
        "sectors.polygon[{index}] reaches outside the table: point [{}, {}] is not in \
         [{}, {}] .. [{}, {}]",
        .point.x, .point.y, .lo.x, .lo.y, .hi.x, .hi.y
    )]
    Outside {
        /// Which polygon.
        index: usize,
        /// Its corner outside.
        point: Vec2,
        /// The box's lower-left corner.
        lo: Vec2,
        /// Its upper-right corner.
        hi: Vec2,
    },
    /// Two polygons have interiors in common.
    #[error("sectors.polygon[{first}] overlaps sectors.polygon[{second}]")]
    Overlap {
        /// The lower-numbered polygon.
        first: usize,
        /// The other one.
        second: usize,
    },
    /// The polygons' areas fall short of the table's.
    #[error("the sectors leave {} of the table's area uncovered", short(*.missing))]
    Uncovered {
        /// The area left over (length²).
        missing: f64,
    },
    /// The polygons' areas add up to more than the table's.
    #[error(
        "the sectors' areas add up to {}, more than the table's {}",
        short(*.covered),
        short(*.table)
    )]
    Overcovered {
        /// The polygons' total area (length²).
        covered: f64,
        /// The table's area (length²).
        table: f64,
    },
}

impl LayoutError {
    /// The first polygon the error names (counted from 1), if any: the one to blame.
    pub fn polygon(&self) -> Option<usize> {
        match *self {
            LayoutError::Polygon { index, .. } | LayoutError::Outside { index, .. } => Some(index),
            LayoutError::Overlap { first, .. } => Some(first),
            _ => None,
        }
    }
}

/// Relative tolerance of [`validate_layout`]: lengths below this fraction of the table's larger
/// side count as zero, so that sectors whose shared edges differ by rounding still fit.
pub const LAYOUT_TOLERANCE: f64 = 1e-9;

/// Checks that the sectors tile the table's box `[lo, hi]` (thesis ch. 5: "the table is covered
/// by fixed, nonoverlapping sectors"): every polygon is a valid simple polygon lying inside the
/// box, no two have interiors in common, and their areas add up to the box's area. Lengths within
/// [`LAYOUT_TOLERANCE`] of the box's larger side count as equal, so shared edges computed with
/// rounding are fine; areas may miss by that tolerance times the perimeters.
///
/// Overlap is found exactly enough to name the pair: two polygons overlap when their edges cross
/// properly, when a stretch of one's boundary runs inside the other, or when they share a stretch
/// of boundary with both interiors on the same side. Only pairs whose boxes meet are compared
/// (a bucket grid), so a 300 × 300 layout takes a fraction of a second.
///
/// The error names polygons from 1 like the scenario file: `sectors.polygon[2] overlaps
/// sectors.polygon[5]`, `the sectors leave 120.5 of the table's area uncovered`.
pub fn validate_layout(polys: &[Polygon], lo: Vec2, hi: Vec2) -> Result<(), LayoutError> {
    if !(lo.is_finite() && hi.is_finite() && lo.x < hi.x && lo.y < hi.y) {
        return Err(LayoutError::NoArea { lo, hi });
    }
    if polys.is_empty() {
        return Err(LayoutError::NoSectors);
    }
    let size = (hi.x - lo.x).max(hi.y - lo.y);
    let tol = LAYOUT_TOLERANCE * size;
    for (i, poly) in polys.iter().enumerate() {
        poly.check().map_err(|source| LayoutError::Polygon {
            index: i + 1,
            source,
        })?;
        for &point in &poly.points {
            if point.x < lo.x - tol
                || point.x > hi.x + tol
                || point.y < lo.y - tol
                || point.y > hi.y + tol
            {
                return Err(LayoutError::Outside {
                    index: i + 1,
                    point,
                    lo,
                    hi,
                });
            }
        }
    }
    let boxes: Vec<(Vec2, Vec2)> = polys.iter().map(|p| pad(p.bounds(), tol)).collect();
    let ccw: Vec<bool> = polys.iter().map(Polygon::is_ccw).collect();
    let mut pairs = box_pairs(&boxes);
    pairs.sort_unstable();
    for (i, j) in pairs {
        let (i, j) = (i as usize, j as usize);
        if interiors_overlap(&polys[i], ccw[i], &polys[j], ccw[j], tol) {
            return Err(LayoutError::Overlap {
                first: i + 1,
                second: j + 1,
            });
        }
    }
    let table = (hi.x - lo.x) * (hi.y - lo.y);
    let (mut covered, mut perimeters) = (0.0, 0.0);
    for p in polys {
        covered += p.area();
        perimeters += p.perimeter();
    }
    let slack = LAYOUT_TOLERANCE * table + tol * perimeters;
    let missing = table - covered;
    if missing > slack {
        return Err(LayoutError::Uncovered { missing });
    }
    if missing < -slack {
        return Err(LayoutError::Overcovered { covered, table });
    }
    Ok(())
}

/// For each polygon, the indices (0-based, ascending) of the others whose closed regions come
/// within `tol` (length, ≥ 0) of it: neighbours across an edge and also those that meet it only
/// at a corner, since a ball can pass from one to the other through the corner (thesis ch. 5: a
/// sector sends NewVelocity messages to its adjacent sectors). Candidate pairs come from a bucket
/// grid over the bounding boxes, so the cost is about linear in the number of polygons for a
/// tiling (300 × 300 sectors are fine).
pub fn adjacency(polys: &[Polygon], tol: f64) -> Vec<Vec<u32>> {
    let tol = tol.max(0.0);
    let boxes: Vec<(Vec2, Vec2)> = polys.iter().map(|p| pad(p.bounds(), tol)).collect();
    let mut out = vec![Vec::new(); polys.len()];
    for (i, j) in box_pairs(&boxes) {
        if regions_within(&polys[i as usize], &polys[j as usize], tol) {
            out[i as usize].push(j);
            out[j as usize].push(i);
        }
    }
    for list in &mut out {
        list.sort_unstable();
    }
    out
}

/// [`adjacency`] of [`grid`]`(lo, hi, nx, ny)`, read off the grid: each cell's neighbours across
/// its edges and corners, ascending.
pub fn grid_adjacency(nx: u32, ny: u32) -> Vec<Vec<u32>> {
    let (nx, ny) = (nx as usize, ny as usize);
    let mut out = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let mut list = Vec::with_capacity(8);
            for y in j.saturating_sub(1)..(j + 2).min(ny) {
                for x in i.saturating_sub(1)..(i + 2).min(nx) {
                    if (x, y) != (i, j) {
                        list.push((y * nx + x) as u32);
                    }
                }
            }
            out.push(list);
        }
    }
    out
}

/// Whether a disk of radius `r` centred at `centre` touches the polygon: the distance from the
/// centre to the closed polygon is at most `r`.
pub fn touches(poly: &Polygon, centre: Vec2, r: f64) -> bool {
    let (lo, hi) = poly.bounds();
    if centre.x < lo.x - r || centre.x > hi.x + r || centre.y < lo.y - r || centre.y > hi.y + r {
        return false;
    }
    poly.distance2_to_point(centre) <= r * r
}

/// The time intervals `[start, end]` (absolute times, ascending, disjoint) during which a disk of
/// radius `r` moving on `traj` touches the polygon, over the whole line of the motion (before
/// `traj.t0` too). A disk at rest gives `[(-∞, ∞)]` when it touches and nothing otherwise.
///
/// Intervals closer than `1e-10` times the polygon's largest coordinate (in distance travelled)
/// are joined, so that rounding never splits one contact in two; a ball is then taken to touch a
/// little longer than it does, which is harmless (DESIGN.md: membership may be conservative).
pub fn touch_intervals(poly: &Polygon, traj: &Trajectory, r: f64) -> Vec<(f64, f64)> {
    if traj.velocity == Vec2::ZERO {
        return if touches(poly, traj.position, r) {
            vec![(f64::NEG_INFINITY, f64::INFINITY)]
        } else {
            Vec::new()
        };
    }
    intervals(poly, traj, r).into_vec()
}

/// The time a disk of radius `r` moving on `traj` enters the polygon: the first time `≥ after` at
/// which it starts touching, having not touched just before (thesis 5.1: the earliest perimeter
/// crossing). `None` when it never touches after `after`, when it is at rest, and when it already
/// touches at `after` (it is not entering; a caller that learns of a new trajectory at `after`
/// should ask [`touches`] first, since a ball that touches now belongs to the sector now).
pub fn entry_time(poly: &Polygon, traj: &Trajectory, r: f64, after: f64) -> Option<f64> {
    if traj.velocity == Vec2::ZERO {
        return None;
    }
    for (a, b) in intervals(poly, traj, r) {
        if b < after {
            continue;
        }
        return if a > after { Some(a) } else { None };
    }
    None
}

/// The time a disk of radius `r` moving on `traj` leaves the polygon for good: the end of its last
/// contact along this straight motion, if that is at or after `after` (thesis 5.1: the latest
/// perimeter crossing). For a non-convex polygon the path may leave and come back; the departure
/// is the last leaving, so the sector knows the ball until it is gone. `None` when the ball is at
/// rest (it never leaves) or its last contact ended before `after`.
pub fn departure_time(poly: &Polygon, traj: &Trajectory, r: f64, after: f64) -> Option<f64> {
    if traj.velocity == Vec2::ZERO {
        return None;
    }
    match intervals(poly, traj, r).last() {
        Some(&(_, b)) if b >= after => Some(b),
        _ => None,
    }
}

/// Relative extension of each edge's extent when matching the offset lines, so that a path through
/// a corner with `r = 0` is caught by one of its two edges whatever the rounding.
const EDGE_END_TOLERANCE: f64 = 1e-12;

/// Relative size (of the polygon) below which a gap between contacts is rounding, not a gap.
const GAP_TOLERANCE: f64 = 1e-10;

/// The touching intervals for a moving disk (`traj.velocity` non-zero), in absolute time.
fn intervals(poly: &Polygon, traj: &Trajectory, r: f64) -> SmallVec<[(f64, f64); 4]> {
    let p = traj.position;
    let v = traj.velocity;
    let (lo, hi) = poly.bounds();
    let mut out: SmallVec<[(f64, f64); 4]> = SmallVec::new();
    // The line must meet the box grown by r (and a hair) at all: a cheap rejection for far sectors.
    let grow = r + 1e-9 * (hi.x - lo.x).max(hi.y - lo.y);
    match (
        range_in(p.x, v.x, lo.x - grow, hi.x + grow),
        range_in(p.y, v.y, lo.y - grow, hi.y + grow),
    ) {
        (Some(x), Some(y)) if x.0.max(y.0) <= x.1.min(y.1) => {}
        _ => return out,
    }
    let mut pieces: SmallVec<[(f64, f64); 16]> = SmallVec::new();
    let n = poly.points.len();
    for k in 0..n {
        let a = poly.points[k];
        let b = poly.points[(k + 1) % n];
        let (u, len) = unit(b - a);
        let nrm = u.perp_cw();
        let rel = p - a;
        let slack = EDGE_END_TOLERANCE * len;
        let along = range_in(rel.dot(u), v.dot(u), -slack, len + slack);
        let across = range_in(rel.dot(nrm), v.dot(nrm), -r, r);
        if let (Some(s), Some(w)) = (along, across) {
            let (t0, t1) = (s.0.max(w.0), s.1.min(w.1));
            if t0 <= t1 {
                pieces.push((t0, t1));
            }
        }
        if let Some(c) = circle_range(p - a, v, r) {
            pieces.push(c);
        }
    }
    if pieces.is_empty() {
        return out;
    }
    pieces.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    let scale =
        lo.x.abs()
            .max(lo.y.abs())
            .max(hi.x.abs())
            .max(hi.y.abs())
            .max(r);
    let gap_tol = GAP_TOLERANCE * scale / v.norm();
    let mut cur = pieces[0];
    for &(s, e) in &pieces[1..] {
        let joined = s <= cur.1 + gap_tol || poly.contains(p + (0.5 * (cur.1 + s)) * v);
        if joined {
            cur.1 = cur.1.max(e);
        } else {
            out.push(cur);
            cur = (s, e);
        }
    }
    out.push(cur);
    for iv in &mut out {
        *iv = (traj.t0 + iv.0, traj.t0 + iv.1);
    }
    out
}

/// The unit vector along `e` and the length of `e`; exact for axis-parallel `e`.
#[inline]
fn unit(e: Vec2) -> (Vec2, f64) {
    if e.x == 0.0 {
        (Vec2::new(0.0, e.y.signum()), e.y.abs())
    } else if e.y == 0.0 {
        (Vec2::new(e.x.signum(), 0.0), e.x.abs())
    } else {
        let len = e.norm();
        (Vec2::new(e.x / len, e.y / len), len)
    }
}

/// The times `τ` at which `x0 + τ·dx` lies in `[lo, hi]`: all of them (infinite ends) when
/// `dx = 0` and `x0` is in range, none when it is not.
#[inline]
fn range_in(x0: f64, dx: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
    if dx == 0.0 {
        return (lo <= x0 && x0 <= hi).then_some((f64::NEG_INFINITY, f64::INFINITY));
    }
    let (t0, t1) = ((lo - x0) / dx, (hi - x0) / dx);
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// The times `τ` at which `|dp + τ·v| ≤ r` (a centre at offset `dp` from a corner, velocity
/// `v ≠ 0`): the roots of `a τ² + 2 b τ + c = 0` taken as `q / a` and `c / q` with
/// `q = −(b + sign(b)·√(b² − a c))`, which never subtracts nearly equal numbers.
#[inline]
fn circle_range(dp: Vec2, v: Vec2, r: f64) -> Option<(f64, f64)> {
    let a = v.norm2();
    let b = dp.dot(v);
    let c = dp.norm2() - r * r;
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    let q = if b >= 0.0 { -(b + sq) } else { sq - b };
    if q == 0.0 {
        return Some((0.0, 0.0)); // grazing the circle right at the fix
    }
    let (t0, t1) = (q / a, c / q);
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// A box grown by `d` on every side.
fn pad((lo, hi): (Vec2, Vec2), d: f64) -> (Vec2, Vec2) {
    (Vec2::new(lo.x - d, lo.y - d), Vec2::new(hi.x + d, hi.y + d))
}

/// Every pair `(i, j)`, `i < j`, of closed boxes that meet, each pair once. The boxes are binned
/// into a uniform grid of cells about the mean box size; a pair is reported only by the cell that
/// holds the lower-left corner of the two boxes' intersection.
fn box_pairs(boxes: &[(Vec2, Vec2)]) -> Vec<(u32, u32)> {
    let n = boxes.len();
    let mut pairs = Vec::new();
    if n < 2 {
        return pairs;
    }
    let (mut lo, mut hi) = (boxes[0].0, boxes[0].1);
    let (mut sum_w, mut sum_h) = (0.0, 0.0);
    for &(a, b) in boxes {
        lo = Vec2::new(lo.x.min(a.x), lo.y.min(a.y));
        hi = Vec2::new(hi.x.max(b.x), hi.y.max(b.y));
        sum_w += b.x - a.x;
        sum_h += b.y - a.y;
    }
    let (w, h) = (hi.x - lo.x, hi.y - lo.y);
    let count = |extent: f64, mean: f64| -> usize {
        if extent > 0.0 && mean > 0.0 {
            ((extent / mean).ceil() as usize).clamp(1, 1 << 16)
        } else {
            1
        }
    };
    let mut nx = count(w, sum_w / n as f64);
    let mut ny = count(h, sum_h / n as f64);
    let max_cells = 4 * n + 16;
    if nx * ny > max_cells {
        let f = ((nx * ny) as f64 / max_cells as f64).sqrt();
        nx = ((nx as f64 / f) as usize).max(1);
        ny = ((ny as f64 / f) as usize).max(1);
    }
    let cell = |x: f64, origin: f64, extent: f64, cells: usize| -> usize {
        if extent > 0.0 {
            ((((x - origin) / extent) * cells as f64) as usize).min(cells - 1)
        } else {
            0
        }
    };
    let cx = |x: f64| cell(x, lo.x, w, nx);
    let cy = |y: f64| cell(y, lo.y, h, ny);
    // compressed cell lists: count, prefix sums, fill
    let mut start = vec![0usize; nx * ny + 1];
    for &(a, b) in boxes {
        for j in cy(a.y)..=cy(b.y) {
            for i in cx(a.x)..=cx(b.x) {
                start[j * nx + i + 1] += 1;
            }
        }
    }
    for k in 0..nx * ny {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut members = vec![0u32; start[nx * ny]];
    for (id, &(a, b)) in boxes.iter().enumerate() {
        for j in cy(a.y)..=cy(b.y) {
            for i in cx(a.x)..=cx(b.x) {
                members[fill[j * nx + i]] = id as u32;
                fill[j * nx + i] += 1;
            }
        }
    }
    for j in 0..ny {
        for i in 0..nx {
            let list = &members[start[j * nx + i]..start[j * nx + i + 1]];
            for (k, &p) in list.iter().enumerate() {
                let (pa, pb) = boxes[p as usize];
                for &q in &list[k + 1..] {
                    let (qa, qb) = boxes[q as usize];
                    if pa.x > qb.x || qa.x > pb.x || pa.y > qb.y || qa.y > pb.y {
                        continue;
                    }
                    if cx(pa.x.max(qa.x)) == i && cy(pa.y.max(qa.y)) == j {
                        pairs.push((p.min(q), p.max(q)));
                    }
                }
            }
        }
    }
    pairs
}

/// Whether two polygons' closed regions come within `tol` of each other.
fn regions_within(a: &Polygon, b: &Polygon, tol: f64) -> bool {
    let t2 = tol * tol;
    for (p, q) in a.edges() {
        let (elo, ehi) = pad(seg_box(p, q), tol);
        for (c, d) in b.edges() {
            let (flo, fhi) = seg_box(c, d);
            if flo.x > ehi.x || elo.x > fhi.x || flo.y > ehi.y || elo.y > fhi.y {
                continue;
            }
            if segment_segment_distance2(p, q, c, d) <= t2 {
                return true;
            }
        }
    }
    a.contains(b.points[0]) || b.contains(a.points[0])
}

/// The bounding box of a segment.
#[inline]
fn seg_box(p: Vec2, q: Vec2) -> (Vec2, Vec2) {
    (
        Vec2::new(p.x.min(q.x), p.y.min(q.y)),
        Vec2::new(p.x.max(q.x), p.y.max(q.y)),
    )
}

/// The squared distance between segments `p`–`q` and `c`–`d` (zero when they meet).
fn segment_segment_distance2(p: Vec2, q: Vec2, c: Vec2, d: Vec2) -> f64 {
    if segments_intersect(p, q, c, d) {
        return 0.0;
    }
    segment_distance2(p, c, d)
        .min(segment_distance2(q, c, d))
        .min(segment_distance2(c, p, q))
        .min(segment_distance2(d, p, q))
}

/// Whether two polygons (with their orientations) have interiors in common, up to `tol`.
fn interiors_overlap(a: &Polygon, a_ccw: bool, b: &Polygon, b_ccw: bool, tol: f64) -> bool {
    boundary_enters(a, a_ccw, b, b_ccw, tol) || boundary_enters(b, b_ccw, a, a_ccw, tol)
}

/// Whether some stretch of `a`'s boundary lies inside `b` or runs along `b`'s boundary with both
/// interiors on the same side, or an edge of `a` properly crosses an edge of `b`.
///
/// Each edge of `a` is cut where `b`'s corners lie on it; between cuts a stretch of it meets `b`'s
/// boundary nowhere (a proper crossing having been reported), so its midpoint tells whether it
/// lies inside `b`, outside, or along an edge of `b`. If neither boundary enters the other
/// polygon and no shared stretch has both interiors on one side, the interiors are disjoint.
fn boundary_enters(a: &Polygon, a_ccw: bool, b: &Polygon, b_ccw: bool, tol: f64) -> bool {
    let (blo, bhi) = pad(b.bounds(), tol);
    let t2 = tol * tol;
    let nb = b.points.len();
    let mut cuts: SmallVec<[f64; 16]> = SmallVec::new();
    for (p, q) in a.edges() {
        let (elo, ehi) = seg_box(p, q);
        if elo.x > bhi.x || blo.x > ehi.x || elo.y > bhi.y || blo.y > ehi.y {
            continue;
        }
        let e = q - p;
        let l2 = e.norm2();
        let len = l2.sqrt();
        cuts.clear();
        cuts.push(0.0);
        cuts.push(1.0);
        for (c, d) in b.edges() {
            let s = (c - p).dot(e) / l2;
            if s > 0.0 && s < 1.0 && segment_distance2(c, p, q) <= t2 {
                cuts.push(s);
            }
            if properly_cross(p, q, c, d, tol) {
                return true;
            }
        }
        cuts.sort_unstable_by(f64::total_cmp);
        let dir_a = if a_ccw { e } else { -e };
        for w in cuts.windows(2) {
            if (w[1] - w[0]) * len <= 4.0 * tol {
                continue;
            }
            let m = p + (0.5 * (w[0] + w[1])) * e;
            let (mut best, mut best_k) = (f64::INFINITY, 0);
            for k in 0..nb {
                let d2 = segment_distance2(m, b.points[k], b.points[(k + 1) % nb]);
                if d2 < best {
                    (best, best_k) = (d2, k);
                }
            }
            if best > t2 {
                if b.contains(m) {
                    return true;
                }
            } else {
                let f = b.points[(best_k + 1) % nb] - b.points[best_k];
                let dir_b = if b_ccw { f } else { -f };
                if dir_a.dot(dir_b) > 0.0 {
                    return true; // a shared stretch with both interiors on its left
                }
            }
        }
    }
    false
}

/// Whether segments `p`–`q` and `c`–`d` cross at a point inside both, each one's ends lying more
/// than `tol` from the other's line on opposite sides.
fn properly_cross(p: Vec2, q: Vec2, c: Vec2, d: Vec2, tol: f64) -> bool {
    let side = |a: Vec2, b: Vec2, x: Vec2| -> f64 {
        let e = b - a;
        e.cross(x - a) / e.norm()
    };
    let (sc, sd) = (side(p, q, c), side(p, q, d));
    if !((sc > tol && sd < -tol) || (sc < -tol && sd > tol)) {
        return false;
    }
    let (sp, sq) = (side(c, d, p), side(c, d, q));
    (sp > tol && sq < -tol) || (sp < -tol && sq > tol)
}

/// Whether the closed segments `a`–`b` and `c`–`d` have a point in common (exact).
fn segments_intersect(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    (o1 == 0 && in_box(a, b, c))
        || (o2 == 0 && in_box(a, b, d))
        || (o3 == 0 && in_box(c, d, a))
        || (o4 == 0 && in_box(c, d, b))
}

/// Whether `p` lies in the bounding box of `a`–`b` (for a point known to be on their line).
#[inline]
fn in_box(a: Vec2, b: Vec2, p: Vec2) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Error bound of the floating-point orientation determinant (Shewchuk's `ccwerrboundA`).
const ORIENT_ERROR_BOUND: f64 = 3.330_669_073_875_472e-16;

/// The exact sign of the orientation of `(a, b, c)`: `1` counter-clockwise, `-1` clockwise, `0`
/// on one line. A floating-point determinant decides unless it is within its error bound; then the
/// determinant is expanded into six products of coordinates, each split exactly into two doubles
/// with a fused multiply-add, and summed exactly as a floating-point expansion.
fn orient(a: Vec2, b: Vec2, c: Vec2) -> i32 {
    let l = (a.x - c.x) * (b.y - c.y);
    let r = (a.y - c.y) * (b.x - c.x);
    let det = l - r;
    if det.abs() > ORIENT_ERROR_BOUND * (l.abs() + r.abs()) {
        return if det > 0.0 { 1 } else { -1 };
    }
    // det = ax·by − ax·cy − cx·by − ay·bx + ay·cx + cy·bx (the cx·cy terms cancel)
    let products = [
        (a.x, b.y),
        (-a.x, c.y),
        (-c.x, b.y),
        (-a.y, b.x),
        (a.y, c.x),
        (c.y, b.x),
    ];
    let mut expansion: SmallVec<[f64; 16]> = SmallVec::new();
    for (x, y) in products {
        let hi = x * y;
        let lo = x.mul_add(y, -hi);
        grow_expansion(&mut expansion, lo);
        grow_expansion(&mut expansion, hi);
    }
    match expansion.iter().rev().find(|&&x| x != 0.0) {
        Some(&x) if x > 0.0 => 1,
        Some(_) => -1,
        None => 0,
    }
}

/// Adds `b` to a non-overlapping expansion (components in increasing magnitude), exactly
/// (Shewchuk's Grow-Expansion); zero components are dropped.
fn grow_expansion(e: &mut SmallVec<[f64; 16]>, b: f64) {
    let mut q = b;
    let mut out: SmallVec<[f64; 16]> = SmallVec::new();
    for &x in e.iter() {
        let (s, err) = two_sum(q, x);
        if err != 0.0 {
            out.push(err);
        }
        q = s;
    }
    if q != 0.0 {
        out.push(q);
    }
    *e = out;
}

/// `a + b` as a rounded sum and its exact error (Knuth's Two-Sum).
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bv = s - a;
    let av = s - bv;
    (s, (a - av) + (b - bv))
}

/// A number in at most six significant digits, without trailing zeros.
fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let digits = (5 - x.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> Vec2 {
        Vec2::new(x, y)
    }

    fn traj(x: f64, y: f64, vx: f64, vy: f64, t0: f64) -> Trajectory {
        Trajectory {
            position: v(x, y),
            velocity: v(vx, vy),
            t0,
        }
    }

    fn square() -> Polygon {
        Polygon::new(vec![v(0.0, 0.0), v(10.0, 0.0), v(10.0, 10.0), v(0.0, 10.0)]).unwrap()
    }

    #[test]
    fn new_rejects_bad_polygons() {
        assert!(Polygon::new(vec![v(0.0, 0.0), v(1.0, 0.0)])
            .unwrap_err()
            .to_string()
            .contains("at least 3"));
        assert!(
            Polygon::new(vec![v(0.0, 0.0), v(1.0, 0.0), v(f64::NAN, 1.0)])
                .unwrap_err()
                .to_string()
                .contains("point 3")
        );
        assert!(Polygon::new(vec![v(0.0, 0.0), v(1.0, 0.0), v(2.0, 0.0)])
            .unwrap_err()
            .to_string()
            .contains("zero area"));
        assert!(
            Polygon::new(vec![v(0.0, 0.0), v(1.0, 0.0), v(1.0, 0.0), v(0.0, 1.0)])
                .unwrap_err()
                .to_string()
                .contains("same point")
        );
        // a bow tie
        let e = Polygon::new(vec![v(0.0, 0.0), v(1.0, 1.0), v(1.0, 0.0), v(0.0, 1.0)]).unwrap_err();
        assert_eq!(
            e,
            PolygonError::EdgesMeet {
                first: 1,
                second: 3
            }
        );
        assert!(e.to_string().contains("edges 1 and 3 meet"), "{e}");
        // a corner touching another edge
        let e = Polygon::new(vec![
            v(0.0, 0.0),
            v(4.0, 0.0),
            v(4.0, 4.0),
            v(2.0, 0.0),
            v(0.0, 4.0),
        ])
        .unwrap_err();
        assert!(e.to_string().contains("meet"), "{e}");
        // a spike folding back
        let e = Polygon::new(vec![v(0.0, 0.0), v(4.0, 0.0), v(2.0, 0.0), v(2.0, 3.0)]).unwrap_err();
        assert!(e.to_string().contains("turns back"), "{e}");
        // the thesis' closed corner list is fine
        let p = Polygon::new(vec![v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 0.0)]).unwrap();
        assert_eq!(p.points.len(), 3);
    }

    #[test]
    fn error_messages() {
        let bad = |pts: Vec<Vec2>| Polygon::new(pts).unwrap_err().to_string();
        assert_eq!(
            bad(vec![v(0.0, 0.0), v(1.0, 0.0)]),
            "a polygon needs at least 3 distinct points, got 2"
        );
        assert_eq!(
            bad(vec![v(0.0, 0.0), v(1.0, 0.0), v(f64::NAN, 1.5)]),
            "point 3 must be two finite numbers, got [NaN, 1.5]"
        );
        assert_eq!(
            bad(vec![v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.5), v(0.0, 1.5)]),
            "points 3 and 4 are the same point [0, 1.5]"
        );
        assert_eq!(
            bad(vec![v(0.0, 0.0), v(1.0, 0.0), v(2.0, 0.0)]),
            "has zero area: all its points lie on one line"
        );
        assert_eq!(
            bad(vec![v(0.0, 0.0), v(4.0, 0.0), v(2.0, 0.0), v(2.0, 3.0)]),
            "turns back on itself at point 2 (the polygon must not intersect itself)"
        );
        assert_eq!(
            bad(vec![v(0.0, 0.0), v(1.0, 1.0), v(1.0, 0.0), v(0.0, 1.0)]),
            "edges 1 and 3 meet (the polygon must not intersect itself; edge k runs from point k \
             to the next)"
        );
        assert_eq!(PolygonError::ZeroArea.to_string(), "has zero area");
        let (lo, hi) = (v(0.0, 0.0), v(4.0, 2.0));
        let rect = |x1: f64| Polygon {
            points: vec![v(0.0, 0.0), v(x1, 0.0), v(x1, 2.0), v(0.0, 2.0)],
        };
        let layout = |polys: &[Polygon], hi: Vec2| validate_layout(polys, lo, hi).unwrap_err();
        assert_eq!(
            layout(&[rect(4.0)], v(0.0, 2.5)).to_string(),
            "the table's box [0, 0] .. [0, 2.5] has no area"
        );
        assert_eq!(
            layout(&[], hi).to_string(),
            "there are no sectors: they leave all of the table's area uncovered"
        );
        let e = layout(
            &[Polygon {
                points: vec![v(0.0, 0.0), v(4.0, 0.0)],
            }],
            hi,
        );
        assert_eq!(
            e.to_string(),
            "sectors.polygon[1] a polygon needs at least 3 distinct points, got 2"
        );
        assert_eq!(e.polygon(), Some(1));
        let e = layout(&[rect(3.0), rect(4.5)], hi);
        assert_eq!(
            e.to_string(),
            "sectors.polygon[2] reaches outside the table: point [4.5, 0] is not in [0, 0] .. [4, 2]"
        );
        assert_eq!(e.polygon(), Some(2));
        let e = layout(&[rect(2.0 / 3.0)], hi);
        assert_eq!(
            e.to_string(),
            "the sectors leave 6.66667 of the table's area uncovered"
        );
        assert_eq!(e.polygon(), None);
        let over = LayoutError::Overcovered {
            covered: 8.5,
            table: 8.0,
        };
        assert_eq!(
            over.to_string(),
            "the sectors' areas add up to 8.5, more than the table's 8"
        );
    }

    #[test]
    fn distance_to_a_segment() {
        let sq = square();
        // crossing the square with both ends outside, along an edge, from inside, and apart
        assert_eq!(sq.distance2_to_segment(v(-5.0, 5.0), v(15.0, 5.0)), 0.0);
        assert_eq!(sq.distance2_to_segment(v(-5.0, 0.0), v(15.0, 0.0)), 0.0);
        assert_eq!(sq.distance2_to_segment(v(5.0, 5.0), v(5.0, 5.0)), 0.0);
        assert_eq!(sq.distance2_to_segment(v(-5.0, 13.0), v(15.0, 13.0)), 9.0);
        // the nearest point is a corner of the square
        assert_eq!(sq.distance2_to_segment(v(13.0, 14.0), v(20.0, 14.0)), 25.0);
    }

    #[test]
    fn area_containment_distance() {
        let sq = square();
        assert_eq!(sq.area(), 100.0);
        assert_eq!(sq.signed_area(), 100.0);
        let cw = Polygon::new(sq.points.iter().rev().copied().collect()).unwrap();
        assert_eq!(cw.signed_area(), -100.0);
        for p in [&sq, &cw] {
            assert!(p.contains(v(5.0, 5.0)));
            assert!(p.contains(v(0.0, 5.0)));
            assert!(p.contains(v(10.0, 10.0)));
            assert!(!p.contains(v(10.0 + 1e-15, 5.0)));
            assert_eq!(p.distance2_to_point(v(13.0, 14.0)), 25.0);
            assert_eq!(p.distance2_to_point(v(3.0, 4.0)), 0.0);
            assert_eq!(p.bounds(), (v(0.0, 0.0), v(10.0, 10.0)));
        }
        assert!(touches(&sq, v(13.0, 14.0), 5.0));
        assert!(!touches(&sq, v(13.0, 14.0), 4.999));
    }

    #[test]
    fn exact_orientation_of_nearly_collinear_points() {
        let a = v(0.1, 0.1);
        let b = v(0.3, 0.3);
        let c = v(0.7, 0.7);
        // 0.1, 0.3, 0.7 as doubles are not exactly on one line; the sign must be consistent
        let s = orient(a, b, c);
        assert_eq!(s, -orient(b, a, c));
        assert_eq!(s, orient(b, c, a));
        assert_eq!(orient(v(0.0, 0.0), v(1.0, 1.0), v(3.0, 3.0)), 0);
        assert_eq!(orient(v(0.0, 0.0), v(1.0, 0.0), v(0.5, 1e-300)), 1);
    }

    #[test]
    fn axis_aligned_entry_and_departure_are_exact() {
        let sq = square();
        let t = traj(-5.0, 5.0, 2.0, 0.0, 1.0);
        // the edge of a disk of radius 1 reaches x = 0 when the centre is at -1: t = 1 + 4/2
        assert_eq!(entry_time(&sq, &t, 1.0, 0.0), Some(3.0));
        assert_eq!(departure_time(&sq, &t, 1.0, 0.0), Some(9.0));
        assert_eq!(touch_intervals(&sq, &t, 1.0), vec![(3.0, 9.0)]);
        // inside at `after`: no entry, departure still the same
        assert_eq!(entry_time(&sq, &t, 1.0, 4.0), None);
        assert_eq!(departure_time(&sq, &t, 1.0, 4.0), Some(9.0));
        assert_eq!(departure_time(&sq, &t, 1.0, 9.5), None);
        // at rest
        let rest = traj(5.0, 5.0, 0.0, 0.0, 0.0);
        assert_eq!(entry_time(&sq, &rest, 1.0, 0.0), None);
        assert_eq!(departure_time(&sq, &rest, 1.0, 0.0), None);
        // past a corner: the rounded corner of the dilated square
        let diag = traj(-10.0, -10.0, 1.0, 1.0, 0.0);
        let te = entry_time(&sq, &diag, 2.0, 0.0).unwrap();
        assert!((te - (10.0 - 2.0 / 2f64.sqrt())).abs() < 1e-12);
        // a path that misses by a hair
        let miss = traj(-5.0, 12.0 + 1e-9, 1.0, 0.0, 0.0);
        assert_eq!(entry_time(&sq, &miss, 2.0, 0.0), None);
    }

    #[test]
    fn non_convex_departure_is_the_last_one() {
        // a U open at the top: walls x in [0,2] and [8,10], floor y in [0,2]
        let u = Polygon::new(vec![
            v(0.0, 0.0),
            v(10.0, 0.0),
            v(10.0, 10.0),
            v(8.0, 10.0),
            v(8.0, 2.0),
            v(2.0, 2.0),
            v(2.0, 10.0),
            v(0.0, 10.0),
        ])
        .unwrap();
        let t = traj(-5.0, 6.0, 1.0, 0.0, 0.0);
        let r = 0.5;
        assert_eq!(
            touch_intervals(&u, &t, r),
            vec![(4.5, 7.5), (12.5, 15.5)],
            "two separate contacts"
        );
        assert_eq!(entry_time(&u, &t, r, 0.0), Some(4.5));
        assert_eq!(entry_time(&u, &t, r, 10.0), Some(12.5));
        assert_eq!(departure_time(&u, &t, r, 0.0), Some(15.5));
        // with a big disk the gap closes
        assert_eq!(touch_intervals(&u, &t, 3.5).len(), 1);
        // through the floor: inside the polygon between the crossings
        let low = traj(-5.0, 1.0, 1.0, 0.0, 0.0);
        assert_eq!(touch_intervals(&u, &low, 0.0), vec![(5.0, 15.0)]);
    }

    #[test]
    fn zero_radius_through_a_corner() {
        let tri = Polygon::new(vec![v(0.0, 0.0), v(3.0, 0.0), v(0.0, 3.0)]).unwrap();
        // the line y = x - 0 passes through the corner (0, 0) and leaves through the hypotenuse
        let t = traj(-1.0, -1.0, 1.0, 1.0, 0.0);
        let iv = touch_intervals(&tri, &t, 0.0);
        assert_eq!(iv.len(), 1);
        assert!(
            (iv[0].0 - 1.0).abs() < 1e-12 && (iv[0].1 - 2.5).abs() < 1e-12,
            "{iv:?}"
        );
    }

    #[test]
    fn layouts() {
        let (lo, hi) = (v(0.0, 0.0), v(600.0, 300.0));
        let g = grid(lo, hi, 3, 2);
        assert_eq!(g.len(), 6);
        assert_eq!(g[0].bounds(), (v(0.0, 0.0), v(200.0, 150.0)));
        assert_eq!(g[5].bounds(), (v(400.0, 150.0), v(600.0, 300.0)));
        validate_layout(&g, lo, hi).unwrap();
        let mut missing = g.clone();
        missing.remove(4);
        assert_eq!(
            validate_layout(&missing, lo, hi).unwrap_err().to_string(),
            "the sectors leave 30000 of the table's area uncovered"
        );
        let mut dup = g.clone();
        dup.push(g[1].clone());
        let e = validate_layout(&dup, lo, hi).unwrap_err();
        assert_eq!(
            e,
            LayoutError::Overlap {
                first: 2,
                second: 7
            }
        );
        assert_eq!(e.polygon(), Some(2));
        assert_eq!(
            e.to_string(),
            "sectors.polygon[2] overlaps sectors.polygon[7]"
        );
        // the same square split along a diagonal, both triangles added to the grid
        let mut split = g.clone();
        let [a, b, c, d] = [
            g[0].points[0],
            g[0].points[1],
            g[0].points[2],
            g[0].points[3],
        ];
        split[0] = Polygon::new(vec![a, b, c]).unwrap();
        split.push(Polygon::new(vec![a, c, d]).unwrap());
        validate_layout(&split, lo, hi).unwrap();
        split.push(Polygon::new(vec![a, b, d]).unwrap());
        let e = validate_layout(&split, lo, hi).unwrap_err();
        assert!(e.to_string().contains("overlaps sectors.polygon[8]"), "{e}");
        let mut out = g.clone();
        out[0].points[0] = v(-1.0, 0.0);
        assert!(validate_layout(&out, lo, hi)
            .unwrap_err()
            .to_string()
            .starts_with("sectors.polygon[1] reaches outside"));
    }

    #[test]
    fn grids_of_any_size_are_valid_layouts() {
        // the sectored engines take a grid without validating it
        let (lo, hi) = (v(-3.7, 1.1), v(1234.567, 890.123));
        for (nx, ny) in [(1, 1), (7, 5), (113, 109)] {
            validate_layout(&grid(lo, hi, nx, ny), lo, hi).unwrap();
        }
    }

    #[test]
    fn adjacency_of_a_grid() {
        let g = grid(v(0.0, 0.0), v(3.0, 3.0), 3, 3);
        let adj = adjacency(&g, 0.0);
        assert_eq!(adj[4], vec![0, 1, 2, 3, 5, 6, 7, 8]);
        assert_eq!(adj[0], vec![1, 3, 4]);
        assert_eq!(adj[1], vec![0, 2, 3, 4, 5]);
        assert_eq!(adj[8], vec![4, 5, 7]);
        // read off the grid, as the sectored engines do, it is the same for any grid
        let (lo, hi) = (v(-3.7, 1.1), v(1234.567, 890.123));
        for (nx, ny) in [(1, 1), (1, 4), (5, 1), (3, 3), (7, 5), (40, 31)] {
            let tol = 1e-9 * (hi - lo).norm();
            assert_eq!(
                grid_adjacency(nx, ny),
                adjacency(&grid(lo, hi, nx, ny), tol)
            );
        }
    }

    #[test]
    fn short_numbers() {
        assert_eq!(short(120.5), "120.5");
        assert_eq!(short(30000.0), "30000");
        assert_eq!(short(1.23456789e-8), "0.0000000123457");
        assert_eq!(short(2.0 / 3.0), "0.666667");
    }
}
