//! Scenarios: the table (cushions, pockets and their corners) and the balls at time 0.
//!
//! A scenario comes from a TOML file (`toml` submodule, the format of DESIGN.md) or from a
//! built-in generator (`builtin`). Either way it is validated once, by [`Scenario::validate`],
//! before any engine sees it; engines may then assume every number is finite, radii and masses are
//! positive, elasticities lie in `[0, 1]`, no segment has zero length and no two balls overlap.

pub mod builtin;
mod disks;
mod periodic;
pub mod random_sites;
pub mod toml;

pub use periodic::MIN_SIDE_DIAMETERS;

use crate::geometry::{PeriodicBox, Trajectory, Vec2};
use crate::vtime::Key;
use std::fmt;

/// The most sectors a grid given by hand may have: 500 × 500. A sector costs its polygon, its
/// neighbours and an object, so a grid of 500 × 500 already takes seconds to set up, and one of
/// 10^4 × 10^4 gigabytes (`--sectors auto` keeps to about eight balls per sector instead).
pub const MAX_SECTORS: u64 = 250_000;

/// A ball as a run starts it: where it is and how it moves at the start (or, taken up from a
/// checkpoint, since the event that last fixed its trajectory).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BallSpec {
    /// Centre at the start, or at `fixed.t` (length).
    pub position: Vec2,
    /// Velocity (length per time).
    pub velocity: Vec2,
    /// Radius (length), positive.
    pub radius: f64,
    /// Mass (any consistent unit), positive.
    pub mass: f64,
    /// The key of the event that fixed its trajectory, in a run taken up from a checkpoint:
    /// `position` is then its centre at `fixed.t`, and the keys of its immediate collisions
    /// descend from this one, exactly as in the run that wrote the checkpoint. `None`: fixed at
    /// the run's start.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fixed: Option<Key>,
    /// The pocket (from 0) it dropped into, in a run taken up from a checkpoint: `position` is
    /// then where it crossed into it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pocket: Option<u32>,
    /// Its colour in pictures (`#rrggbb`); the default ball colour when `None`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour: Option<String>,
    /// What pictures write on it (a pool ball's number, at most 8 characters) in place of its
    /// name; nothing for an empty label.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
}

impl BallSpec {
    /// A plain ball at the start: at `position` with `velocity`, of `radius` and `mass`, no
    /// looks.
    pub fn moving(position: Vec2, velocity: Vec2, radius: f64, mass: f64) -> BallSpec {
        BallSpec {
            position,
            velocity,
            radius,
            mass,
            fixed: None,
            pocket: None,
            colour: None,
            label: None,
        }
    }

    /// A ball as a run holds it between events, for a run that takes that one up: on `traj`
    /// since the event of key `fixed`, in `pocket` if it dropped into one; no looks (the run
    /// copies them from its scenario).
    pub fn taken_up(
        traj: &Trajectory,
        radius: f64,
        mass: f64,
        fixed: &Key,
        pocket: Option<u32>,
    ) -> BallSpec {
        BallSpec {
            position: traj.position,
            velocity: traj.velocity,
            radius,
            mass,
            fixed: Some(fixed.clone()),
            pocket,
            colour: None,
            label: None,
        }
    }

    /// The key its trajectory was fixed at, in a run that starts at `start`.
    pub fn fixed_at(&self, start: f64) -> Key {
        self.fixed.clone().unwrap_or_else(|| Key::start(start))
    }
}

/// A straight cushion. Going from `from` to `to`, the table lies on the right (thesis 3.1.2 and
/// DESIGN.md: cushions run clockwise around the table).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CushionSpec {
    /// First end (length).
    pub from: Vec2,
    /// Second end (length).
    pub to: Vec2,
    /// Ratio of speed after to speed before a bounce, in `[0, 1]` (thesis 3.2).
    pub elasticity: f64,
}

/// A pocket: a line that a ball's centre crosses to drop in (thesis 3.1.3), with a corner at each
/// end (thesis 3.1.4). Oriented like a cushion: the table lies on the right going `from` → `to`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PocketSpec {
    /// First end (length); the first corner of the pocket stands here.
    pub from: Vec2,
    /// Second end (length); the second corner of the pocket stands here.
    pub to: Vec2,
    /// Elasticity of the pocket's two corners, in `[0, 1]` (thesis 3.3).
    pub corner_elasticity: f64,
}

