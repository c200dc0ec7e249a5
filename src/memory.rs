//! Memory: a run's needs estimated before it allocates ([`estimate`], [`least`]), what this
//! process may still take ([`available`]: `MemAvailable` and its control groups' limits), and
//! its use of transparent huge pages (Linux), the one memory setting that depends on the
//! engine. With 2 MiB pages the event list touches fewer page-table entries per event (its
//! loop at 10^6 balls: 1,317-1,324 ns per event with them, 1,410-1,428 without), but every page
//! a run touches for the first time costs the kernel 2 MiB to zero, and the objects engines
//! touch fresh memory all run long, their messages most of all (at 10^5 balls to t = 0.5, 2
//! Time Warp workers take 2.65-3.58 s wall with them, 0.97-2.56 s of it in the kernel, against
//! 2.25-2.75 s without; the sequential objects engine 2.3-2.9 s with 0.7-1.2 s in the kernel,
//! against about 1.7 s without).

/// Lets the kernel back this process's later memory with transparent huge pages, or not
/// (`prctl(PR_SET_THP_DISABLE)`: process-wide, for pages faulted in from now on). Does nothing
/// where the system has no such switch.
pub fn transparent_huge_pages(on: bool) {
    #[cfg(target_os = "linux")]
    // SAFETY: PR_SET_THP_DISABLE takes one integer flag and changes nothing but how the kernel
    // backs this process's memory; it cannot fail in a way that matters (a kernel without it
    // returns an error, which leaves things as they were).
    unsafe {
        libc::prctl(libc::PR_SET_THP_DISABLE, libc::c_ulong::from(!on), 0, 0, 0);
    }
    #[cfg(not(target_os = "linux"))]
    let _ = on;
}

/// Bytes every run holds whatever its size: the program, its allocator's arenas and buffers.
const BASE: u64 = 48 << 20;

/// Peak resident bytes per ball of each engine, measured on the gas at area fraction 0.28 (the
/// scenario, the initial states and the engine together; the objects engines after their
/// pending messages reached their steady number, about 1.5 times their set-up's): the event
/// list 0.60 KiB at 10^6 balls, the time-step engine 0.41 KiB at 10^5, the sectored objects
/// (`--sectors auto`) 4.9 KiB at 10^5, and on 2 Time Warp workers 5.4 KiB.
const PER_BALL: [(Footprint, u64); 4] = [
    (Footprint::EventList, 650),
    (Footprint::TimeStep, 450),
    (Footprint::Sectored, 5_000),
    (Footprint::TimeWarp, 5_500),
];

/// Bytes per pair of balls of the objects engine without sectors, where every ball keeps a
/// record of every other: 378 MiB at 2,025 balls, 151 MiB at 1,024.
const PER_PAIR: u64 = 95;

/// What a run's memory grows with: its engine, and whether sectors keep it linear.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Footprint {
    EventList,
    TimeStep,
    Sectored,
    TimeWarp,
}

/// A run's memory, estimated before it allocates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Estimate {
    /// Peak bytes, about.
    pub bytes: u64,
    /// Whether the engine's memory (and set-up time) grows with the square of the balls: the
    /// objects engine without sectors.
    pub quadratic: bool,
}

/// The memory a run of `balls` balls on `engine` will take at its peak, about (within a
/// factor of 1.5 on the gas; set-up allocates most of it).
pub fn estimate(balls: usize, engine: &crate::run::EngineKind) -> Estimate {
    use crate::run::EngineKind;
    let (footprint, quadratic) = match engine {
        EngineKind::EventList | EngineKind::Regions { .. } => (Footprint::EventList, false),
        EngineKind::TimeStep { .. } => (Footprint::TimeStep, false),
        EngineKind::Objects { .. } => (Footprint::Sectored, true),
        EngineKind::Sectored { .. } => (Footprint::Sectored, false),
        EngineKind::TimeWarp { sectors, .. } => (Footprint::TimeWarp, sectors.is_none()),
    };
    let n = balls as u64;
    let per_ball = PER_BALL
        .iter()
        .find(|(f, _)| *f == footprint)
        .map_or(0, |&(_, b)| b);
    let pairs = if quadratic {
        n.saturating_mul(n).saturating_mul(PER_PAIR)
    } else {
        0
    };
    Estimate {
        bytes: BASE
            .saturating_add(n.saturating_mul(per_ball))
            .saturating_add(pairs),
        quadratic,
    }
}

/// The least memory a run of `balls` balls takes on any engine: enough to refuse a run before
/// its scenario is even generated.
pub fn least(balls: usize) -> u64 {
    let per_ball = PER_BALL.iter().map(|&(_, b)| b).min().unwrap_or(0);
    BASE.saturating_add((balls as u64).saturating_mul(per_ball))
}

