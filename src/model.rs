//! The validated model as plain data: what input produces and the analysis consumes, so that
//! the analysis never depends on how a model was read. Units SI (m, N, Pa, kg).

pub mod checks;
pub mod element_data;
pub mod influence;
pub mod stages;
pub mod thermal;

use crate::materials::mc90_time::RelaxationClass;
use crate::materials::point::Material;
pub use element_data::{BarPoint, DeviatorMode, ElementKind, Integration, InterfaceParams};
pub use influence::{Combination, Influence, Placement};
use serde::Serialize;
pub use stages::{Lifetime, Push, Staging};
pub use thermal::ThermalAction;

/// A continuum element.
#[derive(Debug, Clone, Serialize)]
pub struct Element {
    /// Element kind.
    pub kind: ElementKind,
    /// Node indices (0-based), VTK order.
    pub nodes: Vec<usize>,
    /// Region index.
    pub region: usize,
    /// Integration rule.
    pub integration: Integration,
}

/// A region: a set of elements sharing a material and a thickness.
#[derive(Debug, Clone, Serialize)]
pub struct Region {
    /// User name.
    pub name: String,
    /// Material index.
    pub material: usize,
    /// Out-of-plane thickness [m].
    pub thickness: f64,
}

/// A named material.
#[derive(Debug, Clone, Serialize)]
pub struct NamedMaterial {
    /// User name.
    pub name: String,
    /// The law and its parameters.
    pub law: Material,
    /// A concrete strength the law itself does not model (elastic and elastic_creep
    /// materials): every run checks the stresses of the material's regions and the contact
    /// stresses of the joints beside them against it (`results::strength`). None for laws
    /// that crack and crush, and for elastic materials given no strength.
    pub strength: Option<Strength>,
}

/// Strength of a concrete modelled as elastic, to check its stresses against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Strength {
    /// Mean compressive strength f_cm [Pa] (positive).
    pub fcm: f64,
    /// Mean tensile strength f_tm [Pa] (positive).
    pub ftm: f64,
}

/// Direction of a degree of freedom.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Dir {
    /// Horizontal (x).
    X,
    /// Vertical (y).
    Y,
}

impl Dir {
    /// 0 for x, 1 for y.
    pub fn index(self) -> usize {
        match self {
            Dir::X => 0,
            Dir::Y => 1,
        }
    }
}

/// A named support: a set of constrained dofs with prescribed values.
#[derive(Debug, Clone, Serialize)]
pub struct Support {
    /// User name (used by reaction monitors).
    pub name: String,
    /// Constrained (node, direction, prescribed displacement [m]).
    pub dofs: Vec<(usize, Dir, f64)>,
}

/// A uniform line load on one element edge.
#[derive(Debug, Clone, Serialize)]
pub struct EdgeLoad {
    /// Node indices of the edge (start, end, [mid]).
    pub nodes: Vec<usize>,
    /// Force per unit length of edge [N/m].
    pub q: [f64; 2],
    /// Loaded part of the edge in its natural coordinate, r ∈ [−1, 1].
    pub range: [f64; 2],
}

/// A named load case; steps scale load cases by factors.
#[derive(Debug, Clone, Serialize, Default)]
pub struct LoadCase {
    /// User name.
    pub name: String,
    /// Nodal point forces: (node, [Fx, Fy] [N]).
    pub point_forces: Vec<(usize, [f64; 2])>,
    /// Edge loads.
    pub edge_loads: Vec<EdgeLoad>,
    /// Gravity acceleration [m/s²] applied to all regions' density, if any.
    pub gravity: Option<[f64; 2]>,
    /// Temperature field of a thermal load case: imposed strains, no forces (None: none).
    pub thermal: Option<ThermalAction>,
}

