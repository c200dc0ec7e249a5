//! Built-in scenarios: the thesis' set pieces and a few classic tests of simultaneous contact.
//!
//! | name | what it is |
//! |---|---|
//! | `plate1` | thesis plate 1 (4.2): Ball-2 knocks Ball-1 into the pocket in the top side |
//! | `gas` | the thesis' hard-disk gas (ch. 6): k × k balls with random velocities on a square table |
//! | `reversal` | the reversal test of thesis 4.6–4.7: a 4 × 4 array with random velocities |
//! | `pool` | a racked break on a 2:1 table with six pockets |
//! | `cradle` | Newton's cradle: one ball strikes a row of five touching balls |
//! | `implosion` | a dilute gas whose balls all head for one small disc: a cluster forms and flies apart |
//!
//! Coordinates have y up. Cushions and pockets run clockwise around the table, so the table lies
//! on the right going from `from` to `to` (the right-hand normal of each side points inward).
//!
//! Random draws use [`ChaCha8Rng`] seeded with [`SeedableRng::seed_from_u64`] (default seed 1),
//! whose output is specified bit for bit, and turn its numbers into positions and velocities with
//! IEEE-754 arithmetic only (`+ - * /` and `sqrt`, which are correctly rounded; no `sin`/`cos`,
//! whose last bit depends on the platform's maths library). A seed therefore gives the same
//! scenario, bit for bit, on every platform.

use super::{BallSpec, CushionSpec, Invalid, PocketSpec, Scenario};
use crate::geometry::Vec2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

/// Parameters a generated scenario may take from the command line; `None` = the scenario's
/// default. A scenario that has no use for a parameter rejects it, naming its flag.
#[derive(Clone, Debug, Default)]
pub struct Params {
    /// `--balls N`: how many balls.
    pub balls: Option<usize>,
    /// `--seed S`: the seed of the random velocities (default 1).
    pub seed: Option<u64>,
    /// `--area-fraction PHI`: the fraction of the table the balls cover, in (0, 1); sets the
    /// table's size.
    pub area_fraction: Option<f64>,
    /// `--radius R`: the ball radius (length).
    pub radius: Option<f64>,
    /// `--speed-max V`: speeds are drawn uniform in `[0, V)` (length per time).
    pub speed_max: Option<f64>,
    /// `--lattice square|triangular`: the sites the balls start on.
    pub lattice: Option<Lattice>,
    /// `--temperature KT`: Maxwell-Boltzmann velocities with this kinetic energy per ball.
    pub temperature: Option<f64>,
    /// `--mixture F:Q`: a fraction `F` of the balls large, their diameter `Q` times the others'.
    pub mixture: Option<Mixture>,
    /// `--boundary walled|periodic`: cushions around the box (the default) or a periodic box.
    pub boundary: Option<Boundary>,
}

/// What bounds a generated box.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Boundary {
    /// Four elastic cushions.
    #[default]
    Walled,
    /// None: the box is periodic (a torus).
    Periodic,
}

/// The sites of a lattice start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lattice {
    /// Rows and columns at one spacing.
    Square,
    /// Rows half a spacing apart in turn, `√3/2` spacings above each other: each site has six
    /// neighbours (the densest packing of equal disks).
    Triangular,
    /// No lattice: random sequential addition (up to about 0.5 of the area; compress beyond).
    Random,
}

/// A binary mixture: a fraction of the balls large, by a diameter ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mixture {
    /// The fraction of the balls that are large, in `[0, 1]`.
    pub large: f64,
    /// The large balls' diameter over the small ones', at least 1.
    pub ratio: f64,
}

/// The most balls a generator will lay out (about 5 GB of ball specs); more is refused with an
/// error rather than an allocation failure.
pub const MAX_BALLS: usize = 100_000_000;

pub(super) const BALLS: &str = "--balls";
pub(super) const SEED: &str = "--seed";
pub(super) const AREA: &str = "--area-fraction";
pub(super) const RADIUS: &str = "--radius";
const SPEED: &str = "--speed-max";
pub(super) const LATTICE: &str = "--lattice";
pub(super) const TEMPERATURE: &str = "--temperature";
pub(super) const MIXTURE: &str = "--mixture";
pub(super) const BOUNDARY: &str = "--boundary";

pub(super) const DEFAULT_SEED: u64 = 1;

const GAS_BALLS: usize = 36;
const GAS_RADIUS: f64 = 30.0;
const GAS_SPEED: f64 = 100.0;
const GAS_SPACING: f64 = 100.0;
const GAS_UNTIL: f64 = 4.0;

const REVERSAL_SIDE: f64 = 400.0;
const REVERSAL_RADIUS: f64 = 30.0;
const REVERSAL_SPEED: f64 = 100.0;
const REVERSAL_UNTIL: f64 = 3.0;

/// Centres closer than `2r · (1 + GAP)` count as too close for a generated layout.
pub(super) const GAP: f64 = 1e-9;

/// One built-in: its name, its description and its generator.
struct Builtin {
    name: &'static str,
    describe: fn() -> String,
    build: fn(&Params) -> Result<Scenario, Invalid>,
}

const IMPLOSION_BALLS: usize = 400;
const IMPLOSION_RADIUS: f64 = 1.0;
/// The area fraction of the disc the implosion's balls head for.
const IMPLOSION_FRACTION: f64 = 0.5;
/// The implosion's table side over `√N · r`: the balls start about 80 radii apart.
const IMPLOSION_SIDE: f64 = 100.0;
const IMPLOSION_UNTIL: f64 = 3.0;

