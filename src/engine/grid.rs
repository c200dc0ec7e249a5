//! A uniform cell grid over the table, so that an event costs a bounded number of pair tests.
//!
//! Cells are at least a ball diameter wide (with a small margin), and a ball belongs to the cell
//! holding its centre, so any two touching balls sit in the same or adjacent cells. The outermost
//! cells reach out to infinity: a ball that leaves the table's box stays in its edge cell and the
//! neighbourhood rule still holds.
//!
//! A dense cluster should cost no more per event than the same balls spread out, and memory
//! should stay linear in the ball count `N` on any table. The grid may take one of several
//! layouts, from cells a diameter wide to cells widened until the table holds
//! about `4 N` of them (fewer crossings), and takes the coarsest in which no more than
//! [`CROWDED`] balls share a cell (with at most [`FEW_BALLS`] balls, the coarsest of all: no
//! cell can hold many). Every layout shares one set of cell ids, in one of two forms:
//!
//! * **Dense**, the coarsest layout: an array of every cell in row order, so the 3 × 3 block
//!   around a cell is three short runs of memory and its neighbours are found by arithmetic on
//!   the id.
//! * **Hashed**, every finer one: only the cells near a ball exist, under compact ids from a
//!   hash of their coordinates; each keeps the ids of its existing neighbours. A cell comes into
//!   use when a ball is put in it or its next crossing enters it (always a cell next to the
//!   ball's), and once about `12 N` are in use a sweep recycles those with no ball in their
//!   3 × 3 block. Fixed objects are listed per square block of cells, about `4 N` blocks in all,
//!   and a cell takes its block's list.
//!
//! Balls move, so the layout that suits them changes: a cluster forms in a dilute gas, or
//! flies apart. A cell that overflows its slots marks the grid crowded, and the engine that owns
//! it asks [`Grid::relaid`] for a finer layout; it also asks from time to time whether a
//! coarser one suits the balls again, and then places every ball anew.
//!
//! Each cell stores its balls' indices inline in a fixed number of slots, so a block's balls are
//! read from a few short runs of memory and the balls' own records can then be fetched in
//! parallel (a linked list would chain one cache miss after another); when a cell fills up,
//! every cell gets twice the slots, up to sixteen. Beyond that (balls of very different
//! sizes crowding one cell) the extra balls go to the cell's spill list. The fast paths serve the
//! dense layout with nothing spilled; the hashed layout and spilled balls take a general path
//! through the cell coordinates. Fixed objects are listed once per dense cell or hashed block
//! they may reach.

use super::Table;
use crate::geometry::Vec2;
use pdes_kernel::prefetch::prefetch;
use rustc_hash::FxHashMap;

const NIL: u32 = u32::MAX;

/// Cells are at least this factor times the largest diameter wide. The margin guarantees that two
/// balls that become neighbours when one of them crosses a cell boundary are strictly apart, so a
/// crossing never uncovers an immediate collision.
const CELL_MARGIN: f64 = 1.0 + 1e-6;

/// With at most this many balls the layout is dense on any table: no cell can hold more of them,
/// and wider cells mean fewer crossings.
pub const FEW_BALLS: usize = 64;

/// A layout is used only if at most this many balls share any one of its cells (bar the finest,
/// which is used in any case).
pub const CROWDED: usize = 8;

/// The most slots a cell holds inline; further balls go to its spill list.
const MAX_SLOTS: usize = 16;

/// The most cells along a side, so that cell coordinates and their neighbours' fit in a `u32`.
const MAX_SIDE: f64 = (1u32 << 30) as f64;

/// The steps to the four cells that share an edge with a cell.
const STEPS: [(i64, i64); 4] = [(1, 0), (-1, 0), (0, 1), (0, -1)];

/// For each of [`STEPS`], the neighbours (places in [`AROUND`]) of the cell stepped into that are
/// not next to the cell stepped from.
const ENTERING: [[usize; 3]; 4] = [[2, 4, 7], [0, 3, 5], [5, 6, 7], [0, 1, 2]];

/// The eight neighbours of a cell as coordinate offsets; entry `7 - k` is the opposite of `k`.
const AROUND: [(i32, i32); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

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
    /// Each cell's fixed objects: a range of `fixed_items`.
    fixed_span: Vec<(u32, u32)>,
    fixed_items: Vec<u32>,
    /// One bit per cell: set where some fixed object is near. Small enough to stay in cache, so
    /// the many cells with none cost no trip to memory.
    has_fixed: Vec<u64>,
    /// Set when the fast paths do not apply: the layout is hashed, or some ball is spilled.
    general: bool,
    /// The hashed layout's cells; `None` for the dense layout.
    hashed: Option<Box<Hashed>>,
    /// The balls beyond a full cell's slots, by cell.
    spill: FxHashMap<u32, Vec<u32>>,
    /// Set when a cell overflows its slots in a layout that has finer ones (with more than
    /// [`FEW_BALLS`] balls).
    crowded: bool,
    /// Which of `layouts` this grid is.
    level: usize,
    /// The layouts the grid may take over its table.
    layouts: Layouts,
}

