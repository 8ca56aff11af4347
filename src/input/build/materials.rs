//! `[[materials]]`: elastic, concrete (MC90 with its options), elastic_creep (MC90 creep and
//! shrinkage) and the steels of bars (rebar, prestressing_steel).

use super::fields::{fraction, positive, unique_names};
use super::R;
use crate::input::error::Ctx;
use crate::input::units;
use crate::materials::concrete::creep::ConcreteCreep;
use crate::materials::concrete::{
    CompressionSoftening, ConcreteParams, ShearRetention, TensionSoftening,
};
use crate::materials::mc90::{self, TensileRef};
use crate::materials::point::Material;
use crate::materials::steel::SteelParams;
use crate::model::{NamedMaterial, Strength};
use serde::{Deserialize, Serialize};

/// `viscoplastic = { ... }` of a concrete material (Owen–Hinton option).
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)] // keys documented in docs/input.md
pub struct ViscoplasticIn {
    pub fluidity: Option<f64>,
    pub overstress: Option<String>,
    pub exponent: Option<f64>,
    pub theta: Option<f64>,
    pub safety: Option<f64>,
    pub tau: Option<f64>,
    pub load_steps: Option<String>,
}

/// A `[[materials]]` table as read: every key of every kind (a key of another kind is an
/// error, see [`MaterialKind::keys`]). Documented key by key in docs/input.md.
#[derive(Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)] // keys documented in docs/input.md
pub struct MaterialIn {
    pub name: String,
    pub kind: String,
    #[serde(rename = "E")]
    pub e: Option<f64>,
    pub nu: Option<f64>,
    pub density: Option<f64>,
    // concrete
    pub fcm: Option<f64>,
    pub ftm: Option<f64>,
    pub class: Option<String>,
    #[serde(rename = "C")]
    pub c: Option<f64>,
    pub tensile_reference: Option<String>,
    pub tension_softening: Option<String>,
    pub alpha: Option<f64>,
    #[serde(rename = "Gf")]
    pub gf: Option<f64>,
    pub eps_c1: Option<f64>,
    pub eps_cu: Option<f64>,
    pub compression_softening: Option<String>,
    #[serde(rename = "Gc")]
    pub gc: Option<f64>,
    pub initial_yield_ratio: Option<f64>,
    pub softening_limit: Option<f64>,
    pub crack_ratio: Option<f64>,
    pub shear_k1: Option<f64>,
    pub shear_eps_ref: Option<f64>,
    pub shear_beta_min: Option<f64>,
    pub residual_stiffness: Option<f64>,
    pub secant_crack_tangent: Option<bool>,
    pub double_crack: Option<String>,
    pub crack_integration: Option<String>,
    pub normalize_equivalent_stress: Option<bool>,
    pub viscoplastic: Option<ViscoplasticIn>,
    pub crack_model: Option<String>,
    pub compression_reduction: Option<String>,
    pub compression_reduction_min: Option<f64>,
    pub compression_reduction_spacing: Option<f64>,
    pub shear_retention: Option<String>,
    pub aggregate_size: Option<f64>,
    pub crack_shear_limit: Option<String>,
    pub principal_stress_limit: Option<String>,
    // steel
    pub fy: Option<f64>,
    #[serde(rename = "Et")]
    pub et: Option<f64>,
    #[serde(rename = "Ep")]
    pub ep: Option<f64>,
    pub fptk: Option<f64>,
    pub eps_uk: Option<f64>,
    // elastic_creep (MC90 creep and shrinkage)
    pub rh: Option<f64>,
    pub h0: Option<f64>,
    pub cement: Option<String>,
    pub n_units: Option<usize>,
    pub shrinkage: Option<bool>,
    pub drying_start: Option<f64>,
    // concrete: creep option (takes the elastic_creep keys above)
    pub creep: Option<String>,
    pub nonlinear_creep: Option<bool>,
    // every kind: thermal actions
    pub thermal_expansion: Option<f64>,
}

/// The kinds of `[[materials]]` (`kind = "..."`), one per material law the model file offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MaterialKind {
    /// Linear elastic isotropic (regions).
    Elastic,
    /// Ageing linear viscoelastic concrete: MC90 creep and shrinkage (regions).
    ElasticCreep,
    /// Plane-stress concrete: MC90/Ottosen plasticity and smeared cracking (regions).
    Concrete,
    /// Reinforcing steel, bilinear (bars and bar layers).
    Rebar,
    /// Prestressing steel (bars and bar layers).
    PrestressingSteel,
}

impl MaterialKind {
    /// Every kind, in the order messages list them.
    pub const ALL: [MaterialKind; 5] = [
        MaterialKind::Elastic,
        MaterialKind::ElasticCreep,
        MaterialKind::Concrete,
        MaterialKind::Rebar,
        MaterialKind::PrestressingSteel,
    ];

