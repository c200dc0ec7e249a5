//! Time Warp against the sequential objects engine: for any number of workers, with and
//! without chaos (deliveries delayed and reordered to force rollbacks), the same physical
//! events in the same order, the same message counts and the same final state, bit for bit.

use pdes_kernel::time_warp::TwConfig;
use poolsim::model::pool::NvDelay;
use poolsim::output::{TraceLine, TraceRecorder};
use poolsim::run::{execute, EngineKind, FixedNews, RunConfig, SectorChoice};
use poolsim::scenario::{builtin, load, Scenario};

struct Run {
    trace: Vec<TraceLine>,
    summary: serde_json::Value,
}

fn run(s: &Scenario, engine: EngineKind) -> Run {
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
    Run {
        trace: rec.lines,
        summary: serde_json::to_value(&report.summary).unwrap(),
    }
}

fn sequential(sectors: Option<SectorChoice>) -> EngineKind {
    match sectors {
        None => EngineKind::Objects {
            delay: NvDelay::Exact,
        },
        Some(sectors) => EngineKind::Sectored {
            sectors,
            news: FixedNews::Near,
        },
    }
}

fn time_warp(sectors: Option<SectorChoice>, workers: usize, chaos: Option<u64>) -> EngineKind {
    pure_or_not(sectors, workers, chaos, false)
}

/// Time Warp, `pure` or with batches that nothing can roll back run as final.
fn pure_or_not(
    sectors: Option<SectorChoice>,
    workers: usize,
    chaos: Option<u64>,
    pure: bool,
) -> EngineKind {
    EngineKind::TimeWarp {
        tw: TwConfig {
            workers,
            chaos,
            gvt_interval: Some(256),
            final_batches: !pure,
            ..TwConfig::default()
        },
        delay: NvDelay::Exact,
        sectors,
        news: FixedNews::Near,
    }
}

/// Runs `s` sequentially and under Time Warp on 1, 2 and 3 workers, with and without chaos,
/// pure and not.
fn assert_same(s: &Scenario, sectors: Option<SectorChoice>) -> Vec<serde_json::Value> {
    let want = run(s, sequential(sectors));
    let mut stats = Vec::new();
    for (workers, pure) in [1, 2, 3].into_iter().flat_map(|w| [(w, false), (w, true)]) {
        for chaos in [None, Some(workers as u64 * 31 + 5)] {
            let got = run(s, pure_or_not(sectors, workers, chaos, pure));
            let what = format!(
                "{} {sectors:?} workers {workers} chaos {chaos:?} pure {pure}",
                s.name
            );
            assert_eq!(got.trace, want.trace, "{what}: traces differ");
            for field in ["final_state_digest", "messages", "events"] {
                assert_eq!(got.summary[field], want.summary[field], "{what}: {field}");
            }
            let tw = &got.summary["time_warp"];
            assert_eq!(tw["workers"], workers, "{what}");
            assert_eq!(
                tw["committed"].as_f64(),
                want.summary["engine_stats"]["batches"].as_f64(),
                "{what}: every sequential batch committed once"
            );
            let finals = tw["final_batches"].as_u64().unwrap();
            if pure {
                assert_eq!(finals, 0, "{what}: pure Time Warp runs nothing as final");
            } else if workers == 1 {
                // nothing else sends: every batch is before everything still to come
                assert_eq!(Some(finals), tw["committed"].as_u64(), "{what}");
            }
            stats.push(tw.clone());
        }
    }
    stats
}

fn gas(balls: usize, seed: u64) -> Scenario {
    let p = builtin::Params {
        balls: Some(balls),
        seed: Some(seed),
        ..Default::default()
    };
    builtin::build("gas", &p).unwrap()
}

