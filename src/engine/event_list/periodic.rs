//! The event list in a periodic box.
//!
//! A ball's trajectory is not wrapped while it flies: between two velocity changes it runs on
//! in the plane, and its grid cell (which does wrap around the box) is kept by its crossings as
//! in a walled box. A pair is tested with the image of the partner that sits in the cell next
//! to the ball's own: the whole sides that bring it there are worked out from the two positions
//! and the cells' offset, and added to the separation once (see
//! [`physics::ball_ball_contact_across`](crate::physics::ball_ball_contact_across)), so that a
//! prediction depends on the two trajectories and the image alone, whichever ball makes it.
//! With at least three cells along each side, a cell's neighbours are each one image of one
//! cell, and two touching disks are in neighbouring cells through exactly one image.
//!
//! When its velocity changes, a ball's new trajectory starts from its position taken back into
//! the box by the sides it has travelled, and those sides are added to its count of sides
//! crossed, from which its unwrapped position follows.

use super::{EventList, Near, Shifts, NOT_ON_TABLE};
use crate::geometry::{nearest_whole, PeriodicBox, Vec2};
use pdes_kernel::prefetch::prefetch;

impl EventList {
    /// The box; only called in a periodic box.
    fn period(&self) -> PeriodicBox {
        self.period.expect("a periodic box")
    }

    /// The whole sides along x and y by which ball `i`'s trajectory at time `t` lies beyond the
    /// box image of its cell (its centre at `t` being in that cell, up to rounding).
    pub(super) fn sides_out(&self, i: u32, t: f64) -> (f64, f64) {
        let slot = &self.slots[i as usize];
        let centre = self.grid.cell_centre(slot.cell);
        self.period().images(slot.traj.at(t) - centre)
    }

    /// Ball `i`'s position `p` at time `t`, moved by whole sides into the box image of its cell;
    /// the sides are added to its unwrapped offset.
    pub(super) fn rebased(&mut self, i: u32, p: Vec2, t: f64) -> Vec2 {
        if self.slots[i as usize].cell == NOT_ON_TABLE {
            return p;
        }
        let out = self.sides_out(i, t);
        let total = &mut self.unwrap[i as usize];
        *total = (total.0 + out.0, total.1 + out.1);
        p - self.period().shift(out)
    }

    /// The balls in the 3 × 3 cells around ball `i`, each with the shift that moves it to its
    /// image next to `i`.
    pub(super) fn gather_images(&self, i: u32, near: &mut Near, shifts: &mut Shifts) {
        let cell = self.slots[i as usize].cell;
        if cell != NOT_ON_TABLE {
            let here = self.slots[i as usize].traj.at(self.now);
            self.grid.for_each_near_image(cell, |j, offset| {
                if j != i {
                    prefetch(&self.slots[j as usize]);
                    near.push(j);
                    shifts.push(self.image_shift(here, j, offset));
                }
            });
        }
    }

    /// The balls that come into ball `i`'s 3 × 3 block as its centre moves from cell `from` to
    /// `to`, each with the shift that moves it to its image next to `i`.
    pub(super) fn entering_images(
        &self,
        i: u32,
        (from, to): (u32, u32),
        near: &mut Near,
        shifts: &mut Shifts,
    ) {
        let here = self.slots[i as usize].traj.at(self.now);
        self.grid.for_each_entering_image(from, to, |j, offset| {
            prefetch(&self.slots[j as usize]);
            near.push(j);
            shifts.push(self.image_shift(here, j, offset));
        });
    }

    /// The shift (whole sides) that moves ball `j` to its image in the cell `offset` cells away
    /// from the cell of a ball now at `here`: the offset is below a third of the box, so the
    /// nearest whole number of sides is that image's.
    #[inline]
    fn image_shift(&self, here: Vec2, j: u32, (dx, dy): (i32, i32)) -> Vec2 {
        let (size, cell) = (self.period().size, self.grid.cell_size());
        let target = here + Vec2::new(f64::from(dx) * cell.x, f64::from(dy) * cell.y);
        let d = target - self.slots[j as usize].traj.at(self.now);
        // the offset is a whole number of sides and less than a third of one: multiplying by
        // the sides' inverses rounds to the same whole numbers as dividing would
        Vec2::new(
            nearest_whole(d.x * self.inverse_size.x) * size.x,
            nearest_whole(d.y * self.inverse_size.y) * size.y,
        )
    }

    /// In a periodic box, every ball's image at time `t` (not before the last event): the whole
    /// sides from its position in the box to its unwrapped one; empty in a walled box.
    pub fn images_at(&self, t: f64) -> Vec<[i64; 2]> {
        let Some(b) = self.period else {
            return Vec::new();
        };
        self.unwrapped_at(t)
            .into_iter()
            .zip(&self.slots)
            .map(|(u, slot)| {
                let (x, y) = b.images(u - b.wrap(slot.traj.at(t)));
                [x as i64, y as i64]
            })
            .collect()
    }

    /// Every ball's unwrapped centre at time `t` (not before the last event): its position had
    /// it never been taken back into the box. In a walled box, its centre.
    pub fn unwrapped_at(&self, t: f64) -> Vec<Vec2> {
        (0..self.slots.len())
            .map(|i| {
                let p = self.slots[i].traj.at(t);
                match self.period {
                    Some(b) => p + b.shift(self.unwrap[i]),
                    None => p,
                }
            })
            .collect()
    }
}
