//! Disks that grow while they move: the physics of Lubachevsky-Stillinger compression
//! (Lubachevsky and Stillinger 1990; Donev, Torquato and Stillinger 2005).
//!
//! Every radius grows in proportion, `r_i(t) = r_i · (1 + γ (t − t₀))` with `r_i` the radius at
//! `t₀`, so the ratios of the sizes stay fixed and the contact distance of a pair grows linearly:
//! `σ(t) = σ(t₀) + s (t − t₀)` with `s = (r_a + r_b) γ`. Two disks touch when
//! `|Δp + Δv τ| = σ + s τ`, the quadratic
//!
//! ```text
//!   (Δv² − s²) τ² + 2 (Δp·Δv − σ s) τ + (Δp² − σ²) = 0,
//! ```
//!
//! and they close on each other while its slope `Δp·Δv − σ s` is negative. Unlike rigid disks,
//! a pair that separates slower than its surfaces grow still meets (the leading coefficient is
//! then negative). At contact the normal component `u` of the relative velocity is reflected in
//! the frame of the growing surfaces, `u' = 2 s − u`, so the pair separates faster than it
//! grows; the collision conserves momentum and adds kinetic energy, which a thermostat takes
//! out between cycles.

use crate::geometry::{Trajectory, Vec2};
use crate::physics::Contact;

/// How radii grow: in proportion, at relative rate `rate` per unit time from time `from`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Growth {
    /// `γ`: each radius grows by `γ` times its value at `from` per unit time (not negative).
    pub rate: f64,
    /// `t₀`: the time the radii have their given values.
    pub from: f64,
}

impl Growth {
    /// The factor a radius given at `from` has grown by at `t`.
    #[inline]
    pub fn factor(&self, t: f64) -> f64 {
        1.0 + self.rate * (t - self.from)
    }

    /// When ball `a` (radius `ra` at `from`) touches the image of ball `b` (radius `rb` at
    /// `from`) that `shift` moves next to it, while they close on each other. `a` must be the
    /// ball with the lower index; the time is a function of the two trajectories alone.
    #[inline]
    pub fn contact(
        &self,
        a: &Trajectory,
        ra: f64,
        b: &Trajectory,
        rb: f64,
        shift: Vec2,
    ) -> Contact {
        let (tref, dp, dv) = crate::physics::relative(a, b, shift);
        let sum = ra + rb;
        approach(tref, dp, dv, sum * self.factor(tref), sum * self.rate)
    }

    /// Velocities after balls `a` (radius `ra` at `from`) and `b` collide at positions `pa` and
    /// `pb` (the touching image): the normal relative velocity `u` becomes `2 s − u`, the
    /// tangential components are kept, momentum is conserved. A pair that is not closing in the
    /// frame of its surfaces (a contact found by rounding) is pushed apart at `s`.
    #[inline]
    pub fn velocities(
        &self,
        (pa, va, ma, ra): (Vec2, Vec2, f64, f64),
        (pb, vb, mb, rb): (Vec2, Vec2, f64, f64),
    ) -> (Vec2, Vec2) {
        let s = (ra + rb) * self.rate;
        let c = pb - pa;
        let n = (1.0 / c.norm()) * c;
        let u = (vb - va).dot(n);
        let du = if u < s { 2.0 * (s - u) } else { s };
        let m = ma + mb;
        (va - (du * mb / m) * n, vb + (du * ma / m) * n)
    }
}

