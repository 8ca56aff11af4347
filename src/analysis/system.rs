//! The discrete system: dof map, sparse pattern, displacements, material-point states
//! (committed and trial), and the assembly of internal forces and tangent.

use crate::elements::bar::{bar_green_strain, bar_strain_row};
use crate::elements::continuum::{self, GaussOutput};
use crate::elements::interface::{InterfaceElement, InterfacePointState};
use crate::elements::tendon::{ExternalTendon, TendonLaw};
use crate::elements::total_lagrangian;
use crate::fem::assembly::Assembler;
use crate::fem::dofs::{DofMap, CONSTRAINED};
use crate::materials::point::{crack_base, plastic_base, PointState, TimeContext, UpdateError};
use crate::materials::steel::{update_uniaxial, SteelState};
use crate::model::{Geometry, Model};

use super::families::{BarBlock, ContinuumBlock, Families, JointBlock, TendonBlock};
pub use super::families::{BarOutput, BarPhase};
use super::staged::Staged;
use crate::fem::numbering::{ElementNumbers, Family};
use rayon::prelude::*;

/// Elements per parallel chunk: large enough to amortise scheduling, small enough to keep the
/// element-matrix buffer a few tens of MB.
const CHUNK: usize = 4096;

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
    /// Committed displacements (all dofs) [m].
    pub u: Vec<f64>,
    /// Displacements before the last committed increment [m] (its size sets the history
    /// extrapolation of the next increment).
    pub u_prev: Vec<f64>,
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
    /// External tendons, built when stressed (None before).
    pub tendons: Vec<Option<ExternalTendon>>,
    /// Embedded-bar integration points sorted by host element: (bar index, point index in
    /// the bar). Element e owns `bar_gps[bar_offset[e]..bar_offset[e + 1]]`.
    pub bar_gps: Vec<(usize, usize)>,
    /// Offsets of each element's bar points in `bar_gps` and the bar state arrays.
    pub bar_offset: Vec<usize>,
    /// Element force vectors and matrices of one chunk, kept between assemblies (every
    /// element writes its own before use: a run of many small assemblies zeroed and
    /// reallocated them each time).
    elem_buf: (Vec<f64>, Vec<f64>),
}

/// One embedded-bar point of a host element under the total Lagrangian kinematics.
struct TlBar<'a> {
    kind: crate::fem::shape::QuadKind,
    coords: &'a [[f64; 2]],
    bar: &'a crate::model::Bar,
    /// Point index in the bar.
    p: usize,
    phase: BarPhase,
    committed: &'a SteelState,
    /// Green strain along the bar when it was bonded [-].
    eps_ref: f64,
    /// Relaxation strain of a tendon's steel (stress-free) [-].
    relax: f64,
}

/// Add one bar point's force to `fe` [N] and, if given, its tangent to `ke` [N/m] with the
/// total Lagrangian kinematics (see [`bar_green_strain`]): E_b = Green strain along the bar,
/// σ_b from the steel law at E_b − ε_ref + σ_b,0/E_s, f += g σ A w,
/// K += g E_t A w gᵀ + σ A w (d dᵀ ⊗ I₂). A locked-off, ungrouted tendon keeps its stress;
/// its equivalent forces turn with the concrete (f += g σ_lock A w with the geometric term
/// in K). The trial state and output go to `st` and `out`.
fn tl_bar_point(
    b: TlBar,
    ue: &[f64],
    fe: &mut [f64],
    ke: Option<&mut [f64]>,
    st: &mut SteelState,
    out: &mut BarOutput,
) {
    let nd = ue.len();
    let bp = &b.bar.points[b.p].point;
    if b.phase == BarPhase::Inactive {
        *st = *b.committed;
        *out = BarOutput::default();
        return;
    }
    let (e_b, g, d) = bar_green_strain(b.kind, b.coords, bp, ue);
    let (sig, et) = if b.phase == BarPhase::Locked {
        let sig = b.bar.bonding_stress(b.p) - b.bar.steel.es * b.relax;
        *st = *b.committed;
        *out = BarOutput {
            strain: sig / b.bar.steel.es,
            stress: sig,
            plastic_strain: 0.0,
        };
        (sig, 0.0)
    } else {
        let eps = e_b - b.eps_ref + b.bar.bonding_stress(b.p) / b.bar.steel.es - b.relax;
        let (s_new, sig, et) = update_uniaxial(&b.bar.steel, b.committed, eps);
        *st = s_new;
        *out = BarOutput {
            strain: eps,
            stress: sig,
            plastic_strain: s_new.plastic_strain,
        };
        (sig, et)
    };
    let aw = b.bar.area * bp.weight_length;
    let (fs, ks) = (sig * aw, et * aw);
    for r in 0..nd {
        fe[r] += g[r] * fs;
    }
    let Some(ke) = ke else {
        return;
    };
    for r in 0..nd {
        let gr = g[r] * ks;
        let dr = d[r / 2] * fs;
        for c in 0..nd {
            let mut v = gr * g[c];
            if r % 2 == c % 2 {
                v += dr * d[c / 2];
            }
            ke[r * nd + c] += v;
        }
    }
}

