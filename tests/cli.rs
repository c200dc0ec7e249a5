//! The command line, end to end: the built binary run as a user would, its exit status, stdout
//! and stderr, and the files it writes (the contracts of DESIGN.md, "Contracts other tools rely
//! on").

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `poolsim ARGS` (stdin closed, stdout and stderr captured: neither is a terminal).
fn poolsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_poolsim"))
        .args(args)
        .stdin(std::process::Stdio::null())
        .output()
        .expect("the poolsim binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8(bytes.to_vec()).expect("output is UTF-8")
}

/// Runs a command that must succeed: exit 0 and nothing at all on stderr (no progress bar, no
/// warnings). Returns stdout.
fn success(args: &[&str]) -> String {
    let out = poolsim(args);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(
        out.status.code(),
        Some(0),
        "poolsim {args:?} failed\nstdout: {stdout}\nstderr: {stderr}"
    );
    assert_eq!(stderr, "", "poolsim {args:?} wrote to stderr");
    stdout
}

/// Runs a command whose stdout must be exactly one JSON object on one line, and parses it.
fn success_json(args: &[&str]) -> Value {
    let stdout = success(args);
    assert_eq!(
        stdout.matches('\n').count(),
        1,
        "poolsim {args:?}: not one line: {stdout}"
    );
    assert!(stdout.ends_with('\n'));
    let v: Value = serde_json::from_str(&stdout)
        .unwrap_or_else(|e| panic!("poolsim {args:?}: not JSON ({e}): {stdout}"));
    assert!(v.is_object(), "poolsim {args:?}: not an object: {stdout}");
    v
}

/// Runs a command that must fail with exit status `code` and exactly one line on stderr, that
/// line starting `poolsim: ` and holding no panic text; stdout must stay empty. Returns the line,
/// without its newline.
fn failure(args: &[&str], code: i32) -> String {
    let out = poolsim(args);
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert_eq!(
        out.status.code(),
        Some(code),
        "poolsim {args:?}\nstdout: {stdout}\nstderr: {stderr}"
    );
    assert_eq!(stdout, "", "poolsim {args:?} wrote to stdout");
    assert!(
        stderr.ends_with('\n') && stderr.matches('\n').count() == 1,
        "poolsim {args:?}: stderr is not exactly one line: {stderr:?}"
    );
    for bad in ["panicked", "thread 'main'", "backtrace", "RUST_BACKTRACE"] {
        assert!(!stderr.contains(bad), "poolsim {args:?}: {stderr}");
    }
    let line = stderr.trim_end_matches('\n').to_string();
    assert!(line.starts_with("poolsim: "), "{line}");
    line
}

fn bad_usage(args: &[&str]) -> String {
    failure(args, 2)
}

