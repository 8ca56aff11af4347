//! Warnings for values that are legal but look like the wrong unit (segfem works in N, m, Pa,
//! kg/m³): a modulus of 35 (GPa meant), a strength of 500 (MPa meant), a thickness of 30
//! (cm meant), a beam 7200 long (mm meant). A warning never stops the run; it is returned
//! with the model, printed by the CLI on standard error and listed in summary.json.
//! Thresholds are documented in docs/errors.md ("Warnings").

use super::error::Ctx;

/// Smallest plausible Young's modulus of concrete or steel [Pa]: 1 MPa. Real values are
/// 2e10–2.1e11; 35 or 35000 (GPa or MPa meant) fall far below.
pub const MIN_MODULUS: f64 = 1e6;
/// Smallest plausible strength [Pa]: 1 kPa (a strength given in MPa, e.g. 500, falls below).
pub const MIN_STRENGTH: f64 = 1e3;
/// Plausible thickness range [m]: 1 mm to 20 m (a bridge deck slab is up to ~20 m wide; a
/// web or slab thickness in cm or mm falls above).
pub const THICKNESS_RANGE: (f64, f64) = (1e-3, 20.0);
/// Largest plausible model size (bounding-box diagonal) [m]: 1 km (a mesh in mm falls above).
pub const MAX_MODEL_SIZE: f64 = 1000.0;

/// Warn if a modulus `v` [Pa] at `key` looks like MPa or GPa.
pub fn modulus(w: &mut Vec<String>, ctx: &Ctx, key: &str, v: f64) {
    if v < MIN_MODULUS {
        w.push(format!(
            "{}: {key}: {v} Pa looks like MPa or GPa (35 GPa = 35e9); segfem works in Pa",
            ctx.file
        ));
    }
}

/// Warn if a strength `v` [Pa] at `key` looks like MPa (zero is a legal "no strength").
pub fn strength(w: &mut Vec<String>, ctx: &Ctx, key: &str, v: f64) {
    if v > 0.0 && v < MIN_STRENGTH {
        w.push(format!(
            "{}: {key}: {v} Pa looks like MPa (500 MPa = 500e6); segfem works in Pa",
            ctx.file
        ));
    }
}

/// Warn if a thickness `v` [m] at `key` lies outside [`THICKNESS_RANGE`].
pub fn thickness(w: &mut Vec<String>, ctx: &Ctx, key: &str, v: f64) {
    let (lo, hi) = THICKNESS_RANGE;
    if v < lo || v > hi {
        w.push(format!(
            "{}: {key}: thickness {v} m is outside {lo}–{hi} m; segfem works in metres (0.3 m, not 30 cm)",
            ctx.file
        ));
    }
}

/// Warn if the mesh's bounding-box diagonal `size` [m] exceeds [`MAX_MODEL_SIZE`].
pub fn model_size(w: &mut Vec<String>, ctx: &Ctx, size: f64) {
    if size > MAX_MODEL_SIZE {
        w.push(format!(
            "{}: mesh: the model is {size:.0} m across; coordinates look like millimetres (segfem works in metres)",
            ctx.file
        ));
    }
}
