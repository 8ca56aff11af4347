//! Plain data describing elements: kinds, integration rules and the parameters the element
//! routines of [`crate::elements`] read. Defined here so that data flows from the model to
//! the elements (the elements import these types; the model imports nothing from them).
//! Units SI (m, Pa, Pa/m).

use serde::{Deserialize, Serialize};

/// The continuum element kinds. Each kind's properties (nodes, edges, reference domain,
/// shape functions, quadrature, extrapolation, VTK and Gmsh ids, name) are one descriptor in
/// `crate::fem::kinds` (`ElementKind::info`); a new kind is a variant here, its descriptor
/// file there and its line in `crate::fem::kinds::ALL`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum ElementKind {
    /// 4-node bilinear quadrilateral.
    Q4,
    /// 8-node serendipity quadrilateral.
    Q8,
    /// 9-node Lagrange quadrilateral.
    Q9,
    /// 6-node quadratic triangle.
    T6,
}

/// Integration rule of a continuum element.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Integration {
    /// 2×2 Gauss for Q4, 3×3 for Q8 and Q9.
    #[default]
    Full,
    /// 2×2 Gauss for Q8 and Q9 (Q4 stays 2×2).
    Reduced,
    /// Q4 only: 2×2 Gauss with Wilson–Taylor incompatible bending modes (QM6), condensed
    /// in the element ([`crate::elements::incompatible`]).
    Incompatible,
}

/// Constitutive and integration parameters of a joint.
#[derive(Debug, Clone, PartialEq)]
pub struct InterfaceParams {
    /// Normal penalty stiffness K_n \[Pa/m\] (normal stress per unit penetration), > 0.
    pub kn: f64,
    /// Tangential (shear) penalty stiffness K_t \[Pa/m\], ≥ 0.
    pub kt: f64,
    /// Coulomb friction coefficient μ \[-\], ≥ 0.
    pub friction: f64,
    /// Cohesion c \[Pa\]: shear strength at zero normal stress, ≥ 0. For a joint with
    /// `tensile_strength > 0` (epoxy) it is lost together with the bond; otherwise (dry keyed
    /// joint, key shear term) it is kept while the point is closed.
    pub cohesion: f64,
    /// Tensile strength f_t \[Pa\] of a bonded (epoxy) joint, ≥ 0; 0 = dry joint. While the bond
    /// is intact the normal law is linear in tension too; when the tensile stress exceeds f_t
    /// the point debonds for good and behaves as a dry joint (no tension, no cohesion).
    pub tensile_strength: f64,
    /// Shear-keyed joint: a closed (or bonded) point never slips (no Coulomb limit).
    pub keyed: bool,
    /// `true`: Gauss–Lobatto (nodal) integration; `false`: Gauss–Legendre. Both use as many
    /// points as face A has nodes.
    pub lobatto: bool,
    /// Residual stiffness ratio r \[-\] of an open point (tractions r·K·(λ, g_t − s_p)), 0 ≤ r < 1;
    /// e.g. 1e-6 keeps the global matrix non-singular when a joint is fully open.
    pub residual_ratio: f64,
}

/// How the tendon interacts with the deviators.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DeviatorMode {
    /// No slip at deviators: each span deforms independently (dummy-mesh behaviour).
    Held,
    /// Free sliding: one strain and one force for the whole tendon.
    Frictionless,
    /// Stick/slip with capstan friction coefficient `mu` \[-\] over each deviator's angle.
    Friction {
        /// Friction coefficient μ between tendon and deviator saddle \[-\].
        mu: f64,
    },
}

/// One integration point of a bar piece.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BarPoint {
    /// Natural coordinate ξ in the host element [-].
    pub xi: f64,
    /// Natural coordinate η in the host element [-].
    pub eta: f64,
    /// Unit bar direction (cos φ, sin φ) [-].
    pub dir: [f64; 2],
    /// Integration weight |dx/dr|·w [m]: the sum over a piece is its length.
    pub weight_length: f64,
    /// Arc length from the path start [m].
    pub s: f64,
    /// Global position [m].
    pub x: [f64; 2],
}
