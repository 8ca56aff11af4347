//! Code formulas of the design checks (docs/theory-design.md), in SI units: stresses in
//! Pa, lengths in m, areas in m², forces in N. Each function names its clause.

/// One MPa in Pa.
const MPA: f64 = 1e6;

/// EN 1992-1-1 Table 3.1: characteristic strength from the mean, f_ck = f_cm − 8 MPa [Pa].
pub fn en_fck_from_fcm(fcm: f64) -> f64 {
    fcm - 8.0 * MPA
}

/// EN 1992-1-1 §7.2(2) and (3): the compressive stress limit of concrete under the
/// characteristic combination (k1 = 0.6) or, for linear creep, the quasi-permanent one
/// (k2 = 0.45) [Pa].
pub fn en_concrete_limit(fck: f64, quasi_permanent: bool) -> f64 {
    if quasi_permanent {
        0.45 * fck
    } else {
        0.6 * fck
    }
}

/// AASHTO LRFD Table 5.9.2.3.2a-1: compressive stress limit after losses, 0.45 f'c under
/// effective prestress and permanent loads, 0.60 f'c with transient loads too (φ_w = 1,
/// walls not slender) [Pa].
pub fn aashto_concrete_limit(fc: f64, permanent_only: bool) -> f64 {
    if permanent_only {
        0.45 * fc
    } else {
        0.60 * fc
    }
}

/// EN 1992-1-1 §7.2(5): the mean stress of prestressing steel under the characteristic
/// combination, at most k5 f_pk = 0.75 f_pk [Pa].
pub fn en_tendon_limit(fpk: f64) -> f64 {
    0.75 * fpk
}

/// AASHTO LRFD Table 5.9.2.2-1: prestressing steel at the service limit state after all
/// losses, at most 0.80 f_py, with f_py = 0.90 f_pu for low-relaxation strand [Pa].
pub fn aashto_tendon_limit(fpu: f64) -> f64 {
    0.80 * 0.90 * fpu
}

/// AASHTO LRFD Table 5.9.2.3.2b-1 (segmentally constructed bridges, longitudinal stress
/// through joints in the precompressed tensile zone, after losses): Type B (dry) joints
/// keep at least 0.100 ksi of compression [Pa].
pub const AASHTO_TYPE_B_SERVICE: f64 = 0.100 * KSI;

/// AASHTO LRFD Table 5.9.2.3.1b-1 (temporary stresses before losses, segmental bridges):
/// Type B joints with external tendons keep at least 0.030 ksi of compression [Pa].
pub const AASHTO_TYPE_B_CONSTRUCTION: f64 = 0.030 * KSI;

/// One ksi in Pa (6.894757 MPa).
pub const KSI: f64 = 6.894_757e6;

/// AASHTO LRFD §5.6.3.1.2: the stress in unbonded tendons at nominal flexural resistance,
/// f_ps = f_pe + 900 ksi · (d_p − c)/ℓ_e ≤ f_py, with ℓ_e = 2 ℓ_i/(2 + N_s) [Pa].
/// `fpe` effective prestress [Pa], `dp` depth of the tendon [m], `c` neutral axis depth
/// [m], `li` tendon length between anchorages [m], `ns` support hinges crossed.
pub fn aashto_unbonded_fps(fpe: f64, dp: f64, c: f64, li: f64, ns: usize, fpy: f64) -> f64 {
    let le = 2.0 * li / (2.0 + ns as f64);
    (fpe + 900.0 * KSI * (dp - c) / le).min(fpy)
}

/// AASHTO LRFD §5.6.2.2: the stress block factors α1 and β1 for f'c [Pa] (α1 = 0.85 up to
/// 10 ksi, less 0.02 per ksi above, not below 0.75; β1 = 0.85 up to 4 ksi, less 0.05 per
/// ksi above, not below 0.65).
pub fn aashto_stress_block(fc: f64) -> (f64, f64) {
    let ksi = fc / KSI;
    let alpha1 = (0.85 - 0.02 * (ksi - 10.0).max(0.0)).max(0.75);
    let beta1 = (0.85 - 0.05 * (ksi - 4.0).max(0.0)).max(0.65);
    (alpha1, beta1)
}

