//! The typed values of the command's options: clap parses and checks them, so that a bad value
//! is reported by clap with the option's name and what it takes.

use poolsim::model::pool::NvDelay;
use poolsim::run::{FixedNews, SectorChoice};
use poolsim::scenario::{self, Scenario};
use std::str::FromStr;

/// `--engine`: which engine runs the scenario.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Engine {
    /// The event list (thesis fig. 2), the reference.
    EventList,
    /// Fixed time steps (thesis fig. 1).
    TimeStep,
    /// The pool objects on the sequential kernel (thesis fig. 3 and 14).
    Objects,
    /// The pool objects under Time Warp.
    TimeWarp,
    /// The event list cut into strips of the table, each a kernel object: one worker runs
    /// them in turn, more run them in parallel under Time Warp.
    Regions,
}

/// `--fixed-news`: which balls tell cushions, pockets and corners of a new trajectory.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum News {
    /// Those in sectors within reach of the fixed object.
    Near,
    /// Every ball, at every change (thesis fig. 15).
    Thesis,
}

impl From<News> for FixedNews {
    fn from(n: News) -> FixedNews {
        match n {
            News::Near => FixedNews::Near,
            News::Thesis => FixedNews::Thesis,
        }
    }
}

/// `--sectors`: none, auto, N (N x N) or NxM.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sectors {
    /// No sectors.
    None,
    /// A grid sized for the balls.
    Auto,
    /// A grid of `nx` by `ny` sectors.
    Grid(u32, u32),
}

impl FromStr for Sectors {
    type Err = String;

    fn from_str(text: &str) -> Result<Sectors, String> {
        let bad = || {
            format!(
                "expected none, auto, N or NxM (sectors per side, at least 1 each, at most {} \
                 sectors in all), got `{text}`",
                scenario::MAX_SECTORS
            )
        };
        let count = |t: &str| match t.parse::<u32>() {
            Ok(n) if n >= 1 && u64::from(n) <= scenario::MAX_SECTORS => Ok(n),
            _ => Err(bad()),
        };
        let (nx, ny) = match text {
            "none" => return Ok(Sectors::None),
            "auto" => return Ok(Sectors::Auto),
            _ => match text.split_once(['x', 'X']) {
                Some((nx, ny)) => (count(nx)?, count(ny)?),
                None => (count(text)?, count(text)?),
            },
        };
        if u64::from(nx) * u64::from(ny) > scenario::MAX_SECTORS {
            return Err(bad());
        }
        Ok(Sectors::Grid(nx, ny))
    }
}

/// The layout `--sectors` asks for on scenario `s`; absent means the scenario's own `[sectors]`,
/// if any.
pub fn sector_choice(arg: Option<Sectors>, s: &Scenario) -> Option<SectorChoice> {
    match arg {
        None => s.sectors.as_ref().map(|_| SectorChoice::Scenario),
        Some(Sectors::None) => None,
        Some(Sectors::Auto) => Some(SectorChoice::Auto),
        Some(Sectors::Grid(nx, ny)) => Some(SectorChoice::Grid(nx, ny)),
    }
}

/// `--newvelocity-delay`: a delay in simulation time, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Delay {
    /// The thesis' choice (4.4): a ball at the fastest initial speed moves 1 % of the smallest
    /// diameter in the delay.
    Auto,
    /// This delay (finite, not below 0; 0 is exact).
    Fixed(f64),
}

impl FromStr for Delay {
    type Err = String;

    fn from_str(text: &str) -> Result<Delay, String> {
        if text == "auto" {
            return Ok(Delay::Auto);
        }
        let d: f64 = text
            .parse()
            .map_err(|_| format!("expected a number or `auto`, got `{text}`"))?;
        if !d.is_finite() || d < 0.0 {
            return Err(format!("must be a finite number not below 0, got {d}"));
        }
        Ok(Delay::Fixed(d))
    }
}

