//! What several commands share: generator options, loading a scenario, failures and their exit
//! statuses, the progress line, Time Warp's worker count, MPI start-up.

use indicatif::{ProgressBar, ProgressStyle};
use pdes_kernel::time_warp::TwConfig;
use poolsim::engine::{Event, Observer, RunError, World};
use poolsim::scenario::{self, builtin, Scenario};
use std::io::IsTerminal;

/// Parameters of generated scenarios.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct GenArgs {
    /// Number of balls.
    #[arg(long)]
    pub balls: Option<usize>,
    /// Random seed of generated scenarios.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Fraction of the table's area covered by balls (gas).
    #[arg(long = "area-fraction")]
    pub area_fraction: Option<f64>,
    /// Ball radius (gas).
    #[arg(long)]
    pub radius: Option<f64>,
    /// Speeds are drawn uniform in [0, V) (gas, reversal).
    #[arg(long = "speed-max")]
    pub speed_max: Option<f64>,
    /// The lattice the disks start on: triangular, square, or random (sequential addition)
    /// (disks).
    #[arg(long, value_enum)]
    pub lattice: Option<LatticeArg>,
    /// Maxwell-Boltzmann velocities with this kinetic energy per disk, zero total momentum
    /// (disks).
    #[arg(long, allow_negative_numbers = true)]
    pub temperature: Option<f64>,
    /// A binary mixture F:Q: a fraction F of the disks large, Q times as wide (disks).
    #[arg(long, value_parser = parse_mixture)]
    pub mixture: Option<builtin::Mixture>,
    /// What bounds the box: walled (elastic cushions, the default) or periodic (gas, disks).
    #[arg(long, value_enum)]
    pub boundary: Option<BoundaryArg>,
}

/// `--boundary`: what bounds a generated box.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoundaryArg {
    /// Four elastic cushions.
    Walled,
    /// No walls: a ball leaving through one side comes back through the opposite one.
    Periodic,
}

/// `--lattice`: the sites a start's disks stand on.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum LatticeArg {
    /// Six neighbours per site.
    Triangular,
    /// Four neighbours per site.
    Square,
    /// No lattice: random sequential addition (up to about 0.5 of the area).
    Random,
}

/// Parses `--mixture F:Q`.
fn parse_mixture(text: &str) -> Result<builtin::Mixture, String> {
    let (f, q) = text
        .split_once(':')
        .ok_or_else(|| format!("expected F:Q (a fraction and a diameter ratio), got {text:?}"))?;
    let number = |s: &str| {
        s.trim()
            .parse::<f64>()
            .map_err(|_| format!("expected F:Q (a fraction and a diameter ratio), got {text:?}"))
    };
    Ok(builtin::Mixture {
        large: number(f)?,
        ratio: number(q)?,
    })
}

impl GenArgs {
    fn params(&self) -> builtin::Params {
        builtin::Params {
            balls: self.balls,
            seed: self.seed,
            area_fraction: self.area_fraction,
            radius: self.radius,
            speed_max: self.speed_max,
            lattice: self.lattice.map(|l| match l {
                LatticeArg::Triangular => builtin::Lattice::Triangular,
                LatticeArg::Square => builtin::Lattice::Square,
                LatticeArg::Random => builtin::Lattice::Random,
            }),
            temperature: self.temperature,
            mixture: self.mixture,
            boundary: self.boundary.map(|b| match b {
                BoundaryArg::Walled => builtin::Boundary::Walled,
                BoundaryArg::Periodic => builtin::Boundary::Periodic,
            }),
        }
    }
}

/// A failure with its exit status.
pub struct Failure {
    pub code: u8,
    pub message: String,
}

pub fn usage(message: impl Into<String>) -> Failure {
    Failure {
        code: 2,
        message: message.into(),
    }
}

pub fn internal(message: impl Into<String>) -> Failure {
    Failure {
        code: 1,
        message: message.into(),
    }
}

/// Shows progress in simulated time on stderr.
pub struct Progress {
    pub bar: ProgressBar,
    pub until: f64,
    pub seen: u64,
    /// The trace file, whose size the line shows.
    pub trace: Option<std::path::PathBuf>,
}

