//! The event-list algorithm cut into regions, as a model of the [`pdes_kernel`] crate: the
//! parallel exact simulation (`--engine regions`).
//!
//! ```text
//!          region 0                 region 1                 region 2
//!   ┌──┬───────────┬──┐     ┌──┬───────────┬──┐     ┌──┬───────────┬──┐
//!   │  │  its own  │░░│ ◄─► │░░│  its own  │░░│ ◄─► │░░│  its own  │  │
//!   │  │   balls   │░░│     │░░│   balls   │░░│     │░░│   balls   │  │
//!   └──┴───────────┴──┘     └──┴───────────┴──┘     └──┴───────────┴──┘
//!              halo ░░ : the neighbour's border column, whose balls it keeps as ghosts
//! ```
//!
//! The table's cell grid is cut along x into strips of whole columns with about the same
//! number of balls. Each strip is one kernel object, a [`Region`], that runs the event list
//! over the balls whose cells it holds, plus one column on each side: its neighbours' border
//! columns, whose balls it knows as ghosts. Cells are wider than any two touching balls, so a
//! ball can meet nothing beyond its neighbouring columns: a ball of the region meets only its
//! own balls, ghosts and fixed objects, and a collision across a border is run by both
//! regions, each for its own ball, from the same two trajectories, at the same key.
//!
//! Every change a neighbour must know of is a message sent with zero delay (it arrives after
//! the event's key and before every later one), so each region sees exactly what the event
//! list would:
//! - `Enter`: a ball of the region entered a border column (the neighbour's halo);
//! - `Update`: a ball in a border column turned in an event the neighbour did not run;
//! - `Leave`: it left the border column inwards, or dropped into a pocket;
//! - `Hand`: it crossed the border, and the neighbour owns it from then on.
//!
//! A region's own events come to it as a wake-up message it sends itself at the key of its
//! earliest queued event (and retracts when an earlier one comes up). Events are keyed by
//! the event list's [`Key`]s, computed by the same functions from the same trajectories, so
//! the committed events, their order and the final state are bit-identical to the event
//! list's for any number of regions, on any executor.

mod events;
mod region;

pub use region::{Cold, Region, Slot, Undo};

use crate::engine::grid::Grid;
use crate::engine::{BallState, Event, Table};
use crate::geometry::{Trajectory, Vec2};
use crate::scenario::Scenario;
use crate::vtime::Key;
use pdes_kernel::{Ctx, Envelope, Model, Saving, VTime};
use std::sync::Arc;

/// A ball's course as a neighbour hears of it.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Ghost {
    /// Global index.
    pub gid: u32,
    /// Trajectory since its last turn.
    pub traj: Trajectory,
    /// Radius.
    pub radius: f64,
    /// Mass.
    pub mass: f64,
    /// The key that fixed the trajectory.
    pub fixed_at: Key,
    /// The pocket it is in.
    pub pocket: Option<u32>,
}

/// What a region tells a neighbour.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum News {
    /// A ball came into the border column: a new ghost.
    Enter(Ghost),
    /// A ball in the border column turned.
    Update(Ghost),
    /// A ball (by global index) left the border column inwards or dropped into a pocket.
    Leave(u32),
    /// A ball crossed the border: the receiver owns it now.
    Hand(Ghost),
}

/// A message between regions.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub enum RegionMsg {
    /// To itself: run the events queued at this key.
    Wake,
    /// From a neighbour.
    News(News),
}

/// A physical event as a region reports it.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct RegionEvent {
    /// The event.
    pub event: Event,
    /// Whether two regions ran it (a collision across a border).
    pub across: bool,
    /// The region that reported it (for a collision across a border, the one that ran it
    /// first).
    pub region: u32,
}

/// The message types, by [`Model::kind`].
const KINDS: [&str; 5] = [
    "Wake",
    "GhostEnter",
    "GhostUpdate",
    "GhostLeave",
    "Handover",
];

/// Where a region lies: its grid's box and columns, and its neighbours.
pub struct Shape {
    /// The region's index.
    me: u32,
    /// The table, its box narrowed to the region's columns and halos.
    table: Table,
    /// Grid columns: the strip's and one halo column on each side.
    columns: u32,
    /// Grid rows (the table's).
    rows: u32,
    /// The largest radius.
    rmax: f64,
    /// The region on the left, if any.
    left: Option<u32>,
    /// The region on the right, if any.
    right: Option<u32>,
}

