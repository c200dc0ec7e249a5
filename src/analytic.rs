//! The analytic model of message counts in a sectored pool simulation (thesis ch. 7).
//!
//! The table is the unit square, cut into square sectors of width `s` (so `1/s` per side and
//! `1/s²` in all). `N` balls move at speed `V` for a time `T`, and `m` counts the velocity changes
//! (a collision of two balls adds two). The model adds up the messages of each kind the thesis
//! counts, assuming balls spread evenly (`N s²` per sector):
//!
//! - a ball crosses into a new sector about once per sector width travelled, `N V T / s` times in
//!   all; each crossing costs two SectorEntry and two SectorDeparture messages, and NewVelocity
//!   messages to the `N s²` balls of the sector entered and to its 4 neighbours;
//! - each velocity change costs one VelocityChange, two Collision messages, new sector entries and
//!   departures with the cancellations of the old ones (8), and `N s² + 4` NewVelocity messages.
//!
//! Summed, `F(s) = (N V T / s)(N s² + 8) + m (N s² + 15)`: equation 1 of the thesis when `m = 0`,
//! equation 2 otherwise. Crossings fall and per-sector traffic grows with `s`, so `F` has one
//! minimum: at `N s² = 8` (eight balls per sector) without collisions, and at a smaller sector
//! with them; the thesis reads this as an upper bound on the best sector size (figures 17–18).

use serde::Serialize;
use serde_json::{json, Value};

/// The parameters of the chapter 7 model (unit-square table, square sectors).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ModelParams {
    /// `N`, the number of balls (positive).
    pub balls: f64,
    /// `V`, the speed of every ball (table widths per time unit); the thesis' figures take 1.
    pub speed: f64,
    /// `T`, the duration of the simulation (time units); the thesis' figures take `V T = 1`, one
    /// crossing of the table per ball.
    pub time: f64,
    /// `m`, the number of ball velocity changes (two per collision); 0 gives equation 1.
    pub changes: f64,
}

impl ModelParams {
    /// `N` balls with the thesis' defaults: `V = 1`, `T = 1`, no collisions (`m = 0`).
    pub fn new(balls: f64) -> ModelParams {
        ModelParams {
            balls,
            speed: 1.0,
            time: 1.0,
            changes: 0.0,
        }
    }

    /// Checks the parameters: `N`, `V` and `T` finite and positive, `m` finite and not negative.
    /// The error names the command-line option.
    pub fn validate(&self) -> Result<(), ModelError> {
        if !(self.balls >= 1.0 && self.balls <= MAX_BALLS && self.balls.fract() == 0.0) {
            return Err(ModelError::Balls(self.balls));
        }
        for (flag, value) in [("--speed", self.speed), ("--time", self.time)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(ModelError::NotPositive { flag, value });
            }
        }
        if !(self.changes.is_finite() && self.changes >= 0.0) {
            return Err(ModelError::Changes(self.changes));
        }
        // F is largest at the ends of the widths reported: one sector, and the finest grid
        let finest = 1.0
            / (4.0 * self.balls.sqrt() / (2.0 * 2f64.sqrt()))
                .ceil()
                .max(8.0);
        if !(messages(self, 1.0).is_finite() && messages(self, finest).is_finite()) {
            return Err(ModelError::Overflow(*self));
        }
        Ok(())
    }

    /// The thesis' equation that applies: 1 without velocity changes, 2 with them.
    pub fn equation(&self) -> u32 {
        if self.changes == 0.0 {
            1
        } else {
            2
        }
    }
}

/// Why [`ModelParams`] are refused ([`ModelParams::validate`]); the message names the
/// command-line option.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// `N` is not a whole number from 1 to [`MAX_BALLS`].
    #[error("--balls must be a whole number from 1 to {MAX_BALLS:e}, got {0}")]
    Balls(f64),
    /// `V` or `T` is not a finite positive number.
    #[error("{flag} must be a positive number, got {value:?}")]
    NotPositive {
        /// The option: `--speed` or `--time`.
        flag: &'static str,
        /// Its value.
        value: f64,
    },
    /// `m` is negative or not finite.
    #[error("--changes must be a number not below 0, got {0}")]
    Changes(f64),
    /// The message counts are too large for a 64-bit float.
    #[error(
        "the message counts overflow a 64-bit float for N = {:?}, V = {:?}, T = {:?}, m = {:?}",
        .0.balls, .0.speed, .0.time, .0.changes
    )]
    Overflow(ModelParams),
}