#[test]
fn sectored_gas_is_exact_and_rolls_back() {
    let stats = assert_same(&gas(64, 3), Some(SectorChoice::Grid(4, 4)));
    // chaos on more than one worker must actually force rollbacks
    let rolled: u64 = stats
        .iter()
        .map(|t| t["rolled_back"].as_u64().unwrap())
        .sum();
    assert!(rolled > 0, "no rollback at all: {stats:?}");
    for t in &stats {
        let (processed, committed) = (t["processed"].as_u64(), t["committed"].as_u64());
        assert!(processed >= committed);
    }
}

/// With the thesis' flow (every ball tells every cushion), too: the same trace and messages as
/// the sequential run with that flow, on 2 workers with chaos.
#[test]
fn the_thesis_flow_of_news_is_exact_too() {
    let s = gas(64, 3);
    let sectors = SectorChoice::Grid(4, 4);
    let want = run(
        &s,
        EngineKind::Sectored {
            sectors,
            news: FixedNews::Thesis,
        },
    );
    let mut engine = pure_or_not(Some(sectors), 2, Some(7), false);
    if let EngineKind::TimeWarp { news, .. } = &mut engine {
        *news = FixedNews::Thesis;
    }
    let got = run(&s, engine);
    assert_eq!(got.trace, want.trace);
    for field in ["final_state_digest", "messages"] {
        assert_eq!(got.summary[field], want.summary[field], "{field}");
    }
    let near = run(&s, sequential(Some(sectors)));
    assert_eq!(near.trace, want.trace);
    assert!(
        near.summary["messages"]["NewVelocity"].as_u64()
            < want.summary["messages"]["NewVelocity"].as_u64(),
        "cushions in reach hear less than every cushion"
    );
}

#[test]
fn plain_gas_is_exact() {
    assert_same(&gas(16, 5), None);
}

#[test]
fn the_break_and_the_cradle_are_exact() {
    for name in ["pool", "cradle", "plate1"] {
        let s = builtin::build(name, &builtin::Params::default()).unwrap();
        assert_same(&s, None);
        assert_same(&s, Some(SectorChoice::Grid(2, 2)));
    }
}

#[test]
fn every_hard_case_is_exact() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let s = load(path.to_str().unwrap(), &builtin::Params::default()).unwrap();
            assert_same(&s, None);
            assert_same(&s, Some(SectorChoice::Grid(3, 3)));
            n += 1;
        }
    }
    assert!(n >= 10, "only {n} hard cases found");
}

#[test]
fn a_tight_memory_budget_rolls_back_and_stays_exact() {
    let s = gas(64, 8);
    let want = run(&s, sequential(Some(SectorChoice::Grid(4, 4))));
    let engine = EngineKind::TimeWarp {
        tw: TwConfig {
            workers: 2,
            chaos: Some(3),
            gvt_interval: Some(4096),
            max_uncommitted: 64,
            // every batch saved, so that the budget binds
            final_batches: false,
            window: Some(0.05),
            burst: None,
            record_rounds: false,
        },
        delay: NvDelay::Exact,
        sectors: Some(SectorChoice::Grid(4, 4)),
        news: FixedNews::Near,
    };
    let got = run(&s, engine);
    assert_eq!(got.trace, want.trace);
    let tw = &got.summary["time_warp"];
    assert!(tw["artificial_rollbacks"].as_u64().unwrap() > 0, "{tw}");
}

