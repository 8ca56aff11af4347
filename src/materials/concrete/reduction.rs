//! Compression softening of cracked concrete: the compressive strength and the strain at
//! the peak fall as the strain across the compressed direction opens cracks
//! (docs/theory-concrete.md §5.3).
//!
//! Vecchio & Collins (1993), "Compression response of cracked reinforced concrete", J.
//! Struct. Eng. 119(12):3590–3610, the form in the lateral tensile strain over the peak
//! strain: β_d = 1/(1 + C_d), C_d = 0.27 (ε_lat/ε_c1 − 0.37) (C_d ≥ 0, so β_d ≤ 1),
//! floored at β_min. The reduced curve is the uniaxial one scaled in stress and strain by
//! β_d, σ_β(ε̄) = β_d σ_c(ε̄/β_d): strength β_d f_cm at strain β_d ε_c1 (their strength-and-
//! strain-softened form), the same initial stiffness E and the same shape, so the law stays
//! continuous in ε_lat and its derivatives are analytic.

use super::compression::{self, Hardening};
use super::{CompressionReduction, ConcreteParams};

/// Reduction factor β_d [-] and dβ_d/dε_lat [-] for the lateral tensile strain `lateral`
/// [-] of a point in an element of crack band width `char_length` [m] (β_d = 1 for no
/// reduction or an effective lateral strain ≤ 0.37 ε_c1).
///
/// With a crack spacing s_rm > h (`spacing`) the crack opening w = (ε − ε0) h of the band
/// is smeared over s_rm, as the MCFT's average strain is: ε_lat = ε0 + (ε − ε0) h/s_rm
/// for ε > ε0 ([`lateral_strain`]).
pub fn factor(p: &ConcreteParams, lateral: f64, char_length: f64) -> (f64, f64) {
    let CompressionReduction::VecchioCollins1993 { beta_min, spacing } = p.compression_reduction
    else {
        return (1.0, 0.0);
    };
    let (lat, dlat) = lateral_strain(p.eps0(), lateral, char_length, spacing);
    let cd = 0.27 * (lat / p.eps_c1 - 0.37);
    if cd <= 0.0 {
        return (1.0, 0.0);
    }
    let b = 1.0 / (1.0 + cd);
    if b <= beta_min {
        (beta_min, 0.0)
    } else {
        (b, -b * b * 0.27 / p.eps_c1 * dlat)
    }
}

/// The lateral strain that drives the compression softening [-] and its derivative in the
/// point's lateral strain `lateral` [-]: the point's strain itself in the crack band
/// (`spacing` ≤ `h`, or 0), else its elastic part up to ε0 = f_tm/E `eps0` [-] plus the
/// crack opening of the band, (ε − ε0) h, over the mean crack spacing s_rm = `spacing`
/// [m] (docs/theory-concrete.md §5.3).
pub fn lateral_strain(eps0: f64, lateral: f64, h: f64, spacing: f64) -> (f64, f64) {
    if spacing > h && h > 0.0 && lateral > eps0 {
        let r = h / spacing;
        (eps0 + (lateral - eps0) * r, r)
    } else {
        (lateral, 1.0)
    }
}

/// The hardening functions of the curve scaled by `beta` [-] at curve strain `ebar` [-],
/// and dσ_c/dβ [Pa], dκ/dβ [-] at fixed ε̄. With β = 1 it is exactly
/// [`compression::hardening`].
pub fn scaled_hardening(p: &ConcreteParams, beta: f64, ebar: f64) -> (Hardening, f64, f64) {
    scaled_hardening_with(p, &compression::HardeningLaw::new(p), beta, ebar)
}

/// [`scaled_hardening`] with the hardening law of `p` given (`law`, the same values).
pub fn scaled_hardening_with(
    p: &ConcreteParams,
    law: &compression::HardeningLaw,
    beta: f64,
    ebar: f64,
) -> (Hardening, f64, f64) {
    if beta == 1.0 {
        let h = law.at(ebar);
        let (_, k0) = law.initial_yield();
        let ds = h.sigma_c - ebar * h.dsigma_c;
        return (h, ds, -ds / p.ec - k0);
    }
    let y = ebar / beta;
    let (s0, ds0) = law.curve(y);
    let (_, k0) = law.initial_yield();
    let s = beta * s0;
    // ∂(β σ0(ε̄/β))/∂β = σ0(y) − y σ0'(y).
    let ds_db = s0 - y * ds0;
    let h = Hardening {
        sigma_c: s,
        dsigma_c: ds0,
        kappa: ebar - s / p.ec - beta * k0,
        dkappa: 1.0 - ds0 / p.ec,
    };
    (h, ds_db, -ds_db / p.ec - k0)
}
