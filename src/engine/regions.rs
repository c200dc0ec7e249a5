//! The regions engine: the event list cut into strips of the table
//! ([`crate::model::regions`]), run by the sequential kernel executor or by Time Warp, each
//! region one kernel object. It runs exactly the event list's physical events, in its order.

use super::{BallState, EventCounts, InstantCap, Observer, Outcome, RunError, Table, World};
use crate::model::regions::{Region, Regions, RegionsError};
use crate::scenario::Scenario;
use crate::summary::RegionsSummary;
use pdes_kernel::sequential::Sequential;
use pdes_kernel::time_warp::threads::{total_workers, TimeWarp};
use pdes_kernel::time_warp::{ObjectMap, TwConfig, TwStats};
use pdes_kernel::{ExecError, Executor, Interrupt, VTime};
use std::collections::BTreeMap;

/// The regions engine over one scenario.
pub struct RegionsEngine {
    exec: Box<dyn Executor<Regions, RunError>>,
    /// Balls each region owned at the start.
    balls_start: Vec<usize>,
    /// Committed events run by two regions, and all committed events, so far.
    across: (u64, u64),
    /// Committed events each region reported, so far.
    events: Vec<u64>,
}

/// The committed regions as the balls they own, for observers.
struct View<'a> {
    table: &'a Table,
    regions: &'a [Region],
    n_balls: u32,
}

impl View<'_> {
    /// Ball `gid` as its owner keeps it.
    fn find(&self, gid: u32) -> BallState {
        self.regions
            .iter()
            .find_map(|r| r.ball(gid))
            .expect("every ball has an owner")
    }
}

impl World for View<'_> {
    fn table(&self) -> &Table {
        self.table
    }

    fn n_balls(&self) -> usize {
        self.n_balls as usize
    }

    fn ball(&self, i: u32) -> BallState {
        self.find(i)
    }

    fn for_each_neighbor(&self, i: u32, f: &mut dyn FnMut(u32)) {
        for j in (0..self.n_balls).filter(|&j| j != i) {
            f(j);
        }
    }
}

/// News the busiest region may hear in Time Warp's optimism window when none is set
/// ([`Region::news_rate`]): a region that runs past its neighbours' next news is cut back
/// there, and the kernel's own window, counted in batches and events, does not see that. A
/// twelfth of a news: 10^5 disks at area fraction 0.5 in 2 regions on 2 workers ran 4 % faster
/// at 3 x 10^-4 (a twelfth) than at 4.7 x 10^-4 (an eighth), and 10^6 disks fastest at 10^-4
/// (a twelfth gives 0.97 x 10^-4), where the kernel's window undid half the events run.
const NEWS_PER_WINDOW: f64 = 1.0 / 12.0;

impl RegionsEngine {
    /// Sets `count` regions up at `start`, on the sequential executor or (with `tw`) under
    /// Time Warp, the regions dealt to the workers in blocks of neighbours.
    pub fn new(
        s: &Scenario,
        count: u32,
        start: f64,
        tw: Option<TwConfig>,
    ) -> Result<RegionsEngine, RegionsError> {
        let (model, states) = Regions::new(s, count, start)?;
        let balls_start: Vec<usize> = states.iter().map(Region::owned).collect();
        let start = VTime::start(start);
        let exec: Box<dyn Executor<Regions, RunError>> = match tw {
            None => Box::new(Sequential::new(model, states, start)),
            Some(mut cfg) => {
                let rate = states.iter().map(Region::news_rate).fold(0.0, f64::max);
                if cfg.window.is_none() && rate > 0.0 {
                    cfg.window = Some(NEWS_PER_WINDOW / rate);
                }
                let workers = total_workers(&cfg) as u64;
                let map = (0..u64::from(count))
                    .map(|k| (k * workers / u64::from(count)) as u32)
                    .collect();
                let map = ObjectMap::Given(map);
                Box::new(TimeWarp::new(model, states, start, &map, cfg))
            }
        };
        Ok(RegionsEngine {
            exec,
            events: vec![0; balls_start.len()],
            balls_start,
            across: (0, 0),
        })
    }

    /// Every ball's state at `t` (after the last event), from the committed regions.
    fn balls_at(&self, t: f64) -> Vec<BallState> {
        let m = self.exec.model();
        let view = View {
            table: m.table(),
            regions: self.exec.states(),
            n_balls: m.n_balls(),
        };
        (0..m.n_balls())
            .map(|i| {
                let mut b = view.find(i);
                if b.pocket.is_none() {
                    b.traj.position = b.traj.at(t);
                    b.traj.t0 = t;
                }
                b
            })
            .collect()
    }
}

impl super::Engine for RegionsEngine {
    fn run(&mut self, until: f64, obs: &mut dyn Observer) -> Result<Outcome, RunError> {
        let mut counts = EventCounts::default();
        let n = self.exec.model().n_balls();
        let mut instant = InstantCap::new(n as usize);
        self.exec.observe_states(obs.reads_balls());
        let (across, events) = (&mut self.across, &mut self.events);
        let ended = self
            .exec
            .run(until, &mut |model: &Regions, states: &[Region], out| {
                let ev = out.event;
                across.0 += u64::from(out.across);
                across.1 += 1;
                events[out.region as usize] += 1;
                instant.count(&ev)?;
                counts.add(ev.kind);
                let view = View {
                    table: model.table(),
                    regions: states,
                    n_balls: n,
                };
                obs.on_event(&ev, &view)
            })
            .map_err(|e| match e {
                ExecError::Sink(e) => e,
                ExecError::Failed(m) => RunError::TimeWarp(m),
            })?;
        let stats = self.exec.stats();
        let messages = super::message_counts(self.exec.model(), stats);
        Ok(Outcome {
            t: ended,
            balls: self.balls_at(ended),
            events: counts,
            engine_stats: vec![
                ("regions", self.exec.states().len() as f64),
                ("batches", stats.batches as f64),
                ("messages_delivered", stats.delivered as f64),
            ],
            messages,
        })
    }

    fn stop_on(&mut self, interrupt: Interrupt) {
        self.exec.stop_on(interrupt);
    }

    fn tw_stats(&self) -> Option<TwStats> {
        self.exec.tw_stats()
    }

    fn regions(&self) -> Option<RegionsSummary> {
        let states = self.exec.states();
        let messages: BTreeMap<String, u64> =
            super::message_counts(self.exec.model(), self.exec.stats())
                .into_iter()
                .map(|(k, n)| (k.to_string(), n))
                .collect();
        Some(RegionsSummary {
            count: states.len() as u32,
            columns: states.iter().map(Region::strip_columns).collect(),
            balls_start: self.balls_start.clone(),
            balls_end: states.iter().map(Region::owned).collect(),
            events: self.events.clone(),
            events_across: self.across.0,
            fraction_across: self.across.0 as f64 / self.across.1.max(1) as f64,
            messages,
        })
    }

    fn free(self: Box<Self>) {
        self.exec.free();
    }
}
