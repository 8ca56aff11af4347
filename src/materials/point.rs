//! The material-point dispatcher: the closed set of continuum material kinds, their state,
//! and one update function used by every continuum element.

use super::chain::{chain_step, plane_stress_d1, ChainState, MaxwellChain};
use super::concrete::{self, ConcreteParams, ConcreteState};
use super::elastic::{mul3, plane_stress_d};
use super::mc90_time::shrinkage_strain;
use serde::Serialize;
use std::sync::Arc;

/// A continuum (plane-stress) material.
#[derive(Debug, Clone, Serialize)]
pub enum Material {
    /// Linear elastic isotropic.
    Elastic {
        /// Young's modulus [Pa].
        e: f64,
        /// Poisson ratio [-].
        nu: f64,
        /// Density [kg/m³].
        density: f64,
    },
    /// Plane-stress concrete (MC90/Ottosen plasticity in compression, fixed smeared cracking
    /// in tension; docs/theory-concrete.md).
    Concrete {
        /// Material parameters (strengths and moduli in Pa).
        params: Box<ConcreteParams>,
        /// Density [kg/m³].
        density: f64,
    },
    /// Ageing linear viscoelastic concrete: MC90 creep through an ageing Maxwell chain and,
    /// optionally, MC90 shrinkage as an imposed strain (docs/theory-time.md, "In the engine").
    AgeingViscoelastic {
        /// The chain identified from the MC90 compliance (shared; unit moduli cached per age).
        #[serde(skip)]
        chain: Arc<MaxwellChain>,
        /// Poisson ratio [-] (constant, isotropic creep).
        nu: f64,
        /// Density [kg/m³].
        density: f64,
        /// Day of casting on the analysis clock [d]; concrete age = analysis time − cast_day.
        cast_day: f64,
        /// Include MC90 shrinkage (from the drying start age of the chain's parameters).
        shrinkage: bool,
    },
}

impl Material {
    /// Density [kg/m³] for self weight.
    pub fn density(&self) -> f64 {
        match self {
            Material::Elastic { density, .. } => *density,
            Material::Concrete { density, .. } => *density,
            Material::AgeingViscoelastic { density, .. } => *density,
        }
    }

    /// Initial (elastic) modulus [Pa], used for default penalty stiffnesses and unit checks.
    pub fn initial_modulus(&self) -> f64 {
        match self {
            Material::Elastic { e, .. } => *e,
            Material::Concrete { params, .. } => params.ec,
            // The 28-day tangent modulus E_ci of MC90.
            Material::AgeingViscoelastic { chain, .. } => chain.params().eci(),
        }
    }

    /// A fresh state for one integration point.
    pub fn initial_state(&self) -> PointState {
        match self {
            Material::Elastic { .. } => PointState::Elastic,
            Material::Concrete { .. } => PointState::Concrete(Box::default()),
            Material::AgeingViscoelastic { chain, .. } => {
                PointState::Ageing(Box::new(AgeingState {
                    chain: ChainState::new(chain.n_units()),
                    strain: [0.0; 3],
                }))
            }
        }
    }

    /// The casting day [d] of a time-dependent material (creeping concrete of either
    /// kind), to be set per region; None for materials without ageing.
    pub fn cast_day_mut(&mut self) -> Option<&mut f64> {
        match self {
            Material::AgeingViscoelastic { cast_day, .. } => Some(cast_day),
            Material::Concrete { params, .. } => params.creep.as_mut().map(|c| &mut c.cast_day),
            Material::Elastic { .. } => None,
        }
    }

    /// The casting day [d] of a time-dependent material; None for materials without ageing.
    pub fn cast_day(&self) -> Option<f64> {
        match self {
            Material::AgeingViscoelastic { cast_day, .. } => Some(*cast_day),
            Material::Concrete { params, .. } => params.creep.as_ref().map(|c| c.cast_day),
            Material::Elastic { .. } => None,
        }
    }

    /// True if the tangent of this material is constant (the step can skip re-factorising).
    pub fn is_linear(&self) -> bool {
        // Concrete is never linear.
        matches!(self, Material::Elastic { .. })
    }

    /// Name of the kind, for messages.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Material::Elastic { .. } => "elastic",
            Material::Concrete { .. } => "concrete",
            Material::AgeingViscoelastic { .. } => "ageing viscoelastic",
        }
    }
}

