//! Sinks for what a run produces: the trace (JSON Lines), the final state (JSON), the bit-exact
//! digest of the final state, and event counting. Formats are the contracts of DESIGN.md.

use crate::engine::{BallState, Event, Observer, RunError, Table, World};
use crate::geometry::PeriodicBox;
use crate::scenario::{BallSpec, CushionSpec, Invalid, PocketSpec, Scenario};
use serde::Serialize;
use std::io::Write;

/// One trace line, as written: `{"t": 1.25, "kind": "ball-ball", "objects": ["Ball-1", "Ball-2"]}`.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct TraceLine {
    /// Time of the event.
    pub t: f64,
    /// `ball-ball`, `ball-cushion`, `ball-corner` or `ball-pocket`.
    pub kind: String,
    /// The two objects, lower index first.
    pub objects: [String; 2],
}

impl TraceLine {
    /// The trace line of an event on `table`.
    pub fn new(ev: &Event, table: &Table) -> TraceLine {
        TraceLine {
            t: ev.t,
            kind: ev.kind.name().to_string(),
            objects: [table.name(ev.a), table.name(ev.b)],
        }
    }
}

/// Writes one JSON line per event to `out`.
pub struct TraceWriter<W: Write> {
    out: W,
    lines: u64,
}

impl<W: Write> TraceWriter<W> {
    /// A trace writer over `out` (wrap files in a `BufWriter`) that holds `lines` lines already.
    pub fn new(out: W, lines: u64) -> TraceWriter<W> {
        TraceWriter { out, lines }
    }

    /// The lines in the trace so far.
    pub fn lines(&self) -> u64 {
        self.lines
    }

    /// Writes out what is buffered.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }

    /// Flushes and returns the writer.
    pub fn finish(mut self) -> std::io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

impl<W: Write> Observer for TraceWriter<W> {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        let line = TraceLine::new(ev, world.table());
        serde_json::to_writer(&mut self.out, &line).map_err(|e| RunError::Output(e.to_string()))?;
        self.lines += 1;
        self.out
            .write_all(b"\n")
            .map_err(|e| RunError::Output(e.to_string()))
    }

    fn reads_balls(&self) -> bool {
        false
    }
}

/// Keeps every event's trace line in memory (for tests and for comparing engines).
#[derive(Default)]
pub struct TraceRecorder {
    /// The lines so far.
    pub lines: Vec<TraceLine>,
}

impl Observer for TraceRecorder {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        self.lines.push(TraceLine::new(ev, world.table()));
        Ok(())
    }

    fn reads_balls(&self) -> bool {
        false
    }
}

/// One ball in the final state file.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FinalBall {
    /// `Ball-k`.
    pub name: String,
    /// Centre at the end time, or where it crossed into its pocket.
    pub position: [f64; 2],
    /// Velocity at the end time (zero in a pocket).
    pub velocity: [f64; 2],
    /// Radius.
    pub radius: f64,
    /// Mass.
    pub mass: f64,
    /// The pocket holding it (`Pocket-k`), or null.
    pub pocket: Option<String>,
    /// Its colour in pictures, if the scenario gave one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub colour: Option<String>,
    /// Its label in pictures, if the scenario gave one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
}

/// The final state file: the end time, every ball, and the table, so that it can start
/// another run (`poolsim run FILE.json`).
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FinalState {
    /// The end time.
    pub t: f64,
    /// Every ball, `Ball-1` first.
    pub balls: Vec<FinalBall>,
    /// The cushions, `Cushion-1` first.
    pub cushions: Vec<CushionSpec>,
    /// The pockets, `Pocket-1` first.
    pub pockets: Vec<PocketSpec>,
    /// The periodic box, where the boundary is periodic (the positions then lie in it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub periodic: Option<PeriodicBox>,
}

impl FinalState {
    /// The final state of balls fixed at time `t` on the table of scenario `s`.
    pub fn new(t: f64, balls: &[BallState], s: &Scenario) -> FinalState {
        FinalState {
            t,
            balls: balls
                .iter()
                .enumerate()
                .map(|(i, b)| FinalBall {
                    name: format!("Ball-{}", i + 1),
                    position: b.position(t).into(),
                    velocity: b.velocity().into(),
                    radius: b.radius,
                    mass: b.mass,
                    pocket: b.pocket.map(|k| format!("Pocket-{}", k + 1)),
                    colour: s.balls.get(i).and_then(|b| b.colour.clone()),
                    label: s.balls.get(i).and_then(|b| b.label.clone()),
                })
                .collect(),
            cushions: s.cushions.clone(),
            pockets: s.pockets.clone(),
            periodic: s.periodic,
        }
    }

    /// The scenario that starts where this state ends: its balls at time 0 where they are
    /// at `t` (balls in pockets stay there), on the same table, to run until `until`.
    pub fn to_scenario(&self, name: &str, until: f64) -> Result<Scenario, Invalid> {
        let balls = self
            .balls
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let pocket = match &b.pocket {
                    None => None,
                    Some(p) => {
                        Some(pocket_index(p, self.pockets.len()).ok_or_else(|| Invalid {
                            field: format!("balls[{}].pocket", i + 1),
                            message: format!(
                                "names {p}, not one of the {} pockets (Pocket-1 ...)",
                                self.pockets.len()
                            ),
                        })?)
                    }
                };
                Ok(BallSpec {
                    position: b.position.into(),
                    velocity: b.velocity.into(),
                    radius: b.radius,
                    mass: b.mass,
                    fixed: None,
                    pocket,
                    colour: b.colour.clone(),
                    label: b.label.clone(),
                })
            })
            .collect::<Result<Vec<_>, Invalid>>()?;
        Ok(Scenario {
            name: name.to_string(),
            until,
            balls,
            cushions: self.cushions.clone(),
            pockets: self.pockets.clone(),
            sectors: None,
            periodic: self.periodic,
        })
    }
}

/// The index (from 0) of pocket `Pocket-k` among `n`.
fn pocket_index(name: &str, n: usize) -> Option<u32> {
    let k: u32 = name.strip_prefix("Pocket-")?.parse().ok()?;
    (k >= 1 && k as usize <= n).then(|| k - 1)
}

/// A 64-bit FNV-1a hash, in hex, of every ball's final position and velocity bits (and pocket):
/// equal digests mean bit-identical final states.
pub fn digest(t: f64, balls: &[BallState]) -> String {
    fnv_hex(balls.iter().flat_map(|b| {
        let p = b.position(t);
        let v = b.velocity();
        [p.x, p.y, v.x, v.y]
            .map(f64::to_bits)
            .into_iter()
            .chain([b.pocket.map_or(u64::MAX, u64::from)])
    }))
}

pub use pdes_kernel::digest::fnv_hex;
