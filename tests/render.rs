//! Graphics (thesis 4.2 and the plates): what the frames show, that every engine draws the same
//! picture, and the files `poolsim render` and `poolsim demo` write (SVG, PNG, GIF, one HTML
//! page). No timing is asserted.

use poolsim::model::pool::NvDelay;
use poolsim::render::raster::Rasterizer;
use poolsim::render::svg::{self, Style};
use poolsim::render::{html, record, write, Output, Recording, RenderConfig};
use poolsim::run::{EngineKind, SectorChoice};
use poolsim::scenario::{self, builtin::Params, Scenario};
use poolsim::summary::MessageCounts;
use std::path::Path;
use std::process::Command;

mod common;

/// The sectored objects engine on `grid`.
fn sectored(grid: SectorChoice) -> EngineKind {
    EngineKind::Sectored {
        sectors: grid,
        news: poolsim::run::FixedNews::Near,
    }
}
fn scenario(spec: &str) -> Scenario {
    scenario::load(spec, &Params::default()).expect("the scenario loads")
}

fn plate7() -> Scenario {
    scenario(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/plate7.toml"
    ))
}

fn config(engine: EngineKind, until: f64, frame_time: f64) -> RenderConfig {
    RenderConfig {
        check: true,
        ..RenderConfig::new(engine, until, frame_time)
    }
}

fn plate1(engine: EngineKind) -> Recording {
    record(&scenario("plate1"), &config(engine, 3.0, 1.0)).expect("plate1 records")
}

const OBJECTS: EngineKind = EngineKind::Objects {
    delay: NvDelay::Exact,
};

/// Every element `<TAG ...>` whose start tag contains `marker`.
fn elements<'a>(svg: &'a str, tag: &str, marker: &str) -> Vec<&'a str> {
    let open = format!("<{tag} ");
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(i) = rest.find(&open) {
        let el = &rest[i..];
        let end = el.find('>').expect("a start tag ends");
        if el[..end].contains(marker) {
            out.push(&el[..=end]);
        }
        rest = &el[end..];
    }
    out
}

/// The value of attribute `name` in a start tag.
fn attr<'a>(el: &'a str, name: &str) -> &'a str {
    let key = format!(" {name}=\"");
    let i = el.find(&key).unwrap_or_else(|| panic!("no {name} in {el}")) + key.len();
    let len = el[i..].find('"').expect("the value ends");
    &el[i..i + len]
}

fn num(el: &str, name: &str) -> f64 {
    attr(el, name)
        .parse()
        .unwrap_or_else(|_| panic!("{name} is not a number in {el}"))
}

/// The lines of the `<text class="CLASS">` block whose first line is `first`.
fn text_block(svg: &str, class: &str, first: &str) -> Vec<String> {
    let open = format!("<text class=\"{class}\"");
    for (i, _) in svg.match_indices(&open) {
        let body = &svg[i..i + svg[i..].find("</text>").expect("a text ends")];
        let lines: Vec<String> = body
            .split("<tspan")
            .skip(1)
            .map(|t| {
                let s = &t[t.find('>').expect("a tspan opens") + 1..];
                s[..s.find("</tspan>").expect("a tspan ends")].to_string()
            })
            .collect();
        if lines.first().map(String::as_str) == Some(first) {
            return lines;
        }
    }
    panic!("no {class} block starting with {first}");
}

/// Table coordinates of a pixel, from the mapping on the root element.
fn to_table(svg: &str, x: f64, y: f64) -> (f64, f64) {
    let root = elements(svg, "svg", "data-scale")[0];
    let s = num(root, "data-scale");
    (
        num(root, "data-lo-x") + (x - num(root, "data-left")) / s,
        num(root, "data-hi-y") - (y - num(root, "data-top")) / s,
    )
}

