//! External (unbonded) prestressing tendon connected to the structure only at its anchors
//! and deviators (docs/theory-joints-tendons.md §2).
//!
//! The tendon is a chain of points P_0 (anchor), P_1 … P_{m−1} (deviators), P_m (anchor) with
//! straight spans between them. Span i joins P_i and P_{i+1}. Kinematics are corotational:
//! span lengths ℓ_i = |x_{i+1} − x_i| and unit vectors e_i are evaluated at x = X + u, so the
//! force directions follow the deflected structure (second-order loss of eccentricity) while
//! strains stay small:
//!
//! `ε_i = ε0_i + (ℓ_i − L_i − s_{i+1} + s_i) / L_i`
//!
//! where L_i are the reference span lengths (geometry at the time of prestressing),
//! ε0_i the initial (prestress) strain and s_j the slip of tendon material through deviator j
//! from span j into span j−1 (s_0 = s_m = 0 at the anchors). Deviator modes:
//!
//! * [`DeviatorMode::Held`]: s_j ≡ 0, each span has its own strain (the paper's dummy mesh);
//! * [`DeviatorMode::Frictionless`]: one strain for the whole tendon,
//!   `ε = ε0 + (Σℓ − ΣL)/ΣL`, the same force in every span;
//! * [`DeviatorMode::Friction`]: capstan (Euler–Eytelwein) stick/slip at each deviator,
//!   `e^{−μΔα_j} ≤ N_j/N_{j−1} ≤ e^{μΔα_j}`, solved as an active-set return mapping on the
//!   slips.
//!
//! Internal forces f_i = N_{i−1} e_{i−1} − N_i e_i (the opposite of the forces the tendon
//! exerts on the structure), tangent
//! `K = Σ_{i,k} b_i (∂N_i/∂ℓ_k) b_kᵀ + Σ_i N_i/ℓ_i G_iᵀ (I − e_i e_iᵀ) G_i`,
//! with b_i = ∂ℓ_i/∂u. Units: m, m², Pa, N.

use std::fmt;
use std::sync::Arc;

use crate::materials::steel::{update_uniaxial, HardeningRule, SteelParams, SteelState};

/// Deviator behaviour (plain model data, defined in [`crate::model`]).
pub use crate::model::element_data::DeviatorMode;

/// Uniaxial stress–strain function σ(ε) → (σ \[Pa\], dσ/dε \[Pa\]) of total mechanical strain.
pub type StressFn = Arc<dyn Fn(f64) -> (f64, f64) + Send + Sync>;

/// Uniaxial law of the tendon steel. A tendon cannot carry compression: negative stresses are
/// cut to zero (slack tendon).
#[derive(Clone)]
pub enum TendonLaw {
    /// Linear elastic, σ = E_p ε.
    Elastic,
    /// The uniaxial steel law of [`crate::materials::steel`] (yield f_y, e.g. 0.9 f_ptk,
    /// hardening H, cap f_u), normally with isotropic hardening; its modulus is replaced by
    /// the tendon's E_p so that one tendon has one modulus.
    Steel(SteelParams),
    /// User-supplied nonlinear-elastic (path-independent) law σ(ε), dσ/dε.
    Custom(StressFn),
}

impl fmt::Debug for TendonLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TendonLaw::Elastic => write!(f, "Elastic"),
            TendonLaw::Steel(p) => write!(f, "Steel({p:?})"),
            TendonLaw::Custom(_) => write!(f, "Custom(..)"),
        }
    }
}

impl TendonLaw {
    /// Prestressing steel as in the seed (docs/theory-joints-tendons.md): elastic up to
    /// 0.9 f_ptk, then perfectly plastic. `fptk` in Pa.
    pub fn prestressing_steel(fptk: f64) -> Self {
        // The modulus is the tendon's (see `Steel`); 1 Pa is a placeholder.
        Self::from_steel(&SteelParams::prestressing(1.0, fptk))
    }

    /// Prestressing steel of a uniaxial steel law `steel` (yield f_y, hardening H, cap
    /// f_u: e.g. [`SteelParams::prestressing_hardening`], linear from 0.9 f_ptk to f_ptk at
    /// ε_uk, then perfectly plastic), with **isotropic** hardening: an external tendon is
    /// loaded in tension only (it goes slack instead of yielding in compression), so the
    /// rule matters only after reloading from a slack state.
    pub fn from_steel(steel: &SteelParams) -> Self {
        TendonLaw::Steel(steel.with_rule(HardeningRule::Isotropic))
    }

    /// Stress \[Pa\], tangent \[Pa\] and new history for total strain `eps` \[-\], modulus `e` \[Pa\]
    /// and committed history `c`.
    pub fn update(&self, e: f64, eps: f64, c: &SteelState) -> (f64, f64, SteelState) {
        let (sig, et, st) = match self {
            TendonLaw::Elastic => (e * eps, e, *c),
            TendonLaw::Steel(p) => {
                let (st, sig, et) = update_uniaxial(&SteelParams { es: e, ..*p }, c, eps);
                (sig, et, st)
            }
            TendonLaw::Custom(fun) => {
                let (s, t) = fun(eps);
                (s, t, *c)
            }
        };
        if sig < 0.0 {
            (0.0, 0.0, st)
        } else {
            (sig, et, st)
        }
    }

    /// Strain giving stress `sigma` \[Pa\] on a virgin law (Newton for `Custom`).
    fn strain_for(&self, e: f64, sigma: f64) -> Result<f64, TendonError> {
        match self {
            TendonLaw::Custom(fun) => {
                let mut eps = sigma / e;
                for _ in 0..100 {
                    let (s, t) = fun(eps);
                    if t <= 0.0 {
                        break;
                    }
                    let d = (sigma - s) / t;
                    eps += d;
                    if d.abs() <= 1e-15 * eps.abs().max(1e-12) {
                        return Ok(eps);
                    }
                }
                Err(TendonError::Invalid(format!(
                    "custom law: cannot find the strain of the initial stress {sigma} Pa"
                )))
            }
            TendonLaw::Steel(p) if sigma > p.fy => Err(TendonError::Invalid(format!(
                "initial stress {sigma} Pa exceeds the yield stress {} Pa",
                p.fy
            ))),
            _ => Ok(sigma / e),
        }
    }
}

/// Errors of tendon setup.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TendonError {
    /// Invalid input.
    #[error("invalid external tendon: {0}")]
    Invalid(String),
}

/// State of one span.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SpanState {
    /// Total mechanical strain ε \[-\] (includes the prestrain).
    pub strain: f64,
    /// Stress σ \[Pa\].
    pub stress: f64,
    /// Force N = A_p σ \[N\].
    pub force: f64,
    /// Current chord length ℓ \[m\].
    pub length: f64,
    /// Steel-law history (committed or trial, as the enclosing state).
    pub law: SteelState,
}