/// The layouts a grid may take over one table, from the finest (cells at least a diameter wide,
/// hashed if the table holds more than about `4 N` of them) to the coarsest (the dense layout).
#[derive(Clone, Debug)]
struct Layouts {
    /// Cells along x and y of each layout: the finest first, and each next one with half as many
    /// along each side, until the table holds at most about `4 N` cells.
    dims: Vec<(u32, u32)>,
    /// About `4 N`: the most cells of the dense layout, and of the hashed layout's blocks.
    most: f64,
    /// The smallest cell width.
    w_min: f64,
    /// The largest ball radius.
    rmax: f64,
    /// The number of balls the grid places.
    n: usize,
    /// Whether the table is a periodic box: cells then tile it exactly, at least three along
    /// each side, and wrap around at its sides.
    periodic: bool,
}

impl Layouts {
    /// The layouts for `n` balls of radius at most `rmax` on `table`, cells at least `min_cell`
    /// wide.
    fn new(table: &Table, n: usize, rmax: f64, min_cell: f64) -> Layouts {
        let span = table.hi - table.lo;
        let w_min = (2.0 * rmax * CELL_MARGIN).max(min_cell);
        let most = (4 * n).max(16) as f64;
        let periodic = table.period.is_some();
        // a periodic box keeps three cells along a side even where `min_cell` asks for fewer
        // (its validation makes sure that three are each a diameter wide)
        let fewest = if periodic { 3.0 } else { 1.0 };
        let (mut nx, mut ny) = (
            (span.x / w_min).floor().clamp(fewest, MAX_SIDE),
            (span.y / w_min).floor().clamp(fewest, MAX_SIDE),
        );
        let mut dims = vec![(nx as u32, ny as u32)];
        while nx * ny > most {
            nx = (nx / 2.0).floor().max(fewest);
            ny = (ny / 2.0).floor().max(fewest);
            dims.push((nx as u32, ny as u32));
        }
        Layouts {
            dims,
            most,
            w_min,
            rmax,
            n,
            periodic,
        }
    }

    /// The coarsest layout among `levels` in which no more than `limit` of `centres` share a
    /// cell (with at most [`FEW_BALLS`] balls, the coarsest of all: no cell can hold many), or
    /// `None` if there is none.
    fn coarsest(
        &self,
        table: &Table,
        centres: &[Vec2],
        levels: std::ops::Range<usize>,
        limit: usize,
    ) -> Option<usize> {
        if self.n <= FEW_BALLS {
            return Some(self.dims.len() - 1).filter(|l| levels.contains(l));
        }
        levels
            .rev()
            .find(|&l| !crowded(table, centres, self.dims[l], limit))
    }
}

/// The cells of the hashed layout: those in use, under compact ids.
#[derive(Clone, Debug)]
struct Hashed {
    /// Cell coordinates (`y << 32 | x`) to id.
    ids: FxHashMap<u64, u32>,
    /// Each id's coordinates; `(NIL, NIL)` for a free id.
    at: Vec<(u32, u32)>,
    /// Each id's neighbours in [`AROUND`] order (`NIL` where none exists).
    around: Vec<[u32; 8]>,
    /// Free ids.
    free: Vec<u32>,
    /// Ids in use before a sweep recycles idle ones.
    limit: usize,
    /// Cells along a side of a block.
    side: u32,
    /// Blocks along x.
    blocks_x: u32,
    /// Each block's fixed objects: a range of the grid's `fixed_items`.
    block_fixed: Vec<(u32, u32)>,
}

impl Grid {
    /// Builds a grid for `table` with balls of radius at most `rmax` whose centres start at
    /// `centres`, and the given minimum cell width (at least a diameter; larger means fewer
    /// crossings, more pair tests). Its layout is the coarsest of its layouts in which no more
    /// than [`CROWDED`] balls start in any one cell.
    pub fn new(table: &Table, centres: &[Vec2], rmax: f64, min_cell: f64) -> Grid {
        let layouts = Layouts::new(table, centres.len(), rmax, min_cell);
        let levels = layouts.dims.len();
        let level = match levels {
            1 => 0,
            _ => layouts
                .coarsest(table, centres, 0..levels, CROWDED)
                .unwrap_or(0),
        };
        Grid::laid_out(table, layouts, level)
    }

    /// An empty grid of exactly `nx` × `ny` cells over `table`'s box for balls of radius at
    /// most `rmax`, in the dense form, with room for `n` ball indices (more come with
    /// [`Grid::hold_balls`]): one layout that never changes, for an engine that lays several
    /// grids side by side and needs their columns to stay where it put them.
    pub fn with_dims(table: &Table, n: usize, rmax: f64, (nx, ny): (u32, u32)) -> Grid {
        let layouts = Layouts {
            dims: vec![(nx, ny)],
            most: f64::from(nx) * f64::from(ny),
            w_min: 2.0 * rmax * CELL_MARGIN,
            rmax,
            n,
            periodic: false,
        };
        Grid::laid_out(table, layouts, 0)
    }

    /// The cells along x and y of the coarsest layout this grid may take with at least
    /// `columns` cells along x, if it has one.
    pub fn dims_with_columns(&self, columns: u32) -> Option<(u32, u32)> {
        self.layouts
            .dims
            .iter()
            .rev()
            .find(|d| d.0 >= columns)
            .copied()
    }

    /// Makes room for ball indices below `n`.
    pub fn hold_balls(&mut self, n: usize) {
        if self.cell_of.len() < n {
            self.cell_of.resize(n, NIL);
        }
    }

    /// Puts ball `i` into the cell of column `cx` whose row holds point `p`, and returns that
    /// cell (dense layout).
    pub fn insert_in_column(&mut self, i: u32, cx: u32, p: Vec2) -> u32 {
        let (_, cy) = self.coords_at(p);
        let c = cy * self.nx + cx.min(self.nx - 1);
        self.insert(i, c);
        c
    }

