//! `results.json`: every run, the statistics of every cell, the findings and the thesis' tables.

use super::data::Data;
use super::findings::Finding;
use super::tables::spreadsheet;
use super::thesis::{self, T};
use super::{column, settings, BPS_LABEL, RADIUS, SIZE_LABEL, SPEED_MAX};
use serde_json::{json, Value};

/// The raw numbers and the thesis' tables, for `results.json`.
pub(super) fn results_json(data: &Data, fs: &[Finding]) -> Value {
    let n = data.focus();
    json!({
        "experiment": "thesis",
        "source": "Goldberg 1984, Object-Oriented Simulation of Pool Ball Motion, ch. 6-7",
        "plan": data.plan,
        "scenario": {
            "name": "gas",
            "radius": RADIUS,
            "speed_max": SPEED_MAX,
            "table_side": "100 * sqrt(balls)",
            "until": data.plan.until,
        },
        "columns": {
            "balls_per_sector": BPS_LABEL,
            "thesis_sector_size": SIZE_LABEL,
        },
        "wall_seconds_total": data.wall_total,
        "digests_agree": data.mismatches.is_empty(),
        "digest_mismatches": data.mismatches,
        "runs": data.runs,
        "physics": data.physics,
        "aggregates": aggregates(data),
        "table9": { "balls": n, "columns": spreadsheet(data, n) },
        "findings": fs,
        "thesis": thesis_json(),
    })
}

/// Per number of balls and setting: the statistics over the seeds of each message type and of
/// the wall time.
fn aggregates(data: &Data) -> Vec<Value> {
    let mut aggregates = Vec::new();
    for &n in &data.plan.balls {
        for s in settings(n) {
            let mut by_type = serde_json::Map::new();
            let mut names: Vec<String> = data
                .cell(n, s)
                .first()
                .map(|r| r.messages.keys().cloned().collect())
                .unwrap_or_default();
            names.sort();
            for name in names {
                let st = data.stat(n, s, |r| r.msg(&name));
                by_type.insert(name, json!(st));
            }
            aggregates.push(json!({
                "balls": n,
                "setting": s.name(),
                "sectors_per_side": s.per_side(),
                "balls_per_sector": s.per_side().map(|k| n as f64 / (k * k) as f64),
                "thesis_size": (column(n, s) > 0).then(|| SIZE_LABEL[column(n, s) - 1]),
                "messages": by_type,
                "wall_seconds": data.stat(n, s, |r| r.wall_seconds),
            }));
        }
    }
    aggregates
}

/// The thesis' tables 5 to 10 as printed ("mo" a string, "-" null).
fn thesis_json() -> Value {
    let cells = |r: &[T]| -> Vec<Value> { r.iter().map(|c| c.json()).collect() };
    let by_balls = |t: &[(usize, Vec<Value>)]| -> Value {
        t.iter()
            .map(|(n, r)| json!({ "balls": n, "cells": r }))
            .collect()
    };
    let t5: Vec<(usize, Vec<Value>)> = thesis::TABLE5.iter().map(|(n, r)| (*n, cells(r))).collect();
    let t6: Vec<(usize, Vec<Value>)> = thesis::TABLE6.iter().map(|(n, r)| (*n, cells(r))).collect();
    let t10: Vec<(usize, Vec<Value>)> = thesis::TABLE10
        .iter()
        .map(|(n, r)| (*n, cells(r)))
        .collect();
    let t7: Vec<Value> = thesis::TABLE7
        .iter()
        .map(|(n, r)| {
            json!({
                "balls": n,
                "messages_mean": r[0],
                "messages_sd": r[1],
                "seconds_mean": r[2],
                "seconds_sd": r[3],
            })
        })
        .collect();
    let t8: Vec<Value> = thesis::TABLE8
        .iter()
        .map(|(t, r)| json!({ "type": t, "cells": cells(r) }))
        .collect();
    let (free_path, collisions, table_side) = thesis::TABLE9_PARAMS;
    json!({
        "table5": by_balls(&t5),
        "table6": by_balls(&t6),
        "table7": t7,
        "table8": t8,
        "table9": thesis::TABLE9,
        "table9_params": {
            "free_path": free_path,
            "collisions": collisions,
            "table_side": table_side,
        },
        "table10": by_balls(&t10),
    })
}