/// Committed or trial state of an external tendon.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TendonState {
    /// One entry per span (P_i → P_{i+1}).
    pub spans: Vec<SpanState>,
    /// Slip s_j \[m\] of tendon material through deviator j from span j into span j−1
    /// (index 0 ↔ deviator P_1). Zero for `Held`; not tracked (zero) for `Frictionless`.
    pub slips: Vec<f64>,
    /// Per deviator: 0 stick, +1 slipping towards span j−1 (N_{j−1} = e^{μΔα} N_j),
    /// −1 slipping towards span j (N_j = e^{μΔα} N_{j−1}). Only used by `Friction`.
    pub slipping: Vec<i8>,
}

impl TendonState {
    /// Span forces \[N\].
    pub fn forces(&self) -> Vec<f64> {
        self.spans.iter().map(|s| s.force).collect()
    }
    /// Span stresses \[Pa\].
    pub fn stresses(&self) -> Vec<f64> {
        self.spans.iter().map(|s| s.stress).collect()
    }
}

/// Internal forces, tangent and trial state of a tendon.
#[derive(Debug, Clone, PartialEq)]
pub struct TendonResponse {
    /// Internal forces \[N\], (x, y) per tendon point.
    pub f_int: Vec<f64>,
    /// Tangent ∂f_int/∂u \[N/m\], dense row-major (2·n_points)².
    pub k: Vec<f64>,
    /// `false` when a slipping friction deviator makes the tangent non-symmetric.
    pub symmetric: bool,
    /// Trial state.
    pub state: TendonState,
}

/// An external tendon with the initial span strains in force (after relaxation), which the
/// analysis state keeps (`analysis::families::TendonBlock::initial_strains`): the element
/// the assembly calls.
#[derive(Debug, Clone, Copy)]
pub struct InForce<'a> {
    /// The tendon as stressed.
    pub tendon: &'a ExternalTendon,
    /// Initial span strains ε0_i in force [-], one per span.
    pub strains: &'a [f64],
}

impl super::ElementResponse for InForce<'_> {
    type Committed = TendonState;
    type Trial<'t> = &'t mut Option<TendonState>;

    /// [`ExternalTendon::response_in_force`]; `u` holds the displacements of the tendon
    /// points since the tendon was stressed [m], (x, y) per point.
    fn response(
        &self,
        u: &[f64],
        committed: &TendonState,
        trial: Self::Trial<'_>,
        into: super::Response<'_>,
    ) -> Result<bool, crate::materials::point::UpdateError> {
        let ut: Vec<[f64; 2]> = u.chunks_exact(2).map(|d| [d[0], d[1]]).collect();
        let r = self.tendon.response_in_force(&ut, committed, self.strains);
        into.f.copy_from_slice(&r.f_int);
        if let Some(k) = into.k {
            k.copy_from_slice(&r.k);
        }
        *trial = Some(r.state);
        Ok(r.symmetric)
    }
}

/// External tendon element.
#[derive(Debug, Clone)]
pub struct ExternalTendon {
    points: Vec<[f64; 2]>,
    area: f64,
    modulus: f64,
    law: TendonLaw,
    mode: DeviatorMode,
    ref_lengths: Vec<f64>,
    initial_stress: Vec<f64>,
    /// Span strains at stressing, from the initial stresses [-] (those in force later are
    /// the analysis state's, [`InForce`]).
    initial_strain: Vec<f64>,
    deviation: Vec<f64>,
    /// Thermal strain α_p ΔT of each span, a stress-free strain [-] (thermal actions).
    thermal_strain: Vec<f64>,
}

/// Relative floor on a span's tangent stiffness inside the friction return mapping, so that
/// the local Jacobian stays regular when spans are perfectly plastic or slack.
const KFLOOR: f64 = 1e-9;

impl ExternalTendon {
    /// Tendon through `points` \[m\] (anchor, deviators…, anchor; ≥ 2 points), area `area`
    /// \[m²\], modulus `modulus` \[Pa\], uniform initial stress `initial_stress` \[Pa\] (after
    /// losses), steel law and deviator mode. Deviation angles Δα_j \[rad\] are taken from the
    /// reference geometry (see [`Self::with_deviation_angles`] to override).
    pub fn new(
        points: &[[f64; 2]],
        area: f64,
        modulus: f64,
        initial_stress: f64,
        law: TendonLaw,
        mode: DeviatorMode,
    ) -> Result<Self, TendonError> {
        let bad = |m: &str| Err(TendonError::Invalid(m.to_string()));
        if points.len() < 2 {
            return bad("at least two points (the anchors) are needed");
        }
        if !(area > 0.0 && modulus > 0.0) {
            return bad("area and modulus must be positive");
        }
        if let DeviatorMode::Friction { mu } = mode {
            if !(mu >= 0.0 && mu.is_finite()) {
                return bad("friction coefficient must be non-negative");
            }
        }
        let m = points.len() - 1;
        let mut ref_lengths = Vec::with_capacity(m);
        let mut dirs = Vec::with_capacity(m);
        for i in 0..m {
            let d = [
                points[i + 1][0] - points[i][0],
                points[i + 1][1] - points[i][1],
            ];
            let l = d[0].hypot(d[1]);
            if l <= 0.0 {
                return bad("zero-length span");
            }
            ref_lengths.push(l);
            dirs.push([d[0] / l, d[1] / l]);
        }
        let deviation = (1..m)
            .map(|j| {
                let (a, b) = (dirs[j - 1], dirs[j]);
                let cross = a[0] * b[1] - a[1] * b[0];
                let dot = a[0] * b[0] + a[1] * b[1];
                cross.atan2(dot).abs()
            })
            .collect();
        let mut t = Self {
            points: points.to_vec(),
            area,
            modulus,
            law,
            mode,
            ref_lengths,
            initial_stress: vec![],
            initial_strain: vec![],
            deviation,
            thermal_strain: vec![0.0; m],
        };
        t.set_initial_stresses(vec![initial_stress; m])?;
        Ok(t)
    }

    fn set_initial_stresses(&mut self, s: Vec<f64>) -> Result<(), TendonError> {
        if s.len() != self.n_spans() {
            return Err(TendonError::Invalid(format!(
                "{} initial stresses for {} spans",
                s.len(),
                self.n_spans()
            )));
        }
        let s = if self.mode == DeviatorMode::Frictionless {
            // One stress for a frictionless tendon: the length-weighted mean.
            let lt: f64 = self.ref_lengths.iter().sum();
            let mean = s
                .iter()
                .zip(&self.ref_lengths)
                .map(|(a, l)| a * l)
                .sum::<f64>()
                / lt;
            vec![mean; s.len()]
        } else {
            s
        };
        self.initial_strain = s
            .iter()
            .map(|&x| self.law.strain_for(self.modulus, x))
            .collect::<Result<_, _>>()?;
        self.initial_stress = s;
        Ok(())
    }

