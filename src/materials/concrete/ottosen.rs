//! Ottosen four-parameter criterion in plane stress (docs/theory-concrete.md §2).
//!
//! Stress vectors are Voigt plane-stress vectors (σx, σy, τxy) [Pa], tension positive,
//! σz = τxz = τyz = 0 (the deviator still has s_z = −(σx + σy)/3).

use crate::materials::mc90::OttosenParams;

/// Largest c2 used in λ(θ): dλ/dc is singular at |c| = 1 when c2 = 1 (docs/theory-concrete.md §2).
const C2_MAX: f64 = 1.0 - 1e-12;

/// Stress invariants of a plane-stress state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Invariants {
    /// First invariant I1 = σx + σy [Pa].
    pub i1: f64,
    /// Second deviatoric invariant J2 [Pa²].
    pub j2: f64,
    /// Third deviatoric invariant J3 = det s [Pa³].
    pub j3: f64,
    /// cos 3θ (MC90/Ottosen convention) clamped to [−1, 1]; 0 when J2 = 0 [-].
    pub cos3theta: f64,
}

/// Invariants I1, J2, J3 and cos3θ = (3√3/2) J3 / J2^(3/2) of a plane-stress state `s` [Pa].
pub fn invariants(s: &[f64; 3]) -> Invariants {
    let i1 = s[0] + s[1];
    let m = i1 / 3.0;
    let (sx, sy, sz, t) = (s[0] - m, s[1] - m, -m, s[2]);
    let j2 = 0.5 * (sx * sx + sy * sy + sz * sz) + t * t;
    let j3 = sx * sy * sz - sz * t * t;
    let cos3theta = if j2 <= 0.0 {
        0.0
    } else {
        (1.5 * 3f64.sqrt() * j3 / j2.powf(1.5)).clamp(-1.0, 1.0)
    };
    Invariants {
        i1,
        j2,
        j3,
        cos3theta,
    }
}

/// Principal stresses of a plane-stress state including σz = 0, sorted σ1 ≥ σ2 ≥ σ3 [Pa].
pub fn principal_sorted(s: &[f64; 3]) -> [f64; 3] {
    let c = 0.5 * (s[0] + s[1]);
    let r = (0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2]).sqrt();
    let mut v = [c + r, c - r, 0.0];
    v.sort_by(|a, b| b.total_cmp(a));
    v
}

/// Lode angle θ [rad] in the MC90/Ottosen convention, θ ∈ [0, π/3]:
/// cos 3θ = (3√3/2) J3/J2^(3/2); θ = 0 tensile meridian, θ = π/3 compressive meridian.
/// Evaluated as θ = atan2(√3(σ2 − σ3), 2σ1 − σ2 − σ3) from the sorted principal stresses,
/// which is equivalent but, unlike acos(cos3θ)/3, accurate to round-off at the meridians.
/// Returns 0 for σ = 0.
pub fn lode_angle_mc90(s: &[f64; 3]) -> f64 {
    let [s1, s2, s3] = principal_sorted(s);
    if s1 == s3 {
        return 0.0;
    }
    (3f64.sqrt() * (s2 - s3)).atan2(2.0 * s1 - s2 - s3)
}

/// Lode angle θ_OH [rad] in the Owen–Hinton / Nayak–Zienkiewicz convention, θ ∈ [−π/6, π/6]:
/// sin 3θ_OH = −(3√3/2) J3/J2^(3/2); θ_MC90 = θ_OH + π/6.
pub fn lode_angle_owen_hinton(s: &[f64; 3]) -> f64 {
    lode_angle_mc90(s) - std::f64::consts::FRAC_PI_6
}

/// λ(cos3θ) [-] and dλ/d(cos3θ) [-].
///
/// The two branches of seed eq. 17 (docs/theory-concrete.md §2) are the same analytic function,
/// since π/3 − ⅓ arccos(−x) = ⅓ arccos(x): λ = c1 cos[⅓ arccos(c2 cos3θ)] for all θ. c2 is capped
/// at 1 − 1e-12 so that the derivative stays finite at |cos3θ| = 1.
pub fn lambda(p: &OttosenParams, c: f64) -> (f64, f64) {
    let c2 = p.c2.min(C2_MAX);
    let x = (c2 * c).clamp(-1.0, 1.0);
    let psi = x.acos();
    let lam = p.c1 * (psi / 3.0).cos();
    let dlam = p.c1 * c2 * (psi / 3.0).sin() / (3.0 * (1.0 - x * x).sqrt());
    (lam, dlam)
}

/// Ottosen failure function F(σ) = α J2/f² + λ √J2/f + β I1/f − 1 [-] for strength `fcm`
/// [Pa] (F < 0 inside, F = 0 on the surface).
pub fn criterion(p: &OttosenParams, fcm: f64, s: &[f64; 3]) -> f64 {
    let inv = invariants(s);
    let (lam, _) = lambda(p, inv.cos3theta);
    p.alpha * inv.j2 / (fcm * fcm) + lam * inv.j2.sqrt() / fcm + p.beta * inv.i1 / fcm - 1.0
}

