//! Strength gain of concrete under biaxial compression for the rotating-crack model
//! (docs/theory-concrete.md §5.4): the Kupfer & Gerstle (1973) envelope of the Kupfer,
//! Hilsdorf & Rüsch (1969) tests,
//!
//! K(α) = (1 + 3.65 α)/(1 + α)², α = σ_minor/σ_major ∈ [0, 1] (both compressive),
//!
//! the peak of the major compressive stress over f_cm: 1 in uniaxial compression, 1.257 at
//! α = 0.452, 1.1625 in equal biaxial compression. Both principal curves are stretched by
//! K in stress and strain, σ = −K σ_c(−ε̃/K) (as Vecchio 1992 enhances f_p and ε_p), so the
//! minor direction does not crush before the major one. The fixed model's uncracked
//! concrete gets its biaxial gain from the Ottosen surface; this gives the rotating model
//! the same kind of envelope.
//!
//! Kupfer, H.B. and Gerstle, K.H. (1973), "Behavior of concrete under biaxial stresses",
//! J. Eng. Mech. Div. ASCE 99(EM4):853–866; Kupfer, H., Hilsdorf, H.K. and Rüsch, H.
//! (1969), "Behavior of concrete under biaxial stresses", ACI J. 66(8):656–666.

/// Gain K [-] and dK/dα [-] at the stress ratio `alpha` [-] (clamped to [0, 1]; at α = 1,
/// where α = σ_minor/σ_major has a kink, the derivative from below).
pub fn gain(alpha: f64) -> (f64, f64) {
    let a = alpha.clamp(0.0, 1.0);
    let d = 1.0 + a;
    let k = (1.0 + 3.65 * a) / (d * d);
    (k, (1.65 - 3.65 * a) / (d * d * d))
}

/// Stress ratio α = σ_minor/σ_major [-] of two principal stresses `s` [Pa] that are both
/// compressive, and ∂α/∂σ_i [1/Pa]; `None` unless both are below zero.
pub fn ratio(s: [f64; 2]) -> Option<(f64, [f64; 2])> {
    if !(s[0] < 0.0 && s[1] < 0.0) {
        return None;
    }
    let (maj, min) = if s[0] <= s[1] { (0, 1) } else { (1, 0) };
    // α = (−σ_min)/(−σ_maj) = σ_min/σ_maj.
    let a = s[min] / s[maj];
    let mut d = [0.0; 2];
    d[min] = 1.0 / s[maj];
    d[maj] = -s[min] / (s[maj] * s[maj]);
    Some((a, d))
}