impl Shape {
    /// The neighbours that keep a ball in grid column `col` as a ghost.
    fn facing(&self, col: u32) -> impl Iterator<Item = u32> {
        let left = self.left.filter(|_| col <= 1);
        let right = self.right.filter(|_| col + 2 >= self.columns);
        left.into_iter().chain(right)
    }

    /// The neighbour whose strip column `col` is (a halo column), if any.
    fn beyond(&self, col: u32) -> Option<u32> {
        if col == 0 {
            self.left
        } else if col + 1 == self.columns {
            self.right
        } else {
            None
        }
    }

    /// The border column next to neighbour `n`.
    fn border_facing(&self, n: u32) -> u32 {
        if Some(n) == self.left {
            1
        } else {
            self.columns - 2
        }
    }
}

/// The regions model: the table cut into strips, each a [`Region`].
pub struct Regions {
    /// The whole table.
    table: Table,
    /// Balls on the table (global indices below this).
    n_balls: u32,
}

/// The strips' first columns (the last entry: one past the last column) over `nx` columns
/// holding `per_column` balls each, `count` strips of about equal balls, each at least two
/// columns wide; `None` if there are too few columns.
fn strips(per_column: &[usize], count: u32) -> Option<Vec<u32>> {
    let nx = per_column.len() as u32;
    if count == 0 || nx < 2 * count {
        return None;
    }
    let total: usize = per_column.iter().sum();
    let mut cuts = vec![0];
    let mut acc = 0;
    for (c, &n) in per_column.iter().enumerate() {
        acc += n;
        let k = cuts.len() as u32;
        let c = c as u32 + 1;
        let room = c >= cuts[cuts.len() - 1] + 2 && nx - c >= 2 * (count - k);
        if k < count && room && acc * count as usize >= total * k as usize {
            cuts.push(c);
        }
    }
    while (cuts.len() as u32) < count {
        // a table whose balls sit in few columns: the last strips take two columns each
        let last = cuts[cuts.len() - 1];
        cuts.push(last + 2);
    }
    cuts.push(nx);
    Some(cuts)
}

/// Why a table cannot be cut into regions.
#[derive(Debug, thiserror::Error)]
pub enum RegionsError {
    /// Too few grid columns for the strips asked for.
    #[error(
        "--regions: {asked} regions need at least {} grid columns a ball diameter wide; this \
         table has {columns}",
        2 * asked
    )]
    TooFewColumns {
        /// Regions asked for.
        asked: u32,
        /// Columns the table has.
        columns: u32,
    },
    /// Something the regions do not run yet.
    #[error("--engine regions: {0}")]
    Unsupported(&'static str),
}

impl Regions {
    /// The model and its regions' states at `start` for a validated scenario, cut into
    /// `count` strips.
    pub fn new(
        s: &Scenario,
        count: u32,
        start: f64,
    ) -> Result<(Regions, Vec<Region>), RegionsError> {
        if s.periodic.is_some() {
            return Err(RegionsError::Unsupported(
                "a periodic box runs on the event list only",
            ));
        }
        let table = Table::new(s);
        let balls = BallState::initial(s, start);
        let rmax = balls.iter().map(|b| b.radius).fold(0.0, f64::max);
        let centres: Vec<Vec2> = balls.iter().map(|b| b.position(start)).collect();
        // the event list's layout, or a finer one if it has too few columns for the strips
        let grid = Grid::new(&table, &centres, rmax, 2.0 * rmax);
        let (nx, ny) = match grid.dims() {
            (nx, _) if nx >= 2 * count => grid.dims(),
            (nx, _) => grid
                .dims_with_columns(2 * count)
                .ok_or(RegionsError::TooFewColumns {
                    asked: count,
                    columns: nx,
                })?,
        };
        drop(grid);
        let width = (table.hi.x - table.lo.x) / f64::from(nx);
        let column =
            |p: Vec2| (((p.x - table.lo.x) / width).floor()).clamp(0.0, f64::from(nx - 1)) as u32;
        let mut per_column = vec![0; nx as usize];
        for p in &centres {
            per_column[column(*p) as usize] += 1;
        }
        let cuts = strips(&per_column, count).ok_or(RegionsError::TooFewColumns {
            asked: count,
            columns: nx,
        })?;
        let mut regions: Vec<Region> = (0..count)
            .map(|k| {
                let (c0, c1) = (cuts[k as usize], cuts[k as usize + 1]);
                let mut t = table.clone();
                t.lo.x = table.lo.x + (f64::from(c0) - 1.0) * width;
                t.hi.x = table.lo.x + (f64::from(c1) + 1.0) * width;
                let shape = Shape {
                    me: k,
                    table: t,
                    columns: c1 - c0 + 2,
                    rows: ny,
                    rmax,
                    left: k.checked_sub(1),
                    right: (k + 1 < count).then_some(k + 1),
                };
                Region::new(Arc::new(shape), start)
            })
            .collect();
        // room for every record at once: grown ball by ball, the records were copied over
        // and over, and the old and new copies held at once
        for (k, r) in regions.iter_mut().enumerate() {
            let lo = (cuts[k] as usize).saturating_sub(1);
            let hi = (cuts[k + 1] as usize + 1).min(per_column.len());
            r.reserve(per_column[lo..hi].iter().sum());
        }
        let region_of = |c: u32| cuts.partition_point(|&x| x <= c) as u32 - 1;
        for (i, b) in balls.iter().enumerate() {
            let ghost = Ghost {
                gid: i as u32,
                traj: b.traj,
                radius: b.radius,
                mass: b.mass,
                fixed_at: s.balls[i].fixed_at(start),
                pocket: b.pocket,
            };
            let c = column(centres[i]);
            let owner = region_of(c);
            let local = |k: u32| c + 1 - cuts[k as usize];
            regions[owner as usize].admit(&ghost, owner, Some(local(owner)));
            if owner > 0 && c == cuts[owner as usize] {
                regions[owner as usize - 1].admit(&ghost, owner, Some(local(owner - 1)));
            }
            if owner + 1 < count && c + 1 == cuts[owner as usize + 1] {
                regions[owner as usize + 1].admit(&ghost, owner, Some(0));
            }
        }
        // each region predicts its records' first events, the regions on as many threads as
        // there are cores
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let per = regions.len().div_ceil(threads);
        std::thread::scope(|scope| {
            for part in regions.chunks_mut(per) {
                scope.spawn(move || {
                    for r in part {
                        for i in 0..r.slots.len() as u32 {
                            r.predict(i);
                        }
                        r.settle(start);
                    }
                });
            }
        });
        let model = Regions {
            table,
            n_balls: balls.len() as u32,
        };
        Ok((model, regions))
    }

