//! Tables 5 to 10 in Markdown: ours beside the thesis' numbers, each with its explanation.

use super::data::Data;
use super::thesis::{self, T};
use super::{column, settings, Setting, BPS_LABEL, C_ENTRIES, SIZE_LABEL, THESIS_ADJACENT};
use serde::Serialize;
use std::fmt::Write as _;

/// A Markdown table.
pub(super) fn md_table(header: &[String], rows: &[Vec<String>]) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "| {} |", header.join(" | "));
    let _ = writeln!(
        out,
        "|{}",
        header
            .iter()
            .enumerate()
            .map(|(i, _)| if i == 0 { "---|" } else { "---:|" })
            .collect::<String>()
    );
    for r in rows {
        let _ = writeln!(out, "| {} |", r.join(" | "));
    }
    out
}

/// Owned copies of some strings.
pub(super) fn strings(xs: &[&str]) -> Vec<String> {
    xs.iter().map(|s| s.to_string()).collect()
}

/// The setting of thesis column `c` (0 = none, 1..=5 balls per sector) for `n` balls, if run.
pub(super) fn setting_at(n: usize, c: usize) -> Option<Setting> {
    settings(n).into_iter().find(|&s| column(n, s) == c)
}

/// A table in the layout of thesis table 5 (rows: balls; columns: no sectors and sizes 200..25)
/// with our cell text and the thesis' value beside it.
fn size_layout(
    data: &Data,
    thesis_table: &[(usize, [T; 6])],
    ours: impl Fn(usize, Setting) -> Option<String>,
) -> String {
    let mut header = vec!["Balls".to_string(), "No sectors".to_string()];
    header.extend(
        SIZE_LABEL
            .iter()
            .zip(BPS_LABEL)
            .map(|(s, b)| format!("Size {s} ({b}/sector)")),
    );
    let mut rows = Vec::new();
    for &n in &data.plan.balls {
        let th = thesis::row(thesis_table, n);
        let mut row = vec![n.to_string()];
        for (c, t) in th.iter().enumerate() {
            let cell = match setting_at(n, c).and_then(|s| ours(n, s).map(|o| (s, o))) {
                Some((_, o)) if c == 0 => format!("{o} ({})", t.text()),
                Some((s, o)) => format!("{}: {o} ({})", s.label(), t.text()),
                None if *t == T::No => "-".into(),
                None => format!("- ({})", t.text()),
            };
            row.push(cell);
        }
        rows.push(row);
    }
    md_table(&header, &rows)
}

/// The thesis' table as printed, in the size layout.
fn thesis_size_table(table: &[(usize, [T; 6])]) -> String {
    let mut header = vec!["Balls".to_string(), "No sectors".to_string()];
    header.extend(SIZE_LABEL.iter().map(|s| s.to_string()));
    let rows: Vec<Vec<String>> = table
        .iter()
        .map(|(n, r)| {
            let mut row = vec![n.to_string()];
            row.extend(r.iter().map(|t| t.text()));
            row
        })
        .collect();
    md_table(&header, &rows)
}

/// Table 5: total messages per cell, ours (mean ± SD) beside the thesis' single runs.
pub(super) fn table5(data: &Data) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Table 5. Message count of pool ball simulations\n");
    let _ = writeln!(
        out,
        "Our runs: mean ± sample standard deviation over {} seeds of the total messages of the six \
         types the thesis counts (VelocityChange, NewVelocity, SectorDeparture, SectorEntry, Cancel, \
         Collision); in parentheses the thesis' single run (Goldberg 1984, table 5). Columns are \
         the thesis' sector sizes; each cell names the grid (sectors per side) that size means \
         for its number of balls: size S holds (S/50)² balls per sector. \"-\": not run; \
         \"mo\": the thesis' run overflowed the Dolphin's memory.\n",
        data.plan.seeds
    );
    out.push_str(&size_layout(data, &thesis::TABLE5, |n, s| {
        data.total(n, s).map(|t| t.pm())
    }));
    let _ = writeln!(out, "\nThe thesis' table 5 as printed:\n");
    out.push_str(&thesis_size_table(&thesis::TABLE5));
    out
}

