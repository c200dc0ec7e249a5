//! The sectors of a table (thesis ch. 5): their polygons, which touch which, the index that
//! finds the sectors a disk touches, and which fixed objects each sector's balls must tell.

use crate::engine::{Fixed, Table};
use crate::geometry::Vec2;
use crate::polygon::{self, LayoutError, Polygon};

/// The sectors of a table: their polygons, which touch which, and a bucket index of their boxes
/// so that finding the sectors a disk touches costs O(1), not O(sectors).
#[derive(Clone, Debug)]
pub struct Layout {
    /// The sectors, `Sector-1` first.
    pub polys: Vec<Polygon>,
    /// For each sector, the sectors whose boundaries meet its own (an edge or a corner).
    pub adjacent: Vec<Vec<u32>>,
    /// Which balls tell the cushions, pockets and corners of their trajectories.
    pub fixed_news: FixedNews,
    index: BoxIndex,
}

/// Which balls tell a fixed object (cushion, pocket, corner) of a new trajectory.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FixedNews {
    /// Those in sectors within reach of it: a ball that changes course there, or that enters
    /// such a sector, tells it. The same collisions, with a fraction of the messages.
    #[default]
    Near,
    /// Every ball, at every change, as the thesis' fig. 15 (for its message counts).
    Thesis,
}

/// Sectors bucketed by bounding box on a uniform grid over the table.
#[derive(Clone, Debug)]
struct BoxIndex {
    lo: Vec2,
    cell: Vec2,
    nx: usize,
    ny: usize,
    buckets: Vec<Vec<u32>>,
}

impl BoxIndex {
    fn new(polys: &[Polygon], lo: Vec2, hi: Vec2) -> BoxIndex {
        let n = (polys.len() as f64).sqrt().ceil().max(1.0) as usize;
        let span = hi - lo;
        let cell = Vec2::new(span.x / n as f64, span.y / n as f64);
        let mut index = BoxIndex {
            lo,
            cell,
            nx: n,
            ny: n,
            buckets: vec![Vec::new(); n * n],
        };
        for (k, p) in polys.iter().enumerate() {
            let (a, b) = p.bounds();
            index.for_buckets(a, b, |bucket| bucket.push(k as u32));
        }
        index
    }

    fn range(&self, a: f64, lo: f64, cell: f64, n: usize) -> usize {
        (((a - lo) / cell).floor().max(0.0) as usize).min(n - 1)
    }

    fn for_buckets(&mut self, a: Vec2, b: Vec2, mut f: impl FnMut(&mut Vec<u32>)) {
        let (x0, x1) = (
            self.range(a.x, self.lo.x, self.cell.x, self.nx),
            self.range(b.x, self.lo.x, self.cell.x, self.nx),
        );
        let (y0, y1) = (
            self.range(a.y, self.lo.y, self.cell.y, self.ny),
            self.range(b.y, self.lo.y, self.cell.y, self.ny),
        );
        for y in y0..=y1 {
            for x in x0..=x1 {
                f(&mut self.buckets[y * self.nx + x]);
            }
        }
    }

    /// Sectors whose boxes may hold the point `p`, ascending (the sectors were filed in order).
    fn at(&self, p: Vec2) -> &[u32] {
        let x = self.range(p.x, self.lo.x, self.cell.x, self.nx);
        let y = self.range(p.y, self.lo.y, self.cell.y, self.ny);
        &self.buckets[y * self.nx + x]
    }