    /// The column of cell `c`.
    #[inline]
    pub fn column(&self, c: u32) -> u32 {
        self.coords(c).0
    }

    /// An empty grid in `layouts`' layout number `level`.
    fn laid_out(table: &Table, layouts: Layouts, level: usize) -> Grid {
        let (nx, ny) = layouts.dims[level];
        // a periodic box takes the dense form at every level: its cells wrap around by
        // arithmetic on their coordinates
        let hashed = level + 1 < layouts.dims.len() && !layouts.periodic;
        let span = table.hi - table.lo;
        let cells = if hashed { 0 } else { (nx * ny) as usize };
        let mut g = Grid {
            lo: table.lo,
            width: span.x / f64::from(nx),
            height: span.y / f64::from(ny),
            nx,
            ny,
            cap: 4,
            slots: vec![NIL; 4 * cells],
            cell_of: vec![NIL; layouts.n],
            fixed_span: Vec::with_capacity(cells),
            fixed_items: Vec::new(),
            has_fixed: vec![0; cells.div_ceil(64)],
            general: hashed || layouts.periodic,
            hashed: None,
            spill: FxHashMap::default(),
            crowded: false,
            level,
            layouts,
        };
        if g.width.is_nan() || g.width <= 0.0 || g.height.is_nan() || g.height <= 0.0 {
            g.width = g.layouts.w_min;
            g.height = g.layouts.w_min;
        }
        let reach2 = (g.layouts.rmax * 1.01 + 1e-9 * (g.width + g.height)).powi(2);
        if hashed {
            g.hashed = Some(Box::new(g.blocks(table, reach2, g.layouts.most)));
        } else {
            for c in 0..nx * ny {
                let span = g.list_fixed(table, reach2, g.cell_rect((c % nx, c / nx)));
                g.fixed_span.push(span);
                if span.1 > span.0 {
                    g.has_fixed[c as usize / 64] |= 1 << (c % 64);
                }
            }
        }
        g
    }

    /// An empty grid laid out for balls whose centres are now at `centres` (those on the table),
    /// or `None` if the present layout still suits them. Once a cell of this layout has
    /// overflowed its slots (a cluster has formed), the coarsest layout no coarser than this one
    /// where no cell holds more than [`CROWDED`] (the finest if none), so this one if the balls
    /// have moved apart again. Otherwise, the coarsest coarser layout where no cell holds more
    /// than [`CROWDED`] (a cluster has spread out), if any.
    pub fn relaid(&mut self, table: &Table, centres: &[Vec2]) -> Option<Grid> {
        let last = self.layouts.dims.len() - 1;
        let level = if std::mem::take(&mut self.crowded) {
            let coarsest = self
                .layouts
                .coarsest(table, centres, 0..self.level + 1, CROWDED);
            coarsest.unwrap_or(0)
        } else if self.level < last {
            let coarser = self.level + 1..last + 1;
            let coarsest = self.layouts.coarsest(table, centres, coarser, CROWDED);
            coarsest.unwrap_or(self.level)
        } else {
            self.level
        };
        (level != self.level).then(|| Grid::laid_out(table, self.layouts.clone(), level))
    }

    /// Whether the layout is the coarsest the grid may take.
    #[inline]
    pub fn is_coarsest(&self) -> bool {
        self.level + 1 == self.layouts.dims.len()
    }

    /// Whether a cell of a layout that has finer ones has overflowed its slots since the grid
    /// was laid out: a cluster has formed.
    #[inline]
    pub fn is_crowded(&self) -> bool {
        self.crowded
    }

    /// The hashed layout, with no cell in use yet and the fixed objects listed per square block
    /// of cells, the blocks as few as about `most`.
    fn blocks(&mut self, table: &Table, reach2: f64, most: f64) -> Hashed {
        let mut side = 1;
        while f64::from(self.nx.div_ceil(side)) * f64::from(self.ny.div_ceil(side)) > most {
            side *= 2;
        }
        let (bx, by) = (self.nx.div_ceil(side), self.ny.div_ceil(side));
        let mut block_fixed = Vec::with_capacity((bx * by) as usize);
        for b in 0..bx * by {
            let (x, y) = ((b % bx) * side, (b / bx) * side);
            let last = ((x + side).min(self.nx) - 1, (y + side).min(self.ny) - 1);
            let (lo, hi) = (self.cell_rect((x, y)).0, self.cell_rect(last).1);
            block_fixed.push(self.list_fixed(table, reach2, (lo, hi)));
        }
        Hashed {
            ids: FxHashMap::default(),
            at: Vec::new(),
            around: Vec::new(),
            free: Vec::new(),
            limit: 3 * most as usize + 64,
            side,
            blocks_x: bx,
            block_fixed,
        }
    }

    /// Lists the fixed objects within `reach2` (squared) of the rectangle from `lo` to `hi`, and
    /// returns their range of `fixed_items`.
    fn list_fixed(&mut self, table: &Table, reach2: f64, (lo, hi): (Vec2, Vec2)) -> (u32, u32) {
        let start = self.fixed_items.len() as u32;
        let first = table.n_balls;
        for id in first..first + table.n_fixed() {
            if table.distance2_to_rect(id, lo, hi) <= reach2 {
                self.fixed_items.push(id);
            }
        }
        (start, self.fixed_items.len() as u32)
    }

