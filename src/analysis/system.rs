//! The discrete system: dof map, sparse pattern, displacements, material-point states
//! (committed and trial), and the assembly of internal forces and tangent.
// long: System's build, assembly, commit and stage entry share its private buffers and assembly record (elem_buf, blocks, geometry, last); its methods on public fields only are in state.rs, time.rs, bonded_time.rs and committed.rs

use crate::elements::bar::{bar_green_strain, bar_strain_row};
use crate::elements::continuum::{self, GaussOutput};
use crate::elements::interface::{InterfaceElement, InterfacePointState, Joint};
use crate::elements::tendon::{ExternalTendon, InForce, TendonLaw};
use crate::elements::{ElementResponse, Response};
use crate::fem::assembly::Assembler;
use crate::fem::dofs::{DofMap, CONSTRAINED};
use crate::materials::point::{crack_base, plastic_base, PointState, TimeContext, UpdateError};
use crate::materials::steel::SteelState;
use crate::model::{Geometry, Model};

pub use super::displacements::At;
use super::displacements::Displacements;
use super::families::{BarBlock, ContinuumBlock, Families, JointBlock, TendonBlock};
pub use super::families::{BarOutput, BarPhase};
use super::responses;
use super::scatter::{
    chunks, compute_chunk, continuum_chunk, keep_forces, max_dofs, slot, tie_transform, Outcome,
    Scatter, CHUNK,
};
use super::staged::{Staged, StateBlock};
use super::stages::StageState;
use crate::fem::numbering::{ElementNumbers, Family};
use rayon::prelude::*;

/// The state of the discretised model between and during increments.
pub struct System<'m> {
    /// The model.
    pub model: &'m Model,
    /// Equation numbering.
    pub dofs: DofMap,
    /// Pattern and scatter maps.
    pub asm: Assembler,
    /// Fill-reducing elimination order of the equations for the solver (nested dissection
    /// on large systems, `None`: the solver's AMD).
    pub ordering: Option<Vec<usize>>,
    /// Time spent computing `ordering` [s].
    pub ordering_s: f64,
    /// Offset of each element's first Gauss point in the state arrays.
    pub gp_offset: Vec<usize>,
    /// Assembler numbers of the elements, one block per family.
    pub numbers: ElementNumbers,
    /// The displacements: the Newton iterate of the increment under way, the committed
    /// ones and those before the last committed increment (their difference sets the path
    /// extrapolation of the next increment) [m].
    pub disp: Displacements,
    /// Time interval of the current increment on the analysis clock [d].
    pub time: TimeContext,
    /// The state of every element family (committed and trial).
    pub families: Families,
    /// True if every material is linear, the geometry is linear and there are no joints
    /// (tangent constant).
    pub linear: bool,
    /// Joint contact elements (geometry from the contact search, done once).
    pub interfaces: Vec<InterfaceElement>,
    /// True if the last assembled tangent was made symmetric (friction slip).
    pub symmetrised: bool,
    /// External tendons, built when stressed (None before), on the geometry they were
    /// stressed on; the initial strains in force are the state's
    /// (`families.tendons.initial_strains`).
    pub tendons: Vec<Option<ExternalTendon>>,
    /// Embedded-bar integration points sorted by host element: (bar index, point index in
    /// the bar). Element e owns `bar_gps[bar_offset[e]..bar_offset[e + 1]]`.
    pub bar_gps: Vec<(usize, usize)>,
    /// Offsets of each element's bar points in `bar_gps` and the bar state arrays.
    pub bar_offset: Vec<usize>,
    /// Imposed strains of the thermal load cases at the current factors.
    pub thermal: super::thermal::Thermal,
    /// Construction stages: active elements, their reference displacements, held equations
    /// (None: the model has no stages).
    pub stages: Option<StageState>,
    /// Out-of-balance force of the parts that started to act at the start of the current
    /// step (all dofs, zero on held equations) [N]: the load step removes (1 − level) of it
    /// from the external forces, so that the weight of newly placed segments and the
    /// prestress of tendons stressed with them come in over the step's increments, which
    /// the step can then cut (docs/theory-stages.md §2). Empty: nothing to ramp.
    pub stage_jump: Vec<f64>,
    /// The stage entered last placed elements (set by [`System::enter_stage`], taken by
    /// [`System::ramp_stage_jump`]).
    placed: bool,
    /// Element force vectors and matrices of one chunk, kept between assemblies (every
    /// element writes its own before use: a run of many small assemblies zeroed and
    /// reallocated them each time).
    elem_buf: (Vec<f64>, Vec<f64>),
    /// The second buffer of the continuum loop, which fills one chunk's buffer while the
    /// other's responses are scattered.
    elem_buf2: (Vec<f64>, Vec<f64>),
    /// The tangent blocks each continuum element forms (those the scatter adds).
    blocks: Vec<crate::elements::continuum::NodeBlocks>,
    /// What the element loop keeps between assemblies of a nonlinear run (none for a
    /// linear one, which assembles twice: not worth the memory): the Gauss-point
    /// geometry, tangent memos, bar strain rows, local materials ([`responses::Kept`]).
    kept: responses::Kept,
    /// The last assembly's element forces, for [`System::reassemble_after_latch`].
    last: LastAssembly,
}

/// What [`System::reassemble_after_latch`] needs of the last assembly: its displacements, the
/// forces of every continuum element ([`responses::ND`] entries each) and the points
/// latched since. Kept for nonlinear models without joints, external tendons or stages
/// (`kept`); `valid` while the states are the assembly's, up to the latched points.
#[derive(Default)]
struct LastAssembly {
    kept: bool,
    valid: bool,
    u: Vec<f64>,
    forces: Vec<f64>,
    latched: Vec<usize>,
    /// The force scale of the last assembly [N] ([`Assembled::force_scale`]).
    force_scale: f64,
}

/// What an assembly produced: internal forces (all dofs) and, if asked, tangent values.
pub struct Assembled {
    /// Internal force vector over all dofs [N].
    pub f_int: Vec<f64>,
    /// Lower-triangle tangent values over free equations, if requested.
    pub k_values: Option<Vec<f64>>,
    /// Euclidean norm of the per-dof sums of the absolute element contributions [N]: the
    /// force scale for convergence checks, also when the loading is self-equilibrated
    /// (prestress alone), where f_int itself tends to zero.
    pub force_scale: f64,
}

/// The solver's fill-reducing order of the equations (`None` below the nested-dissection
/// size: the solver's AMD) and the time it took [s].
fn equation_order(
    model: &Model,
    asm: &Assembler,
    elem_nodes: &[Vec<usize>],
    dofs: &DofMap,
) -> (Option<Vec<usize>>, f64) {
    let t_order = std::time::Instant::now();
    // Nested dissection on large systems: on meshes of linear elements (Q4) split
    // along node coordinates; with quadratic elements (whose mid-side nodes a line
    // through the nodes would cut off) split along element edges.
    let all_linear = model.elements.iter().all(|e| e.kind.info().order == 1);
    let ordering = if all_linear {
        (dofs.n_eq >= crate::linalg::ordering::ND_MIN_EQUATIONS).then(|| {
            crate::linalg::ordering::nested_dissection(
                &asm.node_ptr,
                &asm.node_adj,
                &model.nodes,
                &dofs.eq,
                dofs.n_eq,
            )
        })
    } else {
        (dofs.n_eq >= crate::linalg::ordering::ND_MIN_EQUATIONS_QUADRATIC).then(|| {
            crate::linalg::ordering::element_dissection(
                &asm.node_ptr,
                &asm.node_adj,
                &model.nodes,
                &elem_nodes[..model.elements.len()],
                &dofs.eq,
                dofs.n_eq,
            )
        })
    };
    let ordering_s = t_order.elapsed().as_secs_f64();
    (ordering, ordering_s)
}

