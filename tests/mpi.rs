//! Time Warp across MPI ranks (cargo feature `mpi`, OpenMPI's `mpirun` on the path): on 2 and 3
//! ranks on loopback, with and without chaos, pool and PHOLD give the sequential objects
//! engine's trace and final-state digest, bit for bit, and the regions engine the event
//! list's.
#![cfg(feature = "mpi")]

use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_poolsim");

/// Runs poolsim with `args` (under `mpirun -np ranks` when `ranks` is given) and returns its
/// standard output, which must be one JSON object.
fn poolsim(ranks: Option<usize>, chaos: Option<u64>, args: &[&str]) -> serde_json::Value {
    let mut cmd = match ranks {
        None => Command::new(BIN),
        Some(r) => {
            let mut c = Command::new("mpirun");
            c.args([
                "--allow-run-as-root",
                "--oversubscribe",
                "-np",
                &r.to_string(),
            ]);
            if let Some(seed) = chaos {
                c.args(["-x", &format!("POOLSIM_CHAOS={seed}")]);
            }
            c.arg(BIN);
            c
        }
    };
    let out = cmd.args(args).output().expect("mpirun and poolsim start");
    assert!(
        out.status.success(),
        "{args:?} on {ranks:?} ranks: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{args:?}: not one JSON object ({e}): {}",
            String::from_utf8_lossy(&out.stdout)
        )
    })
}

/// The sequential objects engine's trace and digest against Time Warp's on 2 and 3 ranks.
fn assert_same(scenario: &str, extra: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let want_trace = dir.path().join("want.jsonl");
    let mut args = vec!["run", scenario, "--json", "--quiet"];
    args.extend_from_slice(extra);
    let mut seq = args.clone();
    seq.extend([
        "--engine",
        "objects",
        "--trace",
        want_trace.to_str().unwrap(),
    ]);
    let want = poolsim(None, None, &seq);
    for (ranks, workers, chaos) in [
        (2, "1", None),
        (3, "1", None),
        (2, "2", Some(9)),
        (3, "1", Some(4)),
    ] {
        let got_trace = dir.path().join(format!("got-{ranks}-{workers}.jsonl"));
        let mut tw = args.clone();
        tw.extend(["--engine", "time-warp", "--workers", workers]);
        tw.extend(["--trace", got_trace.to_str().unwrap()]);
        let got = poolsim(Some(ranks), chaos, &tw);
        let what = format!("{scenario} {extra:?} on {ranks} ranks x {workers}, chaos {chaos:?}");
        assert_eq!(
            got["final_state_digest"], want["final_state_digest"],
            "{what}"
        );
        assert_eq!(got["messages"], want["messages"], "{what}");
        assert_eq!(got["time_warp"]["ranks"], ranks, "{what}");
        assert_eq!(read(&got_trace), read(&want_trace), "{what}: traces differ");
    }
}

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

#[test]
fn sectored_gas_on_ranks() {
    assert_same("gas", &["--balls", "64", "--sectors", "4"]);
}

/// Ranks learn each other's floors at every round that ends with nothing in flight, and run
/// batches below them as final: some are, on 2 ranks, and the answer stays the sequential one.
#[test]
fn ranks_run_batches_as_final_below_each_others_floors() {
    let args = [
        "run",
        "gas",
        "--balls",
        "900",
        "--sectors",
        "auto",
        "--until",
        "2",
    ];
    let mut seq = args.to_vec();
    seq.extend(["--json", "--quiet", "--engine", "objects"]);
    let want = poolsim(None, None, &seq);
    let mut tw = args.to_vec();
    tw.extend([
        "--json",
        "--quiet",
        "--engine",
        "time-warp",
        "--workers",
        "1",
    ]);
    let got = poolsim(Some(2), None, &tw);
    assert_eq!(got["final_state_digest"], want["final_state_digest"]);
    let t = &got["time_warp"];
    let (fin, committed) = (
        t["final_batches"].as_u64().unwrap(),
        t["committed"].as_u64().unwrap(),
    );
    assert!(fin > 0 && fin < committed, "{fin} of {committed} final");
}

#[test]
fn the_break_on_ranks() {
    assert_same("pool", &[]);
    assert_same("pool", &["--sectors", "2"]);
}

/// The hard cases' scenario files (at least 10 of them).
fn hard_cases() -> Vec<String> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios");
    let cases: Vec<String> = (std::fs::read_dir(dir).unwrap())
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .map(|path| path.to_str().unwrap().to_string())
        .collect();
    assert!(cases.len() >= 10, "{} hard cases", cases.len());
    cases
}

