//! `kind = "concrete"`: plane-stress concrete, MC90/Ottosen plasticity and smeared
//! cracking (fixed or rotating), with its options: tension and compression softening, shear
//! retention, compression softening of cracked concrete, viscoplasticity, MC90 creep.

use super::elastic::DENSITY;
use super::elastic_creep::{mc90_creep, CREEP_KEYS};
use super::{Key, KeyType, Law, Schema, Table, THERMAL_EXPANSION};
use crate::input::build::fields::{fraction, positive};
use crate::input::build::loads::ALPHA_CONCRETE;
use crate::input::build::R;
use crate::input::units;
use crate::materials::concrete::creep::ConcreteCreep;
use crate::materials::concrete::{
    CompressionSoftening, ConcreteParams, ShearRetention, TensionSoftening,
};
use crate::materials::mc90::{self, TensileRef};
use crate::materials::point::Material;

/// A string-valued key.
const fn text(name: &'static str, default: &'static str, doc: &'static str) -> Key {
    Key::typed(name, KeyType::Text, default, doc)
}

/// The keys of `viscoplastic = { ... }` (Owen–Hinton option).
const VISCOPLASTIC_KEYS: &[Key] = &[
    Key::number("fluidity", "1/d", "required", "fluidity γ > 0, per day"),
    text(
        "overstress",
        "linear",
        "overstress function: linear, power or exponential",
    ),
    Key::number(
        "exponent",
        "-",
        "none",
        "N of the power law or M of the exponential, > 0",
    ),
    Key::number("theta", "-", "0", "Θ of the substeps, 0 … 1"),
    Key::number("safety", "-", "0.5", "critical time step factor, in (0, 1]"),
    Key::number(
        "tau",
        "-",
        "0.1",
        "substep as a fraction of the overstress relaxation time, in (0, 1]",
    ),
    text(
        "load_steps",
        "steady",
        "load steps: steady (elastoplastic) or elastic",
    ),
];

