//! Ageing Maxwell chain (Bažant & Wu 1974) for MC90 creep of concrete in plane stress, and a
//! non-ageing uniaxial chain for the relaxation of prestressing steel.
//!
//! Formulation as implemented (docs/theory-time.md §2–§3):
//!
//! * N Maxwell units in parallel under the same strain; unit μ has an ageing spring E_μ(t)
//!   and a dashpot with constant relaxation time τ_μ (a unit with τ = ∞ is a pure spring).
//!   Relaxation function R(t, t') = Σ_μ E_μ(t') exp(−(t − t')/τ_μ).
//! * Relaxation times: **[DECISION, docs/theory-time.md §2]** for the paper's 5 units
//!   τ = {1, 10, 100, 1000, ∞} days; for other N one unit per decade ending at 1000 d, plus
//!   the spring unit (N = 6 → {0.1, 1, …, 1000, ∞}).
//! * R(t, t') from the MC90 compliance by the step-by-step (midpoint) method (§4.3) on a
//!   geometric grid of durations 1e-3 … 1e4 d (10 points per decade, jump
//!   ΔR_0 = E_ci(t') at loading).
//! * E_μ(t') by least squares on R over durations 0.1 … 1e4 d (§4.4); the moduli are cached
//!   per age. A negative modulus (bad τ set) is removed by an active-set step (the unit is
//!   set to zero and the others refitted) **\[DECISION\]**.
//! * Exponential algorithm (§4.5) with E_μ at the mid-step age; plane stress acts on the
//!   unit-modulus elastic matrix D1(ν) (isotropic, constant ν).
//!
//! Units: ages and times in days, moduli and stresses in Pa.

use std::collections::HashMap;
use std::sync::RwLock;

use super::mc90_time::{rho1000, CreepShrinkageParams, RelaxationClass, TimeModelError};

/// Default number of Maxwell units (the paper uses five layers).
pub const DEFAULT_UNITS: usize = 5;

/// Numerical settings of the chain identification.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainSettings {
    /// Relaxation times τ_μ \[days\], increasing; `f64::INFINITY` = pure spring unit.
    pub taus: Vec<f64>,
    /// First duration t − t' of the step-by-step grid for R \[days\] (default 1e-3).
    pub r_grid_start: f64,
    /// Grid points per decade of the step-by-step grid (default 10).
    pub points_per_decade: usize,
    /// Shortest duration used in the least-squares fit \[days\] (default 0.1).
    pub fit_min: f64,
    /// Longest duration used in the least-squares fit and of the R grid \[days\] (default 1e4).
    pub fit_max: f64,
    /// Ages below this are clamped before fitting \[days\] (default 1; MC90 is not meant for
    /// younger concrete and E_ci(t) → 0 as t → 0).
    pub min_age: f64,
}

impl ChainSettings {
    /// Default settings for `n_units` ≥ 2 units: τ one per decade ending at 1000 d plus a
    /// spring (τ = ∞); n = 5 gives the default set {1, 10, 100, 1000, ∞} d
    /// (docs/theory-time.md §2).
    pub fn with_units(n_units: usize) -> Result<Self, TimeModelError> {
        if n_units < 2 {
            return Err(TimeModelError::InvalidParameter(
                "n_units (>= 2)",
                n_units as f64,
            ));
        }
        let nf = n_units - 1;
        let mut taus: Vec<f64> = (0..nf)
            .map(|i| 10f64.powi(3 - (nf - 1 - i) as i32))
            .collect();
        taus.push(f64::INFINITY);
        Ok(Self {
            taus,
            r_grid_start: 1e-3,
            points_per_decade: 10,
            fit_min: 0.1,
            fit_max: 1e4,
            min_age: 1.0,
        })
    }
}

/// Ageing Maxwell chain identified from the MC90 compliance of one concrete.
/// Holds a per-age cache of the unit moduli (thread-safe, behind an `RwLock`).
pub struct MaxwellChain {
    params: CreepShrinkageParams,
    settings: ChainSettings,
    grid: Vec<f64>,
    cache: RwLock<HashMap<u64, Vec<f64>>>,
}

impl std::fmt::Debug for MaxwellChain {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MaxwellChain")
            .field("params", &self.params)
            .field("settings", &self.settings)
            .finish_non_exhaustive()
    }
}

impl Clone for MaxwellChain {
    fn clone(&self) -> Self {
        Self {
            params: self.params.clone(),
            settings: self.settings.clone(),
            grid: self.grid.clone(),
            cache: RwLock::new(HashMap::new()),
        }
    }
}

/// Cache size above which the per-age cache is cleared (memory bound).
const CACHE_LIMIT: usize = 100_000;

impl MaxwellChain {
    /// Chain with `n_units` units and default settings ([`ChainSettings::with_units`]).
    /// Validates the parameters and checks that the fit gives non-negative moduli at
    /// 28 days. Ages in days, moduli in Pa.
    pub fn fit(p: &CreepShrinkageParams, n_units: usize) -> Result<Self, TimeModelError> {
        Self::fit_with_settings(p, ChainSettings::with_units(n_units)?)
    }

    /// Chain with explicit settings (relaxation times in days).
    pub fn fit_with_settings(
        p: &CreepShrinkageParams,
        settings: ChainSettings,
    ) -> Result<Self, TimeModelError> {
        p.validate()?;
        let s = &settings;
        if s.taus.is_empty() || s.taus.iter().any(|&t| t.is_nan() || t <= 0.0) {
            return Err(TimeModelError::InvalidParameter("taus", f64::NAN));
        }
        if s.taus.windows(2).any(|w| w[1].is_nan() || w[1] <= w[0]) {
            return Err(TimeModelError::InvalidParameter(
                "taus (not increasing)",
                f64::NAN,
            ));
        }
        if !(s.r_grid_start > 0.0 && s.r_grid_start <= s.fit_min && s.fit_min < s.fit_max) {
            return Err(TimeModelError::InvalidParameter("fit range", s.fit_min));
        }
        if s.points_per_decade < 2 {
            return Err(TimeModelError::InvalidParameter(
                "points_per_decade",
                s.points_per_decade as f64,
            ));
        }
        let grid = geometric_grid(s.r_grid_start, s.fit_max, s.points_per_decade);
        let chain = Self {
            params: p.clone(),
            settings,
            grid,
            cache: RwLock::new(HashMap::new()),
        };
        let e = chain.try_unit_moduli(28.0)?;
        if e.iter().sum::<f64>() <= 0.0 {
            return Err(TimeModelError::FitFailed("zero chain stiffness".into()));
        }
        Ok(chain)
    }

