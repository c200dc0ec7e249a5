//! Graphics (thesis 4.2 and its plates): frames of a run drawn as the thesis drew them, written
//! as SVG, PNG, an animated GIF, or one self-contained HTML page with a player.
//!
//! ```text
//!  Scenario ──► engine (execute, frame time F) ──► Recorder ──► Recording ──┬─► svg::frame ──► .svg
//!                  │ on_frame, on_event                                      ├─► raster     ──► .png, .gif
//!  objects engines ┴─► run again in chunks up to each frame: message counts  └─► html::page ──► .html
//! ```
//!
//! A frame shows the table after every event up to and including its time (thesis 4.3.1): the
//! title `POOL SIMULATION AT t`, the cushions, the pockets with the names of the balls they hold
//! listed under their labels, the corners, every ball on the table with its name and its velocity
//! vector (a line from the centre to where the ball will be one time unit later; none for a ball
//! at rest), and, on a sectored table, the sectors with their names and the balls inside them
//! (plate 7; a ball then lists the sectors it touches under its name). The drawing depends on the
//! frame only, never on the engine that made it.
//!
//! Besides frames, a recording keeps the run's history (every ball's trajectory pieces and the
//! events, up to a size cap), so the HTML player can show the exact state at any time, and, for
//! the objects engines, the messages sent up to each frame time: the engine is run a second time,
//! stopping at every frame time to read its message statistics.

pub mod html;
#[cfg(feature = "pictures")]
pub mod raster;
/// Without the `pictures` feature: SVG and HTML only.
#[cfg(not(feature = "pictures"))]
#[path = "no_raster.rs"]
pub mod raster;
pub mod svg;
pub mod text_box;

use crate::engine::objects::Objects;
use crate::engine::{
    BallState, Event, EventCounts, Frame, Ignore, Observer, RunError, Span, Table, World,
};
use crate::geometry::Vec2;
use crate::model::sectored::Layout;
use crate::run::{build_objects, execute, sector_layout, EngineKind, RunConfig, SectorChoice};
use crate::scenario::Scenario;
use crate::summary::RunSummary;
use pdes_kernel::Model;
use std::path::{Path, PathBuf};

/// The most frames one recording may hold.
pub const MAX_FRAMES: usize = 20_000;

/// The most ball positions (frames × balls) one recording may hold.
pub const MAX_FRAME_BALLS: usize = 2_000_000;

/// The most trajectory pieces a recording keeps as its history by default; past this the HTML
/// player interpolates between frames instead (a piece is about 130 bytes of the page).
pub const MAX_HISTORY: usize = 250_000;

/// What to draw and how to run: the engine, the end time and the frame time.
#[derive(Clone, Debug)]
pub struct RenderConfig {
    /// The engine that makes the frames.
    pub engine: EngineKind,
    /// The time of the scenario's positions, where the run and its first frame start.
    pub start: f64,
    /// When every ball turns around (thesis 4.6), if ever; frames then stand on a grid through
    /// it ([`Span::frame`]).
    pub reverse_at: Option<f64>,
    /// End time; frames are drawn at `start, start + F, …` up to it.
    pub until: f64,
    /// Time between frames, `F` (positive).
    pub frame_time: f64,
    /// Check invariants at every event while running.
    pub check: bool,
    /// The sectors to draw (none when `None`); a sectored engine draws its own layout whatever
    /// this says, unless it is `None`.
    pub sectors: Option<SectorChoice>,
    /// The most trajectory pieces kept as the history ([`MAX_HISTORY`] by default).
    pub max_history: usize,
}

impl RenderConfig {
    /// Frames every `frame_time` from 0 up to `until` from `engine`; no reversal, no checks, no
    /// sectors drawn, the default history cap.
    pub fn new(engine: EngineKind, until: f64, frame_time: f64) -> RenderConfig {
        RenderConfig {
            engine,
            start: 0.0,
            reverse_at: None,
            until,
            frame_time,
            check: false,
            sectors: None,
            max_history: MAX_HISTORY,
        }
    }
}