/// The most balls the model takes: its table of grids then stays at a few dozen rows.
pub const MAX_BALLS: f64 = 1e15;

/// The model's message count for sectors of width `s` (thesis ch. 7, equations 1 and 2):
/// `F(s) = (N V T / s)(N s² + 8) + m (N s² + 15)`. Meaningful for `0 < s ≤ 1`.
pub fn messages(p: &ModelParams, s: f64) -> f64 {
    let n = p.balls;
    let per_sector = n * s * s;
    n * p.speed * p.time / s * (per_sector + 8.0) + p.changes * (per_sector + 15.0)
}

/// `dF/ds = N V T (N − 8/s²) + 2 m N s`, whose zero is the best sector width (thesis ch. 7).
fn slope(p: &ModelParams, s: f64) -> f64 {
    let n = p.balls;
    n * p.speed * p.time * (n - 8.0 / (s * s)) + 2.0 * p.changes * n * s
}

/// The sector width `s` in `(0, 1]` that minimizes [`messages`]. Without velocity changes this is
/// exactly `2√2 / √N`, eight balls per sector (thesis ch. 7, after equation 1). With them the
/// zero of the cubic `N V T (N − 8/s²) + 2 m N s = 0`, which the thesis leaves unsolved: the
/// slope rises with `s`, so bisection finds its single root, below `2√2 / √N`. A width above 1
/// (fewer than eight balls in all) is clamped to 1, one sector for the whole table. `NaN` for
/// parameters that [`ModelParams::validate`] rejects.
pub fn optimal_sector(p: &ModelParams) -> f64 {
    if p.validate().is_err() {
        return f64::NAN;
    }
    let s0 = 2.0 * 2f64.sqrt() / p.balls.sqrt();
    if p.changes == 0.0 {
        return s0.min(1.0);
    }
    // slope(s0) = 2 m N s0 > 0; halve until the slope is negative
    let mut hi = s0;
    let mut lo = 0.5 * s0;
    while slope(p, lo) >= 0.0 {
        hi = lo;
        lo *= 0.5;
        if lo == 0.0 {
            return hi.min(1.0);
        }
    }
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if slope(p, mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let s = if slope(p, hi).abs() < slope(p, lo).abs() {
        hi
    } else {
        lo
    };
    s.min(1.0)
}

/// `F(s)` at `steps` evenly spaced widths `s = 1/steps, 2/steps, …, 1` (the horizontal axis of
/// the thesis' figures 17 and 18), as `(s, F(s))` pairs.
pub fn table(p: &ModelParams, steps: usize) -> Vec<(f64, f64)> {
    (1..=steps)
        .map(|i| {
            let s = if i == steps {
                1.0
            } else {
                i as f64 / steps as f64
            };
            (s, messages(p, s))
        })
        .collect()
}

/// Whole numbers of sectors per side worth showing: 1 to 8, then 10, 12, 16, 20, 24, 32, … up
/// to four times the optimum, and the two whole counts around the optimum.
fn grid_counts(k_opt: f64) -> Vec<u64> {
    let k_max = (4.0 * k_opt).ceil().max(8.0) as u64;
    let mut ks: Vec<u64> = (1..=8).collect();
    let mut base = 8u64;
    while base < k_max {
        for f in [5, 6, 8] {
            let k = base * f / 4;
            if k <= k_max {
                ks.push(k);
            }
        }
        base *= 2;
    }
    ks.push((k_opt.floor() as u64).max(1));
    ks.push((k_opt.ceil() as u64).max(1));
    ks.sort_unstable();
    ks.dedup();
    ks
}

/// The whole grid `k × k` with the fewest messages, next to the optimal width.
fn best_grid(p: &ModelParams, s_opt: f64) -> u64 {
    let k_opt = 1.0 / s_opt;
    let lo = (k_opt.floor() as u64).max(1);
    let hi = (k_opt.ceil() as u64).max(1);
    if messages(p, 1.0 / hi as f64) < messages(p, 1.0 / lo as f64) {
        hi
    } else {
        lo
    }
}

/// A readable account of the model for `poolsim model`: the parameters, the equation used, a
/// table of `F` for whole grids of `k × k` sectors (width, sectors, balls per sector, messages),
/// the optimal width with its balls per sector, and the best whole grid.
pub fn report(p: &ModelParams) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let s_opt = optimal_sector(p);
    let _ = writeln!(
        out,
        "Message counts in a sectored pool simulation (Goldberg 1984, ch. 7)"
    );
    let _ = writeln!(
        out,
        "unit-square table, square sectors of width s; N = {} balls at speed V = {} for T = {}, \
         m = {} velocity changes",
        p.balls, p.speed, p.time, p.changes
    );
    if p.equation() == 1 {
        let _ = writeln!(
            out,
            "F(s) = (N V T / s)(N s^2 + 8)                 (equation 1)"
        );
    } else {
        let _ = writeln!(
            out,
            "F(s) = (N V T / s)(N s^2 + 8) + m (N s^2 + 15)  (equation 2)"
        );
    }
    if let Err(e) = p.validate() {
        let _ = writeln!(out, "invalid parameters: {e}");
        return out;
    }
    let best = best_grid(p, s_opt);
    let _ = writeln!(out);
    let _ = writeln!(
        out,
        "{:>13}  {:>10}  {:>9}  {:>13}  {:>15}",
        "sectors/side", "width s", "sectors", "balls/sector", "messages F(s)"
    );
    for k in grid_counts(1.0 / s_opt) {
        let s = 1.0 / k as f64;
        let mark = if k == best { "  <- best grid" } else { "" };
        let _ = writeln!(
            out,
            "{:>13}  {:>10.6}  {:>9}  {:>13.3}  {:>15.1}{mark}",
            k,
            s,
            k * k,
            p.balls * s * s,
            messages(p, s)
        );
    }
    let _ = writeln!(out);
    let _ = writeln!(
        out,
        "optimal sector width s* = {:.6} ({:.3} sectors per side, {:.3} balls per sector), \
         F(s*) = {:.1}",
        s_opt,
        1.0 / s_opt,
        p.balls * s_opt * s_opt,
        messages(p, s_opt)
    );
    let sb = 1.0 / best as f64;
    let _ = writeln!(
        out,
        "best whole grid: {best} x {best} sectors ({:.3} balls per sector), F = {:.1}",
        p.balls * sb * sb,
        messages(p, sb)
    );
    if s_opt >= 1.0 {
        let _ = writeln!(
            out,
            "(the unconstrained optimum is wider than the table: one sector is best)"
        );
    }
    out
}

