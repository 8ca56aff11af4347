//! Design checks of a run (`[[checks]]`, docs/theory-design.md): each reads the committed
//! state at the end of its step (an unbonded-tendon check: at the step's peak load) and
//! gives a utilisation and a verdict for summary.json (`design_checks`) and the report.

use crate::analysis::steps::Snapshot;
use crate::analysis::system::System;
use crate::design::formulas::{self, EN_UNBONDED_INCREASE};
use crate::design::joint_section::{ContactPoint, JointSection, Piece};
use crate::model::checks::{CheckKind, Code, DesignCheck};
use crate::model::Model;
use crate::results::fields::principal;
use crate::results::strength::element_place;
use serde::Serialize;

/// The verdict of a check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// Utilisation at most 1.
    Pass,
    /// Utilisation above 1.
    Fail,
    /// A comparison with no pass or fail (the analysis beside a code estimate).
    Info,
    /// The check's step did not end in this run.
    NotEvaluated,
}

/// One checked item (a joint, a tendon, a region).
#[derive(Debug, Clone, Serialize)]
pub struct CheckItem {
    /// What: "joint J4", "tendon T1", "region 'webs'".
    pub item: String,
    /// The demand, in `unit`.
    pub demand: f64,
    /// The limit or capacity, in `unit`.
    pub limit: f64,
    /// Demand over limit (for a minimum compression: the moment over the decompression
    /// moment); may be infinite (JSON null).
    pub utilisation: f64,
    /// Where in the item, when it matters ("element 97 (…)").
    #[serde(skip_serializing_if = "String::is_empty")]
    pub at: String,
}

/// One check's result, as summary.json `design_checks` lists it.
#[derive(Debug, Clone, Serialize)]
pub struct CheckResult {
    /// The check's name.
    pub name: String,
    /// Its kind (`joint_decompression`, …).
    pub check: String,
    /// The code.
    pub code: Code,
    /// The clause of the limit.
    pub clause: String,
    /// The step whose state was checked.
    pub step: String,
    /// The verdict.
    pub verdict: Verdict,
    /// The governing (largest) utilisation; None if not evaluated.
    pub utilisation: Option<f64>,
    /// The governing item.
    pub governing: String,
    /// Unit of `demand` and `limit` of the items ("MPa", "kN").
    pub unit: String,
    /// What the demand and the limit are.
    pub quantity: String,
    /// Every item checked.
    pub items: Vec<CheckItem>,
    /// A line for the report and the terminal.
    pub text: String,
}

/// Collects check results over the run.
#[derive(Debug, Default)]
pub struct DesignWatch {
    done: Vec<Option<CheckResult>>,
    /// Per check: the tendon stress at the end of its `fpe_step` (f_pe) [Pa].
    fpe: Vec<Option<f64>>,
    /// Per check: (load measure, tendon stress) at the step's peak so far.
    peak: Vec<Option<(f64, f64)>>,
}

/// The largest span stress of tendon `t` [Pa] (0 before it is stressed).
fn tendon_stress(sys: &System, t: usize) -> f64 {
    sys.tendon_state(t)
        .map(|st| st.stresses().into_iter().fold(f64::NEG_INFINITY, f64::max))
        .unwrap_or(0.0)
}

impl DesignWatch {
    /// A watch for `model`'s checks.
    pub fn new(model: &Model) -> Self {
        let n = model.checks.len();
        DesignWatch {
            done: vec![None; n],
            fpe: vec![None; n],
            peak: vec![None; n],
        }
    }

