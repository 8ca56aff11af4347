//! Results per construction stage (docs/input.md, "Output files"): for each step of a staged
//! model, the parts it places and removes, the rows of history.csv it produced and the
//! largest joint opening reached during it and the one-way supports that lifted off or
//! touched down, written as `stages.csv` and listed in summary.json. A joint that opens in a stage before the last one opened during
//! construction.

use super::joints::summarise;
use super::recorder::Row;
use crate::analysis::system::System;
use crate::model::Model;

/// One construction stage (one step of a staged model), as reported.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StageResult {
    /// Step number (1-based, as in history.csv).
    pub step: usize,
    /// Step name.
    pub name: String,
    /// Regions and supports placed at the start of the step (in the first step: those that
    /// are removed later; parts that act throughout are not listed).
    pub activated: Vec<String>,
    /// Regions and supports removed at the start of the step.
    pub removed: Vec<String>,
    /// First and last data row of the step in history.csv (1-based, the header not
    /// counted); None when the step produced no converged increment.
    pub history_rows: Option<(usize, usize)>,
    /// Largest opening of an open joint point during the step [m] (0 when none opens).
    pub max_joint_opening: f64,
    /// Name of the joint that reached it (None when none opens).
    pub joint: Option<String>,
    /// One-way supports that lifted off or touched down during the step
    /// ([`support_events`]).
    #[serde(default)]
    pub support_events: Vec<String>,
}

/// Largest opening [m] among the open (not in contact) points of all acting joints of the
/// committed state, with the joint's index; (0, None) when no point is open. A joint whose
/// segments are not both placed yet does not act (its "opening" is round-off).
pub fn largest_opening(sys: &System) -> (f64, Option<usize>) {
    let mut best = (0.0, None);
    let acts = |j: usize| {
        sys.stages.as_ref().is_none_or(|st| {
            sys.model.joints[j]
                .interfaces
                .iter()
                .all(|&i| st.interface_active.get(i).copied().unwrap_or(true))
        })
    };
    for j in (0..sys.model.joints.len()).filter(|&j| acts(j)) {
        for p in summarise(sys, j).profile {
            if !p.closed && p.opening > best.0 {
                best = (p.opening, Some(j));
            }
        }
    }
    best
}

/// Names of the regions and supports whose lifetime satisfies `pick`.
fn parts(model: &Model, pick: impl Fn(crate::model::Lifetime) -> bool) -> Vec<String> {
    let st = &model.staging;
    let regions = model
        .regions
        .iter()
        .enumerate()
        .filter(|(r, _)| pick(st.region(*r)))
        .map(|(_, r)| r.name.clone());
    let supports = model
        .supports
        .iter()
        .enumerate()
        .filter(|(s, _)| pick(st.support(*s)))
        .map(|(_, s)| s.name.clone());
    regions.chain(supports).collect()
}

/// The stages of a staged model from its history rows and, per row, the largest joint
/// opening [m] with its joint ([`largest_opening`]); empty for a model without stages.
pub fn stage_results(
    model: &Model,
    rows: &[Row],
    openings: &[(f64, Option<usize>)],
    lifted: &[Vec<(usize, usize)>],
) -> Vec<StageResult> {
    let mut events = support_events(model, rows, lifted);
    use crate::model::Lifetime;
    if !model.staging.is_staged() {
        return Vec::new();
    }
    model
        .steps
        .iter()
        .enumerate()
        .map(|(i, step)| {
            let mine: Vec<usize> = rows
                .iter()
                .enumerate()
                .filter(|(_, r)| r.step == i)
                .map(|(k, _)| k)
                .collect();
            let history_rows = match (mine.first(), mine.last()) {
                (Some(a), Some(b)) => Some((a + 1, b + 1)),
                _ => None,
            };
            let (max_joint_opening, joint) = mine
                .iter()
                .filter_map(|&k| openings.get(k).and_then(|&(o, j)| j.map(|j| (o, j))))
                .fold(
                    (0.0, None),
                    |best, (o, j)| {
                        if o > best.0 {
                            (o, Some(j))
                        } else {
                            best
                        }
                    },
                );
            StageResult {
                step: i + 1,
                name: step.name.clone(),
                activated: parts(model, |l| l.from == i && l != Lifetime::ALWAYS),
                removed: parts(model, |l| l.until == Some(i)),
                history_rows,
                max_joint_opening,
                joint: joint.map(|j: usize| model.joints[j].name.clone()),
                support_events: events
                    .iter_mut()
                    .filter(|(step, _)| *step == i)
                    .map(|(_, e)| std::mem::take(e))
                    .collect(),
            }
        })
        .collect()
}

