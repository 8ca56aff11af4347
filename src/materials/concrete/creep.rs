//! Creep and shrinkage of the cracking concrete: the MC90 ageing Maxwell chain in series with
//! the crack and plasticity laws of this module (docs/theory-time.md §9).
//!
//! Strain split at a point: ε = ε_ve + ε_f + ε_sh (+ ε_nl), with
//!
//! * ε_ve the strain of the viscoelastic chain (elastic and creep strain of the continuum
//!   between cracks), σ = Σ σ_μ the chain stress;
//! * ε_f the crack and plastic strain of the concrete law: the law maps its input ("mechanical
//!   strain") ε_m = D(E_c)⁻¹ σ + ε_f to σ = F(ε_m) with its own modulus E_c;
//! * ε_sh the MC90 shrinkage strain (isotropic, imposed);
//! * ε_nl the extra creep of MC90's stress-dependent creep factor (option, imposed at the
//!   start of the increment).
//!
//! The same stress σ passes through chain and crack, so a point creeps under the stress it
//! carries: across an open crack the tension-stiffening stress, along it (and in an uncracked
//! point) the full stress. Over an increment t_from → t_to the chain is linear (exponential
//! algorithm): Δε_ve = Δε'' + D1⁻¹Δσ/E''. Eliminating ε_ve gives one local equation for the
//! increment x = Δε_m of the concrete law's input:
//!
//!     G(x) = x + (1/E'' − 1/E_c) D1⁻¹ [F(ε_m,n + x) − σ_n] − (Δε − Δε'' − Δε_sh − Δε_nl) = 0,
//!
//! solved by Newton from the elastic value x0 = (E''/E_c)(Δε − Δε'' − Δε_sh − Δε_nl) (a point
//! whose iterates bounce across the crushing jump is held crushed, `CRUSH_CROSSINGS`); the
//! tangent of the point is dσ/dε = D_F (I + (1/E'' − 1/E_c) D1⁻¹ D_F)⁻¹. Where the law is
//! elastic the first evaluation solves G = 0 and the point is the ageing chain of
//! `elastic_creep` (σ = σ_n + E'' D1 (Δε − Δε'' − Δε_sh)).
//!
//! Units: days, Pa, strains dimensionless.

use super::{update_full, ConcreteParams, ConcreteState, MaterialError, UpdateResult};
use crate::materials::chain::{chain_predictor, plane_stress_d1, plane_stress_d1_inv};
use crate::materials::chain::{ChainState, MaxwellChain};
use crate::materials::mc90_time::{high_stress_creep_factor, shrinkage_strain};
use crate::materials::point::{crack_latch, freeze_cracks, plastic_base, PointState};
use std::sync::Arc;

/// [`plastic_base`] on concrete states.
fn plastic_latch(base: &ConcreteState, trial: &ConcreteState) -> Option<ConcreteState> {
    let (b, t) = (
        PointState::Concrete(Box::new(base.clone())),
        PointState::Concrete(Box::new(trial.clone())),
    );
    match plastic_base(&b, &t)? {
        PointState::Concrete(c) => Some(*c),
        _ => None,
    }
}

/// [`freeze_cracks`] on concrete states.
fn freeze_latch(base: &ConcreteState, trial: &ConcreteState) -> Option<ConcreteState> {
    let (b, t) = (
        PointState::Concrete(Box::new(base.clone())),
        PointState::Concrete(Box::new(trial.clone())),
    );
    match freeze_cracks(&b, &t)? {
        PointState::Concrete(c) => Some(*c),
        _ => None,
    }
}

/// The MC90 creep and shrinkage of a concrete material (`creep = "mc90"`).
#[derive(Debug, Clone)]
pub struct ConcreteCreep {
    /// The chain identified from the MC90 compliance (shared; unit moduli cached per age).
    pub chain: Arc<MaxwellChain>,
    /// Day of casting on the analysis clock [d]; age = analysis time − cast_day.
    pub cast_day: f64,
    /// Include MC90 shrinkage (from the drying start age of the chain's parameters).
    pub shrinkage: bool,
    /// Apply MC90's stress-dependent creep factor exp[1.5(|σ|/f_cm(t) − 0.4)] above
    /// 0.4 f_cm (non-linear creep).
    pub nonlinear: bool,
}

