//! The regions engine against the event list: for any number of regions, on one worker (the
//! sequential executor) and under Time Warp on 2 and 3 workers with and without chaos, the same
//! physical events in the same order and the same final state, bit for bit, under `--check`.

mod common;

use common::{random_scenario, traced};
use pdes_kernel::time_warp::TwConfig;
use poolsim::run::EngineKind;
use poolsim::scenario::{builtin, load, Scenario};
use proptest::prelude::*;

/// `count` regions on `workers` workers (one: the sequential executor), with chaos `chaos`.
fn regions(count: u32, workers: usize, chaos: Option<u64>) -> EngineKind {
    let tw = (workers > 1).then_some(TwConfig {
        workers,
        chaos,
        gvt_interval: Some(64),
        ..TwConfig::default()
    });
    EngineKind::Regions { count, tw }
}

/// Whether `s`'s table has grid columns enough for `count` regions.
fn fits(s: &Scenario, count: u32) -> bool {
    poolsim::model::regions::Regions::new(s, count, 0.0).is_ok()
}

/// Runs `s` on the event list and on `engines`, and asserts every trace and digest equal;
/// returns how many of `engines` the table had columns for.
fn assert_same(s: &Scenario, engines: &[EngineKind]) -> usize {
    assert_same_checked(s, engines, true)
}

/// [`assert_same`], the runs checked at every event if `check` (observers that read the balls
/// make every region's event a batch of its own; without them a batch runs on to the next
/// message).
fn assert_same_checked(s: &Scenario, engines: &[EngineKind], check: bool) -> usize {
    let (want, want_sum) = traced(s, EngineKind::EventList, check);
    let mut ran = 0;
    for &engine in engines {
        let EngineKind::Regions { count, .. } = engine else {
            unreachable!("regions only")
        };
        if !fits(s, count) {
            continue;
        }
        let (got, sum) = traced(s, engine, check);
        assert_eq!(got, want, "{}: {engine:?}: traces differ", s.name);
        assert_eq!(
            sum.final_state_digest, want_sum.final_state_digest,
            "{}: {engine:?}: digests differ",
            s.name
        );
        ran += 1;
    }
    ran
}

/// The sequential and parallel settings every built-in and hard case runs on.
fn settings() -> Vec<EngineKind> {
    vec![
        regions(1, 1, None),
        regions(2, 1, None),
        regions(3, 1, None),
        regions(5, 1, None),
        regions(2, 2, None),
        regions(3, 2, Some(7)),
        regions(4, 3, Some(11)),
    ]
}

#[test]
fn every_builtin_is_exact() {
    for (name, balls) in [
        ("gas", 400),
        ("pool", 0),
        ("cradle", 0),
        ("plate1", 0),
        ("implosion", 300),
        ("disks", 400),
    ] {
        let mut p = builtin::Params::default();
        if balls > 0 {
            p.balls = Some(balls);
        }
        let mut s = builtin::build(name, &p).unwrap();
        s.until = s.until.min(3.0);
        let ran = assert_same(&s, &settings());
        assert!(ran >= 5, "{name}: only {ran} settings had columns enough");
        // unchecked, Time Warp's batches run on, and news comes in after them
        assert_eq!(assert_same_checked(&s, &settings(), false), ran, "{name}");
    }
}