    /// The rectangle of the cell at coordinates `(cx, cy)`, with outer cells extended to
    /// infinity.
    fn cell_rect(&self, (cx, cy): (u32, u32)) -> (Vec2, Vec2) {
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

    /// Whether the layout is hashed (a table larger than about `4 N` cells).
    pub fn is_hashed(&self) -> bool {
        self.hashed.is_some()
    }

    /// The coordinates of the cell holding point `p` (clamped to the grid).
    #[inline]
    fn coords_at(&self, p: Vec2) -> (u32, u32) {
        let cx = ((p.x - self.lo.x) / self.width).floor();
        let cy = ((p.y - self.lo.y) / self.height).floor();
        let cx = cx.clamp(0.0, f64::from(self.nx - 1)) as u32;
        let cy = cy.clamp(0.0, f64::from(self.ny - 1)) as u32;
        (cx, cy)
    }

    /// The coordinates of cell `c`.
    fn coords(&self, c: u32) -> (u32, u32) {
        match &self.hashed {
            Some(h) => h.at[c as usize],
            None => (c % self.nx, c / self.nx),
        }
    }

    /// Puts ball `i` into the cell holding point `p`, and returns that cell.
    pub fn insert_at(&mut self, i: u32, p: Vec2) -> u32 {
        let (cx, cy) = self.coords_at(p);
        let c = if self.hashed.is_some() {
            self.cell_in_use(cx, cy)
        } else {
            cy * self.nx + cx
        };
        self.insert(i, c);
        c
    }

    /// Moves ball `i` (which must be on the grid) into the cell holding point `p` if it is not
    /// there already.
    pub fn move_to(&mut self, i: u32, p: Vec2) {
        let c = self.cell_of[i as usize];
        if self.coords(c) != self.coords_at(p) {
            self.remove_from(i, c);
            self.insert_at(i, p);
        }
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
            if self.cap == MAX_SLOTS {
                self.spill_into(i, c as u32);
                return;
            }
            self.grow();
        }
        let k = self.count(c);
        self.slots[c * self.cap + k] = i;
        self.cell_of[i as usize] = c as u32;
    }

    /// Puts ball `i` into the spill list of cell `c`, whose slots are full.
    #[cold]
    fn spill_into(&mut self, i: u32, c: u32) {
        self.crowded |= self.level > 0 && self.layouts.n > FEW_BALLS;
        self.spill.entry(c).or_default().push(i);
        self.cell_of[i as usize] = c;
        self.general = true;
    }

    /// Doubles every cell's slots (a cell overflowed).
    fn grow(&mut self) {
        let cap = 2 * self.cap;
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
        match cell.iter().position(|&j| j == i) {
            Some(k) => {
                cell[k] = cell[n - 1];
                cell[n - 1] = NIL;
            }
            None => self.unspill(i, c as u32),
        }
        self.cell_of[i as usize] = NIL;
    }

    /// Takes ball `i` out of the spill list of cell `c`.
    #[cold]
    fn unspill(&mut self, i: u32, c: u32) {
        let list = self
            .spill
            .get_mut(&c)
            .expect("a ball is in the cell it was put in");
        let k = list
            .iter()
            .position(|&j| j == i)
            .expect("a ball is in the cell it was put in");
        list.swap_remove(k);
        if list.is_empty() {
            self.spill.remove(&c);
        }
    }

    /// How many balls cell `c` holds in its slots.
    #[inline]
    fn count(&self, c: usize) -> usize {
        let cell = &self.slots[c * self.cap..(c + 1) * self.cap];
        cell.iter().position(|&j| j == NIL).unwrap_or(self.cap)
    }

