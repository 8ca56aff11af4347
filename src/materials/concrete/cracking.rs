//! Smeared fixed orthogonal cracking (seed §5.3, docs/theory-concrete.md §3, §5).
//!
//! After the first crack the point is orthotropic in the fixed crack axes (n, t), n = normal
//! of crack 1 at angle φ from x, t = n rotated by +90°; the Poisson effect is neglected
//! (seed: "insignificant Poisson effect"). With ε' = T(φ)(ε − ε_p) (ε_p = plastic strain of
//! the uncracked phase, frozen):
//!
//! * each direction i ∈ {n, t} has a uniaxial law σ_i(ε'_i):
//!   - cracked direction, ε ≥ 0: tension-softening envelope (seed eq. 21) on loading,
//!     secant to the origin on unloading/reloading (closing/reopening);
//!   - uncracked direction, ε ≥ 0: σ = E ε; a second crack forms (normal t) when σ_t ≥ f_tm;
//!   - ε < 0 (closed crack or compression): 1-D elastoplasticity on the MC90 curve
//!     (same hardening variable ε̄ as the uncracked model, one per direction, closed-form
//!     return), so struts parallel to cracks crush at f_cm;
//! * shear: τ_nt = β G γ_nt, β from [`super::ShearRetention`] at the largest crack-normal
//!   strain reached (so a closed crack keeps its shear reduction);
//! * two cracks both open: each keeps its own law and the shear retention (default), or
//!   no stress at all (`zero_double_crack`, the seed: "concrete stresses are then zeroed").
//!
//! Stress σ = Tᵀ σ', tangent Tᵀ D' T. D' is the consistent tangent of the laws above: it
//! has the off-diagonal term ∂τ/∂ε_n = β'(ε_n) G γ while crack 1 opens on its envelope
//! (non-symmetric) and a negative normal entry on the softening branch.
//! The tangent is *not* consistent (documented algorithmic choice) where the stress is
//! identically zero but the residual stiffness is returned, when `secant_crack_tangent` is
//! set, in the step in which a crack forms (the regime switch is discontinuous), and with
//! IMPL-EX where the Rankine cut-off is active (the crack laws' tangent is returned there,
//! [`PrincipalStressLimit::TensileStrength`]).

use super::{compression, ConcreteParams, ConcreteState, MaterialError, UpdateResult};

/// Upper limit of the shear stress transferred across a fixed crack by aggregate interlock.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum CrackShearLimit {
    /// No limit: τ_nt = β G γ_nt however large (the seed's model).
    #[default]
    None,
    /// Vecchio & Collins (1986), from Walraven's aggregate-interlock tests:
    /// |τ_nt| ≤ v_ci,max = 0.18 √f_cm / (0.31 + 24 w/(a + 16)) (MPa, mm), crack width
    /// w = h ε_max (h the crack band width), a the largest aggregate size.
    VecchioCollins1986 {
        /// Largest aggregate size a [m].
        d_agg: f64,
    },
}

impl CrackShearLimit {
    /// The largest shear stress v_max [Pa] a crack transfers and dv_max/dε_max [Pa], for
    /// concrete strength `fcm` [Pa], largest crack-normal strain `eps` [-] and crack band
    /// width `h` [m]; None without a limit.
    pub fn limit(&self, fcm: f64, eps: f64, h: f64) -> Option<(f64, f64)> {
        match *self {
            CrackShearLimit::None => None,
            CrackShearLimit::VecchioCollins1986 { d_agg } => {
                // 24 w/(a + 16 mm) with w, a in metres: 24/(a + 0.016) per metre of width.
                let c = 24.0 / (d_agg + 0.016);
                let w = h * eps.max(0.0);
                let top = 0.18 * (fcm / 1e6).sqrt() * 1e6;
                let den = 0.31 + c * w;
                let dv = if eps > 0.0 {
                    -top * c * h / (den * den)
                } else {
                    0.0
                };
                Some((top / den, dv))
            }
        }
    }
}