/// Plane-stress derivatives of I1, J2 and J3 with respect to (σx, σy, τxy).
fn invariant_gradients(s: &[f64; 3], inv: &Invariants) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let m = inv.i1 / 3.0;
    let (sx, sy, t) = (s[0] - m, s[1] - m, s[2]);
    let di1 = [1.0, 1.0, 0.0];
    let dj2 = [sx, sy, 2.0 * t];
    let q = 2.0 * inv.j2 / 3.0;
    let dj3 = [
        sx * sx + t * t - q,
        sy * sy + t * t - q,
        2.0 * t * (sx + sy),
    ];
    (di1, dj2, dj3)
}

/// Gradient ∂F/∂(σx, σy, τxy) [1/Pa] of [`criterion`] (docs/theory-concrete.md §2). At σ = 0
/// (J2 = 0) the deviatoric part is undefined and only the hydrostatic part β/f·∂I1 is returned.
pub fn criterion_gradient(p: &OttosenParams, fcm: f64, s: &[f64; 3]) -> [f64; 3] {
    let inv = invariants(s);
    let (di1, dj2, dj3) = invariant_gradients(s, &inv);
    let f_i1 = p.beta / fcm;
    if inv.j2 <= 0.0 {
        return [f_i1 * di1[0], f_i1 * di1[1], 0.0];
    }
    let c = inv.cos3theta;
    let (lam, dlam) = lambda(p, c);
    let sj2 = inv.j2.sqrt();
    let f_j2 =
        p.alpha / (fcm * fcm) + lam / (2.0 * fcm * sj2) - 1.5 * c / inv.j2 * (sj2 / fcm) * dlam;
    let f_j3 = 1.5 * 3f64.sqrt() * dlam / (fcm * inv.j2);
    std::array::from_fn(|i| f_i1 * di1[i] + f_j2 * dj2[i] + f_j3 * dj3[i])
}

/// Equivalent stress σ_e(σ) [Pa]: the strength f for which F(σ; f) = 0 (docs/theory-concrete.md
/// §2), σ_e = ½[p + √(p² + 4αJ2)], p = λ√J2 + βI1. Positively homogeneous of degree 1;
/// σ_e ≥ f_cm ⇔ F(σ; f_cm) ≥ 0.
pub fn equivalent_stress(p: &OttosenParams, s: &[f64; 3]) -> f64 {
    // The value alone, in the operations of [`equivalent_stress_gradient`] (same bits): the
    // routing check of every elastic point calls it.
    let inv = invariants(s);
    if inv.j2 <= 0.0 {
        return (p.beta * inv.i1).max(0.0);
    }
    let (lam, _) = lambda(p, inv.cos3theta);
    let pp = lam * inv.j2.sqrt() + p.beta * inv.i1;
    let root = (pp * pp + 4.0 * p.alpha * inv.j2).sqrt();
    0.5 * (pp + root)
}

/// σ_e [Pa] and its gradient ∂σ_e/∂(σx, σy, τxy) [-]. At σ = 0 the gradient is that of
/// the limit along the hydrostatic direction, (β, β, 0)·[I1 > 0], and is only used as a
/// harmless placeholder (σ = 0 never lies on a loading surface with σ_c > 0).
pub fn equivalent_stress_gradient(p: &OttosenParams, s: &[f64; 3]) -> (f64, [f64; 3]) {
    let inv = invariants(s);
    let (di1, dj2, dj3) = invariant_gradients(s, &inv);
    if inv.j2 <= 0.0 {
        let v = (p.beta * inv.i1).max(0.0);
        let g = if v > 0.0 { p.beta } else { 0.0 };
        return (v, [g, g, 0.0]);
    }
    let (lam, dlam) = lambda(p, inv.cos3theta);
    value_and_gradient(p, &inv, (&di1, &dj2, &dj3), lam, dlam)
}

