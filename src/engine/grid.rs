//! A uniform cell grid over the table, so that an event costs a bounded number of pair tests.
//!
//! Cells are at least a ball diameter wide (with a small margin), and a ball belongs to the cell
//! holding its centre, so any two touching balls sit in the same or adjacent cells. The outermost
//! cells reach out to infinity: a ball that leaves the table's box stays in its edge cell and the
//! neighbourhood rule still holds. Each cell stores its balls' indices inline in a fixed number of
//! slots, so the 3 × 3 block around a ball is read from three short runs of memory and the balls'
//! own records can then be fetched in parallel (a linked list would chain one cache miss after
//! another); when a cell fills up, every cell gets twice the slots. Fixed objects are listed once
//! per cell they may reach, in compressed rows.

use super::Table;
use crate::geometry::Vec2;
use pdes_kernel::prefetch::prefetch;

const NIL: u32 = u32::MAX;

/// Cells are at least this factor times the largest diameter wide. The margin guarantees that two
/// balls that become neighbours when one of them crosses a cell boundary are strictly apart, so a
/// crossing never uncovers an immediate collision.
const CELL_MARGIN: f64 = 1.0 + 1e-6;

/// The cell grid: geometry, per-cell ball lists and per-cell fixed-object lists.
#[derive(Clone, Debug)]
pub struct Grid {
    lo: Vec2,
    width: f64,
    height: f64,
    nx: u32,
    ny: u32,
    cap: usize,
    /// `cap` ball indices per cell, the balls first and `NIL` after them.
    slots: Vec<u32>,
    cell_of: Vec<u32>,
    fixed_start: Vec<u32>,
    fixed_items: Vec<u32>,
    /// One bit per cell: set where some fixed object is near. Small enough to stay in cache, so
    /// the many cells with none cost no trip to memory.
    has_fixed: Vec<u64>,
}

impl Grid {
    /// Builds a grid for `table` with balls of radius at most `rmax`, `n` balls and the given
    /// minimum cell width (at least a diameter; larger means fewer crossings, more pair tests).
    /// The number of cells is capped near `4 n` so that memory stays linear in the ball count.
    pub fn new(table: &Table, n: usize, rmax: f64, min_cell: f64) -> Grid {
        let span = table.hi - table.lo;
        let w_min = (2.0 * rmax * CELL_MARGIN).max(min_cell);
        let cap = (4 * n).max(16) as f64;
        let mut nx = (span.x / w_min).floor().clamp(1.0, 1e6);
        let mut ny = (span.y / w_min).floor().clamp(1.0, 1e6);
        while nx * ny > cap {
            nx = (nx / 2.0).floor().max(1.0);
            ny = (ny / 2.0).floor().max(1.0);
        }
        let (nx, ny) = (nx as u32, ny as u32);
        let mut g = Grid {
            lo: table.lo,
            width: span.x / f64::from(nx),
            height: span.y / f64::from(ny),
            nx,
            ny,
            cap: 4,
            slots: vec![NIL; 4 * (nx * ny) as usize],
            cell_of: vec![NIL; n],
            fixed_start: Vec::new(),
            fixed_items: Vec::new(),
            has_fixed: vec![0; (nx * ny).div_ceil(64) as usize],
        };
        if g.width.is_nan() || g.width <= 0.0 || g.height.is_nan() || g.height <= 0.0 {
            g.width = w_min;
            g.height = w_min;
        }
        g.index_fixed(table, rmax);
        g
    }

    fn index_fixed(&mut self, table: &Table, rmax: f64) {
        let reach2 = (rmax * 1.01 + 1e-9 * (self.width + self.height)).powi(2);
        let first = table.n_balls;
        let ids: Vec<u32> = (first..first + table.n_fixed()).collect();
        self.fixed_start.push(0);
        for c in 0..self.nx * self.ny {
            let (lo, hi) = self.cell_rect(c);
            for &id in &ids {
                if table.distance2_to_rect(id, lo, hi) <= reach2 {
                    self.fixed_items.push(id);
                    self.has_fixed[c as usize / 64] |= 1 << (c % 64);
                }
            }
            self.fixed_start.push(self.fixed_items.len() as u32);
        }
    }

