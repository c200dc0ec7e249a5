//! What the numbers say: the settings of each number of balls ranked, compared seed by seed,
//! and set beside the thesis' choices and the chapter 7 model.

use super::data::{Data, Stat};
use super::tables::setting_at;
use super::thesis;
use super::{settings, Setting};
use crate::analytic::{self, ModelParams};
use serde::Serialize;

/// A paired comparison of two settings over the seeds both ran: `a − b` in total messages.
#[derive(Clone, Copy, Debug, Serialize)]
pub(super) struct Paired {
    pub(super) a: Setting,
    pub(super) b: Setting,
    /// Mean of `a − b` over the seeds.
    pub(super) diff_mean: f64,
    /// Standard error of that mean (`None` for fewer than two seeds).
    pub(super) diff_se: Option<f64>,
    /// Seeds in which `a` sent fewer messages than `b`.
    pub(super) a_wins: usize,
    /// Seeds compared.
    pub(super) seeds: usize,
}

impl Paired {
    /// Whether the difference is within two standard errors of zero: no winner.
    pub(super) fn tie(&self) -> bool {
        self.diff_se
            .is_none_or(|se| self.diff_mean.abs() <= 2.0 * se)
    }
}

impl Data {
    /// Settings `a` and `b` compared seed by seed.
    pub(super) fn paired(&self, n: usize, a: Setting, b: Setting) -> Paired {
        let ra = self.cell(n, a);
        let rb = self.cell(n, b);
        let mut diffs = Vec::new();
        let mut a_wins = 0;
        for x in &ra {
            if let Some(y) = rb.iter().find(|y| y.seed == x.seed) {
                diffs.push(x.total() - y.total());
                if x.total() < y.total() {
                    a_wins += 1;
                }
            }
        }
        let st = Stat::of(&diffs);
        Paired {
            a,
            b,
            diff_mean: st.mean,
            diff_se: st.sd.map(|sd| sd / (st.n as f64).sqrt()),
            a_wins,
            seeds: st.n,
        }
    }
}

/// What the numbers say, per number of balls.
#[derive(Clone, Debug, Serialize)]
pub(super) struct Finding {
    pub(super) balls: usize,
    /// Every setting, fewest mean messages first.
    pub(super) ranked: Vec<(Setting, f64)>,
    /// Settings statistically tied with the best (paired, within two standard errors).
    pub(super) ties_best: Vec<Paired>,
    /// The sectored setting with the fewest mean messages.
    pub(super) best_sectored: Option<Setting>,
    /// Other sectored settings tied with it.
    pub(super) ties_sectored: Vec<Paired>,
    /// The best sectored setting against no sectors.
    pub(super) sectored_vs_none: Option<Paired>,
    /// Settings with more than 8 balls per sector against the best sectored one.
    pub(super) over_eight: Vec<Paired>,
    /// The chapter 7 parameters of our gas: `V T` in table widths and `m`.
    pub(super) model_vt: f64,
    pub(super) model_m: f64,
    /// Eq. 2's optimal sectors per side at those parameters, and its best grid of ours.
    pub(super) model_optimal_per_side: f64,
    pub(super) model_best_grid: Option<Setting>,
    /// Measured / eq. 2 at the best measured grid and at the finest grid.
    pub(super) model_ratio_best: Option<f64>,
    pub(super) model_ratio_finest: Option<f64>,
    /// The thesis' best setting and best sectored setting (table 5), if it ran this N.
    pub(super) thesis_best: Option<Setting>,
    pub(super) thesis_best_sectored: Option<Setting>,
}

impl Finding {
    pub(super) fn best(&self) -> Setting {
        self.ranked[0].0
    }

    pub(super) fn mean(&self, s: Setting) -> Option<f64> {
        self.ranked.iter().find(|r| r.0 == s).map(|r| r.1)
    }

    /// Whether `s` is the best sectored setting or tied with it.
    pub(super) fn among_best_sectored(&self, s: Setting) -> bool {
        self.best_sectored == Some(s) || self.ties_sectored.iter().any(|p| p.b == s)
    }
}

