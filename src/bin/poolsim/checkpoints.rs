//! Checkpoints on the command line: `poolsim run --checkpoint FILE [--checkpoint-every T]`
//! writes them, `poolsim resume FILE` takes a run up from one, cutting its trace back to the
//! checkpoint so that no line appears twice.

use crate::common::{usage, Failure};
use crate::run::{run_from, RunArgs};
use crate::values::Engine;
use poolsim::checkpoint::{Checkpoint, TraceMark};
use poolsim::engine::RunError;
use poolsim::output::TraceWriter;
use poolsim::summary::EventTotals;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// The trace of a run: its writer, and the file beneath it (none for stdout) to sync.
pub struct Trace {
    /// Writes the lines.
    pub writer: TraceWriter<BufWriter<Box<dyn Write>>>,
    /// The file, for syncing it to disk before a checkpoint counts its bytes.
    pub file: Option<File>,
}

/// Opens the trace at `p`: stdout for `-`; the file cut back to `mark` when the run takes up a
/// checkpoint whose trace is this file; else a new file.
pub fn open_trace(p: &Path, mark: Option<&TraceMark>) -> Result<Trace, Failure> {
    if p.as_os_str() == "-" {
        let out: Box<dyn Write> = Box::new(std::io::stdout());
        return Ok(Trace {
            writer: TraceWriter::new(BufWriter::new(out), 0),
            file: None,
        });
    }
    let cannot = |e: std::io::Error| usage(format!("{}: cannot open the trace: {e}", p.display()));
    let same = |m: &&TraceMark| {
        let canon = |q: &Path| q.canonicalize().ok();
        canon(Path::new(&m.path)).is_some_and(|c| canon(p) == Some(c))
    };
    let (file, lines) = match mark.filter(same) {
        Some(m) => {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .open(p)
                .map_err(cannot)?;
            cut_back(&mut file, p, m)?;
            (file, m.lines)
        }
        None => (File::create(p).map_err(cannot)?, 0),
    };
    let sync = file.try_clone().map_err(cannot)?;
    let out: Box<dyn Write> = Box::new(file);
    Ok(Trace {
        writer: TraceWriter::new(BufWriter::new(out), lines),
        file: Some(sync),
    })
}

/// Cuts the trace `file` back to the checkpoint's `mark` and leaves it positioned there, after
/// checking that it holds at least that much, ending on a whole line.
fn cut_back(file: &mut File, p: &Path, mark: &TraceMark) -> Result<(), Failure> {
    let fail = |m: String| usage(format!("{}: {m}", p.display()));
    let len = file.metadata().map_err(|e| fail(e.to_string()))?.len();
    if len < mark.bytes {
        return Err(fail(format!(
            "the trace holds {len} bytes, fewer than the {} the checkpoint counts",
            mark.bytes
        )));
    }
    if mark.bytes > 0 {
        let mut last = [0u8];
        file.seek(SeekFrom::Start(mark.bytes - 1))
            .and_then(|_| file.read_exact(&mut last))
            .map_err(|e| fail(e.to_string()))?;
        if last[0] != b'\n' {
            return Err(fail(format!(
                "the trace does not end a line at byte {}, where the checkpoint cuts it",
                mark.bytes
            )));
        }
    }
    file.set_len(mark.bytes)
        .and_then(|_| file.seek(SeekFrom::End(0)))
        .map(|_| ())
        .map_err(|e| fail(format!("cannot cut the trace back: {e}")))
}

/// Where checkpoints go, and what a run taken up from one adds to its own counts.
pub struct Saver {
    /// The checkpoint file.
    pub path: PathBuf,
    /// The trace file's name as given, when the trace goes to a file.
    pub trace_path: Option<String>,
    /// Events before the run's start and the energy at the first run's start, when the run
    /// took up a checkpoint.
    pub base: Option<(EventTotals, f64)>,
}

impl Saver {
    /// Writes `cp` atomically, after the trace is on disk up to it (its lines and bytes
    /// counted in the checkpoint).
    pub fn save(&self, mut cp: Checkpoint, trace: Option<&mut Trace>) -> Result<(), RunError> {
        let failed = |what: &str, e: std::io::Error| RunError::Output(format!("{what}: {e}"));
        if let (Some(t), Some(path)) = (trace, &self.trace_path) {
            t.writer.flush().map_err(|e| failed(path, e))?;
            if let Some(f) = &t.file {
                f.sync_data().map_err(|e| failed(path, e))?;
                cp.trace = Some(TraceMark {
                    path: path.clone(),
                    bytes: f.metadata().map_err(|e| failed(path, e))?.len(),
                    lines: t.writer.lines(),
                });
            }
        }
        if let Some((events, energy)) = self.base {
            cp.events = add(events, cp.events);
            cp.initial_energy = energy;
        }
        let shown = self.path.display().to_string();
        cp.write(&self.path)
            .map_err(|e| failed(&format!("{shown}: writing the checkpoint"), e))
    }
}

/// Two runs' event counts together.
pub fn add(a: EventTotals, b: EventTotals) -> EventTotals {
    EventTotals {
        ball_ball: a.ball_ball + b.ball_ball,
        ball_cushion: a.ball_cushion + b.ball_cushion,
        ball_corner: a.ball_corner + b.ball_corner,
        ball_pocket: a.ball_pocket + b.ball_pocket,
        total: a.total + b.total,
    }
}

/// `poolsim resume`: takes the run of the checkpoint up to `--until` (the checkpoint's own end
/// by default), continuing the trace it names unless `--trace` says otherwise.
pub fn resume(a: &RunArgs) -> Result<(), Failure> {
    let g = &a.gen;
    if g.balls.is_some()
        || g.seed.is_some()
        || g.area_fraction.is_some()
        || g.radius.is_some()
        || g.speed_max.is_some()
    {
        return Err(usage(
            "a checkpoint holds its balls: --balls, --seed, --area-fraction, --radius and \
             --speed-max are for built-in scenarios",
        ));
    }
    if a.engine == Engine::TimeStep {
        return Err(usage(
            "--engine: the time-step engine does not take up a checkpoint (its state is its \
             grid of steps)",
        ));
    }
    let cp = Checkpoint::read(Path::new(&a.scenario)).map_err(|e| usage(e.to_string()))?;
    let mut a = a.clone();
    if a.trace.is_none() {
        a.trace = cp.trace.as_ref().map(|m| PathBuf::from(&m.path));
    }
    run_from(&a, &cp.scenario, Some(&cp))
}
