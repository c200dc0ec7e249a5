//! The run summary (`poolsim run --json`): what a run did, as a typed contract. Its JSON is
//! specified in `docs/formats.md`; fields keep their names, new ones may be added.

use crate::engine::{EventCounts, EventKind};
pub use crate::model::MessageKind;
use pdes_kernel::time_warp::TwStats;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// What one run did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// The built-in scenario's name or the file's path, as given.
    pub scenario: String,
    /// The engine's name (`event-list`, `time-step`, `objects`, `time-warp`).
    pub engine: String,
    /// Number of balls.
    pub balls: usize,
    /// End time of the run (time units).
    pub until: f64,
    /// Physical events executed, by trace kind.
    pub events: EventTotals,
    /// Messages sent, by the thesis' message types.
    pub messages: MessageCounts,
    /// Kinetic energy at the start and the end.
    pub kinetic_energy: KineticEnergy,
    /// A hash of every ball's final position and velocity bits and pocket (16 hex digits).
    pub final_state_digest: String,
    /// Wall-clock time of the run, set-up included (s).
    pub wall_seconds: f64,
    /// Of that, the time before the first event (s).
    pub setup_seconds: f64,
    /// Events per wall-clock second (1/s).
    pub events_per_second: f64,
    /// Whether invariants were checked at every event (`--check`).
    pub checked: bool,
    /// Engine-specific diagnostics (not a stable contract).
    pub engine_stats: BTreeMap<String, f64>,
    /// Time Warp's statistics, under Time Warp.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_warp: Option<TimeWarpSummary>,
    /// Where and why the run stopped before `until`, when it was interrupted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interrupted: Option<Interruption>,
    /// Pressure, compressibility factor, temperature and collision rate, when observed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub observables: Option<crate::observe::Observed>,
    /// g(r), the mean squared displacement and ψ6 at the sample times, when observed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub structure: Option<crate::structure::StructureFigures>,
    /// The regions engine's layout and traffic, when it ran.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub regions: Option<RegionsSummary>,
}

/// How the regions engine cut the table and what crossed its borders.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RegionsSummary {
    /// How many regions (strips of grid columns along x).
    pub count: u32,
    /// Grid columns of each strip, left to right.
    pub columns: Vec<u32>,
    /// Balls each region owned at the start.
    pub balls_start: Vec<usize>,
    /// Balls each region owned at the end.
    pub balls_end: Vec<usize>,
    /// Physical events each region reported (a collision across a border counts for one of
    /// its two regions): how evenly the work was spread.
    pub events: Vec<u64>,
    /// Physical events run by two regions: collisions across a border.
    pub events_across: u64,
    /// Their fraction of all physical events.
    pub fraction_across: f64,
    /// Messages sent, by type: `Wake` (a region's own next event), `GhostEnter`,
    /// `GhostUpdate`, `GhostLeave`, `Handover`, and `Cancel`.
    pub messages: BTreeMap<String, u64>,
}

/// An interrupted run: the time it stopped at, every event up to it done, and the cause.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Interruption {
    /// The time the run stopped at (the final state's time).
    pub at: f64,
    /// The signal's name (`SIGINT`, `SIGTERM`, `SIGHUP`), or `signal N` for another number.
    pub signal: String,
}

impl Interruption {
    /// A run stopped at `at` by signal number `signal`.
    pub fn new(at: f64, signal: usize) -> Interruption {
        let name = match i32::try_from(signal) {
            Ok(libc::SIGINT) => "SIGINT".to_string(),
            Ok(libc::SIGTERM) => "SIGTERM".to_string(),
            Ok(libc::SIGHUP) => "SIGHUP".to_string(),
            _ => format!("signal {signal}"),
        };
        Interruption { at, signal: name }
    }
}

