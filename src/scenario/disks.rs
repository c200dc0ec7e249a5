//! The built-in `disks`: a hard-disk fluid's start for physics runs. Disks on a square or
//! triangular lattice in a square box of elastic cushions, at a given area fraction, with
//! Maxwell-Boltzmann velocities at a given temperature and zero total momentum, one size or a
//! binary mixture.
//!
//! A lattice is not a fluid: run it until it has forgotten the lattice (a few collisions per
//! disk; at area fraction 0.5 about 5 time units at kT = 1 and unit radius), then start
//! measuring (`--observe-from`), or start a new run from its final state.

use super::builtin::{
    allow, bad, boxed, radius_param, triangular_rows, Boundary, Lattice, Mixture, Params, AREA,
    BALLS, BOUNDARY, DEFAULT_SEED, GAP, LATTICE, MIXTURE, RADIUS, SEED, TEMPERATURE,
};
use super::random_sites::{random_sites, TRIES_PER_DISK};
use super::{BallSpec, Invalid, Scenario};
use crate::geometry::Vec2;
use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

const DISKS_BALLS: usize = 400;
const DISKS_AREA: f64 = 0.5;
const DISKS_RADIUS: f64 = 1.0;
const DISKS_TEMPERATURE: f64 = 1.0;
const DISKS_UNTIL: f64 = 10.0;

/// The one-line description, with the defaults.
pub fn describe() -> String {
    format!(
        "a hard-disk fluid's start: {BALLS} {DISKS_BALLS} disks ({RADIUS} {DISKS_RADIUS}, mass 1) \
         on a {LATTICE} triangular|square|random lattice in a square box ({BOUNDARY} walled by elastic \
         cushions, or periodic) at {AREA} {DISKS_AREA}, Maxwell-Boltzmann velocities at \
         {TEMPERATURE} {DISKS_TEMPERATURE} with zero total momentum, {MIXTURE} F:Q for a \
         fraction F of large disks Q times as wide ({SEED} {DEFAULT_SEED}); until {DISKS_UNTIL}"
    )
}