    /// Starts loading the 3 × 3 block of cells around cell `c` (if it is a cell) into cache.
    #[inline]
    pub fn prefetch_near(&self, c: u32) {
        if self.layouts.periodic {
            // the middle cell of each row is next to one of the others in memory
            let (xs, ys) = self.wrapped_around(c);
            for y in ys {
                for x in [xs[0], xs[2]] {
                    prefetch(&self.slots[(y * self.nx + x) as usize * self.cap]);
                }
            }
            return;
        }
        if self.general {
            self.prefetch_block(c);
            return;
        }
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
        if self.layouts.periodic {
            self.for_each_near_image(c, |j, _| f(j));
            return;
        }
        if self.general {
            self.for_each_in_block(c, &mut f);
            return;
        }
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
        if self.general {
            self.for_each_entering_block(from, to, &mut f);
            return;
        }
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

    /// The ids of the cells of the 3 × 3 block around cell `c`, `c` first (none if `c` is no
    /// cell).
    pub fn cells_near(&self, c: u32) -> impl Iterator<Item = u32> {
        self.block(c).into_iter().filter(|&k| k != NIL)
    }

    /// The ids of the 3 × 3 block of cells around cell `c`, `c` first (`NIL` where there is no
    /// cell, and all `NIL` if `c` is no cell).
    fn block(&self, c: u32) -> [u32; 9] {
        let mut out = [NIL; 9];
        match &self.hashed {
            Some(h) => {
                if let Some(around) = h.around.get(c as usize) {
                    out[0] = c;
                    out[1..].copy_from_slice(around);
                }
            }
            None if c < self.nx * self.ny => {
                out[0] = c;
                if self.layouts.periodic {
                    let (xs, ys) = self.wrapped_around(c);
                    for (k, &(dx, dy)) in AROUND.iter().enumerate() {
                        out[k + 1] = ys[(dy + 1) as usize] * self.nx + xs[(dx + 1) as usize];
                    }
                    return out;
                }
                let (cx, cy) = (i64::from(c % self.nx), i64::from(c / self.nx));
                let (nx, ny) = (i64::from(self.nx), i64::from(self.ny));
                for (k, &(dx, dy)) in AROUND.iter().enumerate() {
                    let (x, y) = (cx + i64::from(dx), cy + i64::from(dy));
                    if (0..nx).contains(&x) && (0..ny).contains(&y) {
                        out[k + 1] = (y * nx + x) as u32;
                    }
                }
            }
            None => {}
        }
        out
    }

    /// Calls `f` with every ball of cell `c`: its slots, then its spill list.
    #[inline(always)]
    fn for_each_in(&self, c: u32, f: &mut impl FnMut(u32)) {
        let c = c as usize;
        for &j in &self.slots[c * self.cap..(c + 1) * self.cap] {
            if j != NIL {
                f(j);
            }
        }
        if !self.spill.is_empty() {
            if let Some(list) = self.spill.get(&(c as u32)) {
                list.iter().for_each(|&j| f(j));
            }
        }
    }

    /// [`Grid::prefetch_near`] through the cell ids.
    #[inline(never)]
    fn prefetch_block(&self, c: u32) {
        let Some(h) = &self.hashed else {
            for k in self.block(c) {
                if k != NIL {
                    prefetch(&self.slots[k as usize * self.cap]);
                }
            }
            return;
        };
        if let Some(around) = h.around.get(c as usize) {
            prefetch(&self.slots[c as usize * self.cap]);
            // a missing neighbour (`NIL`) is past the end
            for &k in around {
                if let Some(slot) = self.slots.get(k as usize * self.cap) {
                    prefetch(slot);
                }
            }
        }
    }

    /// [`Grid::for_each_near`] through the cell ids.
    #[inline(never)]
    fn for_each_in_block(&self, c: u32, f: &mut impl FnMut(u32)) {
        let Some(h) = &self.hashed else {
            for k in self.block(c) {
                if k != NIL {
                    self.for_each_in(k, f);
                }
            }
            return;
        };
        self.for_each_in(c, f);
        for &k in &h.around[c as usize] {
            if k != NIL {
                self.for_each_in(k, f);
            }
        }
    }

    /// [`Grid::for_each_entering`] through the cell ids and their coordinates.
    #[inline(never)]
    fn for_each_entering_block(&self, from: u32, to: u32, f: &mut impl FnMut(u32)) {
        if self.layouts.periodic {
            self.for_each_entering_image(from, to, |j, _| f(j));
            return;
        }
        let (fx, fy) = self.coords(from);
        let (tx, ty) = self.coords(to);
        let step = (i64::from(tx) - i64::from(fx), i64::from(ty) - i64::from(fy));
        if let (Some(h), Some(k)) = (&self.hashed, STEPS.iter().position(|&d| d == step)) {
            // a crossing into a cell next to it: the three cells on its far side
            for e in ENTERING[k] {
                let n = h.around[to as usize][e];
                if n != NIL {
                    self.for_each_in(n, f);
                }
            }
            return;
        }
        let (fx, fy) = (i64::from(fx), i64::from(fy));
        let block = self.block(to);
        let (tx, ty) = (i64::from(tx), i64::from(ty));
        for (&n, (dx, dy)) in block.iter().zip([(0, 0)].into_iter().chain(AROUND)) {
            let (x, y) = (tx + i64::from(dx), ty + i64::from(dy));
            if n != NIL && ((x - fx).abs() > 1 || (y - fy).abs() > 1) {
                self.for_each_in(n, f);
            }
        }
    }

    /// In a periodic box: calls `f` with every ball in the 3 × 3 block of cells around cell `c`
    /// (including `c`), and with the offset of its cell from `c` in cells (each of `-1, 0, 1`
    /// along x and y): which image of the ball is the neighbour.
    #[inline]
    pub fn for_each_near_image(&self, c: u32, mut f: impl FnMut(u32, (i32, i32))) {
        if self.spill.is_empty() {
            // nothing spilled: each cell's balls are its slots up to the first `NIL`
            let (xs, ys) = self.wrapped_around(c);
            for (y, dy) in ys.into_iter().zip(-1..=1) {
                let row = y * self.nx;
                for (x, dx) in xs.into_iter().zip(-1..=1) {
                    let cell = (row + x) as usize * self.cap;
                    for &j in &self.slots[cell..cell + self.cap] {
                        if j == NIL {
                            break;
                        }
                        f(j, (dx, dy));
                    }
                }
            }
            return;
        }
        let block = self.block(c);
        for (&n, offset) in block.iter().zip([(0, 0)].into_iter().chain(AROUND)) {
            if n != NIL {
                self.for_each_in(n, &mut |j| f(j, offset));
            }
        }
    }

    /// In a periodic box: calls `f` with every ball in the cells of the 3 × 3 block around `to`
    /// that are not in the block around `from` (a neighbouring cell, which a centre left for
    /// `to`), and with the offset of its cell from `to`. With three cells along a side one cell
    /// may be in both blocks as two different images: it is new as the image it is around `to`.
    pub fn for_each_entering_image(&self, from: u32, to: u32, mut f: impl FnMut(u32, (i32, i32))) {
        let (fx, fy) = self.coords(from);
        let (tx, ty) = self.coords(to);
        // the step from `from` to `to`, each of -1, 0, 1 whichever side of the box it crossed
        let step = |t: u32, f: u32, n: u32| -> i32 {
            match (i64::from(t) - i64::from(f)).rem_euclid(i64::from(n)) {
                0 => 0,
                1 => 1,
                _ => -1,
            }
        };
        let (sx, sy) = (step(tx, fx, self.nx), step(ty, fy, self.ny));
        let (xs, ys) = self.wrapped_around(to);
        for (y, dy) in ys.into_iter().zip(-1..=1) {
            for (x, dx) in xs.into_iter().zip(-1..=1) {
                if (dx + sx).abs() > 1 || (dy + sy).abs() > 1 {
                    self.for_each_in(y * self.nx + x, &mut |j| f(j, (dx, dy)));
                }
            }
        }
    }

    /// In a periodic box, the columns and rows of the 3 × 3 block around cell `c`, from the
    /// lower left, wrapped round the box.
    #[inline]
    fn wrapped_around(&self, c: u32) -> ([u32; 3], [u32; 3]) {
        let (cx, cy) = (c % self.nx, c / self.nx);
        let before = |v: u32, n: u32| if v == 0 { n - 1 } else { v - 1 };
        let after = |v: u32, n: u32| if v + 1 == n { 0 } else { v + 1 };
        (
            [before(cx, self.nx), cx, after(cx, self.nx)],
            [before(cy, self.ny), cy, after(cy, self.ny)],
        )
    }

    /// The size of a cell along x and y.
    pub fn cell_size(&self) -> Vec2 {
        Vec2::new(self.width, self.height)
    }

    /// The centre of cell `c` of the dense layout.
    pub fn cell_centre(&self, c: u32) -> Vec2 {
        let (cx, cy) = self.coords(c);
        Vec2::new(
            self.lo.x + (f64::from(cx) + 0.5) * self.width,
            self.lo.y + (f64::from(cy) + 0.5) * self.height,
        )
    }

    /// The fixed objects a ball whose centre is in cell `c` may touch before it leaves the cell.
    #[inline]
    pub fn fixed_near(&self, c: u32) -> &[u32] {
        if self.has_fixed[c as usize / 64] & (1 << (c % 64)) == 0 {
            return &[];
        }
        let (a, b) = self.fixed_span[c as usize];
        &self.fixed_items[a as usize..b as usize]
    }

    /// When a centre in cell `c`, moving along `position + (t - t0) velocity`, leaves the cell,
    /// and the cell it enters; `None` if it never leaves (at rest, or heading out through an
    /// outer cell). In the hashed layout the cell entered is brought into use: it stays while a
    /// cell next to it holds a ball.
    #[inline]
    pub fn exit(&mut self, c: u32, position: Vec2, velocity: Vec2, t0: f64) -> Option<(f64, u32)> {
        if self.general {
            return self.exit_general(c, position, velocity, t0);
        }
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

    /// [`Grid::exit`] through the cell coordinates.
    #[inline(never)]
    fn exit_general(
        &mut self,
        c: u32,
        position: Vec2,
        velocity: Vec2,
        t0: f64,
    ) -> Option<(f64, u32)> {
        let (cx, cy) = self.coords(c);
        // a periodic box's outer cells are left through the box's sides too
        let wraps = self.layouts.periodic;
        // the time, and the neighbour entered as its place in `AROUND`
        let mut best: Option<(f64, usize)> = None;
        if velocity.x > 0.0 && (wraps || cx + 1 < self.nx) {
            let b = self.lo.x + f64::from(cx + 1) * self.width;
            best = Some((t0 + (b - position.x) / velocity.x, 4));
        } else if velocity.x < 0.0 && (wraps || cx > 0) {
            let b = self.lo.x + f64::from(cx) * self.width;
            best = Some((t0 + (b - position.x) / velocity.x, 3));
        }
        let y = if velocity.y > 0.0 && (wraps || cy + 1 < self.ny) {
            let b = self.lo.y + f64::from(cy + 1) * self.height;
            Some((t0 + (b - position.y) / velocity.y, 6))
        } else if velocity.y < 0.0 && (wraps || cy > 0) {
            let b = self.lo.y + f64::from(cy) * self.height;
            Some((t0 + (b - position.y) / velocity.y, 1))
        } else {
            None
        };
        let (t, k) = match (best, y) {
            (Some(a), Some(b)) => Some(if b.0 < a.0 { b } else { a }),
            (a, b) => a.or(b),
        }?;
        let (dx, dy) = AROUND[k];
        let (mut x, mut y) = (cx.wrapping_add_signed(dx), cy.wrapping_add_signed(dy));
        if wraps {
            x = (i64::from(cx) + i64::from(dx)).rem_euclid(i64::from(self.nx)) as u32;
            y = (i64::from(cy) + i64::from(dy)).rem_euclid(i64::from(self.ny)) as u32;
        }
        let to = match &self.hashed {
            None => y * self.nx + x,
            Some(h) if h.around[c as usize][k] != NIL => h.around[c as usize][k],
            Some(_) => self.cell_in_use(x, y),
        };
        Some((t, to))
    }

    /// The id of the cell at coordinates `(x, y)` in the hashed layout, brought into use if it
    /// was not.
    fn cell_in_use(&mut self, x: u32, y: u32) -> u32 {
        let h = self.hashed.as_mut().expect("hashed layout");
        let key = u64::from(y) << 32 | u64::from(x);
        if let Some(&c) = h.ids.get(&key) {
            return c;
        }
        if h.free.is_empty() && h.ids.len() >= h.limit {
            self.sweep();
        }
        let h = self.hashed.as_mut().expect("hashed layout");
        let c = match h.free.pop() {
            Some(c) => c,
            None => {
                let c = h.at.len() as u32;
                h.at.push((NIL, NIL));
                h.around.push([NIL; 8]);
                self.slots.resize(self.slots.len() + self.cap, NIL);
                self.has_fixed.resize((c as usize + 1).div_ceil(64), 0);
                c
            }
        };
        h.ids.insert(key, c);
        h.at[c as usize] = (x, y);
        for (k, &(dx, dy)) in AROUND.iter().enumerate() {
            let (ax, ay) = (i64::from(x) + i64::from(dx), i64::from(y) + i64::from(dy));
            if ax < 0 || ay < 0 {
                continue;
            }
            if let Some(&n) = h.ids.get(&((ay as u64) << 32 | ax as u64)) {
                h.around[c as usize][k] = n;
                h.around[n as usize][7 - k] = c;
            }
        }
        let span = h.block_fixed[((y / h.side) * h.blocks_x + x / h.side) as usize];
        match self.fixed_span.get_mut(c as usize) {
            Some(s) => *s = span,
            None => self.fixed_span.push(span),
        }
        if span.1 > span.0 {
            self.has_fixed[c as usize / 64] |= 1 << (c % 64);
        }
        c
    }

    /// Recycles the ids of the hashed cells with no ball in their 3 × 3 block. A cell that a
    /// ball's next crossing enters is next to that ball's cell, so it stays.
    fn sweep(&mut self) {
        let idle: Vec<u32> = (0..self.slots.len() / self.cap)
            .map(|c| c as u32)
            .filter(|&c| self.coords(c).0 != NIL)
            .filter(|&c| self.block(c).iter().all(|&k| k == NIL || self.is_empty(k)))
            .collect();
        let h = self.hashed.as_mut().expect("hashed layout");
        for c in idle {
            let (x, y) = h.at[c as usize];
            h.ids.remove(&(u64::from(y) << 32 | u64::from(x)));
            for (k, n) in h.around[c as usize].into_iter().enumerate() {
                if n != NIL {
                    h.around[n as usize][7 - k] = NIL;
                }
            }
            h.around[c as usize] = [NIL; 8];
            h.at[c as usize] = (NIL, NIL);
            self.has_fixed[c as usize / 64] &= !(1 << (c % 64));
            h.free.push(c);
        }
    }

    /// Whether cell `c` holds no ball.
    fn is_empty(&self, c: u32) -> bool {
        self.slots[c as usize * self.cap] == NIL && !self.spill.contains_key(&c)
    }

    /// Bytes of memory the grid holds.
    pub fn memory_bytes(&self) -> usize {
        let hashed = self.hashed.as_ref().map_or(0, |h| {
            h.ids.capacity() * 16
                + h.at.len() * 8
                + h.around.len() * 32
                + 4 * h.free.len()
                + 8 * h.block_fixed.len()
        });
        4 * (self.slots.len() + self.cell_of.len() + self.fixed_items.len())
            + 8 * (self.fixed_span.len() + self.has_fixed.len())
            + self.spill.values().map(|l| 4 * l.capacity()).sum::<usize>()
            + hashed
    }
}

/// Whether more than `limit` of `centres` fall in one cell of an `nx` × `ny` grid over `table`.
fn crowded(table: &Table, centres: &[Vec2], (nx, ny): (u32, u32), limit: usize) -> bool {
    let span = table.hi - table.lo;
    let (w, h) = (span.x / f64::from(nx), span.y / f64::from(ny));
    let dense = u64::from(nx) * u64::from(ny) <= 4 * centres.len() as u64 + 16;
    let mut count = vec![0usize; if dense { (nx * ny) as usize } else { 0 }];
    let mut hashed = FxHashMap::<u64, usize>::default();
    centres.iter().any(|p| {
        let cx = ((p.x - table.lo.x) / w)
            .floor()
            .clamp(0.0, f64::from(nx - 1)) as u32;
        let cy = ((p.y - table.lo.y) / h)
            .floor()
            .clamp(0.0, f64::from(ny - 1)) as u32;
        let k = if dense {
            &mut count[(cy * nx + cx) as usize]
        } else {
            hashed
                .entry(u64::from(cy) << 32 | u64::from(cx))
                .or_default()
        };
        *k += 1;
        *k > limit
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::{BallSpec, CushionSpec, Scenario};

    /// A `side` × `side` box of cushions with `n` balls of radius 1 (their places do not matter
    /// to the grid's layout).
    fn table(n: usize, side: f64) -> Table {
        let c = |a: (f64, f64), b: (f64, f64)| CushionSpec {
            from: Vec2::new(a.0, a.1),
            to: Vec2::new(b.0, b.1),
            elasticity: 1.0,
        };
        let ball = BallSpec {
            position: Vec2::new(5.0, 5.0),
            velocity: Vec2::ZERO,
            radius: 1.0,
            mass: 1.0,
            fixed: None,
            pocket: None,
            colour: None,
            label: None,
        };
        Table::new(&Scenario {
            name: "grid".to_string(),
            until: 1.0,
            balls: vec![ball; n],
            cushions: vec![
                c((0.0, 0.0), (0.0, side)),
                c((0.0, side), (side, side)),
                c((side, side), (side, 0.0)),
                c((side, 0.0), (0.0, 0.0)),
            ],
            pockets: Vec::new(),
            sectors: None,
            periodic: None,
        })
    }

    fn near(g: &Grid, c: u32) -> Vec<u32> {
        let mut seen = Vec::new();
        g.for_each_near(c, |j| seen.push(j));
        seen.sort_unstable();
        seen
    }

    #[test]
    fn any_number_of_centres_share_a_cell() {
        let n = 300;
        for (side, hashed) in [(10.0, false), (4000.0, true)] {
            let mut g = Grid::new(&table(n, side), &vec![Vec2::new(5.0, 5.0); n], 1.0, 2.0);
            assert_eq!(g.is_hashed(), hashed);
            let cells: Vec<u32> = (0..n as u32)
                .map(|i| g.insert_at(i, Vec2::new(5.0, 5.0)))
                .collect();
            assert!(cells.iter().all(|&c| c == cells[0]));
            assert_eq!(near(&g, cells[0]), (0..n as u32).collect::<Vec<_>>());
            for i in (0..n as u32).step_by(2) {
                g.remove(i);
            }
            let odd: Vec<u32> = (1..n as u32).step_by(2).collect();
            assert_eq!(near(&g, cells[0]), odd);
            // a neighbour sees them all; a cell two away sees none of them
            let to = g.insert_at(0, Vec2::new(7.5, 5.0));
            let mut entering = Vec::new();
            g.for_each_entering(to, cells[0], |j| entering.push(j));
            assert!(entering.is_empty());
            assert!(near(&g, to).len() == odd.len() + 1);
        }
    }

    /// 400 centres on a 20 x 20 square lattice `spacing` apart from `corner`.
    fn square(corner: f64, spacing: f64) -> Vec<Vec2> {
        (0..400)
            .map(|k| {
                let (i, j) = ((k % 20) as f64, (k / 20) as f64);
                Vec2::new(corner + spacing * i, corner + spacing * j)
            })
            .collect()
    }

    /// Places `centres` in a grid as an engine does, and returns the grid's cell for each.
    fn place(g: &mut Grid, centres: &[Vec2]) -> Vec<u32> {
        (0..centres.len() as u32)
            .map(|i| g.insert_at(i, centres[i as usize]))
            .collect()
    }

    #[test]
    fn the_layout_follows_a_cluster_as_it_forms_and_spreads_out() {
        // 400 balls on a 4000 x 4000 table: spread out on a 20 x 20 lattice 200 apart, the
        // dense layout of about 1,600 cells suits them
        let n = 400;
        let t = table(n, 4000.0);
        let spread = square(100.0, 200.0);
        let mut g = Grid::new(&t, &spread, 1.0, 2.0);
        assert!(!g.is_hashed() && g.is_coarsest());
        place(&mut g, &spread);
        assert!(!g.is_crowded());
        assert!(g.relaid(&t, &spread).is_none(), "nothing coarser exists");
        // the balls gather into a 20 x 20 square 3 apart: a cell overflows, and the finer layout
        // chosen holds at most CROWDED balls in a cell
        let cluster = square(2000.0, 3.0);
        for i in 0..n as u32 {
            g.move_to(i, cluster[i as usize]);
        }
        assert!(g.is_crowded());
        let mut fine = g.relaid(&t, &cluster).expect("a finer layout");
        assert!(!g.is_crowded(), "asking clears the mark");
        assert!(fine.is_hashed() && !fine.is_coarsest());
        let cells = place(&mut fine, &cluster);
        for &c in &cells {
            assert!(cells.iter().filter(|&&d| d == c).count() <= CROWDED);
        }
        assert!(!fine.is_crowded());
        // nothing coarser suits the cluster; once it has spread out again, the dense layout does
        assert!(fine.relaid(&t, &cluster).is_none());
        let coarse = fine.relaid(&t, &spread).expect("a coarser layout");
        assert!(!coarse.is_hashed() && coarse.is_coarsest());
        assert_eq!(coarse.dims(), g.dims());
    }

    #[test]
    fn few_balls_keep_the_coarsest_layout() {
        let n = FEW_BALLS;
        let t = table(n, 4000.0);
        let mut g = Grid::new(&t, &vec![Vec2::new(5.0, 5.0); n], 1.0, 2.0);
        assert!(!g.is_hashed());
        place(&mut g, &vec![Vec2::new(5.0, 5.0); n]);
        assert!(!g.is_crowded());
        assert!(g.relaid(&t, &vec![Vec2::new(5.0, 5.0); n]).is_none());
    }

    #[test]
    fn hashed_cells_are_recycled() {
        let n = 100;
        let mut g = Grid::new(&table(n, 4000.0), &vec![Vec2::new(5.0, 5.0); n], 1.0, 2.0);
        assert!(g.is_hashed());
        let mut c = g.insert_at(0, Vec2::new(1.0, 1.0));
        let (mut p, v) = (Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.7));
        for _ in 0..2000 {
            let (t, to) = g.exit(c, p, v, 0.0).expect("heading into the table");
            p = p + t * v;
            g.remove_from(0, c);
            g.insert(0, to);
            assert_eq!(g.coords(to), g.coords_at(p + 1e-9 * v));
            c = to;
        }
        let h = g.hashed.as_ref().expect("hashed");
        assert!(h.at.len() <= h.limit + 1, "{} cells", h.at.len());
        assert!(p.x > 2000.0);
    }
}