/// Memory this process may still take, and what limits it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Available {
    /// Bytes.
    pub bytes: u64,
    /// Where the figure comes from: `MemAvailable` (Linux's estimate of what can be allocated
    /// without swapping) or `the cgroup's memory limit` (its limit less its usage).
    pub source: &'static str,
}

/// The memory this process may still take: the lower of the system's available memory and the
/// room left under its control group's limit (cgroup v1 or v2, the tightest of its ancestors);
/// `None` where neither can be read.
pub fn available() -> Option<Available> {
    let system = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| mem_available(&text))
        .map(|bytes| Available {
            bytes,
            source: "MemAvailable",
        });
    let group = cgroup_room().map(|bytes| Available {
        bytes,
        source: "the cgroup's memory limit",
    });
    match (system, group) {
        (Some(s), Some(g)) => Some(if g.bytes < s.bytes { g } else { s }),
        (s, g) => s.or(g),
    }
}

/// `MemAvailable` of a `/proc/meminfo` text, in bytes.
fn mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib.saturating_mul(1024))
}

/// The room left under the memory limits of this process's control groups: their limit less
/// their usage, the least over the group and its ancestors; `None` without a limit.
fn cgroup_room() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let mut room: Option<u64> = None;
    for line in text.lines() {
        let mut fields = line.splitn(3, ':');
        let (id, controllers, path) = (fields.next()?, fields.next()?, fields.next()?);
        let (base, limit, usage) = if id == "0" && controllers.is_empty() {
            ("/sys/fs/cgroup", "memory.max", "memory.current")
        } else if controllers.split(',').any(|c| c == "memory") {
            (
                "/sys/fs/cgroup/memory",
                "memory.limit_in_bytes",
                "memory.usage_in_bytes",
            )
        } else {
            continue;
        };
        let base = std::path::Path::new(base);
        let mut dir = base.join(path.trim_start_matches('/'));
        loop {
            if let Some(r) = group_room(&dir, limit, usage) {
                room = Some(room.map_or(r, |m| m.min(r)));
            }
            if dir == base || !dir.pop() {
                break;
            }
        }
    }
    room
}

/// One control group's limit less its usage, if it has a limit.
fn group_room(dir: &std::path::Path, limit: &str, usage: &str) -> Option<u64> {
    let read = |f: &str| -> Option<u64> {
        std::fs::read_to_string(dir.join(f))
            .ok()?
            .trim()
            .parse()
            .ok()
    };
    // "max" (v2) does not parse; v1 writes its "no limit" as a number near 2^63
    let limit = read(limit).filter(|&l| l < 1 << 60)?;
    Some(limit.saturating_sub(read(usage).unwrap_or(0)))
}

/// A number of bytes as people read it: `1.5 GiB`, `300 MiB`.
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} B")
    } else {
        format!("{value:.1} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::{EngineKind, SectorChoice};

    #[test]
    fn mem_available_is_read_in_bytes() {
        let text = "MemTotal:       24000000 kB\nMemFree:  100 kB\nMemAvailable:   2048 kB\n";
        assert_eq!(mem_available(text), Some(2 << 20));
        assert_eq!(mem_available("MemTotal: 1 kB\n"), None);
    }

    #[test]
    fn estimates_grow_with_the_balls_and_the_plain_objects_with_their_square() {
        let el = estimate(1_000_000, &EngineKind::EventList);
        assert!(!el.quadratic);
        // 595 MiB measured (the gas at 0.28, 10^6 balls): the estimate must not fall below it
        assert!(el.bytes > 600 << 20 && el.bytes < 1 << 30, "{}", el.bytes);
        let plain = estimate(
            4_900,
            &EngineKind::Objects {
                delay: crate::model::pool::NvDelay::Exact,
            },
        );
        assert!(plain.quadratic);
        assert!(plain.bytes > 2 << 30, "{}", plain.bytes);
        let sectored = estimate(
            4_900,
            &EngineKind::Sectored {
                sectors: SectorChoice::Auto,
                news: Default::default(),
            },
        );
        assert!(!sectored.quadratic && sectored.bytes < plain.bytes / 20);
        assert!(least(100_000_000) > 40 << 30, "10^8 balls take tens of GiB");
        assert!(least(100_000_000) <= estimate(100_000_000, &EngineKind::EventList).bytes);
    }

    #[test]
    fn available_memory_is_found_on_linux() {
        if cfg!(target_os = "linux") {
            let a = available().expect("/proc/meminfo is there");
            assert!(a.bytes > 0, "{a:?}");
        }
    }

    #[test]
    fn bytes_read_as_people_read_them() {
        assert_eq!(human_bytes(512), "512 B");
        assert_eq!(human_bytes(3 << 29), "1.5 GiB");
    }
}