    /// Replace the initial stresses \[Pa\] by one value per span (e.g. from
    /// [`crate::prestress::friction`]). For `Frictionless` the length-weighted mean is used.
    pub fn with_span_initial_stresses(mut self, s: Vec<f64>) -> Result<Self, TendonError> {
        self.set_initial_stresses(s)?;
        Ok(self)
    }

    /// Override the deviation angles Δα_j \[rad\] (one per deviator), e.g. for a curved
    /// saddle whose angle differs from the chord geometry.
    pub fn with_deviation_angles(mut self, a: Vec<f64>) -> Result<Self, TendonError> {
        if a.len() != self.deviation.len() || a.iter().any(|x| x.is_nan() || *x < 0.0) {
            return Err(TendonError::Invalid(
                "one non-negative deviation angle per deviator expected".into(),
            ));
        }
        self.deviation = a;
        Ok(self)
    }

    /// Number of points (anchors + deviators).
    pub fn n_points(&self) -> usize {
        self.points.len()
    }
    /// Number of spans.
    pub fn n_spans(&self) -> usize {
        self.points.len() - 1
    }
    /// Reference span lengths L_i \[m\].
    pub fn reference_lengths(&self) -> &[f64] {
        &self.ref_lengths
    }
    /// Deviation angles Δα_j \[rad\] at the deviators P_1 … P_{m−1}.
    pub fn deviation_angles(&self) -> &[f64] {
        &self.deviation
    }
    /// Initial span stresses \[Pa\].
    pub fn initial_stresses(&self) -> &[f64] {
        &self.initial_stress
    }
    /// Initial (prestress) span strains ε0_i at stressing \[-\], from the initial stresses
    /// (time-dependent analyses impose the steel relaxation on them as a stress-free strain:
    /// the strains then in force are passed to [`Self::response_in_force`]).
    pub fn initial_strains(&self) -> &[f64] {
        &self.initial_strain
    }
    /// Replace the thermal strains α_p ΔT of the spans \[-\] (one per span), stress-free
    /// strains subtracted from the span strains (`Frictionless`: their length-weighted mean
    /// over the whole tendon). Panics on a length mismatch.
    pub fn set_thermal_strains(&mut self, e: &[f64]) {
        assert_eq!(
            e.len(),
            self.n_spans(),
            "tendon: one thermal strain per span"
        );
        self.thermal_strain.copy_from_slice(e);
    }
    /// Steel modulus E_p \[Pa\].
    pub fn modulus(&self) -> f64 {
        self.modulus
    }
    /// Tendon area A_p \[m²\].
    pub fn area(&self) -> f64 {
        self.area
    }
    /// Deviator mode.
    pub fn mode(&self) -> DeviatorMode {
        self.mode
    }

    /// State at prestressing (u = 0): span stresses equal the initial stresses, no slip.
    pub fn initial_state(&self) -> TendonState {
        let m = self.n_spans();
        TendonState {
            spans: (0..m)
                .map(|i| SpanState {
                    strain: self.initial_strain[i],
                    stress: self.initial_stress[i],
                    force: self.area * self.initial_stress[i],
                    length: self.ref_lengths[i],
                    law: SteelState::default(),
                })
                .collect(),
            slips: vec![0.0; m.saturating_sub(1)],
            slipping: vec![0; m.saturating_sub(1)],
        }
    }

    /// Strain of span i for current length `l` and slips `s` (deviator j ↔ s\[j−1\]).
    /// `eps0`: the initial span strains in force.
    fn span_strain(&self, eps0: &[f64], i: usize, l: f64, s: &[f64]) -> f64 {
        let m = self.n_spans();
        let s_left = if i >= 1 { s[i - 1] } else { 0.0 };
        let s_right = if i + 1 < m { s[i] } else { 0.0 };
        eps0[i] - self.thermal_strain[i]
            + (l - self.ref_lengths[i] - s_right + s_left) / self.ref_lengths[i]
    }

    /// Response for displacements `u` \[m\] of the tendon points and the committed state,
    /// at the initial strains of stressing ([`Self::initial_strains`]).
    ///
    /// Panics if `u` or `committed` do not match the tendon.
    pub fn response(&self, u: &[[f64; 2]], committed: &TendonState) -> TendonResponse {
        self.response_in_force(u, committed, &self.initial_strain)
    }

    /// As [`Self::response`], with the initial span strains in force `eps0` \[-\] (one per
    /// span; for `Frictionless` only the first is used), e.g. after steel relaxation.
    ///
    /// Panics if `u`, `committed` or `eps0` do not match the tendon.
    pub fn response_in_force(
        &self,
        u: &[[f64; 2]],
        committed: &TendonState,
        eps0: &[f64],
    ) -> TendonResponse {
        let np = self.n_points();
        let m = self.n_spans();
        assert_eq!(u.len(), np, "tendon: one displacement per point expected");
        assert_eq!(committed.spans.len(), m, "tendon: wrong committed state");
        assert_eq!(
            eps0.len(),
            m,
            "tendon: one initial strain per span expected"
        );
        let mut len = vec![0.0; m];
        let mut dir = vec![[0.0; 2]; m];
        for i in 0..m {
            let d = [
                self.points[i + 1][0] + u[i + 1][0] - self.points[i][0] - u[i][0],
                self.points[i + 1][1] + u[i + 1][1] - self.points[i][1] - u[i][1],
            ];
            let l = d[0].hypot(d[1]);
            len[i] = l;
            dir[i] = [d[0] / l, d[1] / l];
        }
        let ea = self.modulus * self.area;
        // Span forces N, dN/dℓ (m × m, row-major), slips, flags, law states, strains, stresses.
        let mut dndl = vec![0.0; m * m];
        let mut slips = vec![0.0; m.saturating_sub(1)];
        let mut slipping = vec![0i8; m.saturating_sub(1)];
        let mut spans = Vec::with_capacity(m);
        let mut symmetric = true;
        match self.mode {
            DeviatorMode::Frictionless => {
                let lt: f64 = self.ref_lengths.iter().sum();
                let thermal: f64 = (self.thermal_strain.iter())
                    .zip(&self.ref_lengths)
                    .map(|(e, l)| e * l)
                    .sum::<f64>()
                    / lt;
                let eps = eps0[0] - thermal + (len.iter().sum::<f64>() - lt) / lt;
                let (sig, et, st) = self.law.update(self.modulus, eps, &committed.spans[0].law);
                let kk = self.area * et / lt;
                dndl.iter_mut().for_each(|x| *x = kk);
                for &l in &len {
                    spans.push(SpanState {
                        strain: eps,
                        stress: sig,
                        force: self.area * sig,
                        length: l,
                        law: st,
                    });
                }
            }
            DeviatorMode::Held => {
                for i in 0..m {
                    let eps = self.span_strain(eps0, i, len[i], &slips);
                    let (sig, et, st) = self.law.update(self.modulus, eps, &committed.spans[i].law);
                    dndl[i * m + i] = self.area * et / self.ref_lengths[i];
                    spans.push(SpanState {
                        strain: eps,
                        stress: sig,
                        force: self.area * sig,
                        length: len[i],
                        law: st,
                    });
                }
            }
            DeviatorMode::Friction { mu } => {
                let (s, act, st) = self.friction_return(mu, &len, committed, eps0);
                slips = s;
                slipping = act;
                // Tangent dN/dℓ = D (I − C_a (G D C_a)⁻¹ G D).
                let kdiag: Vec<f64> = st
                    .iter()
                    .enumerate()
                    .map(|(i, x)| {
                        let kel = ea / self.ref_lengths[i];
                        (self.area * x.1 / self.ref_lengths[i]).max(KFLOOR * kel)
                    })
                    .collect();
                let active: Vec<usize> =
                    (0..slipping.len()).filter(|&j| slipping[j] != 0).collect();
                for i in 0..m {
                    dndl[i * m + i] = kdiag[i];
                }
                if !active.is_empty()
                    && !self.condense_slips(mu, &active, &slipping, &kdiag, &mut dndl)
                {
                    symmetric = false;
                }
                for i in 0..m {
                    spans.push(SpanState {
                        strain: self.span_strain(eps0, i, len[i], &slips),
                        stress: st[i].0,
                        force: self.area * st[i].0,
                        length: len[i],
                        law: st[i].2,
                    });
                }
            }
        }
        let (f, k) = span_assembly(&dir, &len, &spans, &dndl);
        TendonResponse {
            f_int: f,
            k,
            symmetric,
            state: TendonState {
                spans,
                slips,
                slipping,
            },
        }
    }

