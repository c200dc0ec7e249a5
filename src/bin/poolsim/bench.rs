//! `poolsim bench`: runs the library's measurements and prints each table as its rows come, or
//! one JSON object at the end.

use crate::common::{usage, Failure};
use pdes_kernel::phold::{PholdReport, ROSS_EVENTS_PER_SECOND_PER_CORE};
use poolsim::bench::{
    self, BenchOptions, Measured, ObjectsRow, Part, TwRow, SECTORED_WARM_UP, SECTORED_WINDOW,
};

/// Arguments of `poolsim bench`.
#[derive(clap::Args, Clone, Debug)]
pub struct BenchArgs {
    /// Ball counts.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1024,10000,99856,1000000"
    )]
    pub balls: Vec<usize>,
    /// Area fractions.
    #[arg(
        long = "area-fractions",
        value_delimiter = ',',
        default_value = "0.3,0.6"
    )]
    pub area_fractions: Vec<f64>,
    /// Physical events measured per configuration (at least 5 per ball are run).
    #[arg(long, default_value_t = 2_000_000)]
    pub events: u64,
    /// Ball counts for the objects engine (non-sectored: its cost per event grows with N).
    #[arg(
        long = "objects-balls",
        value_delimiter = ',',
        default_value = "36,144,576"
    )]
    pub objects_balls: Vec<usize>,
    /// Ball counts for the sectored objects engine (`--sectors auto`, area fraction 0.3).
    #[arg(
        long = "sectored-balls",
        value_delimiter = ',',
        default_value = "1024,4096"
    )]
    pub sectored_balls: Vec<usize>,
    /// Ball counts for Time Warp (on each of `--tw-workers`) against the sequential objects
    /// engine: whole runs of the sectored gas (`--sectors auto`) until `--tw-until`, set-up
    /// included.
    #[arg(long = "tw-balls", value_delimiter = ',', default_value = "9801")]
    pub tw_balls: Vec<usize>,
    /// Ball counts for the regions engine (on each of `--tw-workers`, four regions per worker,
    /// one on one worker) against the event list: whole runs of the gas at area fraction 0.5
    /// until `--tw-until`, set-up included.
    #[arg(
        long = "regions-balls",
        value_delimiter = ',',
        default_value = "100000"
    )]
    pub regions_balls: Vec<usize>,
    /// Worker counts of the Time Warp, regions and PHOLD rows.
    #[arg(long = "tw-workers", value_delimiter = ',', default_value = "1,2")]
    pub tw_workers: Vec<usize>,
    /// Simulated time of the Time Warp runs.
    #[arg(long = "tw-until", default_value_t = 1.0)]
    pub tw_until: f64,
    /// Pure Time Warp in the Time Warp and PHOLD runs: no batch runs as final.
    #[arg(long = "tw-pure")]
    pub tw_pure: bool,
    /// PHOLD objects (16 messages each, remote 0.1, lookahead 0.1; as many partitions as the
    /// most workers of `--tw-workers`, at least 2, in every row, so that every row runs one
    /// model).
    #[arg(long = "phold-objects", default_value_t = 1024)]
    pub phold_objects: u32,
    /// Grid cell width in ball diameters.
    #[arg(long = "cell-diameters", default_value_t = 1.0)]
    pub cell_diameters: f64,
    /// Runs of each configuration; the fastest is reported (for Time Warp, the repetition whose
    /// three runs took least in all). Timings on a shared machine swing by tens of per cent.
    #[arg(long, default_value_t = 1)]
    pub repeat: u32,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

impl BenchArgs {
    /// The library's options.
    fn options(&self) -> BenchOptions {
        BenchOptions {
            balls: self.balls.clone(),
            area_fractions: self.area_fractions.clone(),
            events: self.events,
            objects_balls: self.objects_balls.clone(),
            sectored_balls: self.sectored_balls.clone(),
            tw_balls: self.tw_balls.clone(),
            regions_balls: self.regions_balls.clone(),
            tw_workers: self.tw_workers.clone(),
            tw_until: self.tw_until,
            tw_pure: self.tw_pure,
            phold_objects: self.phold_objects,
            cell_diameters: self.cell_diameters,
            repeat: self.repeat,
        }
    }
}

/// Runs the bench, printing its tables as the rows come (or one JSON object at the end).
pub fn bench(a: &BenchArgs) -> Result<(), Failure> {
    let mut table = Table::new(a);
    let report = bench::run(&a.options(), &mut |m| {
        // Time Warp runs without transparent huge pages, as `poolsim run` runs it
        if let Measured::Starting(part) = m {
            poolsim::memory::transparent_huge_pages(!matches!(
                part,
                Part::TimeWarp | Part::Regions
            ));
        }
        if !a.json {
            table.print(m);
        }
    })
    .map_err(|e| usage(e.to_string()))?;
    if a.json {
        println!("{}", serde_json::to_string(&report).expect("plain data"));
    }
    Ok(())
}

/// The text tables, each headed when its first row comes.
struct Table<'a> {
    args: &'a BenchArgs,
    /// The section last headed.
    section: Option<&'static str>,
}

