//! The continuum elements with the bars they host, as the assembly calls them: each
//! element's data gathered from the model, its state slices from the family blocks, its
//! response written into the caller's buffers ([`ElementResponse`]).

use super::families::{BarOutput, BarPhase, Families};
use super::stages::StageState;
use super::tendon_time::BarPointTime;
use crate::elements::bar::{
    bar_point_response, bar_point_small_strain, bar_strain_row, BarKinematics, BarStage,
};
use crate::elements::continuum::{
    gauss_geometry, rule_points, BarTerm, ContinuumElement, Formulation, GaussGeometry,
    GaussOutput, Integration, NodeBlocks, TangentMemo,
};
use crate::elements::{ElementResponse, Response};
use crate::materials::point::{Material, PointState, TimeContext, UpdateError};
use crate::materials::steel::SteelState;
use crate::model::{Geometry, Model};

/// Element force entries per slot of the chunk buffers (2 per node of the largest element).
pub(super) const ND: usize = 2 * crate::fem::shape::MAX_NODES;

/// The Gauss-point geometry of every continuum element ([`GaussGeometry`], packed), computed
/// once: it depends on the undeformed coordinates only, and a nonlinear run assembles
/// hundreds of times (the geometry was 3–5 % of the run's work). Elements with incompatible
/// modes keep computing theirs (none stored).
pub struct GeometryCache {
    /// Start of each element's values in `data` (elements + 1).
    offset: Vec<usize>,
    data: Vec<f64>,
}

impl GeometryCache {
    /// The geometry of every continuum element of `model`.
    pub fn new(model: &Model) -> Self {
        let stored = |e: &crate::model::Element| {
            if e.integration == Integration::Incompatible {
                0
            } else {
                rule_points(e.kind, e.integration).len() * (2 * e.nodes.len() + 1) + 1
            }
        };
        let mut offset = Vec::with_capacity(model.elements.len() + 1);
        offset.push(0);
        let mut data = Vec::with_capacity(model.elements.iter().map(stored).sum());
        let mut coords = [[0.0; 2]; crate::fem::shape::MAX_NODES];
        for el in &model.elements {
            if stored(el) > 0 {
                let n = el.nodes.len();
                for (a, &node) in el.nodes.iter().enumerate() {
                    coords[a] = model.nodes[node];
                }
                gauss_geometry(el.kind, el.integration, &coords[..n]).pack(n, &mut data);
            }
            offset.push(data.len());
        }
        Self { offset, data }
    }

    /// The characteristic length h [m] of element `e` (the last packed value), if stored.
    fn h(&self, e: usize) -> Option<f64> {
        self.data[self.offset[e]..self.offset[e + 1]]
            .last()
            .copied()
    }

    /// The geometry of element `e` (`n` nodes, `n_pts` Gauss points), if stored.
    fn get(&self, e: usize, n: usize, n_pts: usize) -> Option<GaussGeometry> {
        self.packed(e).map(|d| GaussGeometry::unpack(d, n, n_pts))
    }

    /// The packed values of element `e` ([`GaussGeometry::pack`]), if stored: the element
    /// loop reads them in place.
    fn packed(&self, e: usize) -> Option<&[f64]> {
        let d = &self.data[self.offset[e]..self.offset[e + 1]];
        (!d.is_empty()).then_some(d)
    }
}

/// What the assembly keeps between calls besides the Gauss geometry: for a nonlinear run
/// in small strain the elements' tangent memos and the bar points' strain rows, for any
/// nonlinear run the elements' local materials (each a cache of values the element loop
/// computed at every assembly, with the same operations, so the same bits).
pub struct Kept {
    geometry: Option<GeometryCache>,
    memos: Option<TangentMemos>,
    bar_rows: Vec<[f64; ND]>,
    locals: Option<LocalMaterials>,
}