/// Mean balls per sector of a sectored setting for `n` balls.
pub(super) fn bps_of(n: usize, s: Setting) -> Option<f64> {
    s.per_side().map(|k| n as f64 / (k * k) as f64)
}

/// The findings for every number of balls of the plan.
pub(super) fn findings(data: &Data) -> Vec<Finding> {
    let mut out = Vec::new();
    for &n in &data.plan.balls {
        let mut ranked: Vec<(Setting, f64)> = settings(n)
            .into_iter()
            .filter_map(|s| data.total(n, s).map(|t| (s, t.mean)))
            .collect();
        ranked.sort_by(|a, b| a.1.total_cmp(&b.1));
        let best = ranked[0].0;
        let ties_best = ranked[1..]
            .iter()
            .map(|r| data.paired(n, best, r.0))
            .filter(Paired::tie)
            .collect();
        let bs = data.best_sectored(n).map(|b| b.0);
        let ties_sectored = match bs {
            Some(b) => ranked
                .iter()
                .filter(|r| r.0 != b && r.0 != Setting::NoSectors)
                .map(|r| data.paired(n, b, r.0))
                .filter(Paired::tie)
                .collect(),
            None => Vec::new(),
        };
        let over_eight = match bs {
            Some(b) => settings(n)
                .into_iter()
                .filter(|&s| bps_of(n, s).is_some_and(|x| x > 8.0) && s != b)
                .map(|s| data.paired(n, s, b))
                .collect(),
            None => Vec::new(),
        };
        let (vt, m) = data.model_params(n);
        let p = ModelParams {
            balls: n as f64,
            speed: vt,
            time: 1.0,
            changes: m,
        };
        let ok = p.validate().is_ok();
        let model_at = |s: Setting| {
            s.per_side()
                .filter(|_| ok)
                .map(|k| analytic::messages(&p, 1.0 / k as f64))
        };
        let model_best_grid = settings(n)
            .into_iter()
            .filter_map(|s| model_at(s).map(|f| (s, f)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|x| x.0);
        let ratio = |s: Setting| Some(data.total(n, s)?.mean / model_at(s)?);
        let finest = settings(n)
            .into_iter()
            .last()
            .filter(|s| s.per_side().is_some());
        let th = thesis::row(&thesis::TABLE5, n);
        let thesis_min = |from: usize| {
            (from..6)
                .filter_map(|c| th[c].value().map(|v| (c, v)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .and_then(|(c, _)| setting_at(n, c))
        };
        out.push(Finding {
            balls: n,
            ranked,
            ties_best,
            best_sectored: bs,
            ties_sectored,
            sectored_vs_none: bs.map(|b| data.paired(n, b, Setting::NoSectors)),
            over_eight,
            model_vt: vt,
            model_m: m,
            model_optimal_per_side: if ok {
                1.0 / analytic::optimal_sector(&p)
            } else {
                f64::NAN
            },
            model_best_grid,
            model_ratio_best: bs.and_then(ratio),
            model_ratio_finest: finest.and_then(ratio),
            thesis_best: thesis_min(0),
            thesis_best_sectored: thesis_min(1),
        });
    }
    out
}

/// Balls per sector as in the thesis: `9`, `1`, `1/4`; `-` if not sectored.
pub(super) fn bps_text(b: Option<f64>) -> String {
    match b {
        None => "-".into(),
        Some(b) if b < 1.0 => format!("1/{:.0}", 1.0 / b),
        Some(b) => format!("{b:.0}"),
    }
}

/// The label of a setting, `-` if none.
pub(super) fn opt_label(s: Option<Setting>) -> String {
    s.map_or("-".into(), Setting::label)
}

/// Whether a sequence only grows (`up`) or only falls.
pub(super) fn monotone(xs: &[f64], up: bool) -> bool {
    xs.windows(2)
        .all(|w| if up { w[1] > w[0] } else { w[1] < w[0] })
}
