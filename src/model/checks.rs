//! Design checks as plain data (`[[checks]]`, docs/input.md): what is checked, on the
//! state at the end of which step, against which limit.

use serde::Serialize;

/// The code a check follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Code {
    /// Eurocodes (EN 1992-1-1, EN 1992-2).
    En,
    /// AASHTO LRFD Bridge Design Specifications (and the segmental Guide Specification).
    Aashto,
}

/// What a check checks.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "check")]
pub enum CheckKind {
    /// Every listed joint keeps at least `min_compression` at its extreme fibre, read on
    /// the uncracked joint section from the joint's resultants.
    JointDecompression {
        /// Joints (indices into `Model::joints`).
        joints: Vec<usize>,
        /// Required compression [Pa] (0: decompression).
        min_compression: f64,
    },
    /// The largest compression of the listed regions' concrete against `factor` × its
    /// characteristic strength.
    ConcreteStress {
        /// Regions (indices into `Model::regions`) and the characteristic strength
        /// f_ck (or f'c) of each [Pa].
        regions: Vec<(usize, f64)>,
        /// Limit as a fraction of the strength (0.6, 0.45 …).
        factor: f64,
        /// Elements left out: those of the disturbed regions (within one member depth of an
        /// anchorage, deviator, active support or point load), unless asked for.
        excluded: Vec<usize>,
    },
    /// The largest span stress of the listed external tendons against `factor` × f_pk.
    TendonStress {
        /// Tendons (indices into `Model::tendons`).
        tendons: Vec<usize>,
        /// Limit as a fraction of f_pk (0.75 EN; 0.72 AASHTO: 0.80 f_py, f_py = 0.9 f_pu).
        factor: f64,
    },
    /// The stress of an external tendon at the step's peak load beside the code's
    /// estimate of the stress of unbonded tendons at ultimate.
    UnbondedUltimate {
        /// Tendon (index into `Model::tendons`).
        tendon: usize,
        /// Abscissa of the critical section [m].
        x: f64,
        /// AASHTO N_s: support hinges the tendon crosses between its anchorages.
        support_hinges: usize,
        /// Characteristic strength f_ck (EN) or f'c (AASHTO) at the section [Pa].
        fc: f64,
        /// Index of the step at whose end the tendon stress is the effective prestress
        /// f_pe (before the loads the check's step adds).
        fpe_step: usize,
    },
    /// The shear force of each listed joint against the keyed-joint shear strength.
    ShearKeys {
        /// Joints (indices into `Model::joints`).
        joints: Vec<usize>,
        /// Base area of the keys in the failure plane of each joint, A_k [m²].
        key_area: f64,
        /// Compressive strength f'c of the joint's concrete [Pa].
        fc: f64,
        /// Resistance factor φ.
        phi: f64,
    },
}

/// One design check.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DesignCheck {
    /// User name (unique).
    pub name: String,
    /// Index of the step at whose end (for `UnbondedUltimate`: at whose peak load) the
    /// check reads the state.
    pub step: usize,
    /// The code.
    pub code: Code,
    /// The clause the limit comes from, as printed.
    pub clause: String,
    /// What is checked.
    pub kind: CheckKind,
}
