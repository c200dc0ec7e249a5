//! SIGINT and SIGTERM stop a run cleanly on every engine: the process exits with 128 + the
//! signal after writing a trace that parses to its last line, a final state and a summary that
//! says where it stopped; and all three equal those of a run asked to end at that time.

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_poolsim");

/// What a run left behind: its exit status, stderr, summary, trace text and final state.
struct Left {
    code: Option<i32>,
    stderr: String,
    summary: Value,
    trace: String,
    final_state: Value,
}

/// Runs `poolsim run gas ... ARGS` with a trace and a final state in `dir`; with `signal`,
/// sends it once the trace holds some events (and fails the test if the run never ends).
fn run(dir: &Path, tag: &str, args: &[&str], signal: Option<i32>) -> Left {
    let trace = dir.join(format!("{tag}.jsonl"));
    let final_state = dir.join(format!("{tag}.json"));
    let mut child = Command::new(BIN)
        .args(["run", "gas", "--balls", "2500", "--json"])
        .args(args)
        .arg("--trace")
        .arg(&trace)
        .arg("--final-state")
        .arg(&final_state)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("poolsim starts");
    if let Some(sig) = signal {
        let started = Instant::now();
        while std::fs::metadata(&trace).map_or(0, |m| m.len()) < 200_000 {
            assert!(
                started.elapsed() < Duration::from_secs(60),
                "{args:?}: no trace after a minute"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        // SAFETY: sends a signal to the child process this test started and has not reaped.
        let sent = unsafe { libc::kill(child.id() as libc::pid_t, sig) };
        assert_eq!(sent, 0, "the signal was sent");
    }
    let started = Instant::now();
    while child.try_wait().expect("waits").is_none() {
        if started.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            panic!("{args:?}: still running two minutes after the signal");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("its output");
    let stdout = String::from_utf8(out.stdout).expect("UTF-8");
    Left {
        code: out.status.code(),
        stderr: String::from_utf8(out.stderr).expect("UTF-8"),
        summary: serde_json::from_str(&stdout)
            .unwrap_or_else(|e| panic!("{args:?}: no summary ({e}): {stdout}")),
        trace: std::fs::read_to_string(&trace).expect("a trace"),
        final_state: serde_json::from_str(&std::fs::read_to_string(&final_state).unwrap())
            .expect("a final state"),
    }
}

/// Interrupts a run on `engine` with `signal` and checks what it left against a run to the
/// time it stopped at.
fn check(engine: &[&str], signal: i32, name: &str) {
    let dir = tempfile::tempdir().unwrap();
    let mut args = vec!["--until", "1e6"];
    args.extend_from_slice(engine);
    let cut = run(dir.path(), "cut", &args, Some(signal));
    assert_eq!(cut.code, Some(128 + signal), "{engine:?}: {}", cut.stderr);
    assert_eq!(cut.stderr.lines().count(), 1, "{engine:?}: {}", cut.stderr);
    assert!(
        cut.stderr
            .starts_with(&format!("poolsim: interrupted by {name} at t = ")),
        "{engine:?}: {}",
        cut.stderr
    );
    let stopped = &cut.summary["interrupted"];
    assert_eq!(stopped["signal"], name, "{engine:?}");
    let at = stopped["at"].as_f64().expect("a time");
    assert!(at > 0.0 && at < 1e6, "{engine:?}: stopped at {at}");
    assert_eq!(cut.final_state["t"].as_f64(), Some(at), "{engine:?}");
    assert!(cut.trace.ends_with('\n'), "{engine:?}: a cut line");
    let mut last = f64::NEG_INFINITY;
    for line in cut.trace.lines() {
        let ev: Value = serde_json::from_str(line)
            .unwrap_or_else(|e| panic!("{engine:?}: trace line {line:?}: {e}"));
        last = ev["t"].as_f64().expect("a time");
    }
    assert!(last <= at, "{engine:?}: an event at {last}, after {at}");
    // the same run asked to end where the interrupted one stopped
    let until = format!("{at:?}");
    let mut args = vec!["--until", &until];
    args.extend_from_slice(engine);
    let whole = run(dir.path(), "whole", &args, None);
    assert_eq!(whole.code, Some(0), "{engine:?}: {}", whole.stderr);
    assert!(whole.summary.get("interrupted").is_none(), "{engine:?}");
    assert_eq!(
        cut.summary["final_state_digest"], whole.summary["final_state_digest"],
        "{engine:?}: digests"
    );
    assert!(cut.trace == whole.trace, "{engine:?}: traces differ");
    assert_eq!(
        cut.final_state, whole.final_state,
        "{engine:?}: final states"
    );
}

#[test]
fn sigint_stops_the_event_list_cleanly() {
    check(&["--engine", "event-list"], libc::SIGINT, "SIGINT");
}

#[test]
fn sigterm_stops_the_time_step_engine_cleanly() {
    check(
        &["--engine", "time-step", "--dt", "0.001"],
        libc::SIGTERM,
        "SIGTERM",
    );
}

#[test]
fn sigterm_stops_the_sectored_objects_cleanly() {
    check(
        &["--engine", "objects", "--sectors", "auto"],
        libc::SIGTERM,
        "SIGTERM",
    );
}

#[test]
fn sigint_stops_time_warp_cleanly() {
    check(
        &[
            "--engine",
            "time-warp",
            "--workers",
            "2",
            "--sectors",
            "auto",
        ],
        libc::SIGINT,
        "SIGINT",
    );
}

/// An interrupted run writes its checkpoint where it stopped; taken up from it (on another
/// engine), it ends as a run that never stopped, its trace continued where it was cut.
#[test]
fn an_interrupted_run_is_taken_up_from_its_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let cp = dir.path().join("cp.json");
    let cut = run(
        dir.path(),
        "cut",
        &["--until", "1e6", "--checkpoint", cp.to_str().unwrap()],
        Some(libc::SIGINT),
    );
    assert_eq!(cut.code, Some(130), "{}", cut.stderr);
    let at = cut.summary["interrupted"]["at"].as_f64().unwrap();
    let checkpoint: Value = serde_json::from_str(&std::fs::read_to_string(&cp).unwrap()).unwrap();
    assert_eq!(checkpoint["t"].as_f64(), Some(at));
    let end = format!("{:?}", at + 1.0);
    let whole = run(dir.path(), "whole", &["--until", &end], None);
    let out = Command::new(BIN)
        .current_dir(dir.path())
        .args(["resume", "cp.json", "--json", "--until", &end])
        .args(["--engine", "objects", "--sectors", "auto"])
        .output()
        .expect("poolsim runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let taken: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        taken["final_state_digest"],
        whole.summary["final_state_digest"]
    );
    let trace = std::fs::read_to_string(dir.path().join("cut.jsonl")).unwrap();
    assert!(trace == whole.trace, "the trace taken up differs");
}
