//! `kind = "prestressing_steel"`: strand and wire of bonded tendons and bars, elastic to
//! 0.9 f_ptk then plastic, or hardening to f_ptk at ε_uk.

use super::{Key, Law, Schema, Table, THERMAL_EXPANSION};
use crate::input::build::loads::ALPHA_STEEL;
use crate::input::build::R;
use crate::materials::steel::SteelParams;

/// The schema of `kind = "prestressing_steel"`.
pub(super) const SCHEMA: Schema = Schema {
    name: "prestressing_steel",
    keys: &[
        Key::number("Ep", "Pa", "required", "Young's modulus, > 0"),
        Key::number(
            "fptk",
            "Pa",
            "required",
            "characteristic tensile strength, > 0 and far below Ep",
        ),
        Key::number(
            "eps_uk",
            "-",
            "none (plastic at 0.9 fptk)",
            "strain at fptk of the hardening branch, above 0.9 fptk/Ep",
        ),
        THERMAL_EXPANSION,
    ],
    refused: &[],
    thermal_expansion: Some(ALPHA_STEEL),
    build,
};

/// The uniaxial law of embedded bars.
fn build(t: &Table, warnings: &mut Vec<String>) -> R<Law> {
    let (ep, fptk) = t.steel_modulus_and_strength(warnings, "Ep", "fptk")?;
    Ok(Law::Bar(match t.num("eps_uk") {
        None => SteelParams::prestressing(ep, fptk),
        Some(e) if e.is_finite() && e > 0.9 * fptk / ep => {
            SteelParams::prestressing_hardening(ep, fptk, e)
        }
        Some(e) => {
            return Err(t.err(
                "eps_uk",
                format!(
                    "must exceed the yield strain 0.9 fptk/Ep = {:.5} (got {e})",
                    0.9 * fptk / ep
                ),
            ))
        }
    }))
}
