//! An implementation of the CEB-FIP Model Code 1990 time functions written for the tests from
//! the code text (MC90 2.1.4.2, 2.1.6.4 creep, 2.1.6.4.4 shrinkage, 2.3.4.5 relaxation), so
//! that no test builds its expected value with the library's `mc90_time` or `chain` functions
//! (the code under test). The library's `CreepShrinkageParams` is used only as a record of the
//! inputs (its public fields); every constant and formula below is typed here again, and the
//! relaxation function solves the Volterra equation by a different rule (trapezoidal instead of
//! the library's mid-point). tests/time.rs pins this module to the MC90 check values of
//! docs/theory-time.md (hand table) so that a typo here cannot hide a library error.
//!
//! Units: ages and durations in days, stresses and moduli in Pa, h0 in m, rh a fraction.

#![allow(dead_code)]

use segfem::materials::mc90_time::{CementClass, CreepShrinkageParams, RelaxationClass};

/// Inputs the formulas below need, read from the record; the optional MC90 adjustments
/// (cement type on t0, temperature) are not written here, so a test must not turn them on.
fn inputs(p: &CreepShrinkageParams) -> (f64, f64, f64) {
    assert!(
        !p.adjust_age_for_cement && p.temperature.is_none(),
        "the test reference covers MC90 without the optional adjustments"
    );
    (p.fcm / 1e6, p.rh * 100.0, p.h0 * 1000.0)
}

/// s of β_cc (MC90 eq. 2.1-54): 0.20 RS, 0.25 N and R, 0.38 SL.
fn s_coef(c: CementClass) -> f64 {
    match c {
        CementClass::RS => 0.20,
        CementClass::SL => 0.38,
        _ => 0.25,
    }
}

/// β_sc of the notional shrinkage (MC90 eq. 2.1-76): 4 SL, 5 N and R, 8 RS.
fn beta_sc(c: CementClass) -> f64 {
    match c {
        CementClass::SL => 4.0,
        CementClass::RS => 8.0,
        _ => 5.0,
    }
}

/// E_ci = 2.15e4 MPa (fcm/10)^(1/3) \[Pa\] (MC90 eq. 2.1-16, α_E = 1).
pub fn eci(p: &CreepShrinkageParams) -> f64 {
    let (fcm, _, _) = inputs(p);
    2.15e4 * (fcm / 10.0).powf(1.0 / 3.0) * 1e6
}

/// E_ci(t) = [exp{s (1 − √(28/t))}]^0.5 E_ci \[Pa\] (MC90 eqs. 2.1-54, 2.1-57).
pub fn eci_at(p: &CreepShrinkageParams, t: f64) -> f64 {
    let bcc = (s_coef(p.cement) * (1.0 - (28.0 / t).sqrt())).exp();
    bcc.sqrt() * eci(p)
}

/// φ(t, t0) = φ_RH β(fcm) β(t0) β_c(t − t0) (MC90 eqs. 2.1-64 … 2.1-71), 0 for t ≤ t0.
pub fn creep_coefficient(p: &CreepShrinkageParams, t: f64, t0: f64) -> f64 {
    let (fcm, rh, h) = inputs(p);
    if t <= t0 {
        return 0.0;
    }
    let phi_rh = 1.0 + (1.0 - rh / 100.0) / (0.46 * (h / 100.0).powf(1.0 / 3.0));
    let b_fcm = 5.3 / (fcm / 10.0).powf(0.5);
    let b_t0 = 1.0 / (0.1 + t0.powf(0.2));
    let beta_h = (150.0 * (1.0 + (1.2 * rh / 100.0).powf(18.0)) * h / 100.0 + 250.0).min(1500.0);
    let d = t - t0;
    let b_c = (d / (beta_h + d)).powf(0.3);
    phi_rh * b_fcm * b_t0 * b_c
}

