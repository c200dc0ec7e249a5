//! Simulation reversal (thesis 4.6–4.7): run from -Q to 0, turn every ball around, run on to Q;
//! the balls must come back to where they started, on every engine, pockets included.

use poolsim::engine::Span;
use poolsim::model::pool::NvDelay;
use poolsim::output::TraceRecorder;
use poolsim::run::{execute, reverse, EngineKind, RunConfig};
use poolsim::scenario::builtin::{build, Params};

fn objects() -> EngineKind {
    EngineKind::Objects {
        delay: NvDelay::Exact,
    }
}

#[test]
fn thesis_4_7_returns_every_ball_to_its_start() {
    let s = build(
        "reversal",
        &Params {
            seed: Some(3),
            ..Params::default()
        },
    )
    .unwrap();
    let a = reverse(&s, EngineKind::EventList, 3.0, true).unwrap();
    assert!(
        a.events > 100,
        "over 100 collisions from -3 to 3: {}",
        a.events
    );
    assert!(a.max_position_error < 1e-6, "{}", a.max_position_error);
    assert!(a.max_velocity_error < 1e-6, "{}", a.max_velocity_error);
    assert_eq!(a.still_pocketed, 0);
    let b = reverse(&s, objects(), 3.0, true).unwrap();
    assert_eq!(a.events, b.events);
    assert_eq!(a.max_position_error, b.max_position_error);
    assert_eq!(a.max_velocity_error, b.max_velocity_error);
    for k in [1, 2, 5] {
        let sectors = poolsim::run::SectorChoice::Grid(k, k);
        let d = reverse(
            &s,
            EngineKind::Sectored {
                sectors,
                news: poolsim::run::FixedNews::Near,
            },
            3.0,
            true,
        )
        .unwrap();
        assert_eq!(a.events, d.events, "{k} sectors per side");
        assert_eq!(a.max_position_error, d.max_position_error);
    }
    // Time Warp, plain and sectored, on 2 workers with chaos: the same reversal, bit for bit
    for sectors in [None, Some(poolsim::run::SectorChoice::Grid(2, 2))] {
        let tw = pdes_kernel::time_warp::TwConfig {
            workers: 2,
            chaos: Some(11),
            ..Default::default()
        };
        let engine = EngineKind::TimeWarp {
            tw,
            delay: poolsim::model::pool::NvDelay::Exact,
            sectors,
            news: poolsim::run::FixedNews::Near,
        };
        let e = reverse(&s, engine, 3.0, true).unwrap();
        assert_eq!(a.events, e.events, "time warp {sectors:?}");
        assert_eq!(a.max_position_error, e.max_position_error);
        assert_eq!(a.max_velocity_error, e.max_velocity_error);
    }
    let c = reverse(&s, EngineKind::TimeStep { dt: 1e-3 }, 3.0, false).unwrap();
    assert!(c.max_position_error < 1e-3, "{}", c.max_position_error);
}

#[test]
fn a_pocketed_ball_comes_back_out_at_the_mirror_time() {
    let s = build("plate1", &Params::default()).unwrap();
    let sectored = EngineKind::Sectored {
        sectors: poolsim::run::SectorChoice::Grid(3, 3),
        news: poolsim::run::FixedNews::Near,
    };
    for engine in [EngineKind::EventList, objects(), sectored] {
        let cfg = RunConfig {
            engine,
            until: 3.0,
            check: true,
            span: Span {
                start: -3.0,
                reverse_at: Some(0.0),
                frame_time: None,
            },
            interrupt: None,
            checkpoint_every: None,
            thermostat: None,
        };
        let mut rec = TraceRecorder::default();
        execute(&s, &cfg, &mut rec).unwrap();
        let times: Vec<(f64, &str)> = rec.lines.iter().map(|l| (l.t, l.kind.as_str())).collect();
        // forward: Ball-2 strikes Ball-1 at -1.4, Ball-1 drops in at -0.4; backward mirrored
        assert_eq!(
            times,
            vec![
                (-1.4, "ball-ball"),
                (-0.3999999999999999, "ball-pocket"),
                (0.3999999999999999, "ball-pocket"),
                (1.4, "ball-ball"),
            ],
            "{}",
            engine.name()
        );
        let r = reverse(&s, engine, 3.0, true).unwrap();
        assert_eq!(r.still_pocketed, 0);
        assert!(r.max_position_error < 1e-9);
    }
}

#[test]
fn forward_and_backward_events_mirror_each_other() {
    let s = build("reversal", &Params::default()).unwrap();
    let cfg = RunConfig {
        engine: EngineKind::EventList,
        until: 3.0,
        check: true,
        span: Span {
            start: -3.0,
            reverse_at: Some(0.0),
            frame_time: None,
        },
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let mut rec = TraceRecorder::default();
    execute(&s, &cfg, &mut rec).unwrap();
    let fwd: Vec<_> = rec.lines.iter().filter(|l| l.t < 0.0).collect();
    let back: Vec<_> = rec.lines.iter().filter(|l| l.t > 0.0).rev().collect();
    assert_eq!(fwd.len(), back.len());
    for (f, b) in fwd.iter().zip(&back) {
        assert_eq!(f.objects, b.objects);
        assert!((f.t + b.t).abs() < 1e-9, "{} vs {}", f.t, b.t);
    }
}

#[test]
fn the_reversal_study_writes_its_table_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let font = std::path::Path::new("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf");
    poolsim::reversal_study::run(dir.path(), font, true).unwrap();
    let table = std::fs::read_to_string(dir.path().join("reversal.md")).unwrap();
    assert!(table.contains("| 3 | event-list | 112 |"), "{table}");
    let png = std::fs::read(dir.path().join("reversal_error.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let svg = std::fs::read_to_string(dir.path().join("reversal_error.svg")).unwrap();
    assert!(svg.starts_with("<svg") || svg.starts_with("<?xml"));
}