/// Table 6: wall time and messages per second, ours beside the Dolphin's.
pub(super) fn table6(data: &Data) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Table 6. Elapsed time of pool ball simulations\n");
    let _ = writeln!(
        out,
        "Our wall time per run in milliseconds (for each seed the median of {} repetitions, then \
         the mean over {} seeds; one core, setup included), with the Dolphin's seconds from the \
         thesis' table 6 in parentheses.\n",
        data.plan.timing_repeats, data.plan.seeds
    );
    out.push_str(&size_layout(data, &thesis::TABLE6, |n, s| {
        data.stat(n, s, |r| r.wall_seconds * 1e3)
            .map(|t| format!("{:.2} ms", t.mean))
    }));
    let _ = writeln!(
        out,
        "\nMessages per second: ours (mean total messages / mean wall time), and in parentheses \
         the Dolphin's (thesis table 5 / table 6).\n"
    );
    let rate_thesis: Vec<(usize, [T; 6])> = thesis::TABLE5
        .iter()
        .zip(thesis::TABLE6.iter())
        .map(|((n, m), (_, t))| {
            let mut r = [T::No; 6];
            for c in 0..6 {
                r[c] = match (m[c], t[c]) {
                    (T::V(a), T::V(b)) => T::V((a / b * 100.0).round() / 100.0),
                    (x, _) => x,
                };
            }
            (*n, r)
        })
        .collect();
    out.push_str(&size_layout(data, &rate_thesis, |n, s| {
        let m = data.total(n, s)?;
        let w = data.stat(n, s, |r| r.wall_seconds)?;
        Some(format!("{:.2} M/s", m.mean / w.mean / 1e6))
    }));
    let _ = writeln!(out, "\nThe thesis' table 6 (seconds) as printed:\n");
    out.push_str(&thesis_size_table(&thesis::TABLE6));
    out
}

/// Table 7: the spread over seeds of messages and wall time.
pub(super) fn table7(data: &Data) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Table 7. Mean and standard deviation of message counts and elapsed time\n"
    );
    let _ = writeln!(
        out,
        "The non-sectored objects engine over {} seeds (the thesis ran six seeds for its \
         non-sectored cases). Ours: messages and wall milliseconds; thesis: messages and Dolphin \
         seconds.\n",
        data.plan.seeds
    );
    let header = strings(&[
        "Balls",
        "Messages mean",
        "SD",
        "Thesis mean",
        "Thesis SD",
        "Wall ms mean",
        "SD",
        "Thesis s mean",
        "Thesis SD",
    ]);
    let mut rows = Vec::new();
    for &n in &data.plan.balls {
        let m = data.total(n, Setting::NoSectors).unwrap_or_default();
        let w = data
            .stat(n, Setting::NoSectors, |r| r.wall_seconds * 1e3)
            .unwrap_or_default();
        let th = thesis::TABLE7.iter().find(|r| r.0 == n).map(|r| r.1);
        let f = |i: usize| th.map_or("-".to_string(), |t| format!("{}", t[i]));
        let sd = |s: Option<f64>, p: usize| s.map_or("-".to_string(), |x| format!("{x:.p$}"));
        rows.push(vec![
            n.to_string(),
            format!("{:.0}", m.mean),
            sd(m.sd, 0),
            f(0),
            f(1),
            format!("{:.3}", w.mean),
            sd(w.sd, 3),
            f(2),
            f(3),
        ]);
    }
    out.push_str(&md_table(&header, &rows));
    let _ = writeln!(
        out,
        "\nAll settings, messages (mean ± SD, coefficient of variation):\n"
    );
    let header = strings(&["Balls", "Sectors", "Messages", "CV"]);
    let mut rows = Vec::new();
    for &n in &data.plan.balls {
        for s in settings(n) {
            if let Some(t) = data.total(n, s) {
                rows.push(vec![
                    n.to_string(),
                    s.label(),
                    t.pm(),
                    t.sd.map_or("-".into(), |sd| format!("{:.1}%", 100.0 * sd / t.mean)),
                ]);
            }
        }
    }
    out.push_str(&md_table(&header, &rows));
    out
}

/// The thesis' order of message types in table 8, then ours not in the total.
const TYPES8: [&str; 6] = [
    "SectorDeparture",
    "SectorEntry",
    "VelocityChange",
    "Collision",
    "Cancel",
    "NewVelocity",
];