/// Builds the `disks` scenario.
pub fn disks(p: &Params) -> Result<Scenario, Invalid> {
    allow(
        p,
        "disks",
        &[
            BALLS,
            SEED,
            AREA,
            RADIUS,
            LATTICE,
            TEMPERATURE,
            MIXTURE,
            BOUNDARY,
        ],
    )?;
    let n = p.balls.unwrap_or(DISKS_BALLS);
    if !(2..=super::builtin::MAX_BALLS).contains(&n) {
        return Err(bad(
            BALLS,
            format!(
                "must be a whole number from 2 to {} (zero momentum needs two), got {n}",
                super::builtin::MAX_BALLS
            ),
        ));
    }
    let phi = p.area_fraction.unwrap_or(DISKS_AREA);
    if !(phi.is_finite() && phi > 0.0 && phi < 1.0) {
        return Err(bad(
            AREA,
            format!("must lie strictly between 0 and 1, got {phi}"),
        ));
    }
    let kt = p.temperature.unwrap_or(DISKS_TEMPERATURE);
    if !(kt.is_finite() && kt > 0.0) {
        return Err(bad(
            TEMPERATURE,
            format!("must be a positive number, got {kt}"),
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed.unwrap_or(DEFAULT_SEED));
    let radii = radii(p, n, &mut rng)?;
    let covered: f64 = radii.iter().map(|r| PI * r * r).sum();
    let side = (covered / phi).sqrt();
    let rmax = radii.iter().copied().fold(0.0, f64::max);
    let lattice = p.lattice.unwrap_or(Lattice::Triangular);
    let boundary = p.boundary.unwrap_or_default();
    let sites = match (lattice, boundary) {
        (Lattice::Random, _) => {
            let periodic = boundary == Boundary::Periodic;
            let placed = random_sites(&radii, side, periodic, GAP, &mut rng).map_err(|placed| {
                bad(
                    AREA,
                    format!(
                        "{phi} is too dense for random sequential addition: {placed} of {n} disks \
                         placed before one found no room in {TRIES_PER_DISK} tries (equal disks \
                         jam near 0.547); start sparser and compress (poolsim compress)"
                    ),
                )
            })?;
            Ok(placed)
        }
        (_, Boundary::Walled) => sites(lattice == Lattice::Square, n, rmax, side),
        (_, Boundary::Periodic) => periodic_sites(lattice == Lattice::Square, n, rmax, side),
    }
    .map_err(|need| {
        let most = (covered / (need * need) * 1e6).floor() / 1e6;
        let (kind, walls) = (
            if lattice == Lattice::Square { "square" } else { "triangular" },
            if boundary == Boundary::Walled { "walled" } else { "periodic" },
        );
        bad(
            AREA,
            format!("{phi} is too dense for {n} disks on a {kind} lattice in a {walls} box: at most {most}"),
        )
    })?;
    let velocities = maxwell_boltzmann(n, kt, &mut rng);
    let balls = sites
        .into_iter()
        .zip(radii)
        .zip(velocities)
        .map(|((position, radius), velocity)| BallSpec::moving(position, velocity, radius, 1.0))
        .collect();
    let s = Scenario {
        name: "disks".into(),
        until: DISKS_UNTIL,
        balls,
        cushions: Vec::new(),
        pockets: Vec::new(),
        sectors: None,
        periodic: None,
    };
    Ok(boxed(s, side, boundary))
}

/// Every disk's radius: the small radius, and for a mixture the large one on a random choice
/// of `round(F N)` disks.
fn radii(p: &Params, n: usize, rng: &mut ChaCha8Rng) -> Result<Vec<f64>, Invalid> {
    let r = radius_param(p, DISKS_RADIUS)?;
    let mut radii = vec![r; n];
    if let Some(Mixture { large, ratio }) = p.mixture {
        if !((0.0..=1.0).contains(&large) && ratio.is_finite() && ratio >= 1.0) {
            return Err(bad(
                MIXTURE,
                format!(
                    "the fraction must lie in [0, 1] and the diameter ratio be at least 1, got \
                     {large}:{ratio}"
                ),
            ));
        }
        let k = (large * n as f64).round() as usize;
        radii[..k].fill(ratio * r);
        radii.shuffle(rng);
    }
    Ok(radii)
}

/// Sites for `n` disks of radius at most `r` in the box `[0, side]²`, row by row from the
/// bottom, each at least a radius (and a hair) from the walls and two from the others. `Err`
/// holds the smallest side that would take them.
fn sites(square: bool, n: usize, r: f64, side: f64) -> Result<Vec<Vec2>, f64> {
    let d = 2.0 * r * (1.0 + GAP);
    // columns per row, the rows' pitch and shift, and the extent in spacings
    let (m, pitch, shift, need) = if square {
        let k = (n as f64).sqrt().ceil() as usize;
        (k, 1.0, 0.0, k as f64)
    } else {
        let (m, need) = triangular_rows(n);
        (m, 3f64.sqrt() / 2.0, 0.5, need)
    };
    let spacing = side / need;
    if spacing < d {
        return Err(d * need);
    }
    let rows = n.div_ceil(m);
    let width = (m as f64 - 1.0 + if rows > 1 { shift } else { 0.0 }) * spacing;
    let height = (rows as f64 - 1.0) * pitch * spacing;
    let (ox, oy) = ((side - width) / 2.0, (side - height) / 2.0);
    let pts = (0..n)
        .map(|k| {
            let (j, i) = (k / m, k % m);
            let x = ox + (i as f64 + if j % 2 == 1 { shift } else { 0.0 }) * spacing;
            Vec2::new(x, oy + j as f64 * pitch * spacing)
        })
        .collect();
    Ok(pts)
}

/// Sites for `n` disks of radius at most `r` in the periodic box `[0, side)²`: the first `n` of
/// a lattice that tiles the box, `m` columns by `k` rows (for the triangular lattice `k` even
/// and every other row shifted by half a column, the shape nearest the regular lattice). `Err`
/// holds the smallest side that would take them.
fn periodic_sites(square: bool, n: usize, r: f64, side: f64) -> Result<Vec<Vec2>, f64> {
    let d = 2.0 * r * (1.0 + GAP);
    // the closest two sites, in box sides, of `m` columns by `k` rows
    let closest = |m: usize, k: usize| -> f64 {
        let (ax, ay) = (1.0 / m as f64, 1.0 / k as f64);
        if square {
            ax.min(ay)
        } else {
            ax.min((0.25 * ax * ax + ay * ay).sqrt()).min(2.0 * ay)
        }
    };
    let rows = |m: usize| {
        if square {
            n.div_ceil(m)
        } else {
            n.div_ceil(m).next_multiple_of(2)
        }
    };
    let root = (n as f64).sqrt().ceil() as usize;
    let (m, k) = match square {
        true => (root, root),
        false => (root / 2..=2 * root + 2)
            .filter(|&m| m >= 1)
            .map(|m| (m, rows(m)))
            .max_by(|a, b| closest(a.0, a.1).total_cmp(&closest(b.0, b.1)))
            .expect("a range of columns"),
    };
    let spacing = closest(m, k) * side;
    if spacing < d {
        return Err(side * d / spacing);
    }
    let shift = if square { 0.0 } else { 0.5 };
    let (ax, ay) = (side / m as f64, side / k as f64);
    Ok((0..n)
        .map(|s| {
            let (j, i) = (s / m, s % m);
            let offset = if j % 2 == 1 { shift } else { 0.0 };
            Vec2::new((i as f64 + 0.25 + offset) * ax, (j as f64 + 0.5) * ay)
        })
        .collect())
}

/// Velocities of `n` unit masses from the Maxwell-Boltzmann distribution at `kt`: normal
/// components (Box-Muller), the mean removed so that the total momentum is zero, then scaled so
/// that the kinetic energy is `n kt` (two degrees of freedom per disk).
fn maxwell_boltzmann(n: usize, kt: f64, rng: &mut ChaCha8Rng) -> Vec<Vec2> {
    let mut normal = || {
        let u: f64 = rng.gen_range(f64::EPSILON..1.0);
        let a: f64 = 2.0 * PI * rng.gen::<f64>();
        let rho = (-2.0 * u.ln()).sqrt();
        Vec2::new(rho * a.cos(), rho * a.sin())
    };
    let mut v: Vec<Vec2> = (0..n).map(|_| normal()).collect();
    let mean = (1.0 / n as f64) * v.iter().fold(Vec2::ZERO, |s, &x| s + x);
    for x in &mut v {
        *x = *x - mean;
    }
    let kinetic: f64 = v.iter().map(|x| 0.5 * x.norm2()).sum();
    let scale = (n as f64 * kt / kinetic).sqrt();
    v.iter().map(|&x| scale * x).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(f: impl FnOnce(&mut Params)) -> Result<Scenario, Invalid> {
        let mut p = Params::default();
        f(&mut p);
        disks(&p)
    }

    #[test]
    fn a_start_has_its_density_temperature_and_no_momentum() {
        for lattice in [Lattice::Square, Lattice::Triangular] {
            for (n, phi) in [(2, 0.1), (400, 0.5), (1000, 0.7), (37, 0.3)] {
                let s = with(|p| {
                    p.balls = Some(n);
                    p.area_fraction = Some(phi);
                    p.lattice = Some(lattice);
                    p.temperature = Some(2.0);
                })
                .unwrap();
                s.validate().unwrap();
                let (lo, hi) = s.bounds();
                let covered: f64 = s.balls.iter().map(|b| PI * b.radius * b.radius).sum();
                let area = (hi.x - lo.x) * (hi.y - lo.y);
                assert!(
                    (covered / area - phi).abs() < 1e-12,
                    "{lattice:?} {n} {phi}"
                );
                let p = s.balls.iter().fold(Vec2::ZERO, |a, b| a + b.velocity);
                assert!(p.norm() < 1e-9 * n as f64, "{p:?}");
                let k: f64 = s.balls.iter().map(|b| 0.5 * b.velocity.norm2()).sum();
                assert!((k / (2.0 * n as f64) - 1.0).abs() < 1e-12, "{k}");
            }
        }
    }

    #[test]
    fn a_mixture_has_its_share_of_large_disks() {
        let s = with(|p| {
            p.balls = Some(1000);
            p.mixture = Some(Mixture {
                large: 0.5,
                ratio: 1.4,
            });
            p.area_fraction = Some(0.6);
        })
        .unwrap();
        s.validate().unwrap();
        let large = s.balls.iter().filter(|b| b.radius == 1.4).count();
        assert_eq!(large, 500);
        assert_eq!(s.balls.iter().filter(|b| b.radius == 1.0).count(), 500);
    }

    #[test]
    fn bad_values_name_their_flag() {
        let err = |f: fn(&mut Params)| with(f).unwrap_err().field;
        assert_eq!(err(|p| p.area_fraction = Some(0.95)), AREA);
        assert_eq!(err(|p| p.temperature = Some(0.0)), TEMPERATURE);
        assert_eq!(err(|p| p.balls = Some(1)), BALLS);
        assert_eq!(
            err(|p| p.mixture = Some(Mixture {
                large: 0.5,
                ratio: 0.5
            })),
            MIXTURE
        );
        let dense = with(|p| {
            p.area_fraction = Some(0.88);
            p.lattice = Some(Lattice::Square);
        })
        .unwrap_err();
        assert!(dense.message.contains("at most 0.7"), "{}", dense.message);
        // the other built-ins refuse the new parameters
        let gas = super::super::builtin::build(
            "gas",
            &Params {
                temperature: Some(1.0),
                ..Params::default()
            },
        )
        .unwrap_err();
        assert_eq!(gas.field, TEMPERATURE);
    }
}
