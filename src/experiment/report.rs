//! `report.md`: the setup, what agrees with the thesis and what does not, with every table
//! inlined. The words are in the template `report.md.j2`; this module computes what it fills in
//! (numbers already formatted, labels, yes and no) as a [`Context`].

use super::data::Data;
use super::findings::{bps_of, bps_text, monotone, opt_label, Finding, Paired};
use super::tables::{setting_at, spreadsheet, thesis9_column, Sheet};
use super::thesis;
use super::{settings, ExperimentError, Setting, RADIUS, SPEED_MAX};
use minijinja::{AutoEscape, Environment, UndefinedBehavior};
use serde::Serialize;

/// The report's text, with the places [`Context`] fills in.
const TEMPLATE: &str = include_str!("report.md.j2");

/// The report: `tables` are the Markdown of tables 5 to 10 (by file name, table 5 first),
/// `figures` whether figures 17 and 18 were drawn.
pub(super) fn report(
    data: &Data,
    tables: &[(&str, String)],
    fs: &[Finding],
    figures: bool,
) -> Result<String, ExperimentError> {
    let p = &data.plan;
    let ctx = Context {
        quick: p.quick,
        balls: p.balls.clone(),
        seeds: p.seeds,
        until: format!("{}", p.until),
        runs: data.runs.len(),
        repeats: p.timing_repeats,
        wall_total: format!("{:.1}", data.wall_total),
        radius: format!("{RADIUS}"),
        speed_max: format!("{SPEED_MAX}"),
        mismatches: data.mismatches.len(),
        headline: body_of(&tables[0].1),
        agree: fs.iter().map(AgreeRow::of).collect(),
        optimum: Optimum::of(fs),
        crossover: Crossover::of(fs),
        eight: eight_lines(fs),
        table7: table7_lines(data, fs),
        table7_within: table7_within(data, fs),
        mix: Mix::of(data),
        ratios: Ratios::of(data),
        wall: Wall::of(data, fs),
        model: Model::of(data, fs),
        tables: tables
            .iter()
            .skip(1)
            .map(|(name, text)| Section {
                title: title_of(text).unwrap_or(name).to_string(),
                body: body_of(text),
            })
            .collect(),
        figures,
        gas: fs
            .iter()
            .map(|f| GasParams {
                balls: f.balls,
                vt: format!("{:.3}", f.model_vt),
                m: format!("{:.0}", f.model_m),
            })
            .collect(),
    };
    render(&ctx)
}

/// Fills the template in.
fn render(ctx: &Context) -> Result<String, ExperimentError> {
    let mut env = Environment::new();
    env.set_trim_blocks(true);
    env.set_lstrip_blocks(true);
    env.set_keep_trailing_newline(true);
    env.set_undefined_behavior(UndefinedBehavior::Strict);
    env.set_auto_escape_callback(|_| AutoEscape::None);
    env.add_template("report.md", TEMPLATE)
        .and_then(|()| env.get_template("report.md")?.render(ctx))
        .map_err(ExperimentError::Report)
}

/// The title of a table's Markdown: its first line without `# `.
fn title_of(text: &str) -> Option<&str> {
    text.lines().next()?.strip_prefix("# ")
}

/// A table's Markdown without its title line and without its final newline.
fn body_of(text: &str) -> String {
    let body = match text.split_once('\n') {
        Some((first, rest)) if first.starts_with("# ") => rest.trim_start(),
        _ => text,
    };
    body.strip_suffix('\n').unwrap_or(body).to_string()
}

/// What the template fills in.
#[derive(Serialize)]
struct Context {
    quick: bool,
    balls: Vec<usize>,
    seeds: u64,
    until: String,
    runs: usize,
    repeats: u32,
    wall_total: String,
    radius: String,
    speed_max: String,
    /// Runs whose final state differs from the event-list engine's.
    mismatches: usize,
    /// Table 5 without its title.
    headline: String,
    agree: Vec<AgreeRow>,
    optimum: Optimum,
    crossover: Crossover,
    eight: Vec<EightLine>,
    table7: Vec<Table7Line>,
    /// Whether every non-sectored mean lies within one thesis SD of table 7's.
    table7_within: bool,
    mix: Option<Mix>,
    ratios: Option<Ratios>,
    wall: Wall,
    model: Model,
    /// Tables 6 to 10.
    tables: Vec<Section>,
    figures: bool,
    gas: Vec<GasParams>,
}