/// Table 8: messages by type for [`Data::focus`] balls.
pub(super) fn table8(data: &Data) -> String {
    let n = data.focus();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Table 8. Number of messages tabulated by message type\n"
    );
    let _ = writeln!(
        out,
        "{n} balls: our mean over {} seeds{}. VelocityInitialization (thesis 5.4) and \
         CollisionConfirm (ours, beyond the thesis) are shown but, like the thesis, not counted \
         in the total.\n",
        data.plan.seeds,
        if n == 36 {
            ", and in parentheses the thesis' 36-ball run (table 8; sizes 150, 100, 50 are 2×2, \
             3×3, 6×6 sectors)"
        } else {
            " (the thesis' table 8 is for 36 balls, which this run did not include)"
        }
    );
    let sets = settings(n);
    let mut header = vec!["Message type".to_string()];
    header.extend(sets.iter().map(|s| s.label()));
    // thesis table 8 columns: none, b = 9, 4, 1 (columns 0, 2, 3, 4 of table 5)
    let thesis_col = |s: Setting| -> Option<usize> {
        if n != 36 {
            return None;
        }
        match column(n, s) {
            0 => Some(0),
            2 => Some(1),
            3 => Some(2),
            4 => Some(3),
            _ => None,
        }
    };
    let mut rows = Vec::new();
    let mut names: Vec<&str> = TYPES8.to_vec();
    names.push("total");
    names.extend(["VelocityInitialization", "CollisionConfirm"]);
    for name in names {
        let mut row = vec![if name == "total" {
            "**Total**".to_string()
        } else {
            name.to_string()
        }];
        for &s in &sets {
            let ours = data.stat(n, s, |r| r.msg(name)).unwrap_or_default().mean;
            let th = thesis_col(s).map(|c| {
                if name == "total" {
                    thesis::row(&thesis::TABLE5, 36)[column(36, s)]
                } else {
                    thesis::TABLE8
                        .iter()
                        .find(|r| r.0 == name)
                        .map_or(T::No, |r| r.1[c])
                }
            });
            row.push(match th {
                Some(t) => format!("{ours:.0} ({})", t.text()),
                None => format!("{ours:.0}"),
            });
        }
        rows.push(row);
    }
    out.push_str(&md_table(&header, &rows));
    out
}

/// Mean number of sectors adjacent (by an edge or a corner) to a sector of a `k × k` grid.
pub(super) fn mean_adjacent(k: u32) -> f64 {
    if k < 2 {
        return 0.0;
    }
    let k = k as f64;
    (4.0 * 3.0 + 4.0 * (k - 2.0) * 5.0 + (k - 2.0) * (k - 2.0) * 8.0) / (k * k)
}

/// One column of the table 9 spreadsheet.
#[derive(Clone, Debug, Serialize)]
pub(super) struct Sheet {
    pub(super) sectors_per_side: u32,
    pub(super) sectors: u32,
    pub(super) sector_width: f64,
    pub(super) velocity_change: f64,
    pub(super) estimated_entries: f64,
    pub(super) scheduled_entries: f64,
    pub(super) fitted_c: f64,
    pub(super) sectors_occupied: f64,
    pub(super) estimated_balls_per_sector: f64,
    pub(super) estimated_new_velocity: f64,
    pub(super) mean_adjacent_sectors: f64,
    pub(super) estimated_new_velocity_our_adjacency: f64,
    pub(super) actual_new_velocity: f64,
}

/// The columns of the table 9 spreadsheet for `n` balls, one per sectored setting.
pub(super) fn spreadsheet(data: &Data, n: usize) -> Vec<Sheet> {
    let path = data.phys_stat(n, |p| p.free_path).mean;
    let changes = data.phys_stat(n, |p| p.velocity_changes as f64).mean;
    let side = data.phys_stat(n, |p| p.table_side).mean;
    let mut out = Vec::new();
    for s in settings(n) {
        let Setting::Grid(k) = s else { continue };
        let vc = data
            .stat(n, s, |r| r.msg("VelocityChange"))
            .unwrap_or_default()
            .mean;
        let entries = data
            .stat(n, s, |r| r.msg("SectorEntry"))
            .unwrap_or_default()
            .mean
            / 2.0;
        let nv = data
            .stat(n, s, |r| r.msg("NewVelocity"))
            .unwrap_or_default()
            .mean;
        let width = side / k as f64;
        let est_entries = C_ENTRIES * path / width;
        let occupied = if changes > 0.0 { vc / changes } else { 0.0 };
        let bps = occupied * n as f64 / (k * k) as f64;
        let adj = mean_adjacent(k);
        out.push(Sheet {
            sectors_per_side: k,
            sectors: k * k,
            sector_width: width,
            velocity_change: vc,
            estimated_entries: est_entries,
            scheduled_entries: entries,
            fitted_c: if path > 0.0 {
                entries * width / path
            } else {
                0.0
            },
            sectors_occupied: occupied,
            estimated_balls_per_sector: bps,
            estimated_new_velocity: (bps + THESIS_ADJACENT) * (vc + est_entries),
            mean_adjacent_sectors: adj,
            estimated_new_velocity_our_adjacency: (bps + adj) * (vc + est_entries),
            actual_new_velocity: nv,
        });
    }
    out
}