    /// The whole table.
    pub fn table(&self) -> &Table {
        &self.table
    }

    /// Balls on the table.
    pub fn n_balls(&self) -> u32 {
        self.n_balls
    }

    /// Sends the region its wake-up at its earliest queued event, retracting the one it has
    /// if that is another.
    fn schedule(&self, ctx: &mut Ctx<'_, Self>, state: &mut Region) {
        let next = state.first_key().cloned();
        if state.wake().map(|w| &w.0) == next.as_ref() {
            return;
        }
        if let Some((_, h)) = state.wake() {
            ctx.cancel(*h);
        }
        let wake = next.map(|key| {
            let h = ctx.send_at(ctx.me(), VTime::at(key.clone()), RegionMsg::Wake);
            (key, h)
        });
        state.set_wake(wake);
    }
}

impl Model for Regions {
    type Time = Key;
    type Msg = RegionMsg;
    type State = Region;
    type Output = RegionEvent;
    type Undo = Undo;

    fn kind_names(&self) -> &'static [&'static str] {
        &KINDS
    }

    fn kind(&self, msg: &RegionMsg) -> usize {
        match msg {
            RegionMsg::Wake => 0,
            RegionMsg::News(News::Enter(_)) => 1,
            RegionMsg::News(News::Update(_)) => 2,
            RegionMsg::News(News::Leave(_)) => 3,
            RegionMsg::News(News::Hand(_)) => 4,
        }
    }

    fn priority(&self, _msg: &RegionMsg) -> u8 {
        0
    }

    fn init(&self, ctx: &mut Ctx<'_, Self>, _me: u32, state: &mut Region) {
        self.schedule(ctx, state);
    }

    fn handle(
        &self,
        ctx: &mut Ctx<'_, Self>,
        _me: u32,
        state: &mut Region,
        batch: &[Envelope<RegionMsg>],
    ) {
        let now = ctx.now().clone();
        state.begin(ctx.journal());
        let mut woken = false;
        for env in batch {
            match &env.msg {
                RegionMsg::Wake => woken = true,
                RegionMsg::News(news) => state.hear(env.from, news, now.key.t),
            }
        }
        if woken {
            state.set_wake(None);
            // on an executor that allows it, the region's own events up to the next message
            // run in this batch too (a few thousand at most), until one of them has news for
            // a neighbour; the executor marks where each one's old values start in the
            // journal, to undo the batch back to any of them
            state.run_on(&now.key, |k, journal| {
                let t = VTime::at(k.clone());
                if !ctx.may_run(&t) {
                    return false;
                }
                if let Some(j) = ctx.journal() {
                    std::mem::swap(j, journal);
                }
                ctx.reach(t);
                if let Some(j) = ctx.journal() {
                    std::mem::swap(j, journal);
                }
                true
            });
            ctx.reserve_output(state.reports.len());
            for (key, ev) in state.reports.drain(..) {
                ctx.emit_at(VTime::at(key), ev);
            }
            for (to, news) in state.outbox.drain(..) {
                ctx.send_now(to, RegionMsg::News(news));
            }
        }
        self.schedule(ctx, state);
        state.end(ctx.journal());
    }

    fn runs_ahead(&self, _obj: u32) -> bool {
        true
    }

    fn may_take_in(msg: &RegionMsg) -> bool {
        matches!(msg, RegionMsg::News(_))
    }

    fn take_in(
        &self,
        ctx: &mut Ctx<'_, Self>,
        _me: u32,
        state: &mut Region,
        batch: &[Envelope<RegionMsg>],
        again: bool,
    ) -> bool {
        // news that touches nothing the region ran past it is taken in at its key: the
        // region's state is then the one hearing it in its turn gives
        let (at, reached) = (ctx.now().key.clone(), ctx.reached().key.clone());
        state.begin(ctx.journal());
        let taken = batch.iter().all(|env| match &env.msg {
            RegionMsg::News(news) => state.take_in(env.from, news, &at, &reached, again),
            RegionMsg::Wake => false,
        });
        if taken {
            self.schedule(ctx, state);
        }
        state.end(ctx.journal());
        taken
    }

    fn cut(&self, ctx: &mut Ctx<'_, Self>, _me: u32, state: &mut Region) {
        // the events kept sent nothing: only the wake-up for the next one is missing
        state.begin(ctx.journal());
        self.schedule(ctx, state);
        state.end(ctx.journal());
    }

    fn saving(&self, _obj: u32) -> Saving<Region, Undo> {
        Saving::Incremental {
            restore: Region::restore,
        }
    }
}