/// Limit on the largest principal stress of a point with fixed cracks: a remedy for stress
/// locking (Rots 1988), where the shear retained across an inclined crack builds a
/// principal tension at an angle to the crack axes that no crack check sees (the second
/// crack is checked at 90° to the first only), so that cracked concrete carries tension
/// well past f_tm (docs/theory-concrete.md §5.5b). Both cut-offs cap the principal tension
/// in every direction, also near the crack axes: restricting them to directions inclined to
/// the cracks was probed on the beams (session 15) and undid the cut-off on OA1.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum PrincipalStressLimit {
    /// No limit (the seed's model).
    #[default]
    None,
    /// Rankine tension cut-off σ1 ≤ f_tm on the stress of the crack laws
    /// ([`cap_principal_stress`]). Tangent: the cut-off's consistent one with implicit crack
    /// laws; with IMPL-EX the crack laws' own (symmetric, positive) tangent, since the
    /// symmetric part of the consistent one is indefinite (docs/theory-concrete.md §5.5b).
    TensileStrength,
    /// Rankine cut-off that softens with its own inclined crack (a simplified
    /// multi-directional crack, de Borst & Nauta 1985): σ1 ≤ f(κ) = σ_env(ε0 + κ) =
    /// f_tm exp(−κ/α), the crack laws' tension-softening envelope (same α, so the same
    /// crack-band regularisation by the element's band width), κ the largest cut-off crack
    /// strain reached, the strain the return removes along the principal direction,
    /// (σ1_free − σ1)/E ([`cap_softening`]). With IMPL-EX the cap is f(κ̃) at the extrapolated
    /// κ̃ and the tangent the crack laws' one, as for [`Self::TensileStrength`]
    /// (docs/theory-concrete.md §5.5b).
    Softening,
}

/// Rankine tension cut-off of a fixed-cracked point's stress: if the largest principal
/// stress σ1 of `sl` = (σ_n, σ_t, τ_nt) [Pa] exceeds `f` [Pa], `sl` becomes
/// f n1n1 + σ2 n2n2 (principal directions and σ2 kept; both set to f if σ2 > f too), the
/// return of perfect Rankine plasticity with ν = 0; `dl` [Pa] (dσ'/dε' of the crack laws)
/// becomes its consistent tangent Tᵀ A Q dl, with Q, T the stress and strain rotations to the
/// principal axes and A = diag(0, 1, (f − σ2)/(σ1 − σ2)) (the last term the rotation of the
/// principal axes), plus the regularising stiffness `k_min` [Pa] along n1 (perfect
/// plasticity has none). Returns whether the cut-off is active.
pub fn cap_principal_stress(f: f64, sl: &mut [f64; 3], dl: &mut [[f64; 3]; 3], k_min: f64) -> bool {
    cap_principal_stress_with(f, 0.0, sl, dl, k_min)
}

/// As [`cap_principal_stress`] with a cap that moves with the stress: dσ1 = `a1` dσ1_free
/// (`a1` [-] = 0 for a fixed cap; a softening cap's f'/(E + f'), [`cap_softening`]); a
/// capped σ2 follows σ1.
fn cap_principal_stress_with(
    f: f64,
    a1: f64,
    sl: &mut [f64; 3],
    dl: &mut [[f64; 3]; 3],
    k_min: f64,
) -> bool {
    let c = 0.5 * (sl[0] + sl[1]);
    let r = (0.25 * (sl[0] - sl[1]).powi(2) + sl[2] * sl[2]).sqrt();
    let (s1, s2) = (c + r, c - r);
    if s1 <= f {
        return false;
    }
    let psi = 0.5 * (2.0 * sl[2]).atan2(sl[0] - sl[1]);
    let t = strain_transform(psi);
    let (sn, cs) = psi.sin_cos();
    let q = [
        [cs * cs, sn * sn, 2.0 * cs * sn],
        [sn * sn, cs * cs, -2.0 * cs * sn],
        [-cs * sn, cs * sn, cs * cs - sn * sn],
    ];
    let (s2c, a) = if s2 > f {
        (f, [a1, 0.0, 0.0])
    } else {
        (s2, [a1, 1.0, (f - s2) / (s1 - s2)])
    };
    // A Q dl, with the regularising k_min along n1 (dσ_11 = k_min dε_11, ε_11 = T[0]·ε').
    let mut aqd = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            aqd[i][j] = a[i] * (0..3).map(|k| q[i][k] * dl[k][j]).sum::<f64>();
        }
    }
    if s2 > f {
        // σ2 = f(κ) too: it moves with σ1.
        aqd[1] = aqd[0];
    }
    for j in 0..3 {
        aqd[0][j] += k_min * t[0][j];
    }
    let mut d = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            d[i][j] = (0..3).map(|k| t[k][i] * aqd[k][j]).sum();
        }
    }
    let sp = [f, s2c, 0.0];
    *sl = std::array::from_fn(|i| (0..3).map(|k| t[k][i] * sp[k]).sum());
    *dl = d;
    true
}

