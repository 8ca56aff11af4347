//! The material-point dispatcher: the closed set of continuum material kinds, their state,
//! and one update function used by every continuum element.

use super::concrete::{self, ConcreteParams, ConcreteState};
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
    /// Plane-stress concrete (MC90/Ottosen plasticity in compression, fixed smeared cracking
    /// in tension; docs/theory-concrete.md).
    Concrete {
        /// Material parameters (strengths and moduli in Pa).
        params: Box<ConcreteParams>,
        /// Density [kg/m³].
        density: f64,
    },
}

impl Material {
    /// Density [kg/m³] for self weight.
    pub fn density(&self) -> f64 {
        match self {
            Material::Elastic { density, .. } => *density,
            Material::Concrete { density, .. } => *density,
        }
    }

    /// Initial (elastic) modulus [Pa], used for default penalty stiffnesses and unit checks.
    pub fn initial_modulus(&self) -> f64 {
        match self {
            Material::Elastic { e, .. } => *e,
            Material::Concrete { params, .. } => params.ec,
        }
    }

    /// A fresh state for one integration point.
    pub fn initial_state(&self) -> PointState {
        match self {
            Material::Elastic { .. } => PointState::Elastic,
            Material::Concrete { .. } => PointState::Concrete(Box::default()),
        }
    }

    /// True if the tangent of this material is constant (the step can skip re-factorising).
    pub fn is_linear(&self) -> bool {
        // Concrete is never linear.
        matches!(self, Material::Elastic { .. })
    }
}

/// State of one integration point; committed and trial copies are kept by the caller.
#[derive(Debug, Clone, PartialEq)]
pub enum PointState {
    /// Linear elastic materials keep no state.
    Elastic,
    /// Concrete point (boxed: keeps the enum small for elastic models).
    Concrete(Box<ConcreteState>),
}

impl PointState {
    /// The concrete state, if this is a concrete point.
    pub fn concrete(&self) -> Option<&ConcreteState> {
        match self {
            PointState::Concrete(c) => Some(c),
            PointState::Elastic => None,
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
    char_length: f64,
) -> Result<Update, UpdateError> {
    match (mat, committed) {
        (Material::Elastic { e, nu, .. }, PointState::Elastic) => {
            let d = plane_stress_d(*e, *nu);
            Ok((PointState::Elastic, mul3(&d, strain), d))
        }
        (Material::Concrete { params, .. }, PointState::Concrete(c)) => {
            let (st, sig, mut d) = concrete::update(params, c, strain, char_length)
                .map_err(|e| UpdateError::NotConverged(e.to_string()))?;
            // The cracked tangent is unsymmetric (shear retention falls as the crack opens);
            // the symmetric solvers take its symmetric part (same converged answer, possibly
            // more iterations).
            for i in 0..3 {
                for j in 0..i {
                    let m = 0.5 * (d[i][j] + d[j][i]);
                    d[i][j] = m;
                    d[j][i] = m;
                }
            }
            Ok((PointState::Concrete(Box::new(st)), sig, d))
        }
        // States are created by `Material::initial_state`, so a mismatch is a programming
        // error; report it as a failed update rather than panicking.
        _ => Err(UpdateError::NotConverged(
            "material and point state do not match".into(),
        )),
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
        (Material::Concrete { params, .. }, PointState::Concrete(c), PointState::Concrete(t))
            if c.n_cracks == 0 && t.n_cracks > 0 && !c.crushed && !t.crushed =>
        {
            let mut b = (**c).clone();
            let ebar_n = c.ebar.max(concrete::compression::initial_yield(params).0);
            b.n_cracks = 1;
            b.crack_angle = t.crack_angle;
            b.crack_max = [0.0; 2];
            b.dir_ebar = [ebar_n; 2];
            b.dir_plastic = [0.0; 2];
            Some(PointState::Concrete(Box::new(b)))
        }
        _ => None,
    }
}