/// Rolling back to free memory beside batches run as final: what a worker undoes must stay
/// above the floor the other worker last read of it, or that worker's final batches would be
/// overtaken ("an op ... came after a later batch ran as final"). Before the fix, 4 runs in 6
/// of this scenario failed so; the runs are timing-dependent, hence several.
#[test]
fn rolling_back_for_memory_beside_final_batches_stays_exact() {
    let s = gas(400, 1);
    let want = run(&s, sequential(Some(SectorChoice::Grid(5, 5))));
    let mut artificial = 0;
    for _ in 0..6 {
        let engine = EngineKind::TimeWarp {
            tw: TwConfig {
                workers: 2,
                max_uncommitted: 32,
                ..Default::default()
            },
            delay: NvDelay::Exact,
            sectors: Some(SectorChoice::Grid(5, 5)),
            news: FixedNews::Near,
        };
        let cfg = RunConfig {
            engine,
            until: s.until,
            check: true,
            span: Default::default(),
            interrupt: None,
            checkpoint_every: None,
            thermostat: None,
        };
        let mut rec = TraceRecorder::default();
        match execute(&s, &cfg, &mut rec) {
            Ok(report) => {
                assert_eq!(rec.lines, want.trace);
                let tw = report.summary.time_warp.as_ref().unwrap();
                artificial += tw.stats.artificial_rollbacks;
            }
            // a budget this tight may also be too small for an instant: a clear error
            Err(e) => assert!(e.to_string().contains("--tw-memory"), "{e}"),
        }
    }
    assert!(artificial > 0, "no run rolled back to free memory");
}

#[test]
fn an_instant_commits_as_it_goes() {
    // at t = 0 every ball sets out and the sectors relay its trajectory: one long instant, which
    // a GVT of simulation time alone could commit only once it was over
    const INTERVAL: u32 = 32;
    let mut s = gas(400, 5);
    s.until = 1e-9;
    let sectors = Some(SectorChoice::Grid(8, 8));
    let want = run(&s, sequential(sectors));
    let engine = EngineKind::TimeWarp {
        tw: TwConfig {
            workers: 2,
            gvt_interval: Some(INTERVAL),
            ..TwConfig::default()
        },
        delay: NvDelay::Exact,
        sectors,
        news: FixedNews::Near,
    };
    let got = run(&s, engine);
    assert_eq!(got.summary["events"]["total"], 0);
    assert_eq!(
        got.summary["final_state_digest"],
        want.summary["final_state_digest"]
    );
    let tw = &got.summary["time_warp"];
    let batches = want.summary["engine_stats"]["batches"].as_f64().unwrap() as u64;
    assert_eq!(tw["committed"].as_u64(), Some(batches));
    assert!(tw["gvt_rounds"].as_u64().unwrap() > 4, "{tw}");
    // a worker past two GVT intervals of uncommitted batches runs only final ones: it holds
    // that many at most, not its half of the instant
    let peak = tw["peak_uncommitted"].as_u64().unwrap();
    assert!(
        batches > 500 && peak <= 2 * u64::from(INTERVAL) + 1 && peak < batches / 4,
        "{peak} of {batches}: {tw}"
    );
}

#[test]
fn memory_stays_flat_over_many_gvt_rounds() {
    use pdes_kernel::phold::{Phold, PholdConfig};
    use pdes_kernel::time_warp::threads::TimeWarp;
    use pdes_kernel::time_warp::ObjectMap;
    use pdes_kernel::VTime;
    let cfg = PholdConfig {
        objects: 512,
        events_per_object: 8,
        remote: 0.2,
        partitions: 2,
        lookahead: 0.05,
        mean: 1.0,
        seed: 3,
    };
    let (model, states) = Phold::new(cfg);
    let tw = TwConfig {
        workers: 2,
        gvt_interval: Some(512),
        ..TwConfig::default()
    };
    let mut ex = TimeWarp::new(model, states, VTime::start(0.0), &ObjectMap::Block, tw);
    ex.run::<()>(200.0, &mut |_, _, _| Ok(())).unwrap();
    let stats = ex.tw_stats();
    assert!(stats.gvt_rounds >= 100, "{stats:?}");
    assert!(stats.committed > 500_000, "{stats:?}");
    for samples in ex.memory_samples() {
        // held messages plus saved states after each GVT round: after warm-up (the first tenth)
        // the second half never holds much more than the first
        let n = samples.len();
        let early = samples[n / 10..n / 2].iter().max().unwrap();
        let late = samples[n / 2..].iter().max().unwrap();
        assert!(
            *late as f64 <= 1.5 * *early as f64,
            "early {early}, late {late}"
        );
        // and far less than the events committed: fossil collection frees them
        assert!(*late < stats.committed / 20, "{late} vs {stats:?}");
    }
}