/// Table 9: the thesis' NewVelocity estimator (6.1) applied to our runs of [`Data::focus`] balls.
pub(super) fn table9(data: &Data) -> String {
    let n = data.focus();
    let sheets = spreadsheet(data, n);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# Table 9. Spreadsheet for estimating the number of NewVelocity messages\n"
    );
    out.push_str(&table9_method(data, n));
    out.push_str(&table9_parameters(data, n));
    let mut header = vec!["".to_string()];
    header.extend(
        sheets
            .iter()
            .map(|s| format!("{}×{}", s.sectors_per_side, s.sectors_per_side)),
    );
    let rows: Vec<Vec<String>> = TABLE9_ROWS
        .iter()
        .map(|row| table9_row(row, n, &sheets))
        .collect();
    out.push_str(&md_table(&header, &rows));
    let _ = writeln!(
        out,
        "\nThe thesis' sector sizes 150, 100, 50 are in units of its \"50 × balls per side\" \
         table (300 for 36 balls), while its free path and its 600×600 table are in the units \
         of our table; so its estimated entries, c · 7749 / 150 etc., use half the real sector \
         width, and equal ours with c = 6. We divide by the real width and keep c = 3."
    );
    out
}

/// Table 9's first paragraph: the estimator, step by step.
fn table9_method(data: &Data, n: usize) -> String {
    format!(
        "The thesis' estimator (6.1) applied to our {n}-ball runs (means over {} seeds){}:\n\n\
         - estimated sector entries = c · total free path / sector width, c = {C_ENTRIES};\n\
         - sectors occupied by a ball = VelocityChange / velocity changes;\n\
         - estimated balls per sector = sectors occupied · N / sectors;\n\
         - estimated NewVelocity = (estimated balls per sector + 4 adjacent objects) · \
         (VelocityChange + estimated sector entries).\n\n",
        data.plan.seeds,
        if n == 36 {
            ", beside the thesis' 36-ball values in parentheses"
        } else {
            " (the thesis' table 9 is for 36 balls, which this run did not include)"
        }
    )
}

/// Table 9's parameters, ours (mean ± SD over the seeds) beside the thesis'.
fn table9_parameters(data: &Data, n: usize) -> String {
    let path = data.phys_stat(n, |p| p.free_path);
    let bb = data.phys_stat(n, |p| p.ball_ball as f64);
    let cush = data.phys_stat(n, |p| p.ball_cushion as f64);
    let changes = data.phys_stat(n, |p| p.velocity_changes as f64);
    let side = data.phys_stat(n, |p| p.table_side).mean;
    let (tp, tc, tside) = thesis::TABLE9_PARAMS;
    format!(
        "Parameters (ours, mean ± SD over seeds; thesis in parentheses):\n\n\
         - number of balls = {n} (36)\n\
         - total free path = {} ({tp}), measured as Σ over balls of speed × time on the table \
         by an observer of the event-list engine (the same physical events as every objects run)\n\
         - number of collisions: {} ball–ball collisions and {} cushion bounces, so {} ball \
         velocity changes (thesis: {tc} \"collisions\"; we read them as velocity changes, the \
         only reading under which VelocityChange / collisions is the number of sectors a ball \
         occupies)\n\
         - table dimensions = {side}×{side} ({tside}×{tside})\n\n",
        path.pm(),
        bb.pm(),
        cush.pm(),
        changes.pm(),
    )
}

/// What a row of table 9 puts in parentheses beside our value, for 36 balls.
#[derive(Clone, Copy)]
enum Beside {
    /// Nothing: the thesis has no such row.
    Nothing,
    /// The thesis' value in this column of [`thesis::TABLE9`].
    Column(usize),
    /// The thesis' estimated over actual NewVelocity.
    Ratio,
    /// The thesis' sector size.
    Size,
}

