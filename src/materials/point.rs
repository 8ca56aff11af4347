//! The material-point dispatcher: the closed set of continuum material kinds, their state,
//! and one update function used by every continuum element.

use super::chain::{chain_step, plane_stress_d1, ChainState, MaxwellChain};
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
            Material::AgeingViscoelastic { density, .. } => *density,
        }
    }

    /// Initial (elastic) modulus [Pa], used for default penalty stiffnesses and unit checks.
    pub fn initial_modulus(&self) -> f64 {
        match self {
            Material::Elastic { e, .. } => *e,
            // The 28-day tangent modulus E_ci of MC90.
            Material::AgeingViscoelastic { chain, .. } => chain.params().eci(),
        }
    }

    /// A fresh state for one integration point.
    pub fn initial_state(&self) -> PointState {
        match self {
            Material::Elastic { .. } => PointState::Elastic,
            Material::AgeingViscoelastic { chain, .. } => PointState::Ageing {
                chain: ChainState::new(chain.n_units()),
                strain: [0.0; 3],
            },
        }
    }

    /// True if the tangent of this material is constant (the step can skip re-factorising).
    pub fn is_linear(&self) -> bool {
        matches!(self, Material::Elastic { .. })
    }
}

/// State of one integration point; committed and trial copies are kept by the caller.
#[derive(Debug, Clone, PartialEq)]
pub enum PointState {
    /// Linear elastic materials keep no state.
    Elastic,
    /// Ageing viscoelastic concrete: the chain's unit stresses and the committed total strain.
    Ageing {
        /// Hidden unit stresses σ_μ [Pa]; the point's stress is their sum.
        chain: ChainState,
        /// Total strain (εx, εy, γxy) at the end of the step that produced this state [-].
        strain: [f64; 3],
    },
}

/// The time interval of the current increment on the analysis clock [days]. A load step is
/// an instantaneous increment (`t_from == t_to`) at the current time; a time step advances
/// the clock. Concrete ages follow as time − cast_day of the material.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct TimeContext {
    /// Analysis time at the start of the increment [d].
    pub t_from: f64,
    /// Analysis time at the end of the increment [d] (≥ `t_from`).
    pub t_to: f64,
}

impl TimeContext {
    /// An instantaneous increment at time `t` [d].
    pub fn at(t: f64) -> Self {
        Self { t_from: t, t_to: t }
    }

    /// Length of the increment Δt [d].
    pub fn dt(&self) -> f64 {
        self.t_to - self.t_from
    }
}

/// Why a material update failed (the increment is then cut).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UpdateError {
    /// The local return mapping did not converge.
    #[error("material update did not converge: {0}")]
    NotConverged(String),
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
    _char_length: f64,
    time: &TimeContext,
) -> Result<Update, UpdateError> {
    match (mat, committed) {
        (Material::Elastic { e, nu, .. }, PointState::Elastic) => {
            let d = plane_stress_d(*e, *nu);
            Ok((PointState::Elastic, mul3(&d, strain), d))
        }
        (
            Material::AgeingViscoelastic {
                chain,
                nu,
                cast_day,
                shrinkage,
                ..
            },
            PointState::Ageing {
                chain: state,
                strain: eps0,
            },
        ) => {
            let (a0, a1) = (time.t_from - cast_day, time.t_to - cast_day);
            if !(a1 >= a0 && a0.is_finite() && a1.is_finite()) {
                return Err(UpdateError::NotConverged(format!(
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
                PointState::Ageing {
                    chain: st.new_state,
                    strain: *strain,
                },
                sigma,
                d,
            ))
        }
        (m, s) => Err(UpdateError::NotConverged(format!(
            "material point state {s:?} does not belong to {}",
            match m {
                Material::Elastic { .. } => "an elastic material",
                Material::AgeingViscoelastic { .. } => "an ageing viscoelastic material",
            }
        ))),
    }
}