/// What a monitor records.
#[derive(Debug, Clone, Serialize)]
pub enum MonitorKind {
    /// Displacement component of a node [m], or its change since the end of a step.
    Displacement {
        /// Node index.
        node: usize,
        /// Component.
        dir: Dir,
        /// Measure from the end of this step (e.g. "deflection due to Q" after prestress);
        /// None = from the start.
        since_step: Option<usize>,
    },
    /// Sum of the reactions of a support in one direction [N].
    Reaction {
        /// Support index.
        support: usize,
        /// Component.
        dir: Dir,
    },
    /// Current factor of a load case [-].
    LoadFactor {
        /// Load case index.
        case: usize,
    },
    /// Largest opening of a joint over its depth, or of all joints (None) [m].
    JointOpening {
        /// Joint index, or None for the largest over all joints.
        joint: Option<usize>,
    },
    /// Depth of a joint still in contact (closed) [m].
    JointContactDepth {
        /// Joint index.
        joint: usize,
    },
    /// Stress of one span of an external tendon, or the largest span stress [Pa].
    TendonStress {
        /// Tendon index.
        tendon: usize,
        /// Span index (0-based, from the first point), or None for the largest.
        span: Option<usize>,
    },
    /// Force of one span of an external tendon, or the largest span force [N].
    TendonForce {
        /// Tendon index.
        tendon: usize,
        /// Span index (0-based, from the first point), or None for the largest.
        span: Option<usize>,
    },
    /// Largest slip (relative tangential displacement) of a joint, or of all joints [m].
    JointSlip {
        /// Joint index, or None for the largest over all joints.
        joint: Option<usize>,
    },
    /// Stress of an embedded bar [Pa]: at the integration point nearest a point, or the
    /// value of largest magnitude along the bar.
    BarStress {
        /// Bar index.
        bar: usize,
        /// Index into the bar's points, or None for the extreme value.
        point: Option<usize>,
    },
    /// Largest crack-opening strain over the concrete points of a region (all if None) [-].
    MaxCrackStrain {
        /// Region index.
        region: Option<usize>,
    },
    /// Largest equivalent plastic strain over the concrete points of a region [-].
    MaxPlasticStrain {
        /// Region index.
        region: Option<usize>,
    },
    /// Number of crushed concrete integration points in a region [-].
    CrushedPoints {
        /// Region index.
        region: Option<usize>,
    },
    /// Force of a bonded tendon or bar [N]: area × stress at the integration point nearest a
    /// point, or of largest magnitude along it.
    BarForce {
        /// Bar index.
        bar: usize,
        /// Index into the bar's points, or None for the extreme value.
        point: Option<usize>,
    },
    /// Prestress loss of a bonded tendon since it was stressed (pre-tensioned: since its
    /// initial stress) [Pa] (positive = loss), total or one part of the split: at the
    /// integration point nearest a point, or the length-weighted mean along the tendon.
    BarLoss {
        /// Bar index.
        bar: usize,
        /// Index into the bar's points, or None for the mean.
        point: Option<usize>,
        /// Which part.
        part: LossPart,
    },
    /// A stress component at the continuum integration (Gauss) point nearest a point [Pa]
    /// (the point's own stress, not a recovered nodal value).
    StressAtPoint {
        /// Which component.
        component: StressComponent,
        /// Index of the Gauss point (element order, then the element's rule order).
        gauss_point: usize,
    },
    /// The extreme of a stress component over the Gauss points of a region (all if None)
    /// [Pa].
    StressExtreme {
        /// Which component.
        component: StressComponent,
        /// Region index.
        region: Option<usize>,
        /// Largest, smallest, or the value of largest magnitude (with its sign).
        extreme: Extreme,
    },
    /// Largest contact (normal, compression positive) stress over the integration points of
    /// a joint, or of all joints (None) [Pa].
    JointContactStress {
        /// Joint index, or None for the largest over all joints.
        joint: Option<usize>,
    },
    /// Prestress loss of a tendon since stressing, length-weighted mean over its spans
    /// [Pa] (positive = loss), total or one part of the split (docs/theory-time.md).
    TendonLoss {
        /// Tendon index.
        tendon: usize,
        /// Which part.
        part: LossPart,
    },
}