/// The continuum points' initial states: each element's first point (`gp_offset`), the
/// material-point states, the Gauss outputs and, for a nonlinear model, the Gauss-geometry
/// cache.
#[allow(clippy::type_complexity)]
fn initial_points(
    model: &Model,
    linear: bool,
) -> (
    Vec<usize>,
    Staged<Vec<PointState>>,
    Staged<Vec<GaussOutput>>,
    Option<responses::GeometryCache>,
) {
    let mut gp_offset = Vec::with_capacity(model.elements.len() + 1);
    // Sized at once: grown point by point, the states were copied ~twice over.
    let mut committed = Vec::with_capacity(
        model
            .elements
            .iter()
            .map(|e| continuum::rule_points(e.kind, e.integration).len())
            .sum(),
    );
    gp_offset.push(0);
    for e in &model.elements {
        let ngp = continuum::rule_points(e.kind, e.integration).len();
        let mat = &model.materials[model.regions[e.region].material].law;
        for _ in 0..ngp {
            committed.push(mat.initial_state());
        }
        gp_offset.push(committed.len());
    }
    let n_gp = committed.len();
    (
        gp_offset,
        Staged::new(committed),
        Staged::new(vec![GaussOutput::default(); n_gp]),
        (!linear).then(|| responses::GeometryCache::new(model)),
    )
}

/// Embedded-bar points grouped by host element (stable: path order within an element) and
/// each element's offset into them (`System::bar_gps`, `System::bar_offset`).
fn bar_points(model: &Model) -> (Vec<(usize, usize)>, Vec<usize>) {
    let mut bar_gps: Vec<(usize, usize)> = model
        .bars
        .iter()
        .enumerate()
        .flat_map(|(b, bar)| (0..bar.points.len()).map(move |p| (b, p)))
        .collect();
    bar_gps.sort_by_key(|&(b, p)| model.bars[b].points[p].element);
    let mut bar_offset = vec![0; model.elements.len() + 1];
    for &(b, p) in &bar_gps {
        bar_offset[model.bars[b].points[p].element + 1] += 1;
    }
    for e in 0..model.elements.len() {
        bar_offset[e + 1] += bar_offset[e];
    }
    (bar_gps, bar_offset)
}

impl<'m> System<'m> {
    /// Build dof map, pattern and initial states.
    pub fn new(model: &'m Model) -> Self {
        // Supports activated or removed by a stage are equations, held while they act; so
        // are the pushing dofs of one-way supports, held while they touch.
        let constrained: Vec<(usize, f64)> = model
            .supports
            .iter()
            .enumerate()
            .flat_map(|(i, s)| {
                s.dofs
                    .iter()
                    .filter(move |(_, d, _)| !model.staging.support_dof_is_equation(i, *d))
                    .map(|(n, d, v)| (2 * n + d.index(), *v))
            })
            .collect();
        let dofs = DofMap::new(model.nodes.len(), &constrained);
        // The node lists in family order: the assembler's element numbers are the blocks of
        // `numbers`, which `assemble` uses to add the element matrices.
        let numbers = ElementNumbers::new([
            model.elements.len(),
            model.interfaces.len(),
            model.tendons.len(),
        ]);
        let mut elem_nodes: Vec<Vec<usize>> = Vec::with_capacity(numbers.total());
        for f in Family::ALL {
            match f {
                // A list per element: copied on all cores (0.25 million at 5e5 dofs).
                Family::Continuum => {
                    elem_nodes.par_extend(model.elements.par_iter().map(|e| e.nodes.clone()))
                }
                Family::Joint => {
                    elem_nodes.extend(model.interfaces.iter().map(|i| i.nodes.clone()))
                }
                Family::Tendon => elem_nodes.extend(model.tendons.iter().map(|t| t.tie_nodes())),
            }
        }
        assert_eq!(elem_nodes.len(), numbers.total());
        let linear = model.materials.iter().all(|m| m.law.is_linear())
            && model.interfaces.is_empty()
            && model.bars.is_empty()
            && model.geometry == Geometry::Linear
            && !model.staging.is_staged()
            && !model.staging.has_one_way();
        // The pattern and ordering, and beside them the material-point states (≈ 0.15 s
        // of fresh pages at 5e5 dofs): independent, built at once on the two sides of a
        // rayon join.
        let ((asm, ordering, ordering_s), (gp_offset, points, gauss, geometry)) = rayon::join(
            || {
                let asm = Assembler::new(model.nodes.len(), &elem_nodes, &dofs);
                let (ordering, ordering_s) = equation_order(model, &asm, &elem_nodes, &dofs);
                (asm, ordering, ordering_s)
            },
            || initial_points(model, linear),
        );
        let interfaces: Vec<InterfaceElement> = model
            .interfaces
            .iter()
            .map(|i| {
                let c: Vec<[f64; 2]> = i.nodes.iter().map(|&n| model.nodes[n]).collect();
                InterfaceElement::new(&c[..i.n_a], &c[i.n_a..], &i.params)
                    .expect("interface geometry checked at input")
            })
            .collect();
        let iface_committed: Vec<Vec<InterfacePointState>> = interfaces
            .iter()
            .zip(&model.interfaces)
            .map(|(el, i)| el.initial_states(&i.params))
            .collect();
        let (bar_gps, bar_offset) = bar_points(model);
        let n_bp = bar_gps.len();
        let n_tendons = model.tendons.len();
        let thermal = super::thermal::Thermal::new(model, &bar_gps);
        let families = Families {
            continuum: ContinuumBlock {
                points,
                gauss,
                holds: Default::default(),
            },
            joints: JointBlock {
                points: Staged::new(iface_committed),
                held: Vec::new(),
            },
            tendons: TendonBlock {
                u0: vec![Vec::new(); n_tendons],
                initial_strains: vec![Vec::new(); n_tendons],
                states: Staged::new(vec![None; n_tendons]),
                time: vec![None; n_tendons],
            },
            bars: BarBlock {
                steel: Staged::new(vec![SteelState::new(); n_bp]),
                out: Staged::new(vec![BarOutput::default(); n_bp]),
                phase: model
                    .bars
                    .iter()
                    .map(|b| match b.post_tension {
                        Some(_) => BarPhase::Inactive,
                        None => BarPhase::Bonded,
                    })
                    .collect(),
                eps_ref: vec![0.0; n_bp],
                time: vec![None; n_bp],
            },
        };
        let blocks = (0..model.elements.len())
            .into_par_iter()
            .map(|e| {
                let number = numbers.number(Family::Continuum, e);
                let n = model.elements[e].nodes.len();
                crate::elements::continuum::NodeBlocks(asm.node_blocks(number, n))
            })
            .collect::<Vec<_>>();
        Self {
            model,
            kept: responses::Kept::new(model, geometry, &blocks, &bar_gps),
            dofs,
            asm,
            ordering,
            ordering_s,
            gp_offset,
            numbers,
            disp: Displacements::zero(model.n_dofs()),
            time: TimeContext::default(),
            families,
            linear,
            interfaces,
            symmetrised: false,
            tendons: vec![None; n_tendons],
            bar_gps,
            bar_offset,
            thermal,
            stages: (model.staging.is_staged() || model.staging.has_one_way())
                .then(StageState::default),
            stage_jump: Vec::new(),
            placed: false,
            elem_buf: (Vec::new(), Vec::new()),
            elem_buf2: (Vec::new(), Vec::new()),
            last: LastAssembly {
                kept: !linear
                    && model.interfaces.is_empty()
                    && model.tendons.is_empty()
                    && !model.staging.is_staged()
                    && !model.staging.has_one_way(),
                ..Default::default()
            },
            blocks,
        }
    }

