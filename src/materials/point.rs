//! The material-point dispatcher: the closed set of continuum material kinds, their state,
//! and one update function used by every continuum element.

use super::elastic::{mul3, plane_stress_d};
use serde::Serialize;

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
}

impl Material {
    /// Density [kg/m³] for self weight.
    pub fn density(&self) -> f64 {
        match self {
            Material::Elastic { density, .. } => *density,
        }
    }

    /// Initial (elastic) modulus [Pa], used for default penalty stiffnesses and unit checks.
    pub fn initial_modulus(&self) -> f64 {
        match self {
            Material::Elastic { e, .. } => *e,
        }
    }

    /// A fresh state for one integration point.
    pub fn initial_state(&self) -> PointState {
        match self {
            Material::Elastic { .. } => PointState::Elastic,
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
pub fn update(
    mat: &Material,
    committed: &PointState,
    strain: &[f64; 3],
    _char_length: f64,
) -> Result<Update, UpdateError> {
    match (mat, committed) {
        (Material::Elastic { e, nu, .. }, PointState::Elastic) => {
            let d = plane_stress_d(*e, *nu);
            Ok((PointState::Elastic, mul3(&d, strain), d))
        }
    }
}