fn u(v: &Value) -> u64 {
    v.as_u64().unwrap_or_else(|| panic!("not a count: {v}"))
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

fn manifest_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The 1-based number of the one line of `text` that contains `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    let hits: Vec<usize> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| l.contains(needle))
        .map(|(i, _)| i + 1)
        .collect();
    assert_eq!(hits.len(), 1, "{needle:?} is not on exactly one line");
    hits[0]
}

// ---------------------------------------------------------------------------------------------
// Listing, summaries and output files.

/// The names `poolsim scenarios` lists, one per line, first word.
fn builtin_names() -> Vec<String> {
    success(&["scenarios"])
        .lines()
        .map(|l| l.split_whitespace().next().unwrap_or("").to_string())
        .collect()
}

#[test]
fn scenarios_lists_every_builtin() {
    let out = success(&["scenarios"]);
    let names = builtin_names();
    // The thesis' set pieces, in this order; more may be added (DESIGN.md: extend freely).
    assert_eq!(
        names[..5],
        ["plate1", "gas", "reversal", "pool", "cradle"],
        "{out}"
    );
    for line in out.lines() {
        // name, then a description
        assert!(line.split_whitespace().count() > 3, "{line}");
    }
}

#[test]
fn run_json_prints_one_summary_object_and_nothing_on_stderr() {
    let v = success_json(&["run", "plate1", "--json"]);
    for key in [
        "scenario",
        "engine",
        "balls",
        "until",
        "events",
        "messages",
        "kinetic_energy",
        "final_state_digest",
        "wall_seconds",
        "setup_seconds",
        "events_per_second",
    ] {
        assert!(v.get(key).is_some(), "no {key} in {v}");
    }
    assert_eq!(v["scenario"], "plate1");
    assert_eq!(v["engine"], "event-list");
    assert_eq!(u(&v["balls"]), 2);
    assert_eq!(f(&v["until"]), 3.0);
    let ev = &v["events"];
    assert_eq!(u(&ev["ball-ball"]), 1);
    assert_eq!(u(&ev["ball-cushion"]), 0);
    assert_eq!(u(&ev["ball-corner"]), 0);
    assert_eq!(u(&ev["ball-pocket"]), 1);
    assert_eq!(u(&ev["total"]), 2);
    assert!(v["messages"]["total"].is_u64(), "{}", v["messages"]);
    // Ball-2 (mass 1, speed 100) carries 5000; it all ends with Ball-1 in the pocket.
    let ke = &v["kinetic_energy"];
    assert_eq!(f(&ke["initial"]), 5000.0);
    assert_eq!(f(&ke["final"]), 0.0);
    let digest = v["final_state_digest"].as_str().expect("a string digest");
    assert_eq!(digest.len(), 16, "{digest}");
    assert!(digest.chars().all(|c| c.is_ascii_hexdigit()), "{digest}");
    assert!(f(&v["wall_seconds"]) >= f(&v["setup_seconds"]));
    assert!(f(&v["setup_seconds"]) >= 0.0);
    assert!(f(&v["events_per_second"]) >= 0.0);
}

#[test]
fn plain_run_prints_a_readable_summary() {
    let out = success(&["run", "plate1"]);
    assert!(out
        .lines()
        .any(|l| l.starts_with("scenario") && l.ends_with("plate1")));
    assert!(out.contains("ball-ball 1"), "{out}");
    assert!(out.contains("ball-pocket 1"), "{out}");
    assert!(!out.contains("time warp"), "{out}");
    // under Time Warp, a line of its own statistics
    let out = success(&["run", "plate1", "--engine", "time-warp", "--workers", "2"]);
    let line = out
        .lines()
        .find(|l| l.starts_with("time warp"))
        .unwrap_or_else(|| panic!("no time warp line: {out}"));
    assert!(line.contains("2 workers on 1 rank: efficiency"), "{line}");
}

#[test]
fn plate1_trace_has_the_collision_then_the_pocket() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("trace.jsonl");
    let v = success_json(&[
        "run",
        "plate1",
        "--json",
        "--trace",
        trace.to_str().unwrap(),
    ]);
    let body = std::fs::read_to_string(&trace).unwrap();
    let lines: Vec<&str> = body.lines().collect();
    assert_eq!(lines.len(), 2, "{body}");
    assert!(body.ends_with('\n'));
    let first: Value = serde_json::from_str(lines[0]).unwrap();
    let second: Value = serde_json::from_str(lines[1]).unwrap();
    assert_eq!(
        first,
        serde_json::json!({"t": 1.6, "kind": "ball-ball", "objects": ["Ball-1", "Ball-2"]})
    );
    assert_eq!(first["t"].as_f64(), Some(1.6));
    assert_eq!(second["t"].as_f64(), Some(2.6));
    assert_eq!(second["kind"], "ball-pocket");
    assert_eq!(second["objects"], serde_json::json!(["Ball-1", "Pocket-1"]));
    assert_eq!(second.as_object().unwrap().len(), 3, "{second}");
    // Writing a trace changes nothing in the run.
    let plain = success_json(&["run", "plate1", "--json"]);
    assert_eq!(v["final_state_digest"], plain["final_state_digest"]);
    assert_eq!(v["events"], plain["events"]);
}

#[test]
fn plate1_final_state_has_ball1_in_pocket1() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("final.json");
    success(&["run", "plate1", "--final-state", path.to_str().unwrap()]);
    let v: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert_eq!(f(&v["t"]), 3.0);
    let balls = v["balls"].as_array().expect("a balls array");
    assert_eq!(balls.len(), 2);
    for b in balls {
        let keys: Vec<&String> = b.as_object().unwrap().keys().collect();
        for k in ["name", "position", "velocity", "pocket"] {
            assert!(keys.iter().any(|x| *x == k), "no {k} in {b}");
        }
    }
    assert_eq!(balls[0]["name"], "Ball-1");
    assert_eq!(balls[0]["pocket"], "Pocket-1");
    // It dropped in where its centre crossed the pocket line.
    assert_eq!(balls[0]["position"], serde_json::json!([300.0, 400.0]));
    assert_eq!(balls[0]["velocity"], serde_json::json!([0.0, 0.0]));
    assert_eq!(balls[1]["name"], "Ball-2");
    assert!(balls[1]["pocket"].is_null());
    // Ball-2 stopped dead at the contact at y = 260.
    assert_eq!(balls[1]["position"], serde_json::json!([300.0, 260.0]));
    assert_eq!(balls[1]["velocity"], serde_json::json!([0.0, 0.0]));
}

#[test]
fn digest_is_reproducible_and_depends_on_the_seed() {
    let digest = |seed: &str| {
        success_json(&["run", "gas", "--seed", seed, "--json"])["final_state_digest"]
            .as_str()
            .unwrap()
            .to_string()
    };
    let a = digest("1");
    assert_eq!(a, digest("1"));
    let b = digest("2");
    assert_eq!(b, digest("2"));
    assert_ne!(a, b);
    // The default seed is 1.
    let default = success_json(&["run", "gas", "--json"]);
    assert_eq!(default["final_state_digest"], a.as_str());
}

/// Acceptance criterion: 400 balls for 100 time units, checked at every event, with kinetic
/// energy conserved to better than 1e-12 relative.
#[test]
fn gas_400_conserves_energy_to_1e_minus_12() {
    let v = success_json(&[
        "run", "gas", "--balls", "400", "--seed", "3", "--until", "100", "--check", "--json",
    ]);
    assert_eq!(u(&v["balls"]), 400);
    assert_eq!(f(&v["until"]), 100.0);
    assert_eq!(v["checked"], true);
    assert!(u(&v["events"]["ball-ball"]) > 10_000, "{}", v["events"]);
    let e0 = f(&v["kinetic_energy"]["initial"]);
    let e1 = f(&v["kinetic_energy"]["final"]);
    assert!(e0 > 0.0);
    let drift = (e1 - e0).abs() / e0;
    assert!(drift < 1e-12, "relative energy drift {drift:e}");
}

#[test]
fn time_step_engine_reports_its_errors_in_the_summary() {
    let v = success_json(&[
        "run",
        "plate1",
        "--engine",
        "time-step",
        "--dt",
        "0.01",
        "--json",
    ]);
    assert_eq!(v["engine"], "time-step");
    assert_eq!(u(&v["events"]["ball-pocket"]), 1);
    let stats = &v["engine_stats"];
    assert_eq!(f(&stats["dt"]), 0.01);
    assert!(f(&stats["steps"]) >= 300.0);
    assert!(f(&stats["max_overlap_fraction_of_radius"]) > 0.0, "{stats}");
    let delay = f(&stats["mean_detection_delay"]);
    assert!(delay > 0.0 && delay <= 0.01 * (1.0 + 1e-9), "{stats}");
}

// ---------------------------------------------------------------------------------------------
// Bad input: exit status 2, one line naming the file, the line and the field.

/// Four elastic cushions around a 400 × 400 table.
const BOX: &str = "[[cushion]]
from = [0.0, 0.0]
to = [0.0, 400.0]
[[cushion]]
from = [0.0, 400.0]
to = [400.0, 400.0]
[[cushion]]
from = [400.0, 400.0]
to = [400.0, 0.0]
[[cushion]]
from = [400.0, 0.0]
to = [0.0, 0.0]
";

/// A valid two-ball scenario.
fn base() -> String {
    format!(
        "# a valid scenario, edited by one line
[run]
until = 2.0

[[ball]]
position = [100.0, 100.0]
velocity = [10.0, 5.0]
radius = 10.0
mass = 1.0

[[ball]]
position = [200.0, 300.0]
velocity = [-3.0, 0.0]
radius = 20.0

{BOX}"
    )
}

/// The base scenario with one piece of text replaced: `needle` → `replacement`.
fn edited(needle: &str, replacement: &str) -> String {
    let good = base();
    assert_eq!(good.matches(needle).count(), 1, "{needle:?}");
    good.replacen(needle, replacement, 1)
}

/// Writes `body` to `dir/name`, runs it, and checks the one line of stderr: it starts with
/// `poolsim: FILE:LINE: FIELD` where LINE is the line of `body` holding `at`. Returns the line.
fn bad_file(dir: &Path, name: &str, body: &str, at: &str, field: &str) -> String {
    let path: PathBuf = dir.join(name);
    std::fs::write(&path, body).unwrap();
    let p = path.to_str().unwrap();
    let line = bad_usage(&["run", p]);
    let want = format!("poolsim: {p}:{}: {field}", line_of(body, at));
    assert!(line.starts_with(&want), "want {want:?}\n got {line:?}");
    line
}

#[test]
fn the_valid_base_file_runs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("good.toml");
    std::fs::write(&path, base()).unwrap();
    let v = success_json(&["run", path.to_str().unwrap(), "--check", "--json"]);
    assert_eq!(u(&v["balls"]), 2);
    assert_eq!(f(&v["until"]), 2.0);
}

#[test]
fn overlapping_balls_name_both_balls_and_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let body = edited("position = [200.0, 300.0]", "position = [115.0, 110.0]");
    let line = bad_file(
        dir.path(),
        "overlap.toml",
        &body,
        "position = [115.0, 110.0]",
        "ball[2].position",
    );
    assert!(line.contains("Ball-1") && line.contains("Ball-2"), "{line}");
    assert!(line.contains("overlap"), "{line}");
}

#[test]
fn ball_off_the_table_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let body = edited("position = [200.0, 300.0]", "position = [500.0, 300.0]");
    let line = bad_file(
        dir.path(),
        "off.toml",
        &body,
        "position = [500.0, 300.0]",
        "ball[2].position",
    );
    assert!(line.contains("off the table"), "{line}");
}

#[test]
fn bad_numbers_name_their_field_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("radius = 20.0", "radius = 0.0", "ball[2].radius"),
        ("mass = 1.0", "mass = -1.0", "ball[1].mass"),
        (
            "position = [100.0, 100.0]",
            "position = [nan, 100.0]",
            "ball[1].position",
        ),
        (
            "velocity = [-3.0, 0.0]",
            "velocity = [-3.0, inf]",
            "ball[2].velocity",
        ),
        ("mass = 1.0", "mass = \"heavy\"", "ball[1].mass"),
    ];
    for (k, (needle, replacement, field)) in cases.into_iter().enumerate() {
        let body = edited(needle, replacement);
        bad_file(
            dir.path(),
            &format!("bad{k}.toml"),
            &body,
            replacement,
            field,
        );
    }
}

#[test]
fn elasticity_above_one_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let body = edited(
        "to = [400.0, 0.0]\n",
        "to = [400.0, 0.0]\nelasticity = 1.5\n",
    );
    let line = bad_file(
        dir.path(),
        "elastic.toml",
        &body,
        "elasticity = 1.5",
        "cushion[3].elasticity",
    );
    assert!(line.contains("1.5"), "{line}");
}

/// A cushion whose ends coincide; the error points at its `[[cushion]]` entry (the field is the
/// whole cushion, not one end).
#[test]
fn zero_length_cushion_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let body = edited(
        "[[cushion]]\nfrom = [0.0, 400.0]\nto = [400.0, 400.0]\n",
        "[[cushion]]\nfrom = [0.0, 400.0]\nto = [0.0, 400.0]\n",
    );
    let path = dir.path().join("zero.toml");
    std::fs::write(&path, &body).unwrap();
    let p = path.to_str().unwrap();
    let line = bad_usage(&["run", p]);
    // The entry starts at the second `[[cushion]]` header, just above `from = [0.0, 400.0]`.
    let entry = line_of(&body, "from = [0.0, 400.0]") - 1;
    let want = format!("poolsim: {p}:{entry}: cushion[2]");
    assert!(line.starts_with(&want), "want {want:?}\n got {line:?}");
    assert!(line.contains("zero length"), "{line}");
}

#[test]
fn unknown_key_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let body = edited("radius = 20.0", "radius = 20.0\nspin = 3.0");
    let line = bad_file(
        dir.path(),
        "unknown.toml",
        &body,
        "spin = 3.0",
        "ball[2].spin",
    );
    assert!(line.contains("unknown field"), "{line}");
}

/// A ball's colour and label are for pictures: a colour is #rrggbb, a label at most 8
/// characters; anything else is named with its line.
#[test]
fn ball_colours_and_labels_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let good = edited(
        "radius = 20.0",
        "radius = 20.0\ncolour = \"#1f4fb4\"\nlabel = \"2\"",
    );
    let path = dir.path().join("good.toml");
    std::fs::write(&path, &good).unwrap();
    success_json(&["run", path.to_str().unwrap(), "--json"]);
    let body = edited("radius = 20.0", "radius = 20.0\ncolour = \"red\"");
    let line = bad_file(
        dir.path(),
        "colour.toml",
        &body,
        "colour = \"red\"",
        "ball[2].colour",
    );
    assert!(line.contains("#rrggbb"), "{line}");
    let body = edited("radius = 20.0", "radius = 20.0\nlabel = \"a long label\"");
    let line = bad_file(dir.path(), "label.toml", &body, "label = ", "ball[2].label");
    assert!(line.contains("at most 8"), "{line}");
}

#[test]
fn malformed_toml_names_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let body = edited("radius = 20.0", "radius = 20.0.0");
    let path = dir.path().join("malformed.toml");
    std::fs::write(&path, &body).unwrap();
    let p = path.to_str().unwrap();
    let line = bad_usage(&["run", p]);
    let want = format!("poolsim: {p}:{}: ", line_of(&body, "radius = 20.0.0"));
    assert!(line.starts_with(&want), "want {want:?}\n got {line:?}");
}

#[test]
fn missing_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("no-such-scenario.toml");
    let p = path.to_str().unwrap();
    let line = bad_usage(&["run", p]);
    assert!(line.starts_with(&format!("poolsim: {p}: ")), "{line}");
    assert!(line.contains("no such file"), "{line}");
}

#[test]
fn bad_options_name_the_flag() {
    let cases: [(&[&str], &[&str]); 7] = [
        (
            &["run", "gas", "--balls", "0"],
            &["--balls", "whole number", "got 0"],
        ),
        (&["run", "gas", "--until", "-1"], &["--until", "-1"]),
        (
            &["run", "gas", "--engine", "nonsense"],
            &["--engine", "nonsense"],
        ),
        (&["run", "gas", "--engine", "time-step"], &["--dt"]),
        (
            &["run", "gas", "--engine", "time-step", "--dt", "0"],
            &["--dt", "positive"],
        ),
        (
            &["run", "gas", "--area-fraction", "2"],
            &["--area-fraction", "2"],
        ),
        (&["run", "gas", "--dt", "0.1"], &["--dt"]),
    ];
    for (args, words) in cases {
        let line = bad_usage(args);
        for w in words {
            assert!(line.contains(w), "poolsim {args:?}: {line}");
        }
    }
}

#[test]
fn generator_options_are_refused_for_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("good.toml");
    std::fs::write(&path, base()).unwrap();
    let p = path.to_str().unwrap();
    let line = bad_usage(&["run", p, "--seed", "3"]);
    assert!(line.starts_with(&format!("poolsim: {p}: --seed")), "{line}");
}

/// The time-step engine lets balls overlap; `--check` must catch it and stop with exit status 1.
/// With dt = 0.05 on the default gas (speeds up to 100, so up to 5 per step) the first contact it
/// finds is already a few length units deep: seed 1 fails at t = 0.25 with a ball inside a
/// cushion, and every seed tried (1 to 5) fails the same way.
#[test]
fn check_failure_exits_1_with_one_line() {
    for seed in ["1", "2"] {
        let line = failure(
            &[
                "run",
                "gas",
                "--engine",
                "time-step",
                "--dt",
                "0.05",
                "--check",
                "--seed",
                seed,
            ],
            1,
        );
        assert!(line.starts_with("poolsim: check failed"), "{line}");
        assert!(line.contains("overlap"), "{line}");
    }
    // The default seed, as in the README.
    let line = failure(
        &[
            "run",
            "gas",
            "--engine",
            "time-step",
            "--dt",
            "0.05",
            "--check",
        ],
        1,
    );
    assert!(line.starts_with("poolsim: check failed"), "{line}");
}

// ---------------------------------------------------------------------------------------------
// demo, bench, and every scenario under --check.

#[test]
fn demo_runs_the_36_ball_gas() {
    let out = success(&["demo"]);
    let balls = out
        .lines()
        .find(|l| l.starts_with("balls"))
        .unwrap_or_else(|| panic!("no balls line: {out}"));
    assert_eq!(balls.split_whitespace().nth(1), Some("36"), "{out}");
    assert!(out.contains("checked"), "{out}");
    let v = success_json(&["demo", "--json"]);
    assert_eq!(u(&v["balls"]), 36);
    assert_eq!(v["checked"], true);
    assert_eq!(v["scenario"], "gas");
}

/// Counts only: no timing is asserted.
#[test]
fn bench_json_has_the_machine_and_one_row() {
    let v = success_json(&[
        "bench",
        "--balls",
        "100",
        "--area-fractions",
        "0.3",
        "--events",
        "20000",
        "--json",
    ]);
    let machine = v["machine"].as_str().expect("a machine string");
    assert!(!machine.is_empty());
    let rows = v["rows"].as_array().expect("a rows array");
    assert_eq!(rows.len(), 1, "{v}");
    assert_eq!(u(&rows[0]["balls"]), 100);
    assert_eq!(f(&rows[0]["area_fraction"]), 0.3);
    assert!(u(&rows[0]["events"]) >= 20_000, "{}", rows[0]);
    // PHOLD on the sequential kernel, then on 1 and 2 workers of Time Warp and of the
    // conservative executor, each set beside ROSS's record
    let ross = f(&v["phold_ross_events_per_second_per_core"]);
    assert!((ross - 504e9 / 1_966_080.0).abs() < 1.0, "{ross}");
    let phold = v["phold"].as_array().expect("a phold array");
    assert_eq!(phold.len(), 5, "{v}");
    let engines: Vec<&str> = phold
        .iter()
        .map(|p| p["engine"].as_str().unwrap())
        .collect();
    assert_eq!(
        engines,
        [
            "objects",
            "time-warp",
            "time-warp",
            "conservative",
            "conservative"
        ]
    );
    for (p, cores) in phold.iter().zip([1.0, 1.0, 2.0, 1.0, 2.0]) {
        assert_eq!(
            p["final_state_digest"], phold[0]["final_state_digest"],
            "{p}"
        );
        assert!(u(&p["committed"]) > 0, "{p}");
        assert_eq!(p["committed"], phold[0]["committed"], "{p}");
        let (all, per_core) = (
            f(&p["events_per_second"]),
            f(&p["events_per_second_per_core"]),
        );
        assert!((all - per_core * cores).abs() <= 1e-9 * all, "{p}");
    }
}

#[test]
fn every_builtin_passes_check() {
    let names = builtin_names();
    assert!(names.len() >= 5, "{names:?}");
    for name in &names {
        let v = success_json(&["run", name, "--check", "--json"]);
        assert_eq!(v["scenario"], name.as_str());
        assert_eq!(v["checked"], true);
        assert!(u(&v["events"]["total"]) > 0, "{name}: {}", v["events"]);
    }
}

#[test]
fn every_scenario_file_passes_check() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(manifest_dir().join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 10, "{files:?}");
    for file in files {
        let p = file.to_str().unwrap();
        let v = success_json(&["run", p, "--check", "--json"]);
        assert_eq!(v["scenario"], p);
        assert_eq!(v["checked"], true);
    }
}

#[test]
fn time_warp_runs_checked_and_reports_its_statistics() {
    let gas = ["run", "gas", "--balls", "64", "--sectors", "4", "--json"];
    let tw_args = ["--engine", "time-warp", "--workers", "2", "--check"];
    let v = success_json(&[&gas[..], &tw_args[..]].concat());
    assert_eq!(v["engine"], "time-warp");
    let tw = &v["time_warp"];
    assert_eq!(u(&tw["workers"]), 2);
    assert_eq!(u(&tw["ranks"]), 1);
    assert!(u(&tw["processed"]) >= u(&tw["committed"]));
    assert_eq!(
        f(&tw["efficiency"]),
        u(&tw["committed"]) as f64 / u(&tw["processed"]) as f64
    );
    let seq = success_json(&[&gas[..], &["--engine", "objects"][..]].concat());
    assert_eq!(v["final_state_digest"], seq["final_state_digest"]);
}

#[test]
fn time_warp_flags_are_checked() {
    let tw = ["run", "gas", "--engine", "time-warp"];
    for (extra, field) in [
        (&["--workers", "0"][..], "--workers"),
        (&["--tw-memory", "3"][..], "--tw-memory"),
        (&["--tw-window", "-1"][..], "--tw-window"),
        (&["--gvt-interval", "0"][..], "--gvt-interval"),
    ] {
        let args: Vec<&str> = tw.iter().chain(extra).copied().collect();
        assert!(bad_usage(&args).contains(field), "{args:?}");
    }
    let line = bad_usage(&["run", "gas", "--workers", "2"]);
    assert!(line.contains("--workers"), "{line}");
    let out = Command::new(env!("CARGO_BIN_EXE_poolsim"))
        .args(["run", "gas", "--engine", "time-warp"])
        .env("POOLSIM_CHAOS", "lots")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("POOLSIM_CHAOS"));
}

#[test]
fn a_memory_budget_too_small_for_one_instant_is_a_clear_error() {
    // every batch optimistic: with batches run as final the set-up instant fits in 16
    let line = failure(
        &[
            "run",
            "gas",
            "--balls",
            "400",
            "--sectors",
            "5",
            "--engine",
            "time-warp",
            "--workers",
            "2",
            "--tw-pure",
            "--tw-memory",
            "16",
        ],
        1,
    );
    assert!(line.contains("--tw-memory"), "{line}");
}

/// A reader that stops early (`poolsim … | head`) ends the run quietly: no panic, no error text.
#[test]
fn a_closed_pipe_ends_the_run_quietly() {
    use std::io::{BufRead, BufReader};
    use std::process::Stdio;
    for args in [
        &[
            "run",
            "gas",
            "--balls",
            "400",
            "--until",
            "200",
            "--trace",
            "/dev/stdout",
        ][..],
        &[
            "bench",
            "--balls",
            "1000",
            "--area-fractions",
            "0.5",
            "--events",
            "20000",
        ][..],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_poolsim"))
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the poolsim binary runs");
        let mut first = String::new();
        BufReader::new(child.stdout.take().expect("stdout is piped"))
            .read_line(&mut first)
            .expect("one line comes");
        assert!(!first.is_empty(), "{args:?}");
        let out = child.wait_with_output().expect("poolsim ends");
        let err = text(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_ne!(out.status.code(), Some(101), "{args:?}: {err}");
    }
}

/// A ball wedged between two cushions exactly its diameter apart bounces at one instant forever:
/// every engine with instants stops with one clear line and exit status 1, and fast.
#[test]
fn a_wedged_ball_stops_every_engine_with_a_cascade_error() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("wedge.toml");
    std::fs::write(
        &p,
        "[run]\nuntil = 1.0\n\
         [[ball]]\nposition = [10.0, 200.0]\nvelocity = [5.0, 0.0]\nradius = 10.0\n\
         [[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 400.0]\n\
         [[cushion]]\nfrom = [0.0, 400.0]\nto = [20.0, 400.0]\n\
         [[cushion]]\nfrom = [20.0, 400.0]\nto = [20.0, 0.0]\n\
         [[cushion]]\nfrom = [20.0, 0.0]\nto = [0.0, 0.0]\n",
    )
    .unwrap();
    let p = p.to_str().unwrap();
    for engine in [
        &["--engine", "event-list"][..],
        &["--engine", "objects"],
        &["--engine", "objects", "--sectors", "2"],
        &["--engine", "time-warp", "--workers", "2"],
        &["--engine", "time-warp", "--workers", "2", "--sectors", "2"],
    ] {
        let args: Vec<&str> = ["run", p].iter().chain(engine).copied().collect();
        let line = failure(&args, 1);
        assert!(
            line.contains("t = 0") && line.contains("does not end"),
            "{line}"
        );
    }
}

/// Usage errors name what is missing or wrong on their one line, negative numbers included.
#[test]
fn usage_errors_say_what_is_wrong_on_one_line() {
    assert!(bad_usage(&["render", "plate1"]).contains("--out"));
    assert!(bad_usage(&["model"]).contains("--balls"));
    assert!(bad_usage(&[]).contains("no command"));
    assert!(bad_usage(&["experiment", "bogus", "--out", "x"]).contains("thesis, reversal"));
    assert!(bad_usage(&["phold", "--remote", "-0.5"]).contains("-0.5"));
    assert!(bad_usage(&["model", "--balls", "1e40"]).contains("--balls"));
    assert!(bad_usage(&["model", "--balls", "36", "--time", "1e308"]).contains("overflow"));
    assert!(
        bad_usage(&["run", "gas", "--engine", "objects", "--sectors", "1000"]).contains("250000")
    );
    assert!(bad_usage(&["bench", "--phold-objects", "1"]).contains("--phold-objects"));
    assert!(bad_usage(&["bench", "--tw-workers", "1,0"]).contains("--tw-workers"));
    assert!(
        bad_usage(&["bench", "--tw-workers", "8", "--phold-objects", "4"]).contains("8 partitions")
    );
    assert!(bad_usage(&["phold", "--objects", "4294967295"]).contains("events in flight"));
    let line = bad_usage(&[
        "run",
        "gas",
        "--sectors",
        "2",
        "--engine",
        "objects",
        "--fixed-news",
        "all",
    ]);
    assert!(
        line.contains("--fixed-news") && line.contains("'all'"),
        "{line}"
    );
    let line = bad_usage(&[
        "run",
        "gas",
        "--engine",
        "objects",
        "--fixed-news",
        "thesis",
    ]);
    assert!(line.contains("sectored runs"), "{line}");
}

/// `--check` also checks the state the run ends in: with a NewVelocity delay longer than the
/// run, balls pass through each other without a single event, and the check must still fail.
#[test]
fn check_catches_what_no_event_shows() {
    let line = failure(
        &[
            "run",
            "gas",
            "--balls",
            "16",
            "--until",
            "2",
            "--engine",
            "objects",
            "--newvelocity-delay",
            "3",
            "--check",
        ],
        1,
    );
    assert!(
        line.contains("check failed") && line.contains("t = 2"),
        "{line}"
    );
}

/// An output never overwrites the scenario or the other output, and a time step too small to
/// finish is refused before the run starts.
#[test]
fn outputs_that_would_destroy_inputs_and_endless_time_steps_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("s.toml");
    std::fs::copy(manifest_dir().join("scenarios/grazing.toml"), &scenario).unwrap();
    let s = scenario.to_str().unwrap();
    assert!(bad_usage(&["run", s, "--trace", s]).contains("scenario file"));
    let out = dir.path().join("out.json");
    let o = out.to_str().unwrap();
    assert!(bad_usage(&["run", s, "--trace", o, "--final-state", o]).contains("two files"));
    assert!(std::fs::read_to_string(&scenario)
        .unwrap()
        .contains("[[ball]]"));
    let line = bad_usage(&["run", s, "--engine", "time-step", "--dt", "1e-300"]);
    assert!(line.contains("--dt") && line.contains("steps"), "{line}");
}

/// Unix habits: `-` reads the scenario from stdin and writes the trace to stdout (the summary
/// then goes to stderr); `--quiet` drops the human summary but not `--json`.
#[test]
fn dash_means_stdin_and_stdout_and_quiet_means_quiet() {
    let file = manifest_dir().join("scenarios/fig11_three_ball.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_poolsim"))
        .args(["run", "-", "--trace", "-", "--json"])
        .stdin(std::fs::File::open(&file).unwrap())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let trace = text(&out.stdout);
    let lines: Vec<Value> = trace
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert!(!lines.is_empty() && lines.iter().all(|l| l["kind"].is_string()));
    let summary: Value = serde_json::from_str(text(&out.stderr).trim()).unwrap();
    assert_eq!(summary["scenario"], "stdin");
    assert_eq!(u(&summary["events"]["total"]), lines.len() as u64);
    assert_eq!(success(&["run", "plate1", "--quiet"]), "");
    assert_eq!(
        success_json(&["run", "plate1", "--quiet", "--json"])["scenario"],
        "plate1"
    );
    // an empty stdin is a scenario without balls
    let e = bad_usage(&["run", "-"]);
    assert!(e.contains("stdin: ball: the scenario has no balls"), "{e}");
}

/// Flags are named as the user gave them, and only engines that take a flag accept it.
#[test]
fn flags_are_named_as_given() {
    let e = bad_usage(&["phold", "--objects", "0"]);
    assert!(e.contains("--objects: must be at least 1"), "{e}");
    let e = bad_usage(&["phold", "--objects", "4", "--partitions", "9"]);
    assert!(
        e.contains("--partitions: must be from 1 to --objects (4), got 9"),
        "{e}"
    );
    let e = bad_usage(&["model", "--balls", "0"]);
    assert!(e.ends_with("got 0"), "{e}");
    let e = bad_usage(&["reverse", "reversal", "--quit", "3", "--workers", "2"]);
    assert!(
        e.contains("--workers: only the time-warp and regions engines take it"),
        "{e}"
    );
    let r = success_json(&[
        "reverse",
        "reversal",
        "--quit",
        "3",
        "--engine",
        "time-warp",
        "--workers",
        "2",
        "--json",
    ]);
    assert_eq!(r["engine"], "time-warp", "{r}");
}

/// A run that cannot fit in memory is refused before it allocates (a built-in before it is
/// generated), with one line naming what it needs and what there is; `--memory-limit` sets the
/// limit checked against, and `none` checks nothing.
#[test]
fn runs_too_large_for_memory_are_refused_before_they_allocate() {
    let started = std::time::Instant::now();
    let mut huge = vec!["run", "gas", "--balls", "100000000"];
    // on a machine that could hold it, the limit given stands in for what it has
    let room = poolsim::memory::available().map_or(0, |a| a.bytes);
    if room >= poolsim::memory::least(100_000_000) {
        huge.extend(["--memory-limit", "16G"]);
    }
    let line = failure(&huge, 2);
    assert!(
        line.contains("--balls: 100000000 balls need at least")
            && line.contains("GiB")
            && line.contains("--memory-limit"),
        "{line}"
    );
    assert!(
        started.elapsed().as_secs() < 5,
        "refused before the scenario is generated"
    );
    let line = failure(
        &[
            "run",
            "gas",
            "--balls",
            "10000",
            "--engine",
            "objects",
            "--memory-limit",
            "100M",
        ],
        2,
    );
    assert!(
        line.contains("10000 balls on the objects engine without sectors need about")
            && line.contains("100.0 MiB this run may take (--memory-limit)"),
        "{line}"
    );
    let fits = ["run", "gas", "--balls", "400", "--json", "--memory-limit"];
    success_json(&[&fits[..], &["none"]].concat());
    success_json(&[&fits[..], &["1G"]].concat());
    failure(&[&fits[..], &["1M"]].concat(), 2);
    bad_usage(&["run", "gas", "--memory-limit", "lots"]);
}

#[test]
fn samples_are_extended_xyz_that_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let at = |name: &str| dir.path().join(name).display().to_string();
    let (xyz, tw_xyz, fin) = (at("s.xyz"), at("tw.xyz"), at("final.json"));
    let args = ["run", "plate1", "--sample-every", "1", "--quiet", "--json"];
    let sum = success_json(&[&args[..], &["--samples", &xyz, "--final-state", &fin]].concat());
    let plain = success_json(&["run", "plate1", "--quiet", "--json"]);
    assert_eq!(sum["final_state_digest"], plain["final_state_digest"]);
    let text = std::fs::read_to_string(&xyz).unwrap();
    let samples = poolsim::samples::read(&text).unwrap();
    let times: Vec<f64> = samples.iter().map(|s| s.t).collect();
    assert_eq!(times, [0.0, 1.0, 2.0, 3.0]);
    assert_eq!(samples[0].size, (600.0, 400.0));
    // Ball-1 dropped into the pocket at 2.6: the last sample holds Ball-2 alone, where the final
    // state has it, to the bit
    let last = &samples[3].balls;
    assert_eq!((last.len(), last[0].id), (1, 2));
    let state: Value = serde_json::from_str(&std::fs::read_to_string(&fin).unwrap()).unwrap();
    let p = &state["balls"][1]["position"];
    assert_eq!(
        last[0].position,
        (p[0].as_f64().unwrap(), p[1].as_f64().unwrap())
    );
    // Time Warp samples the same, byte for byte
    let tw = [
        "--engine",
        "time-warp",
        "--workers",
        "2",
        "--samples",
        &tw_xyz,
    ];
    success_json(&[&args[..], &tw[..]].concat());
    assert_eq!(std::fs::read_to_string(&tw_xyz).unwrap(), text);
    for (bad, says) in [
        (
            vec!["--sample-every", "1"],
            "--sample-every: only --samples and --observe take samples",
        ),
        (
            vec!["--samples", &xyz, "--sample-every", "-1"],
            "--sample-every: must be a positive",
        ),
        (
            vec!["--samples", &xyz, "--engine", "objects", "--sectors", "2"],
            "--samples: the",
        ),
        (
            vec!["--samples", "/nonexistent/dir/s.xyz"],
            "/nonexistent/dir/s.xyz: cannot write",
        ),
    ] {
        let line = failure(&[&["run", "plate1"][..], &bad[..]].concat(), 2);
        assert!(line.starts_with(&format!("poolsim: {says}")), "{line}");
    }
}

#[test]
fn a_run_starts_from_its_last_sample_as_from_its_final_state() {
    let dir = tempfile::tempdir().unwrap();
    let at = |name: &str| dir.path().join(name).display().to_string();
    let (xyz, fin) = (at("s.xyz"), at("f.json"));
    let first = ["run", "gas", "--balls", "16", "--until", "2", "--quiet"];
    let outputs = [
        "--samples",
        &xyz,
        "--sample-every",
        "1",
        "--final-state",
        &fin,
    ];
    success(&[&first[..], &outputs[..]].concat());
    // the gas's table is a box: the sample's lattice gives the same cushions
    let digest = |start: &str| {
        success_json(&["run", start, "--until", "1", "--quiet", "--json"])["final_state_digest"]
            .clone()
    };
    assert_eq!(digest(&xyz), digest(&fin));
    let bad = at("bad.xyz");
    let head = "Lattice=\"9 0 0 0 9 0 0 0 1\" Origin=\"0 0 0\" Properties=";
    let props = poolsim::samples::PROPERTIES;
    std::fs::write(
        &bad,
        format!("2\n{head}{props} Time=0\nX 1 2 0 0 0 0 1 1 1\n"),
    )
    .unwrap();
    let line = failure(&["run", &bad], 2);
    assert!(
        line.ends_with("bad.xyz:4: not samples poolsim reads: the frame ends before its 2 balls"),
        "{line}"
    );
}

#[test]
fn run_observes_the_pressure_in_blocks_on_every_engine() {
    let base = [
        "run",
        "gas",
        "--balls",
        "100",
        "--until",
        "6",
        "--observe-every",
        "2",
        "--json",
    ];
    let v = success_json(&base);
    let o = &v["observables"];
    assert_eq!(u(&o["blocks"]), 3, "{o}");
    assert_eq!(f(&o["from"]), 0.0);
    assert!(f(&o["z"]["mean"]) > 1.0 && f(&o["z"]["error"]) > 0.0, "{o}");
    assert!(f(&o["pressure_walls"]["mean"]) > 0.0, "{o}");
    // the same events and balls, so the same figures to the bit
    for engine in [
        &["--engine", "objects"][..],
        &[
            "--engine",
            "time-warp",
            "--workers",
            "2",
            "--sectors",
            "auto",
        ][..],
    ] {
        let other = success_json(&[&base[..], engine].concat());
        assert_eq!(other["observables"], *o, "{engine:?}");
    }
    let plain = success_json(
        &base[..base.len() - 3]
            .iter()
            .chain(&["--json"])
            .copied()
            .collect::<Vec<_>>(),
    );
    assert!(plain.get("observables").is_none(), "{plain}");
    assert!(bad_usage(&["run", "gas", "--observe-every", "0"])
        .contains("--observe-every: must be a positive number"));
    assert!(bad_usage(&["run", "gas", "--observe-from", "1"])
        .contains("--observe-from: needs --observe-every or --observe"));
    assert!(bad_usage(&["run", "gas", "--observe-every", "10"])
        .contains("--observe-from: the first block, from 0 to 10, must lie within the run"));
}

#[test]
fn observe_gives_the_structure_at_the_sample_times() {
    let out = poolsim(&[
        "run",
        "disks",
        "--balls",
        "1500",
        "--area-fraction",
        "0.5",
        "--boundary",
        "periodic",
        "--until",
        "30",
        "--observe",
        "gr,msd,psi6",
        "--observe-from",
        "10",
        "--sample-every",
        "2",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let st = &v["structure"];
    let numbers = |x: &serde_json::Value| -> Vec<f64> {
        x.as_array()
            .unwrap()
            .iter()
            .map(|y| y.as_f64().unwrap())
            .collect()
    };
    let (r, g) = (numbers(&st["gr"]["r"]), numbers(&st["gr"]["g"]));
    assert_eq!(st["gr"]["samples"], 11);
    // no pair closer than a diameter (2), the contact peak above 2, and g near 1 far out
    for (&r, &g) in r.iter().zip(&g) {
        if r < 1.95 {
            assert_eq!(g, 0.0, "g({r}) = {g}");
        }
    }
    let peak = g.iter().copied().fold(0.0, f64::max);
    assert!(peak > 2.0 && peak < 4.0, "peak {peak}");
    let tail: f64 = g[80..].iter().sum::<f64>() / 20.0;
    assert!((tail - 1.0).abs() < 0.1, "g far out {tail}");
    let (t, msd) = (numbers(&st["msd"]["t"]), numbers(&st["msd"]["value"]));
    assert_eq!(t.len(), 11);
    assert_eq!((t[0], msd[0]), (0.0, 0.0));
    assert!(msd.windows(2).all(|w| w[1] > w[0]), "{msd:?}");
    // the melted lattice has no hexatic order left
    assert!(numbers(&st["psi6"]["value"]).iter().all(|&p| p < 0.1));
    for (args, what) in [
        (vec!["run", "gas", "--observe", "nope"], "--observe"),
        (
            vec![
                "run",
                "disks",
                "--boundary",
                "periodic",
                "--observe",
                "gr",
                "--gr-max",
                "1e9",
            ],
            "--gr-max",
        ),
        (vec!["run", "gas", "--gr-max", "3"], "--gr-max"),
        (
            vec![
                "run",
                "gas",
                "--observe",
                "gr",
                "--engine",
                "time-step",
                "--dt",
                "0.01",
            ],
            "--observe",
        ),
    ] {
        assert!(bad_usage(&args).contains(what), "{args:?}");
    }
}