/// Physical events by trace kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EventTotals {
    /// Ball–ball collisions.
    #[serde(rename = "ball-ball")]
    pub ball_ball: u64,
    /// Ball–cushion collisions.
    #[serde(rename = "ball-cushion")]
    pub ball_cushion: u64,
    /// Ball–corner collisions.
    #[serde(rename = "ball-corner")]
    pub ball_corner: u64,
    /// Balls pocketed.
    #[serde(rename = "ball-pocket")]
    pub ball_pocket: u64,
    /// All of them.
    pub total: u64,
}

impl From<&EventCounts> for EventTotals {
    fn from(c: &EventCounts) -> EventTotals {
        EventTotals {
            ball_ball: c.get(EventKind::BallBall),
            ball_cushion: c.get(EventKind::BallCushion),
            ball_corner: c.get(EventKind::BallCorner),
            ball_pocket: c.get(EventKind::BallPocket),
            total: c.total(),
        }
    }
}

/// Messages sent, by type: every type, zero where the engine sends none (the event-list and
/// time-step engines send no messages at all).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[allow(non_snake_case)]
pub struct MessageCounts {
    /// [`MessageKind::NewVelocity`].
    pub NewVelocity: u64,
    /// [`MessageKind::Collision`].
    pub Collision: u64,
    /// [`MessageKind::Cancel`].
    pub Cancel: u64,
    /// [`MessageKind::VelocityChange`].
    pub VelocityChange: u64,
    /// [`MessageKind::SectorEntry`].
    pub SectorEntry: u64,
    /// [`MessageKind::SectorDeparture`].
    pub SectorDeparture: u64,
    /// [`MessageKind::VelocityInitialization`].
    pub VelocityInitialization: u64,
    /// [`MessageKind::DisplayYourself`].
    pub DisplayYourself: u64,
    /// [`MessageKind::ReverseYourself`].
    pub ReverseYourself: u64,
    /// [`MessageKind::ReturnToTable`].
    pub ReturnToTable: u64,
    /// [`MessageKind::CollisionConfirm`].
    pub CollisionConfirm: u64,
    /// The simulation-logic messages the thesis counts ([`MessageKind::THESIS_TOTAL`]).
    pub total: u64,
}

impl MessageCounts {
    /// The counts of `sent`, pairs of a type's name and its count; names that are no message
    /// kind are left out.
    pub fn from_named(sent: &[(&str, u64)]) -> MessageCounts {
        let mut m = MessageCounts::default();
        for &(name, n) in sent {
            if let Some(k) = MessageKind::from_name(name) {
                *m.get_mut(k) += n;
            }
        }
        m.total = MessageKind::THESIS_TOTAL.iter().map(|&k| m.get(k)).sum();
        m
    }

    /// The count of kind `k`.
    pub fn get(&self, k: MessageKind) -> u64 {
        let mut copy = *self;
        *copy.get_mut(k)
    }

    /// Every count by its type's name, and `total`.
    pub fn by_name(&self) -> BTreeMap<String, u64> {
        MessageKind::ALL
            .iter()
            .map(|&k| (k.name().to_string(), self.get(k)))
            .chain([("total".to_string(), self.total)])
            .collect()
    }

    fn get_mut(&mut self, k: MessageKind) -> &mut u64 {
        match k {
            MessageKind::NewVelocity => &mut self.NewVelocity,
            MessageKind::Collision => &mut self.Collision,
            MessageKind::Cancel => &mut self.Cancel,
            MessageKind::VelocityChange => &mut self.VelocityChange,
            MessageKind::SectorEntry => &mut self.SectorEntry,
            MessageKind::SectorDeparture => &mut self.SectorDeparture,
            MessageKind::VelocityInitialization => &mut self.VelocityInitialization,
            MessageKind::DisplayYourself => &mut self.DisplayYourself,
            MessageKind::ReverseYourself => &mut self.ReverseYourself,
            MessageKind::ReturnToTable => &mut self.ReturnToTable,
            MessageKind::CollisionConfirm => &mut self.CollisionConfirm,
        }
    }
}