    /// The MC90 parameters the chain was identified from.
    pub fn params(&self) -> &CreepShrinkageParams {
        &self.params
    }

    /// Identification settings.
    pub fn settings(&self) -> &ChainSettings {
        &self.settings
    }

    /// Relaxation times τ_μ \[days\] (last one may be infinite).
    pub fn taus(&self) -> &[f64] {
        &self.settings.taus
    }

    /// Number of units.
    pub fn n_units(&self) -> usize {
        self.settings.taus.len()
    }

    /// Unit moduli E_μ(t') \[Pa\] at concrete age `age` \[days\] (clamped to
    /// `settings.min_age`), from the cache or a new least-squares fit.
    ///
    /// Panics only if the identification fails at that age, which the check in
    /// [`MaxwellChain::fit`] rules out for sane settings.
    pub fn unit_moduli(&self, age: f64) -> Vec<f64> {
        self.try_unit_moduli(age)
            .expect("Maxwell chain identification failed")
    }

    /// Fallible version of [`MaxwellChain::unit_moduli`].
    pub fn try_unit_moduli(&self, age: f64) -> Result<Vec<f64>, TimeModelError> {
        let age = age.max(self.settings.min_age);
        let key = age.to_bits();
        if let Ok(c) = self.cache.read() {
            if let Some(v) = c.get(&key) {
                return Ok(v.clone());
            }
        }
        let e = self.identify(age)?;
        if let Ok(mut c) = self.cache.write() {
            if c.len() >= CACHE_LIMIT {
                c.clear();
            }
            c.insert(key, e.clone());
        }
        Ok(e)
    }

    /// Chain relaxation function Σ E_μ(t') exp(−(t − t')/τ_μ) \[Pa\] (ages in days).
    pub fn chain_relaxation(&self, t: f64, t_prime: f64) -> f64 {
        let e = self.unit_moduli(t_prime);
        let d = (t - t_prime).max(0.0);
        e.iter()
            .zip(&self.settings.taus)
            .map(|(&em, &tau)| em * decay(d, tau))
            .sum()
    }

    fn identify(&self, age: f64) -> Result<Vec<f64>, TimeModelError> {
        let r = relaxation_function(&self.params, age, &self.grid);
        let s = &self.settings;
        let lo = s.fit_min * (1.0 - 1e-9);
        let hi = s.fit_max * (1.0 + 1e-9);
        let samples: Vec<(f64, f64)> = self
            .grid
            .iter()
            .zip(&r)
            .filter(|(&d, _)| d >= lo && d <= hi)
            .map(|(&d, &rv)| (d, rv))
            .collect();
        let n = s.taus.len();
        let basis = |d: f64| -> Vec<f64> { s.taus.iter().map(|&tau| decay(d, tau)).collect() };
        let mut a = vec![vec![0.0; n]; n];
        let mut b = vec![0.0; n];
        for &(d, rv) in &samples {
            let phi = basis(d);
            for i in 0..n {
                b[i] += phi[i] * rv;
                for j in 0..n {
                    a[i][j] += phi[i] * phi[j];
                }
            }
        }
        nonneg_normal_solve(&a, &b)
            .ok_or_else(|| TimeModelError::FitFailed(format!("singular system at age {age}")))
    }
}

/// exp(−d/τ), = 1 for τ = ∞.
fn decay(d: f64, tau: f64) -> f64 {
    if tau.is_infinite() {
        1.0
    } else {
        (-d / tau).exp()
    }
}

/// Geometric grid from `start` to `end` (inclusive) with `per_decade` points per decade.
fn geometric_grid(start: f64, end: f64, per_decade: usize) -> Vec<f64> {
    let decades = (end / start).log10();
    let n = (decades * per_decade as f64).round().max(1.0) as usize;
    (0..=n)
        .map(|k| start * (end / start).powf(k as f64 / n as f64))
        .collect()
}

/// Relaxation function R(t' + d_k, t') \[Pa\] of the MC90 compliance for loading age
/// `t_prime` \[days\], at the increasing durations `durations` \[days\] (all > 0), by the
/// step-by-step midpoint method of docs/theory-time.md §2 (jump ΔR_0 = 1/J(t', t') = E_ci(t') at
/// loading, then the grid given by `durations`; accuracy depends on that grid — about
/// 0.3 % with 30 points per decade from 1e-3 d).
pub fn relaxation_function(p: &CreepShrinkageParams, t_prime: f64, durations: &[f64]) -> Vec<f64> {
    let n = durations.len();
    // Times t_0 = t', t_k = t' + d_k; mid-points t_{k−½}.
    let times: Vec<f64> = std::iter::once(t_prime)
        .chain(durations.iter().map(|&d| t_prime + d))
        .collect();
    let eci = p.eci();
    let beta_h = p.beta_h();
    // J(t, s) = 1/E_ci(s) + φ0(s) β_c(t − s)/E_ci, with the age terms precomputed.
    let age_terms = |s: f64| (1.0 / p.eci_at(s), p.phi0(s) / eci);
    let bc = |d: f64| {
        if d <= 0.0 {
            0.0
        } else {
            (d / (beta_h + d)).powf(0.3)
        }
    };
    let (inv0, ph0) = age_terms(t_prime);
    let mids: Vec<(f64, f64, f64)> = (1..=n)
        .map(|k| {
            let s = 0.5 * (times[k - 1] + times[k]);
            let (i, f) = age_terms(s);
            (s, i, f)
        })
        .collect();
    let mut dr = Vec::with_capacity(n + 1);
    dr.push(1.0 / inv0);
    let mut out = Vec::with_capacity(n);
    let mut r = dr[0];
    for k in 1..=n {
        let tk = times[k];
        let mut rhs = 1.0 - dr[0] * (inv0 + ph0 * bc(tk - t_prime));
        for j in 1..k {
            let (s, i, f) = mids[j - 1];
            rhs -= dr[j] * (i + f * bc(tk - s));
        }
        let (s, i, f) = mids[k - 1];
        let d = rhs / (i + f * bc(tk - s));
        dr.push(d);
        r += d;
        out.push(r);
    }
    out
}