/// Softening Rankine cut-off ([`PrincipalStressLimit::Softening`]) of the crack laws'
/// stress `sl` [Pa] and tangent `dl` [Pa] (crack axes), with committed largest cut-off crack
/// strain `kappa_n` [-], crack-law decay strain `alpha` [-] and regularising stiffness
/// `k_min` [Pa]. The cap is f(κ) = σ_env(ε0 + κ) = f_tm exp(−κ/α), the crack laws'
/// envelope past its peak, and κ = max(κ_n, (σ1_free − f(κ))/E): the strain the return
/// removes along the principal direction, measured with E as the return is that of
/// Rankine plasticity with ν = 0 ([`cap_principal_stress`]).
///
/// * `extrapolated` = Some(κ̃) (IMPL-EX): the cap is f(κ̃), fixed in the increment, and κ
///   is updated afterwards from the stress removed; the tangent is left to the caller.
/// * None (implicit): κ solves E κ + f(κ) = σ1_free (bisection with Newton steps on
///   [κ_n, σ1_free/E], where the left side goes from below σ1_free to above; the first
///   root if the point snaps back, E < |f'|), and the tangent is the consistent one of a
///   cap moving as dσ1 = f'/(E + f') dσ1_free while κ grows.
///
/// Returns the new κ if the cut-off is active, None otherwise (`sl`, `dl` untouched).
pub fn cap_softening(
    p: &ConcreteParams,
    alpha: f64,
    kappa_n: f64,
    extrapolated: Option<f64>,
    sl: &mut [f64; 3],
    dl: &mut [[f64; 3]; 3],
    k_min: f64,
) -> Option<f64> {
    let e0 = p.eps0();
    let cap = |k: f64| tension_envelope(p, alpha, e0 + k.max(0.0));
    let (s1, _) = super::principal_max(sl);
    if let Some(kx) = extrapolated {
        let f = cap(kx).0;
        if !cap_principal_stress_with(f, 0.0, sl, dl, k_min) {
            return None;
        }
        return Some(kappa_n.max((s1 - f) / p.ec));
    }
    let (f_n, _) = cap(kappa_n);
    if s1 <= f_n {
        return None;
    }
    let h = |k: f64| p.ec * k + cap(k).0 - s1;
    if h(kappa_n) >= 0.0 {
        // The stress removed at the committed cap is within κ_n: the cap stays at f(κ_n).
        cap_principal_stress_with(f_n, 0.0, sl, dl, k_min);
        return Some(kappa_n);
    }
    let (mut lo, mut hi) = (kappa_n, s1 / p.ec);
    let mut k = lo;
    for _ in 0..200 {
        let (f, df) = cap(k);
        let v = p.ec * k + f - s1;
        if v.abs() <= 1e-13 * p.ftm || (hi - lo) <= 1e-15 * hi {
            break;
        }
        if v < 0.0 {
            lo = k;
        } else {
            hi = k;
        }
        let slope = p.ec + df;
        let newton = k - v / slope;
        k = if slope > 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
    }
    let (f, df) = cap(k);
    cap_principal_stress_with(f, df / (p.ec + df), sl, dl, k_min);
    Some(k)
}

/// Strain transformation ε' = T ε to axes rotated by `phi` (engineering shear).
pub fn strain_transform(phi: f64) -> [[f64; 3]; 3] {
    let (s, c) = phi.sin_cos();
    [
        [c * c, s * s, c * s],
        [s * s, c * c, -c * s],
        [-2.0 * c * s, 2.0 * c * s, c * c - s * s],
    ]
}

