//! Plane geometry: a small 2-D vector type and the straight-line trajectory of thesis 3.1.
//!
//! Lengths are in the scenario's length unit, times in its time unit; nothing here knows of
//! engines or objects.

use serde::{Deserialize, Serialize};
use std::ops::{Add, Mul, Neg, Sub};

/// A 2-D vector or point, in the scenario's length unit (or length per time for velocities).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(from = "[f64; 2]", into = "[f64; 2]")]
pub struct Vec2 {
    /// The x component.
    pub x: f64,
    /// The y component.
    pub y: f64,
}

impl Vec2 {
    /// The zero vector.
    pub const ZERO: Vec2 = Vec2 { x: 0.0, y: 0.0 };

    /// Builds a vector from its components.
    #[inline]
    pub const fn new(x: f64, y: f64) -> Vec2 {
        Vec2 { x, y }
    }

    /// The dot product `self · o`.
    #[inline]
    pub fn dot(self, o: Vec2) -> f64 {
        self.x * o.x + self.y * o.y
    }

    /// The z component of the cross product `self × o`.
    #[inline]
    pub fn cross(self, o: Vec2) -> f64 {
        self.x * o.y - self.y * o.x
    }

    /// The squared length.
    #[inline]
    pub fn norm2(self) -> f64 {
        self.dot(self)
    }

    /// The length.
    #[inline]
    pub fn norm(self) -> f64 {
        self.norm2().sqrt()
    }

    /// This vector turned a quarter turn clockwise: `(y, -x)`.
    #[inline]
    pub fn perp_cw(self) -> Vec2 {
        Vec2::new(self.y, -self.x)
    }

    /// Whether both components are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
}

impl From<[f64; 2]> for Vec2 {
    fn from(a: [f64; 2]) -> Vec2 {
        Vec2::new(a[0], a[1])
    }
}

impl From<Vec2> for [f64; 2] {
    fn from(v: Vec2) -> [f64; 2] {
        [v.x, v.y]
    }
}

impl Add for Vec2 {
    type Output = Vec2;
    #[inline]
    fn add(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x + o.x, self.y + o.y)
    }
}

impl Sub for Vec2 {
    type Output = Vec2;
    #[inline]
    fn sub(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x - o.x, self.y - o.y)
    }
}

impl Neg for Vec2 {
    type Output = Vec2;
    #[inline]
    fn neg(self) -> Vec2 {
        Vec2::new(-self.x, -self.y)
    }
}

impl Mul<Vec2> for f64 {
    type Output = Vec2;
    #[inline]
    fn mul(self, v: Vec2) -> Vec2 {
        Vec2::new(self * v.x, self * v.y)
    }
}

/// A straight-line motion fixed at time `t0`: `s(t) = position + (t - t0) · velocity`.
///
/// The thesis writes it `s(t) = D + t·v` with `D = s(t0) - t0·v` (3.1); we keep the position fix
/// itself, which loses no precision when `t0` is large.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Trajectory {
    /// Position at `t0` (length).
    pub position: Vec2,
    /// Velocity (length per time).
    pub velocity: Vec2,
    /// Time of the position fix.
    pub t0: f64,
}

impl Trajectory {
    /// The position at time `t`.
    #[inline]
    pub fn at(&self, t: f64) -> Vec2 {
        self.position + (t - self.t0) * self.velocity
    }
}

/// The whole number nearest `x` (halves away from zero), for `|x|` below 2^62: by a cast, not
/// `f64::round`, which is a library call on x86-64 without SSE4.1.
#[inline]
pub fn nearest_whole(x: f64) -> f64 {
    ((x.abs() + 0.5) as i64 as f64).copysign(x)
}

/// A rectangular periodic box: the plane folded onto a torus, so that a centre leaving through
/// one side comes back through the opposite one. Wrapped positions lie in `[lo, lo + size)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PeriodicBox {
    /// The lower-left corner (length).
    pub lo: Vec2,
    /// The sides along x and y (length), both positive.
    pub size: Vec2,
}

impl PeriodicBox {
    /// The upper-right corner (length).
    pub fn hi(&self) -> Vec2 {
        self.lo + self.size
    }