/// σ_e [Pa] and ∂σ_e/∂σ [-] off the apex (J2 > 0) from the invariants, their gradients and
/// λ, dλ/dc at c = cos3θ: shared by [`equivalent_stress_gradient`] and
/// [`equivalent_stress_derivatives`] so the two give the same bits.
fn value_and_gradient(
    p: &OttosenParams,
    inv: &Invariants,
    (di1, dj2, dj3): (&[f64; 3], &[f64; 3], &[f64; 3]),
    lam: f64,
    dlam: f64,
) -> (f64, [f64; 3]) {
    let c = inv.cos3theta;
    let sj2 = inv.j2.sqrt();
    let pp = lam * sj2 + p.beta * inv.i1;
    let root = (pp * pp + 4.0 * p.alpha * inv.j2).sqrt();
    let se = 0.5 * (pp + root);
    // ∂σ_e/∂p and ∂σ_e/∂J2 (explicit α-term)
    let d_p = 0.5 * (1.0 + pp / root);
    let d_j2_direct = p.alpha / root;
    // p = λ(c) √J2 + β I1 with c = (3√3/2) J3 J2^(-3/2)
    let dc_dj2 = -1.5 * c / inv.j2;
    let dc_dj3 = 1.5 * 3f64.sqrt() / inv.j2.powf(1.5);
    let p_j2 = lam / (2.0 * sj2) + sj2 * dlam * dc_dj2;
    let p_j3 = sj2 * dlam * dc_dj3;
    let g_i1 = d_p * p.beta;
    let g_j2 = d_p * p_j2 + d_j2_direct;
    let g_j3 = d_p * p_j3;
    let g = std::array::from_fn(|i| g_i1 * di1[i] + g_j2 * dj2[i] + g_j3 * dj3[i]);
    (se, g)
}

/// Uniaxial-compression factor q_c = σ_e(−1, 0, 0) [-] (docs/theory-concrete.md §4): σ_e of a
/// uniaxial compression of magnitude f is q_c f.
pub fn q_c(p: &OttosenParams) -> f64 {
    // Memoised per thread for the last parameter set: the return mapping normalises σ_e by
    // q_c at every residual, and one evaluation costs an arccos (a sixth of a plastic run).
    thread_local! {
        static LAST: std::cell::Cell<Option<(OttosenParams, f64)>> =
            const { std::cell::Cell::new(None) };
    }
    LAST.with(|last| match last.get() {
        Some((k, q)) if k == *p => q,
        _ => {
            let q = equivalent_stress(p, &[-1.0, 0.0, 0.0]);
            last.set(Some((*p, q)));
            q
        }
    })
}

/// λ [-], dλ/dc [-] and d²λ/dc² [-] at c = cos3θ (see [`lambda`]): with x = c2 c,
/// ψ = arccos x, d²λ/dx² = (c1/3)[x sin(ψ/3)/√(1 − x²) − cos(ψ/3)/3]/(1 − x²).
/// `psi3` is ψ/3 ([`Kept`]).
fn lambda_d2(p: &OttosenParams, c: f64, psi3: f64) -> (f64, f64, f64) {
    // The operations of [`lambda`] (same bits) sharing its arccos and sine/cosine.
    let c2 = p.c2.min(C2_MAX);
    let x = (c2 * c).clamp(-1.0, 1.0);
    let (sin3, cos3) = psi3.sin_cos();
    let lam = p.c1 * cos3;
    let dlam = p.c1 * c2 * sin3 / (3.0 * (1.0 - x * x).sqrt());
    let s2 = 1.0 - x * x;
    let d2 = p.c1 / 3.0 * (x * sin3 / s2.sqrt() - cos3 / 3.0) / s2;
    (lam, dlam, c2 * c2 * d2)
}

/// Outer product a bᵀ.
fn outer(a: &[f64; 3], b: &[f64; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i] * b[j]))
}

/// Hessian ∂²σ_e/∂σ² [1/Pa], analytic (σ_e differentiated twice; derivation in
/// docs/theory-concrete.md §2). With u = √J2, c = cos3θ = k J3 u⁻³ (k = 3√3/2),
/// p = λ(c) u + β I1 and R = √(p² + 4αJ2), σ_e = ½(p + R) has the gradient
/// g = ½(1 + p/R) ∇p + (α/R) ∇J2 and the Hessian
/// H = ∇p ⊗ α(2J2 ∇p − p ∇J2)/R³ + ½(1 + p/R) ∇²p − ∇J2 ⊗ α(p ∇p + 2α ∇J2)/R³ +
/// (α/R) ∇²J2 with ∇²p = λ'' u ∇c⊗∇c + λ'(∇c⊗∇u + ∇u⊗∇c) + λ' u ∇²c + λ ∇²u.
/// Symmetrised (it is symmetric up to round-off). Zero at σ = 0, the apex of the surface
/// (J2 = 0), where σ_e is not twice differentiable; no loading surface passes through it.
pub fn equivalent_stress_hessian(p: &OttosenParams, s: &[f64; 3]) -> [[f64; 3]; 3] {
    equivalent_stress_derivatives(p, s).2
}

/// σ_e [Pa], its gradient [-] and its Hessian [1/Pa] in one pass: the values of
/// [`equivalent_stress_gradient`] and [`equivalent_stress_hessian`] to the bit (the same
/// operations), with the invariants, the arccos and the sine/cosine of λ(θ) evaluated once
/// instead of four times (the return mapping needs all three at every Newton iterate).
pub fn equivalent_stress_derivatives(
    p: &OttosenParams,
    s: &[f64; 3],
) -> (f64, [f64; 3], [[f64; 3]; 3]) {
    derivatives_kept(p, s, &Kept::new(p, s))
}

