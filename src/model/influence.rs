//! Influence lines and traffic envelopes (`[[influence]]`): what the analysis computes at
//! the end of a step by superposition on the tangent stiffness (docs/theory-traffic.md).

use serde::Serialize;

/// One `[[influence]]` table.
#[derive(Debug, Clone, Serialize)]
pub struct Influence {
    /// Name (files `influence_<name>.csv`, `envelopes_<name>.csv`).
    pub name: String,
    /// Index of the step at whose end the tangent stiffness is taken.
    pub after_step: usize,
    /// Start of the path [m].
    pub from: [f64; 2],
    /// Unit vector along the path [-].
    pub along: [f64; 2],
    /// Nodes of the path with their distance from `from` along it [m], increasing.
    pub path: Vec<(usize, f64)>,
    /// Indices of the monitors whose influence lines are computed.
    pub monitors: Vec<usize>,
    /// Also the lines of every joint's contact stress at its top and bottom points.
    pub joints: bool,
    /// Also the lines of σx at the top and bottom Gauss points of every column of Gauss
    /// points (the extreme fibres along the girder).
    pub fibres: bool,
    /// Traffic models enveloped over the lines.
    #[serde(skip)]
    pub traffic: Vec<crate::traffic::Traffic>,
    /// Load combinations of the state at the step's end and the traffic envelopes.
    pub combinations: Vec<Combination>,
    /// Load cases given the loads of a governing traffic position.
    pub place: Vec<Placement>,
}

/// A load case that receives, once the lines are taken, the loads of the traffic position
/// that gives a monitor's extreme (`[[influence.place]]`): the governing vehicle's axles
/// and the lane load on the unfavourable stretches, as nodal forces on the path.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Placement {
    /// Index of the load case (empty in the model file).
    pub case: usize,
    /// Index of the traffic model in `Influence::traffic`.
    pub traffic: usize,
    /// Index of the monitor in `Influence::monitors`.
    pub monitor: usize,
    /// The largest (true) or the smallest value.
    pub max: bool,
}

impl Influence {
    /// Coordinates [m] of the point at distance `s` [m] along the path.
    pub fn point_at(&self, s: f64) -> [f64; 2] {
        [
            self.from[0] + s * self.along[0],
            self.from[1] + s * self.along[1],
        ]
    }
}

/// A load combination: γ_state × (the monitor at the step's end) + the traffic's
/// envelope, its vehicle part × ψ_vehicle × γ_Q and its lane part × ψ_lane × γ_Q.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Combination {
    /// Name ("characteristic", "ULS", "Service I", …).
    pub name: String,
    /// Index of the traffic model (in `Influence::traffic`).
    pub traffic: usize,
    /// Factor on the state at the step's end (permanent actions) [-].
    pub state: f64,
    /// Factor on the vehicle part (γ_Q ψ) [-].
    pub vehicle: f64,
    /// Factor on the lane part (γ_Q ψ) [-].
    pub lane: f64,
}