impl<'a> Table<'a> {
    fn new(args: &'a BenchArgs) -> Table<'a> {
        Table {
            args,
            section: None,
        }
    }

    /// Prints the heading of `section` unless it is the current one.
    fn head(&mut self, section: &'static str) {
        if self.section == Some(section) {
            return;
        }
        if self.section.is_some() {
            println!();
        }
        self.section = Some(section);
        match section {
            "rows" => {
                println!(
                    "event-list engine, thesis gas (seed 1), one thread; {}",
                    bench::machine()
                );
                println!(
                    "{:>9} {:>6} {:>11} {:>9} {:>9} {:>14} {:>9} {:>9}",
                    "balls",
                    "phi",
                    "events",
                    "setup s",
                    "loop s",
                    "events/s",
                    "ns/event",
                    "RSS MiB"
                );
            }
            "objects" => {
                println!(
                    "objects engine (thesis fig. 3, sequential, non-sectored), thesis gas until 4"
                );
                objects_header();
            }
            "sectored" => {
                println!(
                    "sectored objects engine (thesis fig. 14, --sectors auto), gas at area fraction \
                     0.3, t = {SECTORED_WARM_UP} to {} (after set-up and warm-up)",
                    SECTORED_WARM_UP + SECTORED_WINDOW
                );
                objects_header();
            }
            "time_warp" => time_warp_header(self.args),
            "regions" => regions_header(self.args),
            _ => println!(
                "PHOLD beside ROSS's published record, {:.2} M committed events/s per core (504 \
                 billion/s on 1,966,080 Blue Gene/Q cores; Barnes et al., PADS 2013):",
                ROSS_EVENTS_PER_SECOND_PER_CORE / 1e6
            ),
        }
    }

    fn print(&mut self, m: Measured) {
        match m {
            Measured::Starting(_) => {}
            Measured::Row(r) => {
                self.head("rows");
                println!(
                    "{:>9} {:>6.2} {:>11} {:>9.2} {:>9.2} {:>14.0} {:>9.1} {:>9.0}",
                    r.balls,
                    r.area_fraction,
                    r.events,
                    r.setup_seconds,
                    r.seconds,
                    r.events_per_second,
                    r.ns_per_event,
                    r.rss_mib
                );
            }
            Measured::Growth(growth) => {
                for g in growth {
                    println!(
                        "cost per event at {} balls / at {} balls, phi {:.2}: {:.2}",
                        g.to_balls, g.from_balls, g.area_fraction, g.ratio
                    );
                }
            }
            Measured::Objects(r) => {
                self.head("objects");
                objects_row(r);
            }
            Measured::Sectored(r) => {
                self.head("sectored");
                objects_row(r);
            }
            Measured::TimeWarp(r) => {
                self.head("time_warp");
                time_warp_row(r);
            }
            Measured::Regions(r) => {
                self.head("regions");
                time_warp_row(r);
            }
            Measured::Phold(p) => {
                self.head("phold");
                phold_row(p);
            }
        }
    }
}

fn objects_header() {
    println!(
        "{:>9} {:>11} {:>12} {:>9} {:>14} {:>12} {:>10}",
        "balls", "events", "messages", "wall s", "events/s", "messages/s", "msgs/event"
    );
}

fn objects_row(r: &ObjectsRow) {
    println!(
        "{:>9} {:>11} {:>12} {:>9.3} {:>14.0} {:>12.0} {:>10.1}",
        r.balls,
        r.events,
        r.messages,
        r.seconds,
        r.events as f64 / r.seconds,
        r.messages as f64 / r.seconds,
        r.messages as f64 / r.events.max(1) as f64
    );
}

fn time_warp_header(a: &BenchArgs) {
    println!(
        "Time Warp against the sequential objects engine: sectored gas (--sectors auto) \
         until {}, whole runs, each engine's fastest of {} run in turn (median: of the \
         speed-ups within each turn)",
        a.tw_until, a.repeat
    );
    parallel_columns();
}

/// The columns of the Time Warp and regions rows.
fn parallel_columns() {
    println!(
        "{:>9} {:>8} {:>9} {:>9} {:>9} {:>7} {:>11} {:>8} {:>6}  digest",
        "balls",
        "workers",
        "wall s",
        "set-up s",
        "speed-up",
        "median",
        "efficiency",
        "remote",
        "final"
    );
}

fn regions_header(a: &BenchArgs) {
    println!(
        "the regions engine against the event list (seq): gas at area fraction 0.5 until {}, \
         four regions per worker (one on one worker), whole runs, each engine's fastest of {} \
         run in turn",
        a.tw_until, a.repeat
    );
    parallel_columns();
}

fn time_warp_row(r: &TwRow) {
    println!(
        "{:>9} {:>8} {:>9.3} {:>9.3} {:>9.2} {:>7.2} {:>11.3} {:>8.3} {:>6.3}  {}",
        r.balls,
        if r.workers == 0 {
            "seq".to_string()
        } else {
            r.workers.to_string()
        },
        r.seconds,
        r.setup_seconds,
        r.speedup,
        r.median_speedup,
        r.efficiency,
        r.remote_fraction,
        r.final_fraction,
        r.digest
    );
}

fn phold_row(p: &PholdReport) {
    let workers = match (&p.time_warp, &p.conservative) {
        (Some(t), _) => Some(t.workers as usize),
        (_, Some(c)) => Some(c.workers),
        _ => None,
    };
    let executor = match workers {
        Some(1) => "1 worker".to_string(),
        Some(w) => format!("{w} workers"),
        None => "sequential kernel".to_string(),
    };
    println!(
        "PHOLD {} objects x 16 events, remote 0.1, {} partitions, end 20, {} ({}): {} \
         committed, {:.0} events/s, {:.2} M per core, efficiency {:.3}, {}digest {}",
        p.objects,
        p.partitions,
        p.engine,
        executor,
        p.committed,
        p.events_per_second,
        p.events_per_second_per_core / 1e6,
        p.time_warp.as_ref().map_or(1.0, |t| t.efficiency()),
        p.speedup.map_or(String::new(), |s| format!(
            "{s:.2}x the sequential kernel, "
        )),
        p.final_state_digest
    );
}