    /// The rectangle of cell `c`, with outer cells extended to infinity.
    fn cell_rect(&self, c: u32) -> (Vec2, Vec2) {
        let (cx, cy) = (c % self.nx, c / self.nx);
        let x0 = if cx == 0 {
            f64::NEG_INFINITY
        } else {
            self.lo.x + f64::from(cx) * self.width
        };
        let x1 = if cx + 1 == self.nx {
            f64::INFINITY
        } else {
            self.lo.x + f64::from(cx + 1) * self.width
        };
        let y0 = if cy == 0 {
            f64::NEG_INFINITY
        } else {
            self.lo.y + f64::from(cy) * self.height
        };
        let y1 = if cy + 1 == self.ny {
            f64::INFINITY
        } else {
            self.lo.y + f64::from(cy + 1) * self.height
        };
        (Vec2::new(x0, y0), Vec2::new(x1, y1))
    }

    /// Number of cells along x and y.
    pub fn dims(&self) -> (u32, u32) {
        (self.nx, self.ny)
    }

    /// The cell holding point `p` (clamped to the grid).
    #[inline]
    pub fn cell_at(&self, p: Vec2) -> u32 {
        let cx = ((p.x - self.lo.x) / self.width).floor();
        let cy = ((p.y - self.lo.y) / self.height).floor();
        let cx = cx.clamp(0.0, f64::from(self.nx - 1)) as u32;
        let cy = cy.clamp(0.0, f64::from(self.ny - 1)) as u32;
        cy * self.nx + cx
    }

    /// The cell ball `i` is in, or `None` if it was removed.
    #[inline]
    pub fn cell_of(&self, i: u32) -> Option<u32> {
        let c = self.cell_of[i as usize];
        (c != NIL).then_some(c)
    }

    /// Puts ball `i` into cell `c`.
    #[inline]
    pub fn insert(&mut self, i: u32, c: u32) {
        let c = c as usize;
        if self.count(c) == self.cap {
            self.grow();
        }
        let k = self.count(c);
        self.slots[c * self.cap + k] = i;
        self.cell_of[i as usize] = c as u32;
    }

    /// Doubles every cell's slots (a cell overflowed: balls of very different sizes).
    fn grow(&mut self) {
        let cap = 2 * self.cap;
        assert!(cap <= 128, "more than 128 ball centres in one grid cell");
        let cells = self.slots.len() / self.cap;
        let mut slots = vec![NIL; cap * cells];
        for c in 0..cells {
            slots[c * cap..c * cap + self.cap]
                .copy_from_slice(&self.slots[c * self.cap..(c + 1) * self.cap]);
        }
        self.slots = slots;
        self.cap = cap;
    }

    /// Takes ball `i` out of its cell.
    #[inline]
    pub fn remove(&mut self, i: u32) {
        let c = self.cell_of[i as usize];
        if c != NIL {
            self.remove_from(i, c);
        }
    }

    /// Takes ball `i` out of cell `c`, the cell it is in (a caller that knows it saves a read).
    #[inline]
    pub fn remove_from(&mut self, i: u32, c: u32) {
        let c = c as usize;
        let n = self.count(c);
        let cell = &mut self.slots[c * self.cap..c * self.cap + n];
        let k = cell
            .iter()
            .position(|&j| j == i)
            .expect("a ball is in the cell it was put in");
        cell[k] = cell[n - 1];
        cell[n - 1] = NIL;
        self.cell_of[i as usize] = NIL;
    }

    /// How many balls cell `c` holds.
    #[inline]
    fn count(&self, c: usize) -> usize {
        let cell = &self.slots[c * self.cap..(c + 1) * self.cap];
        cell.iter().position(|&j| j == NIL).unwrap_or(self.cap)
    }

    /// Starts loading the 3 × 3 block of cells around cell `c` (if it is a cell) into cache.
    #[inline]
    pub fn prefetch_near(&self, c: u32) {
        if c >= self.nx * self.ny {
            return;
        }
        let (cx, cy) = (c % self.nx, c / self.nx);
        let x0 = cx.saturating_sub(1) as usize;
        let x1 = (cx + 1).min(self.nx - 1) as usize;
        for y in cy.saturating_sub(1)..=(cy + 1).min(self.ny - 1) {
            let row = (y * self.nx) as usize;
            prefetch(&self.slots[(row + x0) * self.cap]);
            prefetch(&self.slots[(row + x1 + 1) * self.cap - 1]);
        }
    }