    /// The whole numbers of sides, along x and y, that the separation `d` exceeds its minimum
    /// image by (rounded to the nearest; a separation of exactly half a side, which has two
    /// nearest images, may go either way).
    #[inline]
    pub fn images(&self, d: Vec2) -> (f64, f64) {
        (
            nearest_whole(d.x / self.size.x),
            nearest_whole(d.y / self.size.y),
        )
    }

    /// The translation by `m` sides along x and y.
    #[inline]
    pub fn shift(&self, m: (f64, f64)) -> Vec2 {
        Vec2::new(m.0 * self.size.x, m.1 * self.size.y)
    }

    /// The minimum image of the separation `d`: the shortest of `d` moved by whole sides.
    #[inline]
    pub fn nearest(&self, d: Vec2) -> Vec2 {
        d - self.shift(self.images(d))
    }

    /// The point `p` moved by whole sides into the box.
    pub fn wrap(&self, p: Vec2) -> Vec2 {
        let fold = |x: f64, lo: f64, l: f64| {
            let w = lo + (x - lo).rem_euclid(l);
            // rounding may land a point just below `lo` on `lo + l` itself
            if w >= lo + l {
                lo
            } else {
                w
            }
        };
        Vec2::new(
            fold(p.x, self.lo.x, self.size.x),
            fold(p.y, self.lo.y, self.size.y),
        )
    }

    /// Its area (length squared).
    pub fn area(&self) -> f64 {
        self.size.x * self.size.y
    }
}

/// The squared distance from point `p` to the segment from `a` to `b`.
pub fn segment_distance2(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let ab = b - a;
    let len2 = ab.norm2();
    let s = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + s * ab)).norm2()
}

/// The squared distance from point `p` to the axis-aligned rectangle `[lo, hi]` (0 inside).
pub fn rect_distance2(p: Vec2, lo: Vec2, hi: Vec2) -> f64 {
    let dx = (lo.x - p.x).max(0.0).max(p.x - hi.x);
    let dy = (lo.y - p.y).max(0.0).max(p.y - hi.y);
    dx * dx + dy * dy
}

/// The squared distance between the segment `a`–`b` and the axis-aligned rectangle `[lo, hi]`.
pub fn segment_rect_distance2(a: Vec2, b: Vec2, lo: Vec2, hi: Vec2) -> f64 {
    if segment_crosses_rect(a, b, lo, hi) {
        return 0.0;
    }
    let corners = [lo, Vec2::new(hi.x, lo.y), hi, Vec2::new(lo.x, hi.y)];
    let mut best = rect_distance2(a, lo, hi).min(rect_distance2(b, lo, hi));
    for c in corners {
        best = best.min(segment_distance2(c, a, b));
    }
    best
}

/// Whether the segment `a`–`b` meets the rectangle `[lo, hi]` (Liang–Barsky clipping).
fn segment_crosses_rect(a: Vec2, b: Vec2, lo: Vec2, hi: Vec2) -> bool {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d.x, a.x - lo.x),
        (d.x, hi.x - a.x),
        (-d.y, a.y - lo.y),
        (d.y, hi.y - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return false;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    t0 <= t1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trajectory_moves_linearly() {
        let tr = Trajectory {
            position: Vec2::new(1.0, 2.0),
            velocity: Vec2::new(3.0, -1.0),
            t0: 2.0,
        };
        assert_eq!(tr.at(4.0), Vec2::new(7.0, 0.0));
    }

    #[test]
    fn distances() {
        let (a, b) = (Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0));
        assert_eq!(segment_distance2(Vec2::new(5.0, 3.0), a, b), 9.0);
        assert_eq!(segment_distance2(Vec2::new(13.0, 4.0), a, b), 25.0);
        let (lo, hi) = (Vec2::new(0.0, 0.0), Vec2::new(1.0, 1.0));
        assert_eq!(rect_distance2(Vec2::new(0.5, 0.5), lo, hi), 0.0);
        assert_eq!(rect_distance2(Vec2::new(4.0, 5.0), lo, hi), 25.0);
        assert_eq!(
            segment_rect_distance2(Vec2::new(-1.0, 0.5), Vec2::new(2.0, 0.5), lo, hi),
            0.0
        );
        assert_eq!(
            segment_rect_distance2(Vec2::new(3.0, -5.0), Vec2::new(3.0, 5.0), lo, hi),
            4.0
        );
    }
}
