//! `poolsim compress`: Lubachevsky-Stillinger growth of the disks of a periodic box to a target
//! area fraction or to jamming; writes the packing as a final state that starts other runs.

use crate::common::{load, run_failure, usage, Failure, GenArgs, LatticeArg};
use crate::signals::{interrupted, stop_on_signals};
use poolsim::compress::{compress, CompressConfig, Compressed, Cycle, Ending};
use poolsim::engine::BallState;
use poolsim::output::FinalState;
use std::io::Write;
use std::path::PathBuf;

/// `poolsim compress`'s arguments.
#[derive(clap::Args, Debug)]
pub struct CompressArgs {
    /// The start: `disks` (by default a random start, periodic, at area fraction 0.2), a
    /// scenario file, a final state or an extended XYZ file; in a periodic box.
    #[arg(default_value = "disks")]
    pub scenario: String,
    #[command(flatten)]
    pub gen: GenArgs,
    /// The smallest disk's diameter gained per unit time, with kT = m = 1.
    #[arg(long, default_value_t = 0.01)]
    pub rate: f64,
    /// Stop once the disks cover this area fraction (default: compress until jammed).
    #[arg(long)]
    pub target: Option<f64>,
    /// Jammed once a cycle's reduced pressure P A / (N kT) passes this.
    #[arg(long = "max-pressure", default_value_t = 1e12)]
    pub max_pressure: f64,
    /// Ball-ball collisions per disk between two rescalings of the velocities to kT = 1.
    #[arg(long = "cycle-collisions", default_value_t = 2.0)]
    pub cycle_collisions: f64,
    /// Write the packing here, as a final state (a start for `poolsim run`).
    #[arg(long = "final-state", default_value = "compressed.json")]
    pub final_state: PathBuf,
    /// Write each cycle's figures here, one JSON object per line.
    #[arg(long)]
    pub cycles: Option<PathBuf>,
    /// Check every event for overlaps.
    #[arg(long)]
    pub check: bool,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
    /// No progress line on stderr.
    #[arg(long)]
    pub quiet: bool,
}

/// The summary of a compression.
#[derive(serde::Serialize)]
struct Summary<'a> {
    disks: usize,
    rate: f64,
    ending: Ending,
    area_fraction: f64,
    z: f64,
    t: f64,
    cycles: usize,
    collisions: u64,
    wall_s: f64,
    final_state: &'a std::path::Path,
}

/// Runs `poolsim compress`.
pub fn run_compress(a: &CompressArgs) -> Result<(), Failure> {
    let mut gen = a.gen.clone();
    if a.scenario == "disks" {
        gen.boundary
            .get_or_insert(crate::common::BoundaryArg::Periodic);
        gen.lattice.get_or_insert(LatticeArg::Random);
        gen.area_fraction.get_or_insert(0.2);
    }
    let start = load(&a.scenario, &gen)?;
    let cfg = CompressConfig {
        rate: a.rate,
        target: a.target,
        max_pressure: a.max_pressure,
        cycle_collisions: a.cycle_collisions,
        check: a.check,
        ..CompressConfig::default()
    };
    cfg.check(&start).map_err(|e| usage(e.to_string()))?;
    let mut cycles_out = match &a.cycles {
        Some(p) => Some(std::io::BufWriter::new(std::fs::File::create(p).map_err(
            |e| usage(format!("{}: cannot write the cycles: {e}", p.display())),
        )?)),
        None => None,
    };
    let mut write_failed = None;
    let bar = progress_line(a.quiet);
    let mut on_cycle = |c: &Cycle| {
        if let Some(b) = &bar {
            b.set_message(format!(
                "cycle at t = {:.4}: area fraction {:.6}, reduced pressure {:.3e}",
                c.t, c.area_fraction, c.z
            ));
        }
        if let Some(w) = cycles_out.as_mut() {
            let line = serde_json::to_string(c).expect("plain data");
            if let Err(e) = writeln!(w, "{line}") {
                write_failed.get_or_insert(e);
            }
        }
    };
    let interrupt = pdes_kernel::Interrupt::new();
    stop_on_signals(&interrupt)?;
    let clock = std::time::Instant::now();
    let done = compress(&start, &cfg, Some(&interrupt), &mut on_cycle).map_err(run_failure)?;
    let wall_s = clock.elapsed().as_secs_f64();
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if let Some(mut w) = cycles_out {
        if let Err(e) = w.flush() {
            write_failed.get_or_insert(e);
        }
    }
    if let (Some(e), Some(p)) = (write_failed, &a.cycles) {
        return Err(usage(format!(
            "{}: cannot write the cycles: {e}",
            p.display()
        )));
    }
    write_packing(&a.final_state, &done)?;
    print_summary(a, &done, wall_s)?;
    interrupted(&interrupt, done.t)
}

/// A spinner with the last cycle's figures on stderr, when it is a terminal and not `quiet`.
fn progress_line(quiet: bool) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] compress: {msg}")
            .expect("a valid template"),
    );
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    Some(bar)
}

/// Writes the packing as a final state at time 0 (the start of whatever runs from it).
fn write_packing(p: &std::path::Path, done: &Compressed) -> Result<(), Failure> {
    let balls = BallState::initial(&done.scenario, 0.0);
    let fs = FinalState::new(0.0, &balls, &done.scenario);
    let text = serde_json::to_string_pretty(&fs).expect("a final state serializes");
    std::fs::write(p, text + "\n")
        .map_err(|e| usage(format!("{}: cannot write the packing: {e}", p.display())))
}

/// Prints the summary: one JSON object, or lines for a reader.
fn print_summary(a: &CompressArgs, done: &Compressed, wall_s: f64) -> Result<(), Failure> {
    let summary = Summary {
        disks: done.scenario.balls.len(),
        rate: a.rate,
        ending: done.ending,
        area_fraction: done.area_fraction(),
        z: done.z(),
        t: done.t,
        cycles: done.cycles.len(),
        collisions: done.collisions(),
        wall_s,
        final_state: &a.final_state,
    };
    let text = if a.json {
        serde_json::to_string(&summary).expect("plain data") + "\n"
    } else {
        let why = match done.ending {
            Ending::Target => "reached the target",
            Ending::Jammed => "jammed",
            Ending::Interrupted => "interrupted",
        };
        format!(
            "compress      {} disks at rate {}: {why} at area fraction {:.6}, reduced pressure \
             {:.4e}\n              t = {:.6}, {} cycles, {} collisions, {:.2} s\n\
             packing       {}\n",
            summary.disks,
            a.rate,
            summary.area_fraction,
            summary.z,
            summary.t,
            summary.cycles,
            summary.collisions,
            wall_s,
            a.final_state.display()
        )
    };
    std::io::stdout()
        .write_all(text.as_bytes())
        .map_err(|e| usage(format!("writing the summary failed: {e}")))
}