    /// Read a converged increment.
    pub fn increment(&mut self, snap: &Snapshot) {
        let sys = snap.system;
        let model = sys.model;
        if model.checks.is_empty() {
            return;
        }
        let load = snap
            .arc_length_factor
            .or(snap.control_force)
            .unwrap_or_else(|| snap.factors.iter().sum());
        for (k, c) in model.checks.iter().enumerate() {
            if let CheckKind::UnbondedUltimate {
                tendon, fpe_step, ..
            } = c.kind
            {
                if snap.step == fpe_step && snap.end_of_step {
                    self.fpe[k] = Some(tendon_stress(sys, tendon));
                }
            }
            if c.step != snap.step {
                continue;
            }
            if let CheckKind::UnbondedUltimate { tendon, .. } = c.kind {
                let s = tendon_stress(sys, tendon);
                if self.peak[k].is_none_or(|(l, _)| load > l) {
                    self.peak[k] = Some((load, s));
                }
            }
            if snap.end_of_step {
                self.done[k] = Some(evaluate(sys, c, self.fpe[k], self.peak[k]));
            }
        }
    }

    /// Every check's result, in model order (a check whose step did not end: not evaluated).
    pub fn results(&self, model: &Model) -> Vec<CheckResult> {
        model
            .checks
            .iter()
            .zip(&self.done)
            .map(|(c, r)| {
                r.clone().unwrap_or_else(|| {
                    let step = &model.steps[c.step].name;
                    CheckResult {
                        name: c.name.clone(),
                        check: kind_name(&c.kind).into(),
                        code: c.code,
                        clause: c.clause.clone(),
                        step: step.clone(),
                        verdict: Verdict::NotEvaluated,
                        utilisation: None,
                        governing: String::new(),
                        unit: String::new(),
                        quantity: String::new(),
                        items: Vec::new(),
                        text: format!(
                            "check '{}': not evaluated: step '{step}' did not end in this run",
                            c.name
                        ),
                    }
                })
            })
            .collect()
    }
}

fn kind_name(k: &CheckKind) -> &'static str {
    match k {
        CheckKind::JointDecompression { .. } => "joint_decompression",
        CheckKind::ConcreteStress { .. } => "concrete_stress",
        CheckKind::TendonStress { .. } => "tendon_stress",
        CheckKind::UnbondedUltimate { .. } => "unbonded_tendon_ultimate",
        CheckKind::ShearKeys { .. } => "shear_keys",
    }
}

/// Joint `j` as a cross-section with its current contact stresses.
pub fn joint_section(sys: &System, j: usize) -> JointSection {
    let model = sys.model;
    let joint = &model.joints[j];
    let first = &model.interfaces[joint.interfaces[0]];
    let origin = model.nodes[first.nodes[0]];
    // The joint's axis: from its first node to the farthest face-A node.
    let far = joint
        .interfaces
        .iter()
        .flat_map(|&i| {
            let ie = &model.interfaces[i];
            ie.nodes[..ie.n_a].to_vec()
        })
        .map(|n| model.nodes[n])
        .max_by(|a, b| {
            let d = |p: &[f64; 2]| (p[0] - origin[0]).hypot(p[1] - origin[1]);
            d(a).total_cmp(&d(b))
        })
        .unwrap_or(origin);
    let len = (far[0] - origin[0])
        .hypot(far[1] - origin[1])
        .max(f64::MIN_POSITIVE);
    let dir = [(far[0] - origin[0]) / len, (far[1] - origin[1]) / len];
    let s_of = |p: [f64; 2]| (p[0] - origin[0]) * dir[0] + (p[1] - origin[1]) * dir[1];
    let mut pieces = Vec::new();
    let mut points = Vec::new();
    for &i in &joint.interfaces {
        let ie = &model.interfaces[i];
        pieces.push(Piece {
            s0: s_of(model.nodes[ie.nodes[0]]),
            s1: s_of(model.nodes[ie.nodes[1]]),
            t: ie.thickness,
        });
        for (p, st) in sys.interfaces[i].points().iter().zip(sys.joint_points(i)) {
            points.push(ContactPoint {
                s: s_of(p.position),
                area: p.weight * ie.thickness,
                normal: st.normal_stress(),
                shear: st.shear_stress(),
            });
        }
    }
    JointSection::new(&pieces, &points)
}

const MPA: f64 = 1e6;