/// Tension envelope σ(ε) [Pa] and slope [Pa] for ε ≥ 0: E ε up to ε0 = f_tm/E, then
/// f_tm exp(−(ε − ε0)/α) (seed eq. 21).
pub fn tension_envelope(p: &ConcreteParams, alpha: f64, eps: f64) -> (f64, f64) {
    let e0 = p.eps0();
    if eps <= e0 {
        (p.ec * eps, p.ec)
    } else {
        let x = (-(eps - e0) / alpha).exp();
        (p.ftm * x, -p.ftm / alpha * x)
    }
}

/// Result of one direction law.
#[derive(Debug, Clone, Copy)]
struct DirResult {
    sigma: f64,
    k: f64,
    emax: f64,
    ebar: f64,
    plastic: f64,
    open: bool,
    loading_crack: bool,
    e_el: f64,
    /// ∂σ/∂ε_lat [Pa]: compression softening by the other direction's tensile strain.
    d_lateral: f64,
    /// Compression reduction factor β_d applied [-] (1 without compression softening).
    beta: f64,
}

/// Committed history of one crack-axis direction.
#[derive(Debug, Clone, Copy)]
struct DirHistory {
    /// A crack normal to this direction exists.
    cracked: bool,
    /// Largest crack strain reached [-].
    emax: f64,
    /// Curve strain of the 1-D compression law [-].
    ebar: f64,
    /// Compressive plastic strain magnitude [-].
    plastic: f64,
    /// Held branch (see [`super::ConcreteState`]): 0 free, 1 loading, −1 unloading.
    frozen: i8,
    /// IMPL-EX: the extrapolated largest crack strain [-] whose secant this direction
    /// follows in tension (None: implicit law).
    extrapolated: Option<f64>,
    /// Compression reduction β_d [-] and dβ_d/dε_lat [-] from the other direction's tensile
    /// strain ([`super::reduction`]).
    reduction: (f64, f64),
}

/// Uniaxial law of one crack-axis direction at strain `e` (`law`: the hardening law of `p`).
fn direction(
    p: &ConcreteParams,
    law: &compression::HardeningLaw,
    alpha: f64,
    h: DirHistory,
    e: f64,
) -> DirResult {
    let DirHistory {
        cracked,
        emax,
        ebar,
        plastic,
        frozen,
        extrapolated,
        reduction: (beta, dbeta),
    } = h;
    let e_el = e + plastic;
    let ebar = ebar.max(law.initial_yield().0);
    let mut r = DirResult {
        sigma: 0.0,
        k: 0.0,
        emax,
        ebar,
        plastic,
        open: false,
        loading_crack: false,
        e_el,
        d_lateral: 0.0,
        beta,
    };
    if e_el >= 0.0 {
        if !cracked {
            r.sigma = p.ec * e_el;
            r.k = p.ec;
        } else if let Some(ex) = extrapolated {
            // IMPL-EX: the secant at the extrapolated e_max up to it, then the smooth,
            // monotone continuation of `implex::tension` (no kink, so no held branch); e_max
            // itself is updated implicitly for the next extrapolation.
            let (s, k) = super::implex::tension(p, alpha, ex, e_el);
            r.sigma = s;
            r.k = k;
            r.emax = e_el.max(emax);
            r.open = e_el > 0.0;
        } else if frozen > 0 || (frozen == 0 && e_el >= emax) || emax <= 0.0 {
            // Loading on the envelope (held there by a frozen branch even a little below
            // e_max: the stress then lies slightly above the secant, an error of the order of
            // the iterates' cycling amplitude).
            let (s, k) = tension_envelope(p, alpha, e_el);
            r.sigma = s;
            r.k = if p.secant_crack_tangent && e_el > 0.0 {
                s / e_el
            } else {
                k
            };
            r.emax = e_el.max(emax);
            r.open = e_el > 0.0;
            r.loading_crack = e_el > 0.0;
        } else {
            // Unloading/reloading on the secant to e_max (held there by a frozen branch
            // even a little beyond e_max).
            let (s, _) = tension_envelope(p, alpha, emax);
            let sec = s / emax;
            r.sigma = sec * e_el;
            r.k = sec;
            r.open = e_el > 0.0;
        }
        return r;
    }
    // Compression: 1-D return on the MC90 curve (closed form, see module doc of
    // `compression`): σ_c(ε̄) = −E(e + p + Δp), Δp = κ(ε̄) − κ(ε̄_n) ⇒
    // ε̄ = −e − p + κ(ε̄_n) + κ0. With compression softening the curve is the one scaled by
    // β_d (κ0 scales with it).
    let (h_n, ds_n, _) = super::reduction::scaled_hardening_with(p, law, beta, ebar);
    let s_tr = p.ec * e_el;
    if -s_tr <= h_n.sigma_c {
        r.sigma = s_tr;
        r.k = p.ec;
        return r;
    }
    let (_, k0) = law.initial_yield();
    let eb = (-e - plastic + h_n.kappa + beta * k0).max(ebar);
    let (h, ds, _) = super::reduction::scaled_hardening_with(p, law, beta, eb);
    r.ebar = eb;
    r.plastic = plastic + (h.kappa - h_n.kappa).max(0.0);
    r.sigma = -h.sigma_c;
    r.k = h.dsigma_c;
    if dbeta != 0.0 && eb > ebar {
        // σ = −σ_β(ε̄), ε̄ = −e − p + κ_β(ε̄_n) + β κ0: ∂ε̄/∂β = −(∂σ_β/∂β)(ε̄_n)/E.
        r.d_lateral = -(ds - h.dsigma_c * ds_n / p.ec) * dbeta;
    }
    r
}