/// Part of a tendon's prestress loss (the parts add up to the total).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum LossPart {
    /// Everything since stressing.
    Total,
    /// Instantaneous (load-step) changes: elastic shortening by later tendons, loads.
    Elastic,
    /// Changes during time steps from the concrete deformation (creep and shrinkage).
    CreepShrinkage,
    /// Relaxation of the steel (stress drop of the chain at the current strain).
    Relaxation,
}

/// A plane stress component or principal stress (monitors).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum StressComponent {
    /// σx [Pa].
    Sx,
    /// σy [Pa].
    Sy,
    /// τxy [Pa].
    Txy,
    /// Major principal stress σ1 [Pa].
    S1,
    /// Minor principal stress σ2 [Pa].
    S2,
}

impl StressComponent {
    /// The component of a stress (σx, σy, τxy) [Pa].
    pub fn of(self, s: [f64; 3]) -> f64 {
        let c = 0.5 * (s[0] + s[1]);
        let r = (0.5 * (s[0] - s[1])).hypot(s[2]);
        match self {
            StressComponent::Sx => s[0],
            StressComponent::Sy => s[1],
            StressComponent::Txy => s[2],
            StressComponent::S1 => c + r,
            StressComponent::S2 => c - r,
        }
    }
}

/// Which extreme of a quantity over a set of points (monitors).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Extreme {
    /// The largest value.
    Max,
    /// The smallest (most compressive) value.
    Min,
    /// The value of largest magnitude, with its sign.
    Abs,
}

/// A named monitor: one column of `history.csv`.
#[derive(Debug, Clone, Serialize)]
pub struct Monitor {
    /// User name.
    pub name: String,
    /// What it records.
    pub kind: MonitorKind,
}

impl Monitor {
    /// Unit of the recorded quantity.
    pub fn unit(&self) -> &'static str {
        match self.kind {
            MonitorKind::Displacement { .. } => "m",
            MonitorKind::Reaction { .. } => "N",
            MonitorKind::LoadFactor { .. } => "-",
            MonitorKind::JointOpening { .. }
            | MonitorKind::JointContactDepth { .. }
            | MonitorKind::JointSlip { .. } => "m",
            MonitorKind::TendonStress { .. } => "Pa",
            MonitorKind::TendonForce { .. } => "N",
            MonitorKind::BarStress { .. } => "Pa",
            MonitorKind::MaxCrackStrain { .. }
            | MonitorKind::MaxPlasticStrain { .. }
            | MonitorKind::CrushedPoints { .. } => "-",
            MonitorKind::TendonLoss { .. } | MonitorKind::BarLoss { .. } => "Pa",
            MonitorKind::BarForce { .. } => "N",
            MonitorKind::StressAtPoint { .. }
            | MonitorKind::StressExtreme { .. }
            | MonitorKind::JointContactStress { .. } => "Pa",
        }
    }
}

/// The kind of an analysis step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum StepKind {
    /// One linear solve with the initial stiffness (the material must be linear).
    Linear,
    /// Incremental load control with Newton–Raphson.
    Load,
    /// Displacement control of one dof (see [`PathControl::Displacement`]).
    Displacement,
    /// Arc-length path following (see [`ArcLengthControl`]).
    ArcLength,
    /// Time step: loads held, the analysis clock advanced in log-spaced substeps (creep,
    /// shrinkage, relaxation); Newton–Raphson per substep. Times in [`Step::time`].
    Time,
}

/// Analysis time [d] at which the analysis starts when no time step says otherwise (the
/// `from` of the first time step overrides it): loading at 28 days on the analysis clock.
pub const DEFAULT_START_DAY: f64 = 28.0;