const BUILTINS: [Builtin; 7] = [
    Builtin {
        name: "plate1",
        describe: || {
            "thesis plate 1: Ball-2 strikes Ball-1 (t = 1.6), which drops into the pocket in the \
             top side (t = 2.6); 600 x 400 table, until 3; no parameters"
                .into()
        },
        build: plate1,
    },
    Builtin {
        name: "gas",
        describe: || {
            format!(
                "thesis ch. 6 hard-disk gas: k x k balls with random velocities on a square table \
                 ({BALLS} {GAS_BALLS}, {RADIUS} {GAS_RADIUS}, {SPEED} {GAS_SPEED}, {SEED} \
                 {DEFAULT_SEED}; side {GAS_SPACING} k, or set by {AREA}; {BOUNDARY} walled or \
                 periodic); until {GAS_UNTIL}"
            )
        },
        build: gas,
    },
    Builtin {
        name: "reversal",
        describe: || {
            format!(
                "thesis 4.6-4.7 reversal test: 4 x 4 balls of radius {REVERSAL_RADIUS} with random \
                 velocities on a {REVERSAL_SIDE} x {REVERSAL_SIDE} table ({SEED} {DEFAULT_SEED}, \
                 {SPEED} {REVERSAL_SPEED}); until {REVERSAL_UNTIL}"
            )
        },
        build: reversal,
    },
    Builtin {
        name: "pool",
        describe: || {
            "a racked break: the cue ball at 400 into 15 touching balls on a 100 x 50 table with \
             six pockets; until 5; no parameters"
                .into()
        },
        build: pool,
    },
    Builtin {
        name: "cradle",
        describe: || {
            "Newton's cradle: Ball-6 strikes a row of five touching balls (1000 x 200 table); \
             until 4; no parameters"
                .into()
        },
        build: cradle,
    },
    Builtin {
        name: "implosion",
        describe: || {
            format!(
                "a dilute gas heading for one disc: {BALLS} {IMPLOSION_BALLS} balls ({RADIUS} \
                 {IMPLOSION_RADIUS}) spread over a square table {IMPLOSION_SIDE} sqrt(N) r wide, \
                 each aimed at a random point of a central disc that would hold them all at area \
                 fraction {AREA} {IMPLOSION_FRACTION}, reached at t = 1; the cluster then flies \
                 apart ({SEED} {DEFAULT_SEED}); until {IMPLOSION_UNTIL}"
            )
        },
        build: implosion,
    },
    Builtin {
        name: "disks",
        describe: super::disks::describe,
        build: super::disks::disks,
    },
];

/// Name and one-line description (with its defaults) of every built-in, in listing order.
pub fn list() -> Vec<(&'static str, String)> {
    BUILTINS.iter().map(|b| (b.name, (b.describe)())).collect()
}

/// Builds and validates a built-in by name.
///
/// Errors: field `scenario` for an unknown name (the message lists the known ones); the flag
/// (`--balls`, `--area-fraction`, ...) for a parameter the scenario does not take or a value it
/// cannot use. Messages do not repeat the field, so `field: message` reads as one sentence.
pub fn build(name: &str, p: &Params) -> Result<Scenario, Invalid> {
    match BUILTINS.iter().find(|b| b.name == name) {
        Some(b) => {
            let scenario = (b.build)(p)?;
            scenario.validate()?;
            Ok(scenario)
        }
        None => {
            let names: Vec<&str> = BUILTINS.iter().map(|b| b.name).collect();
            Err(bad(
                "scenario",
                format!(
                    "unknown built-in scenario `{name}` (known: {})",
                    names.join(", ")
                ),
            ))
        }
    }
}

pub(super) fn bad(field: &str, message: String) -> Invalid {
    Invalid {
        field: field.into(),
        message,
    }
}

/// Rejects every parameter given that `name` does not take.
pub(super) fn allow(p: &Params, name: &str, takes: &[&str]) -> Result<(), Invalid> {
    let given = [
        (BALLS, p.balls.is_some()),
        (SEED, p.seed.is_some()),
        (AREA, p.area_fraction.is_some()),
        (RADIUS, p.radius.is_some()),
        (SPEED, p.speed_max.is_some()),
        (LATTICE, p.lattice.is_some()),
        (TEMPERATURE, p.temperature.is_some()),
        (MIXTURE, p.mixture.is_some()),
        (BOUNDARY, p.boundary.is_some()),
    ];
    for (flag, set) in given {
        if set && !takes.contains(&flag) {
            let accepted = if takes.is_empty() {
                "no parameters".to_string()
            } else {
                takes.join(", ")
            };
            return Err(bad(
                flag,
                format!("does not apply to scenario {name} (it takes {accepted})"),
            ));
        }
    }
    Ok(())
}

pub(super) fn radius_param(p: &Params, default: f64) -> Result<f64, Invalid> {
    let r = p.radius.unwrap_or(default);
    if r.is_finite() && r > 0.0 {
        Ok(r)
    } else {
        Err(bad(RADIUS, format!("must be a positive number, got {r}")))
    }
}

fn speed_param(p: &Params, default: f64) -> Result<f64, Invalid> {
    let v = p.speed_max.unwrap_or(default);
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(bad(SPEED, format!("must be a finite number >= 0, got {v}")))
    }
}

/// A velocity with speed uniform in `[0, vmax)` and direction uniform on the circle.
///
/// The direction is a point drawn uniformly in the unit disk (by rejection from the square),
/// scaled to length 1: only correctly rounded operations, so every platform gets the same bits.
fn random_velocity(rng: &mut ChaCha8Rng, vmax: f64) -> Vec2 {
    let speed = vmax * rng.gen::<f64>();
    loop {
        let x = 2.0 * rng.gen::<f64>() - 1.0;
        let y = 2.0 * rng.gen::<f64>() - 1.0;
        let q = x * x + y * y;
        if q > 1e-12 && q <= 1.0 {
            let s = speed / q.sqrt();
            return Vec2::new(s * x, s * y);
        }
    }
}