/// IMPL-EX compressive plastic strain of crack-axis direction `i` [-] (magnitude) for an
/// increment with extrapolation ratio `ratio` [-]: p̃ = p_n + r (p_n − p_n−1) from the last
/// two committed states, never backwards.
fn implex_plastic(committed: &ConcreteState, i: usize, ratio: f64) -> f64 {
    let (pn, po) = (committed.dir_plastic[i], committed.dir_plastic_old[i]);
    pn + ratio.max(0.0) * (pn - po).max(0.0)
}

/// Stress [Pa] and tangent [Pa] of a crack-axis direction within an IMPL-EX-compression
/// increment, at strain `e` [-] with the extrapolated compressive plastic strain `pt` [-]
/// ([`implex_plastic`]): with x = e + pt, E x in compression (x < 0), else the direction's
/// tension law at x (the IMPL-EX crack law, or E x for an uncracked direction). Linear in
/// compression, continuous at x = 0 (both sides give 0) and its tangent positive.
fn implex_direction(
    p: &ConcreteParams,
    law: &compression::HardeningLaw,
    alpha: f64,
    h: DirHistory,
    pt: f64,
    e: f64,
) -> (f64, f64) {
    let x = e + pt;
    if x < 0.0 {
        return (p.ec * x, p.ec);
    }
    // The tension side of `direction` at elastic strain x: its plastic strain is pt.
    let r = direction(p, law, alpha, DirHistory { plastic: pt, ..h }, e);
    (r.sigma, r.k)
}

/// What a cracked point's crack-axis laws share within one update: the crack band's
/// softening parameter, the hardening law, the crack axes and the strains in them, and each
/// direction's compression reduction from the other's tensile strain.
struct Axes {
    /// Softening parameter of the tension envelope [-].
    alpha: f64,
    /// The hardening law of the 1-D compression laws.
    law: compression::HardeningLaw,
    /// Strain transformation into the crack axes ([`strain_transform`]).
    t: [[f64; 3]; 3],
    /// Elastic strain (strain less the plastic strain of the uncracked state) in the crack
    /// axes [-]: (e_n, e_t, γ_nt).
    el: [f64; 3],
    /// Compression reduction β_d [-] and dβ_d/dε_lat [-] of each direction.
    red: [(f64, f64); 2],
}