/// The invariants of a stress and the angle ψ/3 = ⅓ arccos(c2 cos3θ) of λ(θ) (None at the
/// apex, J2 = 0): what [`equivalent_stress_kept`] evaluates and [`derivatives_kept`]
/// reuses, so that a return mapping checks its trial stress by σ_e and, if it yields,
/// forms the derivatives there without a second arccos.
#[derive(Debug, Clone, Copy)]
pub struct Kept {
    inv: Invariants,
    psi3: Option<f64>,
}

impl Kept {
    /// The invariants of `s` and ψ/3 (the operations of [`lambda`] and [`lambda_d2`]).
    pub fn new(p: &OttosenParams, s: &[f64; 3]) -> Self {
        let inv = invariants(s);
        let psi3 = (inv.j2 > 0.0).then(|| {
            let c2 = p.c2.min(C2_MAX);
            let x = (c2 * inv.cos3theta).clamp(-1.0, 1.0);
            x.acos() / 3.0
        });
        Self { inv, psi3 }
    }
}

/// σ_e [Pa] of `s` (the bits of [`equivalent_stress`]) and what its derivatives at `s`
/// need ([`derivatives_kept`]).
pub fn equivalent_stress_kept(p: &OttosenParams, s: &[f64; 3]) -> (f64, Kept) {
    let kept = Kept::new(p, s);
    let inv = &kept.inv;
    let Some(psi3) = kept.psi3 else {
        return ((p.beta * inv.i1).max(0.0), kept);
    };
    let lam = p.c1 * psi3.cos();
    let pp = lam * inv.j2.sqrt() + p.beta * inv.i1;
    let root = (pp * pp + 4.0 * p.alpha * inv.j2).sqrt();
    (0.5 * (pp + root), kept)
}

/// An upper bound of h(x) = cos(⅓ arccos x) [-] on [−1, 1] without arccos or cosine: h is
/// the largest root of 4h³ − 3h = x, increasing and concave (h′ = 1/(12h² − 3) falls as h
/// rises from ½ to 1), so each tangent h₀ + (x − x₀)/(12h₀² − 3) at x₀ = 4h₀³ − 3h₀ lies
/// above it (up to the round-off of evaluating them, a few 1e-16); the least of the
/// tangents at h₀ = 0.52, 0.55, 0.6, 0.7, 0.8, 0.9, 1.
fn cos_third_acos_above(x: f64) -> f64 {
    [0.52, 0.55, 0.6, 0.7, 0.8, 0.9, 1.0]
        .iter()
        .map(|&h0: &f64| h0 + (x - (4.0 * h0 * h0 * h0 - 3.0 * h0)) / (12.0 * h0 * h0 - 3.0))
        .fold(f64::INFINITY, f64::min)
}

/// Whether σ_e(s)/q as [`equivalent_stress_kept`] computes it is at most `limit`, proven
/// without its arccos, cosine and power from an upper bound. σ_e = ½(p + √(p² + 4αJ2))
/// increases with p = λ√J2 + βI1, and λ = c1 h(c2 cos 3θ) with h(x) = cos(⅓ arccos x)
/// increasing; the bound takes cos 3θ with J2·√J2 for J2^1.5 and 1e-9 added, h from its
/// tangents ([`cos_third_acos_above`]) and λ raised by 1e-12 of itself, I1, J2 and 4αJ2 in
/// the operations of [`invariants`] and [`equivalent_stress_kept`], and keeps a slack of
/// 1e-12 × (2(λ√J2 + |βI1|) + √(p² + 4αJ2)) for the round-off of both evaluations (a few
/// 1e-16 of the same scale; libm's arccos and cosine are within an ulp). Floating-point
/// rounding is monotone, so `true` means the exact evaluation is at most `limit` too
/// (`q` > 0). `false`: not proven (the point may still be inside); the caller evaluates
/// σ_e. In uniaxial compression the bound is 5 % above σ_e.
pub fn below_by_bound(p: &OttosenParams, s: &[f64; 3], q: f64, limit: f64) -> bool {
    if !(p.c1 >= 0.0 && p.alpha >= 0.0 && q > 0.0) {
        return false;
    }
    let i1 = s[0] + s[1];
    let m = i1 / 3.0;
    let (sx, sy, sz, t) = (s[0] - m, s[1] - m, -m, s[2]);
    let j2 = 0.5 * (sx * sx + sy * sy + sz * sz) + t * t;
    if j2.is_nan() || j2 <= 0.0 {
        return false;
    }
    let sj2 = j2.sqrt();
    let j3 = sx * sy * sz - sz * t * t;
    let c = (1.5 * 3f64.sqrt() * j3 / (j2 * sj2)).clamp(-1.0, 1.0);
    let x = (p.c2.min(C2_MAX) * c + 1e-9).clamp(-1.0, 1.0);
    let lam = p.c1 * cos_third_acos_above(x) * (1.0 + 1e-12);
    if !lam.is_finite() {
        return false;
    }
    let (dev, hyd) = (lam * sj2, p.beta * i1);
    let pu = dev + hyd;
    let root = (pu * pu + 4.0 * p.alpha * j2).sqrt();
    let slack = 1e-12 * (2.0 * (dev + hyd.abs()) + root);
    (0.5 * (pu + root) + slack) / q <= limit
}