/// The fixed part of every frame: the table, the balls' names and sizes, the sectors.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The scenario's name.
    pub name: String,
    /// The table: cushions, pockets, corners and the numbering of objects.
    pub table: Table,
    /// The sectors drawn, if any.
    pub sectors: Option<Layout>,
    /// How each ball looks: the scenario's colours and labels (a pool ball's number).
    pub looks: Vec<Look>,
    /// The reversal of the run drawn, if it has one.
    pub turn: Option<Turn>,
}

/// A run whose balls all turn around (thesis 4.6), as its pictures show it.
#[derive(Clone, Debug, PartialEq)]
pub struct Turn {
    /// When every ball turned around.
    pub at: f64,
    /// The time of the last frame, which outlines where each ball started beneath it.
    pub end: f64,
    /// Where each ball started (`None` for a ball that started in a pocket).
    pub starts: Vec<Option<Vec2>>,
}

/// How a ball looks in pictures.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Look {
    /// Its colour (`#rrggbb`), or the default.
    pub colour: Option<String>,
    /// What is written on it in place of its name (nothing when empty).
    pub label: Option<String>,
}

impl Scene {
    /// The scene of a scenario, with the sector layout `sectors` (or none).
    pub fn new(scenario: &Scenario, sectors: Option<Layout>) -> Scene {
        Scene {
            name: scenario.name.clone(),
            table: Table::new(scenario),
            sectors,
            looks: scenario
                .balls
                .iter()
                .map(|b| Look {
                    colour: b.colour.clone(),
                    label: b.label.clone(),
                })
                .collect(),
            turn: None,
        }
    }

    /// `Sector-{k+1}`.
    pub fn sector_name(k: usize) -> String {
        format!("Sector-{}", k + 1)
    }
}

/// One frame with what had happened by its time.
#[derive(Clone, Debug, PartialEq)]
pub struct Shot {
    /// The frame: every ball fixed at its time.
    pub frame: Frame,
    /// Physical events executed up to and including the frame's time.
    pub events: EventCounts,
    /// Messages sent by every batch up to and including the frame's time, by thesis type
    /// (objects engines only; the event-list engine sends none).
    pub messages: Option<Vec<(&'static str, u64)>>,
    /// In a run with a reversal at `r`, for a frame at `r + t` (`t ≥ 0`) whose mirror frame at
    /// `r - t` exists: the largest distance between a ball on the table now and where it was
    /// then (how far the run is from retracing its steps).
    pub mirror_distance: Option<f64>,
}

/// One piece of a ball's path: from time `from` on, the ball is in `state` (until its next
/// piece).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Piece {
    /// The time of the event that put the ball in this state.
    pub from: f64,
    /// The ball's state from then on.
    pub state: BallState,
}

/// The whole run: every ball's path as pieces, and every physical event in execution order.
#[derive(Clone, Debug, Default)]
pub struct History {
    /// For each ball, its pieces in time order; the first starts at time 0.
    pub pieces: Vec<Vec<Piece>>,
    /// Every executed physical event.
    pub events: Vec<Event>,
}

impl History {
    /// Ball `i`'s state at time `t`, after every event up to and including `t`.
    pub fn state_at(&self, i: usize, t: f64) -> BallState {
        let path = &self.pieces[i];
        let k = path.partition_point(|p| p.from <= t).max(1) - 1;
        fix_at(path[k].state, t)
    }

    /// The frame at time `t` (the same as an engine's frame at `t`).
    pub fn frame_at(&self, t: f64) -> Frame {
        Frame {
            t,
            balls: (0..self.pieces.len())
                .map(|i| self.state_at(i, t))
                .collect(),
            images: Vec::new(),
        }
    }

    /// Adds the reversal at `frame`'s time, shown by that frame (every ball as it is after
    /// everything at that time, the reversal included): each ball's state from then on, until
    /// its next event, is the frame's.
    pub fn turn_at(&mut self, frame: &Frame) {
        for (path, b) in self.pieces.iter_mut().zip(&frame.balls) {
            let k = path.partition_point(|p| p.from <= frame.t);
            path.insert(
                k,
                Piece {
                    from: frame.t,
                    state: *b,
                },
            );
        }
    }