/// How NewVelocity messages travel on scenario `s` with `--newvelocity-delay` `arg`.
pub fn nv_delay(arg: Option<Delay>, s: &Scenario) -> NvDelay {
    let d = match arg {
        None => 0.0,
        Some(Delay::Fixed(d)) => d,
        Some(Delay::Auto) => {
            let vmax = s
                .balls
                .iter()
                .map(|b| b.velocity.norm())
                .fold(0.0, f64::max);
            let dmin = s
                .balls
                .iter()
                .map(|b| 2.0 * b.radius)
                .fold(f64::INFINITY, f64::min);
            if vmax > 0.0 && dmin.is_finite() {
                0.01 * dmin / vmax
            } else {
                0.0
            }
        }
    };
    if d > 0.0 {
        NvDelay::Delay(d)
    } else {
        NvDelay::Exact
    }
}

/// `--memory-limit`: the memory a run is checked against before it allocates, in place of what
/// the machine has available; `none` checks nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MemoryLimit {
    /// This many bytes.
    Bytes(u64),
    /// No check.
    None,
}

impl FromStr for MemoryLimit {
    type Err = String;

    fn from_str(text: &str) -> Result<MemoryLimit, String> {
        if text == "none" {
            return Ok(MemoryLimit::None);
        }
        let bad = || {
            format!(
                "expected a size such as 512M, 8G or 1.5T (binary units), or none, got `{text}`"
            )
        };
        let lower = text.to_ascii_lowercase();
        let number = lower.trim_end_matches("ib").trim_end_matches('b');
        let (digits, shift) = match number.chars().last() {
            Some('k') => (&number[..number.len() - 1], 10),
            Some('m') => (&number[..number.len() - 1], 20),
            Some('g') => (&number[..number.len() - 1], 30),
            Some('t') => (&number[..number.len() - 1], 40),
            _ => (number, 0),
        };
        let value: f64 = digits.trim().parse().map_err(|_| bad())?;
        let bytes = value * (1u64 << shift) as f64;
        if !(bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64) {
            return Err(bad());
        }
        Ok(MemoryLimit::Bytes(bytes as u64))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sector_layouts_parse_and_bad_ones_say_what_is_taken() {
        assert_eq!("none".parse(), Ok(Sectors::None));
        assert_eq!("auto".parse(), Ok(Sectors::Auto));
        assert_eq!("3".parse(), Ok(Sectors::Grid(3, 3)));
        assert_eq!("2x5".parse(), Ok(Sectors::Grid(2, 5)));
        for bad in ["0", "3y4", "x", "1000", "-2"] {
            let e = bad.parse::<Sectors>().unwrap_err();
            assert!(e.contains("NxM") && e.contains(bad), "{e}");
        }
    }

    #[test]
    fn delays_parse_and_bad_ones_are_refused() {
        assert_eq!("auto".parse(), Ok(Delay::Auto));
        assert_eq!("0.5".parse(), Ok(Delay::Fixed(0.5)));
        assert!("-1".parse::<Delay>().unwrap_err().contains("-1"));
        assert!("inf".parse::<Delay>().unwrap_err().contains("finite"));
        assert!("soon".parse::<Delay>().unwrap_err().contains("`soon`"));
    }

    #[test]
    fn memory_limits_read_binary_units_and_none() {
        let bytes = |t: &str| t.parse::<MemoryLimit>();
        assert_eq!(bytes("512M"), Ok(MemoryLimit::Bytes(512 << 20)));
        assert_eq!(bytes("8GiB"), Ok(MemoryLimit::Bytes(8 << 30)));
        assert_eq!(bytes("1.5t"), Ok(MemoryLimit::Bytes(3 << 39)));
        assert_eq!(bytes("4096"), Ok(MemoryLimit::Bytes(4096)));
        assert_eq!(bytes("none"), Ok(MemoryLimit::None));
        for bad in ["", "G", "-1G", "0", "lots", "1e30T", "nan"] {
            assert!(bytes(bad).is_err(), "{bad}");
        }
    }
}