    /// Latch the cracks that formed in the last assembly (kept until `commit` or
    /// `unlatch`). Returns the number of newly latched points.
    pub fn latch_cracks(&mut self) -> usize {
        let model = self.model;
        let c = &mut self.families.continuum;
        let gp_offset = &self.gp_offset;
        // The points checked in parallel (the main thread did this alone between
        // assemblies); collected in point order, as the loop over them did. The flag says
        // whether the base is a plastic hold.
        let (latched, points) = (&c.holds.latched, &c.points);
        let new: Vec<(usize, PointState, bool)> = (0..model.elements.len())
            .into_par_iter()
            .flat_map_iter(|e| {
                let el = &model.elements[e];
                let mat = &model.materials[model.regions[el.region].material].law;
                let range = if mat.is_linear() {
                    0..0
                } else {
                    gp_offset[e]..gp_offset[e + 1]
                };
                range.filter_map(move |g| {
                    if latched.binary_search_by_key(&g, |x| x.0).is_ok() {
                        return None;
                    }
                    let (committed, trial) = (&points.committed[g], &points.trial[g]);
                    if let Some(b) = crack_base(mat, committed, trial) {
                        Some((g, b, false))
                    } else {
                        plastic_base(committed, trial).map(|b| (g, b, true))
                    }
                })
            })
            .collect();
        if new.iter().any(|x| x.2) {
            c.holds.held_plastic = true;
        }
        let new = new.into_iter().map(|(g, b, _)| (g, b));
        let n = new.len();
        if self.last.valid {
            self.last.latched.extend(new.clone().map(|x| x.0));
        }
        if n > 0 {
            c.holds.latched.extend(new);
            c.holds.latched.sort_by_key(|x| x.0);
        }
        n
    }

    /// Forget latched cracks (the increment is thrown away).
    pub fn unlatch(&mut self) {
        self.last.valid = false;
        let holds = &mut self.families.continuum.holds;
        holds.latched.clear();
        holds.frozen = false;
        self.families.joints.held.clear();
    }

    /// Release the held contact statuses; true if any were held. The drivers call it when
    /// an increment has converged with them, to check the state against the free law.
    pub fn release_contacts(&mut self) -> bool {
        let held = !self.families.joints.held.is_empty();
        if held {
            self.last.valid = false;
            self.families.joints.held.clear();
        }
        held
    }

    /// Hold the contact status (closed or open) of every joint point as the last assembly
    /// left it, for the rest of the increment (see [`crate::elements::interface::joint_law`]):
    /// the drivers call it when their iterations cycle (`newton::cycling`), as they freeze
    /// the crack branches, since a dry-joint point at decompression can open and close on
    /// alternate iterations. At most once per increment. Returns the number of points held.
    pub fn hold_contacts(&mut self) -> usize {
        let j = &mut self.families.joints;
        if !j.held.is_empty() || j.points.trial.is_empty() {
            return 0;
        }
        self.last.valid = false;
        j.held = j
            .points
            .trial
            .iter()
            .map(|pts| pts.iter().map(|s| s.closed).collect())
            .collect();
        j.held.iter().map(Vec::len).sum()
    }

    /// Hold every cracked point on the branch (loading/unloading) of the last assembly for
    /// the rest of the increment (see [`crate::materials::point::freeze_cracks`]); the Newton
    /// drivers call it when their iterations cycle (`newton::cycling`). At most once per
    /// increment. Returns the number of points held.
    pub fn freeze_cracks(&mut self) -> usize {
        let c = &mut self.families.continuum;
        if c.holds.frozen {
            return 0;
        }
        self.last.valid = false;
        c.holds.frozen = true;
        let latched = &mut c.holds.latched;
        let mut held = Vec::new();
        for g in 0..c.points.trial.len() {
            let base = match latched.binary_search_by_key(&g, |x| x.0) {
                Ok(i) => &latched[i].1,
                Err(_) => &c.points.committed[g],
            };
            if let Some(f) = crate::materials::point::freeze_cracks(base, &c.points.trial[g]) {
                held.push((g, f));
            }
        }
        let count = held.len();
        for (g, f) in held {
            match latched.binary_search_by_key(&g, |x| x.0) {
                Ok(i) => latched[i].1 = f,
                Err(i) => latched.insert(i, (g, f)),
            }
        }
        count
    }

    /// Internal forces and (optionally) tangent at displacements `u` from the committed
    /// states; trial states and Gauss outputs go to the trial side of the family blocks.
    /// Element work runs in parallel chunks, each element into its own slot of the chunk
    /// buffers; the scatter is sequential in element order (continuum elements, joints,
    /// tendons), so results are bit-identical whatever the thread count. The error names
    /// the continuum element whose material point failed.
    pub fn assemble(
        &mut self,
        u: &[f64],
        tangent: bool,
    ) -> Result<Assembled, (usize, UpdateError)> {
        self.assemble_at(At::Given(u), tangent)
    }

    /// As [`System::assemble`], at the trial displacements (`disp.trial`, the Newton
    /// iterate), read in place: no copy of the iterate per iteration.
    pub fn assemble_trial(&mut self, tangent: bool) -> Result<Assembled, (usize, UpdateError)> {
        self.assemble_at(At::Trial, tangent)
    }