    /// The number of pieces over all balls.
    pub fn len(&self) -> usize {
        self.pieces.iter().map(Vec::len).sum()
    }

    /// Whether there is no piece at all (no balls).
    pub fn is_empty(&self) -> bool {
        self.pieces.iter().all(Vec::is_empty)
    }
}

/// A ball's state fixed at time `t`: on its trajectory, or as it is in its pocket.
pub fn fix_at(mut b: BallState, t: f64) -> BallState {
    if b.pocket.is_none() {
        b.traj.position = b.traj.at(t);
        b.traj.t0 = t;
    }
    b
}

/// Everything drawn from one run.
#[derive(Clone, Debug)]
pub struct Recording {
    /// The fixed part of every frame.
    pub scene: Scene,
    /// The engine's name (`event-list`, `objects`, …).
    pub engine: &'static str,
    /// The time of the first frame, where the run started.
    pub start: f64,
    /// End time.
    pub until: f64,
    /// Time between frames.
    pub frame_time: f64,
    /// The frames, at `0, F, 2F, …`.
    pub shots: Vec<Shot>,
    /// The exact history, unless it was longer than the cap (`RenderConfig::max_history`).
    pub history: Option<History>,
    /// The run summary (as `poolsim run --json` prints it).
    pub summary: RunSummary,
}

impl Recording {
    /// The style of its pictures ([`svg::Style::for_run`], from the first frame's balls).
    pub fn style(&self) -> svg::Style {
        let first = self.shots.first().map_or(&[][..], |s| &s.frame.balls[..]);
        svg::Style::for_run(&self.scene, first)
    }
}

/// Records what a run shows: frames with the event counts at their times, and the history.
struct Recorder {
    counts: EventCounts,
    frames: Vec<(Frame, EventCounts)>,
    history: Option<History>,
    pieces: usize,
    cap: usize,
}

impl Recorder {
    fn new(initial: &[BallState], cap: usize) -> Recorder {
        Recorder {
            cap,
            counts: EventCounts::default(),
            frames: Vec::new(),
            history: Some(History {
                pieces: initial
                    .iter()
                    .map(|b| {
                        vec![Piece {
                            from: b.traj.t0,
                            state: *b,
                        }]
                    })
                    .collect(),
                events: Vec::new(),
            }),
            pieces: initial.len(),
        }
        .capped()
    }

    /// Drops the history once it is longer than the cap.
    fn capped(mut self) -> Recorder {
        if self.pieces > self.cap {
            self.history = None;
        }
        self
    }
}

impl Observer for Recorder {
    fn on_event(&mut self, ev: &Event, world: &dyn World) -> Result<(), RunError> {
        self.counts.add(ev.kind);
        let n = world.n_balls() as u32;
        if let Some(h) = &mut self.history {
            for i in [ev.a, ev.b].into_iter().filter(|&i| i < n) {
                h.pieces[i as usize].push(Piece {
                    from: ev.t,
                    state: world.ball(i),
                });
                self.pieces += 1;
            }
            h.events.push(*ev);
            if self.pieces > self.cap {
                self.history = None;
            }
        }
        Ok(())
    }

    fn on_frame(&mut self, frame: &Frame, _: &Table) -> Result<(), RunError> {
        self.frames.push((frame.clone(), self.counts));
        Ok(())
    }
}

/// The times of the frames of a run over `span` (its frame time set) up to `until`, as the
/// engines compute them: `0, F, 2F, …` for a run from 0 without a reversal.
pub fn frame_times(span: Span, until: f64) -> Vec<f64> {
    (0u64..)
        .map_while(|k| span.frame(k).filter(|&t| t <= until))
        .collect()
}

