//! `poolsim run --checkpoint` and `poolsim resume`, end to end: a run taken up from a
//! checkpoint, on any engine, continues the trace where the checkpoint cut it and ends with
//! the same trace, final state and digest as the run that never stopped; bad checkpoints and
//! traces are refused with one line.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_poolsim");

/// Runs poolsim in `dir`: exit status, stdout, stderr.
fn poolsim(dir: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(BIN)
        .current_dir(dir)
        .args(args)
        .output()
        .expect("poolsim runs");
    let text = |b: Vec<u8>| String::from_utf8(b).expect("UTF-8");
    (out.status.code(), text(out.stdout), text(out.stderr))
}

/// Runs poolsim in `dir`, which must succeed; its JSON summary.
fn ok(dir: &Path, args: &[&str]) -> Value {
    let (code, stdout, stderr) = poolsim(dir, args);
    assert_eq!(code, Some(0), "{args:?}: {stderr}");
    serde_json::from_str(&stdout).unwrap_or_else(|e| panic!("{args:?}: {e}: {stdout}"))
}

/// Runs poolsim in `dir`, which must fail with exit 2 and one line; the line.
fn refused(dir: &Path, args: &[&str]) -> String {
    let (code, _, stderr) = poolsim(dir, args);
    assert_eq!(code, Some(2), "{args:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
    stderr
}

fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap()
}

/// The arguments in these parts, one after another.
fn args<'a>(parts: &[&[&'a str]]) -> Vec<&'a str> {
    parts.concat()
}

const GAS: [&str; 6] = ["gas", "--balls", "400", "--seed", "5", "--json"];

/// A run stopped at half time, and taken up twice: once on to three quarters, then again from
/// the half-time checkpoint on to the end, which must cut the trace back to half time.
fn check_engine(engine: &[&str]) {
    check_scenario(&GAS, engine);
}

/// [`check_engine`] on `scenario` (its name and parameters, and `--json`).
fn check_scenario(scenario: &[&str], engine: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let whole = ok(
        d,
        &args(&[
            &["run"],
            scenario,
            engine,
            &[
                "--until",
                "8",
                "--trace",
                "whole.jsonl",
                "--final-state",
                "whole.json",
            ],
        ]),
    );
    ok(
        d,
        &args(&[
            &["run"],
            scenario,
            engine,
            &[
                "--until",
                "4",
                "--trace",
                "t.jsonl",
                "--checkpoint",
                "half.json",
                "--checkpoint-every",
                "1.5",
            ],
        ]),
    );
    std::fs::copy(d.join("half.json"), d.join("kept.json")).unwrap();
    ok(
        d,
        &args(&[
            &["resume", "half.json", "--json"],
            engine,
            &["--until", "6", "--checkpoint", "half.json"],
        ]),
    );
    let taken = ok(
        d,
        &args(&[
            &["resume", "kept.json", "--json"],
            engine,
            &["--until", "8", "--final-state", "taken.json"],
        ]),
    );
    let what = format!("{engine:?}");
    assert_eq!(
        taken["final_state_digest"], whole["final_state_digest"],
        "{what}"
    );
    assert_eq!(taken["events"], whole["events"], "{what}");
    assert_eq!(
        taken["kinetic_energy"]["initial"], whole["kinetic_energy"]["initial"],
        "{what}"
    );
    assert!(
        read(d, "t.jsonl") == read(d, "whole.jsonl"),
        "{what}: traces differ"
    );
    assert_eq!(
        read(d, "taken.json"),
        read(d, "whole.json"),
        "{what}: final states"
    );
}

#[test]
fn the_event_list_taken_up_ends_as_one_run() {
    check_engine(&["--engine", "event-list"]);
}

#[test]
fn a_periodic_box_taken_up_ends_as_one_run() {
    let disks = [
        "disks",
        "--balls",
        "400",
        "--seed",
        "5",
        "--boundary",
        "periodic",
        "--json",
    ];
    check_scenario(&disks, &["--engine", "event-list"]);
}

#[test]
fn the_sectored_objects_taken_up_end_as_one_run() {
    check_engine(&["--engine", "objects", "--sectors", "auto"]);
}

#[test]
fn time_warp_taken_up_ends_as_one_run() {
    check_engine(&[
        "--engine",
        "time-warp",
        "--workers",
        "2",
        "--sectors",
        "auto",
    ]);
}