/// The schema of `kind = "concrete"`.
pub(super) const SCHEMA: Schema = Schema {
    name: "concrete",
    keys: &[
        Key::number("fcm", "Pa", "required", "mean compressive strength"),
        Key::number(
            "E",
            "Pa",
            "MC90 E_ci from fcm",
            "elastic modulus (not with creep)",
        ),
        Key::number("nu", "-", "0.2", "Poisson ratio (uncracked), in [0, 0.499]"),
        DENSITY,
        Key::number(
            "ftm",
            "Pa",
            "MC90 with C",
            "tensile strength, below 0.5 fcm",
        ),
        Key::number("C", "-", "0.14", "MC90 coefficient of ftm, in (0, 1)"),
        text(
            "tensile_reference",
            "fcm",
            "f_ref of the ftm formula: fcm or fck",
        ),
        text(
            "tension_softening",
            "hinton",
            "tension softening: hinton or crack_band",
        ),
        Key::number("alpha", "-", "5e-4", "decay strain of the Hinton law"),
        Key::number(
            "Gf",
            "N/m",
            "MC90, G_f0 = 30 N/m",
            "fracture energy of the crack band",
        ),
        Key::number("eps_c1", "-", "0.0022", "strain at the MC90 peak"),
        Key::number("eps_cu", "-", "0.0035", "crushing strain"),
        text(
            "compression_softening",
            "mc90",
            "post-peak law in compression: mc90 or crush_band",
        ),
        Key::number(
            "Gc",
            "N/m",
            "250 × MC90 G_f",
            "compressive fracture energy of the crush band",
        ),
        Key::number(
            "initial_yield_ratio",
            "-",
            "0 (0.4 with creep)",
            "σ_c0/fcm, elastic range in compression, in [0, 0.9]",
        ),
        Key::number(
            "softening_limit",
            "-",
            "0.25",
            "bound of the post-peak plastic modulus",
        ),
        Key::number(
            "crack_ratio",
            "-",
            "0.5",
            "σ1/ftm at the failure surface above which a point cracks",
        ),
        Key::number("shear_k1", "-", "0.075", "k1 of the seed's shear retention"),
        Key::number(
            "shear_eps_ref",
            "-",
            "0.005",
            "ε_ref of the seed's shear retention",
        ),
        Key::number(
            "shear_beta_min",
            "-",
            "1e-3",
            "floor of the shear retention factor",
        ),
        Key::number(
            "residual_stiffness",
            "-",
            "1e-6",
            "tangent ratio of stress-free points",
        ),
        Key::typed(
            "secant_crack_tangent",
            KeyType::Flag,
            "false",
            "secant tangent of cracked points",
        ),
        text(
            "double_crack",
            "softening",
            "two open cracks: softening or zero",
        ),
        text(
            "crack_integration",
            "implex",
            "crack laws: implex or implicit",
        ),
        text(
            "compression_integration",
            "implicit",
            "compression plasticity: implicit or implex (needs crack_integration = implex)",
        ),
        Key::typed(
            "normalize_equivalent_stress",
            KeyType::Flag,
            "true",
            "uniaxial compression follows the MC90 curve exactly",
        ),
        Key::typed(
            "viscoplastic",
            KeyType::Table(VISCOPLASTIC_KEYS),
            "none",
            "Owen–Hinton elasto-viscoplastic compression plasticity",
        ),
        text("crack_model", "fixed", "fixed or rotating cracks"),
        text(
            "compression_reduction",
            "none",
            "compression softening of cracked concrete: none or vecchio_collins_1993",
        ),
        Key::number(
            "compression_reduction_min",
            "-",
            "0.4",
            "lower bound of β_d, in [1e-3, 1]",
        ),
        Key::number(
            "compression_reduction_spacing",
            "m",
            "none (the crack band)",
            "mean crack spacing for β_d, > 0",
        ),
        text(
            "shear_retention",
            "seed",
            "shear retention of fixed cracks: seed or aggregate",
        ),
        Key::number(
            "aggregate_size",
            "m",
            "0.016",
            "d_agg of aggregate interlock and crack_shear_limit",
        ),
        text(
            "crack_shear_limit",
            "none",
            "shear cap across fixed cracks: none or vecchio_collins_1986",
        ),
        text(
            "principal_stress_limit",
            "none",
            "cut-off of fixed cracks: none, tensile_strength or softening",
        ),
        text("creep", "none", "mc90: MC90 creep and shrinkage in series"),
        CREEP_KEYS[0],
        CREEP_KEYS[1],
        CREEP_KEYS[2],
        CREEP_KEYS[3],
        CREEP_KEYS[4],
        CREEP_KEYS[5],
        Key::typed(
            "nonlinear_creep",
            KeyType::Flag,
            "false",
            "MC90 stress-dependent creep above 0.4 fcm (with creep)",
        ),
        THERMAL_EXPANSION,
    ],
    refused: &[],
    thermal_expansion: Some(ALPHA_CONCRETE),
    build,
};

/// `viscoplastic = { ... }` of a concrete: the Owen–Hinton option (docs/input.md).
fn viscoplastic_option(t: &Table) -> R<crate::materials::concrete::compression::Viscoplastic> {
    use crate::materials::viscoplastic::OverstressFunction;
    let d = crate::materials::concrete::compression::Viscoplastic::default();
    let fluidity = positive(
        t.ctx(),
        &t.key("fluidity"),
        t.num("fluidity")
            .ok_or_else(|| t.err("fluidity", "missing (fluidity γ [1/d])"))?,
    )?;
    let exponent = t
        .num("exponent")
        .map(|e| positive(t.ctx(), &t.key("exponent"), e))
        .transpose()?;
    let overstress = match (t.text("overstress"), exponent) {
        (None | Some("linear"), None) => OverstressFunction::Linear,
        (None | Some("linear"), Some(_)) => {
            return Err(t.err(
                "exponent",
                "is used by overstress = \"power\" or \"exponential\" only",
            ))
        }
        (Some("power"), Some(n)) => OverstressFunction::Power(n),
        (Some("exponential"), Some(m)) => OverstressFunction::Exponential(m),
        (Some("power" | "exponential"), None) => {
            return Err(t.err(
                "exponent",
                "missing (N of the power law, M of the exponential)",
            ))
        }
        (Some(o), _) => {
            return Err(t.err(
                "overstress",
                format!("unknown value '{o}' (expected linear, power or exponential)"),
            ))
        }
    };
    let load_steps = match t.text("load_steps") {
        None | Some("steady") => true,
        Some("elastic") => false,
        Some(o) => {
            return Err(t.err(
                "load_steps",
                format!("unknown value '{o}' (expected steady or elastic)"),
            ))
        }
    };
    Ok(crate::materials::concrete::compression::Viscoplastic {
        fluidity,
        overstress,
        theta: fraction(
            t.ctx(),
            &t.key("theta"),
            t.num("theta").unwrap_or(d.theta),
            0.0,
            1.0,
        )?,
        safety: fraction(
            t.ctx(),
            &t.key("safety"),
            t.num("safety").unwrap_or(d.safety),
            1e-3,
            1.0,
        )?,
        tau: fraction(
            t.ctx(),
            &t.key("tau"),
            t.num("tau").unwrap_or(d.tau),
            1e-4,
            1.0,
        )?,
        steady_load_steps: load_steps,
    })
}