/// How the table is divided into sectors (chapter 5). Kept from the scenario for the sectored
/// engines; the event-list engine ignores it.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum SectorSpec {
    /// A grid of `nx` × `ny` equal rectangles over the table's bounding box.
    Grid {
        /// Sectors along x.
        nx: u32,
        /// Sectors along y.
        ny: u32,
    },
    /// Explicit polygons, each a list of vertices (length).
    Polygons(Vec<Vec<Vec2>>),
}

/// A whole scenario: the table, the balls at time 0 and the default end time.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Scenario {
    /// Name shown in summaries: the built-in's name or the file path.
    pub name: String,
    /// Default end time of a run.
    pub until: f64,
    /// Balls, `Ball-1` first.
    pub balls: Vec<BallSpec>,
    /// Cushions, `Cushion-1` first.
    pub cushions: Vec<CushionSpec>,
    /// Pockets, `Pocket-1` first; pocket `k` (from 0) owns corners `2k` and `2k + 1`.
    pub pockets: Vec<PocketSpec>,
    /// Optional sector layout.
    pub sectors: Option<SectorSpec>,
    /// The periodic box, where the boundary is periodic (no cushions or pockets then); `None`:
    /// the table is walled by its cushions, or open.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub periodic: Option<PeriodicBox>,
}

/// What is wrong with a scenario: one line naming the place and the field.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioError {
    /// The file (or built-in name) the scenario came from.
    pub source: String,
    /// The 1-based line in the file, where there is one.
    pub line: Option<usize>,
    /// The offending field, such as `ball[3].radius` (1-based like the object names).
    pub field: String,
    /// What is wrong with it.
    pub message: String,
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: ", self.source, line)?,
            None => write!(f, "{}: ", self.source)?,
        }
        if self.field.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", self.field, self.message)
        }
    }
}

impl std::error::Error for ScenarioError {}

/// A field that failed validation: its path and the complaint (the caller adds file and line).
#[derive(Clone, Debug, PartialEq)]
pub struct Invalid {
    /// Path of the field, such as `ball[2].position` (1-based indices).
    pub field: String,
    /// What is wrong.
    pub message: String,
}

fn invalid(field: String, message: String) -> Invalid {
    Invalid { field, message }
}

/// A ball's colour is `#rrggbb`; its label at most 8 characters, none of them a control.
fn check_look(f: &str, b: &BallSpec) -> Result<(), Invalid> {
    if let Some(c) = &b.colour {
        let hex = c.strip_prefix('#').filter(|h| h.len() == 6);
        if !hex.is_some_and(|h| h.chars().all(|d| d.is_ascii_hexdigit())) {
            return Err(invalid(
                format!("{f}.colour"),
                format!("must be #rrggbb (six hex digits), got \"{c}\""),
            ));
        }
    }
    if let Some(l) = &b.label {
        if l.chars().count() > 8 || l.chars().any(char::is_control) {
            return Err(invalid(
                format!("{f}.label"),
                format!("must be at most 8 printable characters, got {l:?}"),
            ));
        }
    }
    Ok(())
}

fn check_finite(field: &str, v: f64) -> Result<(), Invalid> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(invalid(
            field.into(),
            format!("must be a finite number, got {v}"),
        ))
    }
}

fn check_vec(field: &str, v: Vec2) -> Result<(), Invalid> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(invalid(
            field.into(),
            format!("must be two finite numbers, got [{}, {}]", v.x, v.y),
        ))
    }
}

fn check_positive(field: &str, v: f64) -> Result<(), Invalid> {
    check_finite(field, v)?;
    if v > 0.0 {
        Ok(())
    } else {
        Err(invalid(field.into(), format!("must be positive, got {v}")))
    }
}

fn check_elasticity(field: &str, v: f64) -> Result<(), Invalid> {
    check_finite(field, v)?;
    if (0.0..=1.0).contains(&v) {
        Ok(())
    } else {
        Err(invalid(
            field.into(),
            format!("must lie in [0, 1], got {v}"),
        ))
    }
}

fn check_segment(field: &str, from: Vec2, to: Vec2) -> Result<(), Invalid> {
    check_vec(&format!("{field}.from"), from)?;
    check_vec(&format!("{field}.to"), to)?;
    if from == to {
        Err(invalid(
            field.into(),
            format!("has zero length (from = to = [{}, {}])", from.x, from.y),
        ))
    } else {
        Ok(())
    }
}

