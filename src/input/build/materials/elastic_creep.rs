//! `kind = "elastic_creep"`: ageing linear viscoelastic concrete, MC90 creep (an ageing
//! Maxwell chain) and shrinkage; its creep keys are also those of `creep = "mc90"` of
//! `concrete`.

use super::elastic::{poisson_and_density, DENSITY, NU};
use super::{Key, KeyType, Law, Schema, Table, THERMAL_EXPANSION};
use crate::input::build::fields::positive;
use crate::input::build::loads::ALPHA_CONCRETE;
use crate::input::build::R;
use crate::materials::chain::{MaxwellChain, DEFAULT_UNITS};
use crate::materials::mc90::{self, TensileRef};
use crate::materials::mc90_time::{CementClass, CreepShrinkageParams};
use crate::materials::point::Material;
use crate::model::Strength;

/// The MC90 creep and shrinkage keys besides `fcm` (shared with `concrete`'s
/// `creep = "mc90"`).
pub(super) const CREEP_KEYS: [Key; 6] = [
    Key::number(
        "rh",
        "-",
        "required",
        "relative humidity as a fraction in (0, 1]",
    ),
    Key::number(
        "h0",
        "m",
        "required",
        "notional size 2 A_c/u, > 0 and ≤ 5 m",
    ),
    Key::typed(
        "cement",
        KeyType::Text,
        "N",
        "MC90 cement class SL, N, R or RS",
    ),
    Key::typed(
        "n_units",
        KeyType::Count,
        "5",
        "Maxwell units of the chain, 2 … 12",
    ),
    Key::typed(
        "shrinkage",
        KeyType::Flag,
        "true",
        "include MC90 drying shrinkage",
    ),
    Key::number(
        "drying_start",
        "d",
        "7",
        "concrete age at the start of drying, ≥ 0",
    ),
];

/// The schema of `kind = "elastic_creep"`.
pub(super) const SCHEMA: Schema = Schema {
    name: "elastic_creep",
    keys: &[
        Key::number(
            "fcm",
            "Pa",
            "required",
            "mean 28-day compressive strength, 5–200 MPa",
        ),
        NU,
        DENSITY,
        CREEP_KEYS[0],
        CREEP_KEYS[1],
        CREEP_KEYS[2],
        CREEP_KEYS[3],
        CREEP_KEYS[4],
        CREEP_KEYS[5],
        THERMAL_EXPANSION,
    ],
    refused: &[(
        "E",
        "an elastic_creep material takes its modulus from fcm (MC90 E_ci); remove E",
    )],
    thermal_expansion: Some(ALPHA_CONCRETE),
    build,
};

/// MC90 creep (ageing Maxwell chain) and shrinkage; the modulus follows from fcm (E_ci of
/// MC90), so `E` is not taken. Checked against its f_cm like an elastic material, with the
/// concrete kind's default f_tm.
fn build(t: &Table, warnings: &mut Vec<String>) -> R<Law> {
    let fcm = positive(t.ctx(), &t.key("fcm"), t.need("fcm", "missing [Pa]")?)?;
    let (chain, shrinkage) = mc90_creep(t, fcm, warnings)?;
    let (nu, density) = poisson_and_density(t)?;
    let law = Material::AgeingViscoelastic {
        chain: std::sync::Arc::new(chain),
        nu,
        density,
        cast_day: 0.0,
        shrinkage,
    };
    let ftm = mc90::f_tm(fcm, mc90::C_MEAN, TensileRef::Fcm);
    Ok(Law::Region {
        law,
        strength: Some(Strength { fcm, ftm }),
    })
}

/// The MC90 creep and shrinkage keys shared by `elastic_creep` and the concrete's
/// `creep = "mc90"` (fcm range, rh, h0, cement, n_units, drying_start, shrinkage): the fitted
/// chain and whether shrinkage is on.
pub(super) fn mc90_creep(
    t: &Table,
    fcm: f64,
    warnings: &mut Vec<String>,
) -> R<(MaxwellChain, bool)> {
    if !(5e6..=200e6).contains(&fcm) {
        return Err(t.err(
            "fcm",
            format!("{fcm} Pa is outside 5–200 MPa; segfem works in Pa (45 MPa = 45e6)"),
        ));
    }
    let rh = t.need(
        "rh",
        "missing (relative humidity as a fraction, 0.7 = 70 %)",
    )?;
    if !(rh.is_finite() && rh > 0.0 && rh <= 1.0) {
        return Err(t.err(
            "rh",
            format!("must be a fraction in (0, 1] (0.7 = 70 %), got {rh}"),
        ));
    }
    if rh < 0.4 {
        warnings.push(format!(
            "{}: {}: RH = {rh} is below the MC90 range 0.4–1.0 (extrapolated)",
            t.ctx().file,
            t.key("rh")
        ));
    }
    let h0 = positive(
        t.ctx(),
        &t.key("h0"),
        t.need("h0", "missing (notional size 2 Ac/u [m])")?,
    )?;
    if h0 > 5.0 {
        return Err(t.err(
            "h0",
            format!("{h0} m is not a notional size 2 Ac/u in metres"),
        ));
    }
    let cement = match t.text("cement") {
        None | Some("N") => CementClass::N,
        Some("R") => CementClass::R,
        Some("SL") => CementClass::SL,
        Some("RS") => CementClass::RS,
        Some(o) => {
            return Err(t.err(
                "cement",
                format!("unknown cement class '{o}' (expected SL, N, R or RS)"),
            ))
        }
    };
    let n_units = t.count("n_units").unwrap_or(DEFAULT_UNITS);
    if !(2..=12).contains(&n_units) {
        return Err(t.err(
            "n_units",
            format!("must lie in 2 … 12 (got {n_units}; the paper uses 5)"),
        ));
    }
    let drying_start = t.num("drying_start").unwrap_or(7.0);
    if !(drying_start.is_finite() && drying_start >= 0.0) {
        return Err(t.err(
            "drying_start",
            format!("must be an age ≥ 0 in days (got {drying_start})"),
        ));
    }
    let p = CreepShrinkageParams::new(fcm, rh, h0, cement, drying_start);
    let chain = MaxwellChain::fit(&p, n_units)
        .map_err(|e| t.err("n_units", format!("creep chain identification failed: {e}")))?;
    Ok((chain, t.flag("shrinkage").unwrap_or(true)))
}
