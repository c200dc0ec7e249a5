//! `poolsim reverse`: the reversal experiment (thesis 4.6-4.7).

use crate::common::*;
use crate::run::*;
use crate::values::{Delay, Engine, Sectors};

/// Arguments of `poolsim reverse`.
#[derive(clap::Args, Clone, Debug)]
pub struct ReverseArgs {
    /// A built-in scenario name, a TOML file, or - for TOML on stdin. its balls are placed at time -Q.
    pub scenario: String,
    /// Quitting time Q.
    #[arg(long, allow_negative_numbers = true)]
    pub quit: f64,
    /// event-list, time-step, objects or time-warp.
    #[arg(long, value_enum, default_value = "event-list")]
    pub engine: Engine,
    /// Sector layout of the objects engines: none, auto, N or NxM.
    #[arg(long)]
    pub sectors: Option<Sectors>,
    #[command(flatten)]
    pub gen: GenArgs,
    /// Worker threads (time-warp engine; default: this machine's cores).
    #[arg(long)]
    pub workers: Option<usize>,
    /// Time step of the time-step engine.
    #[arg(long, allow_negative_numbers = true)]
    pub dt: Option<f64>,
    /// Delay of NewVelocity messages (objects engine).
    #[arg(long = "newvelocity-delay")]
    pub newvelocity_delay: Option<Delay>,
    /// Check invariants at every event.
    #[arg(long)]
    pub check: bool,
    /// Print the report as one JSON object.
    #[arg(long)]
    pub json: bool,
}

pub fn reverse(a: &ReverseArgs) -> Result<(), Failure> {
    if !(a.quit.is_finite() && a.quit > 0.0) {
        return Err(usage(format!(
            "--quit: must be a positive number, got {}",
            a.quit
        )));
    }
    let scenario = load(&a.scenario, &a.gen)?;
    let run_args = RunArgs {
        json: a.json,
        check: a.check,
        dt: a.dt,
        workers: a.workers,
        ..RunArgs::for_engine(
            &a.scenario,
            a.engine,
            a.sectors,
            &a.gen,
            a.newvelocity_delay,
        )
    };
    let engine = engine_of(&run_args, &scenario)?;
    check_options_fit(&run_args, &engine)?;
    let r = poolsim::run::reverse(&scenario, engine, a.quit, a.check).map_err(run_failure)?;
    if a.json {
        println!(
            "{}",
            serde_json::to_string(&r).expect("a report serializes")
        );
    } else {
        println!(
            "{} on {}: -{} to {}, {} events ({} before the reversal); largest error: position \
             {:e}, velocity {:e}{}",
            r.scenario,
            r.engine,
            r.quit,
            r.quit,
            r.events,
            r.forward_events,
            r.max_position_error,
            r.max_velocity_error,
            if r.still_pocketed > 0 {
                format!("; {} balls still in pockets", r.still_pocketed)
            } else {
                String::new()
            }
        );
    }
    Ok(())
}