/// Sets each frame's distance from its mirror frame about the reversal at `r`: for the frame at
/// `r + t`, the largest distance between a ball on the table then and where it was at `r - t`.
fn mirror_distances(shots: &mut [Shot], r: f64) {
    let times: Vec<f64> = shots.iter().map(|s| s.frame.t).collect();
    for k in 0..shots.len() {
        // frame times are in order and finite: the mirror's is found by bisection (as a number:
        // the mirror of 0 is -0)
        let t = times[k] - r;
        let mirror = times.binary_search_by(|&u| (u - r).partial_cmp(&-t).expect("finite"));
        let Some(m) = mirror.ok().filter(|_| t >= 0.0) else {
            continue;
        };
        let (now, then) = (&shots[k].frame.balls, &shots[m].frame.balls);
        let far = now
            .iter()
            .zip(then)
            .filter(|(a, b)| a.pocket.is_none() && b.pocket.is_none())
            .map(|(a, b)| (a.traj.position - b.traj.position).norm())
            .fold(0.0, f64::max);
        shots[k].mirror_distance = Some(far);
    }
}

/// Checks a frame time and end time, and the size of the recording they would make.
fn check_sizes(balls: usize, cfg: &RenderConfig) -> Result<(), RunError> {
    let f = cfg.frame_time;
    if !(f.is_finite() && f > 0.0) {
        return Err(RunError::Input(format!(
            "--frame-time: must be a positive number, got {f}"
        )));
    }
    let u = cfg.until;
    if !(u.is_finite() && u >= cfg.start) {
        return Err(RunError::Input(format!(
            "--until: must be a finite number not below {}, got {u}",
            format_time(cfg.start)
        )));
    }
    let frames = ((u - cfg.start) / f).floor() + 1.0;
    if frames > MAX_FRAMES as f64 || frames * balls as f64 > MAX_FRAME_BALLS as f64 {
        return Err(RunError::Input(format!(
            "--frame-time: {f} up to {u} makes {frames} frames of {balls} balls, more than the \
             {MAX_FRAMES} frames or {MAX_FRAME_BALLS} ball positions one recording holds; use a \
             larger frame time"
        )));
    }
    Ok(())
}