/// Solve the symmetric normal equations A x = b (small, dense) with x ≥ 0 by a simple
/// active-set loop: solve on the free set, fix the most negative unknown at zero, repeat.
/// Returns `None` if a reduced system is singular or nothing stays free.
pub(crate) fn nonneg_normal_solve(a: &[Vec<f64>], b: &[f64]) -> Option<Vec<f64>> {
    let n = b.len();
    let mut free: Vec<usize> = (0..n).collect();
    loop {
        if free.is_empty() {
            return None;
        }
        let m = free.len();
        let mut aa: Vec<Vec<f64>> = free
            .iter()
            .map(|&i| free.iter().map(|&j| a[i][j]).collect())
            .collect();
        let mut bb: Vec<f64> = free.iter().map(|&i| b[i]).collect();
        let x = gauss_solve(&mut aa, &mut bb)?;
        let (worst, val) =
            x.iter().enumerate().fold(
                (0, f64::INFINITY),
                |acc, (k, &v)| {
                    if v < acc.1 {
                        (k, v)
                    } else {
                        acc
                    }
                },
            );
        if val >= 0.0 || m == 0 {
            let mut out = vec![0.0; n];
            for (k, &i) in free.iter().enumerate() {
                out[i] = x[k];
            }
            return Some(out);
        }
        free.remove(worst);
    }
}

