//! Random sequential addition: disks dropped one after another at uniformly random places in a
//! square box, each try that overlaps a disk already placed thrown away (Widom 1966; for equal
//! disks it jams near an area fraction of 0.547, Hinrichsen, Feder and Jøssang 1986). A cell
//! grid keeps each try's test to the disks nearby.

use crate::geometry::{PeriodicBox, Vec2};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Tries per disk before the addition gives up.
pub const TRIES_PER_DISK: usize = 10_000;

/// Centres for disks of radii `radii`, in that order, in the box `[0, side)²`: periodic (a disk
/// may lie across a side, overlaps measured to the nearest image) or walled (each centre at
/// least its radius, and a hair, from the walls). Every pair stays `1 + gap` times its contact
/// distance apart. `Err` holds how many were placed before a disk found no room in
/// [`TRIES_PER_DISK`] tries.
pub fn random_sites(
    radii: &[f64],
    side: f64,
    periodic: bool,
    gap: f64,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<Vec2>, usize> {
    let rmax = radii.iter().copied().fold(0.0, f64::max);
    let reach = 2.0 * rmax * (1.0 + gap);
    let cells = ((side / reach).floor() as usize).clamp(1, 1 << 15);
    let width = side / cells as f64;
    let period = PeriodicBox {
        lo: Vec2::ZERO,
        size: Vec2::new(side, side),
    };
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); cells * cells];
    let mut placed: Vec<Vec2> = Vec::with_capacity(radii.len());
    let cell_of = |p: Vec2| -> (usize, usize) {
        let c = |x: f64| ((x / width).floor().max(0.0) as usize).min(cells - 1);
        (c(p.x), c(p.y))
    };
    for (k, &r) in radii.iter().enumerate() {
        let margin = if periodic { 0.0 } else { r * (1.0 + gap) };
        let fits = |p: Vec2, placed: &[Vec2], grid: &[Vec<u32>]| -> bool {
            let (cx, cy) = cell_of(p);
            for dy in -1i64..=1 {
                for dx in -1i64..=1 {
                    let (x, y) = (cx as i64 + dx, cy as i64 + dy);
                    let n = cells as i64;
                    let inside = (0..n).contains(&x) && (0..n).contains(&y);
                    if !periodic && !inside {
                        continue;
                    }
                    let id = (y.rem_euclid(n) * n + x.rem_euclid(n)) as usize;
                    for &j in &grid[id] {
                        let q = placed[j as usize];
                        let d = if periodic {
                            period.nearest(q - p)
                        } else {
                            q - p
                        };
                        let need = (r + radii[j as usize]) * (1.0 + gap);
                        if d.norm2() < need * need {
                            return false;
                        }
                    }
                }
            }
            true
        };
        let spot = (0..TRIES_PER_DISK)
            .map(|_| {
                Vec2::new(
                    rng.gen_range(margin..side - margin),
                    rng.gen_range(margin..side - margin),
                )
            })
            .find(|&p| fits(p, &placed, &grid));
        let Some(p) = spot else {
            return Err(k);
        };
        let (cx, cy) = cell_of(p);
        grid[cy * cells + cx].push(k as u32);
        placed.push(p);
    }
    Ok(placed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn no_two_disks_overlap_and_all_lie_in_the_box() {
        for periodic in [false, true] {
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            let radii: Vec<f64> = (0..500)
                .map(|k| if k % 2 == 0 { 1.0 } else { 1.4 })
                .collect();
            let covered: f64 = radii.iter().map(|r| std::f64::consts::PI * r * r).sum();
            let side = (covered / 0.4).sqrt();
            let p = random_sites(&radii, side, periodic, 1e-9, &mut rng).unwrap();
            let period = PeriodicBox {
                lo: Vec2::ZERO,
                size: Vec2::new(side, side),
            };
            for i in 0..p.len() {
                let r = radii[i];
                assert!(p[i].x >= 0.0 && p[i].x < side && p[i].y >= 0.0 && p[i].y < side);
                if !periodic {
                    assert!(p[i].x >= r && p[i].x <= side - r && p[i].y >= r && p[i].y <= side - r);
                }
                for j in 0..i {
                    let d = if periodic {
                        period.nearest(p[j] - p[i])
                    } else {
                        p[j] - p[i]
                    };
                    assert!(d.norm() >= r + radii[j], "{periodic} {i} {j}");
                }
            }
        }
    }

    #[test]
    fn past_its_jamming_it_gives_up() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let radii = vec![1.0; 200];
        let side = (200.0 * std::f64::consts::PI / 0.6f64).sqrt();
        assert!(random_sites(&radii, side, true, 0.0, &mut rng).is_err());
    }
}