    /// Calls `f` with every ball in the 3 × 3 block of cells around cell `c` (including any ball
    /// in `c` itself).
    #[inline]
    pub fn for_each_near(&self, c: u32, mut f: impl FnMut(u32)) {
        let (cx, cy) = (c % self.nx, c / self.nx);
        let x0 = cx.saturating_sub(1);
        let x1 = (cx + 1).min(self.nx - 1);
        let y0 = cy.saturating_sub(1);
        let y1 = (cy + 1).min(self.ny - 1);
        for y in y0..=y1 {
            let row = (y * self.nx) as usize;
            let run = (row + x0 as usize) * self.cap..(row + x1 as usize + 1) * self.cap;
            for &j in &self.slots[run] {
                if j != NIL {
                    f(j);
                }
            }
        }
    }

    /// Calls `f` with every ball in the cells of the 3 × 3 block around `to` that are not in the
    /// block around `from` (a ball whose centre moved from `from` to `to`).
    #[inline]
    pub fn for_each_entering(&self, from: u32, to: u32, mut f: impl FnMut(u32)) {
        let (fx, fy) = ((from % self.nx) as i64, (from / self.nx) as i64);
        let (tx, ty) = (to % self.nx, to / self.nx);
        for y in ty.saturating_sub(1)..=(ty + 1).min(self.ny - 1) {
            for x in tx.saturating_sub(1)..=(tx + 1).min(self.nx - 1) {
                if (i64::from(x) - fx).abs() <= 1 && (i64::from(y) - fy).abs() <= 1 {
                    continue;
                }
                let c = (y * self.nx + x) as usize;
                for &j in &self.slots[c * self.cap..(c + 1) * self.cap] {
                    if j != NIL {
                        f(j);
                    }
                }
            }
        }
    }

    /// The fixed objects a ball whose centre is in cell `c` may touch before it leaves the cell.
    #[inline]
    pub fn fixed_near(&self, c: u32) -> &[u32] {
        if self.has_fixed[c as usize / 64] & (1 << (c % 64)) == 0 {
            return &[];
        }
        let (a, b) = (
            self.fixed_start[c as usize] as usize,
            self.fixed_start[c as usize + 1] as usize,
        );
        &self.fixed_items[a..b]
    }

    /// When a centre moving along `position + (t - t0) velocity` leaves cell `c`, and the cell it
    /// enters; `None` if it never leaves (at rest, or heading out through an outer cell).
    #[inline]
    pub fn exit(&self, c: u32, position: Vec2, velocity: Vec2, t0: f64) -> Option<(f64, u32)> {
        let (cx, cy) = (c % self.nx, c / self.nx);
        let mut best: Option<(f64, u32)> = None;
        if velocity.x > 0.0 && cx + 1 < self.nx {
            let b = self.lo.x + f64::from(cx + 1) * self.width;
            best = Some((t0 + (b - position.x) / velocity.x, c + 1));
        } else if velocity.x < 0.0 && cx > 0 {
            let b = self.lo.x + f64::from(cx) * self.width;
            best = Some((t0 + (b - position.x) / velocity.x, c - 1));
        }
        let y = if velocity.y > 0.0 && cy + 1 < self.ny {
            let b = self.lo.y + f64::from(cy + 1) * self.height;
            Some((t0 + (b - position.y) / velocity.y, c + self.nx))
        } else if velocity.y < 0.0 && cy > 0 {
            let b = self.lo.y + f64::from(cy) * self.height;
            Some((t0 + (b - position.y) / velocity.y, c - self.nx))
        } else {
            None
        };
        match (best, y) {
            (Some(a), Some(b)) => Some(if b.0 < a.0 { b } else { a }),
            (a, b) => a.or(b),
        }
    }

    /// Bytes of memory the grid holds.
    pub fn memory_bytes(&self) -> usize {
        4 * (self.slots.len()
            + self.cell_of.len()
            + self.fixed_start.len()
            + self.fixed_items.len())
            + 8 * self.has_fixed.len()
    }
}