    /// Sectors whose boxes may meet the box `[a, b]`, each once, ascending.
    fn candidates(&self, a: Vec2, b: Vec2) -> Vec<u32> {
        let (x0, x1) = (
            self.range(a.x, self.lo.x, self.cell.x, self.nx),
            self.range(b.x, self.lo.x, self.cell.x, self.nx),
        );
        let (y0, y1) = (
            self.range(a.y, self.lo.y, self.cell.y, self.ny),
            self.range(b.y, self.lo.y, self.cell.y, self.ny),
        );
        let mut out: Vec<u32> = Vec::new();
        for y in y0..=y1 {
            for x in x0..=x1 {
                out.extend_from_slice(&self.buckets[y * self.nx + x]);
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

impl Layout {
    /// A layout of the given polygons, which must cover the table's box without overlapping.
    pub fn new(polys: Vec<Polygon>, table: &Table) -> Result<Layout, LayoutError> {
        polygon::validate_layout(&polys, table.lo, table.hi)?;
        Ok(Layout::covering(polys, table))
    }

    /// A layout of polygons known to cover the table's box without overlapping.
    fn covering(polys: Vec<Polygon>, table: &Table) -> Layout {
        let size = (table.hi - table.lo).norm();
        let adjacent = polygon::adjacency(&polys, 1e-9 * size);
        Layout::with_adjacency(polys, adjacent, table)
    }

    /// A layout of polygons that cover the table's box, with their adjacency.
    fn with_adjacency(polys: Vec<Polygon>, adjacent: Vec<Vec<u32>>, table: &Table) -> Layout {
        let index = BoxIndex::new(&polys, table.lo, table.hi);
        Layout {
            polys,
            adjacent,
            fixed_news: FixedNews::default(),
            index,
        }
    }

    /// An `nx` × `ny` grid over the table's box.
    pub fn grid(table: &Table, nx: u32, ny: u32) -> Layout {
        // a grid covers its box exactly (a unit test checks it), so it skips the validation
        // that a layout read from a file needs
        let polys = polygon::grid(table.lo, table.hi, nx, ny);
        Layout::with_adjacency(polys, polygon::grid_adjacency(nx, ny), table)
    }

    /// The grid the analytic model suggests (thesis ch. 7): square-ish sectors holding about
    /// eight balls each, the upper bound on the best size.
    pub fn auto(table: &Table, balls: usize) -> Layout {
        let span = table.hi - table.lo;
        let side = (8.0 * span.x * span.y / balls.max(1) as f64).sqrt();
        let nx = ((span.x / side).round() as u32).max(1);
        let ny = ((span.y / side).round() as u32).max(1);
        Layout::grid(table, nx, ny)
    }

    /// The first sector (by id) that holds point `p`, as `touching(p, 0.0)` would list first.
    pub fn home(&self, p: Vec2) -> Option<u32> {
        self.index
            .at(p)
            .iter()
            .copied()
            .find(|&k| polygon::touches(&self.polys[k as usize], p, 0.0))
    }

    /// The sectors a disk at `centre` with radius `r` touches.
    pub fn touching(&self, centre: Vec2, r: f64) -> Vec<u32> {
        let d = Vec2::new(r, r);
        self.index
            .candidates(centre - d, centre + d)
            .into_iter()
            .filter(|&k| polygon::touches(&self.polys[k as usize], centre, r))
            .collect()
    }
}

/// For each sector, the fixed objects a ball touching it may reach before it leaves the sectors
/// near them, and the fixed objects no sector is near (all of them with [`FixedNews::Thesis`]).
/// A ball whose disk touches a fixed object at time t has its centre in some sector within its
/// radius of the contact point, and was in sectors within twice its radius for a time r / v
/// before: so a fixed object within `2 rmax` of a sector (plus rounding) hears of every
/// trajectory that can reach it, from the ball when it changes course in such a sector or
/// enters one.
pub(super) fn near_fixed(table: &Table, layout: &Layout, rmax: f64) -> (Vec<Vec<u32>>, Vec<u32>) {
    let size = (table.hi - table.lo).norm();
    let reach = 2.0 * rmax + 1e-9 * size;
    let mut near = vec![Vec::new(); layout.polys.len()];
    let mut far = Vec::new();
    let fixed = table.n_balls..table.n_balls + table.n_fixed();
    if layout.fixed_news == FixedNews::Thesis {
        return (near, fixed.collect());
    }
    for id in fixed {
        let (a, b) = match table.fixed(id) {
            Fixed::Cushion(k) => (table.cushions[k as usize].0, table.cushions[k as usize].1),
            Fixed::Pocket(k) => table.pockets[k as usize],
            Fixed::Corner(k) => (table.corners[k as usize].0, table.corners[k as usize].0),
        };
        let d = Vec2::new(reach, reach);
        let lo = Vec2::new(a.x.min(b.x), a.y.min(b.y)) - d;
        let hi = Vec2::new(a.x.max(b.x), a.y.max(b.y)) + d;
        let mut any = false;
        for k in layout.index.candidates(lo, hi) {
            if layout.polys[k as usize].distance2_to_segment(a, b) <= reach * reach {
                near[k as usize].push(id);
                any = true;
            }
        }
        if !any {
            far.push(id);
        }
    }
    (near, far)
}
