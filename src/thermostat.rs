//! Andersen's thermostat (Andersen, J. Chem. Phys. 72, 2384, 1980) for runs at a set
//! temperature: at the instants of a Poisson process of rate `ν N` (ν per disk and unit time),
//! one disk chosen at random takes a fresh velocity from the Maxwell-Boltzmann distribution at
//! `kT`, as if it had hit a particle of a heat bath. Between these kicks the dynamics is the
//! exact hard-disk dynamics; the kicks make the ensemble canonical. Velocity rescaling would not
//! do for hard disks: scaling every velocity alike only changes the clock.
//!
//! The kicks come from their own seeded generator, so a run with a thermostat is as
//! reproducible as one without: the same seed, the same kicks, the same digest.

use crate::geometry::Vec2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The thermostat's settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thermostat {
    /// The bath's temperature `kT` (positive).
    pub kt: f64,
    /// Kicks per disk and unit time (positive).
    pub rate: f64,
    /// The seed of the kicks.
    pub seed: u64,
}

impl Thermostat {
    /// Checks the settings: one line naming the flag at fault.
    pub fn check(&self) -> Result<(), String> {
        if !(self.kt.is_finite() && self.kt > 0.0) {
            return Err(format!(
                "--thermostat: the temperature must be a positive number, got {}",
                self.kt
            ));
        }
        if !(self.rate.is_finite() && self.rate > 0.0) {
            return Err(format!(
                "--thermostat-rate: must be a positive number of kicks per disk and unit time, \
                 got {}",
                self.rate
            ));
        }
        Ok(())
    }
}

/// The kicks of one run: when the next comes, and the generator they come from.
#[derive(Clone, Debug)]
pub struct Bath {
    settings: Thermostat,
    rng: ChaCha8Rng,
    /// Disks the kicks choose among.
    disks: u32,
    /// The time of the next kick.
    pub next: f64,
}

/// One kick: which disk, and its new velocity for its mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kick {
    /// The disk.
    pub disk: u32,
    /// A draw of the Maxwell-Boltzmann distribution at kT for unit mass: divide by the square
    /// root of the disk's mass.
    pub unit_velocity: Vec2,
}

impl Bath {
    /// The kicks of a run of `disks` disks from `start`.
    pub fn new(settings: Thermostat, disks: u32, start: f64) -> Bath {
        let mut b = Bath {
            settings,
            rng: ChaCha8Rng::seed_from_u64(settings.seed),
            disks: disks.max(1),
            next: start,
        };
        b.next = start + b.wait();
        b
    }

    /// A draw of the time between two kicks: exponential with mean `1 / (ν N)`.
    fn wait(&mut self) -> f64 {
        let u: f64 = self.rng.gen_range(f64::EPSILON..1.0);
        -u.ln() / (self.settings.rate * f64::from(self.disks))
    }

    /// The kick due at [`Bath::next`], and the time of the one after it.
    pub fn kick(&mut self) -> Kick {
        let disk = self.rng.gen_range(0..self.disks);
        // Box-Muller: two independent normal components of variance kT
        let u: f64 = self.rng.gen_range(f64::EPSILON..1.0);
        let a: f64 = std::f64::consts::TAU * self.rng.gen::<f64>();
        let rho = (-2.0 * self.settings.kt * u.ln()).sqrt();
        self.next += self.wait();
        Kick {
            disk,
            unit_velocity: Vec2::new(rho * a.cos(), rho * a.sin()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kicks_come_at_the_rate_with_maxwell_velocities() {
        let t = Thermostat {
            kt: 2.0,
            rate: 0.5,
            seed: 3,
        };
        let mut b = Bath::new(t, 100, 10.0);
        let (mut v2, mut v4, n) = (0.0, 0.0, 200_000);
        let mut hits = vec![0u32; 100];
        for _ in 0..n {
            let k = b.kick();
            let s = k.unit_velocity.norm2();
            v2 += s;
            v4 += s * s;
            hits[k.disk as usize] += 1;
        }
        let (v2, v4) = (v2 / n as f64, v4 / n as f64);
        // 2D Maxwell at kT = 2: <v²> = 2 kT, <v⁴> = 2 <v²>²
        assert!((v2 / 4.0 - 1.0).abs() < 0.01, "{v2}");
        assert!((v4 / (2.0 * v2 * v2) - 1.0).abs() < 0.03, "{v4}");
        // n kicks at 50 per unit time take n / 50 time units
        let span = b.next - 10.0;
        assert!((span / (n as f64 / 50.0) - 1.0).abs() < 0.01, "{span}");
        assert!(hits.iter().all(|&h| (1600..2400).contains(&h)));
    }

    #[test]
    fn bad_settings_name_their_flag() {
        let ok = Thermostat {
            kt: 1.0,
            rate: 1.0,
            seed: 1,
        };
        assert!(ok.check().is_ok());
        let e = Thermostat { kt: 0.0, ..ok }.check().unwrap_err();
        assert!(e.starts_with("--thermostat:"));
        let e = Thermostat {
            rate: f64::NAN,
            ..ok
        }
        .check()
        .unwrap_err();
        assert!(e.starts_with("--thermostat-rate:"));
    }
}
