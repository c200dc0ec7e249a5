//! A fuzz target on stable Rust: scenario text built from adversarial pieces (numbers at the
//! edges of `f64`, balls stacked in one spot or astronomically far apart, cushions wound either
//! way, walls with gaps, pockets, sector grids), then parsed, and, when it parses, run briefly on
//! every engine with the invariants checked.
//!
//! The contract: nothing panics; a refused file gets one line naming it; a file that parses runs,
//! or stops with one of the run's own errors; and the exact engines agree with the event list to
//! the bit. `POOLSIM_FUZZ_CASES` sets the number of files (default 48; CI runs more), and
//! `POOLSIM_FUZZ_SEED` the random seed (a number, or `random` for a new one each run; default a
//! fixed seed, so that a run of the tests gives the same answer every time). Inputs that once
//! crashed are kept as tests in `scenario_parsing.rs`.

use pdes_kernel::time_warp::TwConfig;
use poolsim::engine::{Ignore, RunError};
use poolsim::model::pool::NvDelay;
use poolsim::run::{execute, EngineKind, FixedNews, RunConfig, SectorChoice};
use poolsim::scenario::toml::parse;
use poolsim::scenario::Scenario;
use proptest::prelude::*;

const SOURCE: &str = "fuzz.toml";

/// A number as the file writes it: ordinary ones mostly, and the edges now and then.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (0.0..400.0f64).prop_map(|x| format!("{x:?}")),
        2 => (-50.0..50.0f64).prop_map(|x| format!("{x:?}")),
        1 => prop::sample::select(vec![
            "0.0", "-0.0", "1e-300", "-1e-300", "1e300", "-1e300", "1e30", "1e-6", "5e-324",
            "1.7976931348623157e308", "nan", "inf", "-inf", "400", "-1",
        ])
        .prop_map(String::from),
    ]
}

fn pair() -> impl Strategy<Value = String> {
    (number(), number()).prop_map(|(x, y)| format!("[{x}, {y}]"))
}

/// A ball: anywhere on the table, or on a small lattice in one corner (a dense cluster); when
/// `wild`, now and then with a position, radius, velocity or mass at the edges of `f64`.
fn ball(wild: bool) -> BoxedStrategy<String> {
    let w = u32::from(wild);
    let position = prop_oneof![
        8 => (20.0..380.0f64, 20.0..380.0f64).prop_map(|(x, y)| format!("[{x:?}, {y:?}]")),
        4 => (0u32..12, 0u32..12).prop_map(|(i, j)| format!("[{}.0, {}.0]", 50 + 3 * i, 50 + 3 * j)),
        w => pair(),
    ];
    let radius = prop_oneof![
        12 => Just("1.0".to_string()),
        3 => (0.001..1.5f64).prop_map(|r| format!("{r:?}")),
        w => number(),
    ];
    let velocity = prop_oneof![
        12 => (-60.0..60.0f64, -60.0..60.0f64).prop_map(|(x, y)| format!("[{x:?}, {y:?}]")),
        w => pair(),
    ];
    let mass = prop_oneof![
        12 => (0.5..3.0f64).prop_map(|m| format!("{m:?}")),
        w => number(),
    ];
    (
        position,
        radius,
        prop::option::of(velocity),
        prop::option::of(mass),
    )
        .prop_map(|(p, r, v, m)| {
            let mut s = format!("[[ball]]\nposition = {p}\nradius = {r}\n");
            if let Some(v) = v {
                s += &format!("velocity = {v}\n");
            }
            if let Some(m) = m {
                s += &format!("mass = {m}\n");
            }
            s
        })
        .boxed()
}

