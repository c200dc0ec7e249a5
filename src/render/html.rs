//! One self-contained HTML page with a player (no server, no network): the table drawn by
//! [`super::svg::table_layer`], the recording as JSON in a `<script type="application/json">`,
//! and a small script (`player.js`) that draws the moving part at any time.
//!
//! With the run's history embedded (every ball's trajectory pieces, up to
//! [`super::MAX_HISTORY`] by default), the page shows the exact state at any time; without it,
//! positions are interpolated linearly between the frames' positions. Event counts are exact at any time with the history
//! and per frame without it; message counts (objects engines) are those at the last frame not
//! after the time shown.
//!
//! The script offers `window.poolsim.seek(t)` and `window.poolsim.state()`; the query string
//! `?t=T` opens the page paused at `T`, and `&dump=1` also writes `state()` as JSON into
//! `<pre id="poolsim-state">` (for `chromium --headless --dump-dom`).

use super::svg::{self, colour, pocket_anchor, sector_anchors, Anchor, Style, View};
use super::{format_time, History, Recording, Scene};
use crate::engine::{BallState, EventKind, Fixed};
use crate::summary::MessageCounts;
use serde_json::{json, Value};

/// Frames keep their ball positions (`[x, y, vx, vy, pocket]`) beside the history up to this
/// many positions in all; the player needs them only when the history is missing.
pub const FRAME_POSITIONS_WITH_HISTORY: usize = 100_000;

/// The player's script.
const PLAYER: &str = include_str!("player.js");

/// The page's style sheet.
const CSS: &str = r#"
body { font-family: "DejaVu Sans", Verdana, sans-serif; margin: 12px; color: #111; background: #fafafa; }
h1 { font-size: 18px; margin: 0 0 8px 0; }
#bar { display: flex; flex-wrap: wrap; gap: 10px; align-items: center; margin-bottom: 8px; }
#bar button { min-width: 64px; }
#time { width: 360px; }
#clock { font-variant-numeric: tabular-nums; min-width: 70px; display: inline-block; }
#main { display: flex; gap: 16px; align-items: flex-start; flex-wrap: wrap; }
#stage svg { max-width: 100%; max-height: calc(100vh - 96px); width: auto; height: auto; border: 1px solid #ccc; background: white; }
#panel { font-size: 13px; min-width: 260px; }
#panel table { border-collapse: collapse; margin-bottom: 12px; }
#panel td, #panel th { padding: 2px 8px; border-bottom: 1px solid #eee; text-align: left; }
#panel td:last-child { text-align: right; font-variant-numeric: tabular-nums; }
#summary { white-space: pre-wrap; font-size: 11px; max-width: 420px; max-height: 320px; overflow: auto; background: #f0f0f0; padding: 6px; }
svg.hide-sectors .sector { display: none; }
svg.hide-labels .cushion-label { display: none; }
#errors { color: #b00; }
#mode { font-size: 12px; color: #555; margin-bottom: 8px; max-width: 320px; }
"#;

fn anchor_json(a: &Anchor) -> Value {
    json!({"x": a.x, "y": a.y, "h": a.h, "v": a.v})
}

fn ball_json(b: &BallState) -> Value {
    let v = b.velocity();
    json!([b.traj.position.x, b.traj.position.y, v.x, v.y, b.pocket])
}

/// Every sector's name, polygon and the anchors its label may take, best first.
fn sectors_json(scene: &Scene, view: &View) -> Vec<Value> {
    let Some(layout) = &scene.sectors else {
        return Vec::new();
    };
    layout
        .polys
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let pts: Vec<[f64; 2]> = p.points.iter().map(|q| [q.x, q.y]).collect();
            json!({
                "name": Scene::sector_name(k),
                "points": pts,
                "anchors": sector_anchors(scene, view, k).iter().map(anchor_json).collect::<Vec<_>>(),
            })
        })
        .collect()
}