/// State of one integration point; committed and trial copies are kept by the caller.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum PointState {
    /// Linear elastic materials keep no state.
    Elastic,
    /// Concrete point (boxed: keeps the enum small for elastic models).
    Concrete(Box<ConcreteState>),
    /// Ageing viscoelastic concrete (boxed as the concrete's: an elastic model's states are
    /// 16 bytes a point instead of 48, a third of the pages to fault in and copy at each
    /// commit; the checkpoint's encoding is the same as the unboxed variant's).
    Ageing(Box<AgeingState>),
}

/// State of an ageing viscoelastic point: the chain's unit stresses and the committed total
/// strain.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AgeingState {
    /// Hidden unit stresses σ_μ [Pa]; the point's stress is their sum.
    pub chain: ChainState,
    /// Total strain (εx, εy, γxy) at the end of the step that produced this state [-].
    pub strain: [f64; 3],
}

impl PointState {
    /// Name of the kind, for messages.
    pub fn kind_name(&self) -> &'static str {
        match self {
            PointState::Elastic => "elastic",
            PointState::Concrete(_) => "concrete",
            PointState::Ageing(_) => "ageing viscoelastic",
        }
    }

    /// End of an increment, on a committed state: the crack branches and plastic route held
    /// within the increment (see [`freeze_cracks`] and [`plastic_base`]) are released, so
    /// that the next increment starts free.
    pub fn end_increment(&mut self) {
        if let PointState::Concrete(c) = self {
            c.frozen = [0; 2];
            c.hold_plastic = false;
        }
    }

    /// The concrete state, if this is a concrete point.
    pub fn concrete(&self) -> Option<&ConcreteState> {
        match self {
            PointState::Concrete(c) => Some(c),
            _ => None,
        }
    }

    /// Number of smeared cracks (0, 1, 2) [-].
    pub fn n_cracks(&self) -> usize {
        self.concrete().map_or(0, |c| c.n_cracks())
    }

    /// Largest current crack-normal strain (crack opening strain, ≥ 0) [-].
    pub fn crack_strain(&self) -> f64 {
        self.concrete().map_or(0.0, |c| {
            if c.n_cracks() == 0 {
                0.0
            } else {
                c.crack_strains()[..c.n_cracks()]
                    .iter()
                    .fold(0.0_f64, |a, &b| a.max(b))
            }
        })
    }

    /// Angle of the first crack's normal from x [rad] (0 if uncracked).
    pub fn crack_angle(&self) -> f64 {
        self.concrete()
            .filter(|c| c.n_cracks() > 0)
            .map_or(0.0, |c| c.crack_angle())
    }

    /// Equivalent plastic strain [-] (0 for elastic points).
    pub fn equivalent_plastic_strain(&self) -> f64 {
        self.concrete()
            .map_or(0.0, |c| c.equivalent_plastic_strain())
    }

    /// True if the point is crushed.
    pub fn is_crushed(&self) -> bool {
        self.concrete().is_some_and(|c| c.is_crushed())
    }
}

/// The time interval of the current increment on the analysis clock [days]. A load step is
/// an instantaneous increment (`t_from == t_to`) at the current time; a time step advances
/// the clock. Concrete ages follow as time − cast_day of the material.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, serde::Deserialize)]
pub struct TimeContext {
    /// Analysis time at the start of the increment [d].
    pub t_from: f64,
    /// Analysis time at the end of the increment [d] (≥ `t_from`).
    pub t_to: f64,
    /// Size of this increment over the previous converged one [-], for materials that
    /// extrapolate their history (IMPL-EX cracking); 0 = do not extrapolate.
    #[serde(default)]
    pub extrapolation: f64,
}

impl TimeContext {
    /// An instantaneous increment at time `t` [d].
    pub fn at(t: f64) -> Self {
        Self {
            t_from: t,
            t_to: t,
            extrapolation: 0.0,
        }
    }

    /// Length of the increment Δt [d].
    pub fn dt(&self) -> f64 {
        self.t_to - self.t_from
    }
}

