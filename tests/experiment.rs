//! `poolsim experiment thesis --quick` end to end: every file is written, the tables carry the
//! thesis' numbers beside ours, and the figures are real SVG and PNG files. Only what the data
//! show robustly across seeds is asserted; nothing about timing. `poolsim experiment eos
//! --quick`: the equation of state agrees with the literature within its own error bars.

use poolsim::experiment::{run, ExperimentOptions, Which};
use serde_json::Value;
use std::path::Path;

const FILES: [&str; 12] = [
    "table5.md",
    "table6.md",
    "table7.md",
    "table8.md",
    "table9.md",
    "table10.md",
    "results.json",
    "report.md",
    "fig17.svg",
    "fig17.png",
    "fig18.svg",
    "fig18.png",
];

fn quick(dir: &Path) {
    let args = ExperimentOptions {
        which: Which::Thesis,
        out: dir.to_path_buf(),
        seeds: None,
        balls: None,
        quick: true,
        font: None,
        area_fractions: None,
        rates: None,
    };
    run(&args, &mut |_| {}).expect("the quick experiment runs");
}

/// Mean total messages of one cell from results.json.
fn mean_total(results: &Value, balls: u64, setting: &str) -> f64 {
    results["aggregates"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["balls"] == balls && a["setting"] == setting)
        .unwrap_or_else(|| panic!("no cell {balls} balls, {setting}"))["messages"]["total"]["mean"]
        .as_f64()
        .unwrap()
}