    /// The `kind` value in the model file.
    pub fn name(self) -> &'static str {
        match self {
            MaterialKind::Elastic => "elastic",
            MaterialKind::ElasticCreep => "elastic_creep",
            MaterialKind::Concrete => "concrete",
            MaterialKind::Rebar => "rebar",
            MaterialKind::PrestressingSteel => "prestressing_steel",
        }
    }

    /// The keys a table of this kind takes besides `name` and `kind` (schema spelling, in
    /// the order messages list them). The one list per kind: a key of [`MaterialIn`] not
    /// listed here for a kind is an error in a table of that kind.
    pub fn keys(self) -> &'static [&'static str] {
        match self {
            MaterialKind::Elastic => &[
                "E",
                "nu",
                "density",
                "fcm",
                "ftm",
                "class",
                "thermal_expansion",
            ],
            MaterialKind::ElasticCreep => &[
                "fcm",
                "nu",
                "density",
                "rh",
                "h0",
                "cement",
                "n_units",
                "shrinkage",
                "drying_start",
                "thermal_expansion",
            ],
            MaterialKind::Concrete => &[
                "fcm",
                "E",
                "nu",
                "density",
                "ftm",
                "C",
                "tensile_reference",
                "tension_softening",
                "alpha",
                "Gf",
                "eps_c1",
                "eps_cu",
                "compression_softening",
                "Gc",
                "initial_yield_ratio",
                "softening_limit",
                "crack_ratio",
                "shear_k1",
                "shear_eps_ref",
                "shear_beta_min",
                "residual_stiffness",
                "secant_crack_tangent",
                "double_crack",
                "crack_integration",
                "normalize_equivalent_stress",
                "viscoplastic",
                "crack_model",
                "compression_reduction",
                "compression_reduction_min",
                "compression_reduction_spacing",
                "shear_retention",
                "aggregate_size",
                "crack_shear_limit",
                "principal_stress_limit",
                "creep",
                "rh",
                "h0",
                "cement",
                "n_units",
                "shrinkage",
                "drying_start",
                "nonlinear_creep",
                "thermal_expansion",
            ],
            MaterialKind::Rebar => &["E", "fy", "Et", "thermal_expansion"],
            MaterialKind::PrestressingSteel => &["Ep", "fptk", "eps_uk", "thermal_expansion"],
        }
    }

    /// The kind named `s` in `materials[i].kind`.
    fn parse(ctx: &Ctx, i: usize, s: &str) -> R<MaterialKind> {
        MaterialKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = MaterialKind::ALL.iter().map(|k| k.name()).collect();
                let (last, rest) = names.split_last().expect("kinds exist");
                ctx.err(
                    format!("materials[{i}].kind"),
                    format!(
                        "unknown material kind '{s}' (expected {} or {last})",
                        rest.join(", ")
                    ),
                )
            })
    }
}

/// `kind = "elastic"`: E (required), ν and density.
fn elastic_law(ctx: &Ctx, i: usize, m: &MaterialIn, warnings: &mut Vec<String>) -> R<Material> {
    let k = |f: &str| format!("materials[{i}].{f}");
    check_material_keys(ctx, i, m, MaterialKind::Elastic)?;
    let e = positive(ctx, &k("E"), m.e.ok_or_else(|| ctx.err(k("E"), "missing"))?)?;
    let (nu, density) = poisson_and_density(ctx, i, m)?;
    units::modulus(warnings, ctx, &k("E"), e);
    if density > 0.0 && !(100.0..=20000.0).contains(&density) {
        warnings.push(format!(
            "{}: {}: density {density} kg/m³ is unusual; segfem works in kg/m³",
            ctx.file,
            k("density")
        ));
    }
    Ok(Material::Elastic { e, nu, density })
}

/// EN 1992-1-1 Table 3.1 strength classes `C{fck}/{fck,cube}` (normal-weight concrete) [MPa].
const EN_CLASSES: [(u32, u32); 14] = [
    (12, 15),
    (16, 20),
    (20, 25),
    (25, 30),
    (30, 37),
    (35, 45),
    (40, 50),
    (45, 55),
    (50, 60),
    (55, 67),
    (60, 75),
    (70, 85),
    (80, 95),
    (90, 105),
];