#[test]
fn plate1_at_0_shows_the_title_names_and_ball_2_s_velocity() {
    let rec = plate1(EngineKind::EventList);
    assert_eq!(rec.shots.len(), 4);
    let svg = svg::frame(&rec.scene, &rec.shots[0], &Style::default());
    for text in ["POOL SIMULATION AT 0", "Ball-1", "Ball-2", "Pocket-1"] {
        assert!(svg.contains(text), "{text} missing");
    }
    assert!(svg.contains("POOL SIMULATION AT 0.0"), "the thesis' format");
    let ball = elements(&svg, "circle", "data-ball=\"Ball-2\"");
    assert_eq!(ball.len(), 1);
    let (cx, cy) = (num(ball[0], "cx"), num(ball[0], "cy"));
    assert_eq!(to_table(&svg, cx, cy), (300.0, 100.0));
    let v = elements(&svg, "line", "data-ball=\"Ball-2\"");
    assert_eq!(v.len(), 1, "one velocity vector for Ball-2");
    assert_eq!(attr(v[0], "class"), "velocity");
    assert_eq!(
        (num(v[0], "x1"), num(v[0], "y1")),
        (cx, cy),
        "from the centre"
    );
    let (hx, hy) = to_table(&svg, num(v[0], "x2"), num(v[0], "y2"));
    // one time unit at speed 100 straight up; pixels have two decimals
    assert!(
        (hx - 300.0).abs() < 0.02 && (hy - 200.0).abs() < 0.02,
        "head at ({hx}, {hy})"
    );
    assert!(num(v[0], "y2") < cy, "up on the table is up on the screen");
    assert!(
        elements(&svg, "line", "data-ball=\"Ball-1\"").is_empty(),
        "Ball-1 is at rest: no vector"
    );
    assert_eq!(text_block(&svg, "pocket-label", "Pocket-1"), ["Pocket-1"]);
}

#[test]
fn plate4_lists_ball_1_under_pocket_1() {
    let rec = plate1(EngineKind::EventList);
    let svg = svg::frame(&rec.scene, &rec.shots[3], &Style::default());
    assert!(svg.contains("POOL SIMULATION AT 3.0"));
    assert_eq!(
        text_block(&svg, "pocket-label", "Pocket-1"),
        ["Pocket-1", "Ball-1"]
    );
    assert!(elements(&svg, "circle", "data-ball=\"Ball-1\"").is_empty());
    assert_eq!(elements(&svg, "circle", "data-ball=\"Ball-2\"").len(), 1);
    // plates 2 and 3: Ball-1 still on the table at 2.0, moving after the collision at 1.6
    let svg2 = svg::frame(&rec.scene, &rec.shots[2], &Style::default());
    assert_eq!(elements(&svg2, "line", "data-ball=\"Ball-1\"").len(), 1);
    assert_eq!(text_block(&svg2, "pocket-label", "Pocket-1"), ["Pocket-1"]);
}

#[test]
fn plate7_lists_the_balls_in_each_sector_and_the_sectors_of_each_ball() {
    let s = plate7();
    let mut cfg = config(EngineKind::EventList, 0.0, 1.0);
    cfg.sectors = Some(SectorChoice::Scenario);
    let rec = record(&s, &cfg).expect("plate7 records");
    let svg = svg::frame(&rec.scene, &rec.shots[0], &Style::default());
    assert_eq!(elements(&svg, "polygon", "class=\"sector\"").len(), 4);
    assert_eq!(
        text_block(&svg, "label sector-label", "Sector-3"),
        ["Sector-3", "Ball-2", "Ball-3"]
    );
    assert_eq!(
        text_block(&svg, "label sector-label", "Sector-2"),
        ["Sector-2", "Ball-4", "Ball-5", "Ball-7"]
    );
    assert_eq!(
        text_block(&svg, "label ball-label", "Ball-4"),
        ["Ball-4", "Sector-1", "Sector-2"]
    );
    assert_eq!(
        text_block(&svg, "label ball-label", "Ball-3"),
        ["Ball-3", "Sector-3"]
    );
}

/// The pixel boxes of the `<text class="CLASS">` blocks of a frame, by the widths of DejaVu Sans
/// (the frame's font): left, top, right, bottom.
fn text_boxes(svg: &str, class: &str) -> Vec<[f64; 4]> {
    let open = format!("<text class=\"{class}\"");
    svg.match_indices(&open)
        .map(|(i, _)| {
            let body = &svg[i..i + svg[i..].find("</text>").expect("a text ends")];
            let tag = &body[..body.find('>').expect("a start tag ends") + 1];
            let font = num(tag, "font-size");
            let spans = elements(body, "tspan", "y=");
            let lines: Vec<&str> = body
                .split("<tspan")
                .skip(1)
                .map(|t| {
                    let s = &t[t.find('>').expect("a tspan opens") + 1..];
                    &s[..s.find("</tspan>").expect("a tspan ends")]
                })
                .collect();
            let w = lines
                .iter()
                .map(|l| poolsim::render::text_box::width(l, font))
                .fold(0.0, f64::max);
            let x0 = match attr(tag, "text-anchor") {
                "start" => num(tag, "x"),
                "end" => num(tag, "x") - w,
                _ => num(tag, "x") - w / 2.0,
            };
            let (top, bottom) = (num(spans[0], "y"), num(spans[spans.len() - 1], "y"));
            [x0, top - 0.93 * font, x0 + w, bottom + 0.24 * font]
        })
        .collect()
}