#[test]
fn a_failing_sink_stops_every_worker_with_its_error() {
    use poolsim::engine::{Event, Observer, RunError, World};
    /// Fails at the tenth committed event.
    struct FailAt(u32);
    impl Observer for FailAt {
        fn on_event(&mut self, _: &Event, _: &dyn World) -> Result<(), RunError> {
            self.0 += 1;
            if self.0 == 10 {
                return Err(RunError::Output("disk full".into()));
            }
            Ok(())
        }
    }
    let s = gas(64, 2);
    for workers in [1, 2, 3] {
        let cfg = RunConfig {
            engine: time_warp(Some(SectorChoice::Grid(4, 4)), workers, Some(1)),
            until: s.until,
            check: false,
            span: Default::default(),
            interrupt: None,
            checkpoint_every: None,
            thermostat: None,
        };
        let mut obs = FailAt(0);
        match execute(&s, &cfg, &mut obs) {
            Err(RunError::Output(m)) => assert_eq!(m, "disk full"),
            other => panic!("{workers} workers: {other:?}"),
        }
        assert_eq!(obs.0, 10, "no event after the failure reached the sink");
    }
}

#[test]
fn the_projectors_frames_are_the_sequential_ones() {
    use poolsim::engine::{Event, Frame, Observer, RunError, Span, Table, World};
    #[derive(Default)]
    struct Frames(Vec<Frame>);
    impl Observer for Frames {
        fn on_event(&mut self, _: &Event, _: &dyn World) -> Result<(), RunError> {
            Ok(())
        }
        fn on_frame(&mut self, f: &Frame, _: &Table) -> Result<(), RunError> {
            self.0.push(f.clone());
            Ok(())
        }
    }
    let s = builtin::build("plate1", &builtin::Params::default()).unwrap();
    let frames = |engine| {
        let cfg = RunConfig {
            engine,
            until: s.until,
            check: false,
            span: Span {
                frame_time: Some(0.1),
                ..Span::default()
            },
            interrupt: None,
            checkpoint_every: None,
            thermostat: None,
        };
        let mut obs = Frames::default();
        execute(&s, &cfg, &mut obs).unwrap();
        obs.0
    };
    let want = frames(sequential(None));
    assert!(want.len() > 20, "{}", want.len());
    for workers in [2, 3] {
        assert_eq!(
            frames(time_warp(None, workers, Some(4))),
            want,
            "{workers} workers"
        );
    }
}

#[test]
fn batches_run_as_final_beside_optimistic_ones() {
    // big enough that two workers pass each other many times
    let mut s = gas(900, 4);
    s.until = 2.0;
    let sectors = Some(SectorChoice::Auto);
    let want = run(&s, sequential(sectors));
    let got = run(&s, time_warp(sectors, 2, None));
    assert_eq!(got.trace, want.trace);
    let tw = &got.summary["time_warp"];
    let (finals, committed) = (tw["final_batches"].as_u64(), tw["committed"].as_u64());
    let (finals, committed) = (finals.unwrap(), committed.unwrap());
    assert!(finals > 0, "no batch ran as final: {tw}");
    assert!(
        finals < committed,
        "every batch ran as final on 2 workers: {tw}"
    );
    // the set-up instant's relays, which no one can cancel, run as final against the other
    // worker's next generation
    let uncancellable = tw["final_uncancellable"].as_u64().unwrap();
    assert!(
        uncancellable > 0 && uncancellable <= finals,
        "{uncancellable} final by generation: {tw}"
    );
    // optimistic batches are committed as soon as nothing can undo them, not only at rounds
    let early = tw["committed_early"].as_u64().unwrap();
    assert!(
        early > 0 && early <= committed - finals,
        "{early} committed early: {tw}"
    );
}
