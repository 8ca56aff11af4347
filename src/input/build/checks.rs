//! `[[checks]]`: design checks on the results (docs/input.md, docs/theory-design.md).

use super::fields::{index_by_name, positive, unique_names};
use super::R;
use crate::design::formulas::{self, AASHTO_TYPE_B_CONSTRUCTION, AASHTO_TYPE_B_SERVICE};
use crate::input::error::Ctx;
use crate::input::schema::CheckIn;
use crate::materials::point::Material;
use crate::model::checks::{CheckKind, Code, DesignCheck};
use crate::model::{Model, NamedMaterial};

/// The mean compressive strength a material states [Pa], if any.
fn mean_strength(m: &NamedMaterial) -> Option<f64> {
    match &m.law {
        Material::Concrete { params, .. } => Some(params.fcm),
        _ => m.strength.map(|s| s.fcm),
    }
}

/// Resolve a list of names (all of `names` when absent).
fn pick<'a>(
    ctx: &Ctx,
    key: &str,
    what: &str,
    given: Option<&Vec<String>>,
    names: impl Iterator<Item = &'a str> + Clone,
) -> R<Vec<usize>> {
    match given {
        None => Ok((0..names.clone().count()).collect()),
        Some(list) if list.is_empty() => Err(ctx.err(
            key,
            format!("empty: name at least one {what}, or leave the key out for all"),
        )),
        Some(list) => list
            .iter()
            .enumerate()
            .map(|(i, n)| index_by_name(ctx, &format!("{key}[{i}]"), what, names.clone(), n))
            .collect(),
    }
}

/// Keys of one check kind besides the common ones (name, check, step, code, combination).
fn allowed(check: &str) -> &'static [&'static str] {
    match check {
        "joint_decompression" => &["joints", "min_compression"],
        "concrete_stress" => &["regions", "include_d_regions", "fck"],
        "tendon_stress" => &["tendons"],
        "unbonded_tendon_ultimate" => &["tendon", "x", "support_hinges", "fpe_step", "fck"],
        "shear_keys" => &["joints", "key_area", "fck", "phi"],
        _ => &[],
    }
}

const KINDS: &str =
    "joint_decompression, concrete_stress, tendon_stress, unbonded_tendon_ultimate, shear_keys";

/// The combination key of a check, one of `options` (for messages: what each means).
fn combination<'a>(ctx: &Ctx, key: &str, c: &CheckIn, options: &[&'a str]) -> R<&'a str> {
    let given = c.combination.as_deref().ok_or_else(|| {
        ctx.err(
            key,
            format!(
                "missing: the combination the step stands for ({})",
                options.join(", ")
            ),
        )
    })?;
    options
        .iter()
        .copied()
        .find(|o| *o == given)
        .ok_or_else(|| {
            ctx.err(
                key,
                format!(
                    "'{given}' is not one of {} for this check and code",
                    options.join(", ")
                ),
            )
        })
}

/// What every check's builder reads.
#[derive(Clone, Copy)]
struct Args<'a> {
    ctx: &'a Ctx,
    i: usize,
    c: &'a CheckIn,
    model: &'a Model,
    code: Code,
    step: usize,
}

impl Args<'_> {
    /// The key path of field `k` of this check.
    fn key(&self, k: &str) -> String {
        format!("checks[{}].{k}", self.i)
    }

    /// f_ck of region `r`: the check's own, else f_cm − 8 MPa of its material (EN 1992-1-1
    /// Table 3.1; also taken as AASHTO's f'c).
    fn fck_of(&self, r: usize) -> Option<f64> {
        self.c.fck.or_else(|| {
            mean_strength(&self.model.materials[self.model.regions[r].material])
                .map(formulas::en_fck_from_fcm)
        })
    }
}

/// Build every check into the model (after the steps, joints, regions and tendons).
pub(super) fn build(ctx: &Ctx, checks: &[CheckIn], model: &mut Model) -> R<()> {
    unique_names(ctx, "checks", checks.iter().map(|c| c.name.as_str()))?;
    for (i, c) in checks.iter().enumerate() {
        let check = one(ctx, i, c, model)?;
        model.checks.push(check);
    }
    Ok(())
}