impl Progress {
    /// The progress line of a run to `until` (none when quiet or stderr is not a terminal);
    /// with a trace file, it shows how much of the trace is written.
    pub fn new(until: f64, quiet: bool, trace: Option<&std::path::Path>) -> Option<Progress> {
        if quiet || !std::io::stderr().is_terminal() || until.is_nan() || until <= 0.0 {
            return None;
        }
        let bar = ProgressBar::new(1000);
        bar.set_style(
            ProgressStyle::with_template("{spinner} [{elapsed_precise}] {wide_bar} {msg}")
                .expect("a valid template"),
        );
        // the spinner and clock move even before the first event: setting up a large sectored
        // table takes a while
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        bar.set_message(format!("t = 0 / {until}, 0 events"));
        Some(Progress {
            bar,
            until,
            seen: 0,
            trace: trace.filter(|p| p.as_os_str() != "-").map(Into::into),
        })
    }
}

impl Observer for Progress {
    fn on_event(&mut self, ev: &Event, _: &dyn World) -> Result<(), RunError> {
        self.seen += 1;
        if self.seen.is_multiple_of(8192) {
            self.bar
                .set_position((ev.t / self.until * 1000.0).clamp(0.0, 1000.0) as u64);
            let written = match self.trace.as_deref().map(std::fs::metadata) {
                Some(Ok(m)) => format!(", trace {}", poolsim::memory::human_bytes(m.len())),
                _ => String::new(),
            };
            self.bar.set_message(format!(
                "t = {:.3} / {}, {} events{written}",
                ev.t, self.until, self.seen
            ));
        }
        Ok(())
    }

    fn reads_balls(&self) -> bool {
        false
    }
}

pub fn load(spec: &str, gen: &GenArgs) -> Result<Scenario, Failure> {
    scenario::load(spec, &gen.params()).map_err(|e| usage(e.to_string()))
}

/// A run's failure: bad input (exit 2) or the run's own (exit 1).
pub fn run_failure(e: RunError) -> Failure {
    match e {
        RunError::Input(m) => usage(m),
        e @ RunError::Layout(_) => usage(e.to_string()),
        e => internal(e.to_string()),
    }
}

/// MPI, when this process was started by `mpirun` (cargo feature `mpi`), held for the run.
#[cfg(feature = "mpi")]
pub fn start_mpi() -> Result<Option<mpi::environment::Universe>, Failure> {
    let launched = ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"]
        .iter()
        .any(|v| std::env::var_os(v).is_some());
    if !launched {
        return Ok(None);
    }
    use mpi::Threading;
    match mpi::initialize_with_threading(Threading::Serialized) {
        Some((u, Threading::Serialized | Threading::Multiple)) => Ok(Some(u)),
        Some(_) => Err(internal(
            "MPI: the library cannot serve calls from several threads (MPI_THREAD_SERIALIZED)",
        )),
        None => Err(internal("MPI: initialization failed")),
    }
}

/// `--tw-burst`, checked: at least one batch.
pub fn burst(n: Option<u32>) -> Result<Option<u32>, Failure> {
    match n {
        Some(0) => Err(usage("--tw-burst: must be at least 1")),
        n => Ok(n),
    }
}

/// Time Warp's default settings with `--workers` (default: this machine's cores) and
/// `POOLSIM_CHAOS`.
pub fn tw_workers(workers: Option<usize>) -> Result<TwConfig, Failure> {
    let mut tw = TwConfig {
        workers: std::thread::available_parallelism().map_or(1, |n| n.get()),
        chaos: chaos_from_env().map_err(usage)?,
        ..TwConfig::default()
    };
    if let Some(w) = workers {
        if !(1..=1024).contains(&w) {
            return Err(usage(format!("--workers: must be 1 to 1024, got {w}")));
        }
        tw.workers = w;
    }
    Ok(tw)
}

/// Seeds for chaos mode from `POOLSIM_CHAOS`, when set to a number.
pub fn chaos_from_env() -> Result<Option<u64>, String> {
    match std::env::var("POOLSIM_CHAOS") {
        Err(_) => Ok(None),
        Ok(s) if s.is_empty() => Ok(None),
        Ok(s) => s
            .parse()
            .map(Some)
            .map_err(|_| format!("POOLSIM_CHAOS: expected a seed (an integer), got `{s}`")),
    }
}