/// The material of an element of characteristic length `h` [m] with what depends on the
/// element size resolved once for all its points: a concrete with crush-band compression
/// softening gets its ultimate strain ([`concrete::ConcreteParams::for_element`], which the
/// point update otherwise does at every point, copying the parameters). None when nothing
/// depends on the element (the material is used as it is).
pub fn for_element(mat: &Material, h: f64) -> Result<Option<Material>, UpdateError> {
    match mat {
        Material::Concrete { params, density }
            if params.crush_eu.is_none()
                && params.compression_softening != concrete::CompressionSoftening::Mc90 =>
        {
            Ok(Some(Material::Concrete {
                params: Box::new(params.for_element(h)?),
                density: *density,
            }))
        }
        _ => Ok(None),
    }
}

/// Why a material update failed (the increment is then cut).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UpdateError {
    /// The local return mapping did not converge (or met a non-finite strain): the driver
    /// cuts the step and retries.
    #[error("material update did not converge: {0}")]
    NotConverged(String),
    /// A contract inside segfem was broken (parameters the input checks, a time interval
    /// the drivers make): a bug, reported as such and never mistaken for a step cut.
    #[error("internal error in a material update: {0}; please report")]
    Internal(String),
}

impl From<crate::materials::error::MaterialError> for UpdateError {
    fn from(e: crate::materials::error::MaterialError) -> Self {
        use crate::materials::error::MaterialError;
        match e {
            // The input checks every parameter: an invalid one here is a bug.
            MaterialError::InvalidParams(_) => UpdateError::Internal(e.to_string()),
            MaterialError::ReturnMappingNotConverged { .. }
            | MaterialError::LocalNotConverged(_)
            | MaterialError::NonFiniteStrain(_) => UpdateError::NotConverged(e.to_string()),
        }
    }
}

/// Result of a material update: trial state, stress [Pa] and tangent [Pa].
pub type Update = (PointState, [f64; 3], [[f64; 3]; 3]);

/// Stress update from the committed state and the total strain (εx, εy, γxy).
/// `char_length` [m] is the element's characteristic length (crack band).
///
/// Time-dependent materials see an instantaneous increment at time 0 (see
/// [`update_with_time`]).
pub fn update(
    mat: &Material,
    committed: &PointState,
    strain: &[f64; 3],
    char_length: f64,
) -> Result<Update, UpdateError> {
    update_with_time(mat, committed, strain, char_length, &TimeContext::default())
}

/// As [`update`] for the increment `time` (analysis clock in days). Time-independent
/// materials ignore `time`; the ageing viscoelastic point takes one exponential-algorithm
/// step of its Maxwell chain from age `time.t_from − cast_day` to `time.t_to − cast_day`,
/// with the shrinkage increment of that interval as an imposed strain. Its tangent is the
/// incremental modulus E'' D1(ν), constant within the increment.
pub fn update_with_time(
    mat: &Material,
    committed: &PointState,
    strain: &[f64; 3],
    char_length: f64,
    time: &TimeContext,
) -> Result<Update, UpdateError> {
    match (mat, committed) {
        (Material::Elastic { e, nu, .. }, PointState::Elastic) => {
            let d = plane_stress_d(*e, *nu);
            Ok((PointState::Elastic, mul3(&d, strain), d))
        }
        (Material::Concrete { params, .. }, PointState::Concrete(c)) => {
            let (st, sig, d) = concrete_update(params, c, strain, char_length, time)?;
            Ok((PointState::Concrete(Box::new(st)), sig, d))
        }
        (
            Material::AgeingViscoelastic {
                chain,
                nu,
                cast_day,
                shrinkage,
                ..
            },
            PointState::Ageing(ageing),
        ) => {
            let AgeingState {
                chain: state,
                strain: eps0,
            } = &**ageing;
            let (a0, a1) = (time.t_from - cast_day, time.t_to - cast_day);
            if !(a1 >= a0 && a0.is_finite() && a1.is_finite()) {
                return Err(UpdateError::Internal(format!(
                    "ageing concrete: bad time interval {} → {} d",
                    time.t_from, time.t_to
                )));
            }
            let d_eps = [
                strain[0] - eps0[0],
                strain[1] - eps0[1],
                strain[2] - eps0[2],
            ];
            let d_sh = if *shrinkage && a1 > a0 {
                let p = chain.params();
                shrinkage_strain(p, a1) - shrinkage_strain(p, a0)
            } else {
                0.0
            };
            let st = chain_step(chain, *nu, state, a0, a1, &d_eps, d_sh);
            let d1 = plane_stress_d1(*nu);
            let d = d1.map(|r| r.map(|v| v * st.e_incr));
            let sigma = st.new_state.stress();
            Ok((
                PointState::Ageing(Box::new(AgeingState {
                    chain: st.new_state,
                    strain: *strain,
                })),
                sigma,
                d,
            ))
        }
        // States come from `Material::initial_state` and a restored checkpoint is checked
        // kind by kind (`System::restore`): a mismatch is a bug in segfem, not a reason to
        // cut the step, so it must not come back as `NotConverged`.
        (mat, st) => unreachable!(
            "internal error: material {} met a point state of another kind ({}); please report",
            mat.kind_name(),
            st.kind_name()
        ),
    }
}