    /// The tangent dN/dℓ = D (I − C_a (G D C_a)⁻¹ G D) of friction deviators with the
    /// slipping deviators `active` (`slipping`: their directions): `dndl` holds D (the span
    /// stiffnesses `kdiag` [N/m] on its diagonal) on entry. Returns whether it stayed
    /// symmetric (no capstan ratio other than 1).
    fn condense_slips(
        &self,
        mu: f64,
        active: &[usize],
        slipping: &[i8],
        kdiag: &[f64],
        dndl: &mut [f64],
    ) -> bool {
        let m = kdiag.len();
        let mut symmetric = true;
        let na = active.len();
        // G (na × m) and C_a (m × na).
        let mut g = vec![0.0; na * m];
        let mut ca = vec![0.0; m * na];
        for (r, &j) in active.iter().enumerate() {
            let dev = j + 1; // deviator point index; spans dev−1 (left), dev (right)
            let ratio = (mu * self.deviation[j]).exp();
            if ratio != 1.0 {
                symmetric = false;
            }
            let (a, b) = if slipping[j] > 0 {
                (1.0, ratio)
            } else {
                (ratio, 1.0)
            };
            g[r * m + dev - 1] = a;
            g[r * m + dev] = -b;
            // s_j enters span dev−1 with −1/L and span dev with +1/L (×L in D).
            ca[(dev - 1) * na + r] = -1.0;
            ca[dev * na + r] = 1.0;
        }
        // GD (na × m), GDC (na × na).
        let gd: Vec<f64> = (0..na * m).map(|x| g[x] * kdiag[x % m]).collect();
        let mut gdc = vec![0.0; na * na];
        for r in 0..na {
            for c in 0..na {
                gdc[r * na + c] = (0..m).map(|i| gd[r * m + i] * ca[i * na + c]).sum();
            }
        }
        // X = (GDC)⁻¹ GD  (na × m), column by column.
        let mut x = vec![0.0; na * m];
        for col in 0..m {
            let rhs: Vec<f64> = (0..na).map(|r| gd[r * m + col]).collect();
            let sol = dense_solve(gdc.clone(), rhs);
            for r in 0..na {
                x[r * m + col] = sol[r];
            }
        }
        // dN/dℓ = D − D C_a X.
        for i in 0..m {
            for k in 0..m {
                let cx: f64 = (0..na).map(|r| ca[i * na + r] * x[r * m + k]).sum();
                dndl[i * m + k] -= kdiag[i] * cx;
            }
        }
        symmetric
    }

