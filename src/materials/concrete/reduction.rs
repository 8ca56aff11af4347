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
/// [-] (β_d = 1 for no reduction or ε_lat ≤ 0.37 ε_c1).
pub fn factor(p: &ConcreteParams, lateral: f64) -> (f64, f64) {
    let CompressionReduction::VecchioCollins1993 { beta_min } = p.compression_reduction else {
        return (1.0, 0.0);
    };
    let cd = 0.27 * (lateral / p.eps_c1 - 0.37);
    if cd <= 0.0 {
        return (1.0, 0.0);
    }
    let b = 1.0 / (1.0 + cd);
    if b <= beta_min {
        (beta_min, 0.0)
    } else {
        (b, -b * b * 0.27 / p.eps_c1)
    }
}

/// The hardening functions of the curve scaled by `beta` [-] at curve strain `ebar` [-],
/// and dσ_c/dβ [Pa], dκ/dβ [-] at fixed ε̄. With β = 1 it is exactly
/// [`compression::hardening`].
pub fn scaled_hardening(p: &ConcreteParams, beta: f64, ebar: f64) -> (Hardening, f64, f64) {
    if beta == 1.0 {
        let h = compression::hardening(p, ebar);
        let (_, k0) = compression::initial_yield(p);
        let ds = h.sigma_c - ebar * h.dsigma_c;
        return (h, ds, -ds / p.ec - k0);
    }
    let y = ebar / beta;
    let (s0, ds0) = compression::hardening_curve(p, y);
    let (_, k0) = compression::initial_yield(p);
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