/// A setting and its balls per sector.
#[derive(Serialize)]
struct Grid {
    label: String,
    bps: String,
}

impl Grid {
    fn of(n: usize, s: Setting) -> Grid {
        Grid {
            label: s.label(),
            bps: bps_text(bps_of(n, s)),
        }
    }
}

/// A [`Paired`] comparison, for the template's `paired` macro.
#[derive(Serialize)]
struct PairedText {
    /// The label of the setting compared.
    a: String,
    /// Mean difference, signed.
    diff: String,
    /// Its standard error, if more than one seed.
    se: Option<String>,
    wins: usize,
    seeds: usize,
}

impl From<&Paired> for PairedText {
    fn from(p: &Paired) -> PairedText {
        PairedText {
            a: p.a.label(),
            diff: format!("{:+.0}", p.diff_mean),
            se: p.diff_se.map(|se| format!("{se:.0}")),
            wins: p.a_wins,
            seeds: p.seeds,
        }
    }
}

/// Sectors against no sectors, seed by seed.
#[derive(Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "lowercase")]
enum Verdict {
    /// Within two standard errors.
    Tie,
    /// Sectors send fewer messages.
    Pay,
    /// Sectors send more.
    Cost,
}

impl Verdict {
    fn of(p: &Paired) -> Verdict {
        if p.tie() {
            Verdict::Tie
        } else if p.diff_mean < 0.0 {
            Verdict::Pay
        } else {
            Verdict::Cost
        }
    }
}

/// A row of the table of what agrees with the thesis.
#[derive(Serialize)]
struct AgreeRow {
    balls: usize,
    thesis_best: String,
    best: String,
    ties_best: Vec<String>,
    thesis_best_sectored: String,
    best_sectored: Option<Grid>,
    ties_sectored: Vec<Grid>,
    versus: Option<Versus>,
}

/// The best sectored setting against no sectors.
#[derive(Serialize)]
struct Versus {
    percent: String,
    verdict: Verdict,
    wins: usize,
    seeds: usize,
}

impl AgreeRow {
    fn of(f: &Finding) -> AgreeRow {
        let n = f.balls;
        AgreeRow {
            balls: n,
            thesis_best: opt_label(f.thesis_best),
            best: f.best().label(),
            ties_best: f.ties_best.iter().map(|p| p.b.label()).collect(),
            thesis_best_sectored: opt_label(f.thesis_best_sectored),
            best_sectored: f.best_sectored.map(|b| Grid::of(n, b)),
            ties_sectored: f.ties_sectored.iter().map(|p| Grid::of(n, p.b)).collect(),
            versus: match (f.sectored_vs_none, f.mean(Setting::NoSectors)) {
                (Some(pv), Some(none)) => Some(Versus {
                    percent: format!("{:+.0}", 100.0 * pv.diff_mean / none),
                    verdict: Verdict::of(&pv),
                    wins: pv.a_wins,
                    seeds: pv.seeds,
                }),
                _ => None,
            },
        }
    }
}

/// Our best sectored grid against the thesis': the same, within noise, or different.
#[derive(Serialize)]
struct Optimum {
    same: Vec<Same>,
    noise: Vec<Noise>,
    differ: Vec<Differ>,
}

/// Our best sectored grid is the thesis'.
#[derive(Serialize)]
struct Same {
    balls: usize,
    label: String,
}

/// Our best sectored grid ties the thesis'.
#[derive(Serialize)]
struct Noise {
    balls: usize,
    ours: Grid,
    thesis: Grid,
    paired: Option<PairedText>,
}

/// Our best sectored grid is not the thesis'.
#[derive(Serialize)]
struct Differ {
    balls: usize,
    ours: String,
    thesis: String,
}

