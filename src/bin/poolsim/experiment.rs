//! `poolsim experiment`: the thesis' experiments (ch. 6-7) or the reversal study (4.6-4.7),
//! with a progress bar on stderr when it is a terminal.

use crate::common::{usage, Failure};
use indicatif::{ProgressBar, ProgressStyle};
use poolsim::experiment::{self, ExperimentOptions, Progress, Which};
use std::io::IsTerminal;
use std::path::PathBuf;

/// Which experiment `poolsim experiment` runs.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum WhichArg {
    /// Thesis chapter 6 (tables 5-10) with the chapter 7 model (figures 17-18).
    Thesis,
    /// Thesis 4.6-4.7: the reversal error against the quitting time Q.
    Reversal,
    /// The hard-disk fluid's equation of state in a periodic box, beside the literature.
    Eos,
    /// The jammed area fraction of a binary disk mixture against the compression rate.
    Jamming,
}

/// Arguments of `poolsim experiment`.
#[derive(clap::Args, Clone, Debug)]
pub struct ExperimentArgs {
    /// The experiment: `thesis` (chapter 6 tables 5-10 and chapter 7 figures 17-18),
    /// `reversal` (thesis 4.6-4.7), `eos` (the hard-disk equation of state) or `jamming` (the
    /// jammed packing of a disk mixture against the compression rate).
    #[arg(value_enum)]
    pub which: WhichArg,
    /// Directory to write the tables, figures, results.json and report.md into (created if
    /// missing; files already there are overwritten).
    #[arg(long)]
    pub out: PathBuf,
    /// Seeds per cell, 1..=S (default 6, as the thesis ran its non-sectored cases; 2 with --quick);
    /// for jamming, seeds per rate (default 3; 2 with --quick).
    #[arg(long)]
    pub seeds: Option<u64>,
    /// Numbers of balls, comma separated (default 4,16,36,64; 4,16 with --quick); for eos, one
    /// number of disks (default 10000; 1000 with --quick); for jamming, one (default 1000; 200
    /// with --quick).
    #[arg(long, value_delimiter = ',')]
    pub balls: Option<Vec<usize>>,
    /// A reduced grid for CI: 4 and 16 balls, 2 seeds, until 4 (eos: 1000 disks at 0.3 and
    /// 0.5, shorter runs; jamming: 200 disks at rates 0.1 and 0.01, 2 seeds).
    #[arg(long)]
    pub quick: bool,
    /// The equation of state's area fractions, comma separated (default 0.3,0.5,0.6,0.65).
    #[arg(long = "area-fractions", value_delimiter = ',')]
    pub area_fractions: Option<Vec<f64>>,
    /// The jamming study's growth rates, comma separated (default 0.1,0.03,0.01,0.003,0.001).
    #[arg(long, value_delimiter = ',')]
    pub rates: Option<Vec<f64>>,
    /// TrueType font for the figures' text (default: DejaVu Sans from Debian's
    /// fonts-dejavu-core).
    #[arg(long)]
    pub font: Option<PathBuf>,
}

impl ExperimentArgs {
    /// The library's options.
    fn options(&self) -> ExperimentOptions {
        ExperimentOptions {
            which: match self.which {
                WhichArg::Thesis => Which::Thesis,
                WhichArg::Reversal => Which::Reversal,
                WhichArg::Eos => Which::Eos,
                WhichArg::Jamming => Which::Jamming,
            },
            out: self.out.clone(),
            seeds: self.seeds,
            balls: self.balls.clone(),
            quick: self.quick,
            font: self.font.clone(),
            area_fractions: self.area_fractions.clone(),
            rates: self.rates.clone(),
        }
    }
}

/// Runs the experiment, drawing its progress on stderr when that is a terminal.
pub fn experiment(a: &ExperimentArgs) -> Result<(), Failure> {
    let bar = if std::io::stderr().is_terminal() {
        let style = ProgressStyle::with_template(
            "{spinner} experiment thesis [{bar:40}] {pos}/{len} runs {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
        ProgressBar::new(0).with_style(style)
    } else {
        ProgressBar::hidden()
    };
    let mut progress = |p: Progress| match p {
        Progress::Start(total) => bar.set_length(total),
        Progress::Cell { balls, seed } => bar.set_message(format!("{balls} balls, seed {seed}")),
        Progress::RunDone => bar.inc(1),
        Progress::Finished => bar.finish_and_clear(),
    };
    experiment::run(&a.options(), &mut progress).map_err(|e| usage(e.to_string()))?;
    let report = match a.which {
        WhichArg::Thesis => "report.md",
        WhichArg::Reversal => "reversal.md",
        WhichArg::Eos => "eos.md",
        WhichArg::Jamming => "jamming.md",
    };
    println!(
        "wrote {} (with its tables, figures and data beside it)",
        a.out.join(report).display()
    );
    Ok(())
}