impl Kept {
    /// The caches of `model` with its Gauss `geometry` (none for a linear run: nothing
    /// kept); `blocks` are the node blocks each element forms, `bar_gps` the bar points in
    /// assembly order.
    pub fn new(
        model: &Model,
        geometry: Option<GeometryCache>,
        blocks: &[NodeBlocks],
        bar_gps: &[(usize, usize)],
    ) -> Self {
        let small_strain = geometry.is_some() && model.geometry != Geometry::Nonlinear;
        let locals = geometry.as_ref().map(|g| LocalMaterials::new(model, g));
        Self {
            geometry,
            memos: small_strain.then(|| TangentMemos::new(model, blocks, bar_gps)),
            bar_rows: if small_strain {
                bar_strain_rows(model, bar_gps)
            } else {
                Vec::new()
            },
            locals,
        }
    }

    /// The Gauss-point geometry, if kept.
    pub fn geometry(&self) -> Option<&GeometryCache> {
        self.geometry.as_ref()
    }
}

/// The tangent memos of the small-strain continuum elements ([`TangentMemo`]), for a
/// nonlinear run in small strain: one per element with a Gauss-geometry cache (none for
/// incompatible modes), each 1 + 9 n_pts + (embedded bar points) + 4 × (wanted node
/// blocks) values (a Q8 of 9 points assembled by its lower triangle: 226 values, 1.8 kB,
/// and one per bar point; a Q4 of 4 points: 77).
pub struct TangentMemos {
    /// Start of each element's memo in `data` (elements + 1).
    offset: Vec<usize>,
    data: Vec<f64>,
}

impl TangentMemos {
    /// Empty memos for every small-strain element of `model` with the wanted `blocks` and
    /// the embedded bar points `bar_gps` (bar, point).
    pub fn new(model: &Model, blocks: &[NodeBlocks], bar_gps: &[(usize, usize)]) -> Self {
        let mut bars = vec![0; model.elements.len()];
        for &(b, p) in bar_gps {
            bars[model.bars[b].points[p].element] += 1;
        }
        let mut offset = Vec::with_capacity(model.elements.len() + 1);
        offset.push(0);
        let mut len = 0;
        for ((el, b), nb) in model.elements.iter().zip(blocks).zip(bars) {
            if el.integration != Integration::Incompatible {
                let n_pts = rule_points(el.kind, el.integration).len();
                len += TangentMemo::len(el.nodes.len(), n_pts, *b, nb);
            }
            offset.push(len);
        }
        Self {
            offset,
            data: vec![0.0; len],
        }
    }
}

/// The continuum elements' materials with their size-dependent constants
/// ([`crate::materials::point::for_element`] at the element's crack band width: the crush
/// band of a concrete), made once for a nonlinear run instead of at every element
/// response (a copy of the concrete's parameters each time): one per distinct (material,
/// h), each element's index into them.
pub struct LocalMaterials {
    materials: Vec<Material>,
    /// Element e's entry in `materials` (`u32::MAX`: none, the model's material as it is).
    of: Vec<u32>,
}

impl LocalMaterials {
    /// The local materials of every element of `model` whose Gauss geometry `cache`
    /// holds (an element without, or whose material refuses its h, has none: its
    /// response makes or refuses it as before).
    pub fn new(model: &Model, cache: &GeometryCache) -> Self {
        let mut seen = std::collections::HashMap::new();
        let mut materials = Vec::new();
        let of = (0..model.elements.len())
            .map(|e| {
                let m = model.regions[model.elements[e].region].material;
                let Some(h) = cache.h(e) else {
                    return u32::MAX;
                };
                *seen.entry((m, h.to_bits())).or_insert_with(|| {
                    match crate::materials::point::for_element(&model.materials[m].law, h) {
                        Ok(Some(local)) => {
                            materials.push(local);
                            (materials.len() - 1) as u32
                        }
                        _ => u32::MAX,
                    }
                })
            })
            .collect();
        Self { materials, of }
    }