impl Optimum {
    fn of(fs: &[Finding]) -> Optimum {
        let mut o = Optimum {
            same: Vec::new(),
            noise: Vec::new(),
            differ: Vec::new(),
        };
        for f in fs {
            let (Some(th), Some(b)) = (f.thesis_best_sectored, f.best_sectored) else {
                continue;
            };
            if th == b {
                o.same.push(Same {
                    balls: f.balls,
                    label: b.label(),
                });
            } else if f.among_best_sectored(th) {
                o.noise.push(Noise {
                    balls: f.balls,
                    ours: Grid::of(f.balls, b),
                    thesis: Grid::of(f.balls, th),
                    paired: f.ties_sectored.iter().find(|p| p.b == th).map(Into::into),
                });
            } else {
                o.differ.push(Differ {
                    balls: f.balls,
                    ours: b.label(),
                    thesis: th.label(),
                });
            }
        }
        o
    }
}

/// Where sectors start to pay: the numbers of balls by verdict.
#[derive(Serialize)]
struct Crossover {
    pay: Vec<usize>,
    tie: Vec<usize>,
    cost: Vec<usize>,
    /// The fewest balls for which sectors pay.
    first_pay: Option<usize>,
    /// Whether they pay for every number of balls from there up.
    keeps: bool,
}

impl Crossover {
    fn of(fs: &[Finding]) -> Crossover {
        let verdict = |f: &Finding| f.sectored_vs_none.as_ref().map(Verdict::of);
        let by = |v: Verdict| -> Vec<usize> {
            fs.iter()
                .filter(|f| verdict(f) == Some(v))
                .map(|f| f.balls)
                .collect()
        };
        let first_pay = fs
            .iter()
            .find(|f| verdict(f) == Some(Verdict::Pay))
            .map(|f| f.balls);
        let keeps = first_pay.is_some_and(|n0| {
            fs.iter()
                .filter(|f| f.balls >= n0)
                .all(|f| verdict(f) == Some(Verdict::Pay))
        });
        Crossover {
            pay: by(Verdict::Pay),
            tie: by(Verdict::Tie),
            cost: by(Verdict::Cost),
            first_pay,
            keeps,
        }
    }
}

/// One observation on the bound of eight balls per sector: either the best grid has more, or
/// a grid with more is compared with the best.
#[derive(Serialize)]
struct EightLine {
    balls: usize,
    best: Option<EightBest>,
    over: Option<EightOver>,
}

/// The best grid has more than eight balls per sector; the grids tied with it.
#[derive(Serialize)]
struct EightBest {
    grid: Grid,
    ties: Vec<EightTie>,
}

/// A grid tied with the best.
#[derive(Serialize)]
struct EightTie {
    grid: Grid,
    paired: PairedText,
}

/// A grid of more than eight balls per sector against the best grid.
#[derive(Serialize)]
struct EightOver {
    grid: Grid,
    verdict: Comparison,
    /// The best grid's label.
    best: String,
    diff: String,
    wins: usize,
    seeds: usize,
}

/// More or fewer messages than the best grid.
#[derive(Serialize)]
#[serde(rename_all = "lowercase")]
enum Comparison {
    Tie,
    More,
    Fewer,
}

/// What the runs say about eight balls per sector as an upper bound (ch. 7).
fn eight_lines(fs: &[Finding]) -> Vec<EightLine> {
    let mut lines = Vec::new();
    for f in fs {
        let n = f.balls;
        let Some(b) = f.best_sectored else { continue };
        if bps_of(n, b).is_some_and(|x| x > 8.0) {
            let ties = f
                .ties_sectored
                .iter()
                .map(|p| EightTie {
                    grid: Grid::of(n, p.b),
                    paired: p.into(),
                })
                .collect();
            lines.push(EightLine {
                balls: n,
                best: Some(EightBest {
                    grid: Grid::of(n, b),
                    ties,
                }),
                over: None,
            });
        }
        for pv in &f.over_eight {
            let verdict = if pv.tie() {
                Comparison::Tie
            } else if pv.diff_mean > 0.0 {
                Comparison::More
            } else {
                Comparison::Fewer
            };
            lines.push(EightLine {
                balls: n,
                best: None,
                over: Some(EightOver {
                    grid: Grid::of(n, pv.a),
                    verdict,
                    best: b.label(),
                    diff: format!("{:+.0}", pv.diff_mean),
                    wins: pv.a_wins,
                    seeds: pv.seeds,
                }),
            });
        }
    }
    lines
}