    /// As [`System::assemble`], at the displacements `at`. The trial and committed
    /// displacements are read where they are, in [`System::disp`]: the assembly borrows that
    /// field for reading and the state blocks it writes (families, buffers) for writing,
    /// disjoint fields of `self`, so the borrow checker sees that the assembly cannot move
    /// the displacements it is made at (the drivers used to keep the iterate outside the
    /// system for that; now it is the system's own block, [`Displacements`]).
    // long: one pass per element family in the scatter order (continuum with its bars, joints, tendons) that keeps results thread-independent; the passes share the scatter and buffers
    pub fn assemble_at(
        &mut self,
        at: At<'_>,
        tangent: bool,
    ) -> Result<Assembled, (usize, UpdateError)> {
        let u = at.of(&self.disp);
        let model = self.model;
        self.last.valid = false;
        let keep = self.last.kept;
        let mut forces = std::mem::take(&mut self.last.forces);
        if keep {
            forces.resize(model.elements.len() * responses::ND, 0.0);
        }
        let mut sc = Scatter {
            asm: &self.asm,
            f_int: crate::fem::assembly::zeroed_values(u.len()),
            f_abs: crate::fem::assembly::zeroed_values(u.len()),
            k_values: tangent.then(|| crate::fem::assembly::zeroed_values(self.asm.pattern.nnz())),
            symmetrised: false,
        };
        let numbers = &self.numbers;
        let mut buf = std::mem::take(&mut self.elem_buf);
        let time = self.time;
        let stages = self.stages.as_ref();
        // Continuum elements with the bars they host: chunk c is computed (in parallel) while
        // chunk c − 1 is scattered (in element order, as before), each into its own buffer.
        let n_el = model.elements.len();
        let size = continuum_chunk(n_el);
        let mut other = std::mem::take(&mut self.elem_buf2);
        // The computed chunk waiting for its scatter: outcomes and first element.
        let mut pending: Option<(Vec<Outcome>, usize)> = None;
        let of = |e: usize| {
            let nodes = &model.elements[e].nodes;
            (nodes.as_slice(), numbers.number(Family::Continuum, e))
        };
        let mut start = 0;
        while start < n_el {
            let end = (start + size).min(n_el);
            let (chunk, pieces) = responses::split_chunk(
                model,
                &mut self.families,
                &self.gp_offset,
                &self.bar_gps,
                &self.bar_offset,
                &self.thermal,
                u,
                &time,
                tangent,
                (start, end),
                stages,
                &self.blocks,
                (&mut self.kept, tangent),
            );
            // `buf` takes this chunk; `other` holds the pending chunk's responses.
            std::mem::swap(&mut buf, &mut other);
            let (results, scattered) = rayon::join(
                || {
                    compute_chunk(pieces, responses::ND, &mut buf, |p, fe, ke| {
                        if stages.is_some_and(|s| !s.element_acts(p.0)) {
                            return Ok(None);
                        }
                        chunk.element(p, fe, ke).map(|()| Some(true))
                    })
                },
                || match pending.take() {
                    Some((results, first)) => {
                        if keep {
                            keep_forces(&mut forces, first, results.len(), &other.0);
                        }
                        sc.add_chunk(results, first, responses::ND, &mut other, of)
                    }
                    None => Ok(()),
                },
            );
            if let Err(e) = scattered {
                (self.elem_buf, self.elem_buf2) = (buf, other);
                return Err(e);
            }
            pending = Some((results, start));
            start = end;
        }
        if let Some((results, first)) = pending {
            if keep {
                keep_forces(&mut forces, first, results.len(), &buf.0);
            }
            if let Err(e) = sc.add_chunk(results, first, responses::ND, &mut buf, of) {
                (self.elem_buf, self.elem_buf2) = (buf, other);
                return Err(e);
            }
        }
        self.elem_buf2 = other;
        // Joint contact elements.
        let held = &self.families.joints.held;
        let joints = &mut self.families.joints.points;
        let nd = max_dofs(model.interfaces.iter().map(|i| i.nodes.len()));
        let pieces: Vec<_> = joints.trial.iter_mut().enumerate().collect();
        for (start, pieces) in chunks(pieces) {
            let results = compute_chunk(pieces, nd, &mut buf, |(i, trial), fe, ke| {
                let data = &model.interfaces[i];
                if stages.is_some_and(|s| !s.interface_active[i]) {
                    return Ok(None);
                }
                let mut ue: Vec<f64> = data
                    .nodes
                    .iter()
                    .flat_map(|&n| [u[2 * n], u[2 * n + 1]])
                    .collect();
                // Born in a later stage: closed and stress-free where it was placed.
                if let Some(r) = stages.and_then(|s| s.interface_ref[i].as_deref()) {
                    ue.iter_mut().zip(r).for_each(|(a, b)| *a -= b);
                }
                let joint = Joint {
                    element: &self.interfaces[i],
                    params: &data.params,
                    thickness: data.thickness,
                    held: held.get(i).map_or(&[], Vec::as_slice),
                };
                let into = slot(fe, ke, ue.len(), tangent);
                joint
                    .response(&ue, &joints.committed[i], trial, into)
                    .map(Some)
            });
            sc.add_chunk(results, start, nd, &mut buf, |i| {
                let nodes = &model.interfaces[i].nodes;
                (nodes, numbers.number(Family::Joint, i))
            })?;
        }
        // External tendons (corotational: their forces follow the deformed geometry). A
        // point tied to the nodes under an anchor plate moves as their weighted mean and
        // shares its force out by the same weights (f = Tᵀ f_p, K = Tᵀ K_p T).
        let tb = &mut self.families.tendons;
        let tie_nodes: Vec<Vec<usize>> = model.tendons.iter().map(|t| t.tie_nodes()).collect();
        let nd = max_dofs(tie_nodes.iter().map(|n| n.len()));
        let pieces: Vec<_> = tb.states.trial.iter_mut().enumerate().collect();
        for (start, pieces) in chunks(pieces) {
            let results = compute_chunk(pieces, nd, &mut buf, |(t, trial), fe, ke| {
                let (Some(el), Some(committed)) = (&self.tendons[t], &tb.states.committed[t])
                else {
                    return Ok(None);
                };
                let el = InForce {
                    tendon: el,
                    strains: &tb.initial_strains[t],
                };
                let data = &model.tendons[t];
                let ut: Vec<f64> = (0..data.nodes.len())
                    .zip(&tb.u0[t])
                    .flat_map(|(p, u0)| {
                        let up = data.at_point(p, |n| [u[2 * n], u[2 * n + 1]]);
                        [up[0] - u0[0], up[1] - u0[1]]
                    })
                    .collect();
                if data.untied() {
                    let into = slot(fe, ke, ut.len(), tangent);
                    return ElementResponse::response(&el, &ut, committed, trial, into).map(Some);
                }
                let np = ut.len();
                let mut fp = vec![0.0; np];
                let mut kp = vec![0.0; if tangent { np * np } else { 0 }];
                let into = Response {
                    f: &mut fp,
                    k: tangent.then_some(&mut kp[..]),
                };
                let sym = ElementResponse::response(&el, &ut, committed, trial, into)?;
                tie_transform(&data.ties, &tie_nodes[t], &fp, &kp, fe, ke, tangent);
                Ok(Some(sym))
            });
            sc.add_chunk(results, start, nd, &mut buf, |t| {
                (&tie_nodes[t][..], numbers.number(Family::Tendon, t))
            })?;
        }
        self.elem_buf = buf;
        if let (Some(st), Some(k)) = (stages, sc.k_values.as_mut()) {
            st.hold_tangent(&self.asm.pattern, k);
        }
        self.symmetrised = sc.symmetrised;
        let force_scale = sc.f_abs.iter().map(|v| v * v).sum::<f64>().sqrt();
        if keep {
            let last = &mut self.last;
            last.u.clear();
            last.u.extend_from_slice(u);
            last.latched.clear();
            last.valid = true;
        }
        self.last.forces = forces;
        self.last.force_scale = force_scale;
        Ok(Assembled {
            f_int: sc.f_int,
            k_values: sc.k_values,
            force_scale,
        })
    }