/// The strength an elastic material is checked against: `class` (EN 1992-1-1 Table 3.1:
/// f_cm = f_ck + 8 MPa, f_ctm = 0.30 f_ck^(2/3) up to C50/60, 2.12 ln(1 + f_cm/10) above), or
/// `fcm` with `ftm` (default: the `concrete` kind's f_tm of the same f_cm, so that switching
/// the kind keeps the strengths). None when neither is given.
fn elastic_strength(
    ctx: &Ctx,
    i: usize,
    m: &MaterialIn,
    warnings: &mut Vec<String>,
) -> R<Option<Strength>> {
    let k = |f: &str| format!("materials[{i}].{f}");
    if let Some(c) = &m.class {
        if m.fcm.is_some() {
            return Err(ctx.err(k("fcm"), "give class or fcm, not both"));
        }
        let known = || {
            EN_CLASSES
                .iter()
                .map(|(a, b)| format!("C{a}/{b}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let fck = EN_CLASSES
            .iter()
            .find(|(a, b)| *c == format!("C{a}/{b}"))
            .map(|(a, _)| f64::from(*a))
            .ok_or_else(|| {
                ctx.err(
                    k("class"),
                    format!(
                        "unknown strength class '{c}' (EN 1992-1-1 Table 3.1: {})",
                        known()
                    ),
                )
            })?;
        let fcm = fck + 8.0;
        let fctm = if fck <= 50.0 {
            0.30 * fck.powf(2.0 / 3.0)
        } else {
            2.12 * (1.0 + fcm / 10.0).ln()
        };
        let ftm = match m.ftm {
            Some(f) => positive(ctx, &k("ftm"), f)?,
            None => fctm * 1e6,
        };
        return Ok(Some(Strength {
            fcm: fcm * 1e6,
            ftm,
        }));
    }
    match (m.fcm, m.ftm) {
        (None, None) => Ok(None),
        (None, Some(_)) => Err(ctx.err(
            k("ftm"),
            "needs fcm or class (the compressive strength to check against)",
        )),
        (Some(fcm), ftm) => {
            let fcm = positive(ctx, &k("fcm"), fcm)?;
            if fcm < 1e6 {
                warnings.push(format!(
                    "{}: {}: fcm = {fcm} Pa looks like MPa; segfem works in Pa",
                    ctx.file,
                    k("fcm")
                ));
            }
            let ftm = match ftm {
                Some(f) => positive(ctx, &k("ftm"), f)?,
                None => mc90::f_tm(fcm, mc90::C_MEAN, TensileRef::Fcm),
            };
            Ok(Some(Strength { fcm, ftm }))
        }
    }
}

/// The `[[materials]]`: the continuum laws (for regions), and the steels (`rebar`,
/// `prestressing_steel`) by name for bars and bar layers.
#[allow(clippy::type_complexity)]
pub(super) fn build(
    ctx: &Ctx,
    list: &[MaterialIn],
    warnings: &mut Vec<String>,
) -> R<(Vec<NamedMaterial>, Vec<(String, SteelParams)>)> {
    unique_names(ctx, "materials", list.iter().map(|m| m.name.as_str()))?;
    let mut materials = Vec::new();
    let mut steels: Vec<(String, SteelParams)> = Vec::new();
    for (i, m) in list.iter().enumerate() {
        let kind = MaterialKind::parse(ctx, i, &m.kind)?;
        let (law, strength) = match kind {
            MaterialKind::Elastic => (
                elastic_law(ctx, i, m, warnings)?,
                elastic_strength(ctx, i, m, warnings)?,
            ),
            MaterialKind::ElasticCreep => {
                let law = creep_material(ctx, i, m, warnings)?;
                // Its f_cm is given (the creep functions need it): checked like an elastic
                // material's, with the concrete kind's default f_tm.
                let fcm = m.fcm.unwrap_or(0.0);
                let ftm = mc90::f_tm(fcm, mc90::C_MEAN, TensileRef::Fcm);
                (law, Some(Strength { fcm, ftm }))
            }
            // Cracking and crushing are the law's own.
            MaterialKind::Concrete => (concrete_law(ctx, i, m, warnings)?, None),
            MaterialKind::Rebar | MaterialKind::PrestressingSteel => {
                steels.push((m.name.clone(), steel_law(ctx, i, m, kind, warnings)?));
                continue;
            }
        };
        materials.push(NamedMaterial {
            name: m.name.clone(),
            law,
            strength,
        });
    }
    Ok((materials, steels))
}

/// Names of the keys set in material table `m` (`materials[i]`, schema spelling), derived
/// from [`MaterialIn`] itself: serialized, a table keeps exactly the keys given (absent
/// options are skipped), so a new key needs no list of its own here.
fn given_material_keys(ctx: &Ctx, i: usize, m: &MaterialIn) -> R<Vec<String>> {
    // Values read from TOML serialize back to TOML; an error here is a program error.
    let table = toml::Table::try_from(m)
        .map_err(|e| ctx.err(format!("materials[{i}]"), format!("internal error: {e}")))?;
    Ok(table
        .keys()
        .filter(|k| *k != "name" && *k != "kind")
        .cloned()
        .collect())
}

/// A key that does not belong to the material's kind is an error, not silently ignored.
fn check_material_keys(ctx: &Ctx, i: usize, m: &MaterialIn, kind: MaterialKind) -> R<()> {
    let allowed = kind.keys();
    for k in given_material_keys(ctx, i, m)? {
        if !allowed.contains(&k.as_str()) {
            return Err(ctx.err(
                format!("materials[{i}].{k}"),
                format!(
                    "not a key of kind '{}' (its keys: {})",
                    m.kind,
                    allowed.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// `viscoplastic = { ... }` of a concrete: the Owen–Hinton option (docs/input.md).
pub(super) fn viscoplastic_option(
    ctx: &Ctx,
    i: usize,
    v: &ViscoplasticIn,
) -> R<crate::materials::concrete::compression::Viscoplastic> {
    use crate::materials::viscoplastic::OverstressFunction;
    let k = |f: &str| format!("materials[{i}].viscoplastic.{f}");
    let d = crate::materials::concrete::compression::Viscoplastic::default();
    let fluidity = positive(
        ctx,
        &k("fluidity"),
        v.fluidity
            .ok_or_else(|| ctx.err(k("fluidity"), "missing (fluidity γ [1/d])"))?,
    )?;
    let exponent = v
        .exponent
        .map(|e| positive(ctx, &k("exponent"), e))
        .transpose()?;
    let overstress = match (v.overstress.as_deref(), exponent) {
        (None | Some("linear"), None) => OverstressFunction::Linear,
        (None | Some("linear"), Some(_)) => {
            return Err(ctx.err(
                k("exponent"),
                "is used by overstress = \"power\" or \"exponential\" only",
            ))
        }
        (Some("power"), Some(n)) => OverstressFunction::Power(n),
        (Some("exponential"), Some(m)) => OverstressFunction::Exponential(m),
        (Some("power" | "exponential"), None) => {
            return Err(ctx.err(
                k("exponent"),
                "missing (N of the power law, M of the exponential)",
            ))
        }
        (Some(o), _) => {
            return Err(ctx.err(
                k("overstress"),
                format!("unknown value '{o}' (expected linear, power or exponential)"),
            ))
        }
    };
    let load_steps = match v.load_steps.as_deref() {
        None | Some("steady") => true,
        Some("elastic") => false,
        Some(o) => {
            return Err(ctx.err(
                k("load_steps"),
                format!("unknown value '{o}' (expected steady or elastic)"),
            ))
        }
    };
    Ok(crate::materials::concrete::compression::Viscoplastic {
        fluidity,
        overstress,
        theta: fraction(ctx, &k("theta"), v.theta.unwrap_or(d.theta), 0.0, 1.0)?,
        safety: fraction(ctx, &k("safety"), v.safety.unwrap_or(d.safety), 1e-3, 1.0)?,
        tau: fraction(ctx, &k("tau"), v.tau.unwrap_or(d.tau), 1e-4, 1.0)?,
        steady_load_steps: load_steps,
    })
}

/// `kind = "concrete"`: MC90 defaults from f_cm, each overridable.
pub(super) fn concrete_law(
    ctx: &Ctx,
    i: usize,
    m: &MaterialIn,
    warnings: &mut Vec<String>,
) -> R<Material> {
    let k = |f: &str| format!("materials[{i}].{f}");
    check_material_keys(ctx, i, m, MaterialKind::Concrete)?;
    let fcm = positive(
        ctx,
        &k("fcm"),
        m.fcm
            .ok_or_else(|| ctx.err(k("fcm"), "missing (mean compressive strength [Pa])"))?,
    )?;
    if fcm < 1e6 {
        warnings.push(format!(
            "{}: {}: fcm = {fcm} Pa looks like MPa; segfem works in Pa",
            ctx.file,
            k("fcm")
        ));
    }
    let nu = fraction(ctx, &k("nu"), m.nu.unwrap_or(0.2), 0.0, 0.499)?;
    let density = m.density.unwrap_or(0.0);
    if !(density.is_finite() && density >= 0.0) {
        return Err(ctx.err(k("density"), "must be zero or positive"));
    }
    let tref = match m.tensile_reference.as_deref() {
        None | Some("fcm") => TensileRef::Fcm,
        Some("fck") => TensileRef::Fck,
        Some(o) => {
            return Err(ctx.err(
                k("tensile_reference"),
                format!("unknown value '{o}' (expected fcm or fck)"),
            ))
        }
    };
    if m.ftm.is_some() && m.c.is_some() {
        return Err(ctx.err(k("C"), "give ftm or C, not both"));
    }
    let c = m.c.unwrap_or(mc90::C_MEAN);
    if !(c > 0.0 && c < 1.0) {
        return Err(ctx.err(
            k("C"),
            format!("must lie in (0, 1) (MC90: 0.095–0.185; got {c})"),
        ));
    }
    let mut p = ConcreteParams::from_mc90_with(fcm, nu, c, tref);
    concrete_overrides(ctx, i, m, fcm, &mut p, warnings)?;
    concrete_softening(ctx, i, m, fcm, &mut p)?;
    if let Some(v) = &m.viscoplastic {
        p.viscoplastic = Some(viscoplastic_option(ctx, i, v)?);
    }
    shear_options(ctx, i, m, &mut p)?;
    p.creep = concrete_creep(ctx, i, m, fcm, warnings)?;
    if p.creep.is_some()
        && m.initial_yield_ratio.is_none()
        && p.crack_model == crate::materials::concrete::CrackModel::Fixed
    {
        // MC90 creep is linear up to 0.4 f_cm and its compliance holds the whole strain
        // there: the compression plasticity starts at that stress (docs/theory-time.md §9).
        p.initial_yield_ratio = 0.4;
    }
    p.validate()
        .map_err(|e| ctx.err(format!("materials[{i}]"), e.to_string()))?;
    Ok(Material::Concrete {
        params: Box::new(p),
        density,
    })
}

/// The concrete keys of shear behaviour: crack model, compression softening of cracked
/// concrete, shear retention of fixed cracks (docs/input.md).
fn shear_options(ctx: &Ctx, i: usize, m: &MaterialIn, p: &mut ConcreteParams) -> R<()> {
    use crate::materials::concrete::cracking::{CrackShearLimit, PrincipalStressLimit};
    use crate::materials::concrete::{CompressionReduction, CrackModel, ShearRetentionLaw};
    let k = |f: &str| format!("materials[{i}].{f}");
    p.crack_model = match m.crack_model.as_deref() {
        None | Some("fixed") => CrackModel::Fixed,
        Some("rotating") => CrackModel::Rotating,
        Some(o) => {
            return Err(ctx.err(
                k("crack_model"),
                format!("unknown value '{o}' (expected fixed or rotating)"),
            ))
        }
    };
    p.compression_reduction = match m.compression_reduction.as_deref() {
        None | Some("none") => {
            for (key, set) in [
                (
                    "compression_reduction_min",
                    m.compression_reduction_min.is_some(),
                ),
                (
                    "compression_reduction_spacing",
                    m.compression_reduction_spacing.is_some(),
                ),
            ] {
                if set {
                    return Err(ctx.err(
                        k(key),
                        "used by compression_reduction = \"vecchio_collins_1993\" only",
                    ));
                }
            }
            CompressionReduction::None
        }
        Some("vecchio_collins_1993") => CompressionReduction::VecchioCollins1993 {
            beta_min: fraction(
                ctx,
                &k("compression_reduction_min"),
                m.compression_reduction_min.unwrap_or(0.4),
                1e-3,
                1.0,
            )?,
            spacing: match m.compression_reduction_spacing {
                Some(s) => positive(ctx, &k("compression_reduction_spacing"), s)?,
                None => 0.0,
            },
        },
        Some(o) => {
            return Err(ctx.err(
                k("compression_reduction"),
                format!("unknown value '{o}' (expected none or vecchio_collins_1993)"),
            ))
        }
    };
    let seed_keys = m.shear_k1.is_some() || m.shear_eps_ref.is_some();
    p.shear_retention = match m.shear_retention.as_deref() {
        None | Some("seed") => {
            if m.aggregate_size.is_some() && m.crack_shear_limit.is_none() {
                return Err(ctx.err(
                    k("aggregate_size"),
                    "used by shear_retention = \"aggregate\" and crack_shear_limit only",
                ));
            }
            ShearRetentionLaw::Seed
        }
        Some("aggregate") if seed_keys => {
            return Err(ctx.err(
                k("shear_retention"),
                "shear_k1 and shear_eps_ref belong to shear_retention = \"seed\"",
            ))
        }
        Some("aggregate") => ShearRetentionLaw::Aggregate {
            d_agg: positive(ctx, &k("aggregate_size"), m.aggregate_size.unwrap_or(0.016))?,
        },
        Some(o) => {
            return Err(ctx.err(
                k("shear_retention"),
                format!("unknown value '{o}' (expected seed or aggregate)"),
            ))
        }
    };
    p.crack_shear_limit = match m.crack_shear_limit.as_deref() {
        None | Some("none") => CrackShearLimit::None,
        Some("vecchio_collins_1986") => CrackShearLimit::VecchioCollins1986 {
            d_agg: positive(ctx, &k("aggregate_size"), m.aggregate_size.unwrap_or(0.016))?,
        },
        Some(o) => {
            return Err(ctx.err(
                k("crack_shear_limit"),
                format!("unknown value '{o}' (expected none or vecchio_collins_1986)"),
            ))
        }
    };
    p.principal_stress_limit = match m.principal_stress_limit.as_deref() {
        None | Some("none") => PrincipalStressLimit::None,
        Some("tensile_strength") => PrincipalStressLimit::TensileStrength,
        Some("softening") => PrincipalStressLimit::Softening,
        Some(o) => {
            return Err(ctx.err(
                k("principal_stress_limit"),
                format!("unknown value '{o}' (expected none, tensile_strength or softening)"),
            ))
        }
    };
    if p.crack_model == CrackModel::Rotating {
        if m.principal_stress_limit.is_some() {
            return Err(ctx.err(
                k("principal_stress_limit"),
                "rotating cracks follow the principal stress: principal_stress_limit belongs to crack_model = \"fixed\"",
            ));
        }
        if m.crack_shear_limit.is_some() {
            return Err(ctx.err(
                k("crack_shear_limit"),
                "rotating cracks carry no shear across cracks: crack_shear_limit belongs to crack_model = \"fixed\"",
            ));
        }
        if m.shear_retention.is_some() || seed_keys || m.shear_beta_min.is_some() {
            return Err(ctx.err(
                k("shear_retention"),
                "rotating cracks carry no shear across cracks: shear retention keys belong to crack_model = \"fixed\"",
            ));
        }
        for (f, given) in [
            ("viscoplastic", m.viscoplastic.is_some()),
            ("initial_yield_ratio", m.initial_yield_ratio.is_some()),
        ] {
            if given {
                return Err(ctx.err(
                    k(f),
                    "not available with crack_model = \"rotating\" (fixed cracks only)",
                ));
            }
        }
    }
    Ok(())
}

/// The concrete keys that override an MC90 default (ftm, E, strains, crack options, shear
/// retention).
fn concrete_overrides(
    ctx: &Ctx,
    i: usize,
    m: &MaterialIn,
    fcm: f64,
    p: &mut ConcreteParams,
    warnings: &mut Vec<String>,
) -> R<()> {
    let k = |f: &str| format!("materials[{i}].{f}");
    if let Some(ftm) = m.ftm {
        p.ftm = positive(ctx, &k("ftm"), ftm)?;
        units::strength(warnings, ctx, &k("ftm"), ftm);
        if ftm >= 0.5 * fcm {
            return Err(ctx.err(k("ftm"), "must be well below fcm (ftm/fcm < 0.5)"));
        }
        p.ottosen = mc90::ottosen_params(p.ftm, fcm);
    }
    if let Some(e) = m.e {
        p.ec = positive(ctx, &k("E"), e)?;
        units::modulus(warnings, ctx, &k("E"), e);
    }
    if let Some(v) = m.eps_c1 {
        p.eps_c1 = positive(ctx, &k("eps_c1"), v)?;
    }
    if let Some(v) = m.eps_cu {
        p.eps_cu = positive(ctx, &k("eps_cu"), v)?;
    }
    if let Some(v) = m.initial_yield_ratio {
        p.initial_yield_ratio = fraction(ctx, &k("initial_yield_ratio"), v, 0.0, 0.9)?;
    }
    if let Some(v) = m.softening_limit {
        p.softening_limit = positive(ctx, &k("softening_limit"), v)?;
    }
    if let Some(v) = m.crack_ratio {
        p.crack_ratio = fraction(ctx, &k("crack_ratio"), v, 0.0, 1.0)?;
    }
    if let Some(v) = m.residual_stiffness {
        p.residual_stiffness = fraction(ctx, &k("residual_stiffness"), v, 1e-12, 0.1)?;
    }
    if let Some(v) = m.secant_crack_tangent {
        p.secant_crack_tangent = v;
    }
    if let Some(v) = &m.double_crack {
        p.zero_double_crack = match v.as_str() {
            "softening" => false,
            "zero" => true,
            _ => {
                return Err(ctx.err(
                    k("double_crack"),
                    format!("must be \"softening\" or \"zero\", got \"{v}\""),
                ))
            }
        };
    }
    // IMPL-EX by default (docs/theory-concrete.md §5.2, "The default"): with the implicit
    // update the seed beam and the RC example stall soon after cracking.
    if let Some(v) = m.crack_integration.as_deref().or(Some("implex")) {
        p.implex = match v {
            "implicit" => false,
            "implex" => true,
            _ => {
                return Err(ctx.err(
                    k("crack_integration"),
                    format!("must be \"implicit\" or \"implex\", got \"{v}\""),
                ))
            }
        };
    }
    if let Some(v) = m.normalize_equivalent_stress {
        p.normalize_equivalent_stress = v;
    }
    let d = ShearRetention::default();
    p.shear = ShearRetention {
        k1: positive(ctx, &k("shear_k1"), m.shear_k1.unwrap_or(d.k1))?,
        eps_ref: positive(
            ctx,
            &k("shear_eps_ref"),
            m.shear_eps_ref.unwrap_or(d.eps_ref),
        )?,
        beta_min: fraction(
            ctx,
            &k("shear_beta_min"),
            m.shear_beta_min.unwrap_or(d.beta_min),
            1e-9,
            1.0,
        )?,
    };
    Ok(())
}

/// The tension softening (Hinton or crack band) and compression softening (MC90 or crush
/// band) of a concrete.
fn concrete_softening(
    ctx: &Ctx,
    i: usize,
    m: &MaterialIn,
    fcm: f64,
    p: &mut ConcreteParams,
) -> R<()> {
    let k = |f: &str| format!("materials[{i}].{f}");
    p.tension = match m.tension_softening.as_deref() {
        None | Some("hinton") => {
            if m.gf.is_some() {
                return Err(ctx.err(
                    k("Gf"),
                    "Gf is used by tension_softening = \"crack_band\" only",
                ));
            }
            let alpha = m.alpha.unwrap_or(5e-4);
            TensionSoftening::Hinton {
                alpha: positive(ctx, &k("alpha"), alpha)?,
            }
        }
        Some("crack_band") => {
            if m.alpha.is_some() {
                return Err(ctx.err(
                    k("alpha"),
                    "alpha is used by tension_softening = \"hinton\" only",
                ));
            }
            let gf = m.gf.unwrap_or(mc90::fracture_energy(fcm, 30.0));
            TensionSoftening::CrackBand {
                gf: positive(ctx, &k("Gf"), gf)?,
            }
        }
        Some(o) => {
            return Err(ctx.err(
                k("tension_softening"),
                format!("unknown value '{o}' (expected hinton or crack_band)"),
            ))
        }
    };
    p.compression_softening = match m.compression_softening.as_deref() {
        None | Some("mc90") => {
            if m.gc.is_some() {
                return Err(ctx.err(
                    k("Gc"),
                    "Gc is used by compression_softening = \"crush_band\" only",
                ));
            }
            CompressionSoftening::Mc90
        }
        Some("crush_band") => {
            if m.eps_cu.is_some() {
                return Err(ctx.err(
                    k("eps_cu"),
                    "the crush band sets the crushing strain from Gc and the element size; \
                     give eps_cu only with compression_softening = \"mc90\"",
                ));
            }
            let gc = m.gc.unwrap_or(250.0 * mc90::fracture_energy(fcm, 30.0));
            CompressionSoftening::CrushBand {
                gc: positive(ctx, &k("Gc"), gc)?,
            }
        }
        Some(o) => {
            return Err(ctx.err(
                k("compression_softening"),
                format!("unknown value '{o}' (expected mc90 or crush_band)"),
            ))
        }
    };
    Ok(())
}

/// `kind = "rebar"` or `"prestressing_steel"`: the uniaxial law of embedded bars.
fn steel_law(
    ctx: &Ctx,
    i: usize,
    m: &MaterialIn,
    kind: MaterialKind,
    warnings: &mut Vec<String>,
) -> R<SteelParams> {
    let k = |f: &str| format!("materials[{i}].{f}");
    let need = |v: Option<f64>, f: &str| -> R<f64> {
        positive(ctx, &k(f), v.ok_or_else(|| ctx.err(k(f), "missing"))?)
    };
    if kind == MaterialKind::Rebar {
        check_material_keys(ctx, i, m, kind)?;
        let e = need(m.e, "E")?;
        let fy = need(m.fy, "fy")?;
        units::modulus(warnings, ctx, &k("E"), e);
        units::strength(warnings, ctx, &k("fy"), fy);
        if fy >= e {
            return Err(ctx.err(k("fy"), "must be far below E (units are Pa)"));
        }
        match m.et {
            None => Ok(SteelParams::rebar(e, fy)),
            Some(et) if et.is_finite() && (0.0..e).contains(&et) => {
                Ok(SteelParams::rebar_hardening(e, fy, et))
            }
            Some(et) => Err(ctx.err(k("Et"), format!("must lie in [0, E) (got {et})"))),
        }
    } else {
        check_material_keys(ctx, i, m, kind)?;
        let ep = need(m.ep, "Ep")?;
        let fptk = need(m.fptk, "fptk")?;
        units::modulus(warnings, ctx, &k("Ep"), ep);
        units::strength(warnings, ctx, &k("fptk"), fptk);
        if fptk >= ep {
            return Err(ctx.err(k("fptk"), "must be far below Ep (units are Pa)"));
        }
        match m.eps_uk {
            None => Ok(SteelParams::prestressing(ep, fptk)),
            Some(e) if e.is_finite() && e > 0.9 * fptk / ep => {
                Ok(SteelParams::prestressing_hardening(ep, fptk, e))
            }
            Some(e) => Err(ctx.err(
                k("eps_uk"),
                format!(
                    "must exceed the yield strain 0.9 fptk/Ep = {:.5} (got {e})",
                    0.9 * fptk / ep
                ),
            )),
        }
    }
}

/// An `elastic_creep` material: MC90 creep (ageing Maxwell chain) and shrinkage; the
/// modulus follows from fcm (E_ci of MC90), so `E` is not taken.
pub(super) fn creep_material(
    ctx: &Ctx,
    i: usize,
    m: &MaterialIn,
    warnings: &mut Vec<String>,
) -> R<Material> {
    let k = |f: &str| format!("materials[{i}].{f}");
    if m.e.is_some() {
        return Err(ctx.err(
            k("E"),
            "an elastic_creep material takes its modulus from fcm (MC90 E_ci); remove E",
        ));
    }
    check_material_keys(ctx, i, m, MaterialKind::ElasticCreep)?;
    let fcm = positive(
        ctx,
        &k("fcm"),
        m.fcm.ok_or_else(|| ctx.err(k("fcm"), "missing [Pa]"))?,
    )?;
    let (chain, shrinkage) = mc90_creep_keys(ctx, i, m, fcm, warnings)?;
    let (nu, density) = poisson_and_density(ctx, i, m)?;
    Ok(Material::AgeingViscoelastic {
        chain: std::sync::Arc::new(chain),
        nu,
        density,
        cast_day: 0.0,
        shrinkage,
    })
}

/// `creep = "mc90"` of a concrete: the MC90 chain and shrinkage from the same keys as
/// `elastic_creep` (docs/input.md), in series with the crack laws. None without the key; the
/// creep keys are then an error.
fn concrete_creep(
    ctx: &Ctx,
    i: usize,
    m: &MaterialIn,
    fcm: f64,
    warnings: &mut Vec<String>,
) -> R<Option<ConcreteCreep>> {
    let k = |f: &str| format!("materials[{i}].{f}");
    match m.creep.as_deref() {
        None => {
            for (f, given) in [
                ("rh", m.rh.is_some()),
                ("h0", m.h0.is_some()),
                ("cement", m.cement.is_some()),
                ("n_units", m.n_units.is_some()),
                ("shrinkage", m.shrinkage.is_some()),
                ("drying_start", m.drying_start.is_some()),
                ("nonlinear_creep", m.nonlinear_creep.is_some()),
            ] {
                if given {
                    return Err(ctx.err(k(f), "used by creep = \"mc90\" only"));
                }
            }
            Ok(None)
        }
        Some("mc90") => {
            if m.e.is_some() {
                return Err(ctx.err(
                    k("E"),
                    "a creeping concrete takes its modulus from fcm (MC90 E_ci, ageing through \
                     the creep chain); remove E",
                ));
            }
            if m.viscoplastic.is_some() {
                return Err(ctx.err(
                    k("viscoplastic"),
                    "creep and the viscoplastic option are two time laws: choose one",
                ));
            }
            let (chain, shrinkage) = mc90_creep_keys(ctx, i, m, fcm, warnings)?;
            Ok(Some(ConcreteCreep {
                chain: std::sync::Arc::new(chain),
                cast_day: 0.0,
                shrinkage,
                nonlinear: m.nonlinear_creep.unwrap_or(false),
            }))
        }
        Some(o) => Err(ctx.err(k("creep"), format!("unknown value '{o}' (expected mc90)"))),
    }
}

/// The MC90 creep and shrinkage keys shared by `elastic_creep` and the concrete's
/// `creep = "mc90"` (fcm range, rh, h0, cement, n_units, drying_start, shrinkage): the fitted
/// chain and whether shrinkage is on.
fn mc90_creep_keys(
    ctx: &Ctx,
    i: usize,
    m: &MaterialIn,
    fcm: f64,
    warnings: &mut Vec<String>,
) -> R<(crate::materials::chain::MaxwellChain, bool)> {
    use crate::materials::chain::{MaxwellChain, DEFAULT_UNITS};
    use crate::materials::mc90_time::{CementClass, CreepShrinkageParams};
    let k = |f: &str| format!("materials[{i}].{f}");
    if !(5e6..=200e6).contains(&fcm) {
        return Err(ctx.err(
            k("fcm"),
            format!("{fcm} Pa is outside 5–200 MPa; segfem works in Pa (45 MPa = 45e6)"),
        ));
    }
    let rh = m.rh.ok_or_else(|| {
        ctx.err(
            k("rh"),
            "missing (relative humidity as a fraction, 0.7 = 70 %)",
        )
    })?;
    if !(rh.is_finite() && rh > 0.0 && rh <= 1.0) {
        return Err(ctx.err(
            k("rh"),
            format!("must be a fraction in (0, 1] (0.7 = 70 %), got {rh}"),
        ));
    }
    if rh < 0.4 {
        warnings.push(format!(
            "{}: {}: RH = {rh} is below the MC90 range 0.4–1.0 (extrapolated)",
            ctx.file,
            k("rh")
        ));
    }
    let h0 = positive(
        ctx,
        &k("h0"),
        m.h0.ok_or_else(|| ctx.err(k("h0"), "missing (notional size 2 Ac/u [m])"))?,
    )?;
    if h0 > 5.0 {
        return Err(ctx.err(
            k("h0"),
            format!("{h0} m is not a notional size 2 Ac/u in metres"),
        ));
    }
    let cement = match m.cement.as_deref() {
        None | Some("N") => CementClass::N,
        Some("R") => CementClass::R,
        Some("SL") => CementClass::SL,
        Some("RS") => CementClass::RS,
        Some(o) => {
            return Err(ctx.err(
                k("cement"),
                format!("unknown cement class '{o}' (expected SL, N, R or RS)"),
            ))
        }
    };
    let n_units = m.n_units.unwrap_or(DEFAULT_UNITS);
    if !(2..=12).contains(&n_units) {
        return Err(ctx.err(
            k("n_units"),
            format!("must lie in 2 … 12 (got {n_units}; the paper uses 5)"),
        ));
    }
    let drying_start = m.drying_start.unwrap_or(7.0);
    if !(drying_start.is_finite() && drying_start >= 0.0) {
        return Err(ctx.err(
            k("drying_start"),
            format!("must be an age ≥ 0 in days (got {drying_start})"),
        ));
    }
    let p = CreepShrinkageParams::new(fcm, rh, h0, cement, drying_start);
    let chain = MaxwellChain::fit(&p, n_units).map_err(|e| {
        ctx.err(
            k("n_units"),
            format!("creep chain identification failed: {e}"),
        )
    })?;
    Ok((chain, m.shrinkage.unwrap_or(true)))
}

/// The Poisson ratio (required, in (−1, 0.5)) and density (default 0, ≥ 0 [kg/m³]) of a
/// material table.
pub(super) fn poisson_and_density(ctx: &Ctx, i: usize, m: &MaterialIn) -> R<(f64, f64)> {
    let k = |f: &str| format!("materials[{i}].{f}");
    let nu = m.nu.ok_or_else(|| ctx.err(k("nu"), "missing"))?;
    if !(nu > -1.0 && nu < 0.5) {
        return Err(ctx.err(
            k("nu"),
            format!("Poisson ratio must lie in (-1, 0.5) (got {nu})"),
        ));
    }
    let density = m.density.unwrap_or(0.0);
    if !(density.is_finite() && density >= 0.0) {
        return Err(ctx.err(
            k("density"),
            format!("must be zero or positive (got {density})"),
        ));
    }
    Ok((nu, density))
}
