//! The command line of the objects engines, reversal, the model and PHOLD, end to end.

use std::io::Write;
use std::process::{Command, Output};

fn poolsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_poolsim"))
        .args(args)
        .output()
        .expect("poolsim runs")
}

fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON object on stdout")
}

/// Exit status 2 and exactly one line on stderr that mentions `needle`.
fn bad(args: &[&str], needle: &str) {
    let out = poolsim(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    assert!(err.contains(needle), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
}

#[test]
fn objects_engine_reports_messages_by_type() {
    let d = json(&poolsim(&[
        "run",
        "gas",
        "--balls",
        "36",
        "--engine",
        "objects",
        "--sectors",
        "none",
        "--json",
    ]));
    let m = &d["messages"];
    for k in ["NewVelocity", "Collision", "Cancel"] {
        assert!(m[k].as_u64().unwrap() > 0, "{k}: {m}");
    }
    for k in ["VelocityChange", "SectorEntry", "SectorDeparture"] {
        assert_eq!(m[k].as_u64().unwrap(), 0, "{k}: {m}");
    }
    assert_eq!(d["engine"], "objects");
    let plain = json(&poolsim(&["run", "gas", "--balls", "36", "--json"]));
    assert_eq!(d["final_state_digest"], plain["final_state_digest"]);
}

#[test]
fn sectored_engine_reports_sector_messages_and_the_same_state() {
    let plain = json(&poolsim(&["run", "gas", "--json"]));
    for sectors in ["1", "3", "2x5", "auto"] {
        let d = json(&poolsim(&[
            "run",
            "gas",
            "--engine",
            "objects",
            "--sectors",
            sectors,
            "--check",
            "--json",
        ]));
        let m = &d["messages"];
        assert!(m["VelocityChange"].as_u64().unwrap() > 0, "{sectors}: {m}");
        assert!(
            m["VelocityInitialization"].as_u64().unwrap() >= 36,
            "one per ball and sector it touches"
        );
        assert_eq!(
            d["final_state_digest"], plain["final_state_digest"],
            "{sectors}"
        );
    }
}

#[test]
fn bad_sector_layouts_are_refused() {
    bad(
        &["run", "gas", "--engine", "objects", "--sectors", "0"],
        "--sectors",
    );
    bad(
        &["run", "gas", "--engine", "objects", "--sectors", "3y4"],
        "--sectors",
    );
    bad(
        &[
            "run",
            "gas",
            "--engine",
            "objects",
            "--sectors",
            "3",
            "--newvelocity-delay",
            "0.1",
        ],
        "--newvelocity-delay",
    );
    bad(&["run", "gas", "--sectors", "3"], "--sectors");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("overlap.toml");
    let mut f = std::fs::File::create(&path).unwrap();
    writeln!(
        f,
        "[[ball]]\nposition = [50.0, 50.0]\nradius = 5.0\n\
         [[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 100.0]\n\
         [[cushion]]\nfrom = [0.0, 100.0]\nto = [100.0, 100.0]\n\
         [[cushion]]\nfrom = [100.0, 100.0]\nto = [100.0, 0.0]\n\
         [[cushion]]\nfrom = [100.0, 0.0]\nto = [0.0, 0.0]\n\
         [[sectors.polygon]]\npoints = [[0.0, 0.0], [60.0, 0.0], [60.0, 100.0], [0.0, 100.0]]\n\
         [[sectors.polygon]]\npoints = [[50.0, 0.0], [100.0, 0.0], [100.0, 100.0], [50.0, 100.0]]"
    )
    .unwrap();
    drop(f);
    bad(
        &["run", path.to_str().unwrap(), "--engine", "objects"],
        "sectors.polygon[1] overlaps sectors.polygon[2]",
    );
}

#[test]
fn reverse_model_and_phold() {
    let r = json(&poolsim(&[
        "reverse", "reversal", "--quit", "3", "--seed", "3", "--engine", "objects", "--json",
    ]));
    assert!(r["events"].as_u64().unwrap() > 100);
    assert!(r["max_position_error"].as_f64().unwrap() < 1e-6);
    bad(&["reverse", "reversal", "--quit", "-1"], "--quit");
    let m = json(&poolsim(&["model", "--balls", "64", "--json"]));
    let s = m["optimal"]["sector_width"].as_f64().unwrap();
    assert!((s - 8f64.sqrt() / 8.0).abs() < 1e-12, "{m}");
    bad(&["model", "--balls", "-3"], "--balls");
    let p = json(&poolsim(&[
        "phold",
        "--objects",
        "64",
        "--events-per-object",
        "2",
        "--end",
        "5",
        "--json",
    ]));
    assert!(p["committed"].as_u64().unwrap() > 0);
    // the sequential kernel runs on one core
    assert_eq!(p["events_per_second_per_core"], p["events_per_second"]);
    let again = json(&poolsim(&[
        "phold",
        "--objects",
        "64",
        "--events-per-object",
        "2",
        "--end",
        "5",
        "--json",
    ]));
    assert_eq!(p["committed"], again["committed"]);
    bad(&["phold", "--remote", "1.5"], "--remote");
    // Time Warp gives the sequential kernel's digest on either placement; round robin sends
    // most messages between the workers
    let small = ["phold", "--objects", "64", "--end", "5", "--json"];
    let seq = json(&poolsim(&small));
    let mut remote = Vec::new();
    for map in ["block", "round-robin"] {
        let tw = ["--engine", "time-warp", "--workers", "2", "--map", map];
        let r = json(&poolsim(&[&small[..], &tw[..]].concat()));
        assert_eq!(r["final_state_digest"], seq["final_state_digest"], "{map}");
        remote.push(r["time_warp"]["remote_messages"].as_u64().unwrap());
    }
    assert!(remote[1] > 2 * remote[0], "{remote:?}");
    bad(&["phold", "--map", "block"], "--map");
}

#[test]
fn phold_on_the_conservative_executor_gives_the_sequential_digest() {
    let small = [
        "phold",
        "--objects",
        "96",
        "--partitions",
        "2",
        "--end",
        "8",
        "--json",
    ];
    let seq = json(&poolsim(&small));
    for (workers, map) in [("1", "block"), ("2", "block"), ("3", "round-robin")] {
        let c = [
            "--engine",
            "conservative",
            "--workers",
            workers,
            "--map",
            map,
        ];
        let r = json(&poolsim(
            &[&small[..], &c[..], &["--baseline"][..]].concat(),
        ));
        let what = format!("{workers} workers, {map}");
        assert_eq!(r["engine"], "conservative", "{what}");
        assert_eq!(r["final_state_digest"], seq["final_state_digest"], "{what}");
        assert_eq!(r["committed"], seq["committed"], "{what}");
        let c = &r["conservative"];
        let batches: u64 = c["batches"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b.as_u64().unwrap())
            .sum();
        assert_eq!(c["batches"].as_array().unwrap().len().to_string(), workers);
        assert!(batches > 0 && c["windows"].as_u64().unwrap() > 0, "{r}");
        assert!(r["speedup"].as_f64().unwrap() > 0.0, "{r}");
    }
    // no lookahead, no window: the user is told to take another executor
    bad(
        &["phold", "--engine", "conservative", "--lookahead", "0"],
        "--engine conservative: the conservative executor needs a model with a positive \
         lookahead",
    );
    bad(
        &["phold", "--engine", "conservative", "--tw-burst", "8"],
        "--tw-burst: only the time-warp engine takes it",
    );
}

#[test]
fn phold_writes_one_line_of_statistics_per_gvt_round() {
    let path = std::env::temp_dir().join(format!("poolsim-rounds-{}.jsonl", std::process::id()));
    let p = path.to_str().unwrap();
    let report = json(&poolsim(&[
        "phold",
        "--objects",
        "128",
        "--events-per-object",
        "4",
        "--end",
        "20",
        "--engine",
        "time-warp",
        "--workers",
        "2",
        "--stats",
        p,
        "--baseline",
        "--json",
    ]));
    // the sequential baseline of the same invocation
    let seq = report["sequential_wall_seconds"].as_f64().unwrap();
    let x = report["speedup"].as_f64().unwrap();
    assert!((x - seq / report["wall_seconds"].as_f64().unwrap()).abs() < 1e-9);
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::remove_file(&path).unwrap();
    let rounds: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let tw = &report["time_warp"];
    assert_eq!(rounds.len() as u64, tw["gvt_rounds"].as_u64().unwrap());
    let mut last = (0.0, 0u64);
    for (k, r) in rounds.iter().enumerate() {
        assert_eq!(r["round"].as_u64(), Some(k as u64 + 1));
        let workers = r["workers"].as_array().unwrap();
        assert_eq!(workers.len(), 2);
        // GVT and the counts only grow
        let gvt = r["gvt"].as_f64().unwrap();
        let committed: u64 = workers
            .iter()
            .map(|w| w["committed"].as_u64().unwrap())
            .sum();
        assert!(gvt >= last.0 && committed >= last.1, "{r}");
        last = (gvt, committed);
    }
    // the last round passed the end, and every batch committed by then is counted
    assert!(last.0 > 20.0);
    assert_eq!(last.1, tw["committed"].as_u64().unwrap());
    bad(&["phold", "--stats", p], "only the time-warp engine");
    bad(
        &["phold", "--baseline"],
        "only a parallel engine (time-warp, conservative)",
    );
    bad(
        &[
            "phold",
            "--engine",
            "time-warp",
            "--stats",
            "/nonexistent/dir/x.jsonl",
        ],
        "cannot create the round statistics file",
    );
}