    /// The internal forces (no tangent) at `u` when the last assembly was made at `u` to the
    /// bit and since then only [`System::latch_cracks`] changed the states: the elements
    /// holding the points it latched are computed again from their new base states (their
    /// trial states with them), the others' forces are those of the last assembly, which the
    /// same displacements and states would repeat to the bit, and all are summed in element
    /// order as an assembly does. The same forces and trial states as `assemble(u, false)`.
    /// None when that does not hold (or the model keeps no element forces: joints,
    /// external tendons or stages); then assemble.
    pub fn reassemble_after_latch(
        &mut self,
        u: &[f64],
    ) -> Option<Result<Assembled, (usize, UpdateError)>> {
        let last = &self.last;
        if !(last.valid
            && last.u.len() == u.len()
            && last
                .u
                .iter()
                .zip(u)
                .all(|(a, b)| a.to_bits() == b.to_bits()))
        {
            return None;
        }
        let model = self.model;
        let gp_offset = &self.gp_offset;
        let mut elements: Vec<usize> = last
            .latched
            .iter()
            .map(|&g| gp_offset.partition_point(|&o| o <= g) - 1)
            .collect();
        elements.sort_unstable();
        elements.dedup();
        let mut forces = std::mem::take(&mut self.last.forces);
        let mut ke = vec![0.0; responses::ND * responses::ND];
        let time = self.time;
        for &e in &elements {
            let (chunk, mut pieces) = responses::split_chunk(
                model,
                &mut self.families,
                gp_offset,
                &self.bar_gps,
                &self.bar_offset,
                &self.thermal,
                u,
                &time,
                false,
                (e, e + 1),
                None,
                &self.blocks,
                (&mut self.kept, false),
            );
            let piece = pieces.pop().expect("one element");
            let fe = &mut forces[e * responses::ND..(e + 1) * responses::ND];
            if let Err(err) = chunk.element(piece, fe, &mut ke) {
                self.last.forces = forces;
                self.last.valid = false;
                return Some(Err((e, err)));
            }
        }
        // Summed by the assembly's own scatter (no tangent), every element present.
        let mut sc = Scatter {
            asm: &self.asm,
            f_int: crate::fem::assembly::zeroed_values(u.len()),
            f_abs: crate::fem::assembly::zeroed_values(u.len()),
            k_values: None,
            symmetrised: false,
        };
        let numbers = &self.numbers;
        let of = |e: usize| {
            let nodes = &model.elements[e].nodes;
            (nodes.as_slice(), numbers.number(Family::Continuum, e))
        };
        let mut buf = (forces, Vec::new());
        let all_present = vec![Ok(Some(true)); model.elements.len()];
        let summed = sc.add_chunk(all_present, 0, responses::ND, &mut buf, of);
        self.last.forces = buf.0;
        if let Err(e) = summed {
            self.last.valid = false;
            return Some(Err(e));
        }
        self.last.latched.clear();
        self.symmetrised = false;
        let force_scale = sc.f_abs.iter().map(|v| v * v).sum::<f64>().sqrt();
        self.last.force_scale = force_scale;
        Some(Ok(Assembled {
            f_int: sc.f_int,
            k_values: None,
            force_scale,
        }))
    }

    /// Recompute the committed Gauss outputs of the linear elastic points at the committed
    /// displacements, with the imposed strains of the load-case `factors` (those the state was
    /// committed at): a checkpoint leaves them out ([`ContinuumBlock`]). The same element
    /// routine as the assembly at the committed displacements, so the outputs are the ones
    /// the run had, bit for bit. Other states are left as they are (their trial copies are
    /// reset to the committed ones).
    pub fn recover_elastic_outputs(&mut self, factors: &[f64]) -> Result<(), String> {
        let model = self.model;
        let elastic = |e: usize| {
            let gs = self.gp_offset[e]..self.gp_offset[e + 1];
            self.families.continuum.points.committed[gs]
                .iter()
                .any(super::families::is_elastic)
        };
        let n_el = model.elements.len();
        let which: Vec<bool> = (0..n_el).map(elastic).collect();
        if !which.contains(&true) {
            return Ok(());
        }
        let thermal = self.thermal.at(factors);
        let mut buf = std::mem::take(&mut self.elem_buf);
        let time = self.time;
        let mut start = 0;
        while start < n_el {
            let end = (start + CHUNK).min(n_el);
            if which[start..end].contains(&true) {
                let (chunk, pieces) = responses::split_chunk(
                    model,
                    &mut self.families,
                    &self.gp_offset,
                    &self.bar_gps,
                    &self.bar_offset,
                    &thermal,
                    &self.disp.committed,
                    &time,
                    false,
                    (start, end),
                    self.stages.as_ref(),
                    &self.blocks,
                    (&mut self.kept, false),
                );
                let results = compute_chunk(pieces, responses::ND, &mut buf, |p, fe, ke| {
                    if !which[p.0] {
                        return Ok(None);
                    }
                    chunk.element(p, fe, ke).map(|()| Some(true))
                });
                if let Some((i, Err(err))) = results.into_iter().enumerate().find(|r| r.1.is_err())
                {
                    self.elem_buf = buf;
                    return Err(format!(
                        "element {}: its Gauss outputs cannot be recomputed: {err}",
                        start + i + 1
                    ));
                }
            }
            start = end;
        }
        self.elem_buf = buf;
        let c = &mut self.families.continuum;
        for ((p, out), trial) in c
            .points
            .committed
            .iter()
            .zip(c.gauss.committed.iter_mut())
            .zip(&c.gauss.trial)
        {
            if super::families::is_elastic(p) {
                *out = *trial;
            }
        }
        self.families.revert();
        Ok(())
    }

    /// Prestressing operations at the start of step `step`: external tendons assigned to it
    /// are built on the current deformed geometry with their span stresses (post-tensioning
    /// against the concrete as it stands); bonded post-tensioned tendons are locked off or
    /// grouted (their bond strain is measured from the current displacements on).
    pub fn stress_tendons(&mut self, step: usize) {
        self.last.valid = false;
        self.stage_bonded_tendons(step);
        for (t, data) in self.model.tendons.iter().enumerate() {
            if data.stressed_in_step != step || self.tendons[t].is_some() {
                continue;
            }
            let u = &self.disp.committed;
            let u0: Vec<[f64; 2]> = (0..data.nodes.len())
                .map(|p| data.at_point(p, |n| [u[2 * n], u[2 * n + 1]]))
                .collect();
            let el = self.build_tendon(t, &u0);
            let tb = &mut self.families.tendons;
            tb.states.committed[t] = Some(el.initial_state());
            tb.states.trial[t] = Some(el.initial_state());
            tb.initial_strains[t] = el.initial_strains().to_vec();
            tb.u0[t] = u0;
            self.tendons[t] = Some(el);
        }
    }

    /// Lock off and grout the bonded post-tensioned tendons whose steps start now.
    fn stage_bonded_tendons(&mut self, step: usize) {
        let model = self.model;
        for (b, bar) in model.bars.iter().enumerate() {
            let Some(pt) = &bar.post_tension else {
                continue;
            };
            let bars = &mut self.families.bars;
            if pt.stressed_in_step == step && bars.phase[b] == BarPhase::Inactive {
                bars.phase[b] = BarPhase::Locked;
            }
            if pt.grouted_in_step == Some(step) && bars.phase[b] == BarPhase::Locked {
                // The grout bonds the tendon to the concrete as it now stands: strain
                // increments from here on, starting from the locked-off stress.
                for (i, &(bb, p)) in self.bar_gps.iter().enumerate() {
                    if bb != b {
                        continue;
                    }
                    let gp = &bar.points[p];
                    let el = &model.elements[gp.element];
                    let coords = model.element_coords(el);
                    // Measured as the host measures its strains (from its reference when
                    // it was born in a later stage).
                    let mut ue: Vec<f64> = el
                        .nodes
                        .iter()
                        .flat_map(|&n| [self.disp.committed[2 * n], self.disp.committed[2 * n + 1]])
                        .collect();
                    if let Some(r) = self
                        .stages
                        .as_ref()
                        .and_then(|s| s.element_ref[gp.element].as_deref())
                    {
                        ue.iter_mut().zip(r).for_each(|(a, b)| *a -= b);
                    }
                    bars.eps_ref[i] = if model.geometry == Geometry::Nonlinear {
                        bar_green_strain(el.kind, &coords, &gp.point, &ue).0
                    } else {
                        let g = bar_strain_row(el.kind, &coords, &gp.point);
                        // Node by node, x and y paired (the arithmetic of the unstaged
                        // formula, so unstaged results stay bit-identical).
                        (0..el.nodes.len())
                            .map(|a| g[2 * a] * ue[2 * a] + g[2 * a + 1] * ue[2 * a + 1])
                            .sum()
                    };
                }
                bars.phase[b] = BarPhase::Bonded;
            }
        }
    }