fn one(ctx: &Ctx, i: usize, c: &CheckIn, model: &Model) -> R<DesignCheck> {
    let key = |k: &str| format!("checks[{i}].{k}");
    if allowed(&c.check).is_empty() {
        return Err(ctx.err(
            key("check"),
            format!("unknown check '{}' (known: {KINDS})", c.check),
        ));
    }
    // Keys of other kinds are refused, so a misplaced key never passes unread.
    let given: [(&str, bool); 12] = [
        ("joints", c.joints.is_some()),
        ("regions", c.regions.is_some()),
        ("include_d_regions", c.include_d_regions.is_some()),
        ("tendons", c.tendons.is_some()),
        ("tendon", c.tendon.is_some()),
        ("min_compression", c.min_compression.is_some()),
        ("fck", c.fck.is_some()),
        ("x", c.x.is_some()),
        ("support_hinges", c.support_hinges.is_some()),
        ("fpe_step", c.fpe_step.is_some()),
        ("key_area", c.key_area.is_some()),
        ("phi", c.phi.is_some()),
    ];
    for (k, present) in given {
        if present && !allowed(&c.check).contains(&k) {
            return Err(ctx.err(
                key(k),
                format!(
                    "not a key of check '{}' (its keys: name, check, step, code, combination, {})",
                    c.check,
                    allowed(&c.check).join(", ")
                ),
            ));
        }
    }
    let step = index_by_name(
        ctx,
        &key("step"),
        "step",
        model.steps.iter().map(|s| s.name.as_str()),
        &c.step,
    )?;
    let code = match c.code.as_deref().unwrap_or("en") {
        "en" => Code::En,
        "aashto" => Code::Aashto,
        other => {
            return Err(ctx.err(
                key("code"),
                format!("'{other}' is not a code (en or aashto)"),
            ))
        }
    };
    if let Some(f) = c.fck {
        positive(ctx, &key("fck"), f)?;
        // A strength in MPa would make every limit a million times too small.
        if f < 1e6 {
            return Err(ctx.err(
                key("fck"),
                format!("fck = {f} Pa is not a concrete strength (give Pa: 30e6 for 30 MPa)"),
            ));
        }
    }
    let a = Args {
        ctx,
        i,
        c,
        model,
        code,
        step,
    };
    let (clause, kind) = match c.check.as_str() {
        "joint_decompression" => decompression(&a)?,
        "concrete_stress" => concrete_stress(&a)?,
        "tendon_stress" => tendon_stress(&a)?,
        "unbonded_tendon_ultimate" => unbonded(&a)?,
        _ => shear_keys(&a)?,
    };
    Ok(DesignCheck {
        name: c.name.clone(),
        step,
        code,
        clause,
        kind,
    })
}

/// `joint_decompression`: the joints and the required compression.
fn decompression(a: &Args) -> R<(String, CheckKind)> {
    let Args {
        ctx,
        c,
        model,
        code,
        ..
    } = *a;
    let key = |k: &str| a.key(k);
    let joint_names = || model.joints.iter().map(|j| j.name.as_str());
    Ok({
        if model.joints.is_empty() {
            return Err(ctx.err(key("check"), "the model has no joints to check"));
        }
        let joints = pick(
            ctx,
            &key("joints"),
            "joint",
            c.joints.as_ref(),
            joint_names(),
        )?;
        let (clause, p) = match code {
            Code::En => {
                combination(ctx, &key("combination"), c, &["frequent", "characteristic"])?;
                ("EN 1992-2 7.3.1 (Table 7.101N): decompression", 0.0)
            }
            Code::Aashto => match combination(
                ctx,
                &key("combination"),
                c,
                &["service_iii", "construction"],
            )? {
                "service_iii" => (
                    "AASHTO LRFD Table 5.9.2.3.2b-1: Type B joints, 0.100 ksi compression",
                    AASHTO_TYPE_B_SERVICE,
                ),
                _ => (
                    "AASHTO LRFD Table 5.9.2.3.1b-1: Type B joints, 0.030 ksi compression",
                    AASHTO_TYPE_B_CONSTRUCTION,
                ),
            },
        };
        let (clause, min_compression) = match c.min_compression {
            Some(v) if v.is_finite() && v >= 0.0 => {
                (format!("user: {} MPa compression", v / 1e6), v)
            }
            Some(v) => {
                return Err(ctx.err(
                    key("min_compression"),
                    format!("must be a compression ≥ 0 in Pa (got {v})"),
                ))
            }
            None => (clause.to_string(), p),
        };
        (
            clause,
            CheckKind::JointDecompression {
                joints,
                min_compression,
            },
        )
    })
}