/// Gaussian elimination with partial pivoting (overwrites the inputs).
fn gauss_solve(a: &mut [Vec<f64>], b: &mut [f64]) -> Option<Vec<f64>> {
    let n = b.len();
    let scale = a
        .iter()
        .flat_map(|r| r.iter())
        .fold(0.0f64, |m, &v| m.max(v.abs()));
    if scale == 0.0 {
        return None;
    }
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() <= 1e-14 * scale {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        let (top, bottom) = a.split_at_mut(c + 1);
        let piv = &top[c];
        let bc = b[c];
        for (row, br) in bottom.iter_mut().zip(b[c + 1..].iter_mut()) {
            let f = row[c] / piv[c];
            if f != 0.0 {
                for (x, &pv) in row[c..].iter_mut().zip(&piv[c..]) {
                    *x -= f * pv;
                }
                *br -= f * bc;
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let s: f64 = (r + 1..n).map(|k| a[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

// ---------------------------------------------------------------------------------------
// Exponential algorithm, plane stress
// ---------------------------------------------------------------------------------------

/// Hidden state of a chain at one Gauss point: the stress of every unit, plane-stress Voigt
/// (σx, σy, τxy) \[Pa\]. The total stress is the sum over units. An empty vector means a
/// virgin (stress-free) point.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct ChainState {
    /// Unit stresses σ_μ \[Pa\], one 3-vector per unit.
    pub hidden: Vec<[f64; 3]>,
}

impl ChainState {
    /// Stress-free state for `n_units` units.
    pub fn new(n_units: usize) -> Self {
        Self {
            hidden: vec![[0.0; 3]; n_units],
        }
    }

    /// Total stress Σ_μ σ_μ \[Pa\].
    pub fn stress(&self) -> [f64; 3] {
        self.hidden
            .iter()
            .fold([0.0; 3], |s, h| [s[0] + h[0], s[1] + h[1], s[2] + h[2]])
    }
}

/// Result of one time step of the chain.
#[derive(Debug, Clone, PartialEq)]
pub struct ChainStep {
    /// Stress increment Δσ \[Pa\] (Voigt, engineering shear).
    pub d_stress: [f64; 3],
    /// Incremental modulus E'' \[Pa\]; the step tangent is E'' D1(ν).
    pub e_incr: f64,
    /// Stress-independent creep strain increment Δε'' \[-\] (the initial strain of the step;
    /// its pseudo-load is ∫ Bᵀ E'' D1 Δε'' dΩ).
    pub d_creep_strain: [f64; 3],
    /// Updated hidden state.
    pub new_state: ChainState,
}

/// Step quantities known at the start of a step (before the strain increment is known).
#[derive(Debug, Clone, PartialEq)]
pub struct ChainPredictor {
    /// Incremental modulus E'' \[Pa\].
    pub e_incr: f64,
    /// Creep strain increment Δε'' \[-\].
    pub d_creep_strain: [f64; 3],
    /// Decay factors β_μ = exp(−Δt/τ_μ) \[-\].
    pub beta: Vec<f64>,
    /// Factors λ_μ = (1 − β_μ)/(Δt/τ_μ) \[-\].
    pub lambda: Vec<f64>,
    /// Unit moduli at the mid-step age \[Pa\].
    pub moduli: Vec<f64>,
}

/// Plane-stress elastic matrix for unit modulus, D1(ν) = `1/(1−ν²) [[1,ν,0],[ν,1,0],[0,0,(1−ν)/2]]`.
pub fn plane_stress_d1(nu: f64) -> [[f64; 3]; 3] {
    let c = 1.0 / (1.0 - nu * nu);
    [
        [c, c * nu, 0.0],
        [c * nu, c, 0.0],
        [0.0, 0.0, c * 0.5 * (1.0 - nu)],
    ]
}

/// Inverse of [`plane_stress_d1`]: `[[1,−ν,0],[−ν,1,0],[0,0,2(1+ν)]]`.
pub fn plane_stress_d1_inv(nu: f64) -> [[f64; 3]; 3] {
    [
        [1.0, -nu, 0.0],
        [-nu, 1.0, 0.0],
        [0.0, 0.0, 2.0 * (1.0 + nu)],
    ]
}

fn mat_vec(m: &[[f64; 3]; 3], v: &[f64; 3]) -> [f64; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

/// β = exp(−Δt/τ) and λ = (1 − β)/(Δt/τ) for one unit (β = λ = 1 for τ = ∞ or Δt = 0).
fn beta_lambda(dt: f64, tau: f64) -> (f64, f64) {
    if tau.is_infinite() || dt <= 0.0 {
        return (1.0, 1.0);
    }
    let y = dt / tau;
    let em1 = (-y).exp_m1(); // β − 1, accurate for small y
    (1.0 + em1, -em1 / y)
}

/// Quantities of the step from concrete age `t_from` to `t_to` \[days\] that do not depend on
/// the strain increment: E'' and Δε'' (docs/theory-time.md §2, exponential algorithm), with the
/// unit moduli at the mid-step age ½(t_from + t_to). `nu` = Poisson ratio (constant). Panics if
/// `t_to < t_from`.
pub fn chain_predictor(
    chain: &MaxwellChain,
    nu: f64,
    state: &ChainState,
    t_from: f64,
    t_to: f64,
) -> ChainPredictor {
    assert!(t_to >= t_from, "chain step backwards in time");
    let dt = t_to - t_from;
    let moduli = chain.unit_moduli(0.5 * (t_from + t_to));
    let n = moduli.len();
    let (beta, lambda): (Vec<f64>, Vec<f64>) =
        chain.taus().iter().map(|&tau| beta_lambda(dt, tau)).unzip();
    let e_incr: f64 = (0..n).map(|m| lambda[m] * moduli[m]).sum();
    let mut ds = [0.0; 3];
    for (m, h) in state.hidden.iter().enumerate().take(n) {
        for c in 0..3 {
            ds[c] += (1.0 - beta[m]) * h[c];
        }
    }
    let dinv = plane_stress_d1_inv(nu);
    let de = mat_vec(&dinv, &ds);
    ChainPredictor {
        e_incr,
        d_creep_strain: [de[0] / e_incr, de[1] / e_incr, de[2] / e_incr],
        beta,
        lambda,
        moduli,
    }
}

/// One exponential-algorithm step (docs/theory-time.md §2) from age `t_from` to `t_to` \[days\] for
/// a total-strain increment `d_strain` \[-\] (Voigt, engineering shear) with an imposed
/// stress-free strain increment `d_imposed` \[-\] (shrinkage, temperature, …):
///
/// Δσ = E'' D1 (Δε − Δε'' − Δε_imp),  σ_μ ← β_μ σ_μ + λ_μ E_μ D1 (Δε − Δε_imp).
pub fn chain_step_imposed(
    chain: &MaxwellChain,
    nu: f64,
    state: &ChainState,
    t_from: f64,
    t_to: f64,
    d_strain: &[f64; 3],
    d_imposed: &[f64; 3],
) -> ChainStep {
    let pred = chain_predictor(chain, nu, state, t_from, t_to);
    let n = pred.moduli.len();
    let d1 = plane_stress_d1(nu);
    let net = [
        d_strain[0] - d_imposed[0],
        d_strain[1] - d_imposed[1],
        d_strain[2] - d_imposed[2],
    ];
    let d1net = mat_vec(&d1, &net);
    let mut hidden = Vec::with_capacity(n);
    for m in 0..n {
        let old = state.hidden.get(m).copied().unwrap_or([0.0; 3]);
        let f = pred.lambda[m] * pred.moduli[m];
        hidden.push([
            pred.beta[m] * old[0] + f * d1net[0],
            pred.beta[m] * old[1] + f * d1net[1],
            pred.beta[m] * old[2] + f * d1net[2],
        ]);
    }
    let el = [
        net[0] - pred.d_creep_strain[0],
        net[1] - pred.d_creep_strain[1],
        net[2] - pred.d_creep_strain[2],
    ];
    let d1el = mat_vec(&d1, &el);
    ChainStep {
        d_stress: [
            pred.e_incr * d1el[0],
            pred.e_incr * d1el[1],
            pred.e_incr * d1el[2],
        ],
        e_incr: pred.e_incr,
        d_creep_strain: pred.d_creep_strain,
        new_state: ChainState { hidden },
    }
}

/// One chain step with shrinkage as the imposed strain: Δε_imp = Δε_sh (1, 1, 0), where
/// `d_shrinkage` = ε_cs(t_to) − ε_cs(t_from) \[-\] (negative = shortening). Ages in days,
/// `nu` the Poisson ratio. See [`chain_step_imposed`].
pub fn chain_step(
    chain: &MaxwellChain,
    nu: f64,
    state: &ChainState,
    t_from: f64,
    t_to: f64,
    d_strain: &[f64; 3],
    d_shrinkage: f64,
) -> ChainStep {
    chain_step_imposed(
        chain,
        nu,
        state,
        t_from,
        t_to,
        d_strain,
        &[d_shrinkage, d_shrinkage, 0.0],
    )
}

// ---------------------------------------------------------------------------------------
// Non-ageing uniaxial chain for prestressing-steel relaxation (docs/theory-time.md §3)
// ---------------------------------------------------------------------------------------

/// Non-ageing uniaxial Maxwell chain for the relaxation of prestressing steel, fitted to the
/// MC90 loss ρ(t) of [`crate::materials::mc90_time::relaxation_loss`] for the tendon's
/// initial stress ratio (the paper: "the same rheological model … for the prestressing
/// steel relaxation"). Linear: under a varying strain the loss follows by superposition.
///
/// **\[DECISION\]** (docs/theory-time.md §3) five units represent the power law poorly
/// (≈ 35 % error on the 1000 h loss). Since the chain is uniaxial and cheap, the default uses
/// two units per decade, τ = 10^(k/2) × 1e-3 d up to 1e5 d, plus a spring, and fits the loss
/// with relative weights on 1e-3 … 2e4 d (≈ 1.4 min … 5·10⁵ h) under the constraint
/// R(0) = E_p.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SteelRelaxationChain {
    /// Elastic modulus E_p \[Pa\].
    pub ep: f64,
    /// Relaxation times \[days\]; the last is `f64::INFINITY`.
    pub taus: Vec<f64>,
    /// Unit moduli as fractions a_μ of E_p (Σ a_μ = 1) \[-\].
    pub fractions: Vec<f64>,
}

/// Result of a uniaxial chain step.
#[derive(Debug, Clone, PartialEq)]
pub struct UniaxialChainStep {
    /// Stress increment \[Pa\].
    pub d_stress: f64,
    /// Incremental modulus E'' \[Pa\].
    pub e_incr: f64,
    /// Updated unit stresses \[Pa\].
    pub new_hidden: Vec<f64>,
}

impl SteelRelaxationChain {
    /// Chain fitted to the MC90 loss of `class` at initial stress ratio σ_pi/f_ptk \[-\], with
    /// modulus `ep` \[Pa\] and the default relaxation times (see the type documentation).
    /// Below 0.5 f_ptk (no relaxation) the chain is a single spring.
    pub fn fit(
        class: RelaxationClass,
        sigma_pi_over_fptk: f64,
        ep: f64,
    ) -> Result<Self, TimeModelError> {
        let k = class.default_exponent();
        let loss = move |t: f64| {
            super::mc90_time::relaxation_loss_with_exponent(class, sigma_pi_over_fptk, t, k)
        };
        if rho1000(class, sigma_pi_over_fptk) <= 0.0 {
            return Ok(Self {
                ep,
                taus: vec![f64::INFINITY],
                fractions: vec![1.0],
            });
        }
        Self::fit_to_loss(ep, Self::default_taus(), loss, 1e-3, 2e4)
    }

    /// Default relaxation times \[days\]: 1e-3 · 10^(k/2), k = 0 … 16 (1e-3 … 1e5 d), then ∞.
    pub fn default_taus() -> Vec<f64> {
        let mut t: Vec<f64> = (0..=16)
            .map(|k| 1e-3 * 10f64.powf(k as f64 / 2.0))
            .collect();
        t.push(f64::INFINITY);
        t
    }

    /// Fit the unit fractions to a loss function `loss(t_days)` (fraction of the initial
    /// stress) on durations `t_min … t_max` \[days\] (10 points per decade), minimising the
    /// relative error of the loss; the last τ must be infinite (it takes 1 − Σ a_finite).
    pub fn fit_to_loss(
        ep: f64,
        taus: Vec<f64>,
        loss: impl Fn(f64) -> f64,
        t_min: f64,
        t_max: f64,
    ) -> Result<Self, TimeModelError> {
        if ep.is_nan() || ep <= 0.0 {
            return Err(TimeModelError::InvalidParameter("ep", ep));
        }
        if taus.last().is_none_or(|t| !t.is_infinite()) || taus.len() < 2 {
            return Err(TimeModelError::InvalidParameter(
                "taus (last must be infinite)",
                f64::NAN,
            ));
        }
        let nf = taus.len() - 1;
        let grid = geometric_grid(t_min, t_max, 10);
        let mut a = vec![vec![0.0; nf]; nf];
        let mut b = vec![0.0; nf];
        for &t in &grid {
            let target = loss(t);
            if target.is_nan() || target <= 0.0 {
                continue;
            }
            let w2 = 1.0 / (target * target);
            let phi: Vec<f64> = taus[..nf].iter().map(|&tau| -(-t / tau).exp_m1()).collect();
            for i in 0..nf {
                b[i] += w2 * phi[i] * target;
                for j in 0..nf {
                    a[i][j] += w2 * phi[i] * phi[j];
                }
            }
        }
        let mut fr = nonneg_normal_solve(&a, &b)
            .ok_or_else(|| TimeModelError::FitFailed("steel relaxation fit singular".into()))?;
        let s: f64 = fr.iter().sum();
        if s >= 1.0 {
            return Err(TimeModelError::FitFailed(
                "relaxation loss exceeds the initial stress".into(),
            ));
        }
        fr.push(1.0 - s);
        Ok(Self {
            ep,
            taus,
            fractions: fr,
        })
    }

    /// Number of units.
    pub fn n_units(&self) -> usize {
        self.taus.len()
    }

    /// Relative chain loss 1 − R(t)/E_p after `t_days` \[days\] at constant strain \[-\].
    pub fn loss(&self, t_days: f64) -> f64 {
        1.0 - self
            .fractions
            .iter()
            .zip(&self.taus)
            .map(|(&a, &tau)| a * decay(t_days.max(0.0), tau))
            .sum::<f64>()
    }

    /// One exponential step of length `dt` \[days\] with strain increment `d_strain` \[-\]
    /// (stress-free strain already removed); `hidden` = unit stresses \[Pa\] (empty = virgin).
    pub fn step(&self, hidden: &[f64], dt: f64, d_strain: f64) -> UniaxialChainStep {
        assert!(dt >= 0.0, "chain step backwards in time");
        let mut e_incr = 0.0;
        let mut relax = 0.0;
        let mut new_hidden = Vec::with_capacity(self.taus.len());
        for (m, (&a, &tau)) in self.fractions.iter().zip(&self.taus).enumerate() {
            let (b, l) = beta_lambda(dt, tau);
            let em = a * self.ep;
            let old = hidden.get(m).copied().unwrap_or(0.0);
            e_incr += l * em;
            relax += (1.0 - b) * old;
            new_hidden.push(b * old + l * em * d_strain);
        }
        UniaxialChainStep {
            d_stress: e_incr * d_strain - relax,
            e_incr,
            new_hidden,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::mc90_time::{compliance, relaxation_loss, CementClass};
    use super::*;

    /// The check case of docs/theory-time.md §2: fcm 45 MPa, RH 70 %, h = 200 mm, cement N.
    fn params() -> CreepShrinkageParams {
        CreepShrinkageParams::new(45.0e6, 0.70, 0.200, CementClass::N, 7.0)
    }

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    #[test]
    fn default_relaxation_times() {
        let s = ChainSettings::with_units(5).unwrap();
        assert_eq!(s.taus[..4], [1.0, 10.0, 100.0, 1000.0]);
        assert!(s.taus[4].is_infinite());
        let s6 = ChainSettings::with_units(6).unwrap();
        assert!(rel(s6.taus[0], 0.1) < 1e-12);
        assert!(ChainSettings::with_units(1).is_err());
    }

    /// Check 13: R(t, 28) by the step-by-step method of docs/theory-time.md §2 against a
    /// reference solution of the same method (200-step, 1e-3 d grid). Tolerance 1 %: the reference
    /// itself is converged only to ≈ 0.3 % and our grid (30/decade) differs slightly; a wrong jump
    /// or midpoint gives > 5 %.
    #[test]
    fn check_13_relaxation_function() {
        let p = params();
        let grid = geometric_grid(1e-3, 1e4, 30);
        let r = relaxation_function(&p, 28.0, &grid);
        let at = |d: f64| {
            let k = grid.iter().position(|&g| rel(g, d) < 1e-9).unwrap();
            r[k]
        };
        for (d, rmpa) in [
            (0.01, 33171.0),
            (1.0, 27653.0),
            (10.0, 22504.0),
            (100.0, 16220.0),
            (1000.0, 11440.0),
            (10000.0, 9910.0),
        ] {
            let v = at(d) / 1e6;
            assert!(rel(v, rmpa) < 0.01, "R({d}) = {v} vs {rmpa}");
            // Relaxation is below 1/J (the quasi-elastic value) except at the start.
            assert!(v <= 1e-6 / compliance(&p, 28.0 + d, 28.0) * (1.0 + 1e-9));
        }
        // Convergence: the default 10/decade grid used by the fit is within 1 % too.
        let g10 = geometric_grid(1e-3, 1e4, 10);
        let r10 = relaxation_function(&p, 28.0, &g10);
        assert!(rel(*r10.last().unwrap(), *r.last().unwrap()) < 0.01);
    }

    /// The instantaneous response of the chain (a step with Δt = 0 has the modulus
    /// Σ E_μ(t0)) is softer than 1/E_ci(t0) by 9–16 %. The cause is the MC90 creep function,
    /// not its implementation: J(t0, t0) = 1/E_ci(t0) exactly, but β_c ∝ (t − t0)^0.3 makes J
    /// grow by that much within the first 0.1 d, and the chain (shortest τ = 1 d, fitted on
    /// 0.1 … 1e4 d) cannot follow creep faster than its fit window: its instantaneous modulus
    /// is 1/J(t0 + 0.1 d, t0). Tolerances: J at t0 + 1e-12 d against 1/E_ci(t0) within 1e-4
    /// (the power-law term is φ0 (1e-12/β_H)^0.3 ≈ 7e-5 there); Σ E_μ against 1/J(t0 + 0.1)
    /// within 1 % (least-squares extrapolation to Δt = 0; measured ≤ 0.15 %), and against
    /// 1/E_ci(t0) outside 5 % (so a change of definition is noticed).
    #[test]
    fn instantaneous_response_is_the_tenth_of_a_day_compliance() {
        let p = params();
        let chain = MaxwellChain::fit(&p, 5).unwrap();
        for t0 in [7.0, 28.0, 365.0] {
            let inst = 1.0 / p.eci_at(t0);
            assert_eq!(compliance(&p, t0, t0), inst);
            assert!(rel(compliance(&p, t0 + 1e-12, t0), inst) < 1e-4);
            let sum: f64 = chain.unit_moduli(t0).iter().sum();
            let j01 = compliance(&p, t0 + 0.1, t0);
            assert!(
                rel(sum, 1.0 / j01) < 0.01,
                "t0 = {t0}: {sum} vs {}",
                1.0 / j01
            );
            assert!(p.eci_at(t0) / sum > 1.05, "t0 = {t0}");
            // The Δt = 0 step of the chain has exactly that modulus.
            let st = chain_step(
                &chain,
                0.2,
                &ChainState::new(5),
                t0,
                t0,
                &[1e-4, 0.0, 0.0],
                0.0,
            );
            assert!(rel(st.e_incr, sum) < 1e-12);
        }
    }

    /// Check 15: all E_μ(t') > 0 for τ = {1, 10, 100, 1000, ∞} and t' from 3 to 365 d; the
    /// 28-day fit approximates the reference fit quoted in docs/theory-time.md §2
    /// (procedure-dependent ±1 %, so 5 % on the sum and on the spring) and reproduces R within the
    /// quoted maximum fit error (1.6 % → 2.5 %).
    #[test]
    fn check_15_unit_moduli_positive() {
        let p = params();
        let chain = MaxwellChain::fit(&p, 5).unwrap();
        for age in [3.0, 7.0, 14.0, 28.0, 90.0, 180.0, 365.0] {
            let e = chain.unit_moduli(age);
            assert_eq!(e.len(), 5);
            for (m, &em) in e.iter().enumerate() {
                assert!(em > 0.0, "E_{m}({age}) = {em}");
            }
            // Sum below the instantaneous modulus (fast creep absorbed by unit 1).
            assert!(e.iter().sum::<f64>() < p.eci_at(age));
        }
        let e28 = chain.unit_moduli(28.0);
        let sum: f64 = e28.iter().sum();
        assert!(rel(sum, 31183e6) < 0.05, "sum {sum}");
        assert!(rel(e28[4], 10047.5e6) < 0.05, "spring {}", e28[4]);
        let grid = geometric_grid(0.1, 1e4, 10);
        let r = relaxation_function(&p, 28.0, &geometric_grid(1e-3, 1e4, 30));
        let gfine = geometric_grid(1e-3, 1e4, 30);
        for &d in &grid {
            let k = gfine.iter().position(|&g| rel(g, d) < 1e-6).unwrap();
            let fit = chain.chain_relaxation(28.0 + d, 28.0);
            assert!(rel(fit, r[k]) < 0.025, "fit at {d}: {fit} vs {}", r[k]);
        }
        // Cached value is returned unchanged.
        assert_eq!(chain.unit_moduli(28.0), e28);
    }

    /// Apply a uniaxial stress `sigma` at age t0 (step with Δt = 0) and hold it over the
    /// given ages; returns ε_x at each age.
    fn creep_under_constant_stress(
        chain: &MaxwellChain,
        nu: f64,
        t0: f64,
        ages: &[f64],
        sigma: f64,
    ) -> Vec<f64> {
        let dinv = plane_stress_d1_inv(nu);
        let mut state = ChainState::new(chain.n_units());
        let mut eps = [0.0; 3];
        let mut t = t0;
        let mut out = Vec::new();
        let mut target = [sigma, 0.0, 0.0];
        for &tn in std::iter::once(&t0).chain(ages.iter()) {
            let pred = chain_predictor(chain, nu, &state, t, tn);
            let de_el = mat_vec(&dinv, &target);
            let de = [
                pred.d_creep_strain[0] + de_el[0] / pred.e_incr,
                pred.d_creep_strain[1] + de_el[1] / pred.e_incr,
                pred.d_creep_strain[2] + de_el[2] / pred.e_incr,
            ];
            let step = chain_step(chain, nu, &state, t, tn, &de, 0.0);
            for c in 0..3 {
                assert!((step.d_stress[c] - target[c]).abs() <= 1e-9 * sigma.abs());
                eps[c] += de[c];
            }
            state = step.new_state;
            target = [0.0; 3];
            if tn > t0 {
                out.push(eps[0]);
                // Plane stress, constant ν: lateral strain −ν ε_x, no shear.
                assert!(rel(eps[1], -nu * eps[0]) < 1e-9);
                assert!(eps[2].abs() < 1e-20);
            }
            t = tn;
        }
        let s = state.stress();
        assert!(rel(s[0], sigma) < 1e-9 && s[1].abs() < 1e-9 * sigma.abs());
        out
    }

    fn log_ages(t0: f64, first: f64, last: f64, per_decade: usize) -> Vec<f64> {
        geometric_grid(first, last, per_decade)
            .into_iter()
            .map(|d| t0 + d)
            .collect()
    }

    /// Check 14 (docs/theory-time.md §2 and §5): unit stress at t0 = 28, 61 log steps 1e-2 … 1e4 d.
    /// Tolerances 1 % for t − t0 ≥ 1 d and 2 % at 0.1 d as docs/theory-time.md §5 (the 5-unit fit
    /// misses the very fast creep); a wrong E'' or β/λ gives errors of tens of %.
    #[test]
    fn check_14_creep_reproduction_28d() {
        let p = params();
        let chain = MaxwellChain::fit(&p, 5).unwrap();
        let ages = log_ages(28.0, 1e-2, 1e4, 10);
        let sigma = -1.0e6;
        let eps = creep_under_constant_stress(&chain, 0.2, 28.0, &ages, sigma);
        for (k, &t) in ages.iter().enumerate() {
            let d = t - 28.0;
            let j = compliance(&p, t, 28.0);
            let ratio = eps[k] / (sigma * j);
            if d >= 1.0 - 1e-9 {
                assert!((ratio - 1.0).abs() < 0.01, "t-t0 = {d}: ratio {ratio}");
            } else if d >= 0.1 - 1e-9 {
                assert!((ratio - 1.0).abs() < 0.02, "t-t0 = {d}: ratio {ratio}");
            }
        }
    }

    /// Brief: constant-stress creep against MC90 J within 2 % from 1 to 1e4 days for
    /// t0 = 7, 28, 365 d (2 %: fit error of the 5-unit chain at young ages, docs/theory-time.md
    /// §2).
    #[test]
    fn creep_reproduction_several_loading_ages() {
        let p = params();
        let chain = MaxwellChain::fit(&p, 5).unwrap();
        for t0 in [7.0, 28.0, 365.0] {
            let ages = log_ages(t0, 1e-2, 1e4, 10);
            let eps = creep_under_constant_stress(&chain, 0.2, t0, &ages, 1.0);
            let mut worst: f64 = 0.0;
            for (k, &t) in ages.iter().enumerate() {
                if t - t0 >= 1.0 - 1e-9 {
                    worst = worst.max((eps[k] / compliance(&p, t, t0) - 1.0).abs());
                }
            }
            assert!(worst < 0.02, "t0 = {t0}: worst error {worst}");
        }
    }

    /// Creep in shear: a shear stress τ applied at t0 = 28 d and held gives γ(t) =
    /// 2(1 + ν) τ J(t, t0) (plane stress, constant ν: the chain's shear compliance is the
    /// uniaxial one over G/E), no normal strain, within 1 % from 1 d on (the fit's error, as
    /// check 14); a shear creep strain of the wrong sign or size misses it by far more.
    #[test]
    fn creep_in_shear_follows_the_uniaxial_compliance() {
        let p = params();
        let chain = MaxwellChain::fit(&p, 5).unwrap();
        let (nu, t0, tau) = (0.2, 28.0, 1.0e6);
        let dinv = plane_stress_d1_inv(nu);
        let mut state = ChainState::new(chain.n_units());
        let (mut eps, mut t, mut target) = ([0.0; 3], t0, [0.0, 0.0, tau]);
        for tn in std::iter::once(t0).chain(log_ages(t0, 1e-2, 1e4, 10)) {
            let pred = chain_predictor(&chain, nu, &state, t, tn);
            let de_el = mat_vec(&dinv, &target);
            let de: [f64; 3] =
                std::array::from_fn(|c| pred.d_creep_strain[c] + de_el[c] / pred.e_incr);
            let step = chain_step(&chain, nu, &state, t, tn, &de, 0.0);
            for c in 0..3 {
                eps[c] += de[c];
            }
            state = step.new_state;
            target = [0.0; 3];
            if tn - t0 >= 1.0 - 1e-9 {
                let expect = 2.0 * (1.0 + nu) * tau * compliance(&p, tn, t0);
                assert!(
                    rel(eps[2], expect) < 0.01,
                    "t - t0 = {}: γ {} vs {expect}",
                    tn - t0,
                    eps[2]
                );
                assert!(eps[0].abs() < 1e-12 && eps[1].abs() < 1e-12, "{eps:?}");
            }
            t = tn;
        }
    }

    /// Brief: halving Δt changes the 1e4-day strain by < 1 % (the exponential algorithm is
    /// exact for non-ageing units; the remaining dependence comes from the ageing moduli).
    #[test]
    fn time_step_independence() {
        let p = params();
        let chain = MaxwellChain::fit(&p, 5).unwrap();
        let coarse = log_ages(28.0, 1e-2, 1e4, 5);
        let fine = log_ages(28.0, 1e-2, 1e4, 10);
        let ec = *creep_under_constant_stress(&chain, 0.2, 28.0, &coarse, 1.0)
            .last()
            .unwrap();
        let ef = *creep_under_constant_stress(&chain, 0.2, 28.0, &fine, 1.0)
            .last()
            .unwrap();
        assert!(rel(ec, ef) < 0.01, "coarse {ec} fine {ef}");
        // Halving again (10 → 20 per decade) changes the result even less.
        let finer = log_ages(28.0, 1e-2, 1e4, 20);
        let eff = *creep_under_constant_stress(&chain, 0.2, 28.0, &finer, 1.0)
            .last()
            .unwrap();
        assert!(rel(ef, eff) < rel(ec, ef).max(1e-6));
        assert!(rel(ef, eff) < 0.005, "fine {ef} finer {eff}");
    }

    /// The step is linear in the strain increment with tangent E'' D1(ν) (what the FE core
    /// assembles), and the returned stress increment equals the change of Σ σ_μ.
    /// Tolerance 1e-9 relative: pure round-off of an exactly linear map.
    #[test]
    fn step_tangent_and_state_consistency() {
        let p = params();
        let chain = MaxwellChain::fit(&p, 5).unwrap();
        let nu = 0.18;
        let mut st = ChainState::new(5);
        st = chain_step(&chain, nu, &st, 28.0, 28.0, &[-3e-5, 1e-5, 2e-5], 0.0).new_state;
        let base = chain_step(&chain, nu, &st, 28.0, 40.0, &[1e-6, -2e-6, 3e-6], -1e-6);
        let d1 = plane_stress_d1(nu);
        for j in 0..3 {
            let mut de = [1e-6, -2e-6, 3e-6];
            de[j] += 1e-7;
            let s = chain_step(&chain, nu, &st, 28.0, 40.0, &de, -1e-6);
            for (i, d1row) in d1.iter().enumerate() {
                let k = (s.d_stress[i] - base.d_stress[i]) / 1e-7;
                let expect = base.e_incr * d1row[j];
                assert!((k - expect).abs() <= 1e-6 * base.e_incr, "K[{i}][{j}]");
            }
        }
        let before = st.stress();
        let after = base.new_state.stress();
        for i in 0..3 {
            assert!((after[i] - before[i] - base.d_stress[i]).abs() <= 1e-9 * before[0].abs());
        }
        // E'' lies between the spring-only modulus and Σ E_μ; Δt = 0 gives Σ E_μ.
        let e = chain.unit_moduli(34.0);
        assert!(base.e_incr < e.iter().sum::<f64>() && base.e_incr > e[4]);
        let z = chain_step(&chain, nu, &st, 40.0, 40.0, &[0.0; 3], 0.0);
        assert!(rel(z.e_incr, chain.unit_moduli(40.0).iter().sum()) < 1e-12);
        assert!(z.d_stress.iter().all(|v| *v == 0.0));
        // Ages below min_age are clamped (MC90 is not meant for < 1 d).
        assert_eq!(chain.unit_moduli(0.2), chain.unit_moduli(1.0));
    }

    /// Free shrinkage of an unrestrained point produces no stress; fully restrained
    /// shrinkage produces biaxial tension that relaxes.
    #[test]
    fn shrinkage_as_imposed_strain() {
        let p = params();
        let chain = MaxwellChain::fit(&p, 5).unwrap();
        let nu = 0.2;
        let sh = super::super::mc90_time::shrinkage_strain;
        // Free: total strain = shrinkage.
        let mut st = ChainState::new(5);
        let mut t = 7.0;
        for tn in [8.0, 10.0, 30.0, 100.0] {
            let d = sh(&p, tn) - sh(&p, t);
            let s = chain_step(&chain, nu, &st, t, tn, &[d, d, 0.0], d);
            assert!(s.d_stress.iter().all(|v| v.abs() < 1e-6));
            st = s.new_state;
            t = tn;
        }
        // Restrained: zero total strain → tension, below the elastic estimate.
        let mut st = ChainState::new(5);
        let mut t = 7.0;
        for tn in [8.0, 10.0, 30.0, 100.0, 365.0] {
            let d = sh(&p, tn) - sh(&p, t);
            st = chain_step(&chain, nu, &st, t, tn, &[0.0; 3], d).new_state;
            t = tn;
        }
        let s = st.stress();
        let elastic = -p.eci() / (1.0 - nu) * sh(&p, 365.0);
        assert!(s[0] > 0.0 && (s[0] - s[1]).abs() < 1e-6 * s[0]);
        assert!(
            s[0] < 0.8 * elastic,
            "relaxed {} vs elastic {elastic}",
            s[0]
        );
    }

    /// Brief: constant-strain relaxation of steel stepped with the chain against the MC90
    /// code function. Tolerance 3 % of the loss for 1 d ≤ t ≤ 1e4 d (the fit error of a
    /// Dirichlet series with 2 units/decade against a power law is ≈ 1 %; 5 units would give
    /// ≈ 35 %), and 0.1 % of the stress everywhere.
    #[test]
    fn steel_relaxation_constant_strain() {
        for (class, ratio) in [
            (RelaxationClass::Class2, 0.7),
            (RelaxationClass::Class1, 0.75),
            (RelaxationClass::Class3, 0.6),
        ] {
            let ep = 195e9;
            let ch = SteelRelaxationChain::fit(class, ratio, ep).unwrap();
            assert!(ch.fractions.iter().all(|&a| a >= 0.0));
            assert!(rel(ch.fractions.iter().sum::<f64>(), 1.0) < 1e-12);
            let eps0 = ratio * 1860e6 / ep;
            let first = ch.step(&[], 0.0, eps0);
            let mut sigma = first.d_stress;
            assert!(rel(sigma, ep * eps0) < 1e-12);
            let mut h = first.new_hidden;
            let mut t = 0.0;
            for tn in geometric_grid(1e-2, 1e4, 7) {
                let s = ch.step(&h, tn - t, 0.0);
                sigma += s.d_stress;
                h = s.new_hidden;
                t = tn;
                let loss = 1.0 - sigma / (ep * eps0);
                let code = relaxation_loss(class, ratio, t);
                assert!((loss - code).abs() < 1e-3, "{class:?} t={t}");
                if t >= 1.0 {
                    assert!(rel(loss, code) < 0.03, "{class:?} t={t}: {loss} vs {code}");
                }
                assert!(rel(loss, ch.loss(t)) < 1e-9);
            }
        }
        // No relaxation below 0.5 fptk.
        let ch = SteelRelaxationChain::fit(RelaxationClass::Class1, 0.45, 195e9).unwrap();
        assert_eq!(ch.loss(1e4), 0.0);
    }

    /// Varying strain: the stepped response equals the superposition
    /// σ(t) = Σ_i Δε_i R(t − t_i) for step-wise strain changes (exact for a non-ageing chain).
    #[test]
    fn steel_relaxation_varying_strain_superposition() {
        let ep = 195e9;
        let ch = SteelRelaxationChain::fit(RelaxationClass::Class2, 0.75, ep).unwrap();
        let jumps = [(0.0, 7.0e-3), (10.0, -0.4e-3), (100.0, -0.3e-3)];
        let r = |d: f64| ep * (1.0 - ch.loss(d));
        let mut h: Vec<f64> = Vec::new();
        let mut sigma = 0.0;
        let mut t = 0.0;
        let mut times: Vec<f64> = geometric_grid(0.1, 1e4, 5);
        times.extend([0.0, 10.0, 100.0]);
        times.sort_by(f64::total_cmp);
        for tn in times {
            let s = ch.step(&h, tn - t, 0.0);
            sigma += s.d_stress;
            h = s.new_hidden;
            t = tn;
            for &(tj, dj) in &jumps {
                if tj == tn {
                    let s = ch.step(&h, 0.0, dj);
                    sigma += s.d_stress;
                    h = s.new_hidden;
                }
            }
            let exact: f64 = jumps
                .iter()
                .filter(|(tj, _)| *tj <= t)
                .map(|&(tj, dj)| dj * r(t - tj))
                .sum();
            assert!(rel(sigma, exact) < 1e-10, "t={t}: {sigma} vs {exact}");
        }
    }
}