/// Creep state of a concrete point (committed or trial).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct CreepState {
    /// Hidden unit stresses of the chain [Pa]; their sum is the point's stress.
    pub chain: ChainState,
    /// Total strain (εx, εy, γxy) at the end of the increment that produced this state [-].
    pub strain: [f64; 3],
    /// Accumulated shrinkage strain (isotropic) since the point was created [-].
    pub shrinkage: f64,
    /// Accumulated extra (non-linear) creep strain [-].
    pub nonlinear: [f64; 3],
}

/// Local iterations of the series equation before the increment is cut.
const MAX_LOCAL: usize = 60;

/// Changes of the crushed status between Newton iterates of the local series after which a
/// point is held crushed for the rest of its solve.
///
/// Crushing is a jump of the concrete law's stress to zero at ε̄ = ε_cu. In series with the
/// chain the local residual jumps with it, by (1/E'' − 1/E_c) D1⁻¹ σ_cu; where the chain is
/// stiffer than E_c (a load increment on concrete older than 28 days: E'' = E_c(t) > E_c)
/// the jump can straddle the root. The uncrushed law then asks for more strain than ε_cu
/// (its Newton step crosses into crushing) and the crushed one, relieved of its stress,
/// springs back below it (its step crosses out): the iterates bounce across the jump and no
/// uncrushed state satisfies the series. Along the strain path the point reached ε_cu, so it
/// is crushed: it carries no stress and the series becomes linear. Three crossings (in, out,
/// in or out, in, out) by Newton steps are asked before the hold, so that a single overshoot
/// into crushing that comes back to an uncrushed root is not taken for the jump.
const CRUSH_CROSSINGS: usize = 3;

/// Keep the crushed status of the accepted iterate `st` and, if crushed, its state (the base
/// of a crushing hold, [`CRUSH_CROSSINGS`]).
fn note_crushing(
    st: &ConcreteState,
    was_crushed: &mut bool,
    crushed_trial: &mut Option<ConcreteState>,
) {
    *was_crushed = st.crushed;
    if st.crushed {
        *crushed_trial = Some(st.clone());
    }
}

fn matvec(m: &[[f64; 3]; 3], v: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|j| m[i][j] * v[j]).sum())
}

fn matmul(a: &[[f64; 3]; 3], b: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

/// Inverse of a 3×3 matrix (None if singular against its scale).
fn inv3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c = |i: usize, j: usize| {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    let scale = m
        .iter()
        .flatten()
        .fold(0.0_f64, |a, &v| a.max(v.abs()))
        .powi(3);
    if det.is_nan() || det.abs() <= 1e-12 * scale {
        return None;
    }
    Some(std::array::from_fn(|i| {
        std::array::from_fn(|j| c(j, i) / det)
    }))
}

/// MC90's non-linear creep factor exp[1.5(|σ_c|/f_cm − 0.4)] for the stress `s` [Pa]
/// (σ_c the largest compressive principal stress; 1 at and below 0.4 f_cm). f_cm is the
/// 28-day strength, as in the crack and plasticity laws (strengths do not age): for loading
/// at 28 days this is MC90's f_cm(t0).
pub fn nonlinear_factor(creep: &ConcreteCreep, s: &[f64; 3]) -> f64 {
    let c = 0.5 * (s[0] + s[1]);
    let r = (0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2]).sqrt();
    let s2 = c - r;
    if s2 >= 0.0 {
        return 1.0;
    }
    high_stress_creep_factor(-s2 / creep.chain.params().fcm)
}