/// Four cushions of elasticity 1 around the rectangle `[0, w] × [0, h]`, clockwise from the
/// left side.
pub(super) fn box_cushions(w: f64, h: f64) -> Vec<CushionSpec> {
    box_cushions_at(Vec2::ZERO, Vec2::new(w, h))
}

/// Four elastic cushions, clockwise, around the rectangle from `lo` of sides `size`.
pub(super) fn box_cushions_at(lo: Vec2, size: Vec2) -> Vec<CushionSpec> {
    let corners = [
        lo,
        Vec2::new(lo.x, lo.y + size.y),
        lo + size,
        Vec2::new(lo.x + size.x, lo.y),
    ];
    (0..4)
        .map(|i| cushion(corners[i], corners[(i + 1) % 4]))
        .collect()
}

fn cushion(from: Vec2, to: Vec2) -> CushionSpec {
    CushionSpec {
        from,
        to,
        elasticity: 1.0,
    }
}

fn pocket(from: Vec2, to: Vec2) -> PocketSpec {
    PocketSpec {
        from,
        to,
        corner_elasticity: 1.0,
    }
}

fn ball(x: f64, y: f64, vx: f64, vy: f64, radius: f64) -> BallSpec {
    BallSpec {
        position: Vec2::new(x, y),
        velocity: Vec2::new(vx, vy),
        radius,
        mass: 1.0,
        fixed: None,
        pocket: None,
        colour: None,
        label: None,
    }
}

/// Thesis plate 1 (section 4.2): five cushions and one pocket in the middle of the top side of a
/// 600 × 400 table. Ball-2 moves up at speed 100, strikes the resting Ball-1 at t = 1.6, and
/// Ball-1's centre crosses the pocket line at t = 2.6.
fn plate1(p: &Params) -> Result<Scenario, Invalid> {
    allow(p, "plate1", &[])?;
    let v = Vec2::new;
    Ok(Scenario {
        name: "plate1".into(),
        until: 3.0,
        balls: vec![
            ball(300.0, 300.0, 0.0, 0.0, 20.0),
            ball(300.0, 100.0, 0.0, 100.0, 20.0),
        ],
        cushions: vec![
            cushion(v(0.0, 0.0), v(0.0, 400.0)),
            cushion(v(0.0, 400.0), v(270.0, 400.0)),
            cushion(v(330.0, 400.0), v(600.0, 400.0)),
            cushion(v(600.0, 400.0), v(600.0, 0.0)),
            cushion(v(600.0, 0.0), v(0.0, 0.0)),
        ],
        pockets: vec![pocket(v(270.0, 400.0), v(330.0, 400.0))],
        sectors: None,
        periodic: None,
    })
}

/// The smallest `k` with `k * k >= n`: the side of the square grid that holds `n` sites.
fn ceil_sqrt(n: usize) -> usize {
    let mut k = (n as f64).sqrt() as usize;
    while k.checked_mul(k).is_none_or(|kk| kk > n) {
        k -= 1;
    }
    if k * k < n {
        k += 1;
    }
    k
}

/// The best triangular lattice for `n` balls in a square: `(m, need)`, where `m` balls fill a
/// row and the spacing is `side / need`. Rows are offset by half a spacing and `d·√3/2` apart,
/// and the walls stand half a spacing beyond the outermost centres, so a spacing `d > 2r` keeps
/// every ball clear of its neighbours and of the walls.
pub(super) fn triangular_rows(n: usize) -> (usize, f64) {
    let pitch = 3f64.sqrt() / 2.0;
    let k = (n as f64).sqrt().ceil() as usize;
    let mut best = (1, f64::INFINITY);
    for m in 1..=n.min(4 * k + 4) {
        let rows = n.div_ceil(m);
        let need = (m as f64 + 0.5).max((rows - 1) as f64 * pitch + 1.0);
        if need < best.1 {
            best = (m, need);
        }
    }
    best
}

/// Centres of `n` balls of radius `r` in the square `[0, side]²`, row by row from the bottom
/// left: the first `n` sites of a `k × k` grid (`k² ≥ n`, the last sites empty when `n` is not a
/// square) when its spacing `side / k` is at least `2r·(1 + 1e-9)`, else the
/// densest triangular lattice of [`triangular_rows`]. `Err` holds the largest area fraction at
/// which one of the two fits.
fn lattice(n: usize, k: usize, r: f64, side: f64) -> Result<Vec<Vec2>, f64> {
    let min_spacing = 2.0 * r * (1.0 + GAP);
    let s = side / k as f64;
    if s >= min_spacing {
        let sites = (0..k).flat_map(|j| (0..k).map(move |i| (i, j)));
        let pts = sites
            .take(n)
            .map(|(i, j)| Vec2::new((i as f64 + 0.5) * s, (j as f64 + 0.5) * s))
            .collect();
        return Ok(pts);
    }
    let (m, need) = triangular_rows(n);
    let d = side / need;
    if d < min_spacing {
        let smallest_side = min_spacing * need.min(k as f64);
        return Err(n as f64 * PI * r * r / (smallest_side * smallest_side));
    }
    let h = d * 3f64.sqrt() / 2.0;
    let rows = n.div_ceil(m);
    let ox = (side - (m as f64 + 0.5) * d) / 2.0 + d / 2.0;
    let oy = (side - ((rows - 1) as f64 * h + d)) / 2.0 + d / 2.0;
    let mut pts = Vec::with_capacity(n);
    'rows: for j in 0..rows {
        let shift = if j % 2 == 1 { d / 2.0 } else { 0.0 };
        for i in 0..m {
            if pts.len() == n {
                break 'rows;
            }
            pts.push(Vec2::new(ox + shift + i as f64 * d, oy + j as f64 * h));
        }
    }
    Ok(pts)
}

