//! The event list with growing disks, for Lubachevsky-Stillinger compression (see
//! [`crate::growth`]): in a periodic box only, every radius grows in proportion while the disks
//! fly, pairs are predicted with [`Growth::contact`] and collide by [`Growth::velocities`].
//!
//! The grid's cells are laid out for the disks as they will have grown by the end of the run, so
//! a run with growth ends at that time at the latest; a compression runs in cycles, each a new
//! engine over the state the last one left.

use super::{Best, EventList, Options, Slot};
use crate::engine::RunError;
use crate::geometry::Vec2;
use crate::growth::Growth;
use crate::scenario::{Scenario, MIN_SIDE_DIAMETERS};

impl EventList {
    /// The engine over a validated scenario in a periodic box whose disks grow by `growth`
    /// until `until`; its runs end there at the latest. Refused (as bad input) on a walled
    /// table, with a reversal, or when the disks grown by `until` would not fit three abreast
    /// across the box.
    pub fn growing(
        s: &Scenario,
        opts: Options,
        growth: Growth,
        until: f64,
    ) -> Result<EventList, RunError> {
        let refuse = |why: String| Err(RunError::Input(format!("growing disks: {why}")));
        let Some(period) = s.periodic else {
            return refuse("they need a periodic box (no cushions or pockets)".into());
        };
        if opts.span.reverse_at.is_some() {
            return refuse("a run with growth cannot be reversed".into());
        }
        if !(growth.rate.is_finite() && growth.rate >= 0.0) {
            return refuse(format!(
                "the rate must be a number not below 0, got {}",
                growth.rate
            ));
        }
        if !(until.is_finite() && until >= opts.span.start) {
            return refuse(format!(
                "they must grow until a time after the start, got {until}"
            ));
        }
        let rmax = s.balls.iter().map(|b| b.radius).fold(0.0, f64::max);
        let grown = rmax * growth.factor(until);
        if MIN_SIDE_DIAMETERS * 2.0 * grown > period.size.x.min(period.size.y) {
            return refuse(format!(
                "grown to radius {grown} by t = {until}, they would not fit three abreast across \
                 the box"
            ));
        }
        Ok(EventList::build(s, opts, Some((growth, until))))
    }

    /// Offers the contact of ball `i` (slot `b`) with the image of ball `j` that `shift` moves
    /// next to it, both growing by `growth`, to `best`.
    #[inline]
    pub(super) fn offer_grown(
        &self,
        i: u32,
        b: &Slot,
        j: u32,
        shift: Vec2,
        growth: Growth,
        best: &mut Best,
    ) {
        let o = &self.slots[j as usize];
        let contact = if i < j {
            growth.contact(&b.traj, b.radius, &o.traj, o.radius, shift)
        } else {
            growth.contact(&o.traj, o.radius, &b.traj, b.radius, -shift)
        };
        self.offer_contact(i, j, o.counter, contact, best);
    }

    /// Ball `i`'s radius at time `t`: as given, unless the disks grow.
    #[inline]
    pub(super) fn radius_at(&self, i: u32, t: f64) -> f64 {
        let r = self.slots[i as usize].radius;
        self.growth.map_or(r, |g| r * g.factor(t))
    }
}
