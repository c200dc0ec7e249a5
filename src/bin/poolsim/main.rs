//! `poolsim`: the command line over the library. Parses arguments, loads the scenario, runs the
//! pipeline of `poolsim::run`, writes the outputs. Exit status: 0 done, 2 bad input or usage,
//! 1 internal failure or a failed `--check`.

mod bench;
mod checkpoints;
mod common;
mod compress;
mod experiment;
mod model;
mod phold;
mod render;
mod reverse;
mod run;
mod signals;
mod values;

use clap::{Parser, Subcommand};
use model::*;
use phold::*;
use poolsim::scenario::builtin;
use render::*;
use reverse::*;
use run::*;
use std::path::PathBuf;
use std::process::ExitCode;

/// mimalloc: Time Warp's saved states and messages churn the heap; glibc's per-thread arenas
/// hand pages back and fault them in again (a fifth of a worker's time, measured).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// `mi_option_purge_delay`, entry 15 of `mi_option_t` in mimalloc.h (v2 and v3 alike; the Rust
/// bindings do not name it).
const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Lets mimalloc keep the memory it frees instead of handing it back to the system after 10 ms:
/// the engines free and reallocate large blocks all the time, and with transparent huge pages
/// every block handed back costs the kernel a 2 MiB page to zero when it is touched again (a
/// sixth of the sectored objects engine's time at 16k balls, measured with perf; a one-second
/// delay did not help). Resident memory then stays at its peak, which is what a run reports.
fn keep_freed_memory() {
    // SAFETY: sets one of mimalloc's global options, which mimalloc allows at any time.
    unsafe { libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, -1) }
}

#[derive(Parser)]
#[command(
    name = "poolsim",
    version,
    about = "Exact event-driven simulation of pool balls and hard disks (after Goldberg, UCLA 1984)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in scenarios.
    Scenarios,
    /// Run a scenario.
    Run(Box<RunArgs>),
    /// The main job: run the thesis' 36-ball gas with checks on and print the summary.
    Demo {
        /// Print the summary as JSON.
        #[arg(long)]
        json: bool,
        /// Where to write the player page (or FILE.gif, or a folder of frames).
        #[arg(long, default_value = "poolsim-demo.html")]
        out: PathBuf,
    },
    /// Draw a run's frames (thesis 4.2): a folder of SVG and PNG frames, FILE.gif, or FILE.html
    /// (one self-contained page with a player).
    Render(Box<RenderArgs>),
    /// Measure events per second over ball counts and densities.
    Bench(bench::BenchArgs),
    /// Run PHOLD, the standard PDES benchmark, and report committed events per second.
    Phold(PholdArgs),
    /// The analytic model of message counts (thesis ch. 7): F(s) and the best sector size.
    Model(ModelArgs),
    /// Run the thesis' chapter 6 experiment (tables 5-10, figures 17-18) and write a report.
    Experiment(experiment::ExperimentArgs),
    /// Run from -Q to 0, reverse every ball, run on to Q, and report how far the balls end from
    /// where they started (thesis 4.6-4.7).
    Reverse(Box<ReverseArgs>),
    /// Take a run up from a checkpoint (`run --checkpoint FILE`) and run it on to --until (the
    /// checkpoint's own end by default), continuing its trace; any engine but the time-step
    /// one ends in the same state.
    Resume(Box<RunArgs>),
    /// Grow the disks of a periodic box (Lubachevsky-Stillinger) to a target area fraction or
    /// until they jam, and write the packing as a final state.
    Compress(Box<compress::CompressArgs>),
}

/// Lets a closed pipe end the process quietly, as it does every Unix filter (`poolsim bench |
/// head`): Rust ignores SIGPIPE, and printing to a closed pipe would then panic.
fn die_quietly_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: restores the default action of one signal before any thread is started.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Parses the command line; every subcommand takes negative numbers as values, so that a
/// negative value is reported by the check of its option, not as an unknown option.
fn parse_command_line() -> Result<Cli, clap::Error> {
    use clap::{CommandFactory, FromArgMatches};
    let mut cmd = Cli::command();
    let names: Vec<String> = cmd
        .get_subcommands()
        .map(|s| s.get_name().to_string())
        .collect();
    for name in names {
        cmd = cmd.mut_subcommand(name, |s| s.allow_negative_numbers(true));
    }
    Cli::from_arg_matches(&cmd.try_get_matches()?)
}

/// One line for a usage error: clap's first paragraph (the problem, with the arguments it names
/// and the possible values), without its usage and help hints.
fn usage_line(e: &clap::Error) -> String {
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::MissingSubcommand | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        return "no command given (try `poolsim --help`)".to_string();
    }
    let text = e.to_string();
    let first: Vec<&str> = text
        .lines()
        .take_while(|l| !l.trim().is_empty())
        .map(str::trim)
        .collect();
    let line = first.join(" ");
    let line = line.trim_start_matches("error: ");
    if line.is_empty() {
        "bad usage".to_string()
    } else {
        line.to_string()
    }
}

fn main() -> ExitCode {
    keep_freed_memory();
    die_quietly_on_closed_pipe();
    let cli = match parse_command_line() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => e.exit(), // --help, --version
        Err(e) => {
            eprintln!("poolsim: {}", usage_line(&e));
            return ExitCode::from(2);
        }
    };
    let result = match &cli.command {
        Command::Scenarios => {
            for (name, about) in builtin::list() {
                println!("{name:<10} {about}");
            }
            Ok(())
        }
        Command::Run(a) => run(a),
        Command::Demo { json, out } => demo(*json, out),
        Command::Render(a) => render(a),
        Command::Bench(b) => bench::bench(b),
        Command::Phold(a) => phold(a),
        Command::Reverse(a) => reverse(a),
        Command::Resume(a) => checkpoints::resume(a),
        Command::Model(a) => model(a),
        Command::Experiment(a) => experiment::experiment(a),
        Command::Compress(a) => compress::run_compress(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(f) => {
            eprintln!("poolsim: {}", f.message);
            ExitCode::from(f.code)
        }
    }
}