#[test]
fn sector_lists_in_frames_step_off_the_balls_and_their_names() {
    // the 36-ball gas on 2 x 2 sectors: at t = 1 balls sit on the centroids of sectors 1 and 4,
    // and their lists move to free room within the sector; no frame loses a sector's name
    let mut cfg = config(sectored(SectorChoice::Grid(2, 2)), 4.0, 1.0);
    cfg.sectors = Some(SectorChoice::Grid(2, 2));
    let rec = record(&scenario("gas"), &cfg).expect("the gas records");
    let meets =
        |a: &[f64; 4], b: &[f64; 4]| a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
    for shot in &rec.shots {
        let svg = svg::frame(&rec.scene, shot, &Style::default());
        let mut taken = text_boxes(&svg, "label ball-label");
        assert_eq!(taken.len(), 36);
        for c in elements(&svg, "circle", "class=\"ball\"") {
            let (x, y, r) = (num(c, "cx"), num(c, "cy"), num(c, "r"));
            taken.push([x - r, y - r, x + r, y + r]);
        }
        let sectors = text_boxes(&svg, "label sector-label");
        assert_eq!(
            sectors.len(),
            4,
            "t = {}: a sector lost its label",
            shot.frame.t
        );
        for s in sectors {
            assert!(
                !taken.iter().any(|t| meets(t, &s)),
                "t = {}: {s:?}",
                shot.frame.t
            );
            taken.push(s);
        }
        // at t = 0 the balls stand on a lattice with no room for a list between them
        for k in 1..=4 {
            let lines = text_block(&svg, "label sector-label", &format!("Sector-{k}"));
            let room = shot.frame.t == 1.0;
            assert!(!room || lines.len() > 1, "t = 1: Sector-{k} lists no ball");
        }
    }
}

/// The SVG without the counts (the objects engines add a messages line).
fn picture(rec: &Recording, k: usize) -> String {
    let svg = svg::frame(&rec.scene, &rec.shots[k], &Style::default());
    let i = svg.find("<text class=\"counts\"").expect("counts");
    let j = i + svg[i..].find("</text>").expect("counts end");
    format!("{}{}", &svg[..i], &svg[j..])
}

#[test]
fn every_engine_draws_the_same_picture() {
    let a = plate1(EngineKind::EventList);
    let b = plate1(OBJECTS);
    assert!(a.shots[0].messages.is_none());
    assert!(b.shots[0].messages.is_some());
    for k in 0..a.shots.len() {
        assert_eq!(a.shots[k].frame, b.shots[k].frame, "frame {k}");
        assert_eq!(a.shots[k].events, b.shots[k].events, "frame {k}");
        assert_eq!(picture(&a, k), picture(&b, k), "frame {k}");
    }
    // the sectored gas (plates 9-13) against the event-list engine with the same sectors drawn
    let gas = scenario("gas");
    let grid = SectorChoice::Grid(2, 2);
    let mut cfg = config(EngineKind::EventList, 1.0, 0.25);
    cfg.sectors = Some(grid);
    let a = record(&gas, &cfg).expect("event-list records");
    cfg.engine = sectored(grid);
    let b = record(&gas, &cfg).expect("sectored records");
    assert_eq!(a.shots.len(), 5);
    for k in 0..a.shots.len() {
        assert_eq!(a.shots[k].frame, b.shots[k].frame, "frame {k}");
        assert_eq!(a.shots[k].events, b.shots[k].events, "frame {k}");
        assert_eq!(picture(&a, k), picture(&b, k), "frame {k}");
    }
}

#[test]
fn the_history_gives_the_engines_frames_and_the_messages_add_up() {
    for engine in [EngineKind::EventList, OBJECTS] {
        let rec = record(&scenario("gas"), &config(engine, 2.0, 0.1)).expect("records");
        let h = rec.history.as_ref().expect("a short run keeps its history");
        assert_eq!(
            h.events.len() as u64,
            rec.shots.last().unwrap().events.total()
        );
        for shot in &rec.shots {
            assert_eq!(h.frame_at(shot.frame.t), shot.frame, "t = {}", shot.frame.t);
        }
    }
    let grid = SectorChoice::Grid(2, 2);
    let rec = record(&scenario("gas"), &config(sectored(grid), 2.0, 0.5)).expect("records");
    let h = rec.history.as_ref().expect("history");
    for shot in &rec.shots {
        assert_eq!(h.frame_at(shot.frame.t), shot.frame, "t = {}", shot.frame.t);
    }
    // messages grow, and the last frame's are the run's (the run at the end time)
    let totals: Vec<u64> = rec
        .shots
        .iter()
        .map(|s| MessageCounts::from_named(s.messages.as_ref().unwrap()).total)
        .collect();
    assert!(totals.windows(2).all(|w| w[0] <= w[1]), "{totals:?}");
    let last = MessageCounts::from_named(rec.shots.last().unwrap().messages.as_ref().unwrap());
    assert_eq!(last, rec.summary.messages);
}