/// [`equivalent_stress_derivatives`] at `s` from its [`Kept`] values (same bits).
pub fn derivatives_kept(
    p: &OttosenParams,
    s: &[f64; 3],
    kept: &Kept,
) -> (f64, [f64; 3], [[f64; 3]; 3]) {
    let inv = kept.inv;
    let (di1, dj2, dj3) = invariant_gradients(s, &inv);
    let Some(psi3) = kept.psi3 else {
        let v = (p.beta * inv.i1).max(0.0);
        let g = if v > 0.0 { p.beta } else { 0.0 };
        return (v, [g, g, 0.0], [[0.0; 3]; 3]);
    };
    let (j2, c) = (inv.j2, inv.cos3theta);
    let (lam, dlam, d2lam) = lambda_d2(p, c, psi3);
    let (se, grad) = value_and_gradient(p, &inv, (&di1, &dj2, &dj3), lam, dlam);
    let u = j2.sqrt();
    let k = 1.5 * 3f64.sqrt();
    // c(J2, J3): first and second partial derivatives.
    let c_j3 = k / (j2 * u);
    let c_j2 = -1.5 * c / j2;
    let c_j2j3 = -1.5 * c_j3 / j2;
    let c_j2j2 = 3.75 * c / (j2 * j2);
    // Second derivatives of the invariants in (σx, σy, τxy) (σz = 0, s = σ − I1/3).
    let m = inv.i1 / 3.0;
    let (sx, sy, t) = (s[0] - m, s[1] - m, s[2]);
    let hj2 = [
        [2.0 / 3.0, -1.0 / 3.0, 0.0],
        [-1.0 / 3.0, 2.0 / 3.0, 0.0],
        [0.0, 0.0, 2.0],
    ];
    let (a, b, e) = (2.0 / 3.0 * sx, 2.0 / 3.0 * sy, -2.0 / 3.0 * (sx + sy));
    let hj3 = [
        [a, e, 2.0 / 3.0 * t],
        [e, b, 2.0 / 3.0 * t],
        [2.0 / 3.0 * t, 2.0 / 3.0 * t, 2.0 * (sx + sy)],
    ];
    let gc: [f64; 3] = std::array::from_fn(|i| c_j3 * dj3[i] + c_j2 * dj2[i]);
    let gu: [f64; 3] = std::array::from_fn(|i| dj2[i] / (2.0 * u));
    let gp: [f64; 3] = std::array::from_fn(|i| dlam * u * gc[i] + lam * gu[i] + p.beta * di1[i]);
    let (o32, o23, o22, occ) = (
        outer(&dj3, &dj2),
        outer(&dj2, &dj3),
        outer(&dj2, &dj2),
        outer(&gc, &gc),
    );
    let (ocu, ouc) = (outer(&gc, &gu), outer(&gu, &gc));
    let pp = lam * u + p.beta * inv.i1;
    let r = (pp * pp + 4.0 * p.alpha * j2).sqrt();
    let r3 = r * r * r;
    let se_p = 0.5 * (1.0 + pp / r);
    // ∇(½(1 + p/R)) and ∇(α/R).
    let d_sep: [f64; 3] = std::array::from_fn(|i| p.alpha * (2.0 * j2 * gp[i] - pp * dj2[i]) / r3);
    let d_ar: [f64; 3] =
        std::array::from_fn(|i| -p.alpha * (pp * gp[i] + 2.0 * p.alpha * dj2[i]) / r3);
    let mut h = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let hc = c_j3 * hj3[i][j]
                + c_j2 * hj2[i][j]
                + c_j2j3 * (o32[i][j] + o23[i][j])
                + c_j2j2 * o22[i][j];
            let hu = hj2[i][j] / (2.0 * u) - o22[i][j] / (4.0 * u * u * u);
            let hp =
                d2lam * u * occ[i][j] + dlam * (ocu[i][j] + ouc[i][j]) + dlam * u * hc + lam * hu;
            h[i][j] = gp[i] * d_sep[j] + se_p * hp + dj2[i] * d_ar[j] + p.alpha / r * hj2[i][j];
        }
    }
    for (i, j) in [(1, 0), (2, 0), (2, 1)] {
        let v = 0.5 * (h[i][j] + h[j][i]);
        h[i][j] = v;
        h[j][i] = v;
    }
    (se, grad, h)
}