/// The time interval of a time step on the analysis clock [days], split into `substeps`
/// substeps whose durations since `from` grow geometrically from `first` to `to − from`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TimeSpan {
    /// Start [d].
    pub from: f64,
    /// End [d] (> `from`).
    pub to: f64,
    /// Duration of the first substep [d] (0 < first ≤ to − from).
    pub first: f64,
    /// Number of substeps (≥ 1); with `tolerance`, the first pair of substeps lasts as long
    /// as the first of these.
    pub substeps: usize,
    /// Error-controlled substeps (`substep_tolerance`): each pair of substeps agrees with
    /// one substep over the same time to within this fraction of the displacement change
    /// over the pair (step doubling, max norm) [-]; None: the fixed log-spaced substeps.
    pub tolerance: Option<f64>,
}

impl TimeSpan {
    /// Analysis time [d] at the fraction `level` ∈ [0, 1] of the step: substep k ends at
    /// level k/n; within the first substep time is linear in level, later substeps are
    /// geometric (log-spaced durations since `from`). Continuous and increasing, so halving
    /// a level interval (a cut) halves it in log time.
    pub fn time_at(&self, level: f64) -> f64 {
        if level >= 1.0 {
            return self.to;
        }
        let n = self.substeps.max(1);
        let d = self.to - self.from;
        let x = level.max(0.0) * n as f64;
        if n == 1 {
            return self.from + d * level.max(0.0);
        }
        if x <= 1.0 {
            return self.from + self.first * x;
        }
        self.from + self.first * (d / self.first).powf((x - 1.0) / (n as f64 - 1.0))
    }
}

/// An analysis step: load factors are the totals reached at the end of the step, reached
/// linearly from those at the end of the previous step.
#[derive(Debug, Clone, Serialize)]
pub struct Step {
    /// User name.
    pub name: String,
    /// Kind.
    pub kind: StepKind,
    /// Target factor per load case (index = load case).
    pub factors: Vec<f64>,
    /// Number of equal increments.
    pub increments: usize,
    /// Which increments write field output (.vtu).
    pub field_output: FieldOutput,
    /// Path-following control (displacement and arc-length steps).
    pub path: Option<PathControl>,
    /// Time interval of a [`StepKind::Time`] step (None for load steps, which act
    /// instantaneously at the current time).
    pub time: Option<TimeSpan>,
}

/// Which increments of a step write field files (`steps.output`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum FieldOutput {
    /// The step's last increment only (`"end"`).
    #[default]
    End,
    /// Every converged increment (`"increments"`).
    Increments,
    /// None (`"none"`): the history, the summary and the checkpoint only, for runs whose
    /// answers are their monitors (parameter sweeps, benchmarks).
    None,
}

/// Kinematics of the concrete continuum and the embedded bars (`[analysis] geometry`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum Geometry {
    /// Small displacements: linear strain ε = sym ∇u on the undeformed geometry.
    #[default]
    Linear,
    /// Total Lagrangian: Green–Lagrange strain and second Piola–Kirchhoff stress on the
    /// undeformed geometry (small strain, large rotation; docs/theory.md, "Geometric
    /// nonlinearity").
    Nonlinear,
}

