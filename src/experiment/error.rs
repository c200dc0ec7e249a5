//! Why `poolsim experiment` stopped: one line for the user, for the thesis experiment and the
//! reversal study alike.

use crate::engine::RunError;
use crate::scenario::Invalid;
use std::path::PathBuf;

/// Why an experiment stopped (bad arguments, a failed run, an unwritable directory, a missing
/// font, …). Files written before it stay.
#[derive(Debug, thiserror::Error)]
pub enum ExperimentError {
    /// `--seeds` out of range.
    #[error("--seeds must be from 1 to 1000, got {0}")]
    Seeds(u64),
    /// `--area-fractions` empty or outside the fluid's range.
    #[error("--area-fractions: give one or more numbers between 0 and 0.7 (the fluid), got {0:?}")]
    AreaFractions(Vec<f64>),
    /// `--balls` given an empty list.
    #[error("--balls needs at least one number of balls")]
    NoBalls,
    /// A number of balls outside 1 to 4096.
    #[error("--balls: {0} is not a whole number from 1 to 4096")]
    BallsOutOfRange(usize),
    /// An option of the thesis experiment given to the reversal study.
    #[error(
        "{flag}: only the thesis experiment takes it (the reversal study has its own scenarios \
         and quitting times)"
    )]
    ThesisOnly {
        /// The option.
        flag: &'static str,
    },
    /// `--balls` for the equation of state: one number of disks.
    #[error("--balls: the equation of state takes one number of disks, from 16 on")]
    EosBalls,
    /// `--balls` for the jamming study: one number of disks.
    #[error("--balls: the jamming study takes one number of disks, from 16 on")]
    JammingBalls,
    /// `--rates` empty or not all positive.
    #[error("--rates: give one or more positive growth rates, got {0:?}")]
    Rates(Vec<f64>),
    /// An option of the jamming study given to another experiment.
    #[error("{flag}: only the jamming study (experiment jamming) takes it")]
    JammingOnly {
        /// The option.
        flag: &'static str,
    },
    /// An option of the equation of state given to another experiment.
    #[error("{flag}: only the equation of state (experiment eos) takes it")]
    EosOnly {
        /// The option.
        flag: &'static str,
    },
    /// The output directory could not be made.
    #[error("cannot create {path}: {source}")]
    CreateDir {
        /// The directory.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A file could not be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The font file could not be read.
    #[error(
        "cannot read the font {path} for the figures: {source} (install Debian's \
         fonts-dejavu-core, or pass --font FILE with a TrueType font)"
    )]
    ReadFont {
        /// The font file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The font file holds no font plotters can use.
    #[error("the font {0} is not a TrueType or OpenType font")]
    NotAFont(PathBuf),
    /// A figure could not be drawn.
    #[error("drawing {what}: {source}")]
    Draw {
        /// The figure.
        what: String,
        /// Why.
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// A PNG could not be encoded.
    #[error("encoding {path}: {source}")]
    Encode {
        /// The file.
        path: PathBuf,
        /// Why.
        source: png::EncodingError,
    },
    /// `results.json` could not be serialized.
    #[error("results.json: {0}")]
    Results(#[source] serde_json::Error),
    /// The reversal study's table could not be serialized.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// The report's template could not be filled in.
    #[error("report.md: {0:#}")]
    Report(#[source] minijinja::Error),
    /// A thesis gas could not be built.
    #[error("gas with {balls} balls, seed {seed}: {}: {}", .invalid.field, .invalid.message)]
    Gas {
        /// Balls.
        balls: usize,
        /// Seed.
        seed: u64,
        /// The field refused and why.
        invalid: Invalid,
    },
    /// The reversal scenario could not be built.
    #[error("{}: {}", .0.field, .0.message)]
    Scenario(Invalid),
    /// The event-list run of a gas failed.
    #[error("{balls} balls, seed {seed}: {source}")]
    Physics {
        /// Balls.
        balls: usize,
        /// Seed.
        seed: u64,
        /// Why.
        source: RunError,
    },
    /// An objects run of a gas failed.
    #[error("{balls} balls, seed {seed}, sectors {setting}: {source}")]
    Objects {
        /// Balls.
        balls: usize,
        /// Seed.
        seed: u64,
        /// The setting (`none` or `KxK`).
        setting: String,
        /// Why.
        source: RunError,
    },
    /// A repeated objects run sent other messages than the first.
    #[error(
        "{balls} balls, seed {seed}, sectors {setting}: a repeated run sent different messages"
    )]
    Unrepeatable {
        /// Balls.
        balls: usize,
        /// Seed.
        seed: u64,
        /// The setting (`none` or `KxK`).
        setting: String,
    },
    /// A run of the reversal study failed.
    #[error(transparent)]
    Run(#[from] RunError),
    /// Some objects runs ended in another state than the event-list engine's.
    #[error("{count} runs did not end in the event-list engine's final state; first: {first}")]
    Mismatch {
        /// How many.
        count: usize,
        /// The first, described.
        first: String,
    },
}