#[test]
fn the_page_is_one_file_with_its_data_and_no_network() {
    let grid = SectorChoice::Grid(2, 2);
    let mut cfg = config(sectored(grid), 4.0, 0.1);
    cfg.sectors = Some(grid);
    let rec = record(&scenario("gas"), &cfg).expect("records");
    let page = html::page(&rec);
    assert!(page.starts_with("<!DOCTYPE html>"));
    for bad in [
        "http://", "https://", "<link", " src=", "url(http", "@import", "fetch(",
    ] {
        assert!(!page.contains(bad), "the page contains {bad}");
    }
    assert!(page.contains("window.poolsim"));
    let open = "<script id=\"poolsim-data\" type=\"application/json\">";
    let i = page.find(open).expect("the data") + open.len();
    let json = &page[i..i + page[i..].find("</script>").expect("the data ends")];
    let data: serde_json::Value = serde_json::from_str(json).expect("the data is JSON");
    let frames = data["frames"].as_array().expect("frames");
    assert_eq!(frames.len(), 41);
    assert_eq!(frames[10]["t"], 1.0);
    assert_eq!(frames[10]["balls"].as_array().unwrap().len(), 36);
    assert!(frames[40]["messages"]["total"].as_u64().unwrap() > 0);
    assert_eq!(data["sectors"].as_array().unwrap().len(), 4);
    let pieces = data["history"]["pieces"].as_array().expect("the history");
    assert_eq!(pieces.len(), 36);
    assert_eq!(data["summary"]["balls"], 36);
}

fn rasterizer() -> Rasterizer {
    Rasterizer::new().unwrap_or_else(|e| {
        panic!("PNG and GIF need the DejaVu font (Debian package fonts-dejavu-core): {e}")
    })
}

#[test]
fn png_frames_and_the_gif_have_their_signatures() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let rec = plate1(EngineKind::EventList);
    let r = rasterizer();
    let folder = dir.path().join("plate1");
    write(&rec, &Output::from_path(&folder).unwrap(), Some(&r)).expect("frames written");
    for k in 0..4 {
        let png = std::fs::read(folder.join(format!("frame-000{k}.png"))).expect("a PNG");
        assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "frame {k}");
        let svg = std::fs::read_to_string(folder.join(format!("frame-000{k}.svg"))).expect("SVG");
        assert!(svg.contains(&format!("POOL SIMULATION AT {k}.0")));
    }
    let gif = dir.path().join("plate1.gif");
    write(&rec, &Output::from_path(&gif).unwrap(), Some(&r)).expect("GIF written");
    let bytes = std::fs::read(&gif).expect("a GIF");
    assert!(bytes.starts_with(b"GIF89a"));
    assert_eq!(bytes.last(), Some(&0x3b), "the GIF trailer");
}

#[test]
fn labels_are_drawn_in_the_png() {
    // The title's pixels: with the font, the band above the table has dark pixels; the same
    // picture without text has none there.
    let rec = plate1(EngineKind::EventList);
    let svg = svg::frame(&rec.scene, &rec.shots[0], &Style::default());
    let r = rasterizer();
    let dark = |svg: &str| {
        let p = r.pixmap(svg).expect("rasterized");
        let w = p.width() as usize;
        p.data()
            .chunks(4)
            .enumerate()
            .filter(|(i, px)| i / w < 40 && px[0] < 100)
            .count()
    };
    assert!(dark(&svg) > 100, "the title is drawn");
    let i = svg.find("<text class=\"title\"").unwrap();
    let j = i + svg[i..].find("</text>").unwrap() + "</text>".len();
    let untitled = format!("{}{}", &svg[..i], &svg[j..]);
    assert_eq!(dark(&untitled), 0);
}

fn poolsim(args: &[&str], dir: &Path, env: &[(&str, &str)]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_poolsim"))
        .args(args)
        .current_dir(dir)
        .envs(env.iter().copied())
        .stdin(std::process::Stdio::null())
        .output()
        .expect("the poolsim binary runs")
}