/// The messages an objects engine has sent so far, by thesis type, `Cancel` included.
fn messages_of(e: &Objects) -> Vec<(&'static str, u64)> {
    let names = match e {
        Objects::Plain(x) => x.model().kind_names(),
        Objects::Sectored(x) => x.model().kind_names(),
    };
    let stats = e.stats();
    let mut out: Vec<(&'static str, u64)> = names
        .iter()
        .enumerate()
        .map(|(k, n)| (*n, stats.get(k)))
        .collect();
    out.push(("Cancel", stats.cancels));
    out
}

/// Runs an objects engine again, stopping at every frame time: the frames and the messages sent
/// up to each. `None` for engines that send no messages.
#[allow(clippy::type_complexity)]
fn chunked(
    scenario: &Scenario,
    engine: EngineKind,
    span: Span,
    times: &[f64],
) -> Result<Option<Vec<(Frame, EventCounts, Vec<(&'static str, u64)>)>>, RunError> {
    let span = Span {
        frame_time: None,
        ..span
    };
    let Some(mut e) = build_objects(scenario, engine, span)? else {
        return Ok(None);
    };
    let mut counts = EventCounts::default();
    let mut out = Vec::with_capacity(times.len());
    for &t in times {
        let o = e.run(t, &mut Ignore)?;
        for (c, k) in counts.by_kind.iter_mut().zip(o.events.by_kind) {
            *c += k;
        }
        out.push((
            Frame {
                t,
                balls: o.balls.iter().map(|b| fix_at(*b, t)).collect(),
                images: Vec::new(),
            },
            counts,
            messages_of(&e),
        ));
    }
    Ok(Some(out))
}

/// Runs `scenario` as `cfg` says and records every frame, the history and the summary.
///
/// The event-list and plain objects engines draw their own frames (the Projector's
/// DisplayYourself, thesis 4.2); the sectored objects engine's frames are its state when it is
/// stopped at each frame time.
pub fn record(scenario: &Scenario, cfg: &RenderConfig) -> Result<Recording, RunError> {
    check_sizes(scenario.balls.len(), cfg)?;
    let span = Span {
        start: cfg.start,
        reverse_at: cfg.reverse_at,
        frame_time: Some(cfg.frame_time),
    };
    let times = frame_times(span, cfg.until);
    // the sectored engines, sequential or Time Warp, draw their own layout; they draw no
    // frames themselves, and are stopped at each frame time instead
    let own = match cfg.engine {
        EngineKind::Sectored { sectors, .. } => Some(sectors),
        EngineKind::TimeWarp { sectors, .. } => sectors,
        _ => None,
    };
    let drawn = match (cfg.sectors, own) {
        (None, _) => None,
        (Some(_), Some(sectors)) | (Some(sectors), None) => Some(sector_layout(scenario, sectors)?),
    };
    let sectored = own.is_some();
    let initial = BallState::initial(scenario, cfg.start);
    let mut rec = Recorder::new(&initial, cfg.max_history);
    let run = RunConfig {
        engine: cfg.engine,
        until: cfg.until,
        check: cfg.check,
        span: Span {
            frame_time: (!sectored).then_some(cfg.frame_time),
            ..span
        },
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let report = execute(scenario, &run, &mut rec)?;
    let chunks = chunked(scenario, cfg.engine, span, &times)?;
    let shots: Vec<Shot> = match chunks {
        Some(chunks) if sectored => chunks
            .into_iter()
            .map(|(frame, events, messages)| Shot {
                frame,
                events,
                messages: Some(messages),
                mirror_distance: None,
            })
            .collect(),
        chunks => {
            let mut messages = chunks.map(|c| c.into_iter().map(|(_, _, m)| m));
            rec.frames
                .drain(..)
                .map(|(frame, events)| Shot {
                    frame,
                    events,
                    messages: messages.as_mut().and_then(Iterator::next),
                    mirror_distance: None,
                })
                .collect()
        }
    };
    if shots.len() != times.len() {
        return Err(RunError::Output(format!(
            "the engine drew {} frames where {} were due",
            shots.len(),
            times.len()
        )));
    }
    let mut shots = shots;
    let mut history = rec.history;
    if let Some(r) = cfg.reverse_at {
        mirror_distances(&mut shots, r);
        if let (Some(h), Some(at)) = (&mut history, shots.iter().find(|s| s.frame.t == r)) {
            h.turn_at(&at.frame);
        }
    }
    let mut scene = Scene::new(scenario, drawn);
    scene.turn = cfg.reverse_at.map(|at| Turn {
        at,
        end: shots.last().map_or(cfg.until, |s| s.frame.t),
        starts: initial
            .iter()
            .map(|b| b.pocket.is_none().then_some(b.traj.position))
            .collect(),
    });
    Ok(Recording {
        scene,
        engine: cfg.engine.name(),
        start: cfg.start,
        until: cfg.until,
        frame_time: cfg.frame_time,
        shots,
        history,
        summary: report.summary,
    })
}

/// Where frames go, told by the path: `*.html` (or `.htm`) one page with a player, `*.gif` one
/// animated GIF, anything else a folder of `frame-0000.svg` and `frame-0000.png`, ….
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Output {
    /// A folder of SVG and PNG frames.
    Folder(PathBuf),
    /// One self-contained HTML page.
    Html(PathBuf),
    /// One animated GIF.
    Gif(PathBuf),
}

impl Output {
    /// The output a path names, by its extension; a single picture file (`.png`, `.svg`, …) is
    /// refused, since a run has many frames.
    pub fn from_path(path: &Path) -> Result<Output, OutputError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        Ok(match ext.as_deref() {
            Some("html" | "htm") => Output::Html(path.to_path_buf()),
            Some("gif") => Output::Gif(path.to_path_buf()),
            Some(ext @ ("png" | "svg" | "jpg" | "jpeg" | "webp")) => {
                return Err(OutputError::Picture {
                    path: path.to_path_buf(),
                    ext: ext.to_string(),
                })
            }
            _ if path.exists() && !path.is_dir() => {
                return Err(OutputError::File(path.to_path_buf()))
            }
            _ => Output::Folder(path.to_path_buf()),
        })
    }

    /// Whether this output needs the font (PNG and GIF frames do).
    pub fn needs_font(&self) -> bool {
        !matches!(self, Output::Html(_))
    }
}

/// Why a path names no [`Output`] ([`Output::from_path`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum OutputError {
    /// A single picture file, where a run makes many frames.
    #[error(
        "--out: {}: a run has many frames, so not one .{ext} file; give a folder \
         (frame-0000.svg and .png, ...), FILE.html or FILE.gif",
        .path.display()
    )]
    Picture {
        /// The path.
        path: PathBuf,
        /// Its extension, in lower case.
        ext: String,
    },
    /// An existing file that is not a folder.
    #[error(
        "--out: {} is a file, not a folder for the frames; name a folder, FILE.html or FILE.gif",
        .0.display()
    )]
    File(PathBuf),
}