/// As [`update_with_time`], writing the new state into `trial` (the slot of the previous
/// iterate's state): a concrete point reuses the slot's box instead of allocating one per
/// point and assembly. Same state, stress and tangent.
pub fn update_into(
    mat: &Material,
    committed: &PointState,
    strain: &[f64; 3],
    char_length: f64,
    time: &TimeContext,
    trial: &mut PointState,
) -> Result<([f64; 3], [[f64; 3]; 3]), UpdateError> {
    if let (Material::Concrete { params, .. }, PointState::Concrete(c)) = (mat, committed) {
        // Without creep the new state is written into the slot's box in place.
        if let (None, PointState::Concrete(slot)) = (&params.creep, &mut *trial) {
            let (sig, mut d) = concrete::update_full_into(
                params,
                c,
                strain,
                char_length,
                time.dt(),
                time.extrapolation,
                slot,
            )
            .map_err(UpdateError::from)?;
            symmetrise3(&mut d);
            return Ok((sig, d));
        }
        let (st, sig, d) = concrete_update(params, c, strain, char_length, time)?;
        match trial {
            PointState::Concrete(slot) => **slot = st,
            other => *other = PointState::Concrete(Box::new(st)),
        }
        return Ok((sig, d));
    }
    let (st, sig, d) = update_with_time(mat, committed, strain, char_length, time)?;
    *trial = st;
    Ok((sig, d))
}

/// New concrete state, stress (σx, σy, τxy) [Pa] and tangent [Pa].
type ConcreteUpdate = (ConcreteState, [f64; 3], [[f64; 3]; 3]);

/// The concrete point's update (with creep in series where the law has it) and its
/// symmetrised tangent.
fn concrete_update(
    params: &concrete::ConcreteParams,
    c: &ConcreteState,
    strain: &[f64; 3],
    char_length: f64,
    time: &TimeContext,
) -> Result<ConcreteUpdate, UpdateError> {
    let res = match &params.creep {
        // Creep and shrinkage in series with the crack laws (concrete/creep.rs).
        Some(cr) => concrete::creep::update(
            params,
            cr,
            c,
            strain,
            char_length,
            time.t_from,
            time.t_to,
            time.extrapolation,
        ),
        None => concrete::update_full(
            params,
            c,
            strain,
            char_length,
            time.dt(),
            time.extrapolation,
        ),
    };
    let (st, sig, mut d) = res.map_err(UpdateError::from)?;
    symmetrise3(&mut d);
    Ok((st, sig, d))
}

/// The symmetric part of a concrete tangent: the cracked tangent is unsymmetric (shear
/// retention falls as the crack opens); the symmetric solvers take its symmetric part
/// (same converged answer, possibly more iterations).
fn symmetrise3(d: &mut [[f64; 3]; 3]) {
    for i in 0..3 {
        for j in 0..i {
            let m = 0.5 * (d[i][j] + d[j][i]);
            d[i][j] = m;
            d[j][i] = m;
        }
    }
}

/// The state an update should start from for the rest of an increment once a crack has
/// formed at this point in one of its iterations ("crack latching"): the committed state
/// with the trial's first crack (direction fixed, nothing opened yet). Returns None when
/// nothing is to be latched (elastic point, no new crack, already cracked or crushed).
///
/// Crack formation is a jump in stress at fixed strain; without latching, Newton can cycle
/// between an iterate that cracks (softening tangent, which pulls the strain back) and one
/// that does not. With the crack kept, the remaining iterations see one smooth law.
pub fn crack_base(
    mat: &Material,
    committed: &PointState,
    trial: &PointState,
) -> Option<PointState> {
    match (mat, committed, trial) {
        (Material::Concrete { params, .. }, PointState::Concrete(c), PointState::Concrete(t)) => {
            crack_latch(params, c, t).map(|b| PointState::Concrete(Box::new(b)))
        }
        _ => None,
    }
}