#[test]
fn render_and_demo_from_the_command_line() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let d = dir.path();
    let out = poolsim(
        &["render", "plate1", "--out", "frames", "--frame-time", "1"],
        d,
        &[],
    );
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    assert!(out.stderr.is_empty(), "{out:?}");
    for k in 0..4 {
        assert!(d.join(format!("frames/frame-000{k}.png")).is_file());
        assert!(d.join(format!("frames/frame-000{k}.svg")).is_file());
    }
    assert!(!d.join("frames/frame-0004.png").exists());

    let out = poolsim(
        &["render", "plate1", "--out", "p.gif", "--frame-time", "0.5"],
        d,
        &[("POOLSIM_FONT", "/nonexistent/font.ttf")],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("poolsim: /nonexistent/font.ttf: cannot read the font"),
        "{err}"
    );
    assert!(
        err.contains("fonts-dejavu-core") && !err.contains("panicked"),
        "{err}"
    );

    // the page needs no font
    let out = poolsim(
        &["render", "plate1", "--out", "p.html", "--engine", "objects"],
        d,
        &[("POOLSIM_FONT", "/nonexistent/font.ttf")],
    );
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    assert!(std::fs::read_to_string(d.join("p.html"))
        .unwrap()
        .contains("poolsim-data"));

    for bad in [
        vec!["render", "plate1", "--out", "x.html", "--frame-time", "0"],
        vec!["render", "plate1", "--out", "x.html", "--engine", "warp"],
        vec!["render", "plate1", "--out", "x.html", "--sectors", "0"],
        vec!["render", "plate1", "--out", "x.png"],
        vec![
            "render",
            "plate1",
            "--out",
            "x.html",
            "--engine",
            "time-step",
        ],
        vec!["render", "nosuch", "--out", "x.html"],
    ] {
        let out = poolsim(&bad, d, &[]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }

    let out = poolsim(&["demo"], d, &[]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    assert!(text.contains("poolsim-demo.html"), "{text}");
    assert!(d.join("poolsim-demo.html").is_file());
    let out = poolsim(&["demo", "--json", "--out", "d.html"], d, &[]);
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("only the summary JSON on stdout");
    assert_eq!(v["balls"], 36);
    assert_eq!(v["page"], "d.html");
    assert!(
        v["messages"]["SectorEntry"].as_u64().unwrap() > 0,
        "sectored"
    );
    assert!(d.join("d.html").is_file());
}

/// The headless browser, if one is installed (Debian's `chromium`).
fn chromium() -> Option<&'static str> {
    ["chromium", "chromium-browser"].into_iter().find(|b| {
        Command::new(b)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success())
    })
}

/// The headless browser, or `None` after saying that the test skips the browser. CI installs
/// Chromium and sets POOLSIM_REQUIRE_BROWSER, so there this never skips.
fn browser_or_skip() -> Option<&'static str> {
    let found = chromium();
    if found.is_none() {
        assert!(
            std::env::var_os("POOLSIM_REQUIRE_BROWSER").is_none(),
            "POOLSIM_REQUIRE_BROWSER is set but no headless Chromium was found"
        );
        eprintln!("skipped the browser: no headless browser (install Debian's `chromium` package)");
    }
    found
}

/// Opens `page` at `?t=T&dump=1` in headless Chromium: the state the page wrote into
/// `#poolsim-state`, and every console message it logged.
fn browse(browser: &str, page: &Path, t: &str) -> (serde_json::Value, Vec<String>) {
    let profile = tempfile::tempdir().expect("a profile folder");
    let url = format!("file://{}?t={t}&dump=1", page.display());
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--window-size=1280,1000",
            "--enable-logging=stderr",
            "--v=0",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(["--dump-dom", &url])
        .stdin(std::process::Stdio::null())
        .output()
        .expect("chromium runs");
    let dom = String::from_utf8_lossy(&out.stdout);
    let console: Vec<String> = String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.contains(":CONSOLE"))
        .map(str::to_string)
        .collect();
    let open = "<pre id=\"poolsim-state\">";
    let i = dom
        .find(open)
        .unwrap_or_else(|| panic!("no state in the page at t = {t}: {console:?}"))
        + open.len();
    let text = dom[i..i + dom[i..].find("</pre>").expect("the state ends")]
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    (
        serde_json::from_str(&text).expect("the state is JSON"),
        console,
    )
}

