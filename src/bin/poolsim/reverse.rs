//! `poolsim reverse`: the reversal experiment (thesis 4.6-4.7).

use crate::common::*;
use crate::render::render_to;
use crate::run::*;
use crate::values::{sector_choice, Delay, Engine, Sectors};
use poolsim::run::EngineKind;
use poolsim::scenario::Scenario;
use std::path::PathBuf;

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
    /// Draw the run from -Q through the reversal at 0 to Q: a folder (frame-0000.svg and .png,
    /// ...), FILE.html (one page with a player) or FILE.gif.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Time between frames, a whole fraction of Q: frames stand on a grid through the reversal,
    /// each at t with its mirror at -t (default: about 40 frames).
    #[arg(long = "frame-time", allow_negative_numbers = true)]
    pub frame_time: Option<f64>,
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
    let frame_time = frame_time(a, engine)?;
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
    if let (Some(out), Some(f)) = (&a.out, frame_time) {
        let line = draw(a, &scenario, engine, f, out)?;
        // the report alone on standard output when it is JSON
        if a.json {
            eprintln!("wrote {line}");
        } else {
            println!("wrote {line}");
        }
    }
    Ok(())
}

/// The frame time of the pictures `--out` asks for (`None` without `--out`): `--frame-time` if
/// it divides Q into whole frames, or about 40 frames from -Q to Q.
fn frame_time(a: &ReverseArgs, engine: EngineKind) -> Result<Option<f64>, Failure> {
    if a.out.is_none() {
        return match a.frame_time {
            Some(_) => Err(usage("--frame-time: only --out draws frames")),
            None => Ok(None),
        };
    }
    if matches!(engine, EngineKind::TimeStep { .. }) {
        return Err(usage(
            "--out: reverse draws with event-list, objects or time-warp",
        ));
    }
    let whole = |f: f64| poolsim::engine::Span::whole_frames(a.quit, f).is_some_and(|m| m >= 1.0);
    match a.frame_time {
        Some(f) if !(f.is_finite() && f > 0.0) => Err(usage(format!(
            "--frame-time: must be a positive number, got {f}"
        ))),
        Some(f) if !whole(f) => Err(usage(format!(
            "--frame-time: {f} does not divide --quit {} into whole frames (frames stand on a \
             grid through the reversal at 0, so -{0} and {0} must be on it)",
            a.quit
        ))),
        Some(f) => Ok(Some(f)),
        None => {
            let f = poolsim::render::default_frame_time(2.0 * a.quit);
            Ok(Some(if whole(f) {
                f
            } else {
                a.quit / (a.quit / f).ceil()
            }))
        }
    }
}

/// Draws the reversal run from -Q to Q into `out`; the line that says what was written.
fn draw(
    a: &ReverseArgs,
    scenario: &Scenario,
    engine: EngineKind,
    frame_time: f64,
    out: &std::path::Path,
) -> Result<String, Failure> {
    let cfg = poolsim::render::RenderConfig {
        check: a.check,
        sectors: sector_choice(a.sectors, scenario),
        start: -a.quit,
        reverse_at: Some(0.0),
        ..poolsim::render::RenderConfig::new(engine, a.quit, frame_time)
    };
    Ok(render_to(scenario, &cfg, out)?.1)
}
