//! Uncracked concrete in compression: isotropic-hardening elastoplasticity on Ottosen-shaped
//! loading surfaces with the MC90 uniaxial curve as hardening law (MODEL.md §1.4, §2.2, §5.4).
//!
//! Loading surfaces: f(σ, ε̄) = σ̂_e(σ) − σ_c(ε̄) = 0 with σ̂_e = σ_e/q_c (or σ_e when the
//! normalisation is switched off); σ_e is positively homogeneous of degree 1 so the surfaces
//! are scaled copies of the Ottosen failure surface.
//!
//! Hardening variable: ε̄ = the strain of the MC90 uniaxial curve at the current stress
//! level, σ_c(ε̄) = curve(ε̄). The equivalent plastic strain is
//! κ(ε̄) = ε̄ − σ_c(ε̄)/E − κ0 (κ0 makes κ = 0 at initial yield), the plastic part of the
//! uniaxial curve strain. With associated flow Δε_p = Δλ ∂σ̂_e/∂σ and work hardening
//! Δκ = σ:Δε_p/σ_c, Euler's theorem (σ:∂σ̂_e/∂σ = σ̂_e = σ_c on the surface) gives
//! Δκ = Δλ exactly, so a uniaxial compression test reproduces the curve exactly when
//! κ0 = 0 (zero initial yield stress, the paper's "zeroed initial yielding stresses").
//! Using ε̄ rather than κ as the unknown keeps everything smooth: dσ_c/dκ is infinite at
//! κ = 0 when the curve's initial tangent equals E, dσ_c/dε̄ is not.
//!
//! Return mapping: implicit (backward Euler) closest-point projection in the plane-stress
//! subspace, unknowns (σx, σy, τxy, ε̄), residuals
//! r_σ = C(σ − σ_tr) + Δλ n(σ), r_f = σ̂_e(σ) − σ_c(ε̄), Δλ = κ(ε̄) − κ_n,
//! Newton with backtracking line search, substepping of the strain increment as fallback.
//! Consistent tangent: 3×3 block of the inverse local Jacobian.

use super::{d_matrix, ottosen, ConcreteParams};
use crate::materials::error::MaterialError;

/// Newton tolerance on the scaled residual (stresses/f_cm, dimensionless).
const TOL: f64 = 1e-11;
/// Residual below which a stagnating Newton iteration (round-off floor, e.g. near the
/// Lode-angle meridians where λ(θ) is strongly curved) is accepted as converged.
const STAGNATION_TOL: f64 = 1e-6;
/// Maximum Newton iterations per (sub)step.
const MAX_ITER: usize = 60;
/// Largest number of substeps tried.
const MAX_SUBSTEPS: usize = 64;

/// Hardening functions evaluated at the curve strain ε̄.
#[derive(Debug, Clone, Copy)]
pub struct Hardening {
    /// σ_c(ε̄) [Pa]: current size of the loading surface.
    pub sigma_c: f64,
    /// dσ_c/dε̄ [Pa].
    pub dsigma_c: f64,
    /// κ(ε̄) [-]: equivalent plastic strain.
    pub kappa: f64,
    /// dκ/dε̄ [-] (= 1 − (dσ_c/dε̄)/E ≥ 0).
    pub dkappa: f64,
}

/// Curve strain ε̄0 [-] at initial yield (σ_c = r0 f_cm on the ascending branch) and the
/// offset κ0 = ε̄0 − r0 f_cm/E [-].
pub fn initial_yield(p: &ConcreteParams) -> (f64, f64) {
    let r = p.initial_yield_ratio.clamp(0.0, 1.0);
    if r == 0.0 {
        return (0.0, 0.0);
    }
    let kp = p.curve().kp;
    let b = kp - r * (kp - 2.0);
    let eta = 0.5 * (b - (b * b - 4.0 * r).max(0.0).sqrt());
    let e0 = eta * p.eps_c1;
    (e0, e0 - r * p.fcm / p.ec)
}

/// Start ε̄* [-] of the linear post-peak branch: the curve strain beyond the peak at which
/// the plastic modulus H = E E_t/(E − E_t) of the MC90 curve reaches −h E
/// (h = `softening_limit`), i.e. E_t = −h E/(1 − h). None if the curve is never that steep
/// before ε_lim (where its slope is steepest) or h ≥ 1.
///
/// On the ascending formula dσ/dε = (f_cm/ε_c1)(k_p − 2η − aη²)/(1 + aη)², a = k_p − 2;
/// setting it to E_t gives (a + m a²)η² + (2 + 2ma)η − (k_p − m) = 0, m = E_t ε_c1/f_cm.
pub fn softening_start(p: &ConcreteParams) -> Option<f64> {
    let h = p.softening_limit;
    if !(h > 0.0 && h < 1.0) {
        return None;
    }
    let c = p.curve();
    let et = -h * p.ec / (1.0 - h);
    if c.eval(c.eps_lim()).1 >= et {
        return None;
    }
    let a = c.kp - 2.0;
    let m = et * c.eps_c1 / c.fcm;
    let qa = a + m * a * a;
    let qb = 2.0 + 2.0 * m * a;
    let qc = -(c.kp - m);
    let eta = if qa.abs() < 1e-14 {
        -qc / qb
    } else {
        let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
        let r1 = (-qb + disc) / (2.0 * qa);
        let r2 = (-qb - disc) / (2.0 * qa);
        if (1.0..=c.eta_lim + 1e-12).contains(&r1) {
            r1
        } else {
            r2
        }
    };
    Some(eta.clamp(1.0, c.eta_lim) * c.eps_c1)
}