    /// Tendon `t` stressed on the geometry displaced by `u0` (one entry per tendon node) [m].
    pub(crate) fn build_tendon(&self, t: usize, u0: &[[f64; 2]]) -> ExternalTendon {
        let data = &self.model.tendons[t];
        let x: Vec<[f64; 2]> = (0..data.nodes.len())
            .zip(u0)
            .map(|(p, d)| {
                let x0 = data.at_point(p, |n| self.model.nodes[n]);
                [x0[0] + d[0], x0[1] + d[1]]
            })
            .collect();
        ExternalTendon::new(
            &x,
            data.area,
            data.ep,
            data.span_stress[0],
            TendonLaw::from_steel(&data.steel),
            data.mode,
        )
        .and_then(|e| e.with_span_initial_stresses(data.span_stress.clone()))
        .expect("tendon geometry checked at input")
    }

    /// True if some continuum material integrates its cracks by IMPL-EX.
    pub fn has_implex(&self) -> bool {
        self.model.materials.iter().any(|m| {
            matches!(&m.law, crate::materials::point::Material::Concrete { params, .. } if params.implex)
        })
    }

    /// The largest IMPL-EX error of the trial states of the last assembly [-] (fraction of
    /// f_tm, [`crate::materials::concrete::implex::point_error`]) over all IMPL-EX concrete
    /// points, with the extrapolation ratio of the current increment; 0 if there are none.
    /// The points are checked in parallel (each element's crack band width as in its
    /// update).
    pub fn implex_error(&self) -> f64 {
        use crate::materials::point::Material;
        let model = self.model;
        let c = &self.families.continuum;
        let gp_offset = &self.gp_offset;
        let (ratio, dt) = (self.time.extrapolation, self.time.dt());
        (0..model.elements.len())
            .into_par_iter()
            .map(|e| {
                let el = &model.elements[e];
                let Material::Concrete { params, .. } =
                    &model.materials[model.regions[el.region].material].law
                else {
                    return 0.0;
                };
                if !params.implex {
                    return 0.0;
                }
                let h = responses::crack_band_width(model, self.kept.geometry(), e);
                (gp_offset[e]..gp_offset[e + 1])
                    .map(|g| match (&c.points.committed[g], &c.points.trial[g]) {
                        (PointState::Concrete(cs), PointState::Concrete(ts)) => {
                            crate::materials::concrete::implex::point_error(
                                params, cs, ts, h, ratio, dt,
                            )
                        }
                        _ => 0.0,
                    })
                    .fold(0.0, f64::max)
            })
            .reduce(|| 0.0, f64::max)
    }

    /// The global IMPL-EX error of the trial states of the last assembly [-]
    /// (`[solver] implex_force_tolerance`, docs/theory-concrete.md §5.2): the out-of-balance
    /// force the IMPL-EX crack stresses leave against the implicit crack laws at the same
    /// strains, r = Σ_e ∫ Bᵀ Δσ dV with Δσ of every IMPL-EX concrete point
    /// ([`crate::materials::concrete::implex::point_stress_error`]), its Euclidean norm over
    /// the free equations relative to the last assembly's force scale (the scale of the
    /// Newton test, [`Assembled::force_scale`]). 0 without IMPL-EX points or before any
    /// assembly. Small-strain B (also under `geometry = "nonlinear"`, where the measure is
    /// an estimate); elements a construction stage has not placed are skipped.
    pub fn implex_force_error(&self) -> f64 {
        let Some(r) = self.implex_residual() else {
            return 0.0;
        };
        let norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        if self.last.force_scale > 0.0 {
            norm / self.last.force_scale
        } else {
            0.0
        }
    }

    /// The out-of-balance force of [`System::implex_force_error`] over the free equations
    /// [N]; None when no point has an error.
    pub(super) fn implex_residual(&self) -> Option<Vec<f64>> {
        use crate::materials::point::Material;
        let model = self.model;
        let c = &self.families.continuum;
        let (ratio, dt) = (self.time.extrapolation, self.time.dt());
        let stages = self.stages.as_ref();
        // Each element's nodal forces, in parallel; summed into the dofs in element order.
        let forces: Vec<Option<Vec<f64>>> = (0..model.elements.len())
            .into_par_iter()
            .map(|e| {
                let el = &model.elements[e];
                let Material::Concrete { params, .. } =
                    &model.materials[model.regions[el.region].material].law
                else {
                    return None;
                };
                if !params.implex || stages.is_some_and(|s| !s.element_acts(e)) {
                    return None;
                }
                // Most points have no error (uncracked, or cracks on their envelope): the
                // element's geometry only where one has.
                let h = responses::crack_band_width(model, self.kept.geometry(), e);
                let errors: Vec<[f64; 3]> = (self.gp_offset[e]..self.gp_offset[e + 1])
                    .map(|gp| match (&c.points.committed[gp], &c.points.trial[gp]) {
                        (PointState::Concrete(cs), PointState::Concrete(ts)) => {
                            crate::materials::concrete::implex::point_stress_error(
                                params, cs, ts, h, ratio, dt,
                            )
                        }
                        _ => [0.0; 3],
                    })
                    .collect();
                if errors.iter().all(|ds| *ds == [0.0; 3]) {
                    return None;
                }
                let geo = responses::element_geometry(model, self.kept.geometry(), e);
                let thickness = model.regions[el.region].thickness;
                let n = el.nodes.len();
                let mut f = vec![0.0; 2 * n];
                let mut any = false;
                for (g, &ds) in errors.iter().enumerate() {
                    if ds == [0.0; 3] || g >= geo.n_pts {
                        continue;
                    }
                    any = true;
                    let (dn, wdet) = geo.points[g];
                    let w = wdet * thickness;
                    for a in 0..n {
                        let (ax, ay) = (dn[a][0], dn[a][1]);
                        f[2 * a] += w * (ax * ds[0] + ay * ds[2]);
                        f[2 * a + 1] += w * (ay * ds[1] + ax * ds[2]);
                    }
                }
                any.then_some(f)
            })
            .collect();
        if forces.iter().all(Option::is_none) {
            return None;
        }
        let mut r = vec![0.0; model.n_dofs()];
        for (e, f) in forces.iter().enumerate() {
            if let Some(f) = f {
                for (a, &node) in model.elements[e].nodes.iter().enumerate() {
                    r[2 * node] += f[2 * a];
                    r[2 * node + 1] += f[2 * a + 1];
                }
            }
        }
        Some(self.to_free(&r))
    }

    /// Accept the trial states of the last assembly and the trial displacements (the
    /// committed ones become the previous).
    pub fn commit(&mut self) {
        self.last.valid = false;
        self.commit_time_dependent();
        self.disp.commit();
        self.families.commit();
        if let Some(st) = self.stages.as_mut() {
            st.commit();
        }
    }

