//! `poolsim render` and `poolsim demo`: a run's frames as pictures, a GIF or a player page.

use crate::common::*;
use crate::run::*;
use crate::values::{sector_choice, Delay, Engine, Sectors};
use poolsim::run::{EngineKind, FixedNews, SectorChoice};
use poolsim::scenario::Scenario;
use poolsim::summary::RunSummary;
use std::path::PathBuf;

/// Arguments of `poolsim render`.
#[derive(clap::Args, Clone, Debug)]
pub struct RenderArgs {
    /// A built-in scenario name, a TOML file, or - for TOML on stdin.
    pub scenario: String,
    /// A folder (frame-0000.svg and .png, ...), FILE.html (one page with a player) or FILE.gif.
    #[arg(long)]
    pub out: PathBuf,
    /// Time between frames (default: about 40 frames, rounded to 1, 2 or 5 times a power of 10).
    #[arg(long = "frame-time", allow_negative_numbers = true)]
    pub frame_time: Option<f64>,
    /// End time (default: the scenario's).
    #[arg(long, allow_negative_numbers = true)]
    pub until: Option<f64>,
    /// event-list, objects or time-warp.
    #[arg(long, value_enum, default_value = "event-list")]
    pub engine: Engine,
    /// Sectors: none, auto, N or NxM; drawn on any engine, run by the objects engines.
    #[arg(long)]
    pub sectors: Option<Sectors>,
    #[command(flatten)]
    pub gen: GenArgs,
    /// Delay of NewVelocity messages (objects engine).
    #[arg(long = "newvelocity-delay")]
    pub newvelocity_delay: Option<Delay>,
    /// Check invariants at every event.
    #[arg(long)]
    pub check: bool,
}

/// Records a run and writes its frames where `out` says.
pub fn render_to(
    scenario: &Scenario,
    cfg: &poolsim::render::RenderConfig,
    out: &std::path::Path,
) -> Result<(poolsim::render::Recording, String), Failure> {
    use poolsim::render::{raster::Rasterizer, record, write, Output, RenderError};
    let out = Output::from_path(out).map_err(|e| usage(e.to_string()))?;
    let rasterizer = if out.needs_font() {
        Some(Rasterizer::new().map_err(|e| internal(e.to_string()))?)
    } else {
        None
    };
    let rec = record(scenario, cfg).map_err(run_failure)?;
    let line = write(&rec, &out, rasterizer.as_ref()).map_err(|e| match e {
        RenderError::Io { .. } => usage(e.to_string()),
        e => internal(e.to_string()),
    })?;
    Ok((rec, line))
}

pub fn render(a: &RenderArgs) -> Result<(), Failure> {
    let scenario = load(&a.scenario, &a.gen)?;
    let run_args = RunArgs {
        until: a.until,
        check: a.check,
        ..RunArgs::for_engine(
            &a.scenario,
            a.engine,
            a.sectors,
            &a.gen,
            a.newvelocity_delay,
        )
    };
    if a.engine == Engine::TimeStep {
        return Err(usage(
            "--engine: render draws with event-list, objects or time-warp",
        ));
    }
    let engine = engine_of(&run_args, &scenario)?;
    if a.newvelocity_delay.is_some() && engine == EngineKind::EventList {
        return Err(usage(
            "--newvelocity-delay: only the objects engine takes it",
        ));
    }
    let until = a.until.unwrap_or(scenario.until);
    let frame_time = a
        .frame_time
        .unwrap_or_else(|| poolsim::render::default_frame_time(until));
    let cfg = poolsim::render::RenderConfig {
        check: a.check,
        sectors: sector_choice(a.sectors, &scenario),
        ..poolsim::render::RenderConfig::new(engine, until, frame_time)
    };
    let (_, line) = render_to(&scenario, &cfg, &a.out)?;
    println!("wrote {line}");
    Ok(())
}

/// The demo's summary: the run's, with its sector layout and the page it wrote.
#[derive(serde::Serialize)]
pub struct DemoSummary<'a> {
    #[serde(flatten)]
    pub run: &'a RunSummary,
    pub sectors: &'static str,
    pub page: String,
}

/// The main job: the thesis' sectored 36-ball gas (plates 9-13: 2 x 2 sectors, frames every 0.1
/// up to 4) on the objects engine with the thesis' message flow, checked at every event, drawn
/// as one page with a player.
pub fn demo(json: bool, out: &std::path::Path) -> Result<(), Failure> {
    let scenario = load("gas", &GenArgs::default())?;
    let sectors = SectorChoice::Grid(2, 2);
    let cfg = poolsim::render::RenderConfig {
        check: true,
        sectors: Some(sectors),
        ..poolsim::render::RenderConfig::new(
            EngineKind::Sectored {
                sectors,
                news: FixedNews::Thesis,
            },
            scenario.until,
            0.1,
        )
    };
    let (rec, line) = render_to(&scenario, &cfg, out)?;
    if json {
        let demo = DemoSummary {
            run: &rec.summary,
            sectors: "2x2",
            page: out.display().to_string(),
        };
        println!("{}", serde_json::to_string(&demo).expect("plain data"));
        return Ok(());
    }
    print!("{}", human_summary(&rec.summary));
    println!("sectors       2 x 2 (thesis plates 9-13)");
    println!("page          {line}");
    Ok(())
}