#[test]
fn hard_cases_on_ranks() {
    for case in hard_cases() {
        assert_same(&case, &["--sectors", "2"]);
    }
}

#[test]
fn phold_on_ranks() {
    let args = |engine: &str| {
        vec![
            "phold",
            "--objects",
            "256",
            "--end",
            "20",
            "--partitions",
            "3",
            "--json",
            "--engine",
            engine,
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>()
    };
    let seq = args("objects");
    let seq: Vec<&str> = seq.iter().map(String::as_str).collect();
    let want = poolsim(None, None, &seq);
    for (ranks, chaos) in [(2, None), (3, None), (3, Some(2))] {
        let tw = args("time-warp");
        let mut tw: Vec<&str> = tw.iter().map(String::as_str).collect();
        tw.extend(["--workers", "1"]);
        let got = poolsim(Some(ranks), chaos, &tw);
        assert_eq!(
            got["final_state_digest"], want["final_state_digest"],
            "{ranks} ranks"
        );
        assert_eq!(got["committed"], want["committed"]);
        assert_eq!(got["time_warp"]["ranks"], ranks);
    }
}

/// The event list's trace and digest against the regions engine's on 2 and 3 ranks, with
/// and without chaos, with as many regions as workers and with more.
fn assert_regions_same(
    scenario: &str,
    extra: &[&str],
    layouts: &[(usize, &str, &str, Option<u64>)],
) {
    let dir = tempfile::tempdir().unwrap();
    let want_trace = dir.path().join("want.jsonl");
    let mut args = vec!["run", scenario, "--json", "--quiet"];
    args.extend_from_slice(extra);
    let mut seq = args.clone();
    seq.extend(["--trace", want_trace.to_str().unwrap()]);
    let want = poolsim(None, None, &seq);
    for &(ranks, workers, regions, chaos) in layouts {
        let got_trace = dir
            .path()
            .join(format!("got-{ranks}-{workers}-{regions}.jsonl"));
        let mut rg = args.clone();
        rg.extend([
            "--engine",
            "regions",
            "--workers",
            workers,
            "--regions",
            regions,
        ]);
        rg.extend(["--trace", got_trace.to_str().unwrap()]);
        let got = poolsim(Some(ranks), chaos, &rg);
        let what = format!(
            "{scenario} {extra:?}: {regions} regions on {ranks} ranks x {workers}, chaos {chaos:?}"
        );
        assert_eq!(
            got["final_state_digest"], want["final_state_digest"],
            "{what}"
        );
        assert_eq!(got["events"], want["events"], "{what}");
        assert_eq!(got["time_warp"]["ranks"], ranks, "{what}");
        let owned: u64 = (got["regions"]["balls_end"].as_array().unwrap().iter())
            .map(|n| n.as_u64().unwrap())
            .sum();
        assert_eq!(
            owned,
            got["balls"].as_u64().unwrap(),
            "{what}: every ball has an owner"
        );
        assert_eq!(read(&got_trace), read(&want_trace), "{what}: traces differ");
    }
}

/// The regions engine on ranks: a dense gas cut in strips across ranks, and the break, give
/// the event list's answer.
#[test]
fn regions_on_ranks() {
    let layouts = [
        (2, "1", "2", None),
        (3, "1", "4", None),
        (2, "1", "3", Some(5)),
        (2, "2", "4", Some(9)),
    ];
    let dense = ["--balls", "3000", "--area-fraction", "0.6", "--until", "2"];
    assert_regions_same("disks", &dense, &layouts);
    assert_regions_same("pool", &[], &layouts[..2]);
}

/// Every hard case on the regions engine across 2 ranks.
#[test]
fn hard_cases_on_ranks_in_regions() {
    for case in hard_cases() {
        assert_regions_same(&case, &[], &[(2, "1", "2", Some(3))]);
    }
}

/// `--check` with the regions engine on 2 ranks: the collecting rank checks every event with
/// the balls the other rank's regions send it.
#[test]
fn checked_regions_on_ranks() {
    let args = [
        "run",
        "disks",
        "--balls",
        "800",
        "--area-fraction",
        "0.6",
        "--until",
        "1",
    ];
    let mut seq = args.to_vec();
    seq.extend(["--check", "--json", "--quiet"]);
    let want = poolsim(None, None, &seq);
    let mut rg = seq.clone();
    rg.extend(["--engine", "regions", "--workers", "1", "--regions", "3"]);
    let got = poolsim(Some(2), None, &rg);
    assert_eq!(got["checked"], true);
    assert_eq!(got["final_state_digest"], want["final_state_digest"]);
}

/// `--check` on ranks: every committed event and the final state are checked, and only rank 0,
/// which collects the final state, sweeps it (the other ranks hold their initial one).
#[test]
fn checked_run_on_ranks() {
    let args = [
        "run",
        "gas",
        "--balls",
        "400",
        "--sectors",
        "auto",
        "--check",
        "--json",
        "--quiet",
    ];
    let mut seq = args.to_vec();
    seq.extend(["--engine", "objects"]);
    let want = poolsim(None, None, &seq);
    for ranks in [2, 3] {
        let mut tw = args.to_vec();
        tw.extend(["--engine", "time-warp", "--workers", "1"]);
        let got = poolsim(Some(ranks), None, &tw);
        assert_eq!(got["checked"], true, "{ranks} ranks");
        assert_eq!(
            got["final_state_digest"], want["final_state_digest"],
            "{ranks} ranks"
        );
    }
}

/// SIGINT sent to one rank alone stops every rank at the same time: rank 0 writes the trace,
/// the final state and a summary that say where, equal to a sequential run to that time, and
/// the signalled rank exits with 130.
#[test]
fn a_signal_to_one_rank_stops_them_all_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let trace = dir.path().join("cut.jsonl");
    let trace_arg = trace.to_str().unwrap();
    let child = Command::new("mpirun")
        .args(["--allow-run-as-root", "--oversubscribe", "-np", "2", BIN])
        .args([
            "run",
            "gas",
            "--balls",
            "2500",
            "--sectors",
            "auto",
            "--until",
            "1e6",
        ])
        .args([
            "--engine",
            "time-warp",
            "--workers",
            "1",
            "--json",
            "--quiet",
        ])
        .args(["--trace", trace_arg])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("mpirun starts");
    let started = std::time::Instant::now();
    while std::fs::metadata(&trace).map_or(0, |m| m.len()) < 200_000 {
        assert!(started.elapsed().as_secs() < 60, "no trace after a minute");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // the ranks are the processes whose command line names this test's trace file, mpirun
    // among them: signal the last-started one
    let ranks = Command::new("pgrep")
        .args(["-n", "-f", &format!("^{BIN} .*{trace_arg}")])
        .output()
        .expect("pgrep runs");
    let pid: i32 = String::from_utf8_lossy(&ranks.stdout)
        .trim()
        .parse()
        .expect("a rank's pid");
    assert_ne!(pid, child.id() as i32, "a rank, not mpirun");
    // SAFETY: sends a signal to one rank of the job this test started.
    assert_eq!(unsafe { libc::kill(pid, libc::SIGINT) }, 0);
    let out = child.wait_with_output().expect("mpirun ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("poolsim: interrupted by SIGINT at t = "),
        "{stderr}"
    );
    let got: serde_json::Value = serde_json::from_slice(&out.stdout).expect("rank 0's summary");
    assert_eq!(got["interrupted"]["signal"], "SIGINT");
    let at = got["interrupted"]["at"].as_f64().unwrap();
    let until = format!("{at:?}");
    let want_trace = dir.path().join("want.jsonl");
    let want = poolsim(
        None,
        None,
        &[
            "run",
            "gas",
            "--balls",
            "2500",
            "--sectors",
            "auto",
            "--until",
            &until,
            "--engine",
            "objects",
            "--json",
            "--quiet",
            "--trace",
            want_trace.to_str().unwrap(),
        ],
    );
    assert_eq!(got["final_state_digest"], want["final_state_digest"]);
    assert_eq!(read(&trace), read(&want_trace), "traces differ");
}

/// Checkpoints across ranks: rank 0 writes the one file, in stretches that end where the run in
/// one go would pass, and a run taken up from it on ranks ends as the sequential run does.
#[test]
fn checkpoints_on_ranks() {
    let dir = tempfile::tempdir().unwrap();
    let cp = dir.path().join("cp.json");
    let cp = cp.to_str().unwrap();
    let gas = ["run", "gas", "--balls", "400", "--json", "--quiet"];
    let want = poolsim(None, None, &[&gas[..], &["--until", "4"]].concat());
    let tw = [
        "--engine",
        "time-warp",
        "--workers",
        "1",
        "--sectors",
        "auto",
    ];
    let stretch = [
        &gas[..],
        &tw,
        &[
            "--until",
            "2",
            "--checkpoint",
            cp,
            "--checkpoint-every",
            "0.5",
        ],
    ]
    .concat();
    poolsim(Some(2), None, &stretch);
    let taken = poolsim(
        Some(2),
        Some(3),
        &[&["resume", cp, "--json", "--until", "4"][..], &tw].concat(),
    );
    assert_eq!(taken["final_state_digest"], want["final_state_digest"]);
    assert_eq!(taken["events"], want["events"]);
}