/// The content of [`report`] as one JSON object: `params`, `equation`, `optimal` (`sector_width`,
/// `sectors_per_side`, `balls_per_sector`, `messages`), `best_grid` (`sectors_per_side`,
/// `balls_per_sector`, `messages`) and `table` (one object per whole grid: `sectors_per_side`,
/// `sector_width`, `sectors`, `balls_per_sector`, `messages`). Invalid parameters give an object
/// with `params` and `error`.
pub fn report_json(p: &ModelParams) -> Value {
    if let Err(e) = p.validate() {
        return json!({ "model": "goldberg-1984-ch7", "params": p, "error": e.to_string() });
    }
    let s_opt = optimal_sector(p);
    let best = best_grid(p, s_opt);
    let sb = 1.0 / best as f64;
    let rows: Vec<Value> = grid_counts(1.0 / s_opt)
        .into_iter()
        .map(|k| {
            let s = 1.0 / k as f64;
            json!({
                "sectors_per_side": k,
                "sector_width": s,
                "sectors": k * k,
                "balls_per_sector": p.balls * s * s,
                "messages": messages(p, s),
            })
        })
        .collect();
    json!({
        "model": "goldberg-1984-ch7",
        "params": p,
        "equation": p.equation(),
        "optimal": {
            "sector_width": s_opt,
            "sectors_per_side": 1.0 / s_opt,
            "balls_per_sector": p.balls * s_opt * s_opt,
            "messages": messages(p, s_opt),
        },
        "best_grid": {
            "sectors_per_side": best,
            "balls_per_sector": p.balls * sb * sb,
            "messages": messages(p, sb),
        },
        "table": rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with_changes(n: f64, m: f64) -> ModelParams {
        ModelParams {
            changes: m,
            ..ModelParams::new(n)
        }
    }

    #[test]
    fn messages_by_hand() {
        // N = 16, V T = 1, s = 1/2: (16 / 0.5)(16/4 + 8) = 32 * 12
        assert_eq!(messages(&ModelParams::new(16.0), 0.5), 384.0);
        // plus m (N s^2 + 15) = 16 * 19
        assert_eq!(messages(&with_changes(16.0, 16.0), 0.5), 384.0 + 304.0);
        // V and T enter only as their product
        let p = ModelParams {
            speed: 2.0,
            time: 0.25,
            ..ModelParams::new(16.0)
        };
        assert_eq!(messages(&p, 0.5), 192.0);
        // one sector: N V T (N + 8)
        assert_eq!(messages(&ModelParams::new(64.0), 1.0), 64.0 * 72.0);
    }

    #[test]
    fn eight_balls_per_sector_without_collisions() {
        for n in [8.0, 16.0, 32.0, 64.0, 100.0, 1e4, 1e6] {
            let p = ModelParams::new(n);
            let s = optimal_sector(&p);
            assert!(
                (s - 2.0 * 2f64.sqrt() / f64::sqrt(n)).abs() <= 1e-12,
                "N = {n}"
            );
            assert!(
                (n * s * s - 8.0).abs() <= 1e-12 * 8.0,
                "N = {n}: {}",
                n * s * s
            );
        }
        // fewer than eight balls: one sector is best
        assert_eq!(optimal_sector(&ModelParams::new(4.0)), 1.0);
    }

    #[test]
    fn collisions_shrink_the_optimum() {
        // figure 18: V T = 1 and m = N
        for n in [8.0, 16.0, 32.0, 64.0, 1000.0] {
            let free = optimal_sector(&ModelParams::new(n));
            let p = with_changes(n, n);
            let s = optimal_sector(&p);
            assert!(s < free, "N = {n}: {s} vs {free}");
            assert!(n * s * s < 8.0);
            // the derivative vanishes there, relative to its terms
            let scale = n * n + 8.0 * n / (s * s) + 2.0 * n * n * s;
            assert!(slope(&p, s).abs() <= 1e-12 * scale, "N = {n}");
            let h = 1e-6 * s;
            let numeric = (messages(&p, s + h) - messages(&p, s - h)) / (2.0 * h);
            assert!(numeric.abs() <= 1e-4 * scale, "N = {n}: {numeric}");
        }
    }

    #[test]
    fn minimum_on_a_fine_scan() {
        for p in [
            ModelParams::new(64.0),
            with_changes(64.0, 64.0),
            with_changes(36.0, 500.0),
            ModelParams {
                speed: 3.0,
                time: 2.0,
                changes: 10.0,
                balls: 1000.0,
            },
        ] {
            let s = optimal_sector(&p);
            let f = messages(&p, s);
            for i in 1..=100_000 {
                let x = i as f64 / 100_000.0;
                assert!(messages(&p, x) >= f * (1.0 - 1e-12), "{p:?} at s = {x}");
            }
        }
    }

    #[test]
    fn tables_and_reports() {
        let p = ModelParams::new(64.0);
        let t = table(&p, 20);
        assert_eq!(t.len(), 20);
        assert_eq!(t[0].0, 0.05);
        assert_eq!(t[19], (1.0, messages(&p, 1.0)));
        let text = report(&p);
        assert!(text.contains("equation 1"), "{text}");
        assert!(text.contains("8.000 balls per sector"), "{text}");
        assert!(text.contains("3 x 3 sectors"), "{text}");
        let j = report_json(&with_changes(64.0, 64.0));
        assert_eq!(j["equation"], 2);
        assert!(j["optimal"]["balls_per_sector"].as_f64().unwrap() < 8.0);
        assert!(j["table"].as_array().unwrap().len() >= 8);
        assert_eq!(j["params"]["balls"], 64.0);
        let bad = ModelParams::new(0.0);
        assert_eq!(bad.validate(), Err(ModelError::Balls(0.0)));
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "--balls must be a whole number from 1 to 1e15, got 0"
        );
        assert!(optimal_sector(&bad).is_nan());
        assert!(report_json(&bad)["error"].is_string());
        assert!(report(&bad).contains("invalid parameters"));
    }
}
