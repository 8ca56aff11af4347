//! `kind = "rebar"`: reinforcing steel of bars, elastic–perfectly plastic or with linear
//! kinematic hardening.

use super::{Key, Law, Schema, Table, THERMAL_EXPANSION};
use crate::input::build::loads::ALPHA_STEEL;
use crate::input::build::R;
use crate::materials::steel::SteelParams;

/// The schema of `kind = "rebar"`.
pub(super) const SCHEMA: Schema = Schema {
    name: "rebar",
    keys: &[
        Key::number("E", "Pa", "required", "Young's modulus, > 0"),
        Key::number(
            "fy",
            "Pa",
            "required",
            "yield strength, > 0 and far below E",
        ),
        Key::number(
            "Et",
            "Pa",
            "none (perfectly plastic)",
            "hardening tangent after yield, in [0, E)",
        ),
        THERMAL_EXPANSION,
    ],
    refused: &[],
    thermal_expansion: Some(ALPHA_STEEL),
    build,
};

/// The uniaxial law of embedded bars.
fn build(t: &Table, warnings: &mut Vec<String>) -> R<Law> {
    let (e, fy) = t.steel_modulus_and_strength(warnings, "E", "fy")?;
    Ok(Law::Bar(match t.num("Et") {
        None => SteelParams::rebar(e, fy),
        Some(et) if et.is_finite() && (0.0..e).contains(&et) => {
            SteelParams::rebar_hardening(e, fy, et)
        }
        Some(et) => return Err(t.err("Et", format!("must lie in [0, E) (got {et})"))),
    }))
}