/// Our non-sectored mean against the thesis' six-seed mean (table 7).
#[derive(Serialize)]
struct Table7Line {
    balls: usize,
    ours: String,
    mean: String,
    sd: String,
    /// Our mean's distance from the thesis', in thesis standard deviations.
    z: String,
}

/// Our non-sectored means against table 7, for the numbers of balls it has.
fn table7_lines(data: &Data, fs: &[Finding]) -> Vec<Table7Line> {
    fs.iter()
        .filter_map(|f| {
            let t = thesis::TABLE7.iter().find(|r| r.0 == f.balls)?.1;
            let ours = data.total(f.balls, Setting::NoSectors)?;
            Some(Table7Line {
                balls: f.balls,
                ours: format!("{:.0}", ours.mean),
                mean: format!("{:.0}", t[0]),
                sd: format!("{:.0}", t[1]),
                z: format!("{:+.1}", (ours.mean - t[0]) / t[1]),
            })
        })
        .collect()
}

/// Whether every non-sectored mean lies within one thesis SD of table 7's.
fn table7_within(data: &Data, fs: &[Finding]) -> bool {
    fs.iter().all(|f| {
        let Some(t) = thesis::TABLE7.iter().find(|r| r.0 == f.balls) else {
            return true;
        };
        data.total(f.balls, Setting::NoSectors)
            .is_some_and(|o| (o.mean - t.1[0]).abs() <= t.1[1])
    })
}

/// The message mix of table 8 as the sectors shrink, and the estimator of table 9.
#[derive(Serialize)]
struct Mix {
    balls: usize,
    from: String,
    to: String,
    steady: Vec<Trend>,
    unsteady: Vec<Trend>,
    estimator: Option<Estimator>,
}

/// How one message type changes from the coarsest grid to the finest.
#[derive(Serialize)]
struct Trend {
    kind: &'static str,
    /// Whether the thesis expects it to grow (else to fall).
    up: bool,
    /// Our means, coarsest grid first.
    series: Vec<String>,
}

/// Estimated over actual NewVelocity, lowest and highest, with the thesis' 4 adjacent objects
/// and with ours; and our sectors occupied per ball against the thesis'.
#[derive(Serialize)]
struct Estimator {
    thesis_adjacency: [String; 2],
    our_adjacency: [String; 2],
    occupied: Option<Occupied>,
}

/// Sectors occupied per ball, ours and the thesis', and the worst relative difference.
#[derive(Serialize)]
struct Occupied {
    pairs: Vec<[String; 2]>,
    worst: String,
}

impl Mix {
    fn of(data: &Data) -> Option<Mix> {
        let n = data.focus();
        let ks: Vec<Setting> = settings(n)
            .into_iter()
            .filter(|s| s.per_side().is_some())
            .collect();
        if ks.len() < 2 {
            return None;
        }
        let series = |name: &str| -> Vec<f64> {
            ks.iter()
                .filter_map(|&s| data.stat(n, s, |r| r.msg(name)).map(|t| t.mean))
                .collect()
        };
        let checks = [
            ("SectorEntry", true),
            ("SectorDeparture", true),
            ("VelocityChange", true),
            ("Collision", false),
        ];
        let (steady, unsteady): (Vec<_>, Vec<_>) = checks
            .into_iter()
            .map(|(kind, up)| (monotone(&series(kind), up), kind, up))
            .partition(|t| t.0);
        let trend = |(_, kind, up): (bool, &'static str, bool)| Trend {
            kind,
            up,
            series: series(kind).iter().map(|x| format!("{x:.0}")).collect(),
        };
        Some(Mix {
            balls: n,
            from: ks[0].label(),
            to: ks[ks.len() - 1].label(),
            steady: steady.into_iter().map(trend).collect(),
            unsteady: unsteady.into_iter().map(trend).collect(),
            estimator: Estimator::of(n, &spreadsheet(data, n)),
        })
    }
}