/// A checkpoint written by one engine, taken up on another.
#[test]
fn a_checkpoint_is_taken_up_on_another_engine() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let whole = ok(d, &[&["run"][..], &GAS, &["--until", "6"]].concat());
    ok(
        d,
        &[
            &["run"][..],
            &GAS,
            &[
                "--until",
                "3",
                "--checkpoint",
                "cp.json",
                "--engine",
                "objects",
            ],
        ]
        .concat(),
    );
    let taken = ok(
        d,
        &[
            "resume",
            "cp.json",
            "--json",
            "--until",
            "6",
            "--engine",
            "time-warp",
            "--workers",
            "2",
            "--sectors",
            "auto",
        ],
    );
    assert_eq!(taken["final_state_digest"], whole["final_state_digest"]);
}

#[test]
fn bad_checkpoints_and_options_are_refused_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(
        d,
        &[
            &["run"][..],
            &GAS,
            &[
                "--until",
                "2",
                "--trace",
                "t.jsonl",
                "--checkpoint",
                "cp.json",
            ],
        ]
        .concat(),
    );
    // the trace lost its end after the checkpoint was written
    let text = read(d, "t.jsonl");
    std::fs::write(d.join("t.jsonl"), &text[..text.len() / 2]).unwrap();
    let line = refused(d, &["resume", "cp.json"]);
    assert!(
        line.contains("t.jsonl: the trace holds") && line.contains("fewer than"),
        "{line}"
    );
    // a checkpoint that is not one
    std::fs::write(d.join("bad.json"), "{\"format\": \"poolsim-checkpoint\"}").unwrap();
    let line = refused(d, &["resume", "bad.json"]);
    assert!(
        line.starts_with("poolsim: bad.json:") && line.contains("not a checkpoint"),
        "{line}"
    );
    let mut cp: Value = serde_json::from_str(&read(d, "cp.json")).unwrap();
    cp["scenario"]["balls"][2]["pocket"] = 7.into();
    std::fs::write(d.join("pocket.json"), cp.to_string()).unwrap();
    let line = refused(d, &["resume", "pocket.json"]);
    assert!(line.contains("scenario.ball[3].pocket"), "{line}");
    let line = refused(
        d,
        &["resume", "cp.json", "--engine", "time-step", "--dt", "0.01"],
    );
    assert!(line.contains("time-step engine"), "{line}");
    let line = refused(d, &["resume", "cp.json", "--balls", "9"]);
    assert!(line.contains("--balls"), "{line}");
    let line = refused(
        d,
        &[
            "run",
            "gas",
            "--engine",
            "time-step",
            "--dt",
            "0.1",
            "--checkpoint",
            "x.json",
        ],
    );
    assert!(
        line.contains("--checkpoint: the time-step engine"),
        "{line}"
    );
    let line = refused(d, &["run", "gas", "--checkpoint-every", "1"]);
    assert!(line.contains("--checkpoint FILE"), "{line}");
    let line = refused(
        d,
        &[
            "run",
            "gas",
            "--checkpoint",
            "x.json",
            "--checkpoint-every",
            "0",
        ],
    );
    assert!(line.contains("positive"), "{line}");
    let line = refused(
        d,
        &[
            "run",
            "gas",
            "--checkpoint",
            "same.json",
            "--trace",
            "same.json",
        ],
    );
    assert!(line.contains("--trace and --checkpoint"), "{line}");
}

/// A final state starts another run, balls in pockets staying there, on every engine alike.
#[test]
fn a_final_state_starts_another_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(d, &["run", "pool", "--json", "--final-state", "end.json"]);
    let end: Value = serde_json::from_str(&read(d, "end.json")).unwrap();
    let pocketed = |v: &Value| {
        v["balls"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|b| !b["pocket"].is_null())
            .count()
    };
    assert!(pocketed(&end) > 0, "the break pockets a ball");
    assert!(end["cushions"].as_array().unwrap().len() >= 4);
    let mut digests = Vec::new();
    for engine in [
        &["--engine", "event-list"][..],
        &["--engine", "objects"],
        &["--engine", "time-warp", "--workers", "2"],
    ] {
        let args = args(&[
            &[
                "run",
                "end.json",
                "--json",
                "--check",
                "--until",
                "3",
                "--final-state",
                "next.json",
            ],
            engine,
        ]);
        digests.push(ok(d, &args)["final_state_digest"].clone());
    }
    assert!(digests.windows(2).all(|w| w[0] == w[1]), "{digests:?}");
    let next: Value = serde_json::from_str(&read(d, "next.json")).unwrap();
    assert!(
        pocketed(&next) >= pocketed(&end),
        "pocketed balls stay in their pockets"
    );
}