/// `concrete_stress`: the regions with their strengths, the limit, the disturbed regions left out.
fn concrete_stress(a: &Args) -> R<(String, CheckKind)> {
    let Args {
        ctx,
        c,
        model,
        code,
        step,
        ..
    } = *a;
    let key = |k: &str| a.key(k);
    let fck_of = |r: usize| a.fck_of(r);
    Ok({
        let chosen = pick(
            ctx,
            &key("regions"),
            "region",
            c.regions.as_ref(),
            model.regions.iter().map(|r| r.name.as_str()),
        )?;
        let mut regions = Vec::new();
        for r in chosen {
            match fck_of(r) {
                Some(f) => regions.push((r, f)),
                // Listed by name: its strength is needed.
                None if c.regions.is_some() => {
                    return Err(ctx.err(
                        key("regions"),
                        format!(
                            "region '{}': its material '{}' states no strength; give fck",
                            model.regions[r].name, model.materials[model.regions[r].material].name
                        ),
                    ))
                }
                // All regions: those without a strength (steel plates, local zones) are not concrete to check.
                None => {}
            }
        }
        if regions.is_empty() {
            return Err(ctx.err(
                key("regions"),
                "no region has a concrete strength to check against; give fck",
            ));
        }
        let (clause, factor) = match code {
            Code::En => match combination(
                ctx,
                &key("combination"),
                c,
                &["characteristic", "quasi_permanent"],
            )? {
                "characteristic" => ("EN 1992-1-1 7.2(2): 0.6 fck", 0.6),
                _ => ("EN 1992-1-1 7.2(3): 0.45 fck", 0.45),
            },
            Code::Aashto => {
                match combination(ctx, &key("combination"), c, &["service_i", "permanent"])? {
                    "service_i" => ("AASHTO LRFD Table 5.9.2.3.2a-1: 0.60 f'c", 0.60),
                    _ => ("AASHTO LRFD Table 5.9.2.3.2a-1: 0.45 f'c", 0.45),
                }
            }
        };
        let excluded = if c.include_d_regions.unwrap_or(false) {
            Vec::new()
        } else {
            d_region_elements(model, step)
        };
        (
            clause.to_string(),
            CheckKind::ConcreteStress {
                regions,
                factor,
                excluded,
            },
        )
    })
}

/// `tendon_stress`: the tendons and the limit.
fn tendon_stress(a: &Args) -> R<(String, CheckKind)> {
    let Args {
        ctx,
        c,
        model,
        code,
        ..
    } = *a;
    let key = |k: &str| a.key(k);
    Ok({
        if model.tendons.is_empty() {
            return Err(ctx.err(key("check"), "the model has no external tendons to check"));
        }
        let tendons = pick(
            ctx,
            &key("tendons"),
            "tendon",
            c.tendons.as_ref(),
            model.tendons.iter().map(|t| t.name.as_str()),
        )?;
        let (clause, factor) = match code {
            Code::En => {
                combination(ctx, &key("combination"), c, &["characteristic"])?;
                ("EN 1992-1-1 7.2(5): 0.75 fpk", 0.75)
            }
            Code::Aashto => {
                combination(ctx, &key("combination"), c, &["service"])?;
                (
                    "AASHTO LRFD Table 5.9.2.2-1: 0.80 fpy (fpy = 0.90 fpu)",
                    0.72,
                )
            }
        };
        (
            clause.to_string(),
            CheckKind::TendonStress { tendons, factor },
        )
    })
}