/// The thesis' gas (chapter 6): `N` equal balls with random velocities on a square table of
/// four perfectly elastic cushions, no pockets, on the first `N` sites of the smallest `k × k`
/// grid that holds them (all of it when `N` is a square, as in the thesis).
///
/// The side is `100 k` (the thesis' 600 × 600 for 36 balls) or, with `--area-fraction PHI`,
/// `sqrt(N π r² / PHI)`. Velocities are drawn ball by ball in ball order.
fn gas(p: &Params) -> Result<Scenario, Invalid> {
    allow(p, "gas", &[BALLS, SEED, AREA, RADIUS, SPEED, BOUNDARY])?;
    let n = p.balls.unwrap_or(GAS_BALLS);
    if n == 0 || n > MAX_BALLS {
        return Err(bad(
            BALLS,
            format!("must be a whole number from 1 to {MAX_BALLS}, got {n}"),
        ));
    }
    let k = ceil_sqrt(n);
    let r = radius_param(p, GAS_RADIUS)?;
    let vmax = speed_param(p, GAS_SPEED)?;
    let side = match p.area_fraction {
        None => GAS_SPACING * k as f64,
        Some(phi) => {
            if !(phi.is_finite() && phi > 0.0 && phi < 1.0) {
                return Err(bad(
                    AREA,
                    format!("must lie strictly between 0 and 1, got {phi}"),
                ));
            }
            (n as f64 * PI * r * r / phi).sqrt()
        }
    };
    if !(side.is_finite() && side > 0.0) {
        let flag = if p.area_fraction.is_some() {
            AREA
        } else {
            RADIUS
        };
        return Err(bad(
            flag,
            format!("gives a table of side {side}, which is not a usable length"),
        ));
    }
    let positions = lattice(n, k, r, side).map_err(|phi_max| {
        // Round down, so that the value printed is one that works.
        let phi_max = (phi_max * 1e6).floor() / 1e6;
        match p.area_fraction {
            Some(phi) => bad(
                AREA,
                format!(
                    "{phi} is too dense: {n} balls of radius {r} do not fit; the largest area \
                     fraction that fits is {phi_max}"
                ),
            ),
            None if phi_max > 0.0 => bad(
                RADIUS,
                format!(
                    "{r:?} is too large for {n} balls on the default {side} x {side} table; use \
                     a smaller radius or {AREA} at most {phi_max}"
                ),
            ),
            None => bad(
                RADIUS,
                format!(
                    "{r:?} is too large for {n} balls on the default {side} x {side} table; use \
                     a smaller radius"
                ),
            ),
        }
    })?;
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed.unwrap_or(DEFAULT_SEED));
    let balls = positions
        .into_iter()
        .map(|position| BallSpec::moving(position, random_velocity(&mut rng, vmax), r, 1.0))
        .collect();
    Ok(boxed(
        Scenario {
            name: "gas".into(),
            until: GAS_UNTIL,
            balls,
            cushions: Vec::new(),
            pockets: Vec::new(),
            sectors: None,
            periodic: None,
        },
        side,
        p.boundary.unwrap_or_default(),
    ))
}

/// `s` in the square box `[0, side]²`, walled by four elastic cushions or periodic.
pub(super) fn boxed(mut s: Scenario, side: f64, boundary: Boundary) -> Scenario {
    match boundary {
        Boundary::Walled => s.cushions = box_cushions(side, side),
        Boundary::Periodic => {
            s.periodic = Some(crate::geometry::PeriodicBox {
                lo: Vec2::ZERO,
                size: Vec2::new(side, side),
            })
        }
    }
    s
}

/// The reversal test of thesis 4.6–4.7: a 4 × 4 array of balls (centres 50, 150, 250, 350 on a
/// 400 × 400 table) with random velocities, row by row from the bottom left.
fn reversal(p: &Params) -> Result<Scenario, Invalid> {
    allow(p, "reversal", &[SEED, SPEED])?;
    let vmax = speed_param(p, REVERSAL_SPEED)?;
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed.unwrap_or(DEFAULT_SEED));
    let mut balls = Vec::with_capacity(16);
    for j in 0..4 {
        for i in 0..4 {
            let at = Vec2::new(50.0 + 100.0 * i as f64, 50.0 + 100.0 * j as f64);
            let velocity = random_velocity(&mut rng, vmax);
            balls.push(BallSpec::moving(at, velocity, REVERSAL_RADIUS, 1.0));
        }
    }
    Ok(Scenario {
        name: "reversal".into(),
        until: REVERSAL_UNTIL,
        balls,
        cushions: box_cushions(REVERSAL_SIDE, REVERSAL_SIDE),
        pockets: Vec::new(),
        sectors: None,
        periodic: None,
    })
}

/// A racked break on a 100 × 50 table (inches, 2:1 like a regulation table).
///
/// Six pockets are lines across their mouths: at each table corner a diagonal whose ends lie
/// 3.25 from the corner along the two sides, and in the middle of each long side a 5-wide gap.
/// The six cushions fill the sides between them, so a pocket's corners stand at its jaws. Sides
/// and pockets run clockwise from the left cushion. Ball-1, the cue ball, leaves (25, 25) at
/// speed 400 along +x into a touching triangle of Ball-2..Ball-16 whose apex is at (75, 25).
/// The cue ball's colour.
const CUE: &str = "#f4f1e6";

