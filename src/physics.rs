//! The physics every engine shares (thesis ch. 3): when two objects touch, and the velocities
//! after they do.
//!
//! Contact prediction returns a [`Contact`] relative to the later of the two position fixes, so
//! the answer depends only on the two trajectories and never on the caller's clock: every engine
//! that holds the same trajectories computes bit-identical times. Functions that take two balls
//! take them in canonical order (lower object index first); engines must keep that order.
//!
//! Numerics: the earlier root of `a τ² + 2 b τ + c = 0` is taken as `τ = c / (−b + √(b² − a c))`,
//! which never subtracts nearly equal numbers (the textbook `(−b − √…)/a` loses every digit when
//! `a c` is small: near-touching balls or nearly equal velocities).

use crate::geometry::{Trajectory, Vec2};

/// The answer of a contact prediction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Contact {
    /// The objects never touch while closing on each other.
    Never,
    /// They touch at this absolute time, strictly later than both position fixes.
    At(f64),
    /// They already touch (or overlap, by rounding) at the later position fix and are closing:
    /// the collision must happen now (thesis 5.3, the immediate collision).
    Immediate,
}

impl Contact {
    /// The contact time, if any, with `now` standing for an immediate contact.
    pub fn time(self, now: f64) -> Option<f64> {
        match self {
            Contact::Never => None,
            Contact::At(t) => Some(t),
            Contact::Immediate => Some(now),
        }
    }
}

/// Relative tolerance on the segment parameter of a face contact, so that a ball reaching the very
/// end of a cushion is caught by the face or by the corner there, never by neither.
const FACE_END_TOLERANCE: f64 = 1e-12;

/// When does a moving disk meet another, given their separation `dp = p_b − p_a` and relative
/// velocity `dv = v_b − v_a` at reference time `tref`, with contact distance `sigma`?
#[inline]
fn approach(tref: f64, dp: Vec2, dv: Vec2, sigma: f64) -> Contact {
    let b = dp.dot(dv);
    if b >= 0.0 {
        return Contact::Never; // not closing
    }
    let c = dp.norm2() - sigma * sigma;
    if c <= 0.0 {
        return Contact::Immediate;
    }
    let a = dv.norm2();
    let disc = b * b - a * c;
    // a miss, a graze that exchanges no momentum, or speeds so large that the squares overflow
    // (NaN): never an instant collision between balls that are apart
    if disc.is_nan() || disc.is_infinite() || disc <= 0.0 {
        return Contact::Never;
    }
    let tau = c / (disc.sqrt() - b);
    let t = tref + tau;
    if t > tref {
        Contact::At(t)
    } else {
        Contact::Immediate
    }
}

/// When ball `a` (radius `ra`) touches ball `b` (radius `rb`) while they close on each other
/// (thesis 3.1.1). `a` must be the ball with the lower object index.
#[inline]
pub fn ball_ball_contact(a: &Trajectory, ra: f64, b: &Trajectory, rb: f64) -> Contact {
    let tref = a.t0.max(b.t0);
    let dp = b.at(tref) - a.at(tref);
    approach(tref, dp, b.velocity - a.velocity, ra + rb)
}

/// [`ball_ball_contact`] of ball `a` with the image of ball `b` moved by `shift` (whole sides of
/// a periodic box): the separation at the later fix is shifted once, so the time is a function
/// of the two trajectories and the image alone.
#[inline]
pub fn ball_ball_contact_across(
    a: &Trajectory,
    ra: f64,
    b: &Trajectory,
    rb: f64,
    shift: Vec2,
) -> Contact {
    let (tref, dp, dv) = relative(a, b, shift);
    approach(tref, dp, dv, ra + rb)
}

/// The later of two trajectories' fixes, and there the separation from `a` to the image of `b`
/// that `shift` moves (once), and the velocity of `b` relative to `a`: what every prediction of
/// a pair starts from.
#[inline]
pub fn relative(a: &Trajectory, b: &Trajectory, shift: Vec2) -> (f64, Vec2, Vec2) {
    let tref = a.t0.max(b.t0);
    (
        tref,
        (b.at(tref) - a.at(tref)) + shift,
        b.velocity - a.velocity,
    )
}