/// Newton and step-cutting controls.
#[derive(Debug, Clone, Serialize)]
pub struct SolverControls {
    /// Relative force-residual tolerance.
    pub force_tolerance: f64,
    /// Absolute force-residual tolerance [N] (`[solver] absolute_force_tolerance`): the
    /// Euclidean norm of the residual over the free equations that converges an
    /// iteration, in place of `force_tolerance`; None (the default): the relative test.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub absolute_force_tolerance: Option<f64>,
    /// Relative energy tolerance.
    pub energy_tolerance: f64,
    /// Maximum Newton iterations per increment.
    pub max_iterations: usize,
    /// Maximum number of times an increment may be halved.
    pub max_cuts: usize,
    /// Start of the Newton iterations of an increment of a displacement-controlled or
    /// instantaneous load step.
    pub predictor: Predictor,
    /// IMPL-EX error control (`[solver] implex_tolerance`, a fraction of f_tm): an increment
    /// whose largest IMPL-EX crack-stress error exceeds it is retried at half the size, at
    /// most `max_cuts` times (docs/theory-concrete.md §5.2). None (the default): off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub implex_tolerance: Option<f64>,
    /// Global IMPL-EX error control (`[solver] implex_force_tolerance`, a fraction of the
    /// Newton test's force scale): an increment whose out-of-balance force of the IMPL-EX
    /// crack stresses against the implicit laws exceeds it is retried at half the size, as
    /// with `implex_tolerance` (docs/theory-concrete.md §5.2). None (the default): off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub implex_force_tolerance: Option<f64>,
    /// The norm `implex_force_tolerance` bounds (`[solver] implex_force_norm`): the
    /// out-of-balance force against the force scale (the default) or the energy of its
    /// correction against the energy of the state (docs/theory-concrete.md §5.2).
    #[serde(skip_serializing_if = "ImplexForceNorm::is_force")]
    pub implex_force_norm: ImplexForceNorm,
    /// Error-controlled increments of load steps (without `time`), displacement steps and
    /// arc-length steps on nonlinear materials (`[solver] increment_tolerance`,
    /// docs/theory.md): each pair of increments (of arcs) is solved whole and as its halves
    /// and kept if they agree within this fraction of the displacement change over the
    /// pair [-]. None (the default): off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub increment_tolerance: Option<f64>,
    /// Print every Newton iteration's residual and energy norms to standard error
    /// (set by `segfem run --verbose`, not by the model file).
    pub verbose: bool,
}

impl Default for SolverControls {
    fn default() -> Self {
        Self {
            force_tolerance: 1e-6,
            absolute_force_tolerance: None,
            energy_tolerance: 1e-12,
            max_iterations: 25,
            max_cuts: 6,
            predictor: Predictor::LastConverged,
            implex_tolerance: None,
            implex_force_tolerance: None,
            implex_force_norm: ImplexForceNorm::Force,
            increment_tolerance: None,
            verbose: false,
        }
    }
}

/// The norm of the global IMPL-EX error (`[solver] implex_force_norm`, docs/theory-concrete.md
/// §5.2 "Global error control"), both dimensionless [-].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum ImplexForceNorm {
    /// ‖r‖₂ over the free equations / the Newton test's force scale (the default).
    Force,
    /// √|r·K⁻¹r| / √|u·f_int|: the energy of the correction the out-of-balance force r
    /// calls for with the last factorised tangent K, against the work of the current
    /// internal forces on the current displacements (all dofs).
    Energy,
}

impl SolverControls {
    /// The relative force tolerance [-] of an iteration whose free residual has the norm
    /// `rnorm` [N] and the relative size `rel` [-] (`rnorm` over the force scale):
    /// `force_tolerance`, or with `absolute_force_tolerance` that bound over the
    /// iteration's force scale, so that `rel <= tolerance` is the absolute test.
    pub fn relative_force_tolerance(&self, rel: f64, rnorm: f64) -> f64 {
        match self.absolute_force_tolerance {
            Some(a) if rnorm > 0.0 && rel > 0.0 => a * rel / rnorm,
            // A zero residual converges under either test.
            Some(_) => f64::INFINITY,
            None => self.force_tolerance,
        }
    }
}

impl ImplexForceNorm {
    /// True for the default norm (then left out of the serialised controls).
    pub fn is_force(&self) -> bool {
        *self == Self::Force
    }
}

/// Where the Newton iterations of an increment start (`[solver] predictor`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Predictor {
    /// From the last converged displacements (the tangent predictor alone); the default.
    LastConverged,
    /// From the last converged displacements plus the last increment of the same step,
    /// scaled to the length of this one (linear extrapolation of the path); an increment
    /// retried after a failed attempt starts from the last converged state.
    Extrapolated,
}

/// A named joint material (contact law parameters).
#[derive(Debug, Clone, Serialize)]
pub struct JointMaterial {
    /// User name.
    pub name: String,
    /// Contact-law parameters (penalties in Pa/m).
    #[serde(skip)]
    pub params: InterfaceParams,
}