/// Hardening law σ_c(ε̄) [Pa] and slope [Pa]: the MC90 curve, continued beyond ε̄* (see
/// [`softening_start`]) by a straight line of slope E_t = −hE/(1 − h) down to zero stress
/// (then σ_c = 0). The limit keeps the local return-mapping problem well posed: with the
/// raw MC90 branch the plastic modulus reaches ≈ −0.54 E near ε_lim, below −nᵀDn for
/// biaxial compression, where the strain-driven point problem has no (unique) solution.
pub fn hardening_curve(p: &ConcreteParams, ebar: f64) -> (f64, f64) {
    let c = p.curve();
    if let Some(es) = softening_start(p) {
        if ebar > es {
            let (s0, _) = c.eval(es);
            let et = -p.softening_limit * p.ec / (1.0 - p.softening_limit);
            let s = s0 + et * (ebar - es);
            return if s > 0.0 { (s, et) } else { (0.0, 0.0) };
        }
    }
    c.eval(ebar)
}

/// σ_c, κ and their derivatives at curve strain `ebar` [-].
pub fn hardening(p: &ConcreteParams, ebar: f64) -> Hardening {
    let (s, ds) = hardening_curve(p, ebar);
    let (_, k0) = initial_yield(p);
    Hardening {
        sigma_c: s,
        dsigma_c: ds,
        kappa: ebar - s / p.ec - k0,
        dkappa: 1.0 - ds / p.ec,
    }
}

/// Normalised equivalent stress σ̂_e [Pa] and its gradient [-].
pub fn sigma_hat(p: &ConcreteParams, s: &[f64; 3]) -> (f64, [f64; 3]) {
    let (se, g) = ottosen::equivalent_stress_gradient(&p.ottosen, s);
    let q = p.q_norm();
    (se / q, g.map(|v| v / q))
}

/// Result of a plastic update.
#[derive(Debug, Clone, Copy)]
pub struct PlasticUpdate {
    /// Stress (σx, σy, τxy) [Pa].
    pub stress: [f64; 3],
    /// Plastic strain (εx, εy, γxy) [-].
    pub plastic_strain: [f64; 3],
    /// Curve strain ε̄ [-].
    pub ebar: f64,
    /// Consistent tangent [Pa].
    pub tangent: [[f64; 3]; 3],
    /// Whether plastic flow occurred.
    pub plastic: bool,
}

/// Elastoplastic update from (`ep_n`, `ebar_n`) at the committed strain `eps_n` to the
/// total strain `eps`. Tries one step, then 2, 4, … substeps (the tangent returned by a
/// substepped update is that of the last substep, i.e. only approximately consistent).
pub fn update(
    p: &ConcreteParams,
    eps_n: &[f64; 3],
    ep_n: &[f64; 3],
    ebar_n: f64,
    eps: &[f64; 3],
) -> Result<PlasticUpdate, MaterialError> {
    let mut m = 1;
    let mut last_err = None;
    while m <= MAX_SUBSTEPS {
        let mut ep = *ep_n;
        let mut eb = ebar_n;
        let mut res = None;
        let mut ok = true;
        for k in 1..=m {
            let t = k as f64 / m as f64;
            let e: [f64; 3] = std::array::from_fn(|i| eps_n[i] + t * (eps[i] - eps_n[i]));
            match step(p, &ep, eb, &e) {
                Ok(u) => {
                    ep = u.plastic_strain;
                    eb = u.ebar;
                    res = Some(u);
                }
                Err((it, r)) => {
                    last_err = Some(MaterialError::ReturnMappingNotConverged {
                        iterations: it,
                        substeps: m,
                        residual: r,
                        strain: *eps,
                    });
                    ok = false;
                    break;
                }
            }
        }
        if ok {
            if let Some(u) = res {
                return Ok(u);
            }
        }
        m *= 2;
    }
    Err(
        last_err.unwrap_or(MaterialError::ReturnMappingNotConverged {
            iterations: 0,
            substeps: MAX_SUBSTEPS,
            residual: f64::NAN,
            strain: *eps,
        }),
    )
}