fn evaluate(
    sys: &System,
    c: &DesignCheck,
    fpe: Option<f64>,
    peak: Option<(f64, f64)>,
) -> CheckResult {
    let model = sys.model;
    let items = match &c.kind {
        CheckKind::JointDecompression { .. } => decompression_items(sys, c),
        CheckKind::ConcreteStress { .. } => concrete_items(sys, c),
        CheckKind::TendonStress { .. } => tendon_items(sys, c),
        CheckKind::UnbondedUltimate { .. } => unbonded_items(sys, c, fpe, peak),
        CheckKind::ShearKeys { .. } => shear_key_items(sys, c),
    };
    let (unit, quantity, items) = match items {
        Ok(v) => v,
        Err(why) => return not_evaluated(model, c, &why),
    };
    let verdict_kind = if matches!(c.kind, CheckKind::UnbondedUltimate { .. }) {
        Verdict::Info
    } else {
        Verdict::Pass
    };
    let worst = items
        .iter()
        .max_by(|a, b| a.utilisation.total_cmp(&b.utilisation));
    let utilisation = worst.map(|w| w.utilisation).unwrap_or(0.0);
    let governing = worst.map(|w| w.item.clone()).unwrap_or_default();
    let verdict = match verdict_kind {
        Verdict::Info => Verdict::Info,
        _ if utilisation <= 1.0 => Verdict::Pass,
        _ => Verdict::Fail,
    };
    let step = model.steps[c.step].name.clone();
    let word = match verdict {
        Verdict::Pass => "pass",
        Verdict::Fail => "FAIL",
        _ => "analysis/code",
    };
    let text = match worst {
        Some(w) => format!(
            "check '{}' ({}), step '{step}': {word}, utilisation {} at {} ({} {unit} against {} {unit})",
            c.name,
            c.clause,
            fmt_u(utilisation),
            w.item,
            fmt_v(w.demand),
            fmt_v(w.limit)
        ),
        None => format!("check '{}': nothing to check", c.name),
    };
    CheckResult {
        name: c.name.clone(),
        check: kind_name(&c.kind).into(),
        code: c.code,
        clause: c.clause.clone(),
        step,
        verdict,
        utilisation: Some(utilisation),
        governing,
        unit: unit.into(),
        quantity,
        items,
        text,
    }
}

