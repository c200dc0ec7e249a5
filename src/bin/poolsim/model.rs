//! `poolsim model`: the analytic model of message counts (thesis ch. 7).

use crate::common::*;

/// Arguments of `poolsim model`.
#[derive(clap::Args, Clone, Debug)]
pub struct ModelArgs {
    /// Number of balls N on the unit-square table.
    #[arg(long, allow_negative_numbers = true)]
    pub balls: f64,
    /// Ball speed V.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub speed: f64,
    /// Duration T.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub time: f64,
    /// Number of velocity changes m (0: equation 1; otherwise equation 2).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub changes: f64,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

pub fn model(a: &ModelArgs) -> Result<(), Failure> {
    use poolsim::analytic::{report, report_json, ModelParams};
    let p = ModelParams {
        balls: a.balls,
        speed: a.speed,
        time: a.time,
        changes: a.changes,
    };
    p.validate().map_err(|e| usage(e.to_string()))?;
    if a.json {
        println!("{}", report_json(&p));
    } else {
        print!("{}", report(&p));
    }
    Ok(())
}
