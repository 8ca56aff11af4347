//! Perzyna elasto-viscoplasticity helpers after Owen & Hinton (1980), docs/theory-time.md §4.
//!
//! Pure functions that take the yield-function value F, the current yield stress F0 and the
//! flow vector a = ∂F/∂σ (or ∂Q/∂σ) as inputs, so they work with any surface (Ottosen σ_e,
//! von Mises, …). Plane-stress Voigt order (σx, σy, τxy) with engineering shear strain.
//!
//! Units: stresses in Pa (any consistent unit works: only ratios F/F0 and F0/E enter),
//! fluidity γ in 1/time, time in the same unit as 1/γ (fictitious time when viscoplasticity
//! is used only to reach the elastoplastic steady state).

use serde::{Deserialize, Serialize};

/// Overstress function Φ of the Perzyna flow rule (argument x = (F − F0)/F0).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub enum OverstressFunction {
    /// Φ = (F − F0)/F0 (the form the critical time steps below refer to; default).
    #[default]
    Linear,
    /// Φ = ((F − F0)/F0)^N, N > 0.
    Power(f64),
    /// Φ = exp[M (F − F0)/F0] − 1.
    Exponential(f64),
}

/// Macaulay bracket ⟨x⟩ = max(x, 0).
pub fn macaulay(x: f64) -> f64 {
    x.max(0.0)
}

/// Perzyna overstress ⟨Φ(F)⟩ \[-\] for yield-function value `f` and yield stress `f0` > 0
/// (same unit); zero inside the surface (F ≤ F0).
pub fn overstress(law: OverstressFunction, f: f64, f0: f64) -> f64 {
    debug_assert!(f0 > 0.0, "yield stress must be positive");
    let x = (f - f0) / f0;
    if x <= 0.0 {
        return 0.0;
    }
    match law {
        OverstressFunction::Linear => x,
        OverstressFunction::Power(n) => x.powf(n),
        OverstressFunction::Exponential(m) => (m * x).exp_m1(),
    }
}

/// Overstress function Φ(x) \[-\] and its derivative dΦ/dx \[-\] for the normalised
/// overstress x = (F − F0)/F_ref (any positive reference F_ref); both zero for x ≤ 0.
pub fn overstress_of_ratio(law: OverstressFunction, x: f64) -> (f64, f64) {
    if x <= 0.0 {
        return (0.0, 0.0);
    }
    match law {
        OverstressFunction::Linear => (x, 1.0),
        OverstressFunction::Power(n) => (x.powf(n), n * x.powf(n - 1.0)),
        OverstressFunction::Exponential(m) => ((m * x).exp_m1(), m * (m * x).exp()),
    }
}

/// Viscoplastic strain rate ε̇_vp = γ ⟨Φ(F)⟩ a \[1/time\] (docs/theory-time.md §4) for fluidity
/// `gamma` \[1/time\], yield-function value `f`, yield stress `f0` and flow vector `flow` = ∂Q/∂σ
/// [per unit of F/stress; dimensionless when F is a stress].
pub fn viscoplastic_strain_rate(
    law: OverstressFunction,
    gamma: f64,
    f: f64,
    f0: f64,
    flow: &[f64; 3],
) -> [f64; 3] {
    let g = gamma * overstress(law, f, f0);
    [g * flow[0], g * flow[1], g * flow[2]]
}

/// Explicit (Euler, Θ = 0) viscoplastic strain increment Δε_vp = Δt ε̇_vp \[-\] for a time
/// step `dt` \[time\].
pub fn explicit_strain_increment(rate: &[f64; 3], dt: f64) -> [f64; 3] {
    [dt * rate[0], dt * rate[1], dt * rate[2]]
}

/// Θ-method strain increment Δε_vp = Δt [(1 − Θ) ε̇_n + Θ ε̇_{n+1}] \[-\] (docs/theory-time.md §4),
/// `theta` ∈ [0, 1].
pub fn theta_strain_increment(
    rate_n: &[f64; 3],
    rate_np1: &[f64; 3],
    dt: f64,
    theta: f64,
) -> [f64; 3] {
    std::array::from_fn(|i| dt * ((1.0 - theta) * rate_n[i] + theta * rate_np1[i]))
}

/// Work-hardening increment Δκ = σ · Δε_vp / σ_c \[-\] (effective plastic strain from plastic
/// work equivalence, docs/theory-time.md §4), engineering shear in the dot product; `sigma_c` =
/// current uniaxial yield stress (> 0, same unit as σ). Returns 0 for non-positive work.
pub fn hardening_increment(stress: &[f64; 3], d_eps_vp: &[f64; 3], sigma_c: f64) -> f64 {
    let w = stress[0] * d_eps_vp[0] + stress[1] * d_eps_vp[1] + stress[2] * d_eps_vp[2];
    macaulay(w) / sigma_c
}

