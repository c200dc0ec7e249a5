//! The rules of a periodic box: a sound box with no cushions, pockets or sectors, wide enough
//! for the minimum image, every ball inside it and none overlapping another or another's image.

use super::{check_positive, check_vec, invalid, Invalid, Scenario};
use crate::geometry::{PeriodicBox, Vec2};

/// A periodic box must be at least this many largest diameters along each side: the event
/// list's cells are at least a diameter (and a hair) wide, and it needs three of them along
/// each side so that each of a cell's neighbours is one image of one cell.
pub const MIN_SIDE_DIAMETERS: f64 = 3.0 * (1.0 + 2e-6);

impl Scenario {
    /// Checks the periodic box, if the scenario has one.
    pub(super) fn check_periodic(&self) -> Result<(), Invalid> {
        let Some(b) = &self.periodic else {
            return Ok(());
        };
        check_vec("box.origin", b.lo)?;
        check_positive("box.size[1]", b.size.x)?;
        check_positive("box.size[2]", b.size.y)?;
        let refuse = |field: &str, what: &str| {
            Err(invalid(
                field.into(),
                format!("a periodic box has no {what}: remove them or make the boundary walled"),
            ))
        };
        if !self.cushions.is_empty() {
            return refuse("cushion", "cushions");
        }
        if !self.pockets.is_empty() {
            return refuse("pocket", "pockets");
        }
        if self.sectors.is_some() {
            return refuse("sectors", "sectors (it runs on the event-list engine)");
        }
        let rmax = self.balls.iter().map(|b| b.radius).fold(0.0, f64::max);
        let need = MIN_SIDE_DIAMETERS * 2.0 * rmax;
        for (k, side) in [b.size.x, b.size.y].into_iter().enumerate() {
            if side < need {
                return Err(invalid(
                    format!("box.size[{}]", k + 1),
                    format!(
                        "{side} is too small for the largest ball (radius {rmax}): a periodic \
                         box needs at least {need} (3 diameters) along each side"
                    ),
                ));
            }
        }
        for (i, ball) in self.balls.iter().enumerate() {
            if ball.pocket.is_some() {
                return Err(invalid(
                    format!("ball[{}].pocket", i + 1),
                    "a periodic box has no pockets".into(),
                ));
            }
            let p = ball.position;
            let hi = b.hi();
            if !(p.x >= b.lo.x && p.x < hi.x && p.y >= b.lo.y && p.y < hi.y) {
                return Err(invalid(
                    format!("ball[{}].position", i + 1),
                    format!(
                        "Ball-{} at [{}, {}] is outside the periodic box [{}, {}) x [{}, {})",
                        i + 1,
                        p.x,
                        p.y,
                        b.lo.x,
                        hi.x,
                        b.lo.y,
                        hi.y
                    ),
                ));
            }
        }
        overlap_in_box(self, b)
    }
}

/// Refuses two balls that overlap, counting every image: the balls are bucketed in cells at
/// least a largest diameter wide, at least three along each side, and each is compared with
/// the nearest image of every ball in the 3 × 3 cells around it.
fn overlap_in_box(s: &Scenario, b: &PeriodicBox) -> Result<(), Invalid> {
    let rmax = s.balls.iter().map(|b| b.radius).fold(0.0, f64::max);
    let cells = |side: f64| ((side / (2.0 * rmax)).floor() as i64).clamp(3, 1 << 20);
    let (nx, ny) = (cells(b.size.x), cells(b.size.y));
    let cell = |p: Vec2| {
        let f =
            |x: f64, lo: f64, l: f64, n: i64| (((x - lo) / l * n as f64) as i64).clamp(0, n - 1);
        (f(p.y, b.lo.y, b.size.y, ny), f(p.x, b.lo.x, b.size.x, nx))
    };
    let mut sorted: Vec<((i64, i64), usize)> = s
        .balls
        .iter()
        .enumerate()
        .map(|(i, ball)| (cell(ball.position), i))
        .collect();
    sorted.sort_unstable();
    for (i, bi) in s.balls.iter().enumerate() {
        let (cy, cx) = cell(bi.position);
        for y in [cy - 1, cy, cy + 1] {
            for x in [cx - 1, cx, cx + 1] {
                let key = (y.rem_euclid(ny), x.rem_euclid(nx));
                let lo = sorted.partition_point(|e| e.0 < key);
                for &(k, j) in &sorted[lo..] {
                    if k != key {
                        break;
                    }
                    let bj = &s.balls[j];
                    let sigma = bi.radius + bj.radius;
                    let d = b.nearest(bj.position - bi.position);
                    if j > i && d.norm2() < sigma * sigma * (1.0 - 1e-12) {
                        return Err(invalid(
                            format!("ball[{}].position", j + 1),
                            format!(
                                "Ball-{} overlaps Ball-{} (or its image across the periodic box) \
                                 at t = 0 (centres {:.6} apart, radii sum {sigma})",
                                j + 1,
                                i + 1,
                                d.norm()
                            ),
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}
