//! Influence lines, traffic envelopes and combinations written out (`[[influence]]`):
//! `influence_<name>.csv` (position against each monitor's value per newton),
//! `envelopes_<name>.csv` (min/max of each traffic model with the governing axle
//! positions) and `combinations_<name>.csv`, each written whole or not at all, and their
//! summary.json entry.

use super::atomic::write_atomic;
use crate::analysis::influence::InfluenceLines;
use crate::model::Model;
use crate::traffic::{envelope, Extreme};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;

/// One `[[influence]]` table's results (summary.json `influence`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct InfluenceSummary {
    /// Table name.
    pub name: String,
    /// The step at whose end the lines were taken.
    pub after_step: String,
    /// Number of load positions (path nodes).
    pub positions: usize,
    /// Files written (none when `error` is set).
    pub files: Vec<String>,
    /// Why the lines could not be taken (then nothing else is given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// How each traffic model was reduced to the plane-stress girder.
    pub traffic: Vec<String>,
    /// Envelopes: per monitor and traffic model.
    pub envelopes: Vec<EnvelopeRow>,
    /// Combinations: per combination and monitor.
    pub combinations: Vec<CombinationRow>,
}

/// One extreme of a traffic model's effect on a monitor.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct ExtremeOut {
    /// Total [monitor unit].
    pub value: f64,
    /// The vehicles' part, factors included.
    pub vehicle: f64,
    /// The lane load's part (on the unfavourable stretches).
    pub lane: f64,
    /// The governing vehicle ("" when the traffic is absent).
    pub vehicle_name: String,
    /// x of its axles [m], first axle first (empty when absent): where to put the
    /// vehicle in a later step.
    pub axles_x: Vec<f64>,
}

/// The envelope of one monitor under one traffic model.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EnvelopeRow {
    /// Monitor name.
    pub monitor: String,
    /// Unit of the monitor.
    pub unit: String,
    /// Traffic model name.
    pub traffic: String,
    /// The monitor at the step's end (without traffic).
    pub state: f64,
    /// The smallest traffic effect (≤ 0).
    pub min: ExtremeOut,
    /// The largest traffic effect (≥ 0).
    pub max: ExtremeOut,
}

/// One combination of one monitor.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct CombinationRow {
    /// Combination name.
    pub combination: String,
    /// Monitor name.
    pub monitor: String,
    /// Unit of the monitor.
    pub unit: String,
    /// γ_state · state + γ_vehicle · min vehicle part + γ_lane · min lane part.
    pub min: f64,
    /// The same with the largest parts.
    pub max: f64,
}

