//! poolsim: exact event-driven simulation of pool balls and hard disks, after A. P. Goldberg,
//! "Object-Oriented Simulation of Pool Ball Motion" (M.S. thesis, UCLA, 1984).
//!
//! The crate is a few rooms, each with one job:
//! - [`geometry`] and [`physics`]: pure functions of trajectories (thesis ch. 3); [`growth`]:
//!   the same for disks that grow (compression);
//! - [`scenario`]: tables and balls from TOML or built-in generators, validated once;
//! - [`vtime`]: the lexicographic virtual time that orders simultaneous events exactly;
//! - [`model`]: the pool objects as models of the [`pdes_kernel`] crate, a generic
//!   message-passing kernel run in order or optimistically in parallel by Time Warp;
//! - [`engine`]: the event-list, time-step and objects engines;
//! - [`check`]: invariants checked while a run goes (`--check`);
//! - [`output`]: the trace and the final state; [`summary`]: the run summary;
//! - [`observe`]: pressure, compressibility factor, temperature and collision rate, in blocks;
//! - [`memory`]: the one memory setting that depends on the engine (huge pages).

pub mod analytic;
pub mod bench;
pub mod check;
pub mod checkpoint;
pub mod compress;
pub mod engine;
#[cfg(feature = "pictures")]
pub mod eos_study;
#[cfg(feature = "pictures")]
pub mod experiment;
pub mod geometry;
pub mod growth;
#[cfg(feature = "pictures")]
pub mod jamming_study;
pub mod memory;
pub mod model;
pub mod observe;
pub mod output;
pub mod physics;
pub mod polygon;
pub mod render;
#[cfg(feature = "pictures")]
pub mod reversal_study;
pub mod run;
pub mod samples;
pub mod scenario;
pub mod structure;
pub mod summary;
pub mod thermostat;
pub mod vtime;