/// Every frame: its time, the events and messages up to it, and (unless the history makes them
/// too many to be worth it) the balls.
fn frames_json(rec: &Recording) -> Vec<Value> {
    // With the history, the frames' positions are only a convenience for readers of the data.
    let positions = rec.history.is_none()
        || rec.shots.len() * rec.scene.table.n_balls as usize <= FRAME_POSITIONS_WITH_HISTORY;
    rec.shots
        .iter()
        .map(|s| {
            let mut f = json!({
                "t": s.frame.t,
                "events": s.events.by_kind,
                "messages": s.messages.as_deref().map(MessageCounts::from_named),
                "mirror_distance": s.mirror_distance,
            });
            if positions {
                f["balls"] = s.frame.balls.iter().map(ball_json).collect();
            }
            f
        })
        .collect()
}

/// The history: every ball's trajectory pieces and every event, for exact positions at any time.
fn history_json(h: &History) -> Value {
    let pieces: Vec<Vec<Value>> = h
        .pieces
        .iter()
        .map(|path| {
            path.iter()
                .map(|p| {
                    let tr = p.state.traj;
                    json!([
                        p.from,
                        tr.position.x,
                        tr.position.y,
                        tr.t0,
                        tr.velocity.x,
                        tr.velocity.y,
                        p.state.pocket
                    ])
                })
                .collect()
        })
        .collect();
    let events: Vec<Value> = h
        .events
        .iter()
        .map(|e| json!([e.t, e.kind as usize, e.a, e.b]))
        .collect();
    json!({"pieces": pieces, "events": events})
}

/// The recording as the player reads it.
pub fn data(rec: &Recording) -> Value {
    let scene = &rec.scene;
    let view = View::new(scene);
    let table = &scene.table;
    let first = rec.shots.first().map(|s| &s.frame.balls[..]).unwrap_or(&[]);
    let style = rec.style();
    let balls: Vec<Value> = (0..table.n_balls as usize)
        .map(|i| {
            let look = scene.looks.get(i).cloned().unwrap_or_default();
            json!({
                "name": table.name(i as u32),
                "r": first.get(i).map_or(0.0, |b| b.radius),
                "colour": look.colour,
                "label": look.label,
            })
        })
        .collect();
    let pocket_names: Vec<String> = (0..table.pockets.len() as u32)
        .map(|k| table.name(table.fixed_id(Fixed::Pocket(k))))
        .collect();
    let pockets: Vec<Value> = pocket_names
        .iter()
        .enumerate()
        .map(|(k, name)| json!({"name": name, "anchor": anchor_json(&pocket_anchor(scene, &view, k))}))
        .collect();
    let sectors = sectors_json(scene, &view);
    let message_types: Vec<&str> = rec
        .shots
        .first()
        .and_then(|s| s.messages.as_ref())
        .map(|m| m.iter().map(|(n, _)| *n).collect())
        .unwrap_or_default();
    let frames = frames_json(rec);
    let history = rec.history.as_ref().map(history_json);
    json!({
        "scenario": scene.name,
        "engine": rec.engine,
        "start": rec.start,
        "until": rec.until,
        "turn": scene.turn.as_ref().map(|t| json!({
            "at": t.at,
            "end": t.end,
            "starts": t.starts.iter().map(|p| p.map(|p| [p.x, p.y])).collect::<Vec<_>>(),
        })),
        "frame_time": rec.frame_time,
        "view": {
            "scale": view.scale, "lo_x": view.lo_x, "hi_y": view.hi_y,
            "left": view.left, "top": view.top, "width": view.width, "height": view.height,
        },
        "consts": {
            "font": svg::FONT,
            "line": svg::LINE,
            "list_max": svg::LIST_MAX,
            "names_balls": svg::names_balls(scene, &view, first),
            "vectors": style.vectors,
            "arrow_time": style.arrow_time,
            "table_box": [scene.table.lo.x, scene.table.lo.y, scene.table.hi.x, scene.table.hi.y],
            "colours": {
                "ball": colour::BALL, "vector": colour::VECTOR, "text": colour::TEXT,
                "sector": colour::SECTOR, "quiet": colour::QUIET,
            },
        },
        "balls": balls,
        "pocket_names": pocket_names,
        "pockets": pockets,
        "sectors": sectors,
        "event_kinds": EventKind::ALL.iter().map(|k| k.name()).collect::<Vec<_>>(),
        "message_types": message_types,
        "frames": frames,
        "history": history,
        "summary": rec.summary,
    })
}

