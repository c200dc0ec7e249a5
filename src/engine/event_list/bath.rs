//! The event list with Andersen's thermostat (see [`crate::thermostat`]): each kick is a
//! velocity change of one disk at a key of its own, run in its place among the events like the
//! reversal and the frames, after which the disk predicts its events anew and the observers
//! hear of it.

use super::EventList;
use crate::engine::{Observer, RunError};
use crate::vtime::{Key, BATH, DISPLAY};

impl EventList {
    /// Whether the thermostat's next kick comes, by `until`, before the first queued event
    /// (`first`), the reversal and the next frame.
    pub(super) fn bath_first(&self, first: Option<u32>, until: f64) -> bool {
        let Some(b) = &self.bath else {
            return false;
        };
        if b.next > until {
            return false;
        }
        let key = Key::at(b.next, BATH);
        first.is_none_or(|i| key < self.own[i as usize].queued)
            && self.reversal.as_ref().is_none_or(|r| key < *r)
            && self
                .span
                .frame(self.frames)
                .is_none_or(|f| key < Key::at(f, DISPLAY))
    }

    /// Gives the disk of the thermostat's next kick its new velocity (a disk in a pocket keeps
    /// still), and tells `obs`.
    pub(super) fn kick(&mut self, obs: &mut dyn Observer) -> Result<(), RunError> {
        let bath = self.bath.as_mut().expect("a thermostat");
        let t = bath.next;
        let kick = bath.kick();
        let i = kick.disk;
        self.now = t;
        if self.pocket[i as usize].is_some() {
            return Ok(());
        }
        let velocity = (1.0 / self.own[i as usize].mass.sqrt()) * kick.unit_velocity;
        self.set_velocity(i, &Key::at(t, BATH), velocity);
        self.predict(i);
        obs.on_kick(i, t, self)
    }
}