impl Axes {
    /// The crack axes of `committed` at `strain` [-] on an element of crack band width
    /// `char_length` [m].
    fn new(
        p: &ConcreteParams,
        committed: &ConcreteState,
        strain: &[f64; 3],
        char_length: f64,
    ) -> Self {
        let t = strain_transform(committed.crack_angle);
        let ee: [f64; 3] = std::array::from_fn(|i| strain[i] - committed.plastic_strain[i]);
        let el: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| t[i][j] * ee[j]).sum());
        // Compression softening of each direction by the other one's tensile strain.
        let lateral = |j: usize| (el[j] + committed.dir_plastic[j]).max(0.0);
        Self {
            alpha: p.softening_alpha(char_length),
            law: compression::HardeningLaw::new(p),
            t,
            el,
            red: [
                super::reduction::factor(p, lateral(1), char_length),
                super::reduction::factor(p, lateral(0), char_length),
            ],
        }
    }

    /// The committed history of direction `i` with `n_cracks` cracks and largest crack
    /// strains `crack_max` [-] (IMPL-EX cracks: e_max extrapolated with `ratio` [-]).
    fn history(
        &self,
        p: &ConcreteParams,
        committed: &ConcreteState,
        ratio: f64,
        i: usize,
        n_cracks: u8,
        crack_max: &[f64; 2],
    ) -> DirHistory {
        let cracked = (i as u8) < n_cracks;
        DirHistory {
            cracked,
            emax: crack_max[i],
            ebar: committed.dir_ebar[i],
            plastic: committed.dir_plastic[i],
            frozen: committed.frozen[i],
            extrapolated: (p.implex && cracked)
                .then(|| super::implex::extrapolated_max(committed, i, ratio)),
            reduction: self.red[i],
        }
    }
}

/// The IMPL-EX compression's stress differences σ_implex − σ_implicit [Pa] of a cracked
/// point's two crack-axis directions at `strain` [-] (`compression_integration = "implex"`,
/// docs/theory-concrete.md §4): per direction, the stress of [`implex_direction`] at the
/// plastic strain extrapolated with `ratio` [-] ([`implex_plastic`]) minus the implicit
/// law's ([`direction`]) at the same direction strain, both from the committed history and
/// with the same (IMPL-EX or implicit) crack law in tension, so that the crack laws'
/// own difference is not counted here. Zero where both laws give no stress (two open
/// cracks with `double_crack = "zero"`, decided on the committed state as in the update).
/// `p` must be the element's parameters (the crush band's ε_u set), `committed` cracked.
pub(super) fn implex_compression_differences(
    p: &ConcreteParams,
    committed: &ConcreteState,
    strain: &[f64; 3],
    char_length: f64,
    ratio: f64,
) -> [f64; 2] {
    let both_open = committed.n_cracks >= 2
        && committed.crack_strain[0] > 0.0
        && committed.crack_strain[1] > 0.0;
    if both_open && p.zero_double_crack {
        return [0.0; 2];
    }
    let axes = Axes::new(p, committed, strain, char_length);
    std::array::from_fn(|i| {
        let h = axes.history(
            p,
            committed,
            ratio,
            i,
            committed.n_cracks,
            &committed.crack_max,
        );
        let pt = implex_plastic(committed, i, ratio);
        let (s, _) = implex_direction(p, &axes.law, axes.alpha, h, pt, axes.el[i]);
        s - direction(p, &axes.law, axes.alpha, h, axes.el[i]).sigma
    })
}

/// Stress update of a cracked point (`committed.n_cracks` ≥ 1); `implex_c`: IMPL-EX
/// compression in the crack-axis directions (see [`update_cracked_into`]).
pub fn update_cracked(
    p: &ConcreteParams,
    committed: &ConcreteState,
    strain: &[f64; 3],
    char_length: f64,
    ratio: f64,
    implex_c: bool,
) -> UpdateResult {
    let mut st = committed.clone();
    let (s, d) = update_cracked_into(p, committed, strain, char_length, ratio, implex_c, &mut st)?;
    Ok((st, s, d))
}