    /// Capstan stick/slip return mapping: returns slips, slip flags and per span
    /// (σ, E_t, law state). Active-set iteration; Newton on the active slips.
    #[allow(clippy::type_complexity)]
    fn friction_return(
        &self,
        mu: f64,
        len: &[f64],
        committed: &TendonState,
        eps0: &[f64],
    ) -> (Vec<f64>, Vec<i8>, Vec<(f64, f64, SteelState)>) {
        let m = self.n_spans();
        let nd = m.saturating_sub(1);
        let sc = &committed.slips;
        let eval = |s: &[f64]| -> Vec<(f64, f64, SteelState)> {
            (0..m)
                .map(|i| {
                    let eps = self.span_strain(eps0, i, len[i], s);
                    self.law.update(self.modulus, eps, &committed.spans[i].law)
                })
                .collect()
        };
        let ratio: Vec<f64> = self.deviation.iter().map(|a| (mu * a).exp()).collect();
        let mut act = vec![0i8; nd];
        let mut s = sc.clone();
        let scale = self.area * self.modulus * 1e-3;
        for _outer in 0..(4 * nd + 10) {
            // Newton on the active constraints.
            s.clone_from(sc);
            let idx: Vec<usize> = (0..nd).filter(|&j| act[j] != 0).collect();
            let mut st = eval(&s);
            for _ in 0..50 {
                if idx.is_empty() {
                    break;
                }
                let na = idx.len();
                let mut res = vec![0.0; na];
                let mut jac = vec![0.0; na * na];
                for (r, &j) in idx.iter().enumerate() {
                    let (a, b) = if act[j] > 0 {
                        (1.0, ratio[j])
                    } else {
                        (ratio[j], 1.0)
                    };
                    let (nl, nr) = (self.area * st[j].0, self.area * st[j + 1].0);
                    res[r] = a * nl - b * nr;
                    let kl = (self.area * st[j].1 / self.ref_lengths[j])
                        .max(KFLOOR * self.area * self.modulus / self.ref_lengths[j]);
                    let kr = (self.area * st[j + 1].1 / self.ref_lengths[j + 1])
                        .max(KFLOOR * self.area * self.modulus / self.ref_lengths[j + 1]);
                    // ∂N_l/∂s_j = −k_l, ∂N_r/∂s_j = +k_r; s_{j−1} enters N_l (+k_l),
                    // s_{j+1} enters N_r (−k_r).
                    for (c, &jj) in idx.iter().enumerate() {
                        let mut v = 0.0;
                        if jj == j {
                            v += a * (-kl) - b * kr;
                        }
                        if j >= 1 && jj == j - 1 {
                            v += a * kl;
                        }
                        if jj == j + 1 {
                            v -= b * (-kr);
                        }
                        jac[r * na + c] = v;
                    }
                }
                let rmax = res.iter().fold(0.0f64, |x, y| x.max(y.abs()));
                if rmax <= 1e-13 * scale {
                    break;
                }
                let ds = dense_solve(jac, res.iter().map(|x| -x).collect());
                // Backtrack while the residual grows: the span laws are piecewise linear
                // (yield, slack at zero force with the floor stiffness), and a full step
                // taken on a kinked or slack span's tangent can jump far past the root.
                let base = s.clone();
                let mut step = 1.0;
                for _ in 0..60 {
                    for (r, &j) in idx.iter().enumerate() {
                        s[j] = base[j] + step * ds[r];
                    }
                    st = eval(&s);
                    if capstan_residual(&idx, &act, &ratio, self.area, &st) < rmax {
                        break;
                    }
                    step *= 0.5;
                }
            }
            // Consistency checks.
            let mut changed = false;
            let tol = 1e-12;
            for j in 0..nd {
                let (nl, nr) = (st[j].0, st[j + 1].0);
                let ds = s[j] - sc[j];
                match act[j] {
                    0 => {
                        if nl > ratio[j] * nr * (1.0 + tol) + tol * scale / self.area {
                            act[j] = 1;
                            changed = true;
                        } else if nr > ratio[j] * nl * (1.0 + tol) + tol * scale / self.area {
                            act[j] = -1;
                            changed = true;
                        }
                    }
                    a => {
                        if (a as f64) * ds < 0.0 {
                            act[j] = 0;
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                return (s, act, st);
            }
        }
        // No consistent active set found within the iteration cap: return the last one.
        let st = eval(&s);
        (s, act, st)
    }
}

/// Largest capstan residual |a N_l − b N_r| \[N\] over the active deviators `idx`.
fn capstan_residual(
    idx: &[usize],
    act: &[i8],
    ratio: &[f64],
    area: f64,
    st: &[(f64, f64, SteelState)],
) -> f64 {
    idx.iter()
        .map(|&j| {
            let (a, b) = if act[j] > 0 {
                (1.0, ratio[j])
            } else {
                (ratio[j], 1.0)
            };
            (a * area * st[j].0 - b * area * st[j + 1].0).abs()
        })
        .fold(0.0, f64::max)
}

/// Internal forces and tangent [N, N/m] of a tendon's points (x, y per point) from its
/// spans: unit directions `dir`, current lengths `len` [m], span forces (`spans`) and
/// dN/dℓ (`dndl`, m × m row-major, N/m), with the geometric stiffness N/ℓ (I − e eᵀ).
fn span_assembly(
    dir: &[[f64; 2]],
    len: &[f64],
    spans: &[SpanState],
    dndl: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let m = len.len();
    let np = m + 1;
    let nd = 2 * np;
    let mut f = vec![0.0; nd];
    let mut k = vec![0.0; nd * nd];
    // b_i: −e_i at point i, +e_i at point i+1.
    let bvec = |i: usize| -> Vec<(usize, f64)> {
        vec![
            (2 * i, -dir[i][0]),
            (2 * i + 1, -dir[i][1]),
            (2 * i + 2, dir[i][0]),
            (2 * i + 3, dir[i][1]),
        ]
    };
    for i in 0..m {
        let n = spans[i].force;
        for (a, v) in bvec(i) {
            f[a] += n * v;
        }
        for kk in 0..m {
            let c = dndl[i * m + kk];
            if c == 0.0 {
                continue;
            }
            for (a, va) in bvec(i) {
                for (b, vb) in bvec(kk) {
                    k[a * nd + b] += va * c * vb;
                }
            }
        }
        // Geometric stiffness N/ℓ (I − e eᵀ) on [−I, I].
        let e = dir[i];
        let p = [
            [1.0 - e[0] * e[0], -e[0] * e[1]],
            [-e[0] * e[1], 1.0 - e[1] * e[1]],
        ];
        let g = n / len[i];
        for (pa, sa) in [(i, -1.0), (i + 1, 1.0)] {
            for (pb, sb) in [(i, -1.0), (i + 1, 1.0)] {
                for da in 0..2 {
                    for db in 0..2 {
                        k[(2 * pa + da) * nd + 2 * pb + db] += sa * sb * g * p[da][db];
                    }
                }
            }
        }
    }
    (f, k)
}

/// Dense Gaussian elimination with partial pivoting (small systems: active deviators).
fn dense_solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))
            .unwrap_or(c);
        if p != c {
            for j in 0..n {
                a.swap(c * n + j, p * n + j);
            }
            b.swap(c, p);
        }
        let piv = a[c * n + c];
        for r in c + 1..n {
            let f = a[r * n + c] / piv;
            for j in c..n {
                a[r * n + j] -= f * a[c * n + j];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|j| a[r * n + j] * x[j]).sum();
        x[r] = (b[r] - s) / a[r * n + r];
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    const AP: f64 = 4.0 * 140e-6; // 4 strands 0.6" [m²]
    const EP: f64 = 195e9;
    const S0: f64 = 1000e6;

    /// Anchor – 2 deviators – anchor, a typical draped external tendon of a 7.2 m beam.
    fn draped() -> Vec<[f64; 2]> {
        vec![[0.0, 0.0], [2.4, -0.25], [4.8, -0.25], [7.2, 0.0]]
    }

    fn zeros(n: usize) -> Vec<[f64; 2]> {
        vec![[0.0; 2]; n]
    }

    /// Max relative deviation of K from central differences of f_int. h is chosen so that
    /// truncation (∝ h² × third derivative ~ N/ℓ³) and round-off (|f|·1e-16/h) are both far
    /// below the tolerance used by the callers.
    fn fd_check(t: &ExternalTendon, u: &[[f64; 2]], c: &TendonState, h: f64) -> f64 {
        let r = t.response(u, c);
        let nd = 2 * t.n_points();
        let kmax = r.k.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let mut err = 0.0f64;
        for b in 0..nd {
            let mut up = u.to_vec();
            let mut um = u.to_vec();
            up[b / 2][b % 2] += h;
            um[b / 2][b % 2] -= h;
            let fp = t.response(&up, c).f_int;
            let fm = t.response(&um, c).f_int;
            for a in 0..nd {
                let fd = (fp[a] - fm[a]) / (2.0 * h);
                err = err.max((fd - r.k[a * nd + b]).abs() / kmax);
            }
        }
        err
    }

    /// Beam-like deflection of the tendon points (mid deviators down, anchors drawn apart).
    fn bent(scale: f64) -> Vec<[f64; 2]> {
        vec![
            [-0.4 * scale, 0.0],
            [0.1 * scale, -2.0 * scale],
            [-0.1 * scale, -2.2 * scale],
            [0.5 * scale, 0.1 * scale],
        ]
    }

    /// At u = 0 every span carries A_p σ0 and the nodal forces are the equivalent prestress
    /// loads (sum zero). Tolerance 1e-12 rel (round-off only).
    #[test]
    fn initial_forces_and_equilibrium() {
        for mode in [
            DeviatorMode::Held,
            DeviatorMode::Frictionless,
            DeviatorMode::Friction { mu: 0.2 },
        ] {
            let t = ExternalTendon::new(&draped(), AP, EP, S0, TendonLaw::Elastic, mode).unwrap();
            let r = t.response(&zeros(4), &t.initial_state());
            for f in r.state.forces() {
                assert!((f - AP * S0).abs() < 1e-12 * AP * S0);
            }
            let (sx, sy) = (0..4).fold((0.0, 0.0), |a, i| {
                (a.0 + r.f_int[2 * i], a.1 + r.f_int[2 * i + 1])
            });
            assert!(sx.abs() < 1e-12 * AP * S0 && sy.abs() < 1e-12 * AP * S0);
            // Anchor 0: internal force = −N e_0 (tendon pulls the anchor towards P_1).
            let l0 = t.reference_lengths()[0];
            assert!((r.f_int[0] + AP * S0 * 2.4 / l0).abs() < 1e-9 * AP * S0);
        }
    }

    /// Frictionless: same force in every span under a deflection; held: different forces;
    /// all modes: nodal forces sum to zero (equilibrium; 1e-10 of N, round-off).
    #[test]
    fn frictionless_equal_held_different() {
        let u = bent(5e-3);
        let tf = ExternalTendon::new(
            &draped(),
            AP,
            EP,
            S0,
            TendonLaw::Elastic,
            DeviatorMode::Frictionless,
        )
        .unwrap();
        let th = ExternalTendon::new(
            &draped(),
            AP,
            EP,
            S0,
            TendonLaw::Elastic,
            DeviatorMode::Held,
        )
        .unwrap();
        let rf = tf.response(&u, &tf.initial_state());
        let rh = th.response(&u, &th.initial_state());
        let nf = rf.state.forces();
        let nh = rh.state.forces();
        for x in &nf {
            assert!((x - nf[0]).abs() < 1e-12 * nf[0]);
        }
        assert!((nh[0] - nh[1]).abs() > 1e-3 * nh[0]);
        // Frictionless force = the length-weighted mean strain of the held spans.
        let lt: f64 = th.reference_lengths().iter().sum();
        let mean: f64 = nh
            .iter()
            .zip(th.reference_lengths())
            .map(|(n, l)| n * l)
            .sum::<f64>()
            / lt;
        assert!((mean - nf[0]).abs() < 1e-12 * nf[0]);
        for r in [&rf, &rh] {
            let (sx, sy) = (0..4).fold((0.0, 0.0), |a, i| {
                (a.0 + r.f_int[2 * i], a.1 + r.f_int[2 * i + 1])
            });
            assert!(sx.abs() < 1e-10 * nf[0] && sy.abs() < 1e-10 * nf[0]);
        }
    }

    /// Imposed anchor displacement δ along a straight tendon: ΔN = E_p A_p δ/L0 (and the sum
    /// of the span lengths for a frictionless multi-span tendon). Tolerance 1e-9 rel: the
    /// corotational length differs from L0 + δ only by round-off for an axial δ.
    #[test]
    fn anchor_displacement_force_change() {
        let pts = vec![[0.0, 0.0], [3.0, 0.0], [7.5, 0.0]];
        let d = 2e-3;
        let mut u = zeros(3);
        u[2][0] = d;
        for mode in [
            DeviatorMode::Frictionless,
            DeviatorMode::Friction { mu: 0.0 },
        ] {
            let t = ExternalTendon::new(&pts, AP, EP, S0, TendonLaw::Elastic, mode).unwrap();
            let r = t.response(&u, &t.initial_state());
            for n in r.state.forces() {
                let dn = n - AP * S0;
                assert!(
                    (dn - EP * AP * d / 7.5).abs() < 1e-9 * EP * AP * d / 7.5,
                    "{mode:?}"
                );
            }
        }
        let t =
            ExternalTendon::new(&pts, AP, EP, S0, TendonLaw::Elastic, DeviatorMode::Held).unwrap();
        let r = t.response(&u, &t.initial_state());
        let n = r.state.forces();
        assert!((n[0] - AP * S0).abs() < 1e-9 * AP * S0);
        assert!((n[1] - AP * S0 - EP * AP * d / 4.5).abs() < 1e-9 * EP * AP * d / 4.5);
    }

    /// Capstan: pulling one anchor of a V-shaped tendon makes the deviator slip; the span
    /// forces then satisfy N_right/N_left = e^{μΔα}. Tolerance 1e-9 rel (local Newton
    /// converged to 1e-13 of E_p A_p·1e-3).
    #[test]
    fn capstan_ratio_at_slipping_deviator() {
        let pts = vec![[0.0, 0.0], [3.0, -0.4], [6.0, 0.0]];
        let mu = 0.25;
        let t = ExternalTendon::new(
            &pts,
            AP,
            EP,
            S0,
            TendonLaw::Elastic,
            DeviatorMode::Friction { mu },
        )
        .unwrap();
        let dalpha = t.deviation_angles()[0];
        assert!((dalpha - 2.0 * (0.4f64 / 3.0).atan()).abs() < 1e-14);
        let mut u = zeros(3);
        u[2][0] = 5e-3;
        let r = t.response(&u, &t.initial_state());
        let n = r.state.forces();
        assert_eq!(r.state.slipping[0], -1);
        assert!(!r.symmetric);
        assert!((n[1] / n[0] - (mu * dalpha).exp()).abs() < 1e-9);
        // A small pull stays within the cone: stick, identical to held.
        let mut u = zeros(3);
        u[2][0] = 1e-5;
        let r = t.response(&u, &t.initial_state());
        assert_eq!(r.state.slipping[0], 0);
        assert!(r.state.slips[0] == 0.0);
        // μ = 0 gives the frictionless result (elastic law).
        let t0 = ExternalTendon::new(
            &pts,
            AP,
            EP,
            S0,
            TendonLaw::Elastic,
            DeviatorMode::Friction { mu: 0.0 },
        )
        .unwrap();
        let tf = ExternalTendon::new(
            &pts,
            AP,
            EP,
            S0,
            TendonLaw::Elastic,
            DeviatorMode::Frictionless,
        )
        .unwrap();
        let u = vec![[1e-3, 2e-3], [-2e-3, -8e-3], [4e-3, 1e-3]];
        let a = t0.response(&u, &t0.initial_state());
        let b = tf.response(&u, &tf.initial_state());
        for (x, y) in a.state.forces().iter().zip(b.state.forces()) {
            assert!((x - y).abs() < 1e-9 * y);
        }
        for (x, y) in a.k.iter().zip(&b.k) {
            assert!((x - y).abs() < 1e-7 * b.k.iter().fold(0.0f64, |p, q| p.max(q.abs())));
        }
    }

    /// Tangent vs central differences for all modes, elastic and (hardening) plastic, incl. a
    /// slipping friction state with two deviators. h = 1e-7 m: the response is smooth
    /// (geometric terms) within a fixed stick/slip/yield pattern, truncation ~h²·N/ℓ³ and
    /// round-off ~|f|·1e-16/h are both < 1e-8 of max|K|; tolerance 1e-6 of max|K|.
    #[test]
    fn tangent_matches_finite_differences() {
        let laws = [
            TendonLaw::Elastic,
            TendonLaw::from_steel(&SteelParams {
                es: EP,
                fy: 1010e6,
                hardening: 5e9,
                fu: f64::INFINITY,
                rule: HardeningRule::Isotropic,
            }),
        ];
        for law in laws {
            for mode in [
                DeviatorMode::Held,
                DeviatorMode::Frictionless,
                DeviatorMode::Friction { mu: 0.2 },
            ] {
                let t = ExternalTendon::new(&draped(), AP, EP, S0, law.clone(), mode).unwrap();
                let mut u = bent(4e-3);
                u[3][0] += 2e-3;
                let c = t.initial_state();
                let r = t.response(&u, &c);
                if let DeviatorMode::Friction { .. } = mode {
                    assert!(r.state.slipping.iter().any(|&s| s != 0), "{:?}", r.state);
                }
                let e = fd_check(&t, &u, &c, 1e-7);
                assert!(e < 1e-6, "{law:?} {mode:?}: {e}");
            }
        }
    }

    /// A V-shaped tendon with spans of unequal length (2.04 m and 4.02 m) pulled at one
    /// anchor so that its deviator slips: the condensed tangent D (I − C_a (G D C_a)⁻¹ G D)
    /// against central differences of the forces. Equal spans (the capstan test's V) make
    /// D a multiple of I, where a tangent built with D⁻¹ in place of D would agree (found by
    /// mutation testing). Tolerance 1e-6 of the largest entry, as the draped test.
    #[test]
    fn tangent_at_a_slipping_deviator_between_unequal_spans_matches_finite_differences() {
        let pts = vec![[0.0, 0.0], [2.0, -0.4], [6.0, 0.0]];
        let t = ExternalTendon::new(
            &pts,
            AP,
            EP,
            S0,
            TendonLaw::Elastic,
            DeviatorMode::Friction { mu: 0.25 },
        )
        .unwrap();
        let mut u = zeros(3);
        u[2][0] = 3e-3;
        let c = t.initial_state();
        let r = t.response(&u, &c);
        assert!(r.state.slipping[0] != 0, "{:?}", r.state);
        let e = fd_check(&t, &u, &c, 1e-7);
        assert!(e < 1e-6, "{e}");
    }

    /// Frictionless tendon with different thermal strains per span and no displacement:
    /// one force A_p E_p (ε0 − ᾱΔT) with the length-weighted mean ᾱΔT = Σ ε_T,i L_i / Σ L_i
    /// written out here (spans 2.4, 4.0 and 1.6 m; ε0 = σ0/E_p). Tolerance 1e-12 rel
    /// (round-off).
    #[test]
    fn frictionless_tendon_takes_the_length_weighted_mean_thermal_strain() {
        let pts = vec![[0.0, 0.0], [2.4, 0.0], [6.4, 0.0], [8.0, 0.0]];
        let mut t = ExternalTendon::new(
            &pts,
            AP,
            EP,
            S0,
            TendonLaw::Elastic,
            DeviatorMode::Frictionless,
        )
        .unwrap();
        t.set_thermal_strains(&[1e-4, 3e-4, -2e-4]);
        let mean = (1e-4 * 2.4 + 3e-4 * 4.0 - 2e-4 * 1.6) / 8.0;
        let expect = AP * EP * (S0 / EP - mean);
        let r = t.response(&zeros(4), &t.initial_state());
        for n in r.state.forces() {
            assert!((n - expect).abs() < 1e-12 * expect, "{n} vs {expect}");
        }
    }

    /// The accessors give back what the constructors were given, and a deviation angle per
    /// deviator is required, each a number ≥ 0.
    #[test]
    fn accessors_and_deviation_angle_checks() {
        let t = ExternalTendon::new(
            &draped(),
            AP,
            EP,
            S0,
            TendonLaw::Elastic,
            DeviatorMode::Held,
        )
        .unwrap();
        assert_eq!(t.modulus(), EP);
        assert_eq!(t.area(), AP);
        assert_eq!(t.initial_stresses(), &[S0, S0, S0]);
        let spans = vec![1000e6, 990e6, 980e6];
        let t = t.with_span_initial_stresses(spans.clone()).unwrap();
        assert_eq!(t.initial_stresses(), spans.as_slice());
        for bad in [
            vec![0.1],
            vec![0.1, -0.1],
            vec![f64::NAN, 0.1],
            vec![-0.1, 0.1],
        ] {
            assert!(
                t.clone().with_deviation_angles(bad.clone()).is_err(),
                "{bad:?}"
            );
        }
        let t = t.with_deviation_angles(vec![0.1, 0.2]).unwrap();
        assert_eq!(t.deviation_angles(), &[0.1, 0.2]);
    }

    /// Through the element interface the tendon says whether its tangent is symmetric: a
    /// frictionless tendon always, a friction deviator slipping with a capstan ratio
    /// e^{μΔα} ≠ 1 not (the solver then takes the unsymmetric route).
    #[test]
    fn the_element_interface_reports_an_unsymmetric_tangent_only_when_a_deviator_slips() {
        use crate::elements::{ElementResponse, Response};
        let pts = vec![[0.0, 0.0], [2.0, -0.4], [6.0, 0.0]];
        let mut u = [0.0; 6];
        u[4] = 3e-3;
        for (mode, symmetric) in [
            (DeviatorMode::Frictionless, true),
            (DeviatorMode::Friction { mu: 0.25 }, false),
        ] {
            let t = ExternalTendon::new(&pts, AP, EP, S0, TendonLaw::Elastic, mode).unwrap();
            let (mut f, mut k, mut trial) = (vec![0.0; 6], vec![0.0; 36], None);
            let into = Response {
                f: &mut f,
                k: Some(&mut k),
            };
            let strains = t.initial_strains().to_vec();
            let el = InForce {
                tendon: &t,
                strains: &strains,
            };
            let got = ElementResponse::response(&el, &u, &t.initial_state(), &mut trial, into);
            assert_eq!(got.unwrap(), symmetric, "{mode:?}");
            assert!(trial.is_some());
        }
    }

    /// Plastic tendon: stress capped at 0.9 f_ptk (perfectly plastic) and the plastic strain
    /// is kept on unloading. Tolerance 1e-9 rel.
    #[test]
    fn prestressing_steel_yields_at_090_fptk() {
        let fptk = 1860e6;
        let law = TendonLaw::prestressing_steel(fptk);
        let pts = vec![[0.0, 0.0], [5.0, 0.0]];
        let t = ExternalTendon::new(&pts, AP, EP, S0, law, DeviatorMode::Held).unwrap();
        let mut u = zeros(2);
        u[1][0] = 0.05;
        let r = t.response(&u, &t.initial_state());
        assert!((r.state.stresses()[0] - 0.9 * fptk).abs() < 1e-9 * fptk);
        u[1][0] = 0.049;
        let r2 = t.response(&u, &r.state);
        let expect = 0.9 * fptk - EP * 0.001 / 5.0;
        assert!((r2.state.stresses()[0] - expect).abs() < 1e-9 * fptk);
    }

    /// Prestressing steel with ε_uk (SteelParams::prestressing_hardening): on the line from
    /// (0.9 f_ptk/E_p, 0.9 f_ptk) to (ε_uk, f_ptk) in between, tangent its slope; at and beyond
    /// ε_uk the stress stays f_ptk with zero tangent, and unloading from there is elastic.
    /// Tolerance 1e-9 rel (round-off).
    #[test]
    fn prestressing_steel_hardens_to_fptk_at_eps_uk() {
        let (fptk, eps_uk) = (1860e6, 0.035);
        let steel = SteelParams::prestressing_hardening(EP, fptk, eps_uk);
        let law = TendonLaw::from_steel(&steel);
        let (fy, eps_y) = (0.9 * fptk, 0.9 * fptk / EP);
        let slope = (fptk - fy) / (eps_uk - eps_y);
        let c = SteelState::default();
        for eps in [0.5 * eps_y, eps_y + 1e-4, 0.02, eps_uk - 1e-6] {
            let (s, t, _) = law.update(EP, eps, &c);
            let (es, et) = if eps <= eps_y {
                (EP * eps, EP)
            } else {
                (fy + slope * (eps - eps_y), slope)
            };
            assert!(
                (s - es).abs() < 1e-9 * fptk,
                "ε = {eps}: σ = {s}, expected {es}"
            );
            assert!(
                (t - et).abs() < 1e-9 * EP,
                "ε = {eps}: tangent {t}, expected {et}"
            );
        }
        // In steps (history carried) and beyond ε_uk: capped at f_ptk.
        let mut st = c;
        for k in 1..=60 {
            let eps = 0.001 * k as f64;
            let (s, t, n) = law.update(EP, eps, &st);
            st = n;
            if eps > eps_uk {
                assert!(
                    (s - fptk).abs() < 1e-9 * fptk && t == 0.0,
                    "ε = {eps}: {s}, {t}"
                );
            } else if eps > eps_y {
                assert!(
                    (s - fy - slope * (eps - eps_y)).abs() < 1e-9 * fptk,
                    "ε = {eps}: {s}"
                );
            }
        }
        let (s, t, _) = law.update(EP, 0.059, &st);
        assert!((s - (fptk - EP * 0.001)).abs() < 1e-9 * fptk && t == EP);
    }

    /// Second-order effect: a lateral (vertical) deviator movement rotates the span forces
    /// (the anchor's vertical force component changes) even with no length change to first
    /// order — absent in a small-displacement model. Tolerance 1e-9 rel.
    #[test]
    fn force_direction_follows_displacement() {
        let pts = vec![[0.0, 0.0], [3.0, 0.0], [6.0, 0.0]];
        let t = ExternalTendon::new(
            &pts,
            AP,
            EP,
            S0,
            TendonLaw::Elastic,
            DeviatorMode::Frictionless,
        )
        .unwrap();
        let mut u = zeros(3);
        u[1][1] = -0.03;
        let r = t.response(&u, &t.initial_state());
        let n = r.state.forces()[0];
        let l = (9.0f64 + 0.03 * 0.03).sqrt();
        assert!((r.f_int[1] - n * 0.03 / l).abs() < 1e-9 * n);
        assert!((r.f_int[3] + 2.0 * n * 0.03 / l).abs() < 1e-9 * n);
    }

    /// Stick/slip history: after slipping and committing, a small unloading sticks (slip kept,
    /// forces change like a held tendon) and a large unloading slips back the other way with
    /// the inverse capstan ratio. Tolerance 1e-9 rel.
    #[test]
    fn friction_history_stick_after_slip_and_reverse_slip() {
        let pts = vec![[0.0, 0.0], [3.0, -0.4], [6.0, 0.0]];
        let mu = 0.25;
        let t = ExternalTendon::new(
            &pts,
            AP,
            EP,
            S0,
            TendonLaw::Elastic,
            DeviatorMode::Friction { mu },
        )
        .unwrap();
        let ratio = (mu * t.deviation_angles()[0]).exp();
        let mut u = zeros(3);
        u[2][0] = 5e-3;
        let c1 = t.response(&u, &t.initial_state()).state;
        assert!(c1.slips[0] < 0.0);
        u[2][0] = 4.9e-3;
        let r = t.response(&u, &c1);
        assert_eq!(r.state.slipping[0], 0);
        assert_eq!(r.state.slips[0], c1.slips[0]);
        let dn = r.state.forces()[1] - c1.spans[1].force;
        let l1 = t.reference_lengths()[1];
        let dl = r.state.spans[1].length - c1.spans[1].length;
        assert!((dn - EP * AP * dl / l1).abs() < 1e-9 * AP * S0);
        u[2][0] = -5e-3;
        let r = t.response(&u, &c1);
        assert_eq!(r.state.slipping[0], 1);
        let n = r.state.forces();
        assert!((n[0] / n[1] - ratio).abs() < 1e-9);
    }

    /// A user closure law (here linear, σ = 1.1 E ε) is used as given, and the prestrain is
    /// found from it: tolerance 1e-12 rel (Newton on a linear function).
    #[test]
    fn custom_closure_law() {
        let law = TendonLaw::Custom(Arc::new(|e: f64| (1.1 * EP * e, 1.1 * EP)));
        let pts = vec![[0.0, 0.0], [5.0, 0.0]];
        let t = ExternalTendon::new(&pts, AP, EP, S0, law, DeviatorMode::Held).unwrap();
        let mut u = zeros(2);
        u[1][0] = 1e-3;
        let r = t.response(&u, &t.initial_state());
        let expect = AP * (S0 + 1.1 * EP * 1e-3 / 5.0);
        assert!((r.state.forces()[0] - expect).abs() < 1e-12 * expect);
    }
}