#[test]
fn batches_that_run_on_to_the_next_message_are_exact() {
    for (name, balls) in [
        ("gas", 2000),
        ("pool", 0),
        ("implosion", 500),
        ("disks", 2000),
    ] {
        let mut p = builtin::Params::default();
        if balls > 0 {
            p.balls = Some(balls);
        }
        let mut s = builtin::build(name, &p).unwrap();
        s.until = s.until.min(3.0);
        let engines = [
            regions(1, 1, None),
            regions(3, 1, None),
            regions(4, 2, Some(5)),
        ];
        let ran = assert_same_checked(&s, &engines, false);
        assert_eq!(ran, 3, "{name}");
    }
    // under Time Warp too: a batch runs on past its time, and one that a neighbour's news
    // reaches inside its span is cut back to the event before it, not undone whole
    let p = builtin::Params {
        balls: Some(4000),
        ..Default::default()
    };
    let mut s = builtin::build("gas", &p).unwrap();
    s.until = 2.0;
    let engine = regions(2, 2, Some(7));
    assert_eq!(assert_same_checked(&s, &[engine], false), 1);
    let (_, sum) = traced(&s, engine, false);
    let tw = sum.time_warp.expect("time warp ran").stats;
    // more events run on than batches committed, however the threads are scheduled
    assert!(tw.ran_on > tw.committed, "{tw:?}");
    assert!(tw.cuts > 0 && tw.ran_on_undone > 0, "{tw:?}");
    // most news that comes after a region ran past it is taken in without a cut
    assert!(tw.taken_in > tw.take_in_refused, "{tw:?}");
    // one region on one worker runs a short run as one batch, a long one in batches of a few
    // thousand events
    let s = builtin::build("gas", &builtin::Params::default()).unwrap();
    let (_, sum) = traced(&s, regions(1, 1, None), false);
    assert_eq!(sum.engine_stats["batches"], 1.0);
    let p = builtin::Params {
        balls: Some(4000),
        ..Default::default()
    };
    let s = builtin::build("gas", &p).unwrap();
    let (trace, sum) = traced(&s, regions(1, 1, None), false);
    let batches = sum.engine_stats["batches"];
    assert!(trace.len() > 10_000, "{} events", trace.len());
    assert!(
        batches > 1.0 && batches < trace.len() as f64 / 1000.0,
        "{batches} batches"
    );
}

#[test]
fn every_hard_case_is_exact() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let s = load(path.to_str().unwrap(), &builtin::Params::default()).unwrap();
            let ran = assert_same(&s, &settings());
            assert!(ran >= 2, "{}: only {ran} settings fit", s.name);
            assert_eq!(
                assert_same_checked(&s, &settings(), false),
                ran,
                "{}",
                s.name
            );
            n += 1;
        }
    }
    assert!(n >= 10, "only {n} hard cases found");
}

#[test]
fn a_dense_gas_crosses_borders_often_and_stays_exact() {
    let p = builtin::Params {
        balls: Some(900),
        area_fraction: Some(0.6),
        ..Default::default()
    };
    let mut s = builtin::build("disks", &p).unwrap();
    s.until = 2.0;
    let engines = [
        regions(6, 1, None),
        regions(6, 2, Some(3)),
        regions(8, 3, Some(4)),
    ];
    assert_eq!(assert_same(&s, &engines), 3);
    assert_eq!(assert_same_checked(&s, &engines, false), 3);
}

#[test]
fn a_wide_window_takes_news_in_and_stays_exact() {
    // a wide window: news arrives far inside the spans, most of it is taken in, and what is
    // refused cuts a long span back and echoes through the neighbour's anti-messages
    let p = builtin::Params {
        balls: Some(20_000),
        area_fraction: Some(0.5),
        ..Default::default()
    };
    let mut s = builtin::build("gas", &p).unwrap();
    s.until = 1.5;
    for (window, chaos) in [(3e-3, None), (1e-2, Some(13))] {
        let tw = TwConfig {
            workers: 2,
            chaos,
            window: Some(window),
            ..TwConfig::default()
        };
        let engine = EngineKind::Regions {
            count: 2,
            tw: Some(tw),
        };
        assert_eq!(
            assert_same_checked(&s, &[engine], false),
            1,
            "window {window}"
        );
        let (_, sum) = traced(&s, engine, false);
        let tw = sum.time_warp.expect("time warp ran").stats;
        assert!(tw.taken_in > 0 && tw.cuts > 0, "window {window}: {tw:?}");
    }
}

#[test]
fn too_few_columns_is_refused_with_the_count() {
    let s = builtin::build("cradle", &builtin::Params::default()).unwrap();
    let err = poolsim::model::regions::Regions::new(&s, 500, 0.0)
        .err()
        .expect("500 regions do not fit a 1000-wide table of radius-30 balls");
    let msg = err.to_string();
    assert!(
        msg.contains("500 regions need at least 1000 grid columns"),
        "{msg}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn random_tables_are_exact(s in random_scenario(), chaos in 1u64..1000) {
        let engines = [regions(2, 1, None), regions(3, 1, None), regions(3, 2, Some(chaos))];
        let ran = assert_same(&s, &engines);
        prop_assert!(ran >= 1);
        prop_assert_eq!(assert_same_checked(&s, &engines, false), ran);
    }
}