/// [`update_cracked`] with the new state written into `out` (left as it was on an error):
/// the element loop's trial slot, without a state built and moved twice.
///
/// `implex_c` (`compression_integration = "implex"`, docs/theory-concrete.md §4): the state
/// is the implicit laws' as without it, but within the increment each crack-axis direction
/// answers with its law at the elastic strain e + p̃ of its compressive plastic strain
/// extrapolated from the last increment, p̃ = p_n + r (p_n − p_n−1) ([`implex_direction`]):
/// E (e + p̃) in compression (tangent E, no softening and no lateral-strain term), the
/// tension law (IMPL-EX crack or elastic) at e + p̃ otherwise; and a point whose implicit
/// state crushes is crushed at the end of the increment, answering with that stress in it.
// long: the cracked point's stress and tangent per crack state (one/two cracks, IMPL-EX or implicit cracks and compression, shear cap) read as one table of cases against docs/theory-concrete.md
pub fn update_cracked_into(
    p: &ConcreteParams,
    committed: &ConcreteState,
    strain: &[f64; 3],
    char_length: f64,
    ratio: f64,
    implex_c: bool,
    out: &mut ConcreteState,
) -> Result<([f64; 3], [[f64; 3]; 3]), MaterialError> {
    if matches!(p.tension, super::TensionSoftening::CrackBand { .. })
        && !(char_length > 0.0 && char_length.is_finite())
    {
        return Err(MaterialError::InvalidParams(format!(
            "crack band needs a positive characteristic length, got {char_length}"
        )));
    }
    let axes = Axes::new(p, committed, strain, char_length);
    let Axes {
        alpha,
        ref law,
        t,
        el,
        ..
    } = axes;
    let mut n_cracks = committed.n_cracks;
    let mut crack_max = committed.crack_max;
    // IMPL-EX: e_max extrapolated linearly from the last two committed states.
    let extrapolate = |i: usize| super::implex::extrapolated_max(committed, i, ratio);
    let history = |i: usize, n_cracks: u8, crack_max: &[f64; 2]| {
        axes.history(p, committed, ratio, i, n_cracks, crack_max)
    };
    let eval = |i: usize, n_cracks: u8, crack_max: &[f64; 2]| {
        direction(p, law, alpha, history(i, n_cracks, crack_max), el[i])
    };
    let r0 = eval(0, n_cracks, &crack_max);
    let mut r1 = eval(1, n_cracks, &crack_max);
    let mut formed_second = false;
    if n_cracks == 1 && r1.sigma >= p.ftm {
        n_cracks = 2;
        if p.implex {
            // Explicit formation: elastic in this increment, e_max = strain at formation.
            formed_second = true;
            r1.emax = r1.e_el;
        } else {
            crack_max[1] = 0.0;
            r1 = eval(1, n_cracks, &crack_max);
        }
    }
    let g = 0.5 * p.ec / (1.0 + p.nu);
    let st = out;
    super::assign(st, committed);
    st.strain = *strain;
    st.n_cracks = n_cracks;
    st.crack_max = [r0.emax, if n_cracks >= 2 { r1.emax } else { 0.0 }];
    st.crack_strain = [r0.e_el, if n_cracks >= 2 { r1.e_el } else { 0.0 }];
    st.dir_ebar = [r0.ebar, r1.ebar];
    st.dir_plastic = [r0.plastic, r1.plastic];
    st.dir_plastic_old = committed.dir_plastic;
    st.crack_max_old = committed.crack_max;
    st.cutoff_max_old = committed.cutoff_max;
    if formed_second {
        st.crack_max_old[1] = st.crack_max[1];
    }
    // IMPL-EX compression: each direction's stress and tangent in the increment at the
    // committed crack state (a crack formed in it is elastic in it), with the lateral
    // strain's term gone (the reduction acts through the implicit state only).
    let (mut r0, mut r1) = (r0, r1);
    if implex_c {
        for (i, r) in [&mut r0, &mut r1].into_iter().enumerate() {
            let h = history(i, committed.n_cracks, &committed.crack_max);
            let pt = implex_plastic(committed, i, ratio);
            (r.sigma, r.k) = implex_direction(p, law, alpha, h, pt, el[i]);
            r.d_lateral = 0.0;
        }
    }
    if r0.ebar >= r0.beta * p.eps_cu || r1.ebar >= r1.beta * p.eps_cu {
        st.crushed = true;
    }
    if st.crushed && !implex_c {
        st.stress = [0.0; 3];
        let d = super::d_matrix(p.ec, p.nu).map(|r| r.map(|v| v * p.residual_stiffness));
        return Ok(([0.0; 3], d));
    }
    let mut sl = [0.0; 3];
    let mut dl = [[0.0; 3]; 3];
    // Both cracks open → no stress; IMPL-EX decides on the committed state (explicitly), so
    // that the stress stays linear in the increment.
    let both_open = if p.implex {
        committed.n_cracks >= 2
            && committed.crack_strain[0] > 0.0
            && committed.crack_strain[1] > 0.0
    } else {
        n_cracks >= 2 && r0.open && r1.open
    };
    if both_open && p.zero_double_crack {
        let rs = p.residual_stiffness;
        dl[0][0] = rs * p.ec;
        dl[1][1] = rs * p.ec;
        dl[2][2] = rs * g;
    } else {
        sl[0] = r0.sigma;
        sl[1] = r1.sigma;
        dl[0][0] = r0.k;
        dl[1][1] = r1.k;
        dl[0][1] = r0.d_lateral;
        dl[1][0] = r1.d_lateral;
        // Shear retention at the largest crack strain reached by the existing cracks.
        let reached = if p.implex {
            [
                extrapolate(0),
                if committed.n_cracks >= 2 {
                    extrapolate(1)
                } else {
                    0.0
                },
            ]
        } else {
            st.crack_max
        };
        let (imax, emax) = if n_cracks >= 2 && reached[1] > reached[0] {
            (1, reached[1])
        } else {
            (0, reached[0])
        };
        let (beta, dbeta) = p.shear_beta(emax, char_length);
        sl[2] = beta * g * el[2];
        dl[2][2] = beta * g;
        let loading = if imax == 0 {
            r0.loading_crack
        } else {
            r1.loading_crack
        };
        let consistent = loading && !p.secant_crack_tangent && !p.implex;
        if consistent {
            dl[2][imax] = dbeta * g * el[2];
        }
        if let Some((vmax, dv)) = p.crack_shear_limit.limit(p.fcm, emax, char_length) {
            if sl[2].abs() > vmax {
                // On the limit τ follows v_max(w) alone; the shear tangent keeps β_min G so
                // that a fully capped element is not a mechanism (not consistent there).
                let sgn = sl[2].signum();
                sl[2] = sgn * vmax;
                dl[2][2] = p.shear.beta_min * g;
                dl[2][imax] = if consistent { sgn * dv } else { 0.0 };
            }
        }
        let free = dl;
        match p.principal_stress_limit {
            PrincipalStressLimit::None => {}
            PrincipalStressLimit::TensileStrength => {
                if cap_principal_stress(p.ftm, &mut sl, &mut dl, p.shear.beta_min * g) && p.implex {
                    // IMPL-EX: the stress is the cut-off's, the tangent the crack laws'
                    // (symmetric and positive in the increment). The cut-off's consistent
                    // tangent is non-symmetric, and the symmetric part the solvers take is
                    // indefinite (docs/theory-concrete.md §5.5b): Newton stalled on the beams
                    // with it.
                    dl = free;
                }
            }
            PrincipalStressLimit::Softening => {
                let kn = committed.cutoff_max;
                let extrapolated = p
                    .implex
                    .then(|| kn + ratio.max(0.0) * (kn - committed.cutoff_max_old).max(0.0));
                if let Some(k) = cap_softening(
                    p,
                    alpha,
                    kn,
                    extrapolated,
                    &mut sl,
                    &mut dl,
                    p.shear.beta_min * g,
                ) {
                    st.cutoff_max = k;
                    if p.implex {
                        // As for the fixed cut-off: the crack laws' tangent.
                        dl = free;
                    }
                }
            }
        }
    }
    let (s, d) = to_global(&t, &sl, &dl);
    st.stress = s;
    Ok((s, d))
}

/// Stress and tangent from the local (crack or principal) axes back to x, y: σ = Tᵀ σ',
/// D = Tᵀ D' T, with `t` the strain transformation of the local axes.
pub(super) fn to_global(
    t: &[[f64; 3]; 3],
    sl: &[f64; 3],
    dl: &[[f64; 3]; 3],
) -> ([f64; 3], [[f64; 3]; 3]) {
    let s: [f64; 3] = std::array::from_fn(|i| (0..3).map(|k| t[k][i] * sl[k]).sum());
    let mut dt = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            dt[a][b] = (0..3).map(|k| dl[a][k] * t[k][b]).sum();
        }
    }
    let mut d = [[0.0; 3]; 3];
    for a in 0..3 {
        for b in 0..3 {
            d[a][b] = (0..3).map(|k| t[k][a] * dt[k][b]).sum();
        }
    }
    (s, d)
}