impl Scenario {
    /// The number of corners: two per pocket.
    pub fn corner_count(&self) -> usize {
        2 * self.pockets.len()
    }

    /// The position of corner `k` (0-based): pocket `k / 2`'s `from` end for even `k`, `to` for odd.
    pub fn corner_position(&self, k: usize) -> Vec2 {
        let p = &self.pockets[k / 2];
        if k.is_multiple_of(2) {
            p.from
        } else {
            p.to
        }
    }

    /// The lower-left and upper-right corners of the periodic box, or of the box around every
    /// cushion and pocket end, or around the balls when the table has no sides.
    pub fn bounds(&self) -> (Vec2, Vec2) {
        if let Some(b) = &self.periodic {
            return (b.lo, b.hi());
        }
        let mut pts: Vec<Vec2> = self
            .cushions
            .iter()
            .flat_map(|c| [c.from, c.to])
            .chain(self.pockets.iter().flat_map(|p| [p.from, p.to]))
            .collect();
        if pts.is_empty() {
            pts = self
                .balls
                .iter()
                .flat_map(|b| {
                    let r = Vec2::new(b.radius, b.radius);
                    [b.position - r, b.position + r]
                })
                .collect();
        }
        let mut lo = Vec2::new(f64::INFINITY, f64::INFINITY);
        let mut hi = Vec2::new(f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in pts {
            lo = Vec2::new(lo.x.min(p.x), lo.y.min(p.y));
            hi = Vec2::new(hi.x.max(p.x), hi.y.max(p.y));
        }
        if pts_empty(lo) {
            (Vec2::ZERO, Vec2::new(1.0, 1.0))
        } else {
            (lo, hi)
        }
    }

    /// Checks every rule engines rely on; the first broken one is returned with its field path.
    /// Overlap is found with a sort along x, so validation of a million balls stays fast.
    pub fn validate(&self) -> Result<(), Invalid> {
        self.check_balls_and_table()?;
        if self.periodic.is_some() {
            return self.check_periodic();
        }
        self.check_on_table()?;
        self.check_overlaps()?;
        self.check_sectors()
    }

    /// Checks a scenario taken up from a checkpoint at time `t`: sound numbers, a sound table
    /// and sectors, and every ball's trajectory fixed by `t`, in a pocket that exists. Where the
    /// balls are is not checked again: each position is the centre at its own time.
    pub fn validate_taken_up(&self, t: f64) -> Result<(), Invalid> {
        self.check_balls_and_table()?;
        for (i, b) in self.balls.iter().enumerate() {
            let f = format!("ball[{}]", i + 1);
            match &b.fixed {
                None => return Err(invalid(format!("{f}.fixed"), "is missing".into())),
                Some(k) if !(k.t.is_finite() && k.t <= t) => {
                    return Err(invalid(
                        format!("{f}.fixed"),
                        format!(
                            "must be a time no later than the checkpoint's {t}, got {}",
                            k.t
                        ),
                    ))
                }
                Some(_) => {}
            }
            if let Some(k) = b.pocket.filter(|&k| k as usize >= self.pockets.len()) {
                return Err(invalid(
                    format!("{f}.pocket"),
                    format!("names pocket {k} (from 0) of {}", self.pockets.len()),
                ));
            }
        }
        self.check_sectors()
    }

    /// Checks the numbers of every ball, the end time, and the cushions and pockets.
    fn check_balls_and_table(&self) -> Result<(), Invalid> {
        if self.balls.is_empty() {
            return Err(invalid(
                "ball".into(),
                "the scenario has no balls: give at least one `[[ball]]`".into(),
            ));
        }
        check_finite("run.until", self.until)?;
        if self.until < 0.0 {
            return Err(invalid(
                "run.until".into(),
                format!("must not be negative, got {}", self.until),
            ));
        }
        for (i, b) in self.balls.iter().enumerate() {
            let sound = b.position.is_finite()
                && b.velocity.norm2().is_finite()
                && b.radius.is_finite()
                && b.radius > 0.0
                && b.mass.is_finite()
                && b.mass > 0.0;
            if sound && b.colour.is_none() && b.label.is_none() {
                continue; // names a field only to blame it: a gas has 10^5 balls and more
            }
            let f = format!("ball[{}]", i + 1);
            check_look(&f, b)?;
            check_vec(&format!("{f}.position"), b.position)?;
            check_vec(&format!("{f}.velocity"), b.velocity)?;
            if !b.velocity.norm2().is_finite() {
                return Err(invalid(
                    format!("{f}.velocity"),
                    "is too large: its square overflows".into(),
                ));
            }
            check_positive(&format!("{f}.radius"), b.radius)?;
            check_positive(&format!("{f}.mass"), b.mass)?;
        }
        for (i, c) in self.cushions.iter().enumerate() {
            let f = format!("cushion[{}]", i + 1);
            check_segment(&f, c.from, c.to)?;
            check_elasticity(&format!("{f}.elasticity"), c.elasticity)?;
        }
        for (i, p) in self.pockets.iter().enumerate() {
            let f = format!("pocket[{}]", i + 1);
            check_segment(&f, p.from, p.to)?;
            check_elasticity(&format!("{f}.corner_elasticity"), p.corner_elasticity)?;
        }
        Ok(())
    }

    fn check_overlaps(&self) -> Result<(), Invalid> {
        // Bucket the centres in square cells one largest diameter wide: overlapping balls sit in
        // the same or adjacent cells. Sorting the buckets keeps this O(N log N) for any layout.
        let rmax = self.balls.iter().map(|b| b.radius).fold(0.0, f64::max);
        let w = 2.0 * rmax;
        let cell = |p: Vec2| ((p.y / w).floor() as i64, (p.x / w).floor() as i64);
        let mut sorted: Vec<((i64, i64), usize)> = self
            .balls
            .iter()
            .enumerate()
            .map(|(i, b)| (cell(b.position), i))
            .collect();
        sorted.sort_unstable();
        for (i, bi) in self.balls.iter().enumerate() {
            // far-off centres saturate the cell numbers: the neighbours' numbers must too
            let (cy, cx) = cell(bi.position);
            let mut worst: Option<usize> = None;
            for y in cy.saturating_sub(1)..=cy.saturating_add(1) {
                let lo = sorted.partition_point(|e| e.0 < (y, cx.saturating_sub(1)));
                let hi = sorted.partition_point(|e| e.0 <= (y, cx.saturating_add(1)));
                for &(_, j) in &sorted[lo..hi] {
                    let bj = &self.balls[j];
                    if j <= i || bi.pocket.is_some() || bj.pocket.is_some() {
                        continue;
                    }
                    let sigma = bi.radius + bj.radius;
                    // Touching is allowed (a rack, a cradle); overlap beyond rounding is not.
                    if (bj.position - bi.position).norm2() < sigma * sigma * (1.0 - 1e-12) {
                        worst = Some(worst.map_or(j, |w| w.min(j)));
                    }
                }
            }
            if let Some(j) = worst {
                let bj = &self.balls[j];
                return Err(invalid(
                    format!("ball[{}].position", j + 1),
                    format!(
                        "Ball-{} overlaps Ball-{} at t = 0 (centres {:.6} apart, radii sum {})",
                        j + 1,
                        i + 1,
                        (bj.position - bi.position).norm(),
                        bi.radius + bj.radius
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The table's edges: every cushion and pocket mouth, each going clockwise (the table on its
    /// right).
    fn edges(&self) -> Vec<(Vec2, Vec2)> {
        self.cushions
            .iter()
            .map(|c| (c.from, c.to))
            .chain(self.pockets.iter().map(|p| (p.from, p.to)))
            .collect()
    }

    /// Cushions and pockets must run clockwise around the table (DESIGN.md: the table lies on the
    /// right going from `from` to `to`): their signed area about their centre must not be
    /// positive. Otherwise a ball meets each cushion from behind and passes through it.
    fn check_winding(&self) -> Result<(), Invalid> {
        let edges = self.edges();
        let n = 2.0 * edges.len() as f64;
        let centre = edges
            .iter()
            .fold(Vec2::ZERO, |acc, &(a, b)| acc + (1.0 / n) * (a + b));
        let (lo, hi) = self.bounds();
        let size = (hi - lo).norm();
        let area: f64 = edges
            .iter()
            .map(|&(a, b)| 0.5 * (a - centre).cross(b - centre))
            .sum();
        if area > 1e-9 * size * size {
            return Err(invalid(
                "cushion[1]".into(),
                "the cushions run counter-clockwise: the table must lie on the right of each \
                 cushion going from `from` to `to` (swap every from and to)"
                    .into(),
            ));
        }
        Ok(())
    }

    /// Whether the table's cushions and pockets close into loops, leaving no gap a ball could
    /// leave the table through.
    pub fn is_closed(&self) -> bool {
        self.closed_edges().is_some()
    }

    /// The table's edges if they close into loops (every end of an edge meets an end of another,
    /// whichever way each runs); `None` where they leave gaps: an open table has no inside to
    /// check balls against.
    fn closed_edges(&self) -> Option<Vec<(Vec2, Vec2)>> {
        let edges = self.edges();
        let (lo, hi) = self.bounds();
        let tol = 1e-9 * (hi - lo).norm();
        let meets = |k: usize, p: Vec2| {
            edges
                .iter()
                .enumerate()
                .any(|(j, &(a, b))| j != k && ((a - p).norm() <= tol || (b - p).norm() <= tol))
        };
        let closed = edges.len() >= 3
            && edges.len() <= 4096
            && edges
                .iter()
                .enumerate()
                .all(|(k, &(from, to))| meets(k, from) && meets(k, to));
        closed.then_some(edges)
    }

    /// Every cushion and pocket mouth must have the table on its right. The point just to the
    /// right of its middle must lie inside the table's box (where the box has an area), and, on
    /// a closed table, inside the loops its sides make. One wound the wrong way would be met
    /// from behind, and a ball would pass through it.
    fn check_each_winding(&self, loops: Option<&[(Vec2, Vec2)]>) -> Result<(), Invalid> {
        let (lo, hi) = self.bounds();
        let step = 1e-7 * (hi - lo).norm();
        let boxed = lo.x < hi.x && lo.y < hi.y;
        let wrong = self.edges().iter().position(|&(a, b)| {
            let along = b - a;
            let right = (1.0 / along.norm()) * along.perp_cw();
            let p = 0.5 * (a + b) + step * right;
            (boxed && !inside_box(p, lo, hi)) || loops.is_some_and(|e| !encloses(e, p))
        });
        let Some(k) = wrong else {
            return Ok(());
        };
        let (field, what) = match k.checked_sub(self.cushions.len()) {
            None => (format!("cushion[{}]", k + 1), "cushion"),
            Some(p) => (format!("pocket[{}]", p + 1), "pocket"),
        };
        Err(invalid(
            field,
            format!(
                "this {what} runs the wrong way: the table must lie on its right going from \
                 `from` to `to` (swap its from and to)"
            ),
        ))
    }

    fn check_on_table(&self) -> Result<(), Invalid> {
        if self.cushions.is_empty() && self.pockets.is_empty() {
            return Ok(());
        }
        self.check_winding()?;
        let (lo, hi) = self.bounds();
        let loops = self.closed_edges();
        self.check_each_winding(loops.as_deref())?;
        // a ball in a pocket (a state to start from) is where it crossed into it
        for (i, b) in self
            .balls
            .iter()
            .enumerate()
            .filter(|(_, b)| b.pocket.is_none())
        {
            let p = b.position;
            let field = || format!("ball[{}].position", i + 1);
            if !inside_box(p, lo, hi) {
                return Err(invalid(
                    field(),
                    format!(
                        "Ball-{} at [{}, {}] is off the table (table spans [{}, {}] to [{}, {}])",
                        i + 1,
                        p.x,
                        p.y,
                        lo.x,
                        lo.y,
                        hi.x,
                        hi.y
                    ),
                ));
            }
            if loops.as_ref().is_some_and(|e| !encloses(e, p)) {
                return Err(invalid(
                    field(),
                    format!(
                        "Ball-{} at [{}, {}] is outside the table its cushions enclose",
                        i + 1,
                        p.x,
                        p.y
                    ),
                ));
            }
            // a ball overlaps a cushion anywhere along it, its ends included, and a pocket's
            // corner: moving on, it would be inside the one or the other
            let reach2 = (b.radius * (1.0 - 1e-9)).powi(2);
            let through_cushion = self
                .cushions
                .iter()
                .position(|c| crate::geometry::segment_distance2(p, c.from, c.to) < reach2);
            if let Some(c) = through_cushion {
                return Err(invalid(
                    field(),
                    format!("Ball-{} overlaps Cushion-{} at t = 0", i + 1, c + 1),
                ));
            }
            let on_corner = (0..self.corner_count())
                .position(|k| (self.corner_position(k) - p).norm2() < reach2);
            if let Some(k) = on_corner {
                return Err(invalid(
                    field(),
                    format!("Ball-{} overlaps Corner-{} at t = 0", i + 1, k + 1),
                ));
            }
        }
        Ok(())
    }

    fn check_sectors(&self) -> Result<(), Invalid> {
        match &self.sectors {
            None => Ok(()),
            Some(SectorSpec::Grid { nx, ny }) => {
                if *nx == 0 || *ny == 0 {
                    Err(invalid(
                        "sectors.grid".into(),
                        format!("needs at least one sector per side, got [{nx}, {ny}]"),
                    ))
                } else if u64::from(*nx) * u64::from(*ny) > MAX_SECTORS {
                    Err(invalid(
                        "sectors.grid".into(),
                        format!("at most {MAX_SECTORS} sectors, got [{nx}, {ny}]"),
                    ))
                } else {
                    Ok(())
                }
            }
            Some(SectorSpec::Polygons(polys)) => {
                for (i, poly) in polys.iter().enumerate() {
                    let f = format!("sectors.polygon[{}].points", i + 1);
                    if poly.len() < 3 {
                        return Err(invalid(f, "a polygon needs at least 3 points".into()));
                    }
                    for p in poly {
                        check_vec(&f, *p)?;
                    }
                }
                // the layout must cover the table without overlaps whichever engine runs
                let mut shapes = Vec::with_capacity(polys.len());
                for (i, poly) in polys.iter().enumerate() {
                    let f = format!("sectors.polygon[{}].points", i + 1);
                    shapes.push(
                        crate::polygon::Polygon::new(poly.clone())
                            .map_err(|e| invalid(f, e.to_string()))?,
                    );
                }
                let (lo, hi) = self.bounds();
                crate::polygon::validate_layout(&shapes, lo, hi).map_err(|e| {
                    // blame the first polygon the message names, for its line in the file
                    let field = e
                        .polygon()
                        .map_or_else(|| "sectors".into(), |k| format!("sectors.polygon[{k}]"));
                    invalid(field, e.to_string())
                })
            }
        }
    }
}

/// Whether closed loops of `edges` enclose `p` (even-odd rule: a ray towards +x crosses them an
/// odd number of times from inside).
fn encloses(edges: &[(Vec2, Vec2)], p: Vec2) -> bool {
    let crossings = edges
        .iter()
        .filter(|&&(a, b)| {
            (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x)
        })
        .count();
    crossings % 2 == 1
}

fn inside_box(p: Vec2, lo: Vec2, hi: Vec2) -> bool {
    p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y
}

fn pts_empty(lo: Vec2) -> bool {
    !lo.x.is_finite()
}

/// Loads a scenario by built-in name, TOML path, or `-` for TOML on stdin. Generator parameters
/// (`params`) are only accepted by built-ins that use them; a file takes none.
pub fn load(spec: &str, params: &builtin::Params) -> Result<Scenario, ScenarioError> {
    if spec == "-" {
        return toml::load_from(std::io::stdin().lock(), "stdin");
    }
    let is_builtin = builtin::list().iter().any(|(name, _)| *name == spec);
    // an error about the name itself, not about a field
    let about_name = |message: String| ScenarioError {
        source: spec.to_string(),
        line: None,
        field: String::new(),
        message,
    };
    if is_builtin && std::path::Path::new(spec).is_file() {
        return Err(about_name(format!(
            "names both a built-in scenario and a file here; write ./{spec} for the file"
        )));
    }
    if is_builtin {
        return builtin::build(spec, params).map_err(|e| ScenarioError {
            source: format!("built-in scenario {spec}"),
            line: None,
            field: e.field,
            message: e.message,
        });
    }
    let path = std::path::Path::new(spec);
    if !path.exists() {
        let names: Vec<&str> = builtin::list().iter().map(|(n, _)| *n).collect();
        return Err(about_name(format!(
            "no such file, and not a built-in scenario (built-ins: {})",
            names.join(", ")
        )));
    }
    let given = [
        ("--balls", params.balls.is_some()),
        ("--seed", params.seed.is_some()),
        ("--area-fraction", params.area_fraction.is_some()),
        ("--radius", params.radius.is_some()),
        ("--speed-max", params.speed_max.is_some()),
    ];
    if let Some((flag, _)) = given.iter().find(|(_, set)| *set) {
        return Err(ScenarioError {
            source: spec.to_string(),
            line: None,
            field: (*flag).to_string(),
            message: "only generated (built-in) scenarios take this option".into(),
        });
    }
    toml::load(path)
}
