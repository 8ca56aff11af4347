//! From the parsed file to a validated [`Model`]: names resolved, values checked, locations
//! found in the mesh. Every problem is an [`InputError`] naming the key.
//!
//! One module per part of the model file (docs/architecture.md, "Input: from model file to
//! Model"); [`build`] calls them in the order the parts depend on each other, so that a
//! later part can refer to an earlier one by name (regions to materials, monitors to bars).

mod anchorage;
mod bars;
mod checks;
mod controls;
mod fields;
mod influence;
mod joints;
mod loads;
mod materials;
mod mesh;
mod monitors;
mod regions;
mod stages;
mod steps;
mod supports;
mod tendons;
mod time;

pub use materials::{Key, KeyType, MaterialIn, MaterialKind, Schema};
pub(in crate::input) use mesh::integration;
pub use stages::table as stage_table;
pub use time::{DEFAULT_FIRST_SUBSTEP, SUBSTEPS_PER_DECADE};

use super::error::{Ctx, InputError};
use super::schema::File;
use super::{locate, units};
use crate::model::{Model, SolverControls, DEFAULT_START_DAY};

/// A validated model and the warnings met on the way (suspicious but legal values).
pub struct Built {
    /// The model.
    pub model: Model,
    /// Warnings, one line each.
    pub warnings: Vec<String>,
}

type R<T> = Result<T, InputError>;

/// Validate a parsed file into a model.
pub fn build(file: File, ctx: &Ctx) -> R<Built> {
    let mut warnings = Vec::new();
    let w = &mut warnings;
    let (materials, steels) = materials::build(ctx, &file.materials, w)?;
    let regions = regions::build(ctx, &file.regions, &materials, &steels, w)?;
    let joint_materials = joints::materials(ctx, &file.joint_materials, w)?;
    let mesh = file
        .mesh
        .as_ref()
        .ok_or_else(|| ctx.err("mesh", "missing: give a [mesh] table"))?;
    let mesh::Generated {
        nodes,
        mut elements,
        joints,
        groups,
    } = mesh::generate(ctx, mesh, &regions)?;
    let (regions, materials) = regions::place(
        ctx,
        &file.regions,
        mesh,
        &joints,
        &nodes,
        &mut elements,
        regions,
        materials,
        w,
    )?;
    let mut model = Model {
        title: file.title.clone().unwrap_or_default(),
        nodes,
        elements,
        regions,
        materials,
        interfaces: Vec::new(),
        joints: Vec::new(),
        tendons: Vec::new(),
        supports: Vec::new(),
        load_cases: Vec::new(),
        monitors: Vec::new(),
        steps: Vec::new(),
        controls: SolverControls::default(),
        geometry: Default::default(),
        bars: Vec::new(),
        staging: Default::default(),
        checks: Vec::new(),
        influence: Vec::new(),
    };
    units::model_size(w, ctx, locate::model_size(&model));
    if !joints.is_empty() {
        joints::add(ctx, mesh, &mut model, &joints, &joint_materials)?;
    }
    let used = mesh::used_nodes(ctx, &model, w);
    // Local zones behind anchor plates and under bearings, made elastic at the end.
    let mut zones = Vec::new();
    supports::build(ctx, &file.supports, &groups, &mut model, &used, &mut zones)?;
    // The steps tendons are stressed in are resolved once the steps are known (below).
    let external_of =
        tendons::build_external(ctx, &file.tendons, &mut model, &used, &mut zones, w)?;
    supports::hold_unused(&mut model, &used);
    supports::check_rigid_body(ctx, &model, &used)?;
    loads::build(
        ctx,
        &file.load_cases,
        &groups,
        &mut model,
        &used,
        &mut zones,
    )?;
    // Embedded bars before the monitors, which can name them.
    bars::build(
        ctx,
        &file.bars,
        &file.tendons,
        &steels,
        &mut model,
        &mut zones,
    )?;
    super::bar_layers::build(ctx, &file.bar_layers, &steels, &mut model)?;
    joints::bars_across(ctx, &model, w);
    monitors::build(ctx, &file, &mut model, &used)?;
    controls::geometry(ctx, file.analysis.as_ref(), &mut model)?;
    steps::build(ctx, &file.steps, &mut model, &used)?;
    influence::build(ctx, &file, &mut model, &used)?;
    let start = model
        .steps
        .iter()
        .find_map(|s| s.time.map(|t| t.from))
        .unwrap_or(DEFAULT_START_DAY);
    stages::build(ctx, &file.steps, &mut model)?;
    let placed = |r: usize| stages::clock_at(&model, model.staging.region(r).from);
    regions::check_ages(ctx, &model, start, placed, w)?;
    tendons::assign_steps(ctx, &file.tendons, &external_of, &mut model)?;
    loads::thermal_coefficients(ctx, &file, &mut model)?;
    stages::check_tendons(ctx, &mut model)?;
    controls::solver(ctx, file.solver.as_ref(), &mut model)?;
    checks::build(ctx, &file.checks, &mut model)?;
    // Last, once stages and thermal coefficients are known (the zones' region copies
    // inherit them).
    anchorage::apply_local_zones(&mut model, &zones, &used);
    Ok(Built { model, warnings })
}