/// `unbonded_tendon_ultimate`: the tendon, the section, the strength and the step of f_pe.
fn unbonded(a: &Args) -> R<(String, CheckKind)> {
    let Args {
        ctx,
        c,
        model,
        code,
        step,
        ..
    } = *a;
    let key = |k: &str| a.key(k);
    let fck_of = |r: usize| a.fck_of(r);
    Ok({
        if model.tendons.is_empty() {
            return Err(ctx.err(key("check"), "the model has no external tendons to check"));
        }
        if c.combination.is_some() {
            return Err(ctx.err(
                key("combination"),
                "not a key of check 'unbonded_tendon_ultimate' (it reads the step's peak load)",
            ));
        }
        let tendon = index_by_name(
            ctx,
            &key("tendon"),
            "tendon",
            model.tendons.iter().map(|t| t.name.as_str()),
            c.tendon.as_deref().ok_or_else(|| {
                ctx.err(key("tendon"), "missing (the name of an external tendon)")
            })?,
        )?;
        let x = c.x.ok_or_else(|| {
            ctx.err(
                key("x"),
                "missing: the abscissa of the critical section [m]",
            )
        })?;
        let (x0, x1) = model
            .nodes
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p[0]), b.max(p[0]))
            });
        if !(x.is_finite() && x > x0 && x < x1) {
            return Err(ctx.err(
                key("x"),
                format!("must lie inside the model, {x0} < x < {x1} m (got {x})"),
            ));
        }
        // The strength of the regions the section crosses: the least.
        let fc = c.fck.or_else(|| {
            model
                .elements
                .iter()
                .filter(|e| {
                    let xs = e.nodes.iter().map(|&n| model.nodes[n][0]);
                    let lo = xs.clone().fold(f64::INFINITY, f64::min);
                    let hi = xs.fold(f64::NEG_INFINITY, f64::max);
                    lo <= x && x <= hi
                })
                .filter_map(|e| fck_of(e.region))
                .reduce(f64::min)
        });
        let fc =
            fc.ok_or_else(|| ctx.err(key("fck"), "the regions at x state no strength; give fck"))?;
        let fpe_step = match c.fpe_step.as_deref() {
        Some(name) => {
            let k = index_by_name(
                ctx,
                &key("fpe_step"),
                "step",
                model.steps.iter().map(|s| s.name.as_str()),
                name,
            )?;
            if k >= step {
                return Err(ctx.err(
                    key("fpe_step"),
                    format!("'{name}' must come before the check's step '{}'", c.step),
                ));
            }
            k
        }
        None if step > 0 => step - 1,
        None => {
            return Err(ctx.err(
                key("fpe_step"),
                "missing: the check's step is the first, so no earlier step gives the effective prestress",
            ))
        }
    };
        let clause = match code {
            Code::En => "EN 1992-1-1 5.10.8(2): fpe + 100 MPa",
            Code::Aashto => "AASHTO LRFD 5.6.3.1.2: fps = fpe + 900 ksi (dp - c)/le",
        };
        (
            clause.to_string(),
            CheckKind::UnbondedUltimate {
                tendon,
                x,
                support_hinges: c.support_hinges.unwrap_or(0),
                fc,
                fpe_step,
            },
        )
    })
}

/// `shear_keys`: the joints, the key area, the strength and φ.
fn shear_keys(a: &Args) -> R<(String, CheckKind)> {
    let Args {
        ctx,
        c,
        model,
        code,
        ..
    } = *a;
    let key = |k: &str| a.key(k);
    let fck_of = |r: usize| a.fck_of(r);
    let joint_names = || model.joints.iter().map(|j| j.name.as_str());
    Ok({
        if code != Code::Aashto {
            return Err(ctx.err(
            key("code"),
            "shear_keys follows the AASHTO segmental Guide Specification: give code = \"aashto\"",
        ));
        }
        if c.combination.is_some() {
            return Err(ctx.err(
            key("combination"),
            "not a key of check 'shear_keys' (it reads the step's end: make it the factored combination)",
        ));
        }
        if model.joints.is_empty() {
            return Err(ctx.err(key("check"), "the model has no joints to check"));
        }
        let joints = pick(
            ctx,
            &key("joints"),
            "joint",
            c.joints.as_ref(),
            joint_names(),
        )?;
        let key_area = positive(
            ctx,
            &key("key_area"),
            c.key_area.ok_or_else(|| {
                ctx.err(
                    key("key_area"),
                    "missing: the base area of the keys in the failure plane, A_k [m²]",
                )
            })?,
        )?;
        let phi = match c.phi {
            Some(p) if p > 0.0 && p <= 1.0 => p,
            Some(p) => return Err(ctx.err(key("phi"), format!("must lie in (0, 1] (got {p})"))),
            None => 0.9,
        };
        let fc = c.fck.or_else(|| {
            joints
                .iter()
                .flat_map(|&j| &model.joints[j].interfaces)
                .flat_map(|&ie| &model.interfaces[ie].nodes)
                .flat_map(|&n| model.elements.iter().filter(move |e| e.nodes.contains(&n)))
                .filter_map(|e| fck_of(e.region))
                .reduce(f64::min)
        });
        let fc = fc.ok_or_else(|| {
            ctx.err(
                key("fck"),
                "the concrete beside the joints states no strength; give fck",
            )
        })?;
        (
            "AASHTO Guide Spec. segmental (1999): keyed dry joints".to_string(),
            CheckKind::ShearKeys {
                joints,
                key_area,
                fc,
                phi,
            },
        )
    })
}