    /// The local material of element `e`, if made.
    fn get(&self, e: usize) -> Option<&Material> {
        self.materials.get(self.of[e] as usize)
    }
}

/// The strain rows g of the embedded bar points `bar_gps` ([`bar_strain_row`]), in their
/// order, for a small-strain run (they depend on the undeformed geometry only; the
/// assembly recomputed them at every bar point).
pub fn bar_strain_rows(model: &Model, bar_gps: &[(usize, usize)]) -> Vec<[f64; ND]> {
    let mut coords = [[0.0; 2]; crate::fem::shape::MAX_NODES];
    bar_gps
        .iter()
        .map(|&(b, p)| {
            let bp = &model.bars[b].points[p];
            let el = &model.elements[bp.element];
            for (a, &node) in el.nodes.iter().enumerate() {
                coords[a] = model.nodes[node];
            }
            bar_strain_row(el.kind, &coords[..el.nodes.len()], &bp.point)
        })
        .collect()
}

/// The crack band width h [m] of continuum element `e` as its material update takes it
/// ([`GaussGeometry::h`]; an element with incompatible modes uses its Q4 rule's): from
/// `cache` where stored, else computed.
pub(super) fn crack_band_width(model: &Model, cache: Option<&GeometryCache>, e: usize) -> f64 {
    if let Some(h) = cache.and_then(|c| c.h(e)) {
        return h;
    }
    let el = &model.elements[e];
    let mut coords = [[0.0; 2]; crate::fem::shape::MAX_NODES];
    for (a, &n) in el.nodes.iter().enumerate() {
        coords[a] = model.nodes[n];
    }
    let (kind, rule) = match el.integration {
        Integration::Incompatible => (crate::model::ElementKind::Q4, Integration::Full),
        i => (el.kind, i),
    };
    gauss_geometry(kind, rule, &coords[..el.nodes.len()]).h
}

/// The Gauss-point geometry of continuum element `e` ([`GaussGeometry`]) from `cache` where
/// stored, else computed; an element with incompatible modes gives its Q4 rule's (the
/// compatible part of its strains).
pub(super) fn element_geometry(
    model: &Model,
    cache: Option<&GeometryCache>,
    e: usize,
) -> GaussGeometry {
    let el = &model.elements[e];
    let n = el.nodes.len();
    if el.integration != Integration::Incompatible {
        if let Some(g) = cache.and_then(|c| c.get(e, n, rule_points(el.kind, el.integration).len()))
        {
            return g;
        }
    }
    let mut coords = [[0.0; 2]; crate::fem::shape::MAX_NODES];
    for (a, &node) in el.nodes.iter().enumerate() {
        coords[a] = model.nodes[node];
    }
    let (kind, rule) = match el.integration {
        Integration::Incompatible => (crate::model::ElementKind::Q4, Integration::Full),
        i => (el.kind, i),
    };
    gauss_geometry(kind, rule, &coords[..n])
}

/// What the continuum elements of one chunk share (read-only).
pub(super) struct HostChunk<'a> {
    model: &'a Model,
    u: &'a [f64],
    time: &'a TimeContext,
    tangent: bool,
    /// Total Lagrangian kinematics for the continuum and the bars.
    tl: bool,
    gp_offset: &'a [usize],
    /// First Gauss point of the chunk.
    g0: usize,
    /// Committed point states of the chunk.
    committed: &'a [PointState],
    latched: &'a [(usize, PointState)],
    bar_gps: &'a [(usize, usize)],
    bar_offset: &'a [usize],
    /// First bar point of the chunk.
    b0: usize,
    /// The strain rows of the chunk's bar points, if cached (small strain; empty: none).
    bar_rows: &'a [[f64; ND]],
    bar_committed: &'a [SteelState],
    bar_phase: &'a [BarPhase],
    bar_eps_ref: &'a [f64],
    bar_time: &'a [Option<BarPointTime>],
    /// Imposed (thermal) strains of the chunk's Gauss points and bar points (empty: none).
    imposed: &'a [f64],
    bar_imposed: &'a [f64],
    /// Construction stages (reference displacements of elements born late), if any.
    stages: Option<&'a StageState>,
    /// Tangent blocks each element forms (all elements).
    blocks: &'a [NodeBlocks],
    /// The elements' Gauss-point geometry, if cached.
    geometry: Option<&'a GeometryCache>,
    /// The elements' local materials, if made.
    locals: Option<&'a LocalMaterials>,
}