/// One joint contact element between two facing element edges.
#[derive(Debug, Clone, Serialize)]
pub struct InterfaceEl {
    /// Face A nodes (counter-clockwise edge order of its element: start, end, [mid]), then
    /// face B nodes.
    pub nodes: Vec<usize>,
    /// Number of face-A nodes.
    pub n_a: usize,
    /// Thickness of the joint (that of the band it lies in) [m].
    pub thickness: f64,
    /// Contact-law parameters (with the penalty stiffness resolved).
    #[serde(skip)]
    pub params: InterfaceParams,
    /// Joint index.
    pub joint: usize,
}

/// A joint between two segments: a set of interface elements.
#[derive(Debug, Clone, Serialize)]
pub struct Joint {
    /// Name (e.g. "J3").
    pub name: String,
    /// Abscissa [m] (of face A's first node).
    pub x: f64,
    /// Interface elements of this joint (indices into `Model::interfaces`).
    pub interfaces: Vec<usize>,
}

/// An external (unbonded) tendon tied to the concrete at its anchors and deviators.
#[derive(Debug, Clone, Serialize)]
pub struct TendonEl {
    /// User name.
    pub name: String,
    /// Concrete nodes the tendon is tied to (anchor, deviators…, anchor).
    pub nodes: Vec<usize>,
    /// Per tendon point, the nodes it is tied to and their weights (summing to 1): the nodes
    /// under an anchor plate, or the point's own node with weight 1. The point moves as the
    /// weighted mean of its nodes and its force is shared out by the same weights.
    pub ties: Vec<Vec<(usize, f64)>>,
    /// Steel area A_p [m²].
    pub area: f64,
    /// Modulus E_p [Pa].
    pub ep: f64,
    /// Characteristic tensile strength f_ptk [Pa] (yield at 0.9 f_ptk).
    pub fptk: f64,
    /// Uniaxial law of the steel: yield 0.9 f_ptk, perfectly plastic, or hardening to f_ptk
    /// at ε_uk (`[[tendons]] eps_uk`).
    pub steel: crate::materials::steel::SteelParams,
    /// Stress of each span as stressed, on the geometry at the start of its stressing step
    /// (friction and set losses included, its own elastic shortening not: the tendon loses
    /// that during the step) [Pa].
    pub span_stress: Vec<f64>,
    /// Deviator behaviour.
    #[serde(skip)]
    pub mode: DeviatorMode,
    /// Index of the step at whose start the tendon is stressed.
    pub stressed_in_step: usize,
    /// Relaxation class of the steel (None = no relaxation).
    pub relaxation: Option<RelaxationClass>,
}

impl TendonEl {
    /// The distinct nodes of the tendon's ties, in the order of first appearance: the
    /// assembler's node list of the tendon element.
    pub fn tie_nodes(&self) -> Vec<usize> {
        let mut out: Vec<usize> = Vec::new();
        for tie in &self.ties {
            for &(n, _) in tie {
                if !out.contains(&n) {
                    out.push(n);
                }
            }
        }
        out
    }

    /// True if every point is tied to its own node alone (no anchor plate).
    pub fn untied(&self) -> bool {
        self.ties.iter().all(|t| t.len() == 1)
    }

    /// Position of point `p` as the weighted mean of `x(node)` over its ties.
    pub fn at_point(&self, p: usize, x: impl Fn(usize) -> [f64; 2]) -> [f64; 2] {
        match self.ties[p].as_slice() {
            [(n, _)] => x(*n),
            tie => tie.iter().fold([0.0, 0.0], |a, &(n, w)| {
                let v = x(n);
                [a[0] + w * v[0], a[1] + w * v[1]]
            }),
        }
    }
}

