//! The continuum elements with the bars they host, as the assembly calls them: each
//! element's data gathered from the model, its state slices from the family blocks, its
//! response written into the caller's buffers ([`ElementResponse`]).

use super::families::{BarOutput, BarPhase, Families};
use super::stages::StageState;
use super::tendon_time::BarPointTime;
use crate::elements::bar::{bar_point_response, BarKinematics, BarStage};
use crate::elements::continuum::{
    gauss_geometry, rule_points, ContinuumElement, Formulation, GaussGeometry, GaussOutput,
    Integration, NodeBlocks,
};
use crate::elements::{ElementResponse, Response};
use crate::materials::point::{PointState, TimeContext, UpdateError};
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
        let d = &self.data[self.offset[e]..self.offset[e + 1]];
        (!d.is_empty()).then(|| GaussGeometry::unpack(d, n, n_pts))
    }
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
}

/// One element's own trial slices: element index, point states, Gauss outputs, bar steel
/// states and bar outputs.
pub(super) type HostPiece<'a> = (
    usize,
    &'a mut [PointState],
    &'a mut [GaussOutput],
    (&'a mut [SteelState], &'a mut [BarOutput]),
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
    geometry: Option<&'a GeometryCache>,
) -> (HostChunk<'a>, Vec<HostPiece<'a>>) {
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
        bar_committed: &bars.steel.committed[b0..b1],
        bar_phase: &bars.phase,
        bar_eps_ref: &bars.eps_ref[b0..b1],
        bar_time: &bars.time[b0..b1],
        imposed: thermal.points.get(g0..g1).unwrap_or(&[]),
        bar_imposed: thermal.bars.get(b0..b1).unwrap_or(&[]),
        stages,
        blocks,
        geometry,
    };
    let (mut bt_rest, mut bo_rest) = (&mut bars.steel.trial[b0..b1], &mut bars.out.trial[b0..b1]);
    // Per-element slices.
    let mut pieces = Vec::with_capacity(end - start);
    let (mut t_rest, mut o_rest) = (
        &mut cont.points.trial[g0..g1],
        &mut cont.gauss.trial[g0..g1],
    );
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
    (chunk, pieces)
}

impl HostChunk<'_> {
    /// Force into `fe` and (if the chunk wants the tangent) tangent into `ke` of one
    /// continuum element and the bars it hosts; `fe`, `ke` are slots of [`ND`] and `ND²`
    /// entries.
    pub(super) fn element(
        &self,
        (e, t, o, (bt, bo)): HostPiece,
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
            bar_committed,
            bar_phase,
            bar_eps_ref,
            bar_time,
            imposed,
            bar_imposed,
            stages,
            blocks,
            geometry,
        } = *self;
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
        let cached = geometry.and_then(|c| c.get(e, nn, t.len()));
        let element = ContinuumElement {
            formulation: Formulation::new(el.kind, el.integration, tl),
            coords,
            thickness: region.thickness,
            material: mat,
            time,
            imposed: imposed.get(c0..c0 + t.len()).unwrap_or(&[]),
            blocks: blocks[e],
            geometry: cached.as_ref(),
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
        // Embedded bars hosted by this element, through the one bar-point law.
        let kinematics = if tl {
            BarKinematics::TotalLagrangian
        } else {
            BarKinematics::SmallStrain
        };
        let bc0 = bar_offset[e] - b0;
        for (i, (&(b, p), (st, out))) in bar_gps[bar_offset[e]..bar_offset[e + 1]]
            .iter()
            .zip(bt.iter_mut().zip(bo.iter_mut()))
            .enumerate()
        {
            let bar = &model.bars[b];
            // Relaxation of a tendon's steel: a stress-free strain.
            let relax = bar_time[bc0 + i]
                .as_ref()
                .map_or(0.0, |r| r.relax_strain.trial);
            let stage = match bar_phase[b] {
                BarPhase::Inactive => BarStage::Absent,
                BarPhase::Locked => BarStage::Locked {
                    stress: bar.bonding_stress(p) - bar.steel.es * relax,
                },
                BarPhase::Bonded => BarStage::Bonded {
                    eps_ref: bar_eps_ref[bc0 + i],
                    prestrain: bar.bonding_stress(p) / bar.steel.es,
                    relax,
                    thermal: bar_imposed.get(bc0 + i).copied().unwrap_or(0.0),
                },
            };
            let r = bar_point_response(
                kinematics,
                el.kind,
                coords,
                &bar.points[p].point,
                &bar.steel,
                bar.area,
                stage,
                &bar_committed[bc0 + i],
                ue,
                fe,
                tangent.then_some(&mut *ke),
            );
            *st = r.state;
            *out = BarOutput {
                strain: r.strain,
                stress: r.stress,
                plastic_strain: r.plastic_strain,
            };
        }
        Ok(())
    }
}