/// A region as it travels from one MPI rank to another: its place and the balls it owns. The
/// rank that collects results reads only those (final states, and observed states for
/// `--check` and frames); it never runs a region of another rank.
#[derive(serde::Serialize, serde::Deserialize)]
struct Travelling {
    me: u32,
    columns: u32,
    rows: u32,
    lo: Vec2,
    hi: Vec2,
    rmax: f64,
    left: Option<u32>,
    right: Option<u32>,
    now: f64,
    balls: Vec<Ghost>,
}

impl serde::Serialize for Region {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let shape = &self.shape;
        Travelling {
            me: shape.me,
            columns: shape.columns,
            rows: shape.rows,
            lo: shape.table.lo,
            hi: shape.table.hi,
            rmax: shape.rmax,
            left: shape.left,
            right: shape.right,
            now: self.now,
            balls: self.owned_balls(),
        }
        .serialize(s)
    }
}

impl<'de> serde::Deserialize<'de> for Region {
    /// A region holding the balls it owned where it was sent: it answers for them
    /// ([`Region::ball`], [`Region::owned`]), and runs nothing.
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Region, D::Error> {
        let t = Travelling::deserialize(d)?;
        let table = Table {
            n_balls: 0,
            cushions: Vec::new(),
            pockets: Vec::new(),
            corners: Vec::new(),
            lo: t.lo,
            hi: t.hi,
            period: None,
        };
        let shape = Shape {
            me: t.me,
            table,
            columns: t.columns,
            rows: t.rows,
            rmax: t.rmax,
            left: t.left,
            right: t.right,
        };
        let mut region = Region::new(Arc::new(shape), t.now);
        region.reserve(t.balls.len());
        for g in &t.balls {
            region.admit(g, t.me, None);
        }
        Ok(region)
    }
}

#[cfg(test)]
mod tests {
    use super::strips;

    #[test]
    fn strips_hold_about_equal_balls_and_two_columns_at_least() {
        assert_eq!(strips(&[1; 8], 2), Some(vec![0, 4, 8]));
        assert_eq!(strips(&[1; 8], 4), Some(vec![0, 2, 4, 6, 8]));
        assert_eq!(strips(&[1; 3], 2), None);
        let cuts = strips(&[0, 0, 0, 10, 10, 0, 0, 0], 2).unwrap();
        assert_eq!(cuts, vec![0, 4, 8]);
        let cuts = strips(&[9, 0, 0, 0, 0, 0], 3).unwrap();
        assert_eq!(cuts, vec![0, 2, 4, 6]);
    }
}