/// The complete validated model.
#[derive(Debug, Clone, Serialize)]
pub struct Model {
    /// Title.
    pub title: String,
    /// Node coordinates [m].
    pub nodes: Vec<[f64; 2]>,
    /// Continuum elements.
    pub elements: Vec<Element>,
    /// Regions.
    pub regions: Vec<Region>,
    /// Materials.
    pub materials: Vec<NamedMaterial>,
    /// Joint contact elements.
    pub interfaces: Vec<InterfaceEl>,
    /// Joints (groups of interface elements).
    pub joints: Vec<Joint>,
    /// External tendons.
    pub tendons: Vec<TendonEl>,
    /// Supports.
    pub supports: Vec<Support>,
    /// Load cases.
    pub load_cases: Vec<LoadCase>,
    /// Monitors.
    pub monitors: Vec<Monitor>,
    /// Steps, in order.
    pub steps: Vec<Step>,
    /// Solver controls.
    pub controls: SolverControls,
    /// Kinematics of the continuum and the embedded bars.
    pub geometry: Geometry,
    /// Embedded bars and bonded tendons.
    pub bars: Vec<Bar>,
    /// Construction stages (empty: everything acts from the start).
    pub staging: Staging,
    /// Design checks read from the results (`[[checks]]`; empty: none).
    pub checks: Vec<checks::DesignCheck>,
    /// Influence lines and traffic envelopes (`[[influence]]`).
    pub influence: Vec<Influence>,
}

impl Model {
    /// Node coordinates of an element, in its node order.
    pub fn element_coords(&self, e: &Element) -> Vec<[f64; 2]> {
        e.nodes.iter().map(|&n| self.nodes[n]).collect()
    }

    /// Number of degrees of freedom (2 per node).
    pub fn n_dofs(&self) -> usize {
        2 * self.nodes.len()
    }
}

/// One integration point of an embedded bar in its host element (perfect bond).
#[derive(Debug, Clone, Serialize)]
pub struct BarGaussPoint {
    /// Host element index.
    pub element: usize,
    /// Position in the host (natural coordinates), direction, weight [m], arc length [m].
    pub point: BarPoint,
}

/// An embedded bar or bonded tendon, cut through the mesh at input.
#[derive(Debug, Clone, Serialize)]
pub struct Bar {
    /// User name.
    pub name: String,
    /// Cross-section area A_b [m²].
    pub area: f64,
    /// Uniaxial steel law (moduli and stresses in Pa).
    pub steel: crate::materials::steel::SteelParams,
    /// Initial (prestressing) stress σ_b,0 [Pa], present from the first increment on.
    pub initial_stress: f64,
    /// Integration points along the bar, in path order.
    pub points: Vec<BarGaussPoint>,
    /// Number of pieces (host elements crossed).
    pub n_pieces: usize,
    /// Global end points of each piece (entry, exit) [m], for output.
    pub piece_ends: Vec<[[f64; 2]; 2]>,
    /// Range of `points` belonging to each piece.
    pub piece_points: Vec<(usize, usize)>,
    /// Post-tensioning data of a bonded post-tensioned tendon (None: a bar or pre-tensioned
    /// tendon, bonded from the start with `initial_stress`).
    pub post_tension: Option<PostTension>,
    /// Relaxation of a tendon's steel during time steps: MC90 class and f_ptk [Pa] (None =
    /// no relaxation).
    pub relaxation: Option<(RelaxationClass, f64)>,
    /// A smeared layer (`[[bar_layers]]`): the points are the Gauss points of the host
    /// elements, `area` is the steel area per unit width ρ·t [m²/m] and each point's
    /// `weight_length` its share of the element's area w·det J [m²]; one piece per element.
    pub layer: bool,
}

/// Post-tensioning of a bonded tendon (docs/theory-prestress.md): not present before
/// `stressed_in_step`; from then on it loads the concrete with its lock-off stresses (the
/// equivalent forces) and no stiffness; from `grouted_in_step` on it is bonded and takes the
/// concrete's strain increments.
#[derive(Debug, Clone, Serialize)]
pub struct PostTension {
    /// Index of the step at whose start the tendon is stressed and locked off.
    pub stressed_in_step: usize,
    /// Index of the step at whose start the duct is grouted (None = never: the tendon keeps
    /// its lock-off stresses).
    pub grouted_in_step: Option<usize>,
    /// Stress at each integration point after friction and anchorage set [Pa] (order of
    /// [`Bar::points`]).
    pub point_stress: Vec<f64>,
    /// Stress at the jack σ_pi [Pa].
    pub jacking_stress: f64,
    /// Length affected by the anchorage set at the start and the end of the path [m].
    pub set_length: [f64; 2],
}