#[test]
fn the_page_in_a_browser_shows_the_trace_s_positions() {
    let Some(browser) = browser_or_skip() else {
        return;
    };
    let dir = tempfile::tempdir().expect("a temporary folder");
    let grid = SectorChoice::Grid(2, 2);
    let mut cfg = config(sectored(grid), 4.0, 0.1);
    cfg.sectors = Some(grid);
    // Without its history the page moves balls linearly between frames: exact for plate 1
    // between 1.0 and 1.5, before the collision at 1.6.
    let mut short = config(EngineKind::EventList, 3.0, 0.5);
    short.max_history = 0;
    let short = record(&scenario("plate1"), &short).expect("records");
    assert!(short.history.is_none());
    let exact = plate1(EngineKind::EventList);
    let cases = [
        (&exact, &exact, vec!["0", "1.6", "2.6", "2.75"]),
        (&short, &exact, vec!["1.25"]),
    ];
    let gas = record(&scenario("gas"), &cfg).expect("records");
    let cases = cases
        .into_iter()
        .chain([(&gas, &gas, vec!["1.5", "3.14159"])]);
    for (k, (rec, truth, times)) in cases.enumerate() {
        let page = dir.path().join(format!("page{k}.html"));
        std::fs::write(&page, html::page(rec)).expect("the page is written");
        let h = truth.history.as_ref().expect("the history of the truth");
        for t in times {
            let (state, console) = browse(browser, &page, t);
            assert!(console.is_empty(), "console at t = {t}: {console:?}");
            let t: f64 = t.parse().unwrap();
            assert_eq!(state["t"], t);
            assert_eq!(state["exact"], rec.history.is_some());
            let frame = h.frame_at(t);
            let balls = state["balls"].as_array().expect("balls");
            assert_eq!(balls.len(), frame.balls.len());
            for (i, (got, want)) in balls.iter().zip(&frame.balls).enumerate() {
                assert_eq!(got["name"], format!("Ball-{}", i + 1));
                let p = want.traj.position;
                let (x, y) = (got["x"].as_f64().unwrap(), got["y"].as_f64().unwrap());
                let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1.0);
                assert!(close(x, p.x) && close(y, p.y), "Ball-{} at {t}", i + 1);
                let pocket = want.pocket.map(|k| format!("Pocket-{}", k + 1));
                assert_eq!(got["pocket"], serde_json::json!(pocket), "Ball-{}", i + 1);
            }
            let events = match &rec.history {
                Some(h) => h.events.iter().filter(|e| e.t <= t).count() as u64,
                None => h.events.iter().filter(|e| e.t <= 1.0).count() as u64,
            };
            let shown: u64 = state["events"]
                .as_object()
                .unwrap()
                .values()
                .map(|v| v.as_u64().unwrap())
                .sum();
            assert_eq!(shown, events, "events up to {t}");
        }
    }
}

/// The page's layout in a 1280 x 1000 window, by its geometry: no two labels overlap, every
/// velocity arrow stays on the table's picture, and the counts line is inside the window; the
/// 36-ball gas, plain and on sectors (a sector's list that would cover a name goes to hover),
/// the break, and 10^4 balls (whose vectors are off by default).
#[test]
fn the_page_s_layout_keeps_labels_apart_and_arrows_on_the_table() {
    let Some(browser) = browser_or_skip() else {
        return;
    };
    let dir = tempfile::tempdir().expect("a temporary folder");
    let big = scenario::load(
        "gas",
        &Params {
            balls: Some(10_000),
            ..Params::default()
        },
    )
    .unwrap();
    let cases = [
        ("gas", scenario("gas"), 2.0, 0.5, None),
        (
            "gas on 2 x 2 sectors",
            scenario("gas"),
            2.0,
            0.5,
            Some(SectorChoice::Grid(2, 2)),
        ),
        ("pool", scenario("pool"), 2.0, 0.5, None),
        ("gas of 10^4", big, 0.2, 0.1, None),
    ];
    for (name, s, until, frame, sectors) in cases {
        let mut cfg = config(EngineKind::EventList, until, frame);
        cfg.sectors = sectors;
        let rec = record(&s, &cfg).expect("records");
        let page = dir.path().join("layout.html");
        std::fs::write(&page, html::page(&rec)).expect("the page is written");
        for t in ["0", "1"] {
            let (state, console) = browse(browser, &page, t);
            assert!(console.is_empty(), "{name} at {t}: {console:?}");
            let l = &state["layout"];
            let rect = |v: &serde_json::Value| -> [f64; 4] {
                let a = v.as_array().expect("a box");
                [0, 1, 2, 3].map(|k| a[k].as_f64().unwrap())
            };
            let [ww, wh] = [0, 1].map(|k| l["window"][k].as_f64().unwrap());
            let counts = rect(&l["counts"]);
            assert!(
                counts[2] <= ww && counts[3] <= wh,
                "{name} at {t}: the counts line {counts:?} leaves the {ww} x {wh} window"
            );
            let table = rect(&l["table"]);
            let arrows = l["arrows"].as_array().unwrap();
            if s.balls.len() > svg::MAX_NAMED_BALLS {
                assert!(arrows.is_empty(), "{name}: vectors off by default");
            }
            for a in arrows {
                let a = rect(a);
                let inside = |x: f64, y: f64| {
                    x >= table[0] - 1.0
                        && x <= table[2] + 1.0
                        && y >= table[1] - 1.0
                        && y <= table[3] + 1.0
                };
                assert!(
                    inside(a[2], a[3]),
                    "{name} at {t}: arrow {a:?} leaves the table {table:?}"
                );
            }
            let labels: Vec<[f64; 4]> = l["labels"].as_array().unwrap().iter().map(rect).collect();
            for (i, a) in labels.iter().enumerate() {
                for b in &labels[i + 1..] {
                    let apart = a[2] <= b[0] + 0.5
                        || b[2] <= a[0] + 0.5
                        || a[3] <= b[1] + 0.5
                        || b[3] <= a[1] + 0.5;
                    assert!(apart, "{name} at {t}: labels {a:?} and {b:?} overlap");
                }
            }
        }
    }
}