/// One element's own trial slices: element index, point states, Gauss outputs, bar steel
/// states and bar outputs, and its tangent memo (empty: none).
pub(super) type HostPiece<'a> = (
    usize,
    &'a mut [PointState],
    &'a mut [GaussOutput],
    (&'a mut [SteelState], &'a mut [BarOutput]),
    &'a mut [f64],
);

/// Split the state of elements `start..end` so that each element's trial slices can be
/// filled in parallel without aliasing.
#[allow(clippy::too_many_arguments)]
pub(super) fn split_chunk<'a>(
    model: &'a Model,
    families: &'a mut Families,
    gp_offset: &'a [usize],
    bar_gps: &'a [(usize, usize)],
    bar_offset: &'a [usize],
    thermal: &'a super::thermal::Thermal,
    u: &'a [f64],
    time: &'a TimeContext,
    tangent: bool,
    (start, end): (usize, usize),
    stages: Option<&'a StageState>,
    blocks: &'a [NodeBlocks],
    (kept, memos): (&'a mut Kept, bool),
) -> (HostChunk<'a>, Vec<HostPiece<'a>>) {
    let Kept {
        geometry,
        memos: all_memos,
        bar_rows,
        locals,
    } = kept;
    let memos = all_memos.as_mut().filter(|_| memos);
    let (geometry, locals) = (geometry.as_ref(), locals.as_ref());
    let g0 = gp_offset[start];
    let g1 = gp_offset[end];
    let (cont, bars) = (&mut families.continuum, &mut families.bars);
    let (b0, b1) = (bar_offset[start], bar_offset[end]);
    let chunk = HostChunk {
        model,
        u,
        time,
        tangent,
        tl: model.geometry == Geometry::Nonlinear,
        gp_offset,
        g0,
        committed: &cont.points.committed[g0..g1],
        latched: &cont.holds.latched,
        bar_gps,
        bar_offset,
        b0,
        bar_rows: bar_rows.get(b0..b1).unwrap_or(&[]),
        bar_committed: &bars.steel.committed[b0..b1],
        bar_phase: &bars.phase,
        bar_eps_ref: &bars.eps_ref[b0..b1],
        bar_time: &bars.time[b0..b1],
        imposed: thermal.points.get(g0..g1).unwrap_or(&[]),
        bar_imposed: thermal.bars.get(b0..b1).unwrap_or(&[]),
        stages,
        blocks,
        geometry,
        locals,
    };
    let (mut bt_rest, mut bo_rest) = (&mut bars.steel.trial[b0..b1], &mut bars.out.trial[b0..b1]);
    // Per-element slices.
    let mut pieces = Vec::with_capacity(end - start);
    let (mut t_rest, mut o_rest) = (
        &mut cont.points.trial[g0..g1],
        &mut cont.gauss.trial[g0..g1],
    );
    let (m_offset, mut m_rest): (&[usize], &mut [f64]) = match memos {
        Some(TangentMemos { offset, data }) => (offset, &mut data[offset[start]..offset[end]]),
        None => (&[], &mut []),
    };
    let m_len = |e: usize| m_offset.get(e + 1).map_or(0, |o| o - m_offset[e]);
    for e in start..end {
        let (m, mr) = std::mem::take(&mut m_rest).split_at_mut(m_len(e));
        m_rest = mr;
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
        pieces.push((e, t, o, (bt, bo), m));
    }
    (chunk, pieces)
}