/// Replace a square row-major matrix of order n by its symmetric part.
fn symmetrise(k: &mut [f64], n: usize) {
    for i in 0..n {
        for j in 0..i {
            let m = 0.5 * (k[i * n + j] + k[j * n + i]);
            k[i * n + j] = m;
            k[j * n + i] = m;
        }
    }
}

/// Success of one element's update (its force and tangent are in the chunk buffers), or the
/// failing element and why.
type ElementResult = Result<(), (usize, UpdateError)>;

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

impl<'m> System<'m> {
    /// Build dof map, pattern and initial states.
    pub fn new(model: &'m Model) -> Self {
        let constrained: Vec<(usize, f64)> = model
            .supports
            .iter()
            .flat_map(|s| s.dofs.iter().map(|(n, d, v)| (2 * n + d.index(), *v)))
            .collect();
        let dofs = DofMap::new(model.nodes.len(), &constrained);
        // The node lists in family order: the assembler's element numbers are the blocks of
        // `numbers`, which `assemble` uses to add the element matrices.
        let numbers = ElementNumbers::new([
            model.elements.len(),
            model.interfaces.len(),
            model.tendons.len(),
        ]);
        let elem_nodes: Vec<Vec<usize>> = Family::ALL
            .iter()
            .flat_map(|f| -> Box<dyn Iterator<Item = Vec<usize>>> {
                match f {
                    Family::Continuum => Box::new(model.elements.iter().map(|e| e.nodes.clone())),
                    Family::Joint => Box::new(model.interfaces.iter().map(|i| i.nodes.clone())),
                    Family::Tendon => Box::new(model.tendons.iter().map(|t| t.nodes.clone())),
                }
            })
            .collect();
        assert_eq!(elem_nodes.len(), numbers.total());
        let asm = Assembler::new(model.nodes.len(), &elem_nodes, &dofs);
        let t_order = std::time::Instant::now();
        // Nested dissection only on meshes of 4-node elements: with the mid-side nodes of
        // Q8/Q9 its median lines cut through elements and the separators double (at 1e6
        // Q8 dofs the factor grew 55 % over AMD's).
        let all_q4 = model
            .elements
            .iter()
            .all(|e| e.kind == crate::fem::shape::QuadKind::Q4);
        let ordering = (all_q4 && dofs.n_eq >= super::ordering::ND_MIN_EQUATIONS).then(|| {
            super::ordering::nested_dissection(
                &asm.node_ptr,
                &asm.node_adj,
                &model.nodes,
                &dofs.eq,
                dofs.n_eq,
            )
        });
        let ordering_s = t_order.elapsed().as_secs_f64();
        let mut gp_offset = Vec::with_capacity(model.elements.len() + 1);
        let mut committed = Vec::new();
        gp_offset.push(0);
        for e in &model.elements {
            let ngp = continuum::rule(e.kind, e.integration).len();
            let mat = &model.materials[model.regions[e.region].material].law;
            for _ in 0..ngp {
                committed.push(mat.initial_state());
            }
            gp_offset.push(committed.len());
        }
        let linear = model.materials.iter().all(|m| m.law.is_linear())
            && model.interfaces.is_empty()
            && model.bars.is_empty()
            && model.geometry == Geometry::Linear;
        let n_gp = committed.len();
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
        // Bar points grouped by host element (stable: path order within an element).
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
        let n_bp = bar_gps.len();
        let n_tendons = model.tendons.len();
        let families = Families {
            continuum: ContinuumBlock {
                points: Staged::new(committed),
                gauss: Staged::new(vec![GaussOutput::default(); n_gp]),
                holds: Default::default(),
            },
            joints: JointBlock {
                points: Staged::new(iface_committed),
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
        Self {
            model,
            dofs,
            asm,
            ordering,
            ordering_s,
            gp_offset,
            numbers,
            u: vec![0.0; model.n_dofs()],
            u_prev: vec![0.0; model.n_dofs()],
            time: TimeContext::default(),
            families,
            linear,
            interfaces,
            symmetrised: false,
            tendons: vec![None; n_tendons],
            bar_gps,
            bar_offset,
            elem_buf: (Vec::new(), Vec::new()),
        }
    }

    /// Latch the cracks that formed in the last assembly (kept until `commit` or
    /// `unlatch`). Returns the number of newly latched points.
    pub fn latch_cracks(&mut self) -> usize {
        let model = self.model;
        let c = &mut self.families.continuum;
        let mut new = Vec::new();
        for (e, el) in model.elements.iter().enumerate() {
            let mat = &model.materials[model.regions[el.region].material].law;
            if mat.is_linear() {
                continue;
            }
            for g in self.gp_offset[e]..self.gp_offset[e + 1] {
                if c.holds.latched.binary_search_by_key(&g, |x| x.0).is_ok() {
                    continue;
                }
                let (committed, trial) = (&c.points.committed[g], &c.points.trial[g]);
                if let Some(b) = crack_base(mat, committed, trial) {
                    new.push((g, b));
                } else if let Some(b) = plastic_base(committed, trial) {
                    c.holds.held_plastic = true;
                    new.push((g, b));
                }
            }
        }
        let n = new.len();
        if n > 0 {
            c.holds.latched.extend(new);
            c.holds.latched.sort_by_key(|x| x.0);
        }
        n
    }

    /// Forget latched cracks (the increment is thrown away).
    pub fn unlatch(&mut self) {
        let holds = &mut self.families.continuum.holds;
        holds.latched.clear();
        holds.frozen = false;
    }

    /// Hold every cracked point on the branch (loading/unloading) of the last assembly for
    /// the rest of the increment (see [`crate::materials::point::freeze_cracks`]); the Newton
    /// drivers call it when their iterations cycle (`path::cycling`). At most once per
    /// increment. Returns the number of points held.
    pub fn freeze_cracks(&mut self) -> usize {
        let c = &mut self.families.continuum;
        if c.holds.frozen {
            return 0;
        }
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
    /// states; trial states and Gauss outputs are stored in `self.trial` / `self.gauss_trial`.
    /// Element work runs in parallel; the scatter is sequential in element order, so results
    /// are bit-identical whatever the thread count.
    pub fn assemble(
        &mut self,
        u: &[f64],
        tangent: bool,
    ) -> Result<Assembled, (usize, UpdateError)> {
        let model = self.model;
        let mut f_int = vec![0.0; u.len()];
        let mut f_abs = vec![0.0; u.len()];
        let mut k_values = tangent.then(|| vec![0.0; self.asm.pattern.nnz()]);
        let n_el = model.elements.len();
        let time = self.time;
        // Total Lagrangian continuum and bars (a separate code path: the linear one is
        // untouched).
        let tl = model.geometry == Geometry::Nonlinear;
        let mut start = 0;
        // Element vectors and matrices of one chunk, allocated once per assembly (the
        // element loop itself does not allocate).
        const ND: usize = 2 * crate::fem::shape::MAX_NODES;
        // Sized for the elements there are: a small model must not zero a 10 MB buffer on
        // every iteration (that was a quarter of a small contact run).
        let chunk = CHUNK.min(n_el).max(1);
        let (mut fbuf, mut kbuf) = std::mem::take(&mut self.elem_buf);
        fbuf.resize(chunk * ND, 0.0);
        kbuf.resize(chunk * ND * ND, 0.0);
        // Split the state arrays per element once per chunk so that chunks can be filled in
        // parallel without aliasing.
        while start < n_el {
            let end = (start + CHUNK).min(n_el);
            let g0 = self.gp_offset[start];
            let g1 = self.gp_offset[end];
            let (cont, bars) = (&mut self.families.continuum, &mut self.families.bars);
            let trial = &mut cont.points.trial[g0..g1];
            let gout = &mut cont.gauss.trial[g0..g1];
            let committed = &cont.points.committed[g0..g1];
            let gp_offset = &self.gp_offset;
            let (b0, b1) = (self.bar_offset[start], self.bar_offset[end]);
            let bar_committed = &bars.steel.committed[b0..b1];
            let bar_gps = &self.bar_gps;
            let bar_phase = &bars.phase;
            let bar_eps_ref = &bars.eps_ref[b0..b1];
            let bar_time = &bars.time[b0..b1];
            let latched = &cont.holds.latched;
            let bar_offset = &self.bar_offset;
            let (mut bt_rest, mut bo_rest) =
                (&mut bars.steel.trial[b0..b1], &mut bars.out.trial[b0..b1]);
            // Per-element slices.
            let mut pieces = Vec::with_capacity(end - start);
            let (mut t_rest, mut o_rest) = (trial, gout);
            for e in start..end {
                let ngp = gp_offset[e + 1] - gp_offset[e];
                let (t, tr) = t_rest.split_at_mut(ngp);
                let (o, or) = o_rest.split_at_mut(ngp);
                t_rest = tr;
                o_rest = or;
                let nb = bar_offset[e + 1] - bar_offset[e];
                let (bt, btr) = bt_rest.split_at_mut(nb);
                let (bo, bor) = bo_rest.split_at_mut(nb);
                bt_rest = btr;
                bo_rest = bor;
                pieces.push((e, t, o, (bt, bo)));
            }
            let results: Vec<ElementResult> = pieces
                .into_par_iter()
                .zip(fbuf.par_chunks_mut(ND))
                .zip(kbuf.par_chunks_mut(ND * ND))
                .map(|(((e, t, o, (bt, bo)), fe), ke)| {
                    let el = &model.elements[e];
                    let region = &model.regions[el.region];
                    let mat = &model.materials[region.material].law;
                    let nn = el.nodes.len();
                    let nd = 2 * nn;
                    let mut coords = [[0.0; 2]; crate::fem::shape::MAX_NODES];
                    let mut ue = [0.0; ND];
                    for (a, &n) in el.nodes.iter().enumerate() {
                        coords[a] = model.nodes[n];
                        ue[2 * a] = u[2 * n];
                        ue[2 * a + 1] = u[2 * n + 1];
                    }
                    let (coords, ue) = (&coords[..nn], &ue[..nd]);
                    let (fe, ke) = (&mut fe[..nd], &mut ke[..nd * nd]);
                    let c0 = gp_offset[e] - g0;
                    // Start from the latched crack states where a crack formed in this
                    // increment, from the committed states elsewhere.
                    let base = &committed[c0..c0 + t.len()];
                    let first = latched.partition_point(|x| x.0 < gp_offset[e]);
                    let owned: Option<Vec<PointState>> = latched
                        .get(first)
                        .filter(|x| x.0 < gp_offset[e + 1])
                        .map(|_| {
                            let mut v = base.to_vec();
                            for (g, st) in latched[first..]
                                .iter()
                                .take_while(|x| x.0 < gp_offset[e + 1])
                            {
                                v[g - gp_offset[e]] = st.clone();
                            }
                            v
                        });
                    let states = owned.as_deref().unwrap_or(base);
                    if tl {
                        total_lagrangian::response_tl(
                            el.kind,
                            el.integration,
                            coords,
                            region.thickness,
                            mat,
                            states,
                            ue,
                            fe,
                            tangent.then_some(&mut *ke),
                            t,
                            o,
                            &time,
                        )
                    } else {
                        continuum::response_at(
                            el.kind,
                            el.integration,
                            coords,
                            region.thickness,
                            mat,
                            states,
                            ue,
                            fe,
                            tangent.then_some(&mut *ke),
                            t,
                            o,
                            &time,
                        )
                    }
                    .map_err(|err| (e, err))?;
                    // Embedded bars hosted by this element: uniaxial steel at each point,
                    // ε_b = T(φ) B u_e − ε_ref + σ_b,0/E_s; f += g σ A w, K += g E_t A w gᵀ.
                    // A locked-off, ungrouted tendon adds f += g σ_lock A w only: these are
                    // the equivalent prestressing forces (anchor, curvature and friction
                    // forces integrated by parts through the shape functions).
                    let bc0 = bar_offset[e] - b0;
                    for (i, (&(b, p), (st, out))) in bar_gps[bar_offset[e]..bar_offset[e + 1]]
                        .iter()
                        .zip(bt.iter_mut().zip(bo.iter_mut()))
                        .enumerate()
                    {
                        let bar = &model.bars[b];
                        let bp = &bar.points[p].point;
                        // Relaxation of a tendon's steel: a stress-free strain.
                        let relax = bar_time[bc0 + i]
                            .as_ref()
                            .map_or(0.0, |r| r.relax_strain_trial);
                        if tl {
                            tl_bar_point(
                                TlBar {
                                    kind: el.kind,
                                    coords,
                                    bar,
                                    p,
                                    phase: bar_phase[b],
                                    committed: &bar_committed[bc0 + i],
                                    eps_ref: bar_eps_ref[bc0 + i],
                                    relax,
                                },
                                ue,
                                fe,
                                tangent.then_some(&mut *ke),
                                st,
                                out,
                            );
                            continue;
                        }
                        match bar_phase[b] {
                            BarPhase::Inactive => {
                                *st = bar_committed[bc0 + i];
                                *out = BarOutput::default();
                                continue;
                            }
                            BarPhase::Locked => {
                                let sig = bar.bonding_stress(p) - bar.steel.es * relax;
                                *st = bar_committed[bc0 + i];
                                *out = BarOutput {
                                    strain: sig / bar.steel.es,
                                    stress: sig,
                                    plastic_strain: 0.0,
                                };
                                let g = bar_strain_row(el.kind, coords, bp);
                                let fs = sig * bar.area * bp.weight_length;
                                for r in 0..nd {
                                    fe[r] += g[r] * fs;
                                }
                                continue;
                            }
                            BarPhase::Bonded => {}
                        }
                        let g = bar_strain_row(el.kind, coords, bp);
                        let eps = g.iter().zip(ue).map(|(a, b)| a * b).sum::<f64>()
                            - bar_eps_ref[bc0 + i]
                            + bar.bonding_stress(p) / bar.steel.es
                            - relax;
                        let (s_new, sig, et) =
                            update_uniaxial(&bar.steel, &bar_committed[bc0 + i], eps);
                        *st = s_new;
                        *out = BarOutput {
                            strain: eps,
                            stress: sig,
                            plastic_strain: s_new.plastic_strain,
                        };
                        let fs = sig * bar.area * bp.weight_length;
                        let ks = et * bar.area * bp.weight_length;
                        for r in 0..nd {
                            fe[r] += g[r] * fs;
                            let gr = g[r] * ks;
                            if gr != 0.0 {
                                for c in 0..nd {
                                    ke[r * nd + c] += gr * g[c];
                                }
                            }
                        }
                    }
                    Ok(())
                })
                .collect();
            for (i, r) in results.into_iter().enumerate() {
                let e = start + i;
                r?;
                let nd = 2 * model.elements[e].nodes.len();
                let fe = &fbuf[i * ND..i * ND + nd];
                let ke = &kbuf[i * ND * ND..i * ND * ND + nd * nd];
                for (a, &n) in model.elements[e].nodes.iter().enumerate() {
                    f_int[2 * n] += fe[2 * a];
                    f_int[2 * n + 1] += fe[2 * a + 1];
                    f_abs[2 * n] += fe[2 * a].abs();
                    f_abs[2 * n + 1] += fe[2 * a + 1].abs();
                }
                if let Some(k) = k_values.as_mut() {
                    self.asm
                        .add_matrix(self.numbers.number(Family::Continuum, e), ke, k);
                }
            }
            start = end;
        }
        self.elem_buf = (fbuf, kbuf);
        // Joint contact elements.
        let results: Vec<_> = self
            .interfaces
            .par_iter()
            .zip(&model.interfaces)
            .zip(&self.families.joints.points.committed)
            .map(|((el, data), committed)| {
                let ue: Vec<f64> = data
                    .nodes
                    .iter()
                    .flat_map(|&n| [u[2 * n], u[2 * n + 1]])
                    .collect();
                el.response_with(&data.params, data.thickness, &ue, committed, true)
            })
            .collect();
        let mut symmetrised = false;
        for (i, r) in results.into_iter().enumerate() {
            let nodes = &model.interfaces[i].nodes;
            for (a, &n) in nodes.iter().enumerate() {
                f_int[2 * n] += r.f_int[2 * a];
                f_int[2 * n + 1] += r.f_int[2 * a + 1];
                f_abs[2 * n] += r.f_int[2 * a].abs();
                f_abs[2 * n + 1] += r.f_int[2 * a + 1].abs();
            }
            if let Some(k) = k_values.as_mut() {
                let mut ke = r.k;
                if !r.symmetric {
                    // Slip makes the tangent unsymmetric; the Cholesky path takes its
                    // symmetric part (more iterations, same converged answer).
                    symmetrise(&mut ke, 2 * nodes.len());
                    symmetrised = true;
                }
                self.asm
                    .add_matrix(self.numbers.number(Family::Joint, i), &ke, k);
            }
            self.families.joints.points.trial[i] = r.states;
        }
        // External tendons (corotational: their forces follow the deformed geometry).
        let tb = &mut self.families.tendons;
        for (t, tendon) in self.tendons.iter().enumerate() {
            let (Some(el), Some(committed)) = (tendon, &tb.states.committed[t]) else {
                continue;
            };
            let nodes = &model.tendons[t].nodes;
            let ut: Vec<[f64; 2]> = nodes
                .iter()
                .zip(&tb.u0[t])
                .map(|(&n, u0)| [u[2 * n] - u0[0], u[2 * n + 1] - u0[1]])
                .collect();
            let r = el.response(&ut, committed);
            for (a, &n) in nodes.iter().enumerate() {
                f_int[2 * n] += r.f_int[2 * a];
                f_int[2 * n + 1] += r.f_int[2 * a + 1];
                f_abs[2 * n] += r.f_int[2 * a].abs();
                f_abs[2 * n + 1] += r.f_int[2 * a + 1].abs();
            }
            if let Some(k) = k_values.as_mut() {
                let mut ke = r.k;
                if !r.symmetric {
                    symmetrise(&mut ke, 2 * nodes.len());
                    symmetrised = true;
                }
                self.asm
                    .add_matrix(self.numbers.number(Family::Tendon, t), &ke, k);
            }
            tb.states.trial[t] = Some(r.state);
        }
        self.symmetrised = symmetrised;
        let force_scale = f_abs.iter().map(|v| v * v).sum::<f64>().sqrt();
        Ok(Assembled {
            f_int,
            k_values,
            force_scale,
        })
    }

    /// Prestressing operations at the start of step `step`: external tendons assigned to it
    /// are built on the current deformed geometry with their span stresses (post-tensioning
    /// against the concrete as it stands); bonded post-tensioned tendons are locked off or
    /// grouted (their bond strain is measured from the current displacements on).
    pub fn stress_tendons(&mut self, step: usize) {
        self.stage_bonded_tendons(step);
        for (t, data) in self.model.tendons.iter().enumerate() {
            if data.stressed_in_step != step || self.tendons[t].is_some() {
                continue;
            }
            let u0: Vec<[f64; 2]> = data
                .nodes
                .iter()
                .map(|&n| [self.u[2 * n], self.u[2 * n + 1]])
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
                    bars.eps_ref[i] = if model.geometry == Geometry::Nonlinear {
                        let ue: Vec<f64> = el
                            .nodes
                            .iter()
                            .flat_map(|&n| [self.u[2 * n], self.u[2 * n + 1]])
                            .collect();
                        bar_green_strain(el.kind, &coords, &gp.point, &ue).0
                    } else {
                        let g = bar_strain_row(el.kind, &coords, &gp.point);
                        el.nodes
                            .iter()
                            .enumerate()
                            .map(|(a, &n)| {
                                g[2 * a] * self.u[2 * n] + g[2 * a + 1] * self.u[2 * n + 1]
                            })
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
        let x: Vec<[f64; 2]> = data
            .nodes
            .iter()
            .zip(u0)
            .map(|(&n, d)| [self.model.nodes[n][0] + d[0], self.model.nodes[n][1] + d[1]])
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

    /// Accept the trial states of the last assembly and the displacements `u`.
    pub fn commit(&mut self, u: &[f64]) {
        self.commit_time_dependent();
        std::mem::swap(&mut self.u, &mut self.u_prev);
        self.u.copy_from_slice(u);
        self.families.commit();
    }

    /// Gather the free-equation part of a full dof vector.
    pub fn to_free(&self, full: &[f64]) -> Vec<f64> {
        let mut r = vec![0.0; self.dofs.n_eq];
        for (d, &q) in self.dofs.eq.iter().enumerate() {
            if q != CONSTRAINED {
                r[q] = full[d];
            }
        }
        r
    }
}