/// Why a picture could not be made.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct RasterError(pub String);

/// Why rendering failed.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The run failed or its input is unusable.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A picture could not be made (no font, …).
    #[error(transparent)]
    Raster(#[from] RasterError),
    /// A file could not be written.
    #[error("{}: cannot write: {error}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What went wrong.
        error: std::io::Error,
    },
}

pub(crate) fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> RenderError + '_ {
    move |error| RenderError::Io {
        path: path.to_path_buf(),
        error,
    }
}

/// `1 frame`, `2 frames`.
pub(crate) fn frames(k: usize) -> String {
    if k == 1 {
        "1 frame".into()
    } else {
        format!("{k} frames")
    }
}

/// The file name of frame `k` of `count` (`frame-0000`, with more digits past 10 000 frames).
pub fn frame_name(k: usize, count: usize) -> String {
    let width = count.saturating_sub(1).to_string().len().max(4);
    format!("frame-{k:0width$}")
}

/// Writes a recording to `out`; `rasterizer` is needed for PNG and GIF frames. Returns one line
/// that says what was written.
pub fn write(
    rec: &Recording,
    out: &Output,
    rasterizer: Option<&raster::Rasterizer>,
) -> Result<String, RenderError> {
    let need = || RasterError("PNG and GIF frames need a rasterizer with a font".to_string());
    match out {
        Output::Html(path) => {
            std::fs::write(path, html::page(rec)).map_err(io_error(path))?;
            Ok(format!(
                "{}: one page, {} every {}, {}",
                path.display(),
                frames(rec.shots.len()),
                format_time(rec.frame_time),
                if rec.history.is_some() {
                    "exact at any time"
                } else {
                    "interpolated between frames (the history was too long to embed)"
                }
            ))
        }
        Output::Folder(dir) => raster::write_folder(rec, dir, rasterizer.ok_or_else(need)?),
        Output::Gif(path) => raster::write_gif(rec, path, rasterizer.ok_or_else(need)?),
    }
}

/// A frame time for a run to `until` when none is given: about 40 frames, rounded to 1, 2 or 5
/// times a power of ten (0.1 for the thesis' runs to 3 or 4).
pub fn default_frame_time(until: f64) -> f64 {
    if !(until.is_finite() && until > 0.0) {
        return 1.0;
    }
    let raw = until / 40.0;
    let decade = 10f64.powf(raw.log10().floor());
    let best = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .min_by(|a, b| {
            let da = (a.ln() - raw.ln()).abs();
            let db = (b.ln() - raw.ln()).abs();
            da.total_cmp(&db)
        })
        .unwrap_or(raw);
    // 0.1 and not 0.10000000000000002
    let digits = (-best.log10().floor()).max(0.0) as i32 + 1;
    let p = 10f64.powi(digits);
    (best * p).round() / p
}