/// Total messages of every seed of one cell.
fn totals(results: &Value, balls: u64, setting: &str) -> Vec<(u64, u64)> {
    results["runs"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["balls"] == balls && r["setting"] == setting)
        .map(|r| {
            (
                r["seed"].as_u64().unwrap(),
                r["messages"]["total"].as_u64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn quick_experiment_writes_tables_figures_and_report() {
    let dir = tempfile::tempdir().unwrap();
    quick(dir.path());
    for f in FILES {
        let meta = std::fs::metadata(dir.path().join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert!(meta.len() > 0, "{f} is empty");
    }
    let read = |f: &str| std::fs::read_to_string(dir.path().join(f)).unwrap();

    // Table 5: the thesis' numbers (as printed) and ours side by side.
    let t5 = read("table5.md");
    for thesis in [
        "632", "4936", "7677", "5366", "6549", "11831", "17313", "17801", "mo",
    ] {
        assert!(t5.contains(thesis), "table 5 lacks the thesis' {thesis}");
    }
    let results: Value = serde_json::from_str(&read("results.json")).unwrap();
    let ours_16_2 = mean_total(&results, 16, "2x2");
    assert!(
        t5.contains(&format!("2×2: {ours_16_2:.0} ± ")),
        "table 5 lacks our 16-ball 2x2 mean {ours_16_2:.0}:\n{t5}"
    );
    assert!(read("table10.md").contains("5368"));
    assert!(read("table7.md").contains("3850"));
    assert!(read("table8.md").contains("NewVelocity"));
    assert!(read("table9.md").contains("7749"));
    assert!(read("table6.md").contains("38575"));

    // Every engine executed the event-list engine's physics.
    assert_eq!(results["digests_agree"], true);
    assert_eq!(results["plan"]["seeds"], 2);
    assert_eq!(results["plan"]["balls"], serde_json::json!([4, 16]));

    // 16 balls: the 2x2 grid (4 balls per sector) beats 8x8 (1/4 per sector) in every seed, by
    // far; and the non-sectored engine sends more messages for more balls, in every seed.
    let a = totals(&results, 16, "2x2");
    let b = totals(&results, 16, "8x8");
    assert_eq!(a.len(), 2);
    for ((s1, x), (s2, y)) in a.iter().zip(&b) {
        assert_eq!(s1, s2);
        assert!(2 * x < *y, "seed {s1}: 2x2 {x} vs 8x8 {y}");
    }
    for (seed, few) in totals(&results, 4, "none") {
        let many = totals(&results, 16, "none");
        let (_, m) = many.iter().find(|r| r.0 == seed).unwrap();
        assert!(few * 3 < *m, "seed {seed}: 4 balls {few} vs 16 balls {m}");
    }
    // Finer grids cost more for 4 balls too: 1x1 < 2x2 < 4x4 in the mean.
    let g: Vec<f64> = ["1x1", "2x2", "4x4"]
        .iter()
        .map(|s| mean_total(&results, 4, s))
        .collect();
    assert!(g[0] < g[1] && g[1] < g[2], "{g:?}");

    // Figures: SVG documents and PNG files.
    for f in ["fig17.svg", "fig18.svg"] {
        let svg = read(f);
        assert!(
            svg.contains("<svg") && svg.trim_end().ends_with("</svg>"),
            "{f}"
        );
        assert!(svg.contains("Figure 1"), "{f} has no title");
    }
    for f in ["fig17.png", "fig18.png"] {
        let png = std::fs::read(dir.path().join(f)).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{f}");
        assert!(png.len() > 10_000, "{f} is suspiciously small");
    }

    // The report inlines table 5 and says where it stands.
    let report = read("report.md");
    assert!(report.contains("## Headline: table 5"));
    assert!(report.contains("| 16 | "));
    assert!(report.contains("What does not agree"));
    assert!(report.contains("fig17.svg"));
}

#[test]
fn a_missing_font_is_a_clear_error_after_the_tables() {
    let dir = tempfile::tempdir().unwrap();
    let args = ExperimentOptions {
        which: Which::Thesis,
        out: dir.path().to_path_buf(),
        seeds: Some(1),
        balls: Some(vec![4]),
        quick: true,
        font: Some(dir.path().join("no-such-font.ttf")),
        area_fractions: None,
        rates: None,
    };
    let err = run(&args, &mut |_| {}).unwrap_err().to_string();
    assert!(
        err.contains("no-such-font.ttf") && err.contains("fonts-dejavu-core"),
        "{err}"
    );
    assert!(dir.path().join("table5.md").exists());
    assert!(dir.path().join("report.md").exists());
}

#[test]
fn bad_arguments_name_the_option() {
    let dir = tempfile::tempdir().unwrap();
    let mut args = ExperimentOptions {
        which: Which::Thesis,
        out: dir.path().to_path_buf(),
        seeds: None,
        balls: Some(vec![5000]),
        quick: true,
        font: None,
        area_fractions: None,
        rates: None,
    };
    assert!(run(&args, &mut |_| {})
        .unwrap_err()
        .to_string()
        .contains("--balls"));
    args.balls = None;
    args.seeds = Some(0);
    assert!(run(&args, &mut |_| {})
        .unwrap_err()
        .to_string()
        .contains("--seeds"));
}

#[test]
fn the_quick_equation_of_state_meets_the_literature_within_its_error_bars() {
    let dir = tempfile::tempdir().unwrap();
    let args = ExperimentOptions {
        which: Which::Eos,
        out: dir.path().to_path_buf(),
        seeds: None,
        balls: None,
        quick: true,
        font: None,
        area_fractions: None,
        rates: None,
    };
    run(&args, &mut |_| {}).expect("the quick equation of state runs");
    for file in ["eos.md", "eos.json", "eos.svg", "eos.png"] {
        assert!(dir.path().join(file).is_file(), "{file} missing");
    }
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("eos.json")).unwrap())
            .unwrap();
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), 2);
    for p in points {
        let (z, err) = (
            p["z"]["mean"].as_f64().unwrap(),
            p["z"]["error"].as_f64().unwrap(),
        );
        let liu = p["liu"].as_f64().unwrap();
        // 1000 disks, 1000 collisions each: a standard error near 0.2 %; three of them
        assert!(err > 0.0 && err < 0.005 * z, "{p}");
        assert!((z - liu).abs() < 3.0 * err, "Z = {z} +- {err}, Liu {liu}");
        // the virial and the collision rate give one Z
        let rate = &p["z_from_rate"];
        let both = (err.powi(2) + rate["error"].as_f64().unwrap().powi(2)).sqrt();
        assert!(
            (z - rate["mean"].as_f64().unwrap()).abs() < 3.0 * both,
            "{p}"
        );
    }
    let bad = ExperimentOptions {
        area_fractions: Some(vec![0.8]),
        ..args
    };
    assert!(run(&bad, &mut |_| {})
        .unwrap_err()
        .to_string()
        .contains("--area-fractions"));
}

#[test]
fn the_quick_jamming_study_packs_denser_the_slower_it_grows() {
    let dir = tempfile::tempdir().unwrap();
    let args = ExperimentOptions {
        which: Which::Jamming,
        out: dir.path().to_path_buf(),
        seeds: None,
        balls: None,
        quick: true,
        font: None,
        area_fractions: None,
        rates: None,
    };
    run(&args, &mut |_| {}).expect("the quick jamming study runs");
    for file in ["jamming.md", "jamming.json", "jamming.svg", "jamming.png"] {
        assert!(dir.path().join(file).is_file(), "{file} missing");
    }
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("jamming.json")).unwrap())
            .unwrap();
    let points = json["points"].as_array().unwrap();
    let phi: Vec<(f64, f64)> = points
        .iter()
        .map(|p| {
            (
                p["area_fraction"]["mean"].as_f64().unwrap(),
                p["area_fraction"]["error"].as_f64().unwrap(),
            )
        })
        .collect();
    assert_eq!(phi.len(), 2);
    // 200 disks jam below 0.83 at rate 0.1 and above 0.84 at 0.01 (0.822 and 0.846 measured)
    assert!((0.80..0.835).contains(&phi[0].0), "{phi:?}");
    assert!((0.835..0.86).contains(&phi[1].0), "{phi:?}");
    assert!(phi[1].0 - phi[0].0 > 3.0 * (phi[0].1 + phi[1].1), "{phi:?}");
    assert_eq!(json["runs"].as_array().unwrap().len(), 4);
    for (rates, flag) in [(vec![0.0], "--rates"), (vec![], "--rates")] {
        let bad = ExperimentOptions {
            rates: Some(rates),
            ..args.clone()
        };
        assert!(run(&bad, &mut |_| {})
            .unwrap_err()
            .to_string()
            .contains(flag));
    }
    let eos = ExperimentOptions {
        which: Which::Eos,
        rates: Some(vec![0.1]),
        ..args
    };
    assert!(run(&eos, &mut |_| {})
        .unwrap_err()
        .to_string()
        .contains("only the jamming study"));
}