/// The break's balls in their colours with their numbers on white discs; the cue ball plain.
#[test]
fn pool_balls_are_drawn_in_their_colours_with_their_numbers() {
    let rec = record(&scenario("pool"), &config(EngineKind::EventList, 0.0, 1.0)).expect("records");
    let svg = svg::frame(&rec.scene, &rec.shots[0], &rec.style());
    // the 8 in the middle of the third row: Ball-6
    let eight = elements(&svg, "circle", "data-ball=\"Ball-6\"");
    assert!(eight[0].contains("fill=\"#111111\""), "{}", eight[0]);
    assert_eq!(text_block(&svg, "label ball-label", "8"), ["8"]);
    let cue = elements(&svg, "circle", "data-ball=\"Ball-1\"");
    assert!(cue[0].contains("fill=\"#f4f1e6\""), "{}", cue[0]);
    assert!(!svg.contains(">Ball-1<"), "the cue ball carries no text");
    assert_eq!(elements(&svg, "circle", "class=\"ball-disc\"").len(), 15);
}

/// The reversal experiment recorded from -3 through the reversal at 0 to 3 on `engine`.
fn reversal(engine: EngineKind, frame_time: f64) -> Recording {
    let cfg = RenderConfig {
        start: -3.0,
        reverse_at: Some(0.0),
        ..config(engine, 3.0, frame_time)
    };
    record(&scenario("reversal"), &cfg).expect("the reversal records")
}

#[test]
fn a_reversal_is_recorded_from_its_start_back_to_it() {
    // Time Warp on sectors, like the sequential sectored engine, is stopped at each frame time
    let grid = SectorChoice::Grid(2, 2);
    for engine in [
        EngineKind::EventList,
        OBJECTS,
        sectored(grid),
        common::two_workers(Some(grid)),
    ] {
        let rec = reversal(engine, 0.2);
        let times: Vec<f64> = rec.shots.iter().map(|s| s.frame.t).collect();
        assert_eq!((times[0], times[30], times.len()), (-3.0, 3.0, 31));
        for (k, s) in rec.shots.iter().enumerate() {
            // every frame's mirror is drawn: -t for t, and the distance is measured after 0
            assert_eq!(times[30 - k], -s.frame.t);
            assert_eq!(s.mirror_distance.is_some(), s.frame.t >= 0.0);
        }
        let back = rec.shots[30].mirror_distance.unwrap();
        assert!(back > 0.0 && back < 1e-9, "{}: {back}", rec.engine);
        // the history holds the reversal: it gives every frame's balls, before and after it
        let h = rec.history.as_ref().expect("a history");
        for s in &rec.shots {
            for (a, b) in h.frame_at(s.frame.t).balls.iter().zip(&s.frame.balls) {
                let d = (a.traj.position - b.traj.position).norm();
                assert!(d < 1e-9, "{} at {}: {d}", rec.engine, s.frame.t);
                assert!((a.traj.velocity - b.traj.velocity).norm() < 1e-9);
            }
        }
        let turn = rec
            .scene
            .turn
            .as_ref()
            .expect("the scene knows the reversal");
        assert_eq!((turn.at, turn.end), (0.0, 3.0));
        let first = svg::frame(&rec.scene, &rec.shots[0], &Style::default());
        let last = svg::frame(&rec.scene, &rec.shots[30], &Style::default());
        assert!(first.contains(">POOL SIMULATION AT -3.0<"));
        assert!(first.contains(">every ball turns around at 0.0<"));
        assert!(last.contains(">POOL SIMULATION AT 3.0<"));
        assert!(last.contains("where it was at -3.0 is "));
        assert_eq!(elements(&first, "circle", "class=\"start\"").len(), 0);
        assert_eq!(elements(&last, "circle", "class=\"start\"").len(), 16);
    }
}

/// Each ball's centre in a frame's SVG, in table coordinates, by name.
fn centres(svg: &str) -> Vec<(String, (f64, f64))> {
    elements(svg, "circle", "class=\"ball\"")
        .into_iter()
        .map(|c| {
            let at = to_table(svg, num(c, "cx"), num(c, "cy"));
            (attr(c, "data-ball").to_string(), at)
        })
        .collect()
}

