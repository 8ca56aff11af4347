//! `kind = "elastic"`: linear elastic isotropic, optionally checked against a concrete
//! strength (`fcm` with `ftm`, or an EN class).

use super::{Key, KeyType, Law, Schema, Table, THERMAL_EXPANSION};
use crate::input::build::fields::positive;
use crate::input::build::R;
use crate::input::units;
use crate::materials::mc90::{self, TensileRef};
use crate::materials::point::Material;
use crate::model::Strength;

/// `nu` of `elastic` and `elastic_creep`.
pub(super) const NU: Key = Key::number("nu", "-", "required", "Poisson ratio, −1 < ν < 0.5");
/// `density` of every continuum kind.
pub(super) const DENSITY: Key = Key::number(
    "density",
    "kg/m³",
    "0",
    "mass density, ≥ 0; used only by gravity loads",
);

/// The schema of `kind = "elastic"`.
pub(super) const SCHEMA: Schema = Schema {
    name: "elastic",
    keys: &[
        Key::number("E", "Pa", "required", "Young's modulus, > 0"),
        NU,
        DENSITY,
        Key::number(
            "fcm",
            "Pa",
            "none",
            "mean compressive strength the stresses are checked against",
        ),
        Key::number(
            "ftm",
            "Pa",
            "from fcm or class",
            "mean tensile strength checked against (with fcm or class)",
        ),
        Key::typed(
            "class",
            KeyType::Text,
            "none",
            "EN 1992-1-1 strength class C12/15 … C90/105, instead of fcm",
        ),
        THERMAL_EXPANSION,
    ],
    refused: &[],
    // It could be concrete or steel: a thermal case heating it needs the key.
    thermal_expansion: None,
    build,
};

/// E (required), ν and density, then the strength checked against.
fn build(t: &Table, warnings: &mut Vec<String>) -> R<Law> {
    let ctx = t.ctx();
    let e = positive(ctx, &t.key("E"), t.need("E", "missing")?)?;
    let (nu, density) = poisson_and_density(t)?;
    units::modulus(warnings, ctx, &t.key("E"), e);
    if density > 0.0 && !(100.0..=20000.0).contains(&density) {
        warnings.push(format!(
            "{}: {}: density {density} kg/m³ is unusual; segfem works in kg/m³",
            ctx.file,
            t.key("density")
        ));
    }
    Ok(Law::Region {
        law: Material::Elastic { e, nu, density },
        strength: strength(t, warnings)?,
    })
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
fn strength(t: &Table, warnings: &mut Vec<String>) -> R<Option<Strength>> {
    let ctx = t.ctx();
    if let Some(c) = t.text("class") {
        if t.has("fcm") {
            return Err(t.err("fcm", "give class or fcm, not both"));
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
            .find(|(a, b)| c == format!("C{a}/{b}"))
            .map(|(a, _)| f64::from(*a))
            .ok_or_else(|| {
                t.err(
                    "class",
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
        let ftm = match t.num("ftm") {
            Some(f) => positive(ctx, &t.key("ftm"), f)?,
            None => fctm * 1e6,
        };
        return Ok(Some(Strength {
            fcm: fcm * 1e6,
            ftm,
        }));
    }
    match (t.num("fcm"), t.num("ftm")) {
        (None, None) => Ok(None),
        (None, Some(_)) => Err(t.err(
            "ftm",
            "needs fcm or class (the compressive strength to check against)",
        )),
        (Some(fcm), ftm) => {
            let fcm = positive(ctx, &t.key("fcm"), fcm)?;
            if fcm < 1e6 {
                warnings.push(format!(
                    "{}: {}: fcm = {fcm} Pa looks like MPa; segfem works in Pa",
                    ctx.file,
                    t.key("fcm")
                ));
            }
            let ftm = match ftm {
                Some(f) => positive(ctx, &t.key("ftm"), f)?,
                None => mc90::f_tm(fcm, mc90::C_MEAN, TensileRef::Fcm),
            };
            Ok(Some(Strength { fcm, ftm }))
        }
    }
}

/// The Poisson ratio (required, in (−1, 0.5)) and density (default 0, ≥ 0 [kg/m³]) of a
/// material table.
pub(super) fn poisson_and_density(t: &Table) -> R<(f64, f64)> {
    let nu = t.need("nu", "missing")?;
    if !(nu > -1.0 && nu < 0.5) {
        return Err(t.err(
            "nu",
            format!("Poisson ratio must lie in (-1, 0.5) (got {nu})"),
        ));
    }
    let density = t.num("density").unwrap_or(0.0);
    if !(density.is_finite() && density >= 0.0) {
        return Err(t.err(
            "density",
            format!("must be zero or positive (got {density})"),
        ));
    }
    Ok((nu, density))
}