/// Kinetic energy (mass × length² / time²).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct KineticEnergy {
    /// Of every ball at the start.
    pub initial: f64,
    /// Of the balls on the table at the end.
    #[serde(rename = "final")]
    pub end: f64,
    /// What pocketed balls carried as they dropped in.
    pub pocketed: f64,
    /// (final + pocketed − initial) / initial, 0 when initial is 0.
    pub relative_drift: f64,
}

impl KineticEnergy {
    /// The energies, and the drift they make.
    pub fn new(initial: f64, end: f64, pocketed: f64) -> KineticEnergy {
        KineticEnergy {
            initial,
            end,
            pocketed,
            relative_drift: if initial > 0.0 {
                (end + pocketed - initial) / initial
            } else {
                0.0
            },
        }
    }
}

/// Time Warp's statistics with the ratios read off them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TimeWarpSummary {
    /// The counts.
    #[serde(flatten)]
    pub stats: TwStats,
    /// Committed over processed batches (1 when nothing was processed).
    pub efficiency: f64,
    /// Messages to another worker over all messages (0 when none).
    pub remote_fraction: f64,
    /// The process's peak resident memory (MiB).
    pub peak_rss_mib: f64,
}

impl TimeWarpSummary {
    /// The summary of `stats`, with the process's peak memory `peak_rss_mib`.
    pub fn new(stats: TwStats, peak_rss_mib: f64) -> TimeWarpSummary {
        TimeWarpSummary {
            efficiency: stats.efficiency(),
            remote_fraction: if stats.messages > 0 {
                stats.remote_messages as f64 / stats.messages as f64
            } else {
                0.0
            },
            peak_rss_mib,
            stats,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_counts_name_every_kind_and_total_the_thesis_ones() {
        let sent = [
            ("NewVelocity", 5),
            ("Collision", 3),
            ("Cancel", 2),
            ("DisplayYourself", 7),
            ("CollisionConfirm", 1),
            ("Unknown", 100),
        ];
        let m = MessageCounts::from_named(&sent);
        assert_eq!(m.total, 10);
        assert_eq!(m.get(MessageKind::DisplayYourself), 7);
        let v = serde_json::to_value(m).unwrap();
        for k in MessageKind::ALL {
            assert!(v.get(k.name()).is_some(), "{}", k.name());
        }
        assert_eq!(v.as_object().unwrap().len(), MessageKind::ALL.len() + 1);
    }

    #[test]
    fn a_summary_reads_back_from_its_json() {
        let s = RunSummary {
            scenario: "gas".into(),
            engine: "event-list".into(),
            balls: 4,
            until: 1.0,
            events: EventTotals {
                ball_ball: 2,
                total: 2,
                ..EventTotals::default()
            },
            messages: MessageCounts::default(),
            kinetic_energy: KineticEnergy::new(2.0, 2.0, 0.0),
            final_state_digest: "0123456789abcdef".into(),
            wall_seconds: 0.5,
            setup_seconds: 0.1,
            events_per_second: 4.0,
            checked: false,
            engine_stats: BTreeMap::new(),
            time_warp: None,
            interrupted: None,
            observables: None,
            structure: None,
            regions: None,
        };
        let text = serde_json::to_string(&s).unwrap();
        assert!(
            text.contains("\"ball-ball\":2") && text.contains("\"final\":2.0"),
            "{text}"
        );
        assert!(!text.contains("time_warp"), "{text}");
        assert!(!text.contains("interrupted"), "{text}");
        assert_eq!(serde_json::from_str::<RunSummary>(&text).unwrap(), s);
        let stopped = RunSummary {
            interrupted: Some(Interruption::new(0.25, libc::SIGTERM as usize)),
            ..s
        };
        let text = serde_json::to_string(&stopped).unwrap();
        assert!(
            text.contains(r#""interrupted":{"at":0.25,"signal":"SIGTERM"}"#),
            "{text}"
        );
        assert_eq!(serde_json::from_str::<RunSummary>(&text).unwrap(), stopped);
    }
}