impl Estimator {
    fn of(n: usize, sheets: &[Sheet]) -> Option<Estimator> {
        if sheets.is_empty() {
            return None;
        }
        let range = |ratio: fn(&Sheet) -> f64| {
            let xs: Vec<f64> = sheets.iter().map(ratio).collect();
            [
                format!("{:.2}", xs.iter().copied().fold(f64::INFINITY, f64::min)),
                format!(
                    "{:.2}",
                    xs.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                ),
            ]
        };
        Some(Estimator {
            thesis_adjacency: range(|s| s.estimated_new_velocity / s.actual_new_velocity),
            our_adjacency: range(|s| {
                s.estimated_new_velocity_our_adjacency / s.actual_new_velocity
            }),
            occupied: Occupied::of(n, sheets),
        })
    }
}

impl Occupied {
    /// For 36 balls, on the grids of table 9.
    fn of(n: usize, sheets: &[Sheet]) -> Option<Occupied> {
        if n != 36 {
            return None;
        }
        let pairs: Vec<(f64, f64)> = sheets
            .iter()
            .filter_map(|s| {
                let c = thesis9_column(s.sectors_per_side)?;
                Some((s.sectors_occupied, thesis::TABLE9[c][2]))
            })
            .collect();
        if pairs.is_empty() {
            return None;
        }
        let worst = pairs
            .iter()
            .map(|(a, b)| (a / b - 1.0).abs())
            .fold(0.0, f64::max);
        Some(Occupied {
            pairs: pairs
                .iter()
                .map(|(a, b)| [format!("{a:.2}"), format!("{b}")])
                .collect(),
            worst: format!("{:.0}", 100.0 * worst),
        })
    }
}

/// Our totals over the thesis' single runs, cell by cell, and what they say.
#[derive(Serialize)]
struct Ratios {
    /// Rows of the table: balls, then the ratio (or `-`) per thesis column.
    rows: Vec<Vec<String>>,
    single: Vec<SingleRun>,
    /// Lowest and highest coefficient of variation of the totals, in percent; none with one seed.
    cv: Option<[String; 2]>,
    sectored: Option<Sectored>,
}

/// A thesis non-sectored single run (table 5) against its own six-seed mean (table 7).
#[derive(Serialize)]
struct SingleRun {
    balls: usize,
    single: String,
    mean: String,
    sd: String,
    z: String,
}

/// The sectored ratios: lowest, highest, and the mean per number of balls.
#[derive(Serialize)]
struct Sectored {
    lo: RatioAt,
    hi: RatioAt,
    by_balls: Vec<RatioOf>,
    /// Whether the mean grows with the number of balls (over more than one).
    grows: bool,
}

/// A ratio in one cell.
#[derive(Serialize)]
struct RatioAt {
    ratio: String,
    balls: usize,
    grid: Grid,
}

/// The mean ratio for a number of balls.
#[derive(Serialize)]
struct RatioOf {
    ratio: String,
    balls: usize,
}

impl Ratios {
    fn of(data: &Data) -> Option<Ratios> {
        let mut rows = Vec::new();
        let mut sectored: Vec<(usize, Setting, f64)> = Vec::new();
        for &n in &data.plan.balls {
            let th = thesis::row(&thesis::TABLE5, n);
            let mut row = vec![n.to_string()];
            let mut any = false;
            for (c, t) in th.iter().enumerate() {
                let cell =
                    setting_at(n, c).and_then(|s| Some((s, data.total(n, s)?.mean / t.value()?)));
                row.push(match cell {
                    Some((s, r)) => {
                        any = true;
                        if s != Setting::NoSectors {
                            sectored.push((n, s, r));
                        }
                        format!("{r:.2}")
                    }
                    None => "-".into(),
                });
            }
            if any {
                rows.push(row);
            }
        }
        (!rows.is_empty()).then(|| Ratios {
            rows,
            single: single_runs(data),
            cv: cv_range(data),
            sectored: Sectored::of(data, &sectored),
        })
    }
}