    /// Add `ratio` × the last converged increment (committed − previous) to the free dofs
    /// of the trial displacements [m]: the extrapolated start of the next increment
    /// ([`crate::model::Predictor`]).
    pub fn extrapolate(&mut self, ratio: f64) {
        // Held equations stay where they are (a one-way support touching down in this
        // increment moved in the last one).
        let held = |q: usize| self.stages.as_ref().is_some_and(|st| st.held[q]);
        let d_ = &mut self.disp;
        for (d, &q) in self.dofs.eq.iter().enumerate() {
            if q != CONSTRAINED && !held(q) {
                d_.trial[d] += ratio * (d_.committed[d] - d_.previous[d]);
            }
        }
    }

    /// Gather the free-equation part of a full dof vector (zero on the equations a
    /// construction stage holds).
    pub fn to_free(&self, full: &[f64]) -> Vec<f64> {
        let mut r = vec![0.0; self.dofs.n_eq];
        for (d, &q) in self.dofs.eq.iter().enumerate() {
            if q != CONSTRAINED {
                r[q] = full[d];
            }
        }
        if let Some(st) = &self.stages {
            st.hold_free(&mut r);
        }
        r
    }

    /// Enter the construction stage of step `step` (nothing for a model without stages):
    /// elements and joints that start to act are stress-free at the current displacements,
    /// removed supports leave their reactions to be released over the step. `f_ext` are the
    /// external forces at the end of the previous step (all dofs) [N].
    pub fn enter_stage(&mut self, step: usize, f_ext: &[f64]) -> Result<(), (usize, UpdateError)> {
        let Some(entered) = self.stages.as_ref().map(|s| s.step.is_some()) else {
            return Ok(());
        };
        let reaction = if entered && StageState::removes_support(self.model, step) {
            // The committed state at the committed displacements: internal forces only.
            let a = self.assemble_at(At::Committed, false);
            self.families.revert();
            Some(
                a?.f_int
                    .iter()
                    .zip(f_ext)
                    .map(|(i, e)| i - e)
                    .collect::<Vec<_>>(),
            )
        } else {
            None
        };
        let (model, u, eq) = (self.model, &self.disp.committed, &self.dofs.eq);
        self.stage_jump.clear();
        if let Some(st) = self.stages.as_mut() {
            let before = st.element_active.clone();
            st.enter(model, step, u, eq, reaction.as_deref());
            self.placed = entered
                && st
                    .element_active
                    .iter()
                    .enumerate()
                    .any(|(e, &a)| a && !before.get(e).copied().unwrap_or(false));
        }
        Ok(())
    }

    /// Whether the stage entered last placed elements whose out-of-balance force
    /// [`System::ramp_stage_jump`] has not yet computed.
    pub fn stage_jump_pending(&self) -> bool {
        self.placed
    }

    /// After [`System::enter_stage`] and [`System::stress_tendons`] of a step that placed
    /// elements: the out-of-balance force `f_ext` (the external forces at the step's start,
    /// all dofs [N]) plus the released reactions, less the internal forces at the committed
    /// displacements, on the free equations — the jump the new parts bring (see
    /// [`System::stage_jump`]).
    pub fn ramp_stage_jump(&mut self, f_ext: &[f64]) -> Result<(), (usize, UpdateError)> {
        self.stage_jump.clear();
        if !std::mem::take(&mut self.placed) {
            return Ok(());
        }
        self.last.valid = false;
        let a = self.assemble_at(At::Committed, false);
        self.families.revert();
        let f_int = a?.f_int;
        let st = self.stages.as_ref().expect("placing needs stages");
        let mut jump: Vec<f64> = f_ext
            .iter()
            .zip(&st.release)
            .zip(&f_int)
            .map(|((e, r), i)| e + r - i)
            .collect();
        for (d, &q) in self.dofs.eq.iter().enumerate() {
            if q == CONSTRAINED || st.held[q] {
                jump[d] = 0.0;
            }
        }
        self.stage_jump = jump;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::materials::concrete::ConcreteState;
    use crate::materials::point::Material;

    /// The displacement block inside the system, on one elastic Q4 (1 × 1 m) held in x on
    /// its left edge and in y at node 1: an assembly at `At::Trial` / `At::Committed` is the
    /// assembly at a copy of that vector (forces bit for bit; trial and committed differ, so
    /// a mix-up shows), `commit` shifts committed to previous and takes the trial, the path
    /// extrapolation adds r (committed − previous) to the free dofs of the trial only, and a
    /// restore of a snapshot sets the trial back to the committed displacements.
    #[test]
    fn displacements_are_assembled_committed_and_restored_in_place() {
        let text = r#"
[[materials]]
name = "e"
kind = "elastic"
E = 30e9
nu = 0.2

[[regions]]
name = "r"
material = "e"
thickness = 0.1

[mesh]
type = "explicit"
nodes = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
blocks = [{ region = "r", element = "Q4", elements = [[1, 2, 3, 4]] }]

[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 1.0]]
ux = 0.0

[[supports]]
name = "pin"
node = 1
uy = 0.0

[[load_cases]]
name = "pull"
line_loads = [{ line = [[1.0, 0.0], [1.0, 1.0]], q = [1e5, 0.0] }]

[[steps]]
name = "s"
kind = "load"
loads = { pull = 1.0 }
increments = 1
"#;
        let model = crate::input::parse(text, "test.toml").unwrap().model;
        let mut sys = System::new(&model);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        // Node 2 (dofs 2, 3) and node 3 (dofs 4, 5) pulled right, the top lifted.
        let u1 = vec![0.0, 0.0, 1e-4, 0.0, 1e-4, 2e-5, 0.0, 2e-5];
        sys.disp.trial.copy_from_slice(&u1);
        let f1 = sys.assemble(&u1, false).unwrap().f_int;
        assert_eq!(bits(&sys.assemble_trial(false).unwrap().f_int), bits(&f1));
        sys.commit();
        assert_eq!(sys.displacements(), &u1[..]);
        assert_eq!(sys.previous_displacements(), &[0.0; 8][..]);
        let u2: Vec<f64> = u1.iter().map(|x| 3.0 * x).collect();
        sys.disp.trial.copy_from_slice(&u2);
        let f2 = sys.assemble(&u2, false).unwrap().f_int;
        assert_ne!(
            bits(&f1),
            bits(&f2),
            "the two states must differ for the test to see"
        );
        assert_eq!(bits(&sys.assemble_trial(false).unwrap().f_int), bits(&f2));
        assert_eq!(
            bits(&sys.assemble_at(At::Committed, false).unwrap().f_int),
            bits(&f1)
        );
        sys.commit();
        assert_eq!(
            (sys.displacements(), sys.previous_displacements()),
            (&u2[..], &u1[..])
        );
        // Extrapolation by ½ of the last increment u2 − u1, on the free dofs; the held ones
        // (0, 1: node 1; 6: node 4's x) keep their trial values.
        sys.disp.trial[6] = 7.0;
        sys.extrapolate(0.5);
        let expected: Vec<f64> = (0..8)
            .map(|d| match d {
                0 | 1 => 0.0,
                6 => 7.0,
                _ => u2[d] + 0.5 * (u2[d] - u1[d]),
            })
            .collect();
        assert_eq!(sys.disp.trial, expected);
        // A snapshot restored: committed and previous as saved, the trial back on them.
        let saved = sys.snapshot();
        sys.disp.trial.fill(1.0);
        sys.disp.commit();
        sys.restore(saved).unwrap();
        assert_eq!(sys.disp.committed, u2);
        assert_eq!(sys.disp.previous, u1);
        assert_eq!(sys.disp.trial, u2);
    }