/// The neutral axis depth c [m] and tendon stress f_ps [Pa] of AASHTO §5.6.3.1.2 on a
/// section of bands: the compression block α1 f'c over the depth β1 c from the top, of
/// width `width(depth)` (the section's width at a depth below its top [m]), balances
/// A_ps f_ps(c). Bonded mild steel is not counted (at a dry joint none crosses). The
/// block force grows and f_ps falls with c, so the root is one; found by bisection.
pub fn aashto_unbonded_section(
    fc: f64,
    aps: f64,
    fps_of_c: impl Fn(f64) -> f64,
    width: impl Fn(f64) -> f64,
    depth: f64,
) -> (f64, f64) {
    let (alpha1, beta1) = aashto_stress_block(fc);
    // Block force to a depth a, by the midpoint rule on fine strips (the width is
    // piecewise constant; 2000 strips over the depth put the error below 0.05 %).
    let block = |a: f64| {
        let n = 2000;
        let h = a / n as f64;
        (0..n).map(|i| width((i as f64 + 0.5) * h) * h).sum::<f64>() * alpha1 * fc
    };
    let excess = |c: f64| block((beta1 * c).min(depth)) - aps * fps_of_c(c);
    let (mut lo, mut hi) = (0.0, depth / beta1);
    if excess(hi) < 0.0 {
        return (hi, fps_of_c(hi));
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if excess(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let c = 0.5 * (lo + hi);
    (c, fps_of_c(c))
}

/// EN 1992-1-1 §5.10.8(2): the stress increase of unbonded tendons from the effective
/// prestress to the ultimate limit state, Δσ_p,ULS = 100 MPa (recommended value) when the
/// deformation of the whole member is not computed [Pa].
pub const EN_UNBONDED_INCREASE: f64 = 100.0 * MPA;

/// AASHTO Guide Specifications for Segmental Concrete Bridges (2nd ed., 1999), the shear
/// strength of a keyed dry joint: V_j = A_k √f'c (12 + 0.017 σ_n) + 0.6 A_sm σ_n in psi
/// units, here in SI: A_k √f'c (0.9964 + 0.2047 σ_n) with f'c and σ_n in MPa and A_k in
/// mm² [N]. `ak` base area of the keys in the failure plane [m²], `asm` area of smooth
/// contact [m²], `fc` [Pa], `sigma_n` mean compression across the joint [Pa].
pub fn aashto_shear_key_capacity(ak: f64, asm: f64, fc: f64, sigma_n: f64) -> f64 {
    // The psi formula converted exactly: 1 psi = 1/145.0377 MPa.
    let psi_per_mpa = 145.037_738;
    let fc_psi = fc / MPA * psi_per_mpa;
    let sn_psi = sigma_n.max(0.0) / MPA * psi_per_mpa;
    let in2_per_m2 = 1.0 / 0.0254_f64.powi(2);
    let lb_to_n = 4.448_221_615;
    let key = ak * in2_per_m2 * fc_psi.sqrt() * (12.0 + 0.017 * sn_psi);
    let smooth = 0.6 * asm * in2_per_m2 * sn_psi;
    (key + smooth) * lb_to_n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The SI coefficients quoted in the doc comment (0.9964, 0.2047), from the psi formula
    /// by hand: 12 √145.04 / 145.04 = 0.99640 and 0.017 · √145.04 = 0.20473.
    #[test]
    fn shear_key_formula_in_si() {
        let ak = 0.05; // m² = 50,000 mm²
        let (fc, sn) = (40e6, 2e6);
        let v = aashto_shear_key_capacity(ak, 0.0, fc, sn);
        let si = 50_000.0 * 40f64.sqrt() * (0.99640 + 0.20473 * 2.0);
        assert!((v / si - 1.0).abs() < 1e-4, "{v} against {si}");
        // The smooth part alone: 0.6 A σ (1e-6: the psi, inch and pound constants are
        // rounded to 7–10 digits).
        let v = aashto_shear_key_capacity(0.0, 0.2, fc, sn);
        assert!((v / (0.6 * 0.2 * 2e6) - 1.0).abs() < 1e-6);
    }

    /// β1 = 0.85 − 0.05 (f'c − 4 ksi), 0.65 floor; α1 = 0.85 to 10 ksi (LRFD 5.6.2.2).
    #[test]
    fn stress_block_factors() {
        let (a, b) = aashto_stress_block(6.0 * KSI);
        assert_eq!(a, 0.85);
        assert!((b - 0.75).abs() < 1e-12);
        let (a, b) = aashto_stress_block(12.0 * KSI);
        assert!((a - 0.81).abs() < 1e-12);
        assert_eq!(b, 0.65);
    }

    /// A rectangular section by hand: b = 0.5 m, f'c = 5 ksi (α1 0.85, β1 0.80),
    /// A_ps = 1000 mm², f_pe = 1000 MPa, d_p = 0.8 m, ℓ_i = 10 m, N_s = 0 (ℓ_e = 10 m),
    /// f_py = 1674 MPa. c solves 0.85 f'c 0.8 c b = A_ps (f_pe + 6205.3 MPa (0.8 − c)/10):
    /// linear in c: c (0.34 f'c + A_ps 620.53e6) = A_ps (1000e6 + 496.43e6).
    #[test]
    fn unbonded_rectangle_by_hand() {
        let fc = 5.0 * KSI;
        let (aps, fpe, dp, li, fpy) = (1e-3, 1000e6, 0.8, 10.0, 1674e6);
        let k = 900.0 * KSI / li;
        let c_hand = aps * (fpe + k * dp) / (0.85 * fc * 0.8 * 0.5 + aps * k);
        let (c, fps) = aashto_unbonded_section(
            fc,
            aps,
            |c| aashto_unbonded_fps(fpe, dp, c, li, 0, fpy),
            |_| 0.5,
            1.0,
        );
        assert!((c / c_hand - 1.0).abs() < 1e-6, "{c} against {c_hand}");
        let fps_hand = fpe + k * (dp - c_hand);
        assert!((fps / fps_hand - 1.0).abs() < 1e-6);
    }
}