/// The thesis' non-sectored single runs against its own six-seed means, where it has both.
fn single_runs(data: &Data) -> Vec<SingleRun> {
    data.plan
        .balls
        .iter()
        .filter_map(|&n| {
            let single = thesis::row(&thesis::TABLE5, n)[0].value()?;
            let t7 = thesis::TABLE7.iter().find(|r| r.0 == n)?.1;
            Some(SingleRun {
                balls: n,
                single: format!("{single:.0}"),
                mean: format!("{:.0}", t7[0]),
                sd: format!("{:.0}", t7[1]),
                z: format!("{:+.1}", (single - t7[0]) / t7[1]),
            })
        })
        .collect()
}

/// The range of coefficients of variation of the totals over all cells, in percent.
fn cv_range(data: &Data) -> Option<[String; 2]> {
    let cvs: Vec<f64> = data
        .cells
        .keys()
        .filter_map(|&(n, s)| {
            let t = data.total(n, s)?;
            Some(t.sd? / t.mean)
        })
        .collect();
    if cvs.is_empty() {
        return None;
    }
    Some([
        format!(
            "{:.0}",
            100.0 * cvs.iter().copied().fold(f64::INFINITY, f64::min)
        ),
        format!("{:.0}", 100.0 * cvs.iter().copied().fold(0.0, f64::max)),
    ])
}

impl Sectored {
    fn of(data: &Data, ratios: &[(usize, Setting, f64)]) -> Option<Sectored> {
        let lo = ratios.iter().copied().min_by(|a, b| a.2.total_cmp(&b.2))?;
        let hi = ratios.iter().copied().max_by(|a, b| a.2.total_cmp(&b.2))?;
        let at = |(n, s, r): (usize, Setting, f64)| RatioAt {
            ratio: format!("{r:.2}"),
            balls: n,
            grid: Grid::of(n, s),
        };
        let per_n: Vec<(usize, f64)> = data
            .plan
            .balls
            .iter()
            .filter_map(|&n| {
                let rs: Vec<f64> = ratios.iter().filter(|r| r.0 == n).map(|r| r.2).collect();
                (!rs.is_empty()).then(|| (n, rs.iter().sum::<f64>() / rs.len() as f64))
            })
            .collect();
        let grows = monotone(&per_n.iter().map(|x| x.1).collect::<Vec<_>>(), true);
        Some(Sectored {
            lo: at(lo),
            hi: at(hi),
            grows: grows && per_n.len() > 1,
            by_balls: per_n
                .into_iter()
                .map(|(n, r)| RatioOf {
                    ratio: format!("{r:.2}"),
                    balls: n,
                })
                .collect(),
        })
    }
}

/// Messages per second, the Dolphin's and ours (lowest, highest, and their ratio), and the
/// best sectored 36-ball grid against no sectors.
#[derive(Serialize)]
struct Wall {
    dolphin: [String; 3],
    ours: [String; 3],
    sectored: Option<WallSectored>,
}

/// The best sectored 36-ball grid against no sectors: fewer messages, and how fast.
#[derive(Serialize)]
struct WallSectored {
    grid: String,
    fewer: String,
    speed: Speed,
    /// How many times as fast (or as slow); empty when about as fast.
    factor: String,
    /// Whether a sectored message takes longer than a plain one.
    costlier: bool,
}

/// The sectored run's speed against the non-sectored one.
#[derive(Serialize)]
#[serde(rename_all = "lowercase")]
enum Speed {
    /// Within 10%.
    Same,
    Faster,
    Slower,
}

impl Wall {
    fn of(data: &Data, fs: &[Finding]) -> Wall {
        let rate = |n: usize, s: Setting| -> Option<f64> {
            Some(data.total(n, s)?.mean / data.stat(n, s, |r| r.wall_seconds)?.mean)
        };
        let ours: Vec<f64> = data
            .plan
            .balls
            .iter()
            .flat_map(|&n| settings(n).into_iter().map(move |s| (n, s)))
            .filter_map(|(n, s)| rate(n, s))
            .collect();
        let dolphin: Vec<f64> = thesis::TABLE5
            .iter()
            .zip(thesis::TABLE6.iter())
            .flat_map(|((_, m), (_, t))| {
                m.iter()
                    .zip(t.iter())
                    .filter_map(|(a, b)| Some(a.value()? / b.value()?))
                    .collect::<Vec<_>>()
            })
            .collect();
        let lo = |xs: &[f64]| xs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = |xs: &[f64]| xs.iter().copied().fold(0.0, f64::max);
        Wall {
            dolphin: [
                format!("{:.2}", lo(&dolphin)),
                format!("{:.2}", hi(&dolphin)),
                format!("{:.1}", hi(&dolphin) / lo(&dolphin)),
            ],
            ours: [
                format!("{:.1}", lo(&ours) / 1e6),
                format!("{:.1}", hi(&ours) / 1e6),
                format!("{:.1}", hi(&ours) / lo(&ours)),
            ],
            sectored: WallSectored::of(data, fs),
        }
    }
}