/// Plane-stress elastic stress correction −D Δε_vp \[stress\]: the initial-stress "pseudo-load"
/// of one Gauss point is ∫ Bᵀ D Δε_vp dΩ. `e` = Young's modulus, `nu` = Poisson ratio.
pub fn elastic_stress_of_strain(e: f64, nu: f64, d_eps: &[f64; 3]) -> [f64; 3] {
    let c = e / (1.0 - nu * nu);
    [
        c * (d_eps[0] + nu * d_eps[1]),
        c * (nu * d_eps[0] + d_eps[1]),
        c * 0.5 * (1.0 - nu) * d_eps[2],
    ]
}

/// Cormeau critical time step for the Tresca surface and Φ = (F − F0)/F0:
/// Δt ≤ (1 + ν) F0/(γ E) \[time\]. `f0` and `e` in the same stress unit, `gamma` in 1/time.
pub fn critical_dt_tresca(e: f64, nu: f64, gamma: f64, f0: f64) -> f64 {
    (1.0 + nu) * f0 / (gamma * e)
}

/// Cormeau critical time step for von Mises and Φ = (F − F0)/F0:
/// Δt ≤ 4(1 + ν) F0/(3 γ E) \[time\].
pub fn critical_dt_von_mises(e: f64, nu: f64, gamma: f64, f0: f64) -> f64 {
    4.0 * (1.0 + nu) * f0 / (3.0 * gamma * e)
}

/// Cormeau critical time step for Mohr–Coulomb (friction angle `phi` in radians) and
/// Φ = (F − F0)/F0: Δt ≤ 4(1 + ν)(1 − 2ν) F0/[γ E (1 − 2ν + sin²φ)] \[time\].
pub fn critical_dt_mohr_coulomb(e: f64, nu: f64, gamma: f64, f0: f64, phi: f64) -> f64 {
    let s = phi.sin();
    4.0 * (1.0 + nu) * (1.0 - 2.0 * nu) * f0 / (gamma * e * (1.0 - 2.0 * nu + s * s))
}

/// Critical time step for the Ottosen surface **\[DECISION\]**: no closed form is known
/// (docs/theory-time.md §4); use the von Mises value times `safety` (recommended 0.5) \[time\].
pub fn critical_dt_ottosen_estimate(e: f64, nu: f64, gamma: f64, f0: f64, safety: f64) -> f64 {
    safety * critical_dt_von_mises(e, nu, gamma, f0)
}

/// Owen–Hinton time-step control (docs/theory-time.md §4) \[time\]: the next step is the smallest
/// of `growth` × `dt_prev` (k ≈ 1.5), `tau` × ε̄/‖ε̇_vp‖ (τ ≈ 0.01–0.15; ignored if the rate is
/// zero) and `dt_crit`.
pub fn next_time_step(
    dt_prev: f64,
    growth: f64,
    tau: f64,
    eff_total_strain: f64,
    eff_vp_rate: f64,
    dt_crit: f64,
) -> f64 {
    let mut dt = (growth * dt_prev).min(dt_crit);
    if eff_vp_rate > 0.0 && eff_total_strain > 0.0 {
        dt = dt.min(tau * eff_total_strain / eff_vp_rate);
    }
    dt
}

/// Stationarity test of the viscoplastic time loop: Σ‖Δε_vp‖ of the step over Σ‖ε_vp‖
/// accumulated ≤ `tol` (≈ 1e-3 … 1e-2). `true` also when nothing has yielded.
pub fn is_stationary(sum_step_increment_norm: f64, sum_total_vp_norm: f64, tol: f64) -> bool {
    if sum_total_vp_norm <= 0.0 {
        return sum_step_increment_norm <= 0.0;
    }
    sum_step_increment_norm / sum_total_vp_norm <= tol
}