/// The table: the 400 × 400 box, each side possibly reversed, left out, or split by a pocket,
/// and sometimes a stray wall of random ends; with whether it is closed (no side left out, no
/// stray wall: a ball that leaves its box is then a bug, where an open table may let it go).
fn table() -> impl Strategy<Value = (String, bool)> {
    let side = prop::sample::select(vec![
        "keep", "keep", "keep", "keep", "keep", "keep", "reverse", "drop", "pocket", "pocket",
    ]);
    (
        prop::collection::vec(side, 4),
        prop::option::of((pair(), pair())),
        prop::option::of(0.0..=1.0f64),
    )
        .prop_map(|(sides, stray, elasticity)| {
            let corners = [(0.0, 0.0), (0.0, 400.0), (400.0, 400.0), (400.0, 0.0)];
            let mut s = String::new();
            for (k, how) in sides.iter().enumerate() {
                let (a, b) = (corners[k], corners[(k + 1) % 4]);
                let seg = |kind: &str, a: (f64, f64), b: (f64, f64)| {
                    format!(
                        "[[{kind}]]\nfrom = [{:?}, {:?}]\nto = [{:?}, {:?}]\n",
                        a.0, a.1, b.0, b.1
                    )
                };
                let mid = ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0);
                let near = ((a.0 * 3.0 + b.0) / 4.0, (a.1 * 3.0 + b.1) / 4.0);
                match *how {
                    "keep" => s += &seg("cushion", a, b),
                    "reverse" => s += &seg("cushion", b, a),
                    "pocket" => {
                        s += &seg("cushion", a, near);
                        s += &seg("pocket", near, mid);
                        s += &seg("cushion", mid, b);
                    }
                    _ => {}
                }
            }
            if let Some(e) = elasticity {
                s = s.replacen(
                    "[[cushion]]\n",
                    &format!("[[cushion]]\nelasticity = {e:?}\n"),
                    1,
                );
            }
            let closed = stray.is_none() && !sides.contains(&"drop");
            if let Some((a, b)) = stray {
                s += &format!("[[cushion]]\nfrom = {a}\nto = {b}\n");
            }
            (s, closed)
        })
}

/// A whole file: a run section (or none), up to 15 balls, a table, and sometimes sectors; with
/// whether its table is closed.
fn scenario_text() -> impl Strategy<Value = (String, bool)> {
    (
        prop::option::of(prop_oneof![
            4 => (0.0..3.0f64).prop_map(|t| format!("{t:?}")),
            1 => number(),
        ]),
        prop_oneof![
            1 => Just(Vec::new()),
            8 => prop::collection::vec(ball(false), 1..16),
            4 => prop::collection::vec(ball(true), 1..6),
        ],
        table(),
        prop::option::of((0u32..5, 0u32..5)),
    )
        .prop_map(|(until, balls, (table, closed), sectors)| {
            let mut s = String::new();
            if let Some(t) = until {
                s += &format!("[run]\nuntil = {t}\n");
            }
            s += &balls.concat();
            s += &table;
            if let Some((nx, ny)) = sectors {
                s += &format!("[sectors]\ngrid = [{nx}, {ny}]\n");
            }
            (s, closed)
        })
}

/// The final-state digest of a run (`check`: with the invariants checked), or its error.
fn digest(s: &Scenario, engine: EngineKind, check: bool) -> Result<String, RunError> {
    let cfg = RunConfig {
        engine,
        until: s.until.min(3.0),
        check,
        span: Default::default(),
        interrupt: None,
        checkpoint_every: None,
        thermostat: None,
    };
    execute(s, &cfg, &mut Ignore).map(|r| r.summary.final_state_digest)
}

/// Runs `s` on every engine: the exact ones must agree with the event list, which keeps its
/// invariants on a closed table. (On an open table a ball may leave the box through a gap, or
/// meet a one-sided wall from behind and pass through it, which the check reports.)
fn run_everywhere(s: &Scenario, text: &str, closed: bool) -> Result<(), TestCaseError> {
    if let Err(RunError::Violation(v)) = digest(s, EngineKind::EventList, true) {
        if closed {
            return Err(TestCaseError::fail(format!("event list: {v}\n{text}")));
        }
    }
    let reference = digest(s, EngineKind::EventList, false);
    let _ = digest(s, EngineKind::TimeStep { dt: 0.01 }, true);
    let sectored = |tw: Option<usize>| match tw {
        None => EngineKind::Sectored {
            sectors: SectorChoice::Auto,
            news: FixedNews::Near,
        },
        Some(workers) => EngineKind::TimeWarp {
            tw: TwConfig {
                workers,
                ..TwConfig::default()
            },
            delay: NvDelay::Exact,
            sectors: Some(SectorChoice::Auto),
            news: FixedNews::Near,
        },
    };
    let exact = [
        (
            "objects",
            EngineKind::Objects {
                delay: NvDelay::Exact,
            },
        ),
        ("sectored", sectored(None)),
        ("time-warp", sectored(Some(2))),
    ];
    for (name, engine) in exact {
        let got = digest(s, engine, false);
        match (&reference, &got) {
            (Ok(want), Ok(have)) => prop_assert_eq!(want, have, "{} differs\n{}", name, text),
            // sectors cover a closed table alone
            (Ok(_), Err(RunError::Input(e))) if !closed && e.starts_with("--sectors:") => {}
            (Ok(_), Err(e)) => {
                return Err(TestCaseError::fail(format!("{name}: {e}\n{text}")));
            }
            (Err(_), _) => {} // the event list stopped (a cascade): the others need not agree
        }
    }
    Ok(())
}