/// A time as the title shows it: one decimal like the thesis' `0.0` and `1.0` where that is
/// exact to 1e-9, else as few decimals as show it to that precision.
pub fn format_time(t: f64) -> String {
    let t = if t == 0.0 { 0.0 } else { t }; // no "-0.0"
    for digits in 1..=9 {
        let p = 10f64.powi(digits);
        if ((t * p).round() / p - t).abs() <= 1e-9 * t.abs().max(1.0) {
            return format!("{t:.*}", digits as usize);
        }
    }
    format!("{t}")
}

/// The sectors (0-based) a ball on the table touches in `scene`, ascending; none for a pocketed
/// ball or an unsectored scene.
pub fn sectors_of(scene: &Scene, b: &BallState) -> Vec<u32> {
    match (&scene.sectors, b.pocket) {
        (Some(layout), None) => layout.touching(b.traj.position, b.radius),
        _ => Vec::new(),
    }
}

/// The area centroid of a polygon (its vertex mean if the area is zero).
pub fn centroid(points: &[Vec2]) -> Vec2 {
    let n = points.len();
    let (mut a, mut cx, mut cy) = (0.0, 0.0, 0.0);
    for k in 0..n {
        let (p, q) = (points[k], points[(k + 1) % n]);
        let c = p.cross(q);
        a += c;
        cx += (p.x + q.x) * c;
        cy += (p.y + q.y) * c;
    }
    if a.abs() > 0.0 {
        Vec2::new(cx / (3.0 * a), cy / (3.0 * a))
    } else {
        let s = points.iter().fold(Vec2::ZERO, |s, p| s + *p);
        Vec2::new(s.x / n.max(1) as f64, s.y / n.max(1) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_are_formatted_like_the_thesis() {
        assert_eq!(format_time(0.0), "0.0");
        assert_eq!(format_time(-0.0), "0.0");
        assert_eq!(format_time(3.0), "3.0");
        assert_eq!(format_time(0.1 + 0.2), "0.3");
        assert_eq!(format_time(1.25), "1.25");
        assert_eq!(format_time(-3.0), "-3.0");
    }

    #[test]
    fn default_frame_times_are_round() {
        assert_eq!(default_frame_time(4.0), 0.1);
        assert_eq!(default_frame_time(3.0), 0.1);
        assert_eq!(default_frame_time(100.0), 2.0);
        assert_eq!(default_frame_time(0.3), 0.01);
        assert_eq!(default_frame_time(0.0), 1.0);
    }

    fn every(f: f64) -> Span {
        Span {
            frame_time: Some(f),
            ..Span::default()
        }
    }

    #[test]
    fn frame_times_reach_until() {
        assert_eq!(frame_times(every(1.0), 3.0), vec![0.0, 1.0, 2.0, 3.0]);
        assert_eq!(frame_times(every(0.35), 0.1).len(), 1);
        assert_eq!(frame_times(every(0.1), 0.35).len(), 4);
    }

    #[test]
    fn frames_about_a_reversal_are_mirror_images() {
        // 1.7 is not 17 tenths in floating point: the ends are the start and its mirror exactly
        for (q, f) in [(3.0, 0.2), (1.7, 0.1), (3.0, 0.1), (1.0, 0.3)] {
            let span = Span {
                start: -q,
                reverse_at: Some(0.0),
                frame_time: Some(f),
            };
            let times = frame_times(span, q);
            let whole = ((q / f).round() - q / f).abs() < 1e-9;
            if whole {
                assert_eq!((times[0], *times.last().unwrap()), (-q, q), "{q} {f}");
            }
            assert!(times[0] >= -q && times.contains(&0.0));
            for t in &times {
                assert!(
                    times.contains(&-t),
                    "{q} {f}: {t} has no mirror in {times:?}"
                );
            }
        }
    }

    #[test]
    fn centroid_of_a_square() {
        let sq = [
            Vec2::new(0.0, 0.0),
            Vec2::new(2.0, 0.0),
            Vec2::new(2.0, 2.0),
            Vec2::new(0.0, 2.0),
        ];
        assert_eq!(centroid(&sq), Vec2::new(1.0, 1.0));
    }
}