/// The lift-offs and touch-downs of the one-way supports, step by step, from the
/// (points lifted off, points acting) of every support at each history row (`lifted`,
/// parallel to `rows`; empty without one-way supports): (step index, text), the text naming
/// the support and the history rows (1-based, as in history.csv). A support whose points
/// all lift off "lifts off", one whose points all come back "touches down"; a line support
/// of which only some points lift off says how many.
pub fn support_events(
    model: &Model,
    rows: &[Row],
    lifted: &[Vec<(usize, usize)>],
) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    if lifted.len() != rows.len() {
        return out;
    }
    let none = vec![(0, 0); model.supports.len()];
    for i in 0..model.steps.len() {
        let mine: Vec<usize> = (0..rows.len()).filter(|&k| rows[k].step == i).collect();
        let Some(&first) = mine.first() else { continue };
        let before = if first == 0 {
            &none
        } else {
            &lifted[first - 1]
        };
        for (s, sp) in model.supports.iter().enumerate() {
            let state = |k: usize| lifted[k].get(s).copied().unwrap_or((0, 0));
            let start = before.get(s).copied().unwrap_or((0, 0));
            // Rows of this step where the support's count of lifted points changed while it
            // acted (a support removed, or not placed yet, has no points acting: it neither
            // lifts off nor touches down).
            let mut prev = start.0;
            let mut changed = Vec::new();
            for &k in &mine {
                let (off, acting) = state(k);
                if acting > 0 && off != prev {
                    changed.push(k + 1);
                }
                if acting > 0 {
                    prev = off;
                }
            }
            let (Some(&a), Some(&b)) = (changed.first(), changed.last()) else {
                continue;
            };
            let (end, points) = state(*mine.last().expect("not empty"));
            if points == 0 {
                continue;
            }
            let name = &sp.name;
            let text = if start.0 == 0 && end == points {
                format!("{name} lifts off (history row {a})")
            } else if end == 0 && start.0 > 0 {
                format!("{name} touches down (history row {b})")
            } else if end == start.0 {
                format!("{name}: points lift off and touch down again (history rows {a}–{b})")
            } else {
                format!(
                    "{name}: {end} of {points} points lifted off at the step's end, {} at its start (history rows {a}–{b})",
                    start.0
                )
            };
            out.push((i, text));
        }
    }
    out
}

/// A CSV field, quoted when it holds a comma, a quote or a line break (RFC 4180).
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// The text of stages.csv: a header with units, then one line per stage. Lists of parts
/// are separated by `;`; an empty row range (a step that did not run) leaves its cells
/// blank.
pub fn render_csv(stages: &[StageResult]) -> String {
    let mut s = String::from(
        "step,name,activated,removed,first_row,last_row,max_joint_opening [m],joint,support_events\n",
    );
    for st in stages {
        let (a, b) = st
            .history_rows
            .map_or((String::new(), String::new()), |(a, b)| {
                (a.to_string(), b.to_string())
            });
        s.push_str(&format!(
            "{},{},{},{},{a},{b},{:e},{},{}\n",
            st.step,
            field(&st.name),
            field(&st.activated.join(";")),
            field(&st.removed.join(";")),
            st.max_joint_opening,
            field(st.joint.as_deref().unwrap_or("")),
            field(&st.support_events.join(";")),
        ));
    }
    s
}

/// Smallest joint opening reported as one [m]: 0.01 mm. Creep, shrinkage and round-off
/// part a closed joint by micrometres (the viaduct's 1.5 µm), which no designer acts on.
pub const OPENING_THRESHOLD: f64 = 1e-5;

/// Number of construction stages: up to the last stage that places or removes a part; the
/// stages after it (creep of the finished structure, temperature, traffic) are service.
pub fn construction_stages(stages: &[StageResult]) -> usize {
    stages
        .iter()
        .rposition(|s| !s.activated.is_empty() || !s.removed.is_empty())
        .map_or(0, |i| i + 1)
}

/// The construction stages ([`construction_stages`]) in which a joint opened by more than
/// [`OPENING_THRESHOLD`] (construction openings).
pub fn construction_openings(stages: &[StageResult]) -> impl Iterator<Item = &StageResult> {
    stages
        .iter()
        .take(construction_stages(stages))
        .filter(|s| s.max_joint_opening > OPENING_THRESHOLD && s.joint.is_some())
}

/// A file-name-safe form of a step name: letters, digits, `-` and `_` kept, any other run
/// of characters made one `-`, trimmed of `-` at both ends (empty if nothing is left).
pub fn file_slug(name: &str) -> String {
    let mut s = String::new();
    for c in name.chars() {
        if c.is_ascii_alphanumeric() || c == '_' {
            s.push(c);
        } else if !s.ends_with('-') {
            s.push('-');
        }
    }
    s.trim_matches('-').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slugs_are_file_safe() {
        assert_eq!(file_slug("strike falsework"), "strike-falsework");
        assert_eq!(file_slug(" span 1 / pier (temp) "), "span-1-pier-temp");
        assert_eq!(file_slug("äö"), "");
    }

    /// Construction ends with the last stage that places or removes a part: an opening in a
    /// later stage (traffic) is not a construction opening, nor one of a few micrometres.
    #[test]
    fn construction_openings_are_those_of_construction_stages_above_the_threshold() {
        let stage = |step: usize, placed: &[&str], removed: &[&str], opening: f64| StageResult {
            step,
            name: format!("s{step}"),
            activated: placed.iter().map(|s| s.to_string()).collect(),
            removed: removed.iter().map(|s| s.to_string()).collect(),
            history_rows: Some((step, step)),
            max_joint_opening: opening,
            joint: (opening > 0.0).then(|| "J4".to_string()),
            support_events: Vec::new(),
        };
        let stages = [
            stage(1, &["span1"], &[], 2e-5),
            stage(2, &[], &["falsework"], 1.5e-6),
            stage(3, &[], &[], 3e-5),
            stage(4, &["span2"], &[], 0.0),
            stage(5, &[], &[], 1.5e-6),
            stage(6, &[], &[], 2e-3),
        ];
        assert_eq!(construction_stages(&stages), 4);
        let steps: Vec<usize> = construction_openings(&stages).map(|s| s.step).collect();
        assert_eq!(steps, [1, 3]);
    }

    #[test]
    fn csv_fields_with_commas_are_quoted() {
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"x\""), "\"say \"\"x\"\"\"");
        assert_eq!(field("plain"), "plain");
    }
}