/// `kind = "concrete"`: MC90 defaults from f_cm, each overridable.
fn build(t: &Table, warnings: &mut Vec<String>) -> R<Law> {
    let fcm = positive(
        t.ctx(),
        &t.key("fcm"),
        t.num("fcm")
            .ok_or_else(|| t.err("fcm", "missing (mean compressive strength [Pa])"))?,
    )?;
    if fcm < 1e6 {
        warnings.push(format!(
            "{}: {}: fcm = {fcm} Pa looks like MPa; segfem works in Pa",
            t.ctx().file,
            t.key("fcm")
        ));
    }
    let nu = fraction(
        t.ctx(),
        &t.key("nu"),
        t.num("nu").unwrap_or(0.2),
        0.0,
        0.499,
    )?;
    let density = t.num("density").unwrap_or(0.0);
    if !(density.is_finite() && density >= 0.0) {
        return Err(t.err("density", "must be zero or positive"));
    }
    let tref = match t.text("tensile_reference") {
        None | Some("fcm") => TensileRef::Fcm,
        Some("fck") => TensileRef::Fck,
        Some(o) => {
            return Err(t.err(
                "tensile_reference",
                format!("unknown value '{o}' (expected fcm or fck)"),
            ))
        }
    };
    if t.has("ftm") && t.has("C") {
        return Err(t.err("C", "give ftm or C, not both"));
    }
    let c = t.num("C").unwrap_or(mc90::C_MEAN);
    if !(c > 0.0 && c < 1.0) {
        return Err(t.err(
            "C",
            format!("must lie in (0, 1) (MC90: 0.095–0.185; got {c})"),
        ));
    }
    let mut p = ConcreteParams::from_mc90_with(fcm, nu, c, tref);
    concrete_overrides(t, fcm, &mut p, warnings)?;
    concrete_softening(t, fcm, &mut p)?;
    if let Some(v) = &t.sub("viscoplastic") {
        p.viscoplastic = Some(viscoplastic_option(v)?);
    }
    shear_options(t, &mut p)?;
    p.creep = concrete_creep(t, fcm, warnings)?;
    if p.creep.is_some()
        && t.num("initial_yield_ratio").is_none()
        && p.crack_model == crate::materials::concrete::CrackModel::Fixed
    {
        // MC90 creep is linear up to 0.4 f_cm and its compliance holds the whole strain
        // there: the compression plasticity starts at that stress (docs/theory-time.md §9).
        p.initial_yield_ratio = 0.4;
    }
    if p.compression_implex {
        // The extrapolated stress is built on the load-increment route of fixed-crack
        // concrete alone (docs/theory-concrete.md §4, "IMPL-EX in compression").
        for (with, on) in [
            ("creep", p.creep.is_some()),
            ("viscoplastic", p.viscoplastic.is_some()),
            (
                "crack_model = \"rotating\"",
                p.crack_model == crate::materials::concrete::CrackModel::Rotating,
            ),
        ] {
            if on {
                return Err(t.err(
                    "compression_integration",
                    format!("\"implex\" is not available with {with} (fixed cracks, load increments only)"),
                ));
            }
        }
    }
    p.validate().map_err(|e| t.table_err(e.to_string()))?;
    // Cracking and crushing are the law's own: no strength check.
    Ok(Law::Region {
        law: Material::Concrete {
            params: Box::new(p),
            density,
        },
        strength: None,
    })
}

