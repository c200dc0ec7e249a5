//! The sectored objects engine (thesis ch. 5) against the event-list engine: the same physical
//! events in the same order and the same final state, bit for bit, for grids of 1 to 25 sectors
//! per side, irregular polygon layouts, the hard cases and random tables.

use poolsim::geometry::Vec2;
use poolsim::output::{TraceLine, TraceRecorder};
use poolsim::run::{execute, EngineKind, FixedNews, RunConfig, SectorChoice};
use poolsim::scenario::{builtin, load, Scenario, SectorSpec};
use proptest::prelude::*;

mod common;

fn run(s: &Scenario, engine: EngineKind) -> (Vec<TraceLine>, serde_json::Value) {
    let mut rec = TraceRecorder::default();
    let cfg = RunConfig {
        engine,
        until: s.until,
        check: true,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    let report = execute(s, &cfg, &mut rec).unwrap_or_else(|e| panic!("{}: {e}", s.name));
    (rec.lines, serde_json::to_value(&report.summary).unwrap())
}

fn assert_same(s: &Scenario, sectors: SectorChoice) {
    let (want, ws) = run(s, EngineKind::EventList);
    let mut sent = Vec::new();
    for news in [FixedNews::Near, FixedNews::Thesis] {
        let (got, gs) = run(s, EngineKind::Sectored { sectors, news });
        assert_eq!(
            got, want,
            "{} with {sectors:?}, {news:?}: traces differ",
            s.name
        );
        assert_eq!(
            gs["final_state_digest"], ws["final_state_digest"],
            "{} with {sectors:?}, {news:?}",
            s.name
        );
        sent.push(gs["messages"]["NewVelocity"].as_u64().unwrap_or(0));
    }
    // fixed objects hear only from balls within reach of them: never more news than in fig. 15
    assert!(sent[0] <= sent[1], "{} with {sectors:?}: {sent:?}", s.name);
}

const GRIDS: [u32; 9] = [1, 2, 3, 4, 5, 7, 10, 16, 25];

fn hard_cases() -> Vec<Scenario> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios");
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            out.push(load(path.to_str().unwrap(), &builtin::Params::default()).unwrap());
        }
    }
    out
}

#[test]
fn builtins_on_every_grid() {
    for (name, _) in builtin::list() {
        let s = builtin::build(name, &builtin::Params::default()).unwrap();
        for n in GRIDS {
            assert_same(&s, SectorChoice::Grid(n, n));
        }
        assert_same(&s, SectorChoice::Auto);
        assert_same(&s, SectorChoice::Grid(3, 7));
    }
}

#[test]
fn hard_cases_on_every_grid() {
    for s in hard_cases() {
        for n in GRIDS {
            assert_same(&s, SectorChoice::Grid(n, n));
        }
    }
}

#[test]
fn a_fast_ball_cannot_tunnel_through_a_ball_on_a_sector_boundary() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/sector_boundary.toml"
    );
    let s = load(path, &builtin::Params::default()).unwrap();
    let (trace, summary) = run(
        &s,
        EngineKind::Sectored {
            sectors: SectorChoice::Scenario,
            news: FixedNews::Near,
        },
    );
    assert_eq!(trace.len(), 1);
    assert_eq!(trace[0].t, 0.16);
    assert_eq!(
        trace[0].objects,
        ["Ball-1".to_string(), "Ball-2".to_string()]
    );
    assert!(summary["messages"]["SectorEntry"].as_u64().unwrap() > 0);
    assert_same(&s, SectorChoice::Scenario);
}