/// Stress update of a creeping concrete point over the increment `t_from` → `t_to`
/// (analysis clock [d]) at total strain `strain`; `char_length` [m] and the IMPL-EX `ratio`
/// as in [`update_full`]. See the module documentation for the formulation.
#[allow(clippy::too_many_arguments)]
// long: one local Newton solve (latching, crushing holds, backtracking) whose tangent and chain update use its last iterate; split, they would pass a dozen locals
pub fn update(
    p: &ConcreteParams,
    creep: &ConcreteCreep,
    committed: &ConcreteState,
    strain: &[f64; 3],
    char_length: f64,
    t_from: f64,
    t_to: f64,
    ratio: f64,
) -> UpdateResult {
    let (a0, a1) = (t_from - creep.cast_day, t_to - creep.cast_day);
    if !(a1 >= a0 && a0.is_finite() && a1.is_finite()) {
        return Err(MaterialError::InvalidParams(format!(
            "creeping concrete: bad time interval {t_from} → {t_to} d"
        )));
    }
    if !strain.iter().all(|v| v.is_finite()) {
        return Err(MaterialError::NonFiniteStrain(*strain));
    }
    let cs = committed
        .creep
        .as_deref()
        .cloned()
        .unwrap_or_else(|| CreepState {
            chain: ChainState::new(creep.chain.n_units()),
            ..CreepState::default()
        });
    let nu = p.nu;
    let pred = chain_predictor(&creep.chain, nu, &cs.chain, a0, a1);
    let e2 = pred.e_incr;
    let d_sh = if creep.shrinkage && a1 > a0 {
        let q = creep.chain.params();
        shrinkage_strain(q, a1) - shrinkage_strain(q, a0)
    } else {
        0.0
    };
    // Extra creep of MC90's stress-dependent factor, explicit on the committed stress.
    let d_nl: [f64; 3] = if creep.nonlinear && a1 > a0 {
        let k = nonlinear_factor(creep, &committed.stress);
        pred.d_creep_strain.map(|v| (k - 1.0) * v)
    } else {
        [0.0; 3]
    };
    let d_star: [f64; 3] = std::array::from_fn(|i| {
        strain[i] - cs.strain[i] - pred.d_creep_strain[i] - d_nl[i] - if i < 2 { d_sh } else { 0.0 }
    });
    let ec = p.ec;
    let cr = 1.0 / e2 - 1.0 / ec;
    let d1inv = plane_stress_d1_inv(nu);
    let eps_mn = committed.strain;
    let sig_n = committed.stress;
    // The concrete law must not see the creep state (its own update clones it through).
    let mut base = committed.clone();
    base.creep = None;
    let eval = |base: &ConcreteState, x: &[f64; 3]| {
        let em: [f64; 3] = std::array::from_fn(|i| eps_mn[i] + x[i]);
        let (st, s, d) = update_full(p, base, &em, char_length, 0.0, ratio)?;
        let ds: [f64; 3] = std::array::from_fn(|i| s[i] - sig_n[i]);
        let g0 = matvec(&d1inv, &ds);
        let g: [f64; 3] = std::array::from_fn(|i| x[i] + cr * g0[i] - d_star[i]);
        Ok::<_, MaterialError>((st, s, d, g))
    };
    let scale = d_star
        .iter()
        .chain(eps_mn.iter())
        .fold(p.eps0(), |a, &v| a.max(v.abs()));
    let tol = 1e-12 * scale;
    let mut x: [f64; 3] = d_star.map(|v| v * (e2 / ec));
    let (mut st, mut s, mut d, mut g) = eval(&base, &x)?;
    let mut it = 0;
    let mut frozen = false;
    // Crushing of the iterates: how often a Newton step changed it, and the last crushed
    // trial state (see `CRUSH_CROSSINGS`).
    let mut crush_changes = 0;
    let mut was_crushed = st.crushed;
    let mut crushed_trial = st.crushed.then(|| st.clone());
    while g.iter().any(|v| v.abs() > tol) {
        // Latching, as the global iterations do (point.rs): a crack formed or a plastic
        // route taken in an iterate is kept for the rest of the solve, and crack branches
        // are held once the iterates cycle; the law is then smooth in x. A point whose
        // iterates keep crossing the crushing jump is held crushed (`CRUSH_CROSSINGS`).
        let latched = (crush_changes >= CRUSH_CROSSINGS && !base.crushed)
            .then(|| crushed_trial.take())
            .flatten()
            .or_else(|| crack_latch(p, &base, &st))
            .or_else(|| plastic_latch(&base, &st))
            .or_else(|| {
                (it >= 12 && !frozen).then(|| {
                    frozen = true;
                    freeze_latch(&base, &st)
                })?
            });
        if let Some(b) = latched {
            base = b;
            (st, s, d, g) = eval(&base, &x)?;
            note_crushing(&st, &mut was_crushed, &mut crushed_trial);
            continue;
        }
        if it == MAX_LOCAL {
            // A strain increment too large for the local series (a crack opening or a
            // strut softening within it), not a bug: the driver cuts the step.
            return Err(MaterialError::LocalNotConverged(format!(
                "creeping concrete: the series of creep and cracking did not converge \
                 (residual {:.3e} after {MAX_LOCAL} local iterations)",
                g.iter().fold(0.0_f64, |a, &v| a.max(v.abs()))
            )));
        }
        it += 1;
        let gp = {
            let m = matmul(&d1inv, &d);
            std::array::from_fn(|i| {
                std::array::from_fn(|j| (if i == j { 1.0 } else { 0.0 }) + cr * m[i][j])
            })
        };
        let dx = inv3(&gp).map(|gi| matvec(&gi, &g));
        let Some(dx) = dx else {
            return Err(MaterialError::LocalNotConverged(
                "creeping concrete: creep in series with a softening crack snaps back \
                 (local tangent singular); use smaller time steps or a ductile tension law"
                    .into(),
            ));
        };
        // Backtracking: halve the correction while the residual grows.
        let g_norm = g.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
        let mut step = 1.0;
        loop {
            let xt: [f64; 3] = std::array::from_fn(|i| x[i] - step * dx[i]);
            let r = eval(&base, &xt)?;
            let r_norm = r.3.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
            if r_norm < g_norm || step < 1e-3 {
                x = xt;
                (st, s, d, g) = r;
                if st.crushed != was_crushed {
                    crush_changes += 1;
                }
                note_crushing(&st, &mut was_crushed, &mut crushed_trial);
                break;
            }
            step *= 0.5;
        }
    }
    // Tangent dσ/dε = D_F (I + c D1⁻¹ D_F)⁻¹.
    let m = matmul(&d1inv, &d);
    let gp: [[f64; 3]; 3] = std::array::from_fn(|i| {
        std::array::from_fn(|j| (if i == j { 1.0 } else { 0.0 }) + cr * m[i][j])
    });
    let tangent = match inv3(&gp) {
        Some(gi) => matmul(&d, &gi),
        None => {
            return Err(MaterialError::LocalNotConverged(
                "creeping concrete: creep in series with a softening crack snaps back \
                 (tangent singular); use smaller time steps or a ductile tension law"
                    .into(),
            ))
        }
    };
    // The chain takes Δε_ve = Δε'' + D1⁻¹Δσ/E'', so that its stress stays the law's stress.
    let ds: [f64; 3] = std::array::from_fn(|i| s[i] - sig_n[i]);
    let dsd = matvec(&d1inv, &ds);
    let d_ve: [f64; 3] = std::array::from_fn(|i| pred.d_creep_strain[i] + dsd[i] / e2);
    let d1 = plane_stress_d1(nu);
    let d1ve = matvec(&d1, &d_ve);
    let hidden = (0..pred.moduli.len())
        .map(|mu| {
            let old = cs.chain.hidden.get(mu).copied().unwrap_or([0.0; 3]);
            let f = pred.lambda[mu] * pred.moduli[mu];
            std::array::from_fn(|c| pred.beta[mu] * old[c] + f * d1ve[c])
        })
        .collect();
    // The local holds end with the update: the global iterations decide their own.
    st.hold_plastic = committed.hold_plastic;
    st.frozen = committed.frozen;
    st.creep = Some(Box::new(CreepState {
        chain: ChainState { hidden },
        strain: *strain,
        shrinkage: cs.shrinkage + d_sh,
        nonlinear: std::array::from_fn(|i| cs.nonlinear[i] + d_nl[i]),
    }));
    Ok((st, s, tangent))
}