/// The colours of pool balls 1 to 8 (9 to 15 repeat 1 to 7, striped on a real table): yellow,
/// blue, red, purple, orange, green, maroon, black.
const POOL_COLOURS: [&str; 8] = [
    "#f2c318", "#1f4fb4", "#d0312d", "#5b2a86", "#ef7d1a", "#1f7a3a", "#7a1f2b", "#111111",
];

/// The numbers of the racked balls, apex first, row by row: the 8 in the middle of the third
/// row, a solid and a stripe at the back corners.
const RACK: [usize; 15] = [1, 9, 2, 10, 8, 3, 11, 7, 14, 4, 5, 13, 15, 6, 12];

fn pool(p: &Params) -> Result<Scenario, Invalid> {
    allow(p, "pool", &[])?;
    const W: f64 = 100.0;
    const H: f64 = 50.0;
    const R: f64 = 1.125;
    const C: f64 = 3.25;
    const S: f64 = 2.5;
    let v = Vec2::new;
    let mid = W / 2.0;
    let cushions = vec![
        cushion(v(0.0, C), v(0.0, H - C)),
        cushion(v(C, H), v(mid - S, H)),
        cushion(v(mid + S, H), v(W - C, H)),
        cushion(v(W, H - C), v(W, C)),
        cushion(v(W - C, 0.0), v(mid + S, 0.0)),
        cushion(v(mid - S, 0.0), v(C, 0.0)),
    ];
    let pockets = vec![
        pocket(v(0.0, H - C), v(C, H)),
        pocket(v(mid - S, H), v(mid + S, H)),
        pocket(v(W - C, H), v(W, H - C)),
        pocket(v(W, C), v(W - C, 0.0)),
        pocket(v(mid + S, 0.0), v(mid - S, 0.0)),
        pocket(v(C, 0.0), v(0.0, C)),
    ];
    let mut cue = ball(25.0, 25.0, 400.0, 0.0, R);
    cue.colour = Some(CUE.into());
    cue.label = Some(String::new());
    let mut balls = vec![cue];
    let row_step = R * 3f64.sqrt();
    let mut numbers = RACK.iter();
    for i in 0..5 {
        for j in 0..=i {
            let x = 75.0 + i as f64 * row_step;
            let y = 25.0 + (j as f64 - i as f64 / 2.0) * 2.0 * R;
            let mut b = ball(x, y, 0.0, 0.0, R);
            let k = *numbers.next().expect("fifteen numbers");
            b.colour = Some(POOL_COLOURS[(k - 1) % 8].into());
            b.label = Some(k.to_string());
            balls.push(b);
        }
    }
    Ok(Scenario {
        name: "pool".into(),
        until: 5.0,
        balls,
        cushions,
        pockets,
        sectors: None,
        periodic: None,
    })
}

/// Newton's cradle on a 1000 × 200 table: Ball-1..Ball-5 (radius 10) touch in a row at y = 100,
/// x = 500..580, at rest; Ball-6 leaves (300, 100) at speed 100 along +x and strikes Ball-1 at
/// t = 1.8.
fn cradle(p: &Params) -> Result<Scenario, Invalid> {
    allow(p, "cradle", &[])?;
    let mut balls: Vec<BallSpec> = (0..5)
        .map(|i| ball(500.0 + 20.0 * i as f64, 100.0, 0.0, 0.0, 10.0))
        .collect();
    balls.push(ball(300.0, 100.0, 100.0, 0.0, 10.0));
    Ok(Scenario {
        name: "cradle".into(),
        until: 4.0,
        balls,
        cushions: box_cushions(1000.0, 200.0),
        pockets: Vec::new(),
        sectors: None,
        periodic: None,
    })
}