/// Owen–Hinton number of forward-Euler sub-increments m = int[8 (σ̄_trial − F0)/F0] + 1 for
/// the elastoplastic return (docs/theory-time.md §4) \[-\]; 1 inside the surface.
pub fn owen_hinton_substeps(sigma_trial: f64, f0: f64) -> usize {
    let x = 8.0 * (sigma_trial - f0) / f0;
    if x <= 0.0 {
        1
    } else {
        x.floor() as usize + 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    /// Check 16: critical Δt for E = 35495.72, ν = 0.2, γ = F0 = 1 (docs/theory-time.md §4).
    /// 1e-6 relative as docs/theory-time.md §5 (values printed with 7 digits).
    #[test]
    fn check_16_critical_time_steps() {
        let (e, nu) = (35495.72, 0.2);
        assert!(rel(critical_dt_tresca(e, nu, 1.0, 1.0), 3.380689e-5) < 1e-6);
        assert!(rel(critical_dt_von_mises(e, nu, 1.0, 1.0), 4.507586e-5) < 1e-6);
        let mc = critical_dt_mohr_coulomb(e, nu, 1.0, 1.0, 30f64.to_radians());
        assert!(rel(mc, 9.545476e-5) < 1e-6);
        // Scaling: ∝ F0, ∝ 1/γ.
        assert!(rel(critical_dt_von_mises(e, nu, 2.0, 3.0), 1.5 * 4.507586e-5) < 1e-6);
        // φ = 0 Mohr–Coulomb (Tresca-like) gives 4(1+ν)/E.
        assert!(rel(critical_dt_mohr_coulomb(e, nu, 1.0, 1.0, 0.0), 4.8 / e) < 1e-12);
        assert!(
            rel(
                critical_dt_ottosen_estimate(e, nu, 1.0, 1.0, 0.5),
                0.5 * 4.507586e-5
            ) < 1e-6
        );
    }

    #[test]
    fn overstress_and_rate() {
        let a = [0.3, -0.1, 0.2];
        // Inside or on the surface: no flow.
        assert_eq!(
            viscoplastic_strain_rate(OverstressFunction::Linear, 2.0, 9.0, 10.0, &a),
            [0.0; 3]
        );
        assert_eq!(overstress(OverstressFunction::Linear, 10.0, 10.0), 0.0);
        // Linear: Φ = 0.2 at F = 12, F0 = 10; rate = γ Φ a.
        let r = viscoplastic_strain_rate(OverstressFunction::Linear, 2.0, 12.0, 10.0, &a);
        for i in 0..3 {
            assert!((r[i] - 0.4 * a[i]).abs() < 1e-15);
        }
        assert!(rel(overstress(OverstressFunction::Power(2.0), 12.0, 10.0), 0.04) < 1e-12);
        assert!(
            rel(
                overstress(OverstressFunction::Exponential(3.0), 12.0, 10.0),
                (0.6f64).exp() - 1.0
            ) < 1e-12
        );
        let d = explicit_strain_increment(&r, 0.5);
        assert!(rel(d[0], 0.5 * r[0]) < 1e-15);
        let th = theta_strain_increment(&[1.0, 0.0, 0.0], &[3.0, 0.0, 0.0], 2.0, 0.5);
        assert!(rel(th[0], 4.0) < 1e-15);
    }

    /// Explicit marching of a 1-D bar at fixed total strain (E ε̇_vp feeds back into σ):
    /// the error factor per step is 1 − γEΔt/F0, so below Δt = F0/(γE) the stress relaxes
    /// monotonically to F0, while for Δt = 2.5 F0/(γE) the first step overshoots far inside
    /// the surface (where ⟨Φ⟩ = 0 freezes it) — the instability the Cormeau limits guard.
    #[test]
    fn explicit_relaxation_is_stable_below_critical() {
        let (e, gamma, f0) = (30e9, 1.0, 20e6);
        let run = |dt: f64| {
            let mut s = 30e6;
            for _ in 0..200 {
                let rate = viscoplastic_strain_rate(
                    OverstressFunction::Linear,
                    gamma,
                    s,
                    f0,
                    &[1.0, 0.0, 0.0],
                );
                s -= e * rate[0] * dt;
            }
            s
        };
        let dtc = f0 / (gamma * e);
        assert!(rel(run(0.9 * dtc), f0) < 1e-6);
        assert!(rel(run(2.5 * dtc), f0) > 0.5);
    }

    #[test]
    fn hardening_and_controls() {
        let s = [-30e6, -10e6, 5e6];
        let de = [-1e-4, 0.2e-4, 0.5e-4];
        let w = 30e6 * 1e-4 - 10e6 * 0.2e-4 + 5e6 * 0.5e-4;
        assert!(rel(hardening_increment(&s, &de, 40e6), w / 40e6) < 1e-12);
        assert_eq!(hardening_increment(&s, &[1e-4, 0.0, 0.0], 40e6), 0.0);
        assert_eq!(owen_hinton_substeps(9.0, 10.0), 1);
        assert_eq!(owen_hinton_substeps(12.0, 10.0), 2);
        assert_eq!(owen_hinton_substeps(13.0, 10.0), 3);
        assert!(rel(next_time_step(1.0, 1.5, 0.1, 1e-3, 1e-3, 10.0), 0.1) < 1e-12);
        assert!(rel(next_time_step(1.0, 1.5, 0.1, 1e-3, 0.0, 10.0), 1.5) < 1e-12);
        assert!(rel(next_time_step(1.0, 1.5, 0.1, 1e-3, 0.0, 1.2), 1.2) < 1e-12);
        assert!(is_stationary(1e-4, 1.0, 1e-3));
        assert!(!is_stationary(1e-2, 1.0, 1e-3));
        assert!(is_stationary(0.0, 0.0, 1e-3));
        let ds = elastic_stress_of_strain(1.0, 0.2, &[1.0, 0.0, 1.0]);
        assert!(rel(ds[0], 1.0 / 0.96) < 1e-12 && rel(ds[2], 0.4 / 0.96) < 1e-12);
    }
}