impl WallSectored {
    fn of(data: &Data, fs: &[Finding]) -> Option<WallSectored> {
        let f = fs.iter().find(|f| f.balls == 36)?;
        let b = f.best_sectored?;
        let none_w = data.stat(36, Setting::NoSectors, |r| r.wall_seconds)?;
        let none_m = f.mean(Setting::NoSectors)?;
        let bw = data.stat(36, b, |r| r.wall_seconds)?;
        let bm = f.mean(b)?;
        let (speed, factor) = match none_w.mean / bw.mean {
            r if (0.9..=1.1).contains(&r) => (Speed::Same, String::new()),
            r if r > 1.0 => (Speed::Faster, format!("{r:.1}")),
            r => (Speed::Slower, format!("{:.1}", 1.0 / r)),
        };
        Some(WallSectored {
            grid: b.label(),
            fewer: format!("{:.0}", 100.0 * (1.0 - bm / none_m)),
            speed,
            factor,
            costlier: bm / bw.mean < none_m / none_w.mean,
        })
    }
}

/// The chapter 7 model against our counts.
#[derive(Serialize)]
struct Model {
    /// Whether eq. 2's best grid is as fine as the measured best or finer, for every N.
    finer: bool,
    /// Whether eq. 2 predicts fewer messages than we count (by more than 5%) for every N.
    fewer: bool,
    lines: Vec<ModelLine>,
    scheduled: Option<Scheduled>,
}

/// Eq. 2 against our counts for one number of balls.
#[derive(Serialize)]
struct ModelLine {
    balls: usize,
    model_best: String,
    optimum: String,
    measured_best: String,
    ratio_best: String,
    ratio_finest: String,
}

/// Collisions scheduled (Collision / 2) and collisions that happened, no sectors.
#[derive(Serialize)]
struct Scheduled {
    balls: usize,
    scheduled: String,
    happened: String,
}

impl Model {
    fn of(data: &Data, fs: &[Finding]) -> Model {
        let lines = fs
            .iter()
            .filter_map(|f| {
                Some(ModelLine {
                    balls: f.balls,
                    model_best: f.model_best_grid?.label(),
                    optimum: format!("{:.1}", f.model_optimal_per_side),
                    measured_best: f.best_sectored?.label(),
                    ratio_best: format!("{:.1}", f.model_ratio_best?),
                    ratio_finest: format!("{:.1}", f.model_ratio_finest?),
                })
            })
            .collect();
        let finer = fs.iter().all(|f| {
            match (
                f.model_best_grid.and_then(Setting::per_side),
                f.best_sectored.and_then(Setting::per_side),
            ) {
                (Some(a), Some(b)) => a >= b,
                _ => true,
            }
        });
        let n = data.focus();
        let scheduled = data
            .stat(n, Setting::NoSectors, |r| r.msg("Collision"))
            .map(|c| Scheduled {
                balls: n,
                scheduled: format!("{:.0}", c.mean / 2.0),
                happened: format!(
                    "{:.0}",
                    data.phys_stat(n, |p| (p.ball_ball + p.ball_cushion) as f64)
                        .mean
                ),
            });
        Model {
            finer,
            fewer: fs
                .iter()
                .all(|f| f.model_ratio_best.is_none_or(|r| r > 1.05)),
            lines,
            scheduled,
        }
    }
}

/// One of tables 6 to 10 in the report.
#[derive(Serialize)]
struct Section {
    title: String,
    body: String,
}

/// The chapter 7 parameters of our gas of `balls` balls.
#[derive(Serialize)]
struct GasParams {
    balls: usize,
    vt: String,
    m: String,
}