/// Hessian ∂²σ_e/∂σ² [1/Pa] by central differences of the analytic gradient, step
/// h = 1e-6 · max(|σ|, 1 Pa); relative accuracy ≈ 1e-9 (truncation O(h²), round-off
/// O(ε_mach/h)). Symmetrised. The check of [`equivalent_stress_hessian`] (it was the
/// return mapping's Hessian before the analytic one; 40× slower per plastic update).
pub fn equivalent_stress_hessian_fd(p: &OttosenParams, s: &[f64; 3]) -> [[f64; 3]; 3] {
    let scale = s.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1.0);
    let h = 1e-6 * scale;
    let mut hm = [[0.0; 3]; 3];
    for j in 0..3 {
        let mut sp = *s;
        let mut sm = *s;
        sp[j] += h;
        sm[j] -= h;
        let gp = equivalent_stress_gradient(p, &sp).1;
        let gm = equivalent_stress_gradient(p, &sm).1;
        for (row, (a, b)) in hm.iter_mut().zip(gp.iter().zip(gm.iter())) {
            row[j] = (a - b) / (2.0 * h);
        }
    }
    for (i, j) in [(1, 0), (2, 0), (2, 1)] {
        let a = 0.5 * (hm[i][j] + hm[j][i]);
        hm[i][j] = a;
        hm[j][i] = a;
    }
    hm
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::materials::mc90::OttosenParams;

    const FCM: f64 = 45e6;
    const FTM: f64 = 3.81595e6;

    fn params() -> OttosenParams {
        OttosenParams::from_k(FTM / FCM)
    }

    /// Principal plane-stress state (σ1, σ2) in x–y axes.
    fn ps(a: f64, b: f64) -> [f64; 3] {
        [a, b, 0.0]
    }

    /// Check 3 (docs/theory-concrete.md §7): Lode angles, both conventions (1e-10 abs: exact
    /// states, only round-off in acos/asin near ±1 — computed via clamp so exact).
    #[test]
    fn check3_lode_angles() {
        let d = std::f64::consts::PI / 180.0;
        let cases = [
            (ps(1e6, 0.0), 0.0, -30.0, 1.0),
            (ps(-1e6, 0.0), 60.0, 30.0, -1.0),
            (ps(1e6, -1e6), 30.0, 0.0, 0.0),
        ];
        for (s, t_mc, t_oh, c) in cases {
            assert!((invariants(&s).cos3theta - c).abs() < 1e-10);
            assert!((lode_angle_mc90(&s) - t_mc * d).abs() < 1e-10, "{s:?}");
            assert!(
                (lode_angle_owen_hinton(&s) - t_oh * d).abs() < 1e-10,
                "{s:?}"
            );
            assert!((lode_angle_mc90(&s) - lode_angle_owen_hinton(&s) - 30.0 * d).abs() < 1e-10);
        }
        // The atan2 form agrees with the definition via cos3θ at a generic state, and with
        // the Owen–Hinton definition sin3θ_OH = −cos3θ (1e-12: both well conditioned here).
        let s = [2e6, -25e6, 4e6];
        let c = invariants(&s).cos3theta;
        assert!((lode_angle_mc90(&s) - c.acos() / 3.0).abs() < 1e-12);
        assert!(((3.0 * lode_angle_owen_hinton(&s)).sin() + c).abs() < 1e-12);
        // Same states rotated by 30° in the plane must give the same angle (invariance).
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let rot = |a: f64, b: f64| {
            [
                a * c * c + b * s * s,
                a * s * s + b * c * c,
                (a - b) * s * c,
            ]
        };
        assert!((lode_angle_mc90(&rot(-1e6, 0.0)) - 60.0 * d).abs() < 1e-8);
    }

    /// Check 4 (docs/theory-concrete.md §7): I1, J2, cos3θ, λ, F at reference points (1e-5 abs
    /// on F and cos3θ; λ to 1e-4 and J2 to 1e-3 MPa² because the hand values give them to that many
    /// decimals). Each principal triple (σ1, σ2, σ3) has one zero, so it is the plane-stress
    /// state with the two non-zero values in x, y and σz = 0.
    #[test]
    fn check4_point_values() {
        let p = params();
        let table = [
            ([0.0, -45.0], -45.0, 675.0, -1.0, 6.78774, 0.011657),
            ([3.81595, 0.0], 3.81595, 4.85380, 1.0, 13.16069, -0.001336),
            ([-20.0, -40.0], -60.0, 400.0, 0.0, 11.39938, -0.678007),
            ([2.0, -30.0], -28.0, 321.333, -0.98601, 7.23862, -0.096742),
        ];
        for (s2, i1, j2, c, lam, f) in table {
            let s = [s2[0] * 1e6, s2[1] * 1e6, 0.0];
            let inv = invariants(&s);
            assert!((inv.i1 / 1e6 - i1).abs() < 1e-5, "I1 {s2:?}");
            assert!(
                (inv.j2 / 1e12 - j2).abs() < 1e-3,
                "J2 {s2:?}: {}",
                inv.j2 / 1e12
            );
            assert!(
                (inv.cos3theta - c).abs() < 1e-5,
                "c {s2:?}: {}",
                inv.cos3theta
            );
            let (l, _) = lambda(&p, inv.cos3theta);
            assert!((l - lam).abs() < 1e-4, "λ {s2:?}: {l}");
            let ff = criterion(&p, FCM, &s);
            assert!((ff - f).abs() < 1e-5, "F {s2:?}: {ff}");
        }
    }

    /// Check 5 (docs/theory-concrete.md §7): strength ratios along radial paths (1e-4 rel). Uses
    /// the homogeneity of σ_e: the radial strength along a unit direction d is f_cm/σ_e(d).
    #[test]
    fn check5_strength_ratios() {
        for (k, table) in [
            (0.084799, [0.99465, 0.08491, 1.19306, 1.33134, 0.08547]),
            (0.074425, [0.99522, 0.07485, 1.20774, 1.33111, 0.07610]),
        ] {
            let p = OttosenParams::from_k(k);
            let dirs = [
                [-1.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [-1.0, -1.0, 0.0],
                [-1.0, -0.5, 0.0],
                [1.0, -1.0, 0.0],
            ];
            for (d, want) in dirs.iter().zip(table) {
                let ratio = 1.0 / equivalent_stress(&p, d);
                assert!(((ratio - want) / want).abs() < 1e-4, "k={k} {d:?}: {ratio}");
                // and F = 0 on the surface point (consistency of σ_e with F)
                let s = d.map(|v| v * ratio * FCM);
                assert!(criterion(&p, FCM, &s).abs() < 1e-10);
            }
        }
    }

    /// Check 6 (docs/theory-concrete.md §7): q_c, σ_e homogeneity (1e-9 rel: pure round-off), and
    /// the uniaxial tension ratio σ_e/σ1 = 11.77698 (1e-6 rel, table has 7 digits).
    #[test]
    fn check6_equivalent_stress() {
        let p = OttosenParams::from_k(0.084799);
        assert!((q_c(&p) - 1.0053828).abs() < 1e-6);
        let (lc, _) = lambda(&p, -1.0);
        assert!((lc - 6.787735).abs() < 1e-5);
        assert!((equivalent_stress(&p, &[1.0, 0.0, 0.0]) - 11.77698).abs() < 1e-4);
        for s in [[-30e6, -10e6, 5e6], [2e6, -25e6, 4e6], [1e6, 1e6, 0.0]] {
            let a = equivalent_stress(&p, &s);
            let b = equivalent_stress(&p, &s.map(|v| 2.0 * v));
            assert!(((b - 2.0 * a) / a).abs() < 1e-9);
        }
    }

    /// Check 7 (docs/theory-concrete.md §7): ∂F/∂σ vs hand values (values in 1/MPa, 1e-6 rel) and
    /// gradient of F and σ_e vs central differences (1e-6 rel: FD truncation with h = 1e-4 MPa is
    /// 1e-10).
    #[test]
    fn check7_gradients() {
        let p = params();
        let table = [
            (
                [-30.0, -10.0, 5.0],
                -0.798334,
                [-0.02285331, 0.01234167, 0.01759749],
            ),
            (
                [2.0, -25.0, 4.0],
                -0.061236,
                [0.26843418, -0.01926574, 0.08524442],
            ),
            (
                [-20.0, -20.0, 8.0],
                -0.905418,
                [-0.00532319, -0.00532319, 0.02803170],
            ),
        ];
        for (s_mpa, f, g) in table {
            let s = s_mpa.map(|v| v * 1e6);
            assert!((criterion(&p, FCM, &s) - f).abs() < 1e-6);
            let a = criterion_gradient(&p, FCM, &s).map(|v| v * 1e6);
            for i in 0..3 {
                assert!(
                    ((a[i] - g[i]) / g[i]).abs() < 2e-6,
                    "{s_mpa:?} {i}: {}",
                    a[i]
                );
            }
            let h = 100.0;
            let (_, ge) = equivalent_stress_gradient(&p, &s);
            for i in 0..3 {
                let mut sp = s;
                let mut sm = s;
                sp[i] += h;
                sm[i] -= h;
                let fd = (criterion(&p, FCM, &sp) - criterion(&p, FCM, &sm)) / (2.0 * h);
                let an = criterion_gradient(&p, FCM, &s)[i];
                assert!((fd - an).abs() < 1e-6 * an.abs().max(1e-9), "F grad {i}");
                let fde = (equivalent_stress(&p, &sp) - equivalent_stress(&p, &sm)) / (2.0 * h);
                assert!(
                    (fde - ge[i]).abs() < 1e-6 * ge[i].abs().max(1e-3),
                    "σe grad {i}"
                );
            }
        }
    }

    /// The analytic Hessian of σ_e equals central differences of the analytic gradient
    /// (step 1e-6 |σ|: truncation ~1e-12, round-off ~1e-10 of the gradient's scale / |σ|)
    /// over the plane-stress octant of states: biaxial compression, tension–compression,
    /// shear, near both meridians (cos3θ → ±1, where λ'' is largest). Tolerance 1e-5 of the
    /// largest entry: far above the FD error, far below any wrong or missing term.
    #[test]
    fn analytic_hessian_matches_finite_differences() {
        let p = params();
        let states = [
            [-30.0, -10.0, 5.0],
            [2.0, -25.0, 4.0],
            [-20.0, -20.0, 8.0],
            [-40.0, -12.0, 0.0],
            [-45.0, 0.0, 0.0],
            [-45.0, -45.0, 0.0],
            [3.0, 0.0, 0.0],
            [0.0, 0.0, 10.0],
            [-60.0, -30.0, -15.0],
            [-45.0, -0.001, 0.0],
        ];
        for s_mpa in states {
            let s = s_mpa.map(|v| v * 1e6);
            let an = equivalent_stress_hessian(&p, &s);
            let fd = equivalent_stress_hessian_fd(&p, &s);
            let hmax = fd.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(hmax > 0.0);
            for i in 0..3 {
                for j in 0..3 {
                    assert!(
                        (an[i][j] - fd[i][j]).abs() < 1e-5 * hmax,
                        "{s_mpa:?} H[{i}][{j}] = {} vs FD {}",
                        an[i][j],
                        fd[i][j]
                    );
                }
            }
        }
    }

    /// The bound never proves a state inside a limit its exact σ_e/q passes: at the exact
    /// value less 1e-9 of it (far beyond the round-off of either evaluation, far below the
    /// slack) it says "not proven", over a grid of plane-stress states (compression,
    /// tension, near-hydrostatic, pure shear; the tensile meridian, where λ reaches c1 and
    /// the bound is tight, included); and it does prove the states well inside (uniaxial
    /// compression against 1.06 × its σ_e; every state of the grid against twice its σ_e).
    #[test]
    fn bound_on_equivalent_stress_never_passes_the_exact_value() {
        let p = params();
        let q = q_c(&p);
        let vals = [-60e6, -45e6, -20e6, -3e6, -1e3, 0.0, 1e3, 1e6, 3.8e6, 1e7];
        let mut proved = 0;
        for &a in &vals {
            for &b in &vals {
                for &t in &[0.0, 1e3, 2e6, -7e6] {
                    let s = [a, b, t];
                    let exact = equivalent_stress_kept(&p, &s).0 / q;
                    if exact > 0.0 {
                        assert!(!below_by_bound(&p, &s, q, exact * (1.0 - 1e-9)), "{s:?}");
                    }
                    if below_by_bound(&p, &s, q, 2.0 * exact.abs()) {
                        proved += 1;
                    }
                }
            }
        }
        // Near-hydrostatic biaxial compression: σ_e small against |I1| (cancellation).
        let s = [-30e6, -30e6 + 1.0, 0.5];
        let exact = equivalent_stress_kept(&p, &s).0 / q;
        assert!(!below_by_bound(&p, &s, q, exact - 1e-9 * 30e6));
        // Uniaxial compression (σ_e/q = f by the normalisation): the bound within 6 %.
        assert!(below_by_bound(&p, &[-20e6, 0.0, 0.0], q, 1.06 * 20e6));
        assert!(!below_by_bound(&p, &[-20e6, 0.0, 0.0], q, 20e6));
        let states = vals.len() * vals.len() * 4;
        assert_eq!(proved, states - 1, "all but σ = 0 proved within 2×");
    }

    /// The tangents lie above cos(⅓ arccos x) on [−1, 1] (2001 points) up to round-off
    /// (at a tangent's touching point the two evaluations differ in the last bits; the
    /// bound's 1e-12 covers that) and within 2.5 % of it (the first tangent, next to
    /// x = −1 where the slope is infinite, is the loosest).
    #[test]
    fn tangents_bound_cos_third_acos_from_above() {
        for i in 0..=2000 {
            let x = -1.0 + i as f64 / 1000.0;
            let h = (x.acos() / 3.0).cos();
            let b = cos_third_acos_above(x);
            assert!(
                b * (1.0 + 1e-12) >= h && b <= 1.025 * h,
                "x = {x}: {b} against {h}"
            );
        }
    }
}