/// The seed the files are drawn with.
fn seed() -> proptest::test_runner::RngSeed {
    use proptest::test_runner::RngSeed;
    match std::env::var("POOLSIM_FUZZ_SEED").ok().as_deref() {
        None => RngSeed::Fixed(20_261_128),
        Some("random") => RngSeed::Random,
        Some(n) => n.parse().map_or(RngSeed::Random, RngSeed::Fixed),
    }
}

fn cases() -> u32 {
    std::env::var("POOLSIM_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(48)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: cases(),
        rng_seed: seed(),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Parse, validate and run: one line for a refusal, agreement and no panic for the rest.
    #[test]
    fn any_scenario_is_refused_in_one_line_or_runs_alike_everywhere(
        (text, closed) in scenario_text()
    ) {
        match parse(&text, SOURCE) {
            Err(e) => {
                let shown = e.to_string();
                prop_assert!(shown.starts_with(SOURCE), "{}", shown);
                prop_assert!(!shown.contains('\n'), "{}", shown);
            }
            Ok(s) => run_everywhere(&s, &text, closed)?,
        }
    }
}

/// Found by the fuzz target: a ball of radius 10^-6 meeting a cushion at y = 400, where the
/// position is known to 6 × 10^-14; the check took the rounding for an overlap.
#[test]
fn a_tiny_ball_at_a_far_cushion_passes_the_check() {
    let text = "[[ball]]\nposition = [20.0, 373.29657642904925]\nradius = 1e-6\n\
        velocity = [0.0, 43.787449093110006]\n\
        [[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 400.0]\n\
        [[cushion]]\nfrom = [0.0, 400.0]\nto = [400.0, 400.0]\n\
        [[cushion]]\nfrom = [400.0, 400.0]\nto = [400.0, 0.0]\n\
        [[cushion]]\nfrom = [400.0, 0.0]\nto = [0.0, 0.0]\n";
    let s = parse(text, SOURCE).unwrap();
    run_everywhere(&s, text, true).unwrap();
}

/// Found by the fuzz target: on a table open at the bottom, two balls leave through the gap and
/// meet below it. The event list sees them collide; sectors cover the table alone, so the
/// sectored engines did not, and ended elsewhere. They now refuse an open table in one line.
#[test]
fn two_balls_that_meet_outside_an_open_table_are_no_sectored_run() {
    let text = "[[ball]]\nposition = [77.34087969802017, 20.0]\nradius = 1.0\n\
        velocity = [-3.91102269536947, -18.52239980369066]\n\
        [[ball]]\nposition = [71.0, 77.0]\nradius = 1.0\n\
        velocity = [-59.266119903076294, -43.70839063130629]\n\
        [[cushion]]\nfrom = [0.0, 0.0]\nto = [0.0, 400.0]\n\
        [[cushion]]\nfrom = [0.0, 400.0]\nto = [400.0, 400.0]\n\
        [[cushion]]\nfrom = [400.0, 400.0]\nto = [400.0, 0.0]\n";
    let s = parse(text, SOURCE).unwrap();
    assert!(!s.is_closed());
    let sectored = EngineKind::Sectored {
        sectors: SectorChoice::Auto,
        news: FixedNews::Near,
    };
    match digest(&s, sectored, false) {
        Err(RunError::Input(e)) => {
            assert!(e.starts_with("--sectors: a sectored run needs a closed table"))
        }
        other => panic!("{other:?}"),
    }
    // the plain objects engine has no sectors: it agrees with the event list
    run_everywhere(&s, text, false).unwrap();
}