/// When two disks with separation `dp` and relative velocity `dv` at `tref`, contact distance
/// `sigma` then, growing at `s` per unit time, touch while closing.
#[inline]
fn approach(tref: f64, dp: Vec2, dv: Vec2, sigma: f64, s: f64) -> Contact {
    let b = dp.dot(dv) - sigma * s;
    let c = dp.norm2() - sigma * sigma;
    let a = dv.norm2() - s * s;
    let tau = if b < 0.0 {
        if c <= 0.0 {
            return Contact::Immediate;
        }
        let disc = b * b - a * c;
        if !(disc > 0.0 && disc.is_finite()) {
            return Contact::Never; // a miss (only when the pair outruns its growth)
        }
        c / (disc.sqrt() - b)
    } else if a < 0.0 {
        // separating now, but slower than the surfaces grow: the later root, or (overlapping
        // by rounding and never apart) the moment the separation stops
        let disc = b * b - a * c;
        if disc > 0.0 {
            (b + disc.sqrt()) / -a
        } else {
            b / -a
        }
    } else {
        return Contact::Never;
    };
    let t = tref + tau;
    if t > tref && t.is_finite() {
        Contact::At(t)
    } else if t.is_finite() {
        Contact::Immediate
    } else {
        Contact::Never
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn traj(x: f64, y: f64, vx: f64, vy: f64) -> Trajectory {
        Trajectory {
            position: Vec2::new(x, y),
            velocity: Vec2::new(vx, vy),
            t0: 0.0,
        }
    }

    #[test]
    fn disks_at_rest_meet_when_they_have_grown_to_touch() {
        // radii 1 and 1, centres 4 apart: they touch when each radius is 2, at t = 1 / rate
        let g = Growth {
            rate: 0.5,
            from: 0.0,
        };
        let (a, b) = (traj(0.0, 0.0, 0.0, 0.0), traj(4.0, 0.0, 0.0, 0.0));
        assert_eq!(g.contact(&a, 1.0, &b, 1.0, Vec2::ZERO), Contact::At(2.0));
        // across a side of a periodic box
        let far = traj(-6.0, 0.0, 0.0, 0.0);
        let shift = Vec2::new(10.0, 0.0);
        assert_eq!(g.contact(&a, 1.0, &far, 1.0, shift), Contact::At(2.0));
    }

    #[test]
    fn a_pair_separating_slower_than_it_grows_still_meets() {
        let g = Growth {
            rate: 1.0,
            from: 0.0,
        };
        // radii 1: contact distance 2 + 2 t; separation 3 + 0.5 t: meet at t = 1 / 1.5
        let (a, b) = (traj(0.0, 0.0, 0.0, 0.0), traj(3.0, 0.0, 0.5, 0.0));
        match g.contact(&a, 1.0, &b, 1.0, Vec2::ZERO) {
            Contact::At(t) => assert!((t - 1.0 / 1.5).abs() < 1e-15, "{t}"),
            other => panic!("{other:?}"),
        }
        // faster than it grows: never
        let fast = traj(3.0, 0.0, 3.0, 0.0);
        assert_eq!(g.contact(&a, 1.0, &fast, 1.0, Vec2::ZERO), Contact::Never);
    }

    #[test]
    fn no_growth_is_the_rigid_contact() {
        let g = Growth {
            rate: 0.0,
            from: 0.0,
        };
        let (a, b) = (traj(0.0, 0.0, 1.0, 0.0), traj(10.0, 0.0, -1.0, 0.0));
        assert_eq!(g.contact(&a, 1.0, &b, 1.0, Vec2::ZERO), Contact::At(4.0));
        let (va, vb) = g.velocities(
            (Vec2::new(5.0, 0.0), Vec2::new(1.0, 0.0), 1.0, 1.0),
            (Vec2::new(7.0, 0.0), Vec2::new(-1.0, 0.0), 1.0, 1.0),
        );
        assert_eq!((va, vb), (Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.0)));
    }

    #[test]
    fn touching_and_closing_is_immediate() {
        let g = Growth {
            rate: 0.1,
            from: 0.0,
        };
        // touching at rest: the growth closes them
        let (a, b) = (traj(0.0, 0.0, 0.0, 0.0), traj(2.0, 0.0, 0.0, 0.0));
        assert_eq!(g.contact(&a, 1.0, &b, 1.0, Vec2::ZERO), Contact::Immediate);
    }

    fn v2() -> impl Strategy<Value = Vec2> {
        (-10.0..10.0f64, -10.0..10.0f64).prop_map(|(x, y)| Vec2::new(x, y))
    }

    proptest! {
        #[test]
        fn contact_is_at_the_grown_distance_and_closing(
            va in v2(), vb in v2(), dx in -20.0..20.0f64, dy in -20.0..20.0f64,
            rate in 0.0..2.0f64, t0 in 0.0..3.0f64,
        ) {
            let g = Growth { rate, from: 0.0 };
            let a = Trajectory { position: Vec2::new(0.0, 0.0), velocity: va, t0 };
            let b = Trajectory { position: Vec2::new(dx, dy), velocity: vb, t0 };
            let (ra, rb) = (1.5, 0.5);
            prop_assume!((b.at(t0) - a.at(t0)).norm() > (ra + rb) * g.factor(t0) * (1.0 + 1e-9));
            if let Contact::At(t) = g.contact(&a, ra, &b, rb, Vec2::ZERO) {
                let sigma = (ra + rb) * g.factor(t);
                let d = b.at(t) - a.at(t);
                prop_assert!((d.norm() - sigma).abs() <= 1e-8 * (1.0 + (vb - va).norm() * t + sigma));
                // the gap closes at contact: the normal relative speed is below the growth
                let u = (vb - va).dot((1.0 / d.norm()) * d);
                prop_assert!(u <= (ra + rb) * rate + 1e-9 * (1.0 + (vb - va).norm()));
            }
        }

        #[test]
        fn collisions_conserve_momentum_and_separate_faster_than_growth(
            va in v2(), vb in v2(), dir in 0.0..std::f64::consts::TAU,
            ma in 0.1..10.0f64, mb in 0.1..10.0f64, rate in 0.0..2.0f64,
        ) {
            let g = Growth { rate, from: 0.0 };
            let (ra, rb) = (1.0, 1.4);
            let n = Vec2::new(dir.cos(), dir.sin());
            let (pa, pb) = (Vec2::new(1.0, 2.0), Vec2::new(1.0, 2.0) + (ra + rb) * n);
            let (a2, b2) = g.velocities((pa, va, ma, ra), (pb, vb, mb, rb));
            let p0 = ma * va + mb * vb;
            let p1 = ma * a2 + mb * b2;
            prop_assert!((p1 - p0).norm() <= 1e-12 * (1.0 + ma * va.norm() + mb * vb.norm()));
            let s = (ra + rb) * rate;
            prop_assert!((b2 - a2).dot(n) >= s - 1e-9 * (1.0 + (vb - va).norm()));
            // tangential components kept
            let t = n.perp_cw();
            prop_assert!((a2.dot(t) - va.dot(t)).abs() <= 1e-9 * (1.0 + va.norm()));
        }
    }
}