/// Elements of the disturbed regions at step `step`: those with a node closer than one
/// member depth to a concentrated force: a tendon point (anchorage, deviator), a node of
/// a support active in the step, a point load of a case the step applies. There the
/// stresses follow the force's spreading, not the section's (Saint-Venant; the D-regions of
/// Schlaich, Schäfer & Jennewein, PCI J. 32(3), 1987), and are designed by strut-and-tie
/// and anchorage-zone rules (EN 1992-1-1 6.5, 8.10.3), not by the stress limits.
fn d_region_elements(model: &Model, step: usize) -> Vec<usize> {
    let mut used = vec![false; model.nodes.len()];
    for el in &model.elements {
        for &n in &el.nodes {
            used[n] = true;
        }
    }
    let mut points: Vec<[f64; 2]> = Vec::new();
    for t in &model.tendons {
        for ties in &t.ties {
            points.push(ties.iter().fold([0.0, 0.0], |a, &(n, w)| {
                [a[0] + w * model.nodes[n][0], a[1] + w * model.nodes[n][1]]
            }));
        }
    }
    for (s, sup) in model.supports.iter().enumerate() {
        if !model.staging.support(s).active_in(step) {
            continue;
        }
        points.extend(
            sup.dofs
                .iter()
                .filter(|d| used[d.0])
                .map(|d| model.nodes[d.0]),
        );
    }
    for (c, case) in model.load_cases.iter().enumerate() {
        if model.steps[step].factors.get(c).is_some_and(|f| *f != 0.0) {
            points.extend(case.point_forces.iter().map(|(n, _)| model.nodes[*n]));
        }
    }
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    points.dedup();
    // Bounding boxes of the elements.
    let boxes: Vec<([f64; 2], [f64; 2])> = model
        .elements
        .iter()
        .map(|el| {
            let mut lo = [f64::INFINITY; 2];
            let mut hi = [f64::NEG_INFINITY; 2];
            for &n in &el.nodes {
                for k in 0..2 {
                    lo[k] = lo[k].min(model.nodes[n][k]);
                    hi[k] = hi[k].max(model.nodes[n][k]);
                }
            }
            (lo, hi)
        })
        .collect();
    // The member depth at x: the height of the elements spanning x.
    let depth_at = |x: f64| {
        let (lo, hi) = boxes
            .iter()
            .filter(|b| b.0[0] <= x && x <= b.1[0])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), b| {
                (lo.min(b.0[1]), hi.max(b.1[1]))
            });
        (hi - lo).max(0.0)
    };
    let reach: Vec<f64> = points.iter().map(|p| depth_at(p[0])).collect();
    // An element reaching into the region (any node closer than the depth) is left out
    // whole: its Gauss points lie up to half an element nearer the force than its centroid.
    model
        .elements
        .iter()
        .enumerate()
        .filter(|(_, el)| {
            el.nodes.iter().any(|&n| {
                let q = model.nodes[n];
                points
                    .iter()
                    .zip(&reach)
                    .any(|(p, r)| (q[0] - p[0]).hypot(q[1] - p[1]) < *r - 1e-9 * r)
            })
        })
        .map(|(e, _)| e)
        .collect()
}