#[test]
fn reverse_draws_plates_5_and_6_and_a_page() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let d = dir.path();
    let args = ["reverse", "reversal", "--quit", "3", "--json", "--out"];
    let out = poolsim(&[&args[..], &["plates"]].concat(), d, &[]);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("only the report on stdout");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("wrote plates: 31 frames every 0.2"),
        "{err}"
    );
    let balls = report["balls"]
        .as_array()
        .expect("each ball's start and end");
    assert_eq!(balls.len(), 16);
    let read =
        |k: usize| std::fs::read_to_string(d.join(format!("plates/frame-{k:04}.svg"))).unwrap();
    // plate 5 is the first frame (t = -3) and plate 6 the last (t = 3), at the report's places
    for (k, end) in [(0, "start"), (30, "end")] {
        let drawn = centres(&read(k));
        assert_eq!(drawn.len(), 16);
        for ((name, (x, y)), b) in drawn.iter().zip(balls) {
            assert_eq!(b["name"], name.as_str());
            let p = &b[end];
            let (px, py) = (p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
            // frames place centres to a hundredth of a pixel
            assert!(
                (x - px).abs() < 0.01 && (y - py).abs() < 0.01,
                "{name} {end}"
            );
        }
        assert!(d.join(format!("plates/frame-{k:04}.png")).is_file());
    }
    for (bad, says) in [
        (
            vec!["--frame-time", "0.35"],
            "--frame-time: 0.35 does not divide --quit 3",
        ),
        (
            vec!["--frame-time", "0.2"],
            "--frame-time: only --out draws frames",
        ),
        (
            vec!["--engine", "time-step", "--dt", "0.01", "--out", "x"],
            "--out: reverse draws",
        ),
    ] {
        let mut a = vec!["reverse", "reversal", "--quit", "3"];
        a.extend(&bad);
        if !bad.contains(&"--out") && bad[1] == "0.35" {
            a.extend(["--out", "y"]);
        }
        let out = poolsim(&a, d, &[]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{a:?}: {err}");
        assert!(err.starts_with(&format!("poolsim: {says}")), "{err}");
    }

    let out = poolsim(
        &["reverse", "reversal", "--quit", "3", "--out", "r.html"],
        d,
        &[],
    );
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let Some(browser) = browser_or_skip() else {
        return;
    };
    reversal_page_in_a_browser(browser, &d.join("r.html"), balls);
}

/// The reversal's page at -3 and 3 shows the balls at the report's `balls`' starts and ends,
/// at 3 a distance from -3 of almost nothing, at -1 none; its labels are apart and its arrows on
/// the table.
fn reversal_page_in_a_browser(browser: &str, page: &Path, balls: &[serde_json::Value]) {
    for (t, end) in [("-3", "start"), ("3", "end"), ("-1", "")] {
        let (state, console) = browse(browser, page, t);
        assert!(console.is_empty(), "console at t = {t}: {console:?}");
        if end.is_empty() {
            assert_eq!(state["mirror_distance"], serde_json::Value::Null);
            continue;
        }
        for (got, b) in state["balls"].as_array().unwrap().iter().zip(balls) {
            let p = &b[end];
            for (axis, k) in [("x", 0), ("y", 1)] {
                let (g, w) = (got[axis].as_f64().unwrap(), p[k].as_f64().unwrap());
                assert!(
                    (g - w).abs() <= 1e-9 * w.abs().max(1.0),
                    "{} at {t}",
                    b["name"]
                );
            }
        }
        if t == "3" {
            let far = state["mirror_distance"]
                .as_f64()
                .expect("measured after the reversal");
            assert!(far < 1e-9, "{far}");
        }
        // the layout: no two labels overlap, every arrow ends on the table
        let layout = &state["layout"];
        let boxes: Vec<Vec<f64>> = serde_json::from_value(layout["labels"].clone()).unwrap();
        for (i, a) in boxes.iter().enumerate() {
            for b in &boxes[i + 1..] {
                let meet = a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
                assert!(!meet, "labels overlap at t = {t}: {a:?} {b:?}");
            }
        }
        let table: Vec<f64> = serde_json::from_value(layout["table"].clone()).unwrap();
        let arrows: Vec<Vec<f64>> = serde_json::from_value(layout["arrows"].clone()).unwrap();
        for a in arrows {
            let inside = a[2] >= table[0] - 1.0 && a[2] <= table[2] + 1.0;
            assert!(
                inside && a[3] >= table[1] - 1.0 && a[3] <= table[3] + 1.0,
                "{a:?}"
            );
        }
    }
}