/// JSON that can stand inside a `<script>` element: no `<` at all (so no `</script>`).
fn script_safe(v: &Value) -> String {
    serde_json::to_string(v)
        .expect("a recording serializes")
        .replace('<', "\\u003c")
}

/// The whole page.
pub fn page(rec: &Recording) -> String {
    let scene = &rec.scene;
    let view = View::new(scene);
    let name = svg::escape(&scene.name);
    let mut out = String::with_capacity(64 * 1024);
    out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    out.push_str(&format!(
        "<title>poolsim: {name}, {} engine, {} to {}</title>\n<style>{CSS}</style>\n</head>\n<body>\n",
        rec.engine,
        format_time(rec.start),
        format_time(rec.until)
    ));
    out.push_str(&format!(
        "<h1>poolsim: {name} ({} engine, {} balls, frames every {})</h1>\n",
        rec.engine,
        scene.table.n_balls,
        format_time(rec.frame_time)
    ));
    out.push_str(concat!(
        "<div id=\"bar\">",
        "<button id=\"play\" type=\"button\">Play</button>",
        "<button id=\"back\" type=\"button\" title=\"previous frame\">&#9664;</button>",
        "<button id=\"fwd\" type=\"button\" title=\"next frame\">&#9654;</button>",
        "<input id=\"time\" type=\"range\" min=\"0\" value=\"0\" aria-label=\"time\">",
        "<span>t = <span id=\"clock\">0.0</span></span>",
        "<span id=\"mirror\" title=\"after a reversal: the largest distance between a ball now and where it was at the mirror time\"></span>",
        "<label>speed <select id=\"speed\">",
        "<option value=\"0.1\">0.1&#215;</option><option value=\"0.25\">0.25&#215;</option>",
        "<option value=\"0.5\">0.5&#215;</option><option value=\"1\" selected>1&#215;</option>",
        "<option value=\"2\">2&#215;</option><option value=\"4\">4&#215;</option>",
        "<option value=\"10\">10&#215;</option></select></label>",
        "<label><input id=\"loop\" type=\"checkbox\"> loop</label>",
        "<label><input id=\"show-sectors\" type=\"checkbox\" checked> sectors</label>",
        "<label><input id=\"show-vectors\" type=\"checkbox\" checked> vectors</label>",
        "<label><input id=\"show-labels\" type=\"checkbox\" checked> labels</label>",
        "</div>\n<div id=\"main\">\n<div id=\"stage\">"
    ));
    out.push_str(&svg::open_svg(&view, false).replacen("<svg ", "<svg id=\"pool\" ", 1));
    out.push_str(&svg::table_layer(scene, &view, &Style::default()));
    out.push_str("<g id=\"dyn\"></g></svg></div>\n");
    out.push_str(
        "<div id=\"panel\"><div id=\"mode\"></div><table id=\"counts\"></table>\
         <div>run summary (<code>poolsim run --json</code>):</div>\
         <pre id=\"summary\"></pre><div id=\"errors\"></div></div>\n</div>\n",
    );
    out.push_str("<pre id=\"poolsim-state\" hidden></pre>\n");
    out.push_str(&format!(
        "<script id=\"poolsim-data\" type=\"application/json\">{}</script>\n",
        script_safe(&data(rec))
    ));
    out.push_str(concat!(
        "<script>\nwindow.addEventListener('error', function (e) {\n",
        "  var d = document.getElementById('errors'); if (d) d.textContent += 'error: ' + e.message + '\\n';\n",
        "});\n</script>\n"
    ));
    out.push_str("<script>\n");
    out.push_str(PLAYER);
    out.push_str(concat!(
        "\ndocument.getElementById('summary').textContent =\n",
        "  JSON.stringify(window.poolsim.data.summary, null, 1);\n",
        "</script>\n</body>\n</html>\n"
    ));
    out
}