/// A check's unit, what it reads and its items; Err: why it cannot be evaluated.
type Items = Result<(&'static str, String, Vec<CheckItem>), String>;

/// The items of a `JointDecompression` check (Err: why it cannot be evaluated).
fn decompression_items(sys: &System, c: &DesignCheck) -> Items {
    let model = sys.model;
    let CheckKind::JointDecompression {
        joints,
        min_compression,
    } = &c.kind
    else {
        unreachable!("called for its own kind")
    };
    let items = joints
        .iter()
        .map(|&j| {
            let sec = joint_section(sys, j);
            CheckItem {
                item: format!("joint {}", model.joints[j].name),
                demand: sec.least_fibre() / MPA,
                limit: min_compression / MPA,
                utilisation: sec.decompression_utilisation(*min_compression),
                at: String::new(),
            }
        })
        .collect();
    Ok((
        "MPa",
        "least fibre compression of the uncracked joint section against the required compression; utilisation = M / M_decompression".into(),
        items,
    ))
}

/// The items of a `ConcreteStress` check (Err: why it cannot be evaluated).
fn concrete_items(sys: &System, c: &DesignCheck) -> Items {
    let model = sys.model;
    let CheckKind::ConcreteStress {
        regions,
        factor,
        excluded,
    } = &c.kind
    else {
        unreachable!("called for its own kind")
    };
    let mut skip = vec![false; model.elements.len()];
    for &e in excluded {
        skip[e] = true;
    }
    let items = regions
        .iter()
        .map(|&(r, fck)| {
            let mut worst = (0.0, usize::MAX);
            for (e, el) in model.elements.iter().enumerate() {
                if el.region != r || skip[e] {
                    continue;
                }
                for g in sys.element_gauss(e) {
                    let (_, s2) = principal(&g.stress);
                    if -s2 > worst.0 {
                        worst = (-s2, e);
                    }
                }
            }
            let limit = factor * fck;
            CheckItem {
                item: format!("region '{}'", model.regions[r].name),
                demand: worst.0 / MPA,
                limit: limit / MPA,
                utilisation: worst.0 / limit,
                at: if worst.1 == usize::MAX {
                    String::new()
                } else {
                    element_place(model, worst.1)
                },
            }
        })
        .collect();
    let quantity = if excluded.is_empty() {
        "largest compression −σ2 at the Gauss points against the limit".to_string()
    } else {
        format!(
            "largest compression −σ2 at the Gauss points against the limit; {} elements of the disturbed regions (within one member depth of anchorages, deviators, supports and point loads) left out",
            excluded.len()
        )
    };
    Ok(("MPa", quantity, items))
}

/// The items of a `TendonStress` check (Err: why it cannot be evaluated).
fn tendon_items(sys: &System, c: &DesignCheck) -> Items {
    let model = sys.model;
    let CheckKind::TendonStress { tendons, factor } = &c.kind else {
        unreachable!("called for its own kind")
    };
    let items = tendons
        .iter()
        .map(|&t| {
            let s = tendon_stress(sys, t);
            let limit = factor * model.tendons[t].fptk;
            CheckItem {
                item: format!("tendon {}", model.tendons[t].name),
                demand: s / MPA,
                limit: limit / MPA,
                utilisation: s / limit,
                at: String::new(),
            }
        })
        .collect();
    Ok(("MPa", "largest span stress against the limit".into(), items))
}

/// The items of a `UnbondedUltimate` check (Err: why it cannot be evaluated).
fn unbonded_items(
    sys: &System,
    c: &DesignCheck,
    fpe: Option<f64>,
    peak: Option<(f64, f64)>,
) -> Items {
    let model = sys.model;
    let CheckKind::UnbondedUltimate {
        tendon,
        x,
        support_hinges,
        fc,
        ..
    } = &c.kind
    else {
        unreachable!("called for its own kind")
    };
    let name = &model.tendons[*tendon].name;
    let (Some(fpe), Some((_, s_peak))) = (fpe, peak) else {
        return Err(
            "the step giving the effective prestress (fpe_step) did not end in this run".into(),
        );
    };
    let code = match c.code {
        Code::En => fpe + EN_UNBONDED_INCREASE,
        Code::Aashto => aashto_fps(model, *tendon, *x, *support_hinges, *fc, fpe)?,
    };
    let items = vec![CheckItem {
        item: format!("tendon {name}"),
        demand: s_peak / MPA,
        limit: code / MPA,
        utilisation: s_peak / code,
        at: format!("fpe = {:.1} MPa", fpe / MPA),
    }];
    Ok((
        "MPa",
        "tendon stress at the step's peak load from the analysis beside the code's estimate at ultimate".into(),
        items,
    ))
}

/// The items of a `ShearKeys` check (Err: why it cannot be evaluated).
fn shear_key_items(sys: &System, c: &DesignCheck) -> Items {
    let model = sys.model;
    let CheckKind::ShearKeys {
        joints,
        key_area,
        fc,
        phi,
    } = &c.kind
    else {
        unreachable!("called for its own kind")
    };
    let mut items = Vec::new();
    for &j in joints {
        let sec = joint_section(sys, j);
        let asm = sec.area - key_area;
        if asm < 0.0 {
            return Err(format!(
                "key_area {key_area} m² exceeds the area of joint {} ({:.4} m²)",
                model.joints[j].name, sec.area
            ));
        }
        let cap = phi * formulas::aashto_shear_key_capacity(*key_area, asm, *fc, sec.mean());
        items.push(CheckItem {
            item: format!("joint {}", model.joints[j].name),
            demand: sec.v.abs() / 1e3,
            limit: cap / 1e3,
            utilisation: sec.v.abs() / cap,
            at: format!("σn = {:.2} MPa", sec.mean() / MPA),
        });
    }
    Ok((
        "kN",
        "shear force across the joint against φ V_j of the keyed joint".into(),
        items,
    ))
}

fn fmt_u(u: f64) -> String {
    if u.is_finite() {
        format!("{u:.3}")
    } else {
        "∞ (no compression left to decompress)".into()
    }
}

fn fmt_v(v: f64) -> String {
    format!("{v:.2}")
}

fn not_evaluated(model: &Model, c: &DesignCheck, why: &str) -> CheckResult {
    CheckResult {
        name: c.name.clone(),
        check: kind_name(&c.kind).into(),
        code: c.code,
        clause: c.clause.clone(),
        step: model.steps[c.step].name.clone(),
        verdict: Verdict::NotEvaluated,
        utilisation: None,
        governing: String::new(),
        unit: String::new(),
        quantity: String::new(),
        items: Vec::new(),
        text: format!("check '{}': not evaluated: {why}", c.name),
    }
}

/// The AASHTO §5.6.3.1.2 stress of tendon `t` at ultimate at the section at `x` [Pa]: d_p
/// from the tendon's path, ℓ_i its length between anchorages, the section's widths from
/// the elements that span `x` (bands of their thickness over their height).
fn aashto_fps(
    model: &Model,
    t: usize,
    x: f64,
    ns: usize,
    fc: f64,
    fpe: f64,
) -> Result<f64, String> {
    let tendon = &model.tendons[t];
    // Tendon points as the weighted means of their ties (anchor plates' centres).
    let pts: Vec<[f64; 2]> = tendon
        .ties
        .iter()
        .map(|ties| {
            ties.iter().fold([0.0, 0.0], |a, &(n, w)| {
                [a[0] + w * model.nodes[n][0], a[1] + w * model.nodes[n][1]]
            })
        })
        .collect();
    let li: f64 = pts
        .windows(2)
        .map(|p| (p[1][0] - p[0][0]).hypot(p[1][1] - p[0][1]))
        .sum();
    let y_t = pts
        .windows(2)
        .find_map(|p| {
            let (a, b) = (p[0], p[1]);
            let (lo, hi) = (a[0].min(b[0]), a[0].max(b[0]));
            (lo <= x && x <= hi && hi > lo)
                .then(|| a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0]))
        })
        .ok_or_else(|| format!("tendon {} does not pass x = {x} m", tendon.name))?;
    // Bands of the section at x: (bottom, top, thickness) of the elements spanning x.
    let mut bands = Vec::new();
    for el in &model.elements {
        let xs = el.nodes.iter().map(|&n| model.nodes[n][0]);
        let ys = el.nodes.iter().map(|&n| model.nodes[n][1]);
        let (x0, x1) = (
            xs.clone().fold(f64::INFINITY, f64::min),
            xs.fold(f64::NEG_INFINITY, f64::max),
        );
        if x0 <= x && x < x1 {
            let (y0, y1) = (
                ys.clone().fold(f64::INFINITY, f64::min),
                ys.fold(f64::NEG_INFINITY, f64::max),
            );
            bands.push((y0, y1, model.regions[el.region].thickness));
        }
    }
    let top = bands.iter().map(|b| b.1).fold(f64::NEG_INFINITY, f64::max);
    let bottom = bands.iter().map(|b| b.0).fold(f64::INFINITY, f64::min);
    if bands.is_empty() {
        return Err(format!("no element spans x = {x} m"));
    }
    let dp = top - y_t;
    let fpy = 0.9 * tendon.fptk;
    let width = |depth: f64| {
        let y = top - depth;
        bands
            .iter()
            .filter(|b| b.0 <= y && y < b.1)
            .map(|b| b.2)
            .sum::<f64>()
    };
    let (_, fps) = formulas::aashto_unbonded_section(
        fc,
        tendon.area,
        |c| formulas::aashto_unbonded_fps(fpe, dp, c, li, ns, fpy),
        width,
        top - bottom,
    );
    Ok(fps)
}