impl Bar {
    /// Initial strain ε_b,0 = σ_b,0/E_s [-] added to the bond strain (the bar carries σ_b,0
    /// at zero displacement).
    pub fn prestrain(&self) -> f64 {
        self.initial_stress / self.steel.es
    }

    /// Stress [Pa] the bar carries at point `p` when it becomes bonded: the lock-off stress
    /// of a post-tensioned tendon, else `initial_stress`.
    pub fn bonding_stress(&self, p: usize) -> f64 {
        match &self.post_tension {
            Some(pt) => pt.point_stress[p],
            None => self.initial_stress,
        }
    }
}

/// How a path-following step is controlled.
#[derive(Debug, Clone, Serialize)]
pub enum PathControl {
    /// Displacement control: one dof (or the same component of all nodes on a line, moved
    /// together) is driven linearly from its value at the start of the step to `value`; the
    /// reaction of the control is the load.
    Displacement {
        /// Controlled nodes (one for a point; all nodes on a line).
        nodes: Vec<usize>,
        /// Component.
        dir: Dir,
        /// Total displacement of the dof at the end of the step [m].
        value: f64,
    },
    /// Crisfield's cylindrical arc-length method with the step's load cases as reference
    /// load f_ref = Σ_c loads_c f_c (added to the loads held from earlier steps).
    ArcLength(ArcLengthControl),
}

/// Arc-length controls and stop criteria (first one reached ends the step).
#[derive(Debug, Clone, Serialize)]
pub struct ArcLengthControl {
    /// Load-factor increment of the first increment Δλ₀ [-] (sets the arc length).
    pub initial_increment: f64,
    /// Desired Newton iterations per increment (step-size adaptation) [-].
    pub desired_iterations: usize,
    /// Maximum arc length as a multiple of the first one [-].
    pub max_growth: f64,
    /// Stop when λ reaches this value [-].
    pub target_factor: Option<f64>,
    /// Stop when this dof's displacement reaches the value [m] (node, direction, value).
    pub target_displacement: Option<(usize, Dir, f64)>,
    /// Maximum number of increments.
    pub max_increments: usize,
    /// Reference load factors per load case (the step's `loads`) [-].
    pub reference: Vec<f64>,
}

/// Length scale of the model (bounding-box diagonal) [m], for relative tolerances.
pub fn model_size(model: &Model) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &model.nodes {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2))
        .sqrt()
        .max(f64::MIN_POSITIVE)
}

#[cfg(test)]
mod tests {
    use super::SolverControls;

    /// With `absolute_force_tolerance` the relative test `rel <= tolerance` is the absolute
    /// one ‖r‖ ≤ a: at a force scale S (rel = ‖r‖ / S), residuals just under and just over
    /// a converge and do not; without it the relative bound is `force_tolerance` itself.
    #[test]
    fn absolute_force_tolerance_is_the_residual_norm_in_newtons() {
        let mut c = SolverControls::default();
        let scale = 4.0e6; // N, the RC example's order of force scale
        for rnorm in [9.99, 10.01] {
            let rel = rnorm / scale;
            assert_eq!(
                rel <= c.relative_force_tolerance(rel, rnorm),
                rel <= c.force_tolerance
            );
        }
        c.absolute_force_tolerance = Some(10.0);
        for (rnorm, converged) in [(9.99, true), (10.01, false), (400.0, false)] {
            let rel = rnorm / scale;
            assert_eq!(
                rel <= c.relative_force_tolerance(rel, rnorm),
                converged,
                "{rnorm} N"
            );
        }
        // A zero residual converges under either test.
        assert!(0.0 <= c.relative_force_tolerance(0.0, 0.0));
    }
}