/// When a ball of radius `r` touches the fixed point `c`, a pocket's corner (thesis 3.1.4).
#[inline]
pub fn ball_corner_contact(ball: &Trajectory, r: f64, c: Vec2) -> Contact {
    approach(ball.t0, c - ball.position, -ball.velocity, r)
}

/// When a ball of radius `r` touches the face of the segment `from` → `to` from the table side
/// (the right going `from` → `to`), moving into it, with the contact point on the segment
/// (thesis 3.1.2). With `r = 0` this is the crossing of a pocket line (thesis 3.1.3).
#[inline]
pub fn ball_face_contact(ball: &Trajectory, r: f64, from: Vec2, to: Vec2) -> Contact {
    let l = to - from;
    let len2 = l.norm2();
    let n = l.perp_cw(); // into the table, length |l|
    let vn = ball.velocity.dot(n);
    if vn >= 0.0 {
        return Contact::Never;
    }
    let rel = ball.position - from;
    let len = len2.sqrt();
    let gap = rel.dot(n) - r * len; // |l| times the distance still to go
    if rel.dot(n) < 0.0 {
        return Contact::Never; // centre behind the face: the ball is not on this side
    }
    let (tau, immediate) = if gap <= 0.0 {
        (0.0, true)
    } else {
        (gap / -vn, false)
    };
    let along = (rel + tau * ball.velocity).dot(l) / len2;
    if !(-FACE_END_TOLERANCE..=1.0 + FACE_END_TOLERANCE).contains(&along) {
        return Contact::Never;
    }
    let t = ball.t0 + tau;
    if immediate || t <= ball.t0 {
        Contact::Immediate
    } else {
        Contact::At(t)
    }
}

/// Velocities after two balls collide (thesis 3.4), for any masses: the components along the
/// line of centres `c = p_b − p_a` change as in a head-on elastic collision, the rest is kept.
/// `a` is the lower-indexed ball; positions are at the instant of contact.
#[inline]
pub fn ball_ball_velocities(
    pa: Vec2,
    va: Vec2,
    ma: f64,
    pb: Vec2,
    vb: Vec2,
    mb: f64,
) -> (Vec2, Vec2) {
    let c = pb - pa;
    let closing = (va - vb).dot(c) / c.norm2();
    let (ka, kb) = if ma == mb {
        (1.0, 1.0)
    } else {
        let m = ma + mb;
        (2.0 * mb / m, 2.0 * ma / m)
    };
    (va - (ka * closing) * c, vb + (kb * closing) * c)
}

/// Velocity after a bounce off a face along `l` (thesis 3.2): the angle of reflection equals the
/// angle of incidence and the speed is multiplied by `elasticity`.
#[inline]
pub fn reflect(v: Vec2, l: Vec2, elasticity: f64) -> Vec2 {
    let p = l.perp_cw();
    let r = v - (2.0 * v.dot(p) / p.norm2()) * p;
    if elasticity == 1.0 {
        r
    } else {
        elasticity * r
    }
}

/// Velocity after hitting the cushion `from` → `to` (thesis 3.2).
#[inline]
pub fn cushion_velocity(v: Vec2, from: Vec2, to: Vec2, elasticity: f64) -> Vec2 {
    reflect(v, to - from, elasticity)
}

/// Velocity after a ball centred at `p` hits the corner at `c` (thesis 3.3): a bounce off the line
/// through the contact point perpendicular to `p − c`.
#[inline]
pub fn corner_velocity(v: Vec2, p: Vec2, c: Vec2, elasticity: f64) -> Vec2 {
    let n = p - c;
    reflect(v, Vec2::new(-n.y, n.x), elasticity)
}

