//! Sinks for what a run produces: the trace (JSON Lines), the final state (JSON), the bit-exact
//! digest of the final state, and event counting. Formats are the contracts of DESIGN.md.

use crate::engine::{BallState, Event, Observer, RunError, Table, World};
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
pub struct FinalBall {
    /// `Ball-k`.
    pub name: String,
    /// Centre at the end time, or where it crossed into its pocket.
    pub position: [f64; 2],
    /// Velocity at the end time (zero in a pocket).
    pub velocity: [f64; 2],
    /// The pocket holding it (`Pocket-k`), or null.
    pub pocket: Option<String>,
}

/// The final state file: `{"t": T, "balls": [...]}`.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct FinalState {
    /// The end time.
    pub t: f64,
    /// Every ball, `Ball-1` first.
    pub balls: Vec<FinalBall>,
}

impl FinalState {
    /// The final state of balls fixed at time `t`.
    pub fn new(t: f64, balls: &[BallState]) -> FinalState {
        FinalState {
            t,
            balls: balls
                .iter()
                .enumerate()
                .map(|(i, b)| FinalBall {
                    name: format!("Ball-{}", i + 1),
                    position: b.position(t).into(),
                    velocity: b.velocity().into(),
                    pocket: b.pocket.map(|k| format!("Pocket-{}", k + 1)),
                })
                .collect(),
        }
    }
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