/// A dilute gas that gathers into one dense cluster and flies apart: a test of any grid laid out
/// for where the balls start. The balls start on the first `n` sites of a `k × k` grid over the
/// middle 80 % of the table (`k² ≥ n`), each moved at random within its site, and head for a
/// point drawn uniformly in the disc at the table's centre that would hold them all at the area
/// fraction given, which they reach at t = 1 unless they meet on the way.
fn implosion(p: &Params) -> Result<Scenario, Invalid> {
    allow(p, "implosion", &[BALLS, SEED, RADIUS, AREA])?;
    let n = p.balls.unwrap_or(IMPLOSION_BALLS);
    if n == 0 || n > MAX_BALLS {
        return Err(bad(
            BALLS,
            format!("must be from 1 to {MAX_BALLS}, got {n}"),
        ));
    }
    let r = radius_param(p, IMPLOSION_RADIUS)?;
    let phi = p.area_fraction.unwrap_or(IMPLOSION_FRACTION);
    if !(phi > 0.0 && phi < 1.0) {
        return Err(bad(AREA, format!("must be between 0 and 1, got {phi}")));
    }
    let side = IMPLOSION_SIDE * (n as f64).sqrt() * r;
    let k = ceil_sqrt(n);
    let site = 0.8 * side / k as f64;
    let disc = (n as f64 / phi).sqrt() * r;
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed.unwrap_or(DEFAULT_SEED));
    let mut unit_disc = || loop {
        let (x, y) = (2.0 * rng.gen::<f64>() - 1.0, 2.0 * rng.gen::<f64>() - 1.0);
        if x * x + y * y <= 1.0 {
            return Vec2::new(x, y);
        }
    };
    let centre = Vec2::new(side / 2.0, side / 2.0);
    let balls = (0..n)
        .map(|s| {
            let corner = site * Vec2::new((s % k) as f64, (s / k) as f64);
            let jitter = 0.5 * site - r * (1.0 + GAP);
            let position = Vec2::new(0.1 * side, 0.1 * side)
                + corner
                + Vec2::new(0.5 * site, 0.5 * site)
                + jitter * unit_disc();
            let aim = centre + disc * unit_disc();
            ball(
                position.x,
                position.y,
                aim.x - position.x,
                aim.y - position.y,
                r,
            )
        })
        .collect();
    Ok(Scenario {
        name: "implosion".into(),
        until: IMPLOSION_UNTIL,
        balls,
        cushions: box_cushions(side, side),
        pockets: Vec::new(),
        sectors: None,
        periodic: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names() -> Vec<&'static str> {
        list().into_iter().map(|(n, _)| n).collect()
    }

    fn gas_with(balls: usize, seed: u64, phi: Option<f64>) -> Result<Scenario, Invalid> {
        build(
            "gas",
            &Params {
                balls: Some(balls),
                seed: Some(seed),
                area_fraction: phi,
                ..Params::default()
            },
        )
    }

    #[test]
    fn every_builtin_builds_validates_and_is_named() {
        assert_eq!(
            names(),
            [
                "plate1",
                "gas",
                "reversal",
                "pool",
                "cradle",
                "implosion",
                "disks"
            ]
        );
        for (name, description) in list() {
            assert!(!description.is_empty() && !description.contains('\n'));
            let s = build(name, &Params::default()).unwrap();
            s.validate().unwrap();
            assert_eq!(s.name, name);
            assert!(!s.balls.is_empty() && !s.cushions.is_empty());
        }
    }

    #[test]
    fn every_side_has_the_table_on_its_right() {
        for name in names() {
            let s = build(name, &Params::default()).unwrap();
            let ends: Vec<Vec2> = s
                .cushions
                .iter()
                .flat_map(|c| [c.from, c.to])
                .chain(s.pockets.iter().flat_map(|p| [p.from, p.to]))
                .collect();
            let sum = ends.iter().fold(Vec2::ZERO, |a, &b| a + b);
            let centroid = (1.0 / ends.len() as f64) * sum;
            let sides = s
                .cushions
                .iter()
                .map(|c| (c.from, c.to))
                .chain(s.pockets.iter().map(|p| (p.from, p.to)));
            for (k, (from, to)) in sides.enumerate() {
                let mid = 0.5 * (from + to);
                let inward = (to - from).perp_cw();
                assert!(
                    inward.dot(centroid - mid) > 0.0,
                    "{name}: side {k} from {from:?} to {to:?} faces away from the table"
                );
            }
        }
    }

    #[test]
    fn plate1_is_the_thesis_picture() {
        let s = build("plate1", &Params::default()).unwrap();
        assert_eq!(s.until, 3.0);
        assert_eq!(s.cushions.len(), 5);
        assert_eq!(s.pockets.len(), 1);
        assert_eq!(s.pockets[0].from, Vec2::new(270.0, 400.0));
        assert_eq!(s.pockets[0].to, Vec2::new(330.0, 400.0));
        assert_eq!(s.balls[0].position, Vec2::new(300.0, 300.0));
        assert_eq!(s.balls[0].velocity, Vec2::ZERO);
        assert_eq!(s.balls[1].position, Vec2::new(300.0, 100.0));
        assert_eq!(s.balls[1].velocity, Vec2::new(0.0, 100.0));
        // Ball-2 closes the 160 gap at speed 100: contact at t = 1.6; Ball-1 then has 100 to go.
        let gap = s.balls[0].position.y - s.balls[1].position.y - 40.0;
        assert_eq!(gap / 100.0, 1.6);
    }

    #[test]
    fn gas_defaults_follow_the_thesis() {
        let s = build("gas", &Params::default()).unwrap();
        assert_eq!(s.balls.len(), 36);
        assert_eq!(s.bounds(), (Vec2::ZERO, Vec2::new(600.0, 600.0)));
        assert_eq!(s.balls[0].position, Vec2::new(50.0, 50.0));
        assert_eq!(s.balls[1].position, Vec2::new(150.0, 50.0));
        assert_eq!(s.balls[6].position, Vec2::new(50.0, 150.0));
        assert!(s.pockets.is_empty());
        assert_eq!(s.until, 4.0);
        for b in &s.balls {
            assert_eq!((b.radius, b.mass), (30.0, 1.0));
            assert!(b.velocity.norm() < 100.0);
        }
    }

    #[test]
    fn gas_seed_is_deterministic() {
        let a = gas_with(400, 3, None).unwrap();
        let b = gas_with(400, 3, None).unwrap();
        let c = gas_with(400, 4, None).unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_eq!(a.balls.len(), 400);
        let positions = |s: &Scenario| s.balls.iter().map(|b| b.position).collect::<Vec<_>>();
        assert_eq!(positions(&a), positions(&c));
    }

    #[test]
    fn seeded_velocities_are_pinned() {
        // These bits must never change, on any platform: a seed names one scenario.
        let s = build("reversal", &Params::default()).unwrap();
        let v = s.balls[0].velocity;
        let again = {
            let mut rng = ChaCha8Rng::seed_from_u64(1);
            random_velocity(&mut rng, 100.0)
        };
        assert_eq!(v, again);
        assert_eq!((v.x.to_bits(), v.y.to_bits()), PINNED_REVERSAL_BALL1);
    }

    const PINNED_REVERSAL_BALL1: (u64, u64) = (13854089065394845240, 4621270761056742218);

    #[test]
    fn velocities_are_spread_in_speed_and_direction() {
        let s = gas_with(10_000, 7, Some(0.3)).unwrap();
        let n = s.balls.len() as f64;
        let mean_speed = s.balls.iter().map(|b| b.velocity.norm()).sum::<f64>() / n;
        assert!((mean_speed - 50.0).abs() < 1.5, "{mean_speed}");
        let mean_v = s.balls.iter().fold(Vec2::ZERO, |a, b| a + b.velocity);
        assert!((1.0 / n * mean_v).norm() < 1.5);
        let right = s.balls.iter().filter(|b| b.velocity.x > 0.0).count() as f64;
        assert!((right / n - 0.5).abs() < 0.02);
    }

    #[test]
    fn dense_gas_uses_a_triangular_lattice() {
        let s = gas_with(900, 1, Some(0.85)).unwrap();
        s.validate().unwrap();
        assert_eq!(s.balls.len(), 900);
        let mut xs: Vec<u64> = s.balls.iter().map(|b| b.position.x.to_bits()).collect();
        xs.sort_unstable();
        xs.dedup();
        assert!(
            xs.len() > 30,
            "{} columns: not a triangular lattice",
            xs.len()
        );
        // Rows are offset by half a spacing.
        let d = s.balls[1].position.x - s.balls[0].position.x;
        let m = s
            .balls
            .iter()
            .position(|b| b.position.y > s.balls[0].position.y)
            .unwrap();
        assert!((s.balls[m].position.x - s.balls[0].position.x - d / 2.0).abs() < 1e-9 * d);
        let area: f64 = s.balls.iter().map(|b| PI * b.radius * b.radius).sum();
        let (lo, hi) = s.bounds();
        assert!((area / ((hi.x - lo.x) * (hi.y - lo.y)) - 0.85).abs() < 1e-12);
    }

    #[test]
    fn too_dense_gas_names_the_largest_fraction() {
        let e = gas_with(400, 1, Some(0.95)).unwrap_err();
        assert_eq!(e.field, "--area-fraction");
        let best: f64 = e.message.rsplit(' ').next().unwrap().parse().unwrap();
        assert!(best > 0.8 && best < 0.9069, "{}", e.message);
        gas_with(400, 1, Some(best)).unwrap();
        let e = build(
            "gas",
            &Params {
                radius: Some(60.0),
                ..Params::default()
            },
        )
        .unwrap_err();
        assert_eq!(e.field, "--radius");
        assert!(
            e.message.contains("--area-fraction at most"),
            "{}",
            e.message
        );
        for n in [1, 4, 9, 16, 25, 100] {
            let e = gas_with(n, 1, Some(0.99)).unwrap_err();
            let best: f64 = e.message.rsplit(' ').next().unwrap().parse().unwrap();
            gas_with(n, 1, Some(best)).unwrap();
        }
    }

    #[test]
    fn a_gas_takes_any_number_of_balls() {
        // 10 balls: the first 10 sites of the 4 x 4 grid of a 400 x 400 table
        let s = gas_with(10, 1, None).unwrap();
        assert_eq!(s.balls.len(), 10);
        assert_eq!(s.bounds().1, Vec2::new(400.0, 400.0));
        assert_eq!(s.balls[9].position, Vec2::new(150.0, 250.0));
        s.validate().unwrap();
        // the square numbers keep the thesis' k x k grid, and the dense ones still fit
        assert_eq!(
            gas_with(16, 1, None).unwrap().balls[4].position,
            Vec2::new(50.0, 150.0)
        );
        for (n, phi) in [
            (2, None),
            (3, Some(0.3)),
            (5, None),
            (99_999, Some(0.5)),
            (100_001, Some(0.5)),
        ] {
            let s = gas_with(n, 1, phi).unwrap();
            assert_eq!(s.balls.len(), n);
            s.validate().unwrap();
        }
        let e = gas_with(0, 1, None).unwrap_err();
        assert!(e.message.contains("whole number from 1"), "{}", e.message);
        assert_eq!(e.field, "--balls");
        assert_eq!(gas_with(usize::MAX, 1, None).unwrap_err().field, "--balls");
        assert_eq!(gas_with(1, 1, None).unwrap().balls.len(), 1);
    }

    #[test]
    fn bad_parameter_values_name_their_flag() {
        let cases = [
            (
                Params {
                    area_fraction: Some(1.0),
                    ..Params::default()
                },
                "--area-fraction",
            ),
            (
                Params {
                    area_fraction: Some(f64::NAN),
                    ..Params::default()
                },
                "--area-fraction",
            ),
            (
                Params {
                    area_fraction: Some(1e-320),
                    ..Params::default()
                },
                "--area-fraction",
            ),
            (
                Params {
                    radius: Some(-1.0),
                    ..Params::default()
                },
                "--radius",
            ),
            (
                Params {
                    speed_max: Some(f64::INFINITY),
                    ..Params::default()
                },
                "--speed-max",
            ),
        ];
        for (p, flag) in cases {
            assert_eq!(build("gas", &p).unwrap_err().field, flag, "{p:?}");
        }
        let still = build(
            "gas",
            &Params {
                speed_max: Some(0.0),
                ..Params::default()
            },
        )
        .unwrap();
        assert!(still.balls.iter().all(|b| b.velocity == Vec2::ZERO));
    }

    #[test]
    fn parameters_a_scenario_does_not_take_are_refused() {
        let phi = Params {
            area_fraction: Some(0.5),
            ..Params::default()
        };
        for name in ["plate1", "pool", "cradle", "reversal"] {
            let e = build(name, &phi).unwrap_err();
            assert_eq!(e.field, "--area-fraction", "{name}");
            assert!(e.message.contains(name));
        }
        let seed = Params {
            seed: Some(2),
            ..Params::default()
        };
        assert_eq!(build("pool", &seed).unwrap_err().field, "--seed");
        let balls = Params {
            balls: Some(16),
            ..Params::default()
        };
        assert_eq!(build("reversal", &balls).unwrap_err().field, "--balls");
        let s = build("reversal", &seed).unwrap();
        assert_ne!(s, build("reversal", &Params::default()).unwrap());
    }

    #[test]
    fn unknown_name_lists_the_known_ones() {
        let e = build("snooker", &Params::default()).unwrap_err();
        assert_eq!(e.field, "scenario");
        for name in names() {
            assert!(e.message.contains(name), "{}", e.message);
        }
    }

    #[test]
    fn reversal_is_a_four_by_four_array() {
        let s = build("reversal", &Params::default()).unwrap();
        assert_eq!(s.balls.len(), 16);
        assert_eq!(s.balls[5].position, Vec2::new(150.0, 150.0));
        assert_eq!(s.bounds(), (Vec2::ZERO, Vec2::new(400.0, 400.0)));
        assert_eq!(s.until, 3.0);
        assert!(s.balls.iter().all(|b| b.radius == 30.0));
    }

    #[test]
    fn pool_rack_touches() {
        let s = build("pool", &Params::default()).unwrap();
        assert_eq!(
            (s.balls.len(), s.cushions.len(), s.pockets.len()),
            (16, 6, 6)
        );
        assert_eq!(s.cushions[0].from, Vec2::new(0.0, 3.25));
        assert_eq!(s.pockets[0].to, Vec2::new(3.25, 50.0));
        assert_eq!(s.pockets[1].from, Vec2::new(47.5, 50.0));
        assert_eq!(s.balls[0].velocity, Vec2::new(400.0, 0.0));
        assert_eq!(s.balls[1].position, Vec2::new(75.0, 25.0));
        // The table is closed: each side ends where the next begins, cushions and pockets
        // alternating clockwise.
        for k in 0..6 {
            assert_eq!(s.cushions[k].to, s.pockets[k].from);
            assert_eq!(s.pockets[k].to, s.cushions[(k + 1) % 6].from);
        }
        // Every rack ball touches at least two others.
        let rack = &s.balls[1..];
        for (i, a) in rack.iter().enumerate() {
            let touching = rack
                .iter()
                .enumerate()
                .filter(|&(j, b)| j != i && ((a.position - b.position).norm() - 2.25).abs() < 1e-9)
                .count();
            assert!(touching >= 2, "Ball-{} touches {touching}", i + 2);
        }
    }

    #[test]
    fn cradle_row_touches() {
        let s = build("cradle", &Params::default()).unwrap();
        assert_eq!(s.balls.len(), 6);
        for i in 0..4 {
            assert_eq!(s.balls[i + 1].position.x - s.balls[i].position.x, 20.0);
        }
        assert_eq!(s.balls[5].position, Vec2::new(300.0, 100.0));
        assert_eq!(s.balls[5].velocity, Vec2::new(100.0, 0.0));
    }

    #[test]
    fn the_implosion_aims_every_ball_into_its_disc() {
        for (balls, phi, seed) in [(None, None, None), (Some(1000), Some(0.3), Some(5))] {
            let p = Params {
                balls,
                area_fraction: phi,
                seed,
                ..Default::default()
            };
            let s = build("implosion", &p).unwrap();
            let n = balls.unwrap_or(IMPLOSION_BALLS);
            assert_eq!(s.balls.len(), n);
            let side = s.cushions[1].to.x;
            let centre = Vec2::new(side / 2.0, side / 2.0);
            let disc = (n as f64 / phi.unwrap_or(IMPLOSION_FRACTION)).sqrt();
            for b in &s.balls {
                assert!((b.position + b.velocity - centre).norm() <= disc, "{b:?}");
                let inside = |x: f64| (0.1 * side..=0.9 * side).contains(&x);
                assert!(inside(b.position.x) && inside(b.position.y), "{b:?}");
            }
        }
        let speed = Params {
            speed_max: Some(1.0),
            ..Default::default()
        };
        let e = build("implosion", &speed).unwrap_err();
        assert_eq!(e.field, "--speed-max");
        for phi in [0.0, 1.0, f64::NAN] {
            let p = Params {
                area_fraction: Some(phi),
                ..Default::default()
            };
            assert_eq!(build("implosion", &p).unwrap_err().field, "--area-fraction");
        }
    }

    #[test]
    fn large_gas_builds_quickly() {
        let start = std::time::Instant::now();
        let s = gas_with(250_000, 1, Some(0.6)).unwrap();
        assert_eq!(s.balls.len(), 250_000);
        let dense = gas_with(250_000, 1, Some(0.85)).unwrap();
        assert_eq!(dense.balls.len(), 250_000);
        assert!(
            start.elapsed().as_secs_f64() < 20.0,
            "{:?}",
            start.elapsed()
        );
    }

    #[test]
    fn ceiling_square_roots() {
        let cases = [
            (1, 1),
            (2, 2),
            (4, 2),
            (35, 6),
            (36, 6),
            (37, 7),
            (1_000_000, 1000),
        ];
        for (n, k) in cases {
            assert_eq!(ceil_sqrt(n), k, "{n}");
        }
        assert_eq!(ceil_sqrt(0), 0);
    }
}
