//! Checkpoints: a run's complete state at a time between events, from which a run is taken up
//! exactly (`poolsim run --checkpoint FILE --checkpoint-every T`, `poolsim resume FILE`).
//!
//! Every engine that computes events from trajectories computes the same keys from the same
//! trajectories, so a checkpoint holds, for each ball, its trajectory as last fixed (the centre
//! at that time and the velocity), the key of the event that fixed it, and its pocket: a run
//! set up from them (each engine's own set-up, predictions and messages made afresh) executes
//! the same physical events at the same keys as the run that wrote it, on any engine and any
//! number of workers. The file is JSON (`docs/formats.md`), written atomically.

use crate::scenario::{Scenario, ScenarioError};
use crate::summary::EventTotals;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

/// The `format` field of every checkpoint.
pub const FORMAT: &str = "poolsim-checkpoint";

/// The version of the format this build writes and reads.
pub const VERSION: u32 = 1;

/// A run's complete state at time `t`: every event up to `t` has happened, none after it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`] when written.
    pub version: u32,
    /// The checkpoint's time.
    pub t: f64,
    /// The end time the run was asked for.
    pub until: f64,
    /// The engine that wrote it (any engine but the time-step one may take it up).
    pub engine: String,
    /// The scenario, its balls as the run held them at `t`: each with the key that fixed its
    /// trajectory (its `position` is the centre at that key's time) and its pocket.
    pub scenario: Scenario,
    /// Physical events executed from the run's start up to `t`.
    pub events: EventTotals,
    /// Kinetic energy of the balls at the run's start.
    pub initial_energy: f64,
    /// Where the trace stood at `t`, when the run wrote one to a file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trace: Option<TraceMark>,
}

/// How much of a trace file belongs to the run up to a checkpoint.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct TraceMark {
    /// The file, as the run was given it.
    pub path: String,
    /// Its bytes up to the checkpoint (whole lines).
    pub bytes: u64,
    /// Its lines up to the checkpoint.
    pub lines: u64,
}

impl Checkpoint {
    /// Reads and checks the checkpoint at `path`; a fault is one line naming the file and
    /// the field.
    pub fn read(path: &Path) -> Result<Checkpoint, ScenarioError> {
        let source = path.display().to_string();
        let fail = |field: &str, message: String| ScenarioError {
            source: source.clone(),
            line: None,
            field: field.to_string(),
            message,
        };
        let text = std::fs::read_to_string(path)
            .map_err(|e| fail("", format!("cannot read the checkpoint: {e}")))?;
        let cp: Checkpoint = serde_json::from_str(&text).map_err(|e| ScenarioError {
            source: source.clone(),
            line: Some(e.line()),
            field: String::new(),
            message: format!("not a checkpoint: {e}"),
        })?;
        if cp.format != FORMAT || cp.version != VERSION {
            return Err(fail(
                "format",
                format!(
                    "expected {FORMAT} version {VERSION}, got {} version {}",
                    cp.format, cp.version
                ),
            ));
        }
        if !(cp.t.is_finite() && cp.until.is_finite()) {
            return Err(fail(
                "t",
                format!("must be finite, got {} and until {}", cp.t, cp.until),
            ));
        }
        cp.scenario
            .validate_taken_up(cp.t)
            .map_err(|e| fail(&format!("scenario.{}", e.field), e.message))?;
        Ok(cp)
    }

    /// Writes the checkpoint to `path` atomically: to a file beside it, flushed to disk, then
    /// renamed over it, so that `path` always holds a whole checkpoint, the last or the one
    /// before.
    pub fn write(&self, path: &Path) -> std::io::Result<()> {
        let text = serde_json::to_vec(self).map_err(std::io::Error::other)?;
        write_atomically(path, &text)
    }
}

/// Writes `bytes` to `path` atomically: a temporary file in the same folder, synced, renamed
/// over `path`, and the folder synced so that the rename lasts.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    // readable as any file the run writes (a temporary file is the owner's alone)
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    let mut tmp = builder.tempfile_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    std::fs::File::open(dir)?.sync_all()
}