/// Kinetic energy `m |v|² / 2`.
#[inline]
pub fn kinetic_energy(mass: f64, v: Vec2) -> f64 {
    0.5 * mass * v.norm2()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn traj(x: f64, y: f64, vx: f64, vy: f64, t0: f64) -> Trajectory {
        Trajectory {
            position: Vec2::new(x, y),
            velocity: Vec2::new(vx, vy),
            t0,
        }
    }

    #[test]
    fn head_on_balls_meet_when_surfaces_touch() {
        let a = traj(0.0, 0.0, 1.0, 0.0, 0.0);
        let b = traj(10.0, 0.0, -1.0, 0.0, 0.0);
        assert_eq!(ball_ball_contact(&a, 1.0, &b, 1.0), Contact::At(4.0));
        // separating balls never meet
        let c = traj(10.0, 0.0, 2.0, 0.0, 0.0);
        assert_eq!(ball_ball_contact(&a, 1.0, &c, 1.0), Contact::Never);
    }

    #[test]
    fn touching_and_closing_is_immediate() {
        let a = traj(0.0, 0.0, 1.0, 0.0, 2.0);
        let b = traj(2.0, 0.0, 0.0, 0.0, 1.0);
        assert_eq!(ball_ball_contact(&a, 1.0, &b, 1.0), Contact::Immediate);
        let away = traj(0.0, 0.0, -1.0, 0.0, 2.0);
        assert_eq!(ball_ball_contact(&away, 1.0, &b, 1.0), Contact::Never);
    }

    #[test]
    fn overflowing_speeds_are_never_an_instant_collision() {
        let a = traj(0.0, 0.0, 1e200, 0.0, 0.0);
        let b = traj(180.0, 0.0, -1e200, 0.0, 0.0);
        assert_ne!(ball_ball_contact(&a, 10.0, &b, 10.0), Contact::Immediate);
    }

    #[test]
    fn exact_graze_exchanges_nothing() {
        let a = traj(0.0, 0.0, 1.0, 0.0, 0.0);
        let b = traj(10.0, 2.0, 0.0, 0.0, 0.0);
        assert_eq!(ball_ball_contact(&a, 1.0, &b, 1.0), Contact::Never);
    }

    #[test]
    fn near_touching_time_has_no_cancellation() {
        // A gap of about 1e-10 closed at speed 1, head on and at a glancing angle. The gap itself
        // is only known to an ulp of the positions (4e-16), so that is the best any formula can
        // do; the textbook root (-b - sqrt(b^2 - ac)) / a is off by far more at the glance.
        let a = traj(0.0, 0.0, 1.0, 0.0, 0.0);
        let b = traj(2.0 + 1e-10, 0.0, 0.0, 0.0, 0.0);
        let gap = (2.0 + 1e-10) - 2.0;
        match ball_ball_contact(&a, 1.0, &b, 1.0) {
            Contact::At(t) => assert!((t - gap).abs() < 2e-15, "t = {t}"),
            other => panic!("{other:?}"),
        }
        // fast relative speed, tiny gap: tau = c / (sqrt(disc) - b) keeps its digits
        let fast = traj(0.0, 0.0, 1e6, 0.0, 0.0);
        match ball_ball_contact(&fast, 1.0, &b, 1.0) {
            Contact::At(t) => assert!((t - gap / 1e6).abs() < 2e-21, "t = {t}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn cushion_contact_and_bounce() {
        // left side going up: table on the right (+x)
        let (from, to) = (Vec2::new(0.0, 0.0), Vec2::new(0.0, 100.0));
        let ball = traj(50.0, 50.0, -10.0, 5.0, 1.0);
        assert_eq!(ball_face_contact(&ball, 10.0, from, to), Contact::At(5.0));
        let v = cushion_velocity(ball.velocity, from, to, 1.0);
        assert_eq!(v, Vec2::new(10.0, 5.0));
        let v = cushion_velocity(ball.velocity, from, to, 0.5);
        assert_eq!(v, Vec2::new(5.0, 2.5));
        // moving away, behind, or past the end: never
        assert_eq!(
            ball_face_contact(&traj(50.0, 50.0, 10.0, 0.0, 0.0), 10.0, from, to),
            Contact::Never
        );
        assert_eq!(
            ball_face_contact(&traj(-50.0, 50.0, -10.0, 0.0, 0.0), 10.0, from, to),
            Contact::Never
        );
        assert_eq!(
            ball_face_contact(&traj(50.0, 150.0, -10.0, 0.0, 0.0), 10.0, from, to),
            Contact::Never
        );
        // resting against it and pushed in: immediate
        assert_eq!(
            ball_face_contact(&traj(10.0, 50.0, -1.0, 0.0, 3.0), 10.0, from, to),
            Contact::Immediate
        );
        // sliding along it while touching: never
        assert_eq!(
            ball_face_contact(&traj(10.0, 50.0, 0.0, 1.0, 3.0), 10.0, from, to),
            Contact::Never
        );
    }

    #[test]
    fn pocket_is_a_zero_radius_face() {
        let (from, to) = (Vec2::new(270.0, 400.0), Vec2::new(330.0, 400.0));
        // top side runs left to right: the table is below
        let ball = traj(300.0, 300.0, 0.0, 100.0, 0.0);
        assert_eq!(ball_face_contact(&ball, 0.0, to, from), Contact::Never);
        assert_eq!(ball_face_contact(&ball, 0.0, from, to), Contact::At(1.0));
    }

    #[test]
    fn corner_hit_head_on_reverses() {
        let ball = traj(0.0, 0.0, 1.0, 0.0, 0.0);
        let c = Vec2::new(10.0, 0.0);
        assert_eq!(ball_corner_contact(&ball, 2.0, c), Contact::At(8.0));
        let p = ball.at(8.0);
        assert_eq!(
            corner_velocity(ball.velocity, p, c, 1.0),
            Vec2::new(-1.0, 0.0)
        );
    }

    #[test]
    fn equal_masses_exchange_head_on() {
        let (va, vb) = ball_ball_velocities(
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            1.0,
            Vec2::new(2.0, 0.0),
            Vec2::new(-1.0, 0.0),
            1.0,
        );
        assert_eq!((va, vb), (Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.0)));
    }

    fn v2() -> impl Strategy<Value = Vec2> {
        (-100.0..100.0f64, -100.0..100.0f64).prop_map(|(x, y)| Vec2::new(x, y))
    }

    proptest! {
        #[test]
        fn ball_ball_conserves_momentum_and_energy(
            va in v2(), vb in v2(), dir in 0.0..std::f64::consts::TAU,
            ma in 0.01..100.0f64, mb in 0.01..100.0f64, ra in 0.1..10.0f64, rb in 0.1..10.0f64,
        ) {
            let pa = Vec2::new(1.0, 2.0);
            let pb = pa + (ra + rb) * Vec2::new(dir.cos(), dir.sin());
            let (a2, b2) = ball_ball_velocities(pa, va, ma, pb, vb, mb);
            let p0 = ma * va + mb * vb;
            let p1 = ma * a2 + mb * b2;
            let scale = ma * va.norm() + mb * vb.norm() + 1e-300;
            prop_assert!((p1 - p0).norm() <= 1e-12 * scale);
            let e0 = kinetic_energy(ma, va) + kinetic_energy(mb, vb);
            let e1 = kinetic_energy(ma, a2) + kinetic_energy(mb, b2);
            prop_assert!((e1 - e0).abs() <= 1e-12 * e0.max(1e-300));
            // the tangential components are untouched
            let t = (pb - pa).perp_cw();
            prop_assert!((a2.dot(t) - va.dot(t)).abs() <= 1e-9 * (1.0 + va.norm()) * t.norm());
        }

        #[test]
        fn ball_ball_swap_symmetry(
            va in v2(), vb in v2(), dx in -50.0..50.0f64, dy in -50.0..50.0f64,
            t0a in 0.0..5.0f64, t0b in 0.0..5.0f64,
        ) {
            let a = Trajectory { position: Vec2::new(0.0, 0.0), velocity: va, t0: t0a };
            let b = Trajectory { position: Vec2::new(dx, dy), velocity: vb, t0: t0b };
            prop_assert_eq!(ball_ball_contact(&a, 1.0, &b, 2.0), ball_ball_contact(&b, 2.0, &a, 1.0));
            let (a2, b2) = ball_ball_velocities(a.position, va, 1.0, b.position, vb, 1.0);
            let (b3, a3) = ball_ball_velocities(b.position, vb, 1.0, a.position, va, 1.0);
            prop_assert!((a2 - a3).norm() <= 1e-9 * (1.0 + va.norm() + vb.norm()));
            prop_assert!((b2 - b3).norm() <= 1e-9 * (1.0 + va.norm() + vb.norm()));
        }

        #[test]
        fn predicted_contact_is_at_touching_distance(
            va in v2(), vb in v2(), dx in -50.0..50.0f64, dy in -50.0..50.0f64,
        ) {
            let a = Trajectory { position: Vec2::new(0.0, 0.0), velocity: va, t0: 0.0 };
            let b = Trajectory { position: Vec2::new(dx, dy), velocity: vb, t0: 0.0 };
            let (ra, rb) = (1.5, 0.5);
            if let Contact::At(t) = ball_ball_contact(&a, ra, &b, rb) {
                let d = (b.at(t) - a.at(t)).norm();
                prop_assert!((d - (ra + rb)).abs() <= 1e-9 * (1.0 + (va - vb).norm() * t));
                prop_assert!((b.at(t) - a.at(t)).dot(vb - va) < 0.0);
            }
        }

        #[test]
        fn cushion_reflection_law_and_elasticity(
            v in v2(), l in v2(), e in 0.0..=1.0f64,
        ) {
            prop_assume!(l.norm() > 1e-3);
            let out = reflect(v, l, e);
            prop_assert!((out.norm() - e * v.norm()).abs() <= 1e-9 * (1.0 + v.norm()));
            let lh = (1.0 / l.norm()) * l;
            let n = lh.perp_cw();
            prop_assert!((out.dot(lh) - e * v.dot(lh)).abs() <= 1e-9 * (1.0 + v.norm()));
            prop_assert!((out.dot(n) + e * v.dot(n)).abs() <= 1e-9 * (1.0 + v.norm()));
        }

        #[test]
        fn corner_bounce_reverses_normal_component(
            v in v2(), dir in 0.0..std::f64::consts::TAU, e in 0.0..=1.0f64,
        ) {
            let c = Vec2::new(3.0, 4.0);
            let n = Vec2::new(dir.cos(), dir.sin());
            let p = c + 2.0 * n;
            let out = corner_velocity(v, p, c, e);
            prop_assert!((out.dot(n) + e * v.dot(n)).abs() <= 1e-9 * (1.0 + v.norm()));
            prop_assert!((out.norm() - e * v.norm()).abs() <= 1e-9 * (1.0 + v.norm()));
        }

        #[test]
        fn face_contact_touches_at_radius(
            x in 1.0..99.0f64, y in 11.0..99.0f64, v in v2(), r in 0.0..10.0f64,
        ) {
            // bottom side runs right to left: the table is above
            let (from, to) = (Vec2::new(100.0, 0.0), Vec2::new(0.0, 0.0));
            let ball = Trajectory { position: Vec2::new(x, y), velocity: v, t0: 0.0 };
            if let Contact::At(t) = ball_face_contact(&ball, r, from, to) {
                let p = ball.at(t);
                prop_assert!((p.y - r).abs() <= 1e-9 * (1.0 + y));
                prop_assert!(p.x >= -1e-9 && p.x <= 100.0 + 1e-9);
                prop_assert!(v.y < 0.0);
            }
        }
    }
}
