use poolsim::engine::Ignore;
use poolsim::run::{execute, EngineKind, RunConfig};
use poolsim::scenario::builtin::{self, Params};

#[test]
fn probe() {
    let s = builtin::build("gas", &Params::default()).unwrap();
    for until in [0.2, 0.3, 0.4, 0.5, 0.7, 1.0] {
        let cfg = RunConfig {
            engine: EngineKind::EventList,
            until,
            check: false,
        };
        let exact = execute(&s, &cfg, &mut Ignore).unwrap();
        let mut line = format!("until {until} events {}:", exact.outcome.events.total());
        for dt in [0.1, 0.01, 0.001, 0.0001] {
            let cfg = RunConfig {
                engine: EngineKind::TimeStep { dt },
                until,
                check: false,
            };
            let r = execute(&s, &cfg, &mut Ignore).unwrap();
            let err = r
                .outcome
                .balls
                .iter()
                .zip(&exact.outcome.balls)
                .map(|(a, b)| (a.position(until) - b.position(until)).norm())
                .fold(0.0, f64::max);
            let st: std::collections::HashMap<_, _> =
                r.outcome.engine_stats.iter().cloned().collect();
            line += &format!(
                " dt {dt}: err {err:.4} ev {} steps {} pairs {} sep {};",
                r.outcome.events.total(),
                st["steps"],
                st["pair_tests"],
                st["overlapping_separating_pairs"]
            );
        }
        println!("{line}");
    }
}