impl HostChunk<'_> {
    /// Force into `fe` and (if the chunk wants the tangent) tangent into `ke` of one
    /// continuum element and the bars it hosts; `fe`, `ke` are slots of [`ND`] and `ND²`
    /// entries.
    pub(super) fn element(
        &self,
        (e, t, o, (bt, bo), memo): HostPiece,
        fe: &mut [f64],
        ke: &mut [f64],
    ) -> Result<(), UpdateError> {
        let HostChunk {
            model,
            u,
            time,
            tangent,
            tl,
            gp_offset,
            g0,
            committed,
            latched,
            bar_gps,
            bar_offset,
            b0,
            bar_rows,
            imposed,
            stages,
            blocks,
            geometry,
            locals,
            ..
        } = *self;
        let el = &model.elements[e];
        let region = &model.regions[el.region];
        let local = locals.and_then(|l| l.get(e));
        let mat = local.unwrap_or(&model.materials[region.material].law);
        let nn = el.nodes.len();
        let nd = 2 * nn;
        let mut coords = [[0.0; 2]; crate::fem::shape::MAX_NODES];
        let mut ue = [0.0; ND];
        for (a, &n) in el.nodes.iter().enumerate() {
            coords[a] = model.nodes[n];
            ue[2 * a] = u[2 * n];
            ue[2 * a + 1] = u[2 * n + 1];
        }
        // Born in a later stage: stress-free at the displacements it was placed at.
        if let Some(r) = stages.and_then(|s| s.element_ref[e].as_deref()) {
            ue.iter_mut().zip(r).for_each(|(a, b)| *a -= b);
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
        let cached = geometry.and_then(|c| c.packed(e));
        let formulation = Formulation::new(el.kind, el.integration, tl);
        let bc0 = bar_offset[e] - b0;
        let gps = &bar_gps[bar_offset[e]..bar_offset[e + 1]];
        // Small strain with the bars' strain rows cached: the bars' laws first and their
        // terms added by the element after its points' (the same additions in the same
        // order as `bars_after`), so that the element's tangent memo covers them.
        let rows = bar_rows
            .get(bc0..bc0 + gps.len())
            .filter(|_| matches!(formulation, Formulation::SmallStrain { .. }) && !gps.is_empty());
        let mut on_stack = [BarTerm::default(); 8];
        let mut on_heap = Vec::new();
        let terms: &[BarTerm] = match rows {
            Some(rows) => {
                let terms = if gps.len() <= on_stack.len() {
                    &mut on_stack[..gps.len()]
                } else {
                    on_heap.resize(gps.len(), BarTerm::default());
                    &mut on_heap[..]
                };
                self.bar_terms(e, rows, ue, (bt, bo), terms);
                terms
            }
            None => &[],
        };
        let element = ContinuumElement {
            formulation,
            coords,
            thickness: region.thickness,
            material: mat,
            localised: local.is_some(),
            time,
            imposed: imposed.get(c0..c0 + t.len()).unwrap_or(&[]),
            blocks: blocks[e],
            geometry: cached,
            memo: std::cell::Cell::from_mut(memo).as_slice_of_cells(),
            bars: terms,
        };
        element.response(
            ue,
            states,
            (t, o),
            Response {
                f: fe,
                k: tangent.then_some(&mut *ke),
            },
        )?;
        if rows.is_none() {
            self.bars_after(
                e,
                (el.kind, coords),
                ue,
                (bt, bo),
                fe,
                tangent.then_some(ke),
            );
        }
        Ok(())
    }

    /// The stage of element `e`'s bar point `i` (in the chunk's order), as its law sees it.
    fn bar_stage(&self, e: usize, i: usize) -> BarStage {
        let (b, p) = self.bar_gps[self.bar_offset[e] + i];
        let c = self.bar_offset[e] - self.b0 + i;
        let bar = &self.model.bars[b];
        // Relaxation of a tendon's steel: a stress-free strain.
        let relax = self.bar_time[c]
            .as_ref()
            .map_or(0.0, |r| r.relax_strain.trial);
        match self.bar_phase[b] {
            BarPhase::Inactive => BarStage::Absent,
            BarPhase::Locked => BarStage::Locked {
                stress: bar.bonding_stress(p) - bar.steel.es * relax,
            },
            BarPhase::Bonded => BarStage::Bonded {
                eps_ref: self.bar_eps_ref[c],
                prestrain: bar.bonding_stress(p) / bar.steel.es,
                relax,
                thermal: self.bar_imposed.get(c).copied().unwrap_or(0.0),
            },
        }
    }

    /// The laws of element `e`'s bar points in small strain with their strain rows `rows`
    /// at the element displacements `ue`: trial states and outputs into `bt`, `bo`, the
    /// terms the element adds into `terms` (an absent point's left empty).
    fn bar_terms<'r>(
        &self,
        e: usize,
        rows: &'r [[f64; ND]],
        ue: &[f64],
        (bt, bo): (&mut [SteelState], &mut [BarOutput]),
        terms: &mut [BarTerm<'r>],
    ) {
        let gps = &self.bar_gps[self.bar_offset[e]..self.bar_offset[e + 1]];
        let c0 = self.bar_offset[e] - self.b0;
        for (i, (((&(b, p), g), (st, out)), term)) in gps
            .iter()
            .zip(rows)
            .zip(bt.iter_mut().zip(bo.iter_mut()))
            .zip(terms.iter_mut())
            .enumerate()
        {
            let bar = &self.model.bars[b];
            let (r, factors) = bar_point_small_strain(
                g,
                bar.points[p].point.weight_length,
                &bar.steel,
                bar.area,
                self.bar_stage(e, i),
                &self.bar_committed[c0 + i],
                ue,
            );
            *st = r.state;
            *out = BarOutput {
                strain: r.strain,
                stress: r.stress,
                plastic_strain: r.plastic_strain,
            };
            if let Some((force, stiffness)) = factors {
                *term = BarTerm {
                    row: g,
                    force,
                    stiffness,
                };
            }
        }
    }

    /// Element `e`'s bar points through the one bar-point law, added to the element's
    /// force `fe` and tangent `ke` after its own response (host kind and node coordinates
    /// `host`, element displacements `ue`): the total Lagrangian kinematics, or small
    /// strain without cached rows.
    fn bars_after(
        &self,
        e: usize,
        (kind, coords): (crate::model::ElementKind, &[[f64; 2]]),
        ue: &[f64],
        (bt, bo): (&mut [SteelState], &mut [BarOutput]),
        fe: &mut [f64],
        mut ke: Option<&mut [f64]>,
    ) {
        let kinematics = if self.tl {
            BarKinematics::TotalLagrangian
        } else {
            BarKinematics::SmallStrain
        };
        let gps = &self.bar_gps[self.bar_offset[e]..self.bar_offset[e + 1]];
        let c0 = self.bar_offset[e] - self.b0;
        for (i, (&(b, p), (st, out))) in
            gps.iter().zip(bt.iter_mut().zip(bo.iter_mut())).enumerate()
        {
            let bar = &self.model.bars[b];
            let r = bar_point_response(
                kinematics,
                kind,
                coords,
                &bar.points[p].point,
                self.bar_rows.get(c0 + i),
                &bar.steel,
                bar.area,
                self.bar_stage(e, i),
                &self.bar_committed[c0 + i],
                ue,
                fe,
                ke.as_deref_mut(),
            );
            *st = r.state;
            *out = BarOutput {
                strain: r.strain,
                stress: r.stress,
                plastic_strain: r.plastic_strain,
            };
        }
    }
}