/// Write the files of one table's lines (or record why there are none) into `dir`.
pub fn write(
    dir: &Path,
    model: &Model,
    lines: &Result<InfluenceLines, (usize, String)>,
) -> std::io::Result<InfluenceSummary> {
    let (table, l) = match lines {
        Ok(l) => (l.table, Some(l)),
        Err((t, _)) => (*t, None),
    };
    let inf = &model.influence[table];
    let mut out = InfluenceSummary {
        name: inf.name.clone(),
        after_step: model.steps[inf.after_step].name.clone(),
        positions: inf.path.len(),
        files: Vec::new(),
        error: None,
        traffic: inf.traffic.iter().map(|t| t.note.clone()).collect(),
        envelopes: Vec::new(),
        combinations: Vec::new(),
    };
    let Some(l) = l else {
        out.error = lines.as_ref().err().map(|e| e.1.clone());
        return Ok(out);
    };
    // Influence lines: position, point, then each line per newton.
    let mut csv = String::from("s [m],x [m],y [m]");
    for (name, unit) in &l.names {
        let _ = write!(csv, ",{name} [{unit}/N]");
    }
    csv.push('\n');
    for (i, &s) in l.s.iter().enumerate() {
        let p = inf.point_at(s);
        let _ = write!(csv, "{s:.6},{:.6},{:.6}", p[0], p[1]);
        for v in &l.values {
            let _ = write!(csv, ",{:.9e}", v[i]);
        }
        csv.push('\n');
    }
    let file = format!("influence_{}.csv", inf.name);
    write_atomic(&dir.join(&file), csv.as_bytes())?;
    out.files.push(file);
    if inf.traffic.is_empty() {
        return Ok(out);
    }
    let place = |e: Extreme| ExtremeOut {
        value: e.value,
        vehicle: e.vehicle,
        lane: e.lane,
        vehicle_name: e.vehicle_name,
        axles_x: e.axles.iter().map(|&s| inf.point_at(s)[0]).collect(),
    };
    for (k, line) in l.values.iter().enumerate() {
        for t in &inf.traffic {
            let (min, max) = envelope(t, &l.s, line);
            out.envelopes.push(EnvelopeRow {
                monitor: l.names[k].0.clone(),
                unit: l.names[k].1.clone(),
                traffic: t.name.clone(),
                state: l.state[k],
                min: place(min),
                max: place(max),
            });
        }
    }
    let mut csv = String::from(
        "monitor,unit,traffic,state,min,min_vehicle,min_lane,min_vehicle_name,min_axles_x [m],max,max_vehicle,max_lane,max_vehicle_name,max_axles_x [m]\n",
    );
    for e in &out.envelopes {
        let axles = |x: &[f64]| {
            x.iter()
                .map(|v| format!("{v:.4}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let _ = writeln!(
            csv,
            "{},{},{},{:.9e},{:.9e},{:.9e},{:.9e},{},{},{:.9e},{:.9e},{:.9e},{},{}",
            e.monitor,
            e.unit,
            e.traffic,
            e.state,
            e.min.value,
            e.min.vehicle,
            e.min.lane,
            e.min.vehicle_name,
            axles(&e.min.axles_x),
            e.max.value,
            e.max.vehicle,
            e.max.lane,
            e.max.vehicle_name,
            axles(&e.max.axles_x)
        );
    }
    let file = format!("envelopes_{}.csv", inf.name);
    write_atomic(&dir.join(&file), csv.as_bytes())?;
    out.files.push(file);
    if inf.combinations.is_empty() {
        return Ok(out);
    }
    let n_traffic = inf.traffic.len();
    for c in &inf.combinations {
        for k in 0..l.values.len() {
            let e = &out.envelopes[k * n_traffic + c.traffic];
            let at = |x: &ExtremeOut| c.state * e.state + c.vehicle * x.vehicle + c.lane * x.lane;
            out.combinations.push(CombinationRow {
                combination: c.name.clone(),
                monitor: e.monitor.clone(),
                unit: e.unit.clone(),
                min: at(&e.min),
                max: at(&e.max),
            });
        }
    }
    let mut csv = String::from("combination,monitor,unit,min,max\n");
    for c in &out.combinations {
        let _ = writeln!(
            csv,
            "{},{},{},{:.9e},{:.9e}",
            c.combination, c.monitor, c.unit, c.min, c.max
        );
    }
    let file = format!("combinations_{}.csv", inf.name);
    write_atomic(&dir.join(&file), csv.as_bytes())?;
    out.files.push(file);
    Ok(out)
}

/// One line per influence table and per envelope and combination, for the command's
/// report: the extremes with the governing vehicle and its axles' x.
pub fn headlines(tables: &[InfluenceSummary]) -> Vec<String> {
    let mut out = Vec::new();
    for t in tables {
        if let Some(e) = &t.error {
            out.push(format!(
                "influence '{}' after step '{}': not taken: {e}",
                t.name, t.after_step
            ));
            continue;
        }
        out.push(format!(
            "influence '{}' after step '{}': {} positions, {}",
            t.name,
            t.after_step,
            t.positions,
            t.files.join(", ")
        ));
        let at = |x: &ExtremeOut| {
            if x.axles_x.is_empty() {
                "no traffic".to_string()
            } else {
                format!(
                    "{} at x = {} m",
                    x.vehicle_name,
                    x.axles_x
                        .iter()
                        .map(|v| format!("{v:.3}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        };
        for e in &t.envelopes {
            out.push(format!(
                "  {} {}: max {:+.4e} {} ({}), min {:+.4e} {} ({})",
                e.traffic,
                e.monitor,
                e.max.value,
                e.unit,
                at(&e.max),
                e.min.value,
                e.unit,
                at(&e.min)
            ));
        }
        for c in &t.combinations {
            out.push(format!(
                "  {} {}: {:+.4e} to {:+.4e} {}",
                c.combination, c.monitor, c.min, c.max, c.unit
            ));
        }
    }
    out
}
