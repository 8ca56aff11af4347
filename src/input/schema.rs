//! The model-file schema (TOML), as read by serde. Every table rejects unknown keys so that a
//! misspelt key is an error, not a silent default. Documented key by key in docs/input.md.

#![allow(missing_docs)]

use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct File {
    pub title: Option<String>,
    #[serde(default)]
    pub materials: Vec<MaterialIn>,
    #[serde(default)]
    pub regions: Vec<RegionIn>,
    #[serde(default)]
    pub joint_materials: Vec<JointMaterialIn>,
    pub mesh: Option<MeshIn>,
    #[serde(default)]
    pub tendons: Vec<TendonIn>,
    #[serde(default)]
    pub supports: Vec<SupportIn>,
    #[serde(default)]
    pub load_cases: Vec<LoadCaseIn>,
    #[serde(default)]
    pub monitors: Vec<MonitorIn>,
    #[serde(default)]
    pub steps: Vec<StepIn>,
    pub solver: Option<SolverIn>,
    #[serde(default)]
    pub bars: Vec<BarIn>,
    #[serde(default)]
    pub bar_layers: Vec<BarLayerIn>,
    pub analysis: Option<AnalysisIn>,
    /// Design checks read from the results.
    #[serde(default)]
    pub checks: Vec<CheckIn>,
    /// Influence lines, traffic envelopes and combinations.
    #[serde(default)]
    pub influence: Vec<InfluenceIn>,
    /// Generator of a span-by-span segmental viaduct (expanded before validation).
    pub viaduct: Option<super::generators::viaduct::ViaductIn>,
}

/// One `[[checks]]` table (docs/input.md, "[[checks]]").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckIn {
    pub name: String,
    pub check: String,
    pub step: String,
    pub code: Option<String>,
    pub combination: Option<String>,
    pub joints: Option<Vec<String>>,
    pub regions: Option<Vec<String>>,
    pub include_d_regions: Option<bool>,
    pub tendons: Option<Vec<String>>,
    pub tendon: Option<String>,
    pub min_compression: Option<f64>,
    pub fck: Option<f64>,
    pub x: Option<f64>,
    pub support_hinges: Option<usize>,
    pub fpe_step: Option<String>,
    pub key_area: Option<f64>,
    pub phi: Option<f64>,
}