/// A row of table 9: its label, our value of a column, and what goes beside it.
type Table9Row = (&'static str, fn(&Sheet) -> String, Beside);

/// The rows of table 9, in order.
const TABLE9_ROWS: [Table9Row; 13] = [
    (
        "Number of sectors",
        |s| s.sectors.to_string(),
        Beside::Nothing,
    ),
    (
        "Sector width (ours; thesis label)",
        |s| format!("{:.0}", s.sector_width),
        Beside::Size,
    ),
    (
        "VelocityChange",
        |s| format!("{:.0}", s.velocity_change),
        Beside::Column(0),
    ),
    (
        "Estimated sector entries",
        |s| format!("{:.0}", s.estimated_entries),
        Beside::Column(1),
    ),
    (
        "Scheduled sector entries (SectorEntry / 2)",
        |s| format!("{:.0}", s.scheduled_entries),
        Beside::Nothing,
    ),
    (
        "c that fits our entries",
        |s| {
            if s.sectors_per_side > 1 {
                format!("{:.2}", s.fitted_c)
            } else {
                "-".into()
            }
        },
        Beside::Nothing,
    ),
    (
        "Sectors occupied by a ball",
        |s| format!("{:.2}", s.sectors_occupied),
        Beside::Column(2),
    ),
    (
        "Estimated balls per sector",
        |s| format!("{:.1}", s.estimated_balls_per_sector),
        Beside::Column(3),
    ),
    (
        "Estimated NewVelocity messages",
        |s| format!("{:.0}", s.estimated_new_velocity),
        Beside::Column(4),
    ),
    (
        "Actual NewVelocity messages",
        |s| format!("{:.0}", s.actual_new_velocity),
        Beside::Column(5),
    ),
    (
        "Estimate / actual",
        |s| format!("{:.2}", s.estimated_new_velocity / s.actual_new_velocity),
        Beside::Ratio,
    ),
    (
        "Mean adjacent sectors (ours: edges and corners)",
        |s| format!("{:.2}", s.mean_adjacent_sectors),
        Beside::Nothing,
    ),
    (
        "Estimated NewVelocity with our adjacency",
        |s| format!("{:.0}", s.estimated_new_velocity_our_adjacency),
        Beside::Nothing,
    ),
];

/// The column of [`thesis::TABLE9`] for a `k × k` grid of 36 balls (4, 9, 36 sectors), if any.
pub(super) fn thesis9_column(k: u32) -> Option<usize> {
    match k {
        2 => Some(0),
        3 => Some(1),
        6 => Some(2),
        _ => None,
    }
}

/// One row of table 9: the label, then for each grid our value with the thesis' beside it.
fn table9_row((label, ours, beside): &Table9Row, n: usize, sheets: &[Sheet]) -> Vec<String> {
    let mut row = vec![label.to_string()];
    for s in sheets {
        let ours = ours(s);
        let th = if n == 36 {
            thesis9_column(s.sectors_per_side)
        } else {
            None
        };
        row.push(match (th, *beside) {
            (Some(c), Beside::Column(t)) => format!("{ours} ({})", thesis::TABLE9[c][t]),
            (Some(c), Beside::Ratio) => format!(
                "{ours} ({:.2})",
                thesis::TABLE9[c][4] / thesis::TABLE9[c][5]
            ),
            (Some(c), Beside::Size) => format!("{ours} ({})", SIZE_LABEL[c + 1]),
            _ => ours,
        });
    }
    row
}

/// Table 10: total messages by balls per sector.
pub(super) fn table10(data: &Data) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Table 10. Message count by balls per sector\n");
    let _ = writeln!(
        out,
        "Table 5 regrouped by the mean number of balls per sector, N / k²: our mean ± SD over \
         {} seeds, and the thesis' table 10 in parentheses (the thesis prints 5368 here for the \
         16-ball, 4-per-sector run it lists as 5366 in table 5).\n",
        data.plan.seeds
    );
    let mut header = vec!["Balls".to_string()];
    header.extend(BPS_LABEL.iter().map(|s| s.to_string()));
    let mut rows = Vec::new();
    for &n in &data.plan.balls {
        let th = thesis::row(&thesis::TABLE10, n);
        let mut row = vec![n.to_string()];
        for (c, t) in th.iter().enumerate() {
            row.push(
                match setting_at(n, c + 1).and_then(|s| data.total(n, s).map(|x| (s, x))) {
                    Some((s, x)) => format!("{}: {} ({})", s.label(), x.pm(), t.text()),
                    None if *t == T::No => "-".into(),
                    None => format!("- ({})", t.text()),
                },
            );
        }
        rows.push(row);
    }
    out.push_str(&md_table(&header, &rows));
    out
}