    /// The global IMPL-EX error (`System::implex_force_error`, docs/theory-concrete.md §5.2)
    /// against a hand value: one Q4 concrete element a × b = 0.2 × 0.1 m, thickness 0.15 m,
    /// the left edge held in x and its lower node in y, every point with one crack at
    /// φ = 30° that formed at 1.1 ε0 and opened to 3.1 ε0, now at 8 ε0 with the extrapolated
    /// ẽ = 5.1 ε0 (ratio 1). Each point's crack-normal stress differs by
    /// Δs = σ_env(ẽ) + ∫_ẽ^8ε0 σ_env(x)/x dx − σ_env(8 ε0) (the Hinton envelope written out,
    /// the integral by Simpson's rule, error ~1e-12 f_tm), so Δσ = Δs n ⊗ n is uniform and
    /// r_a = t Δσ ∫∇N_a dA with ∫∇N_a dA = (±b/2, ±a/2) for the rectangle (exact under the
    /// 2 × 2 rule); the measure is ‖r‖ over the five free dofs divided by the force scale
    /// (set here to 1 kN). Tolerance 1e-9 relative: round-off and Simpson's error.
    #[test]
    fn implex_force_and_energy_errors_match_the_hand_nodal_forces() {
        let (a, b, t): (f64, f64, f64) = (0.2, 0.1, 0.15);
        let text = format!(
            r#"
[[materials]]
name = "c"
kind = "concrete"
fcm = 38e6

[[regions]]
name = "r"
material = "c"
thickness = {t}

[mesh]
type = "explicit"
nodes = [[0.0, 0.0], [{a}, 0.0], [{a}, {b}], [0.0, {b}]]
blocks = [{{ region = "r", element = "Q4", elements = [[1, 2, 3, 4]] }}]

[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, {b}]]
ux = 0.0

[[supports]]
name = "pin"
node = 1
uy = 0.0

[[load_cases]]
name = "pull"
line_loads = [{{ line = [[{a}, 0.0], [{a}, {b}]], q = [1e5, 0.0] }}]

[[steps]]
name = "s"
kind = "load"
loads = {{ pull = 1.0 }}
increments = 1
"#
        );
        let model = crate::input::parse(&text, "test.toml").unwrap().model;
        let Material::Concrete { params: p, .. } = &model.materials[0].law else {
            panic!("concrete expected");
        };
        assert!(p.implex, "IMPL-EX is the default");
        let mut sys = System::new(&model);
        let h = (a * b).sqrt();
        let (e0, ft, alpha) = (p.eps0(), p.ftm, p.softening_alpha(h));
        let phi = 30f64.to_radians();
        let mut committed = ConcreteState::new();
        committed.n_cracks = 1;
        committed.crack_angle = phi;
        committed.crack_max = [3.1 * e0, 0.0];
        committed.crack_max_old = [1.1 * e0, 0.0];
        let mut trial = committed.clone();
        trial.crack_strain = [8.0 * e0, 0.0];
        trial.crack_max = [8.0 * e0, 0.0];
        let points = &mut sys.families.continuum.points;
        for g in 0..4 {
            points.committed[g] = PointState::Concrete(Box::new(committed.clone()));
            points.trial[g] = PointState::Concrete(Box::new(trial.clone()));
        }
        sys.time.extrapolation = 1.0;
        let scale = 1e3;
        sys.last.force_scale = scale;
        // Δs by hand.
        let env = |x: f64| ft * (-(x - e0) / alpha).exp();
        let (lo, hi, n) = (5.1 * e0, 8.0 * e0, 4000);
        let dx = (hi - lo) / n as f64;
        let simpson = (0..=n)
            .map(|i| {
                let x = lo + i as f64 * dx;
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * env(x) / x
            })
            .sum::<f64>()
            * dx
            / 3.0;
        let ds = env(lo) + simpson - env(hi);
        assert!(ds > 0.1 * ft, "an overshoot to measure: {ds}");
        let (c, s) = (phi.cos(), phi.sin());
        let sig = [ds * c * c, ds * s * s, ds * c * s];
        // Free dofs: node 2 (x, y), node 3 (x, y), node 4 (y).
        let force = |g: [f64; 2]| {
            [
                t * (sig[0] * g[0] + sig[2] * g[1]),
                t * (sig[2] * g[0] + sig[1] * g[1]),
            ]
        };
        let (f2, f3, f4) = (
            force([b / 2.0, -a / 2.0]),
            force([b / 2.0, a / 2.0]),
            force([-b / 2.0, a / 2.0]),
        );
        let want = [f2[0], f2[1], f3[0], f3[1], f4[1]]
            .iter()
            .map(|v| v * v)
            .sum::<f64>()
            .sqrt()
            / scale;
        let got = sys.implex_force_error();
        assert!(
            (got - want).abs() < 1e-9 * want,
            "measure {got:.12e}, want {want:.12e}"
        );
        // The energy norm with a diagonal stand-in tangent K = diag(k_q), k_q = (q + 1) ×
        // 1e9 N/m by equation: r·K⁻¹r = Σ r_q² / k_q, against u·f_int over all dofs (a
        // prescribed dof's reaction included: node 1's x, held by the support).
        let pattern = &sys.asm.pattern;
        let k = |q: usize| (q + 1) as f64 * 1e9;
        let mut values = vec![0.0; pattern.row_idx.len()];
        for j in 0..pattern.n {
            let at = pattern.col_ptr[j];
            assert_eq!(pattern.row_idx[at], j, "the diagonal first in its column");
            values[at] = k(j);
        }
        let mut solver = crate::linalg::solver::SparseCholesky::new(pattern).unwrap();
        let no_factor =
            super::super::driver::implex_energy_error(&sys, &mut solver, &[1.0; 8], &[1.0; 8]);
        assert_eq!(no_factor, 0.0, "no factor, no measure");
        solver.factorize(pattern, &values).unwrap();
        let by_dof = [(2, f2[0]), (3, f2[1]), (4, f3[0]), (5, f3[1]), (7, f4[1])];
        let correction: f64 = by_dof.iter().map(|&(d, f)| f * f / k(sys.dofs.eq[d])).sum();
        let mut u = [0.0; 8];
        let mut f_int = [0.0; 8];
        (u[0], f_int[0]) = (2e-4, -3e3);
        (u[2], f_int[2]) = (1e-4, 4e3);
        (u[7], f_int[7]) = (-5e-5, 2e3);
        let state = (2e-4_f64 * -3e3 + 1e-4 * 4e3 - 5e-5 * 2e3).abs();
        let want = (correction / state).sqrt();
        let got = super::super::driver::implex_energy_error(&sys, &mut solver, &u, &f_int);
        assert!(
            (got - want).abs() < 1e-9 * want,
            "energy measure {got:.12e}, want {want:.12e}"
        );
        // Without extrapolation (ratio 0: ẽ = ε_max) the law leaves the envelope earlier
        // and overshoots more.
        sys.time.extrapolation = 0.0;
        let larger = sys.implex_force_error();
        assert!(larger > got, "{larger} vs {got}");
        // Unchanged crack strain at ε_max with no extrapolation: both laws give σ_env(ε_max).
        let points = &mut sys.families.continuum.points;
        for g in 0..4 {
            let mut same = committed.clone();
            same.crack_strain = [3.1 * e0, 0.0];
            points.trial[g] = PointState::Concrete(Box::new(same));
        }
        assert!(sys.implex_force_error() < 1e-12, "no error on the envelope");
    }
}