// The material table lives with its kinds and builders (one file per material law's input).
pub use super::build::MaterialIn;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegionIn {
    pub name: String,
    pub material: String,
    pub thickness: f64,
    pub cast_day: Option<f64>,
    pub boxes: Option<Vec<[[f64; 2]; 2]>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshIn {
    #[serde(rename = "type")]
    pub kind: String,
    // banded
    pub length: Option<f64>,
    pub origin: Option<[f64; 2]>,
    pub nx: Option<usize>,
    pub element: Option<String>,
    pub integration: Option<String>,
    #[serde(default)]
    pub bands: Vec<BandIn>,
    // segmental
    pub segments: Option<Vec<f64>>,
    pub n_segments: Option<usize>,
    pub nx_per_segment: Option<usize>,
    pub joint_material: Option<String>,
    #[serde(default)]
    pub cast_joints: Vec<String>,
    #[serde(default)]
    pub soffit: Vec<[f64; 2]>,
    pub soffit_band: Option<String>,
    #[serde(default)]
    pub camber: Vec<[f64; 2]>,
    // gmsh
    pub file: Option<String>,
    #[serde(default)]
    pub joints: Vec<GmshJointIn>,
    pub segment_cast_days: Option<Vec<f64>>,
    // explicit
    #[serde(default)]
    pub nodes: Vec<[f64; 2]>,
    #[serde(default)]
    pub blocks: Vec<BlockIn>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointMaterialIn {
    pub name: String,
    pub kind: String,
    pub friction: Option<f64>,
    pub cohesion: Option<f64>,
    pub tensile_strength: Option<f64>,
    pub kn: Option<f64>,
    pub kt: Option<f64>,
    pub penalty_factor: Option<f64>,
    pub residual_stiffness_ratio: Option<f64>,
    pub integration: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GmshJointIn {
    pub a: String,
    pub b: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TendonIn {
    pub name: String,
    pub kind: String,
    #[serde(default)]
    pub points: Vec<[f64; 2]>,
    pub parabola: Option<ParabolaIn>,
    pub arc: Option<ArcIn>,
    pub segments: Option<Vec<PathPartIn>>,
    pub area: f64,
    #[serde(rename = "Ep")]
    pub ep: f64,
    pub fptk: f64,
    pub eps_uk: Option<f64>,
    pub initial_stress: Option<f64>,
    pub jacking_stress: Option<f64>,
    pub jacking_force: Option<f64>,
    pub anchorage_set: Option<f64>,
    pub grouted_in_step: Option<String>,
    pub gauss_points: Option<usize>,
    pub jacking: Option<String>,
    pub friction: Option<f64>,
    pub wobble: Option<f64>,
    pub deviators: Option<String>,
    pub deviator_friction: Option<f64>,
    pub stressed_in_step: Option<String>,
    pub relaxation_class: Option<i64>,
    pub thermal_expansion: Option<f64>,
    pub anchor_plate: Option<f64>,
    pub local_zone: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BandIn {
    pub region: String,
    pub depth: f64,
    pub rows: usize,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockIn {
    pub region: String,
    pub element: String,
    pub integration: Option<String>,
    pub elements: Vec<Vec<i64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupportIn {
    pub name: String,
    pub node: Option<i64>,
    pub point: Option<[f64; 2]>,
    pub line: Option<Vec<[f64; 2]>>,
    pub group: Option<String>,
    pub ux: Option<f64>,
    pub uy: Option<f64>,
    pub bearing: Option<f64>,
    pub local_zone: Option<bool>,
    pub one_way: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadCaseIn {
    pub name: String,
    pub gravity: Option<[f64; 2]>,
    #[serde(default)]
    pub point_loads: Vec<PointLoadIn>,
    #[serde(default)]
    pub line_loads: Vec<LineLoadIn>,
    pub temperature: Option<TemperatureIn>,
}

/// `[load_cases.temperature]`: a thermal action (docs/input.md, "Thermal actions").
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemperatureIn {
    pub uniform: Option<f64>,
    pub linear: Option<f64>,
    pub top: Option<f64>,
    pub bottom: Option<f64>,
    pub profile: Option<Vec<[f64; 2]>>,
    pub code_profile: Option<String>,
    pub zone: Option<i64>,
    pub negative_factor: Option<f64>,
    pub tendons: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointLoadIn {
    pub node: Option<i64>,
    pub point: Option<[f64; 2]>,
    pub force: [f64; 2],
    pub bearing: Option<f64>,
    pub local_zone: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LineLoadIn {
    pub line: Option<[[f64; 2]; 2]>,
    pub group: Option<String>,
    pub q: [f64; 2],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonitorIn {
    pub name: String,
    pub kind: String,
    pub node: Option<i64>,
    pub point: Option<[f64; 2]>,
    pub component: Option<String>,
    pub support: Option<String>,
    pub case: Option<String>,
    pub joint: Option<String>,
    pub tendon: Option<String>,
    pub span: Option<i64>,
    pub since_step: Option<String>,
    pub bar: Option<String>,
    pub region: Option<String>,
    pub extreme: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepIn {
    pub name: String,
    pub kind: String,
    #[serde(default)]
    pub loads: BTreeMap<String, f64>,
    pub increments: Option<usize>,
    pub output: Option<String>,
    pub control: Option<ControlIn>,
    pub initial_increment: Option<f64>,
    pub desired_iterations: Option<usize>,
    pub max_growth: Option<f64>,
    pub target_factor: Option<f64>,
    pub stop_displacement: Option<ControlIn>,
    // time steps
    pub from: Option<f64>,
    pub to: Option<f64>,
    pub duration: Option<f64>,
    pub substeps: Option<usize>,
    pub first_substep: Option<f64>,
    pub substep_tolerance: Option<f64>,
    // construction stages
    #[serde(default)]
    pub activate: Vec<String>,
    #[serde(default)]
    pub remove: Vec<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlIn {
    pub node: Option<i64>,
    pub point: Option<[f64; 2]>,
    pub line: Option<[[f64; 2]; 2]>,
    pub component: Option<String>,
    pub value: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarIn {
    pub name: String,
    pub path: Option<Vec<[f64; 2]>>,
    pub parabola: Option<ParabolaIn>,
    pub arc: Option<ArcIn>,
    pub segments: Option<Vec<PathPartIn>>,
    pub area: f64,
    pub material: String,
    pub initial_stress: Option<f64>,
    pub gauss_points: Option<usize>,
}

/// A smeared layer of parallel bars (`[[bar_layers]]`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BarLayerIn {
    pub name: String,
    pub material: String,
    pub region: String,
    pub boxes: Option<Vec<[[f64; 2]; 2]>>,
    pub direction: [f64; 2],
    pub ratio: f64,
}

/// One part of a composite path: exactly one of a polyline, a parabola or an arc.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathPartIn {
    pub points: Option<Vec<[f64; 2]>>,
    pub parabola: Option<ParabolaIn>,
    pub arc: Option<ArcIn>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParabolaIn {
    pub start: [f64; 2],
    pub end: [f64; 2],
    pub sag: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArcIn {
    pub center: [f64; 2],
    pub radius: f64,
    pub theta_start: f64,
    pub theta_end: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverIn {
    pub force_tolerance: Option<f64>,
    pub absolute_force_tolerance: Option<f64>,
    pub energy_tolerance: Option<f64>,
    pub max_iterations: Option<usize>,
    pub max_cuts: Option<usize>,
    pub predictor: Option<String>,
    pub implex_tolerance: Option<f64>,
    pub implex_force_tolerance: Option<f64>,
    pub implex_force_norm: Option<String>,
    pub increment_tolerance: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnalysisIn {
    pub geometry: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InfluenceIn {
    pub name: String,
    pub after_step: Option<String>,
    pub line: Option<[[f64; 2]; 2]>,
    pub monitors: Option<Vec<String>>,
    pub joints: Option<bool>,
    pub fibres: Option<bool>,
    #[serde(default)]
    pub traffic: Vec<TrafficIn>,
    #[serde(default)]
    pub combinations: Vec<CombinationIn>,
    #[serde(default)]
    pub place: Vec<PlaceIn>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaceIn {
    pub case: String,
    pub traffic: Option<String>,
    pub monitor: String,
    pub extreme: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrafficIn {
    pub name: String,
    pub model: String,
    pub carriageway_width: Option<f64>,
    #[serde(rename = "alpha_Q")]
    pub alpha_big_q: Option<[f64; 3]>,
    pub alpha_q: Option<[f64; 3]>,
    pub impact: Option<f64>,
    pub loads: Option<Vec<f64>>,
    pub spacings: Option<Vec<f64>>,
    pub lane_load: Option<f64>,
    pub lanes: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CombinationIn {
    pub name: String,
    pub kind: String,
    pub traffic: Option<String>,
    pub state: Option<f64>,
    pub vehicle: Option<f64>,
    pub lane: Option<f64>,
}