/// Solve the 4×4 linear system a x = b by Gaussian elimination with partial pivoting.
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> Option<[f64; 4]> {
    for c in 0..4 {
        let piv = (c..4).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[piv][c].abs() < 1e-300 || !a[piv][c].is_finite() {
            return None;
        }
        a.swap(c, piv);
        b.swap(c, piv);
        for r in c + 1..4 {
            let f = a[r][c] / a[c][c];
            let pivot_row = a[c];
            for (ark, ack) in a[r].iter_mut().zip(pivot_row.iter()).skip(c) {
                *ark -= f * ack;
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0.0; 4];
    for r in (0..4).rev() {
        let s: f64 = (r + 1..4).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

/// One backward-Euler step; on failure returns (iterations, residual).
fn step(
    p: &ConcreteParams,
    ep_n: &[f64; 3],
    ebar_n: f64,
    eps: &[f64; 3],
) -> Result<PlasticUpdate, (usize, f64)> {
    let d = d_matrix(p.ec, p.nu);
    let ee: [f64; 3] = std::array::from_fn(|i| eps[i] - ep_n[i]);
    let s_tr: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| d[i][j] * ee[j]).sum());
    let h_n = hardening(p, ebar_n);
    let (se_tr, _) = sigma_hat(p, &s_tr);
    if se_tr <= h_n.sigma_c * (1.0 + 1e-13) {
        return Ok(PlasticUpdate {
            stress: s_tr,
            plastic_strain: *ep_n,
            ebar: ebar_n,
            tangent: d,
            plastic: false,
        });
    }
    let (e, nu, f) = (p.ec, p.nu, p.fcm);
    // Compliance C = D⁻¹.
    let c = [
        [1.0 / e, -nu / e, 0.0],
        [-nu / e, 1.0 / e, 0.0],
        [0.0, 0.0, 2.0 * (1.0 + nu) / e],
    ];
    // Scaling: unknown y = (σ/f, ε̄/ε_c1), residual R = (E r_σ/f, r_f/f).
    let rs = [e / f, e / f, e / f, 1.0 / f];
    let cs = [f, f, f, p.eps_c1];
    let resid = |s: &[f64; 3], eb: f64| -> ([f64; 4], f64) {
        let h = hardening(p, eb);
        let dl = h.kappa - h_n.kappa;
        let (se, n) = sigma_hat(p, s);
        let mut r = [0.0; 4];
        for i in 0..3 {
            let cs_i: f64 = (0..3).map(|j| c[i][j] * (s[j] - s_tr[j])).sum();
            r[i] = (cs_i + dl * n[i]) * rs[i];
        }
        r[3] = (se - h.sigma_c) * rs[3];
        let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        (r, norm)
    };
    let jac = |s: &[f64; 3], eb: f64| -> [[f64; 4]; 4] {
        let h = hardening(p, eb);
        let dl = h.kappa - h_n.kappa;
        let (_, n) = sigma_hat(p, s);
        let q = p.q_norm();
        let hs = ottosen::equivalent_stress_hessian(&p.ottosen, s);
        let mut j = [[0.0; 4]; 4];
        for a in 0..3 {
            for b in 0..3 {
                j[a][b] = c[a][b] + dl * hs[a][b] / q;
            }
            j[a][3] = h.dkappa * n[a];
            j[3][a] = n[a];
        }
        j[3][3] = -h.dsigma_c;
        j
    };
    let scaled = |j: &[[f64; 4]; 4]| -> [[f64; 4]; 4] {
        std::array::from_fn(|a| std::array::from_fn(|b| rs[a] * j[a][b] * cs[b]))
    };

    let mut s = s_tr;
    let mut eb = ebar_n;
    let (mut r, mut norm) = resid(&s, eb);
    let mut it = 0;
    'newton: while norm > TOL {
        it += 1;
        if it > MAX_ITER || !norm.is_finite() {
            return Err((it, norm));
        }
        let js = scaled(&jac(&s, eb));
        let dy = solve4(js, r.map(|v| -v)).ok_or((it, norm))?;
        // Backtracking line search on ‖R‖ (keeps ε̄ ≥ ε̄_n, i.e. Δλ ≥ 0).
        let mut t = 1.0;
        loop {
            let s_new: [f64; 3] = std::array::from_fn(|i| s[i] + t * dy[i] * cs[i]);
            let eb_new = (eb + t * dy[3] * cs[3]).max(ebar_n);
            let (r_new, n_new) = resid(&s_new, eb_new);
            if n_new.is_finite() && (n_new <= (1.0 - 1e-4 * t) * norm || t < 1e-3) {
                if n_new >= norm && norm < STAGNATION_TOL {
                    // Round-off floor reached (no descent possible): accept the iterate.
                    break 'newton;
                }
                s = s_new;
                eb = eb_new;
                r = r_new;
                norm = n_new;
                break;
            }
            t *= 0.5;
        }
    }
    // Consistent tangent: J [dσ; dε̄] = [dε; 0].
    let j = jac(&s, eb);
    let js = scaled(&j);
    let mut tangent = [[0.0; 3]; 3];
    for col in 0..3 {
        let mut b = [0.0; 4];
        b[col] = rs[col];
        let y = solve4(js, b).ok_or((it, norm))?;
        for row in 0..3 {
            tangent[row][col] = y[row] * cs[row];
        }
    }
    let h = hardening(p, eb);
    let dl = h.kappa - h_n.kappa;
    let (_, n) = sigma_hat(p, &s);
    let ep: [f64; 3] = std::array::from_fn(|i| ep_n[i] + dl * n[i]);
    Ok(PlasticUpdate {
        stress: s,
        plastic_strain: ep,
        ebar: eb,
        tangent,
        plastic: true,
    })
}