/// Irregular layouts over a `w` × `h` box: triangles, a brick wall with T junctions, and
/// non-convex L-shapes fitted together.
fn layouts(w: f64, h: f64) -> Vec<Vec<Vec<Vec2>>> {
    let p = |x: f64, y: f64| Vec2::new(x * w, y * h);
    let mut triangles = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            let (x0, y0, x1, y1) = (
                i as f64 / 3.0,
                j as f64 / 3.0,
                (i + 1) as f64 / 3.0,
                (j + 1) as f64 / 3.0,
            );
            if (i + j) % 2 == 0 {
                triangles.push(vec![p(x0, y0), p(x1, y0), p(x1, y1)]);
                triangles.push(vec![p(x0, y0), p(x1, y1), p(x0, y1)]);
            } else {
                triangles.push(vec![p(x0, y0), p(x1, y0), p(x0, y1)]);
                triangles.push(vec![p(x1, y0), p(x1, y1), p(x0, y1)]);
            }
        }
    }
    let mut bricks = Vec::new();
    for row in 0..4 {
        let (y0, y1) = (row as f64 / 4.0, (row + 1) as f64 / 4.0);
        let cuts: Vec<f64> = if row % 2 == 0 {
            vec![0.0, 0.25, 0.5, 0.75, 1.0]
        } else {
            vec![0.0, 0.125, 0.375, 0.625, 0.875, 1.0]
        };
        for k in 0..cuts.len() - 1 {
            bricks.push(vec![
                p(cuts[k], y0),
                p(cuts[k + 1], y0),
                p(cuts[k + 1], y1),
                p(cuts[k], y1),
            ]);
        }
    }
    // two L-shapes and two rectangles
    let ells = vec![
        vec![
            p(0.0, 0.0),
            p(0.6, 0.0),
            p(0.6, 0.3),
            p(0.3, 0.3),
            p(0.3, 1.0),
            p(0.0, 1.0),
        ],
        vec![
            p(0.6, 0.0),
            p(1.0, 0.0),
            p(1.0, 1.0),
            p(0.7, 1.0),
            p(0.7, 0.3),
            p(0.6, 0.3),
        ],
        vec![p(0.3, 0.3), p(0.7, 0.3), p(0.7, 0.6), p(0.3, 0.6)],
        vec![p(0.3, 0.6), p(0.7, 0.6), p(0.7, 1.0), p(0.3, 1.0)],
    ];
    vec![triangles, bricks, ells]
}

fn with_layout(s: &Scenario, polys: Vec<Vec<Vec2>>) -> Scenario {
    let (lo, _) = s.bounds();
    let mut s = s.clone();
    s.sectors = Some(SectorSpec::Polygons(
        polys
            .into_iter()
            .map(|poly| poly.into_iter().map(|q| lo + q).collect())
            .collect(),
    ));
    s
}

#[test]
fn irregular_polygon_layouts() {
    let mut scenarios: Vec<Scenario> = ["gas", "pool", "reversal", "plate1"]
        .iter()
        .map(|n| builtin::build(n, &builtin::Params::default()).unwrap())
        .collect();
    scenarios.extend(hard_cases());
    for s in scenarios {
        let (lo, hi) = s.bounds();
        let span = hi - lo;
        for polys in layouts(span.x, span.y) {
            let s = with_layout(&s, polys);
            assert_same(&s, SectorChoice::Scenario);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(80))]

    #[test]
    fn random_tables_and_layouts(
        s in common::random_scenario(),
        nx in 1u32..9,
        ny in 1u32..9,
        which in 0usize..4,
    ) {
        prop_assume!(s.validate().is_ok());
        let (want, ws) = run(&s, EngineKind::EventList);
        let (got, gs) = if which == 3 {
            run(&s, EngineKind::Sectored { sectors: SectorChoice::Grid(nx, ny), news: FixedNews::Near })
        } else {
            let (lo, hi) = s.bounds();
            let span = hi - lo;
            let polys = layouts(span.x, span.y).swap_remove(which);
            run(&with_layout(&s, polys), EngineKind::Sectored { sectors: SectorChoice::Scenario, news: FixedNews::Near })
        };
        prop_assert_eq!(got, want);
        prop_assert_eq!(&gs["final_state_digest"], &ws["final_state_digest"]);
    }
}