/// The concrete keys of shear behaviour: crack model, compression softening of cracked
/// concrete, shear retention of fixed cracks (docs/input.md).
fn shear_options(t: &Table, p: &mut ConcreteParams) -> R<()> {
    use crate::materials::concrete::cracking::{CrackShearLimit, PrincipalStressLimit};
    use crate::materials::concrete::{CompressionReduction, CrackModel, ShearRetentionLaw};
    p.crack_model = match t.text("crack_model") {
        None | Some("fixed") => CrackModel::Fixed,
        Some("rotating") => CrackModel::Rotating,
        Some(o) => {
            return Err(t.err(
                "crack_model",
                format!("unknown value '{o}' (expected fixed or rotating)"),
            ))
        }
    };
    p.compression_reduction = match t.text("compression_reduction") {
        None | Some("none") => {
            for (key, set) in [
                (
                    "compression_reduction_min",
                    t.has("compression_reduction_min"),
                ),
                (
                    "compression_reduction_spacing",
                    t.has("compression_reduction_spacing"),
                ),
            ] {
                if set {
                    return Err(t.err(
                        key,
                        "used by compression_reduction = \"vecchio_collins_1993\" only",
                    ));
                }
            }
            CompressionReduction::None
        }
        Some("vecchio_collins_1993") => CompressionReduction::VecchioCollins1993 {
            beta_min: fraction(
                t.ctx(),
                &t.key("compression_reduction_min"),
                t.num("compression_reduction_min").unwrap_or(0.4),
                1e-3,
                1.0,
            )?,
            spacing: match t.num("compression_reduction_spacing") {
                Some(s) => positive(t.ctx(), &t.key("compression_reduction_spacing"), s)?,
                None => 0.0,
            },
        },
        Some(o) => {
            return Err(t.err(
                "compression_reduction",
                format!("unknown value '{o}' (expected none or vecchio_collins_1993)"),
            ))
        }
    };
    let seed_keys = t.has("shear_k1") || t.has("shear_eps_ref");
    p.shear_retention = match t.text("shear_retention") {
        None | Some("seed") => {
            if t.has("aggregate_size") && t.text("crack_shear_limit").is_none() {
                return Err(t.err(
                    "aggregate_size",
                    "used by shear_retention = \"aggregate\" and crack_shear_limit only",
                ));
            }
            ShearRetentionLaw::Seed
        }
        Some("aggregate") if seed_keys => {
            return Err(t.err(
                "shear_retention",
                "shear_k1 and shear_eps_ref belong to shear_retention = \"seed\"",
            ))
        }
        Some("aggregate") => ShearRetentionLaw::Aggregate {
            d_agg: positive(
                t.ctx(),
                &t.key("aggregate_size"),
                t.num("aggregate_size").unwrap_or(0.016),
            )?,
        },
        Some(o) => {
            return Err(t.err(
                "shear_retention",
                format!("unknown value '{o}' (expected seed or aggregate)"),
            ))
        }
    };
    p.crack_shear_limit = match t.text("crack_shear_limit") {
        None | Some("none") => CrackShearLimit::None,
        Some("vecchio_collins_1986") => CrackShearLimit::VecchioCollins1986 {
            d_agg: positive(
                t.ctx(),
                &t.key("aggregate_size"),
                t.num("aggregate_size").unwrap_or(0.016),
            )?,
        },
        Some(o) => {
            return Err(t.err(
                "crack_shear_limit",
                format!("unknown value '{o}' (expected none or vecchio_collins_1986)"),
            ))
        }
    };
    p.principal_stress_limit = match t.text("principal_stress_limit") {
        None | Some("none") => PrincipalStressLimit::None,
        Some("tensile_strength") => PrincipalStressLimit::TensileStrength,
        Some("softening") => PrincipalStressLimit::Softening,
        Some(o) => {
            return Err(t.err(
                "principal_stress_limit",
                format!("unknown value '{o}' (expected none, tensile_strength or softening)"),
            ))
        }
    };
    if p.crack_model == CrackModel::Rotating {
        if t.has("principal_stress_limit") {
            return Err(t.err("principal_stress_limit",
                "rotating cracks follow the principal stress: principal_stress_limit belongs to crack_model = \"fixed\"",
            ));
        }
        if t.has("crack_shear_limit") {
            return Err(t.err("crack_shear_limit",
                "rotating cracks carry no shear across cracks: crack_shear_limit belongs to crack_model = \"fixed\"",
            ));
        }
        if t.has("shear_retention") || seed_keys || t.has("shear_beta_min") {
            return Err(t.err("shear_retention",
                "rotating cracks carry no shear across cracks: shear retention keys belong to crack_model = \"fixed\"",
            ));
        }
        for (f, given) in [
            ("viscoplastic", t.has("viscoplastic")),
            ("initial_yield_ratio", t.has("initial_yield_ratio")),
        ] {
            if given {
                return Err(t.err(
                    f,
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
    t: &Table,
    fcm: f64,
    p: &mut ConcreteParams,
    warnings: &mut Vec<String>,
) -> R<()> {
    if let Some(ftm) = t.num("ftm") {
        p.ftm = positive(t.ctx(), &t.key("ftm"), ftm)?;
        units::strength(warnings, t.ctx(), &t.key("ftm"), ftm);
        if ftm >= 0.5 * fcm {
            return Err(t.err("ftm", "must be well below fcm (ftm/fcm < 0.5)"));
        }
        p.ottosen = mc90::ottosen_params(p.ftm, fcm);
    }
    if let Some(e) = t.num("E") {
        p.ec = positive(t.ctx(), &t.key("E"), e)?;
        units::modulus(warnings, t.ctx(), &t.key("E"), e);
    }
    if let Some(v) = t.num("eps_c1") {
        p.eps_c1 = positive(t.ctx(), &t.key("eps_c1"), v)?;
    }
    if let Some(v) = t.num("eps_cu") {
        p.eps_cu = positive(t.ctx(), &t.key("eps_cu"), v)?;
    }
    if let Some(v) = t.num("initial_yield_ratio") {
        p.initial_yield_ratio = fraction(t.ctx(), &t.key("initial_yield_ratio"), v, 0.0, 0.9)?;
    }
    if let Some(v) = t.num("softening_limit") {
        p.softening_limit = positive(t.ctx(), &t.key("softening_limit"), v)?;
    }
    if let Some(v) = t.num("crack_ratio") {
        p.crack_ratio = fraction(t.ctx(), &t.key("crack_ratio"), v, 0.0, 1.0)?;
    }
    if let Some(v) = t.num("residual_stiffness") {
        p.residual_stiffness = fraction(t.ctx(), &t.key("residual_stiffness"), v, 1e-12, 0.1)?;
    }
    if let Some(v) = t.flag("secant_crack_tangent") {
        p.secant_crack_tangent = v;
    }
    if let Some(v) = t.text("double_crack") {
        p.zero_double_crack = match v {
            "softening" => false,
            "zero" => true,
            _ => {
                return Err(t.err(
                    "double_crack",
                    format!("must be \"softening\" or \"zero\", got \"{v}\""),
                ))
            }
        };
    }
    // IMPL-EX by default (docs/theory-concrete.md §5.2, "The default"): with the implicit
    // update the seed beam and the RC example stall soon after cracking.
    if let Some(v) = t.text("crack_integration").or(Some("implex")) {
        p.implex = match v {
            "implicit" => false,
            "implex" => true,
            _ => {
                return Err(t.err(
                    "crack_integration",
                    format!("must be \"implicit\" or \"implex\", got \"{v}\""),
                ))
            }
        };
    }
    if let Some(v) = t.text("compression_integration") {
        p.compression_implex = match v {
            "implicit" => false,
            "implex" if p.implex => true,
            "implex" => {
                return Err(t.err(
                    "compression_integration",
                    "\"implex\" needs crack_integration = \"implex\" (the increment's extrapolation ratio comes with it)".to_string(),
                ))
            }
            _ => {
                return Err(t.err(
                    "compression_integration",
                    format!("must be \"implicit\" or \"implex\", got \"{v}\""),
                ))
            }
        };
    }
    if let Some(v) = t.flag("normalize_equivalent_stress") {
        p.normalize_equivalent_stress = v;
    }
    let d = ShearRetention::default();
    p.shear = ShearRetention {
        k1: positive(
            t.ctx(),
            &t.key("shear_k1"),
            t.num("shear_k1").unwrap_or(d.k1),
        )?,
        eps_ref: positive(
            t.ctx(),
            &t.key("shear_eps_ref"),
            t.num("shear_eps_ref").unwrap_or(d.eps_ref),
        )?,
        beta_min: fraction(
            t.ctx(),
            &t.key("shear_beta_min"),
            t.num("shear_beta_min").unwrap_or(d.beta_min),
            1e-9,
            1.0,
        )?,
    };
    Ok(())
}

/// The tension softening (Hinton or crack band) and compression softening (MC90 or crush
/// band) of a concrete.
fn concrete_softening(t: &Table, fcm: f64, p: &mut ConcreteParams) -> R<()> {
    p.tension = match t.text("tension_softening") {
        None | Some("hinton") => {
            if t.has("Gf") {
                return Err(t.err(
                    "Gf",
                    "Gf is used by tension_softening = \"crack_band\" only",
                ));
            }
            let alpha = t.num("alpha").unwrap_or(5e-4);
            TensionSoftening::Hinton {
                alpha: positive(t.ctx(), &t.key("alpha"), alpha)?,
            }
        }
        Some("crack_band") => {
            if t.has("alpha") {
                return Err(t.err(
                    "alpha",
                    "alpha is used by tension_softening = \"hinton\" only",
                ));
            }
            let gf = t.num("Gf").unwrap_or(mc90::fracture_energy(fcm, 30.0));
            TensionSoftening::CrackBand {
                gf: positive(t.ctx(), &t.key("Gf"), gf)?,
            }
        }
        Some(o) => {
            return Err(t.err(
                "tension_softening",
                format!("unknown value '{o}' (expected hinton or crack_band)"),
            ))
        }
    };
    p.compression_softening = match t.text("compression_softening") {
        None | Some("mc90") => {
            if t.has("Gc") {
                return Err(t.err(
                    "Gc",
                    "Gc is used by compression_softening = \"crush_band\" only",
                ));
            }
            CompressionSoftening::Mc90
        }
        Some("crush_band") => {
            if t.has("eps_cu") {
                return Err(t.err(
                    "eps_cu",
                    "the crush band sets the crushing strain from Gc and the element size; \
                     give eps_cu only with compression_softening = \"mc90\"",
                ));
            }
            let gc = t
                .num("Gc")
                .unwrap_or(250.0 * mc90::fracture_energy(fcm, 30.0));
            CompressionSoftening::CrushBand {
                gc: positive(t.ctx(), &t.key("Gc"), gc)?,
            }
        }
        Some(o) => {
            return Err(t.err(
                "compression_softening",
                format!("unknown value '{o}' (expected mc90 or crush_band)"),
            ))
        }
    };
    Ok(())
}

/// `creep = "mc90"` of a concrete: the MC90 chain and shrinkage from the same keys as
/// `elastic_creep` (docs/input.md), in series with the crack laws. None without the key; the
/// creep keys are then an error.
fn concrete_creep(t: &Table, fcm: f64, warnings: &mut Vec<String>) -> R<Option<ConcreteCreep>> {
    match t.text("creep") {
        None => {
            let keys = CREEP_KEYS.iter().map(|k| k.name);
            for f in keys.chain(["nonlinear_creep"]) {
                if t.has(f) {
                    return Err(t.err(f, "used by creep = \"mc90\" only"));
                }
            }
            Ok(None)
        }
        Some("mc90") => {
            if t.has("E") {
                return Err(t.err(
                    "E",
                    "a creeping concrete takes its modulus from fcm (MC90 E_ci, ageing through \
                     the creep chain); remove E",
                ));
            }
            if t.has("viscoplastic") {
                return Err(t.err(
                    "viscoplastic",
                    "creep and the viscoplastic option are two time laws: choose one",
                ));
            }
            let (chain, shrinkage) = mc90_creep(t, fcm, warnings)?;
            Ok(Some(ConcreteCreep {
                chain: std::sync::Arc::new(chain),
                cast_day: 0.0,
                shrinkage,
                nonlinear: t.flag("nonlinear_creep").unwrap_or(false),
            }))
        }
        Some(o) => Err(t.err("creep", format!("unknown value '{o}' (expected mc90)"))),
    }
}