/// J(t, t0) = 1/E_ci(t0) + φ(t, t0)/E_ci \[1/Pa\] (MC90 eq. 2.1-63).
pub fn compliance(p: &CreepShrinkageParams, t: f64, t0: f64) -> f64 {
    1.0 / eci_at(p, t0) + creep_coefficient(p, t, t0) / eci(p)
}

/// ε_cs(t, ts) = ε_s(fcm) β_RH β_s(t − ts) (MC90 eqs. 2.1-74 … 2.1-79), negative = shortening.
pub fn shrinkage_strain(p: &CreepShrinkageParams, t: f64) -> f64 {
    let (fcm, rh, h) = inputs(p);
    let d = t - p.t_shrinkage_start;
    if d <= 0.0 {
        return 0.0;
    }
    let eps_s = (160.0 + 10.0 * beta_sc(p.cement) * (9.0 - fcm / 10.0)) * 1e-6;
    let beta_rh = if rh >= 99.0 {
        0.25
    } else {
        -1.55 * (1.0 - (rh / 100.0).powi(3))
    };
    let b_s = (d / (350.0 * (h / 100.0).powi(2) + d)).sqrt();
    eps_s * beta_rh * b_s
}

/// MC90 relaxation ρ(t) = ρ1000 (t / 1000 h)^k as a fraction of σ_pi (MC90 2.3.4.5, figure
/// 2.3.3 read as a table at σ_pi/f_ptk = 0.6, 0.7, 0.8 and zero at 0.5, linear between; k =
/// 0.12 class 1, 0.19 classes 2 and 3). `t_days` in days.
pub fn relaxation_loss(class: RelaxationClass, ratio: f64, t_days: f64) -> f64 {
    if t_days <= 0.0 || ratio <= 0.5 {
        return 0.0;
    }
    let (table, k) = match class {
        RelaxationClass::Class1 => ([0.0, 4.5, 8.0, 12.0], 0.12),
        RelaxationClass::Class2 => ([0.0, 1.0, 2.5, 4.5], 0.19),
        RelaxationClass::Class3 => ([0.0, 2.0, 4.0, 7.0], 0.19),
    };
    // Piecewise linear in 0.1 steps from 0.5, the last segment extended above 0.8.
    let x = (ratio - 0.5) / 0.1;
    let i = (x.floor() as usize).min(2);
    let rho1000_pct = table[i] + (table[i + 1] - table[i]) * (x - i as f64);
    rho1000_pct / 100.0 * (24.0 * t_days / 1000.0).powf(k)
}

/// Relaxation function R(t' + d, t') \[Pa\] of the MC90 compliance at each duration d
/// (sorted, positive): the stress history under a unit strain imposed at t' and held, from
/// ∫ J(t, s) dR(s) = 1 discretised with the trapezoidal rule on the nodes t', t' + d_k
/// (Bažant's step-by-step method). Use a fine geometric grid (≥ 20 points per decade).
pub fn relaxation_function(p: &CreepShrinkageParams, t_prime: f64, durations: &[f64]) -> Vec<f64> {
    let t: Vec<f64> = std::iter::once(t_prime)
        .chain(durations.iter().map(|d| t_prime + d))
        .collect();
    // R at the nodes; R(t') = 1/J(t', t') = E_ci(t').
    let mut r = vec![1.0 / compliance(p, t_prime, t_prime)];
    for k in 1..t.len() {
        // Σ_j ΔR_j [J(t_k, t_j) + J(t_k, t_{j−1})]/2 + R_0 J(t_k, t_0) = 1, solved for ΔR_k.
        let mut lhs = r[0] * compliance(p, t[k], t[0]);
        for j in 1..k {
            lhs += (r[j] - r[j - 1])
                * 0.5
                * (compliance(p, t[k], t[j]) + compliance(p, t[k], t[j - 1]));
        }
        let w = 0.5 * (compliance(p, t[k], t[k]) + compliance(p, t[k], t[k - 1]));
        r.push(r[k - 1] + (1.0 - lhs) / w);
    }
    r.remove(0);
    r
}