/// [`crack_base`] for a concrete point: the committed state `c` with the first crack of the
/// trial `t`, or None (IMPL-EX, no new crack, already cracked or crushed). Also used by the
/// local solve of creeping concrete (concrete/creep.rs).
pub(crate) fn crack_latch(
    params: &ConcreteParams,
    c: &ConcreteState,
    t: &ConcreteState,
) -> Option<ConcreteState> {
    if params.implex || c.n_cracks != 0 || t.n_cracks == 0 || c.crushed || t.crushed {
        return None;
    }
    let mut b = c.clone();
    let ebar_n = c.ebar.max(concrete::compression::initial_yield(params).0);
    b.n_cracks = 1;
    b.crack_angle = t.crack_angle;
    b.crack_max = [0.0; 2];
    b.dir_ebar = [ebar_n; 2];
    b.dir_plastic = [0.0; 2];
    Some(b)
}

/// The state an update should start from for the rest of an increment once an uncracked
/// concrete point has flowed plastically in one of its iterations ("plastic latching"): the
/// committed (or latched) state held on the compression-plasticity route. Returns None when
/// there is nothing to hold (not concrete, cracked, crushed, no flow, already held).
///
/// The route between compression plasticity and the elastic/cracking branch is decided on
/// the trial stress; near that boundary a point can alternate between the returned stress
/// and an elastic trial beyond the loading surface, a jump that keeps Newton cycling. The
/// return mapping itself is continuous (it unloads elastically), so holding the route makes
/// the rest of the increment smooth; the route is free again in the next increment.
pub fn plastic_base(base: &PointState, trial: &PointState) -> Option<PointState> {
    match (base, trial) {
        (PointState::Concrete(b), PointState::Concrete(t))
            if b.n_cracks == 0
                && t.n_cracks == 0
                && !b.crushed
                && !t.crushed
                && !b.hold_plastic
                // Flowed: the plastic strain moved (ε̄ alone also rises from 0 to the
                // initial-yield value on a virgin point's first plastic-route update).
                && t.plastic_strain != b.plastic_strain =>
        {
            let mut h = (**b).clone();
            h.hold_plastic = true;
            Some(PointState::Concrete(Box::new(h)))
        }
        _ => None,
    }
}

/// The state an update should start from for the rest of an increment whose Newton
/// iterations cycle ("branch freezing"): `base` (the committed or latched state) with each
/// crack held on the branch the trial state took — loading on the envelope or unloading on
/// the secant — and a second crack that formed in the trial kept (IMPL-EX cracks are held on
/// the side of their kink at the extrapolated strain the trial took: the secant, or the
/// capped line past it). Returns None when there is
/// nothing to hold (not a cracked concrete point, or already frozen).
///
/// Smeared cracks that compete for localisation make Newton alternate between iterates in
/// which one crack loads and its neighbour unloads and the reverse; the response has a kink
/// at e = e_max and no smaller increment removes it. With the branches held, the remaining
/// iterations see a smooth law and converge; the held branch can be slightly wrong at the
/// converged state (by the cycling amplitude), which is the documented price.
pub fn freeze_cracks(base: &PointState, trial: &PointState) -> Option<PointState> {
    match (base, trial) {
        (PointState::Concrete(b), PointState::Concrete(t))
            if b.n_cracks > 0 && !b.crushed && !t.crushed && b.frozen == [0; 2] =>
        {
            let mut f = (**b).clone();
            if t.n_cracks > f.n_cracks {
                f.n_cracks = t.n_cracks;
                f.crack_max[1] = 0.0;
            }
            for i in 0..f.n_cracks as usize {
                f.frozen[i] = if t.crack_max[i] > f.crack_max[i] {
                    1
                } else if t.crack_strain[i] > 0.0 {
                    -1
                } else {
                    0
                };
            }
            (f.frozen != [0; 2]).then(|| PointState::Concrete(Box::new(f)))
        }
        _ => None,
    }
}
