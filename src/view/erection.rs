//! The erection figure of a staged run: the deflection of the deck (the top of the placed
//! segments) along the girder at the end of the stages that place or remove parts (at most
//! eight, evenly picked, the last always) — the cantilevers growing and deflecting, the
//! closures, the release onto the bearings (docs/theory-stages.md).

use super::data::{read_pvd, Grid};
use super::figures::{save, CurveFigure, Series};
use super::{displacements, units, ViewError};
use crate::results::stages::StageResult;
use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

/// Most stage curves drawn (evenly picked among the stages that place or remove parts,
/// the first and the last included).
const MAX_CURVES: usize = 8;

/// The erection figure of the run in `dir`, written to `out` as `erection`; nothing for a
/// run without stages that place parts.
pub fn erection_figure(dir: &Path, out: &Path) -> Result<Vec<PathBuf>, ViewError> {
    let Some(stages) = read_stages(dir) else {
        return Ok(Vec::new());
    };
    let regions = units::region_names(dir);
    let placing: Vec<&StageResult> = stages
        .iter()
        .filter(|s| s.history_rows.is_some())
        .filter(|s| !(s.activated.is_empty() && s.removed.is_empty()))
        .collect();
    if placing.len() < 2 {
        return Ok(Vec::new());
    }
    let mut chosen: Vec<&StageResult> = (0..MAX_CURVES.min(placing.len()))
        .map(|k| placing[k * (placing.len() - 1) / (MAX_CURVES.min(placing.len()) - 1).max(1)])
        .collect();
    chosen.dedup_by_key(|s| s.step);
    // Steps with `output = "none"` leave no fields to draw (the plot notes the skip).
    if !dir.join("results.pvd").is_file() {
        return Ok(Vec::new());
    }
    let outputs = read_pvd(dir)?;
    let mut series = Vec::new();
    for s in chosen {
        let (_, row) = s.history_rows.expect("filtered");
        let Some(o) = outputs.iter().find(|o| o.time as usize == row) else {
            continue;
        };
        let grid = o.grid()?;
        let active = active_regions(&stages, &regions, s.step);
        series.push(Series {
            label: format!("{} {}", s.step, s.name),
            points: deck(&grid, &active),
            panel: 0,
        });
    }
    if series.is_empty() {
        return Ok(Vec::new());
    }
    let fig = CurveFigure {
        title: "Erection: deck deflection since each segment was placed, end of the stages".into(),
        x_label: "x [m]".into(),
        y_label: "deflection [mm]".into(),
        y_labels: vec!["deflection [mm]".into()],
        series,
        reference: None,
    };
    save(&fig, out, "erection")
}

/// summary.json `stages`, if any.
fn read_stages(dir: &Path) -> Option<Vec<StageResult>> {
    let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    let stages: Vec<StageResult> = serde_json::from_value(v["stages"].clone()).ok()?;
    (!stages.is_empty()).then_some(stages)
}

/// Region indices active at the end of step `step`: placed in an earlier stage (or never
/// placed by a later one: they act from the start) and not removed since.
pub fn active_regions(stages: &[StageResult], regions: &[String], step: usize) -> HashSet<usize> {
    let placed_later: HashSet<&str> = stages
        .iter()
        .filter(|s| s.step > 1)
        .flat_map(|s| s.activated.iter().map(String::as_str))
        .collect();
    let mut active: HashSet<usize> = (0..regions.len())
        .filter(|&r| !placed_later.contains(regions[r].as_str()))
        .collect();
    for s in stages.iter().filter(|s| s.step <= step) {
        for (r, name) in regions.iter().enumerate() {
            if s.step > 1 && s.activated.contains(name) {
                active.insert(r);
            }
            if s.removed.contains(name) {
                active.remove(&r);
            }
        }
    }
    active
}

/// The vertical displacement [mm] of the highest node of the active cells at each node
/// column, NaN (one, breaking the line) over columns where nothing is placed yet.
fn deck(g: &Grid, active: &HashSet<usize>) -> Vec<(f64, f64)> {
    let region = g.cell_data.iter().find(|a| a.name == "region");
    let disp = displacements(g);
    let size = g
        .points
        .iter()
        .fold(0.0_f64, |m, p| m.max(p[0].abs()).max(p[1].abs()))
        .max(1.0);
    // Nodes of one column share their x to round-off: key x at 1e-9 of the model.
    let key = |x: f64| (x / (1e-9 * size)).round() as i64;
    // Per node column: its x and the highest active node (None: nothing placed there).
    let mut top: BTreeMap<i64, (f64, Option<(f64, usize)>)> = BTreeMap::new();
    for (c, cell) in g.cells.iter().enumerate() {
        let Some(r) = region.map(|a| a.get(c, 0) as usize) else {
            continue;
        };
        if !matches!(g.types[c], 9 | 23 | 28 | 5 | 22) {
            continue;
        }
        for &n in cell {
            let p = g.points[n];
            let e = top.entry(key(p[0])).or_insert((p[0], None));
            if active.contains(&r) && e.1.is_none_or(|(y, _)| p[1] > y) {
                e.1 = Some((p[1], n));
            }
        }
    }
    let mut points: Vec<(f64, f64)> = Vec::new();
    for &(x, hit) in top.values() {
        let y = hit.map_or(f64::NAN, |(_, n)| disp[n][1] * 1e3);
        // One break between placed parts is enough.
        if y.is_nan() && points.last().is_some_and(|p| p.1.is_nan()) {
            continue;
        }
        points.push((x, y));
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stage(step: usize, activated: &[&str], removed: &[&str]) -> StageResult {
        StageResult {
            step,
            name: format!("s{step}"),
            activated: activated.iter().map(|s| s.to_string()).collect(),
            removed: removed.iter().map(|s| s.to_string()).collect(),
            history_rows: Some((step, step)),
            max_joint_opening: 0.0,
            joint: None,
            support_events: Vec::new(),
        }
    }

    /// A region acts from the start unless a later stage places it, from its stage on, and
    /// not after its removal; supports in the lists are ignored.
    #[test]
    fn regions_act_from_their_stage_until_removed() {
        let regions: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
        let stages = [
            stage(1, &["prop"], &[]),
            stage(2, &["b"], &[]),
            stage(3, &["c"], &["a", "prop"]),
        ];
        let at = |k| {
            let mut v: Vec<usize> = active_regions(&stages, &regions, k).into_iter().collect();
            v.sort();
            v
        };
        assert_eq!(at(1), vec![0]);
        assert_eq!(at(2), vec![0, 1]);
        assert_eq!(at(3), vec![1, 2]);
    }
}
