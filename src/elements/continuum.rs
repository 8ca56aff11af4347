//! Isoparametric plane-stress continuum elements (every kind of [`crate::fem::kinds`]): internal force and tangent
//! stiffness from the trial displacements, consistent body and edge loads.

use crate::fem::quadrature::{gauss, Point2};
use crate::fem::shape::{cartesian_derivatives, jacobian, line_shape, MAX_NODES};
use crate::materials::point::{update_into, Material, PointState, TimeContext, UpdateError};
use crate::model::ElementKind;
use serde::{Deserialize, Serialize};
use std::cell::Cell;

/// Integration rule (plain model data, defined in [`crate::model`]).
pub use crate::model::element_data::Integration;

/// The Gauss points of an element kind under a rule.
pub fn rule(kind: ElementKind, integration: Integration) -> Vec<Point2> {
    rule_points(kind, integration).to_vec()
}

/// The Gauss points of an element kind under a rule, from tables built once (the element
/// loop must not allocate); the kind's descriptor owns them ([`crate::fem::kinds`]).
pub fn rule_points(kind: ElementKind, integration: Integration) -> &'static [Point2] {
    kind.rule(integration)
}

/// How a continuum element turns nodal displacements into strains and forces: the one switch
/// between the small-strain element, the Q4 with incompatible modes and the total Lagrangian
/// element (chosen from the element's kind and rule and the model's geometry).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Formulation {
    /// Small strains: an isoparametric element of `kind` integrated by `integration`.
    SmallStrain {
        /// Element kind.
        kind: ElementKind,
        /// Integration rule (full or reduced).
        integration: Integration,
    },
    /// Q4 with Wilson–Taylor incompatible bending modes, condensed in the element
    /// ([`super::incompatible`]).
    IncompatibleModes,
    /// Total Lagrangian: Green strain, second Piola–Kirchhoff stress, referred to the
    /// undeformed element ([`super::total_lagrangian`]).
    TotalLagrangian {
        /// Element kind.
        kind: ElementKind,
        /// Integration rule.
        integration: Integration,
    },
}

impl Formulation {
    /// The formulation of an element of `kind` under `integration`; `large_displacements`
    /// for a geometrically nonlinear model (the input refuses incompatible modes with it).
    pub fn new(kind: ElementKind, integration: Integration, large_displacements: bool) -> Self {
        if large_displacements {
            Formulation::TotalLagrangian { kind, integration }
        } else if integration == Integration::Incompatible {
            debug_assert!(kind.info().incompatible_modes, "checked at input");
            Formulation::IncompatibleModes
        } else {
            Formulation::SmallStrain { kind, integration }
        }
    }
}

/// A continuum element ready to answer: formulation, node coordinates [m], thickness [m],
/// material and the time increment of the analysis clock.
pub struct ContinuumElement<'a> {
    /// Kinematics and integration.
    pub formulation: Formulation,
    /// Node coordinates [m].
    pub coords: &'a [[f64; 2]],
    /// Thickness [m].
    pub thickness: f64,
    /// Material of every point.
    pub material: &'a Material,
    /// `material` already carries the element's size-dependent constants
    /// ([`crate::materials::point::for_element`] at its h), made once by the caller.
    pub localised: bool,
    /// Time increment (creep, shrinkage) [d].
    pub time: &'a TimeContext,
    /// Imposed (stress-free) normal strain θ [-] of each Gauss point, ε_th = θ (1, 1, 0)
    /// (thermal actions, [`super::thermal`]); empty: none.
    pub imposed: &'a [f64],
    /// The node blocks of the tangent to form (the assembly wants one of (a, b), (b, a)).
    pub blocks: NodeBlocks,
    /// The Gauss-point geometry if already known, as packed by [`GaussGeometry::pack`] (a
    /// cache read in place; None: computed from `coords`).
    pub geometry: Option<&'a [f64]>,
    /// The element's tangent memo ([`TangentMemo`]; empty: none), small strain only.
    pub memo: &'a [Cell<f64>],
    /// The terms of the embedded bar points the element adds after its own ([`BarTerm`];
    /// small strain only, empty: none, the caller adds its bars).
    pub bars: &'a [BarTerm<'a>],
}

/// What an embedded bar point adds to its host's force and tangent in small strain
/// ([`crate::elements::bar::bar_point_small_strain`]): f += g σ A w, K += g (E_t A w) gᵀ,
/// added by the host after its own points' terms, so that its tangent memo covers them.
#[derive(Debug, Clone, Copy, Default)]
pub struct BarTerm<'a> {
    /// Strain row g (at least 2n entries; empty: an absent point, which adds nothing).
    pub row: &'a [f64],
    /// σ A w [N].
    pub force: f64,
    /// E_t A w [N].
    pub stiffness: f64,
}

/// One element's pass over its material points: what the points are updated with and
/// where the answer goes; the arguments the small-strain, total Lagrangian and
/// incompatible-mode responses share.
pub struct PointsPass<'c, 'o> {
    /// Thickness [m].
    pub thickness: f64,
    /// Material of every point.
    pub mat: &'c Material,
    /// Committed point states.
    pub committed: &'c [PointState],
    /// The element's nodal displacements (ux, uy per node) [m].
    pub u: &'c [f64],
    /// Internal force (2n) [N], written.
    pub f: &'o mut [f64],
    /// Row-major tangent (2n × 2n) [N/m], formed only when given.
    pub k: Option<&'o mut [f64]>,
    /// Trial point states, written.
    pub trial: &'o mut [PointState],
    /// Gauss outputs, written.
    pub out: &'o mut [GaussOutput],
    /// Time increment of the analysis clock [d].
    pub time: &'c TimeContext,
    /// Imposed (stress-free) normal strain θ [-] of each Gauss point (empty: none).
    pub imposed: &'c [f64],
    /// The node blocks of the tangent to form ([`NodeBlocks::ALL`]: all; the
    /// incompatible-mode element forms all).
    pub blocks: NodeBlocks,
}

impl super::ElementResponse for ContinuumElement<'_> {
    type Committed = [PointState];
    /// The points' trial states and Gauss outputs.
    type Trial<'t> = (&'t mut [PointState], &'t mut [GaussOutput]);

    fn response(
        &self,
        u: &[f64],
        committed: &[PointState],
        (trial, out): Self::Trial<'_>,
        into: super::Response<'_>,
    ) -> Result<bool, UpdateError> {
        let c = self.coords;
        // One pass for all three formulations (the incompatible-mode element forms all
        // node blocks).
        let pass = PointsPass {
            thickness: self.thickness,
            mat: self.material,
            committed,
            u,
            f: into.f,
            k: into.k,
            trial,
            out,
            time: self.time,
            imposed: self.imposed,
            blocks: self.blocks,
        };
        let (kind, integration, tl) = match self.formulation {
            Formulation::SmallStrain { kind, integration } => (kind, integration, false),
            Formulation::TotalLagrangian { kind, integration } => (kind, integration, true),
            Formulation::IncompatibleModes => {
                super::incompatible::response_at(c, pass)?;
                return Ok(true);
            }
        };
        debug_assert!(
            !tl || self.bars.is_empty(),
            "bar terms in small strain only"
        );
        if tl {
            let computed = match self.geometry {
                Some(packed) => {
                    let n = kind.n_nodes();
                    GaussGeometry::unpack(packed, n, (packed.len() - 1) / (2 * n + 1))
                }
                None => gauss_geometry(kind, integration, c),
            };
            super::total_lagrangian::response_tl(kind, &computed, pass)?;
        } else {
            let mut buf = [0.0; PACKED_MAX];
            let packed = match self.geometry {
                Some(packed) => packed,
                None => {
                    let len =
                        gauss_geometry(kind, integration, c).pack_into(kind.n_nodes(), &mut buf);
                    &buf[..len]
                }
            };
            small_strain(kind, packed, pass, (self.memo, self.localised, self.bars))?;
        }
        Ok(true)
    }
}

/// Values computed at one Gauss point for output.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct GaussOutput {
    /// Strain (εx, εy, γxy) [-].
    pub strain: [f64; 3],
    /// Stress (σx, σy, τxy) [Pa].
    pub stress: [f64; 3],
}

/// Strain–displacement matrix rows at one point: (∂N/∂x, ∂N/∂y) per node, and the
/// integration factor w·det J [m²].
fn point_derivatives(
    kind: ElementKind,
    coords: &[[f64; 2]],
    p: &Point2,
) -> ([[f64; 2]; MAX_NODES], f64) {
    let s = kind.eval(p.0, p.1);
    let (_, det, inv) = jacobian(&s, coords);
    (cartesian_derivatives(&s, &inv), det * p.2)
}

/// Smallest det J over the Gauss points and the corners (negative or zero means inverted or
/// degenerate). Corners are included because a Q4 can fold without any Gauss point seeing it.
pub fn min_jacobian(kind: ElementKind, coords: &[[f64; 2]], integration: Integration) -> f64 {
    let mut pts: Vec<(f64, f64)> = rule(kind, integration).iter().map(|p| (p.0, p.1)).collect();
    pts.extend(kind.info().domain.vertices().iter().map(|v| (v[0], v[1])));
    pts.iter()
        .map(|(x, e)| jacobian(&kind.eval(*x, *e), coords).1)
        .fold(f64::INFINITY, f64::min)
}

/// Points per side of the grid [`fold`] samples det J on (ξ, η = −1, −0.75, …, 1 on the
/// square; 0, 0.125, …, 1 on the triangle).
const FOLD_GRID: usize = 9;

/// Where a quadratic element folds inside although det J is positive at its corners and
/// integration points (a mid-side node moved far from the middle of its edge): the smallest
/// det J on a grid of 9 points a side over the element and the grid's edges, and its (ξ, η),
/// if it is not positive. A quadratic element's det J is a polynomial of degree up to 4 in ξ
/// and η that can dip below zero between the Gauss points; the grid's spacing of 1/8 of the
/// element finds any fold reaching about a sixteenth of the element across. A linear kind's
/// det J (Q4: linear in each of ξ, η) is smallest at a corner, which [`min_jacobian`]
/// checks: None.
pub fn fold(kind: ElementKind, coords: &[[f64; 2]]) -> Option<(f64, f64, f64)> {
    let info = kind.info();
    if info.order == 1 {
        return None;
    }
    let mut low = (f64::INFINITY, 0.0, 0.0);
    for [x, e] in info.domain.grid(FOLD_GRID) {
        let d = jacobian(&kind.eval(x, e), coords).1;
        if d.is_nan() || d < low.0 {
            low = (d, x, e);
        }
    }
    (low.0.is_nan() || low.0 <= 0.0).then_some(low)
}

/// The message of a fold found by [`fold`].
pub fn fold_message(f: (f64, f64, f64)) -> String {
    format!(
        "element folds inside: det J = {:.3e} at (ξ, η) = ({:.2}, {:.2}) although positive at its corners and integration points; a mid-side node is too far from the middle of its edge",
        f.0, f.1, f.2
    )
}

/// Element area [m²].
pub fn area(kind: ElementKind, coords: &[[f64; 2]]) -> f64 {
    kind.info()
        .domain
        .exact_rule()
        .iter()
        .map(|p| jacobian(&kind.eval(p.0, p.1), coords).1 * p.2)
        .sum()
}

/// Internal force `f` (2n) and row-major tangent `k` (2n × 2n) of one element, with the trial
/// states and Gauss outputs written to `trial` and `out`. `u` holds the element's nodal
/// displacements (ux, uy per node) [m]; `thickness` [m].
#[allow(clippy::too_many_arguments)]
pub fn response(
    kind: ElementKind,
    integration: Integration,
    coords: &[[f64; 2]],
    thickness: f64,
    mat: &Material,
    committed: &[PointState],
    u: &[f64],
    f: &mut [f64],
    k: &mut [f64],
    trial: &mut [PointState],
    out: &mut [GaussOutput],
) -> Result<(), UpdateError> {
    response_with_time(
        kind,
        integration,
        coords,
        thickness,
        mat,
        committed,
        u,
        f,
        k,
        trial,
        out,
        &TimeContext::default(),
    )
}

/// As [`response`] for the time increment `time` (analysis clock, days), which the
/// material points of time-dependent materials need (creep, shrinkage).
#[allow(clippy::too_many_arguments)]
pub fn response_with_time(
    kind: ElementKind,
    integration: Integration,
    coords: &[[f64; 2]],
    thickness: f64,
    mat: &Material,
    committed: &[PointState],
    u: &[f64],
    f: &mut [f64],
    k: &mut [f64],
    trial: &mut [PointState],
    out: &mut [GaussOutput],
    time: &TimeContext,
) -> Result<(), UpdateError> {
    if integration == Integration::Incompatible {
        debug_assert!(kind.info().incompatible_modes, "checked at input");
        return super::incompatible::response_at(
            coords,
            PointsPass {
                thickness,
                mat,
                committed,
                u,
                f,
                k: Some(k),
                trial,
                out,
                time,
                imposed: &[],
                blocks: NodeBlocks::ALL,
            },
        );
    }
    response_at(
        kind,
        &gauss_geometry(kind, integration, coords),
        PointsPass {
            thickness,
            mat,
            committed,
            u,
            f,
            k: Some(k),
            trial,
            out,
            time,
            imposed: &[],
            blocks: NodeBlocks::ALL,
        },
    )
}

/// The geometry of an element at its Gauss points: for each point of the rule (first
/// `n_pts` entries) the Cartesian shape derivatives (∂N/∂x, ∂N/∂y per node) and w·det J [m²],
/// and the characteristic length h = √(Σ w det J) [m], which the material update may need
/// (crack band). It depends on the undeformed node coordinates only.
#[derive(Debug, Clone, Copy)]
pub struct GaussGeometry {
    /// Points of the rule.
    pub n_pts: usize,
    /// Shape derivatives and w·det J of each point.
    pub points: [([[f64; 2]; MAX_NODES], f64); 9],
    /// Characteristic length [m].
    pub h: f64,
}

impl GaussGeometry {
    /// Append the values for an element of `n` nodes to `out` (point by point: derivatives
    /// then w·det J; h last).
    pub fn pack(&self, n: usize, out: &mut Vec<f64>) {
        for (dn, w) in &self.points[..self.n_pts] {
            for d in &dn[..n] {
                out.extend_from_slice(d);
            }
            out.push(*w);
        }
        out.push(self.h);
    }

    /// Write the values of [`GaussGeometry::pack`] for an element of `n` nodes into the
    /// front of `out` (at least [`PACKED_MAX`] long); their count.
    pub fn pack_into(&self, n: usize, out: &mut [f64]) -> usize {
        let s = 2 * n + 1;
        for (g, (dn, w)) in self.points[..self.n_pts].iter().enumerate() {
            let row = &mut out[g * s..(g + 1) * s];
            for a in 0..n {
                row[2 * a] = dn[a][0];
                row[2 * a + 1] = dn[a][1];
            }
            row[2 * n] = *w;
        }
        out[self.n_pts * s] = self.h;
        self.n_pts * s + 1
    }

    /// The geometry of an element of `n` nodes and `n_pts` points from its packed values
    /// (the same bits as computed).
    pub fn unpack(data: &[f64], n: usize, n_pts: usize) -> Self {
        let mut g = GaussGeometry {
            n_pts,
            points: [([[0.0; 2]; MAX_NODES], 0.0); 9],
            h: data[n_pts * (2 * n + 1)],
        };
        for (p, chunk) in g.points[..n_pts]
            .iter_mut()
            .zip(data.chunks_exact(2 * n + 1))
        {
            for a in 0..n {
                p.0[a] = [chunk[2 * a], chunk[2 * a + 1]];
            }
            p.1 = chunk[2 * n];
        }
        g
    }
}

/// The most values [`GaussGeometry::pack`] writes: 9 points of 9 nodes and h.
pub const PACKED_MAX: usize = 9 * (2 * MAX_NODES + 1) + 1;

/// The Gauss-point geometry of an element of `kind` with nodes at `coords` under the rule
/// `integration` (computed for all points before any material update).
pub fn gauss_geometry(
    kind: ElementKind,
    integration: Integration,
    coords: &[[f64; 2]],
) -> GaussGeometry {
    let pts = rule_points(kind, integration);
    let mut geo = [([[0.0; 2]; MAX_NODES], 0.0); 9];
    let mut area = 0.0;
    for (g, p) in pts.iter().enumerate() {
        geo[g] = point_derivatives(kind, coords, p);
        area += geo[g].1;
    }
    GaussGeometry {
        n_pts: pts.len(),
        points: geo,
        h: area.sqrt(),
    }
}

/// As [`response_with_time`] for an element of `kind` whose Gauss-point geometry (full or
/// reduced rule) is `geometry` ([`gauss_geometry`]); the tangent is formed only when `k` is
/// given (a residual check or a stress recovery needs forces and stresses alone). `imposed`
/// holds the stress-free normal strain θ of each Gauss point (empty: none): the material
/// sees ε − θ (1, 1, 0), the output keeps the total strain ε. Only the node blocks `blocks`
/// of the tangent are formed (the others are zero; [`NodeBlocks::ALL`]: all).
pub fn response_at(
    kind: ElementKind,
    geometry: &GaussGeometry,
    pass: PointsPass<'_, '_>,
) -> Result<(), UpdateError> {
    let mut buf = [0.0; PACKED_MAX];
    let len = geometry.pack_into(kind.n_nodes(), &mut buf);
    small_strain(kind, &buf[..len], pass, (&[], false, &[]))
}

/// [`response_at`] with the Gauss geometry `packed` ([`GaussGeometry::pack`], read in
/// place) and the element's tangent memo `memo` ([`TangentMemo`]; empty: none): when every
/// point's tangent D has the bits of the memo's, the tangent is the memo's (the same
/// function of the same values), else it is formed and kept there. Dispatches on the
/// kind's node count and the rule's point count, so that the loops over nodes and points
/// have fixed trip counts ([`small_strain_fixed`]).
fn small_strain(
    kind: ElementKind,
    packed: &[f64],
    pass: PointsPass<'_, '_>,
    memo: (&[Cell<f64>], bool, &[BarTerm]),
) -> Result<(), UpdateError> {
    let n = kind.n_nodes();
    let n_pts = (packed.len() - 1) / (2 * n + 1);
    debug_assert_eq!(packed.len(), n_pts * (2 * n + 1) + 1, "packed geometry");
    macro_rules! fixed {
        ($n:literal, $p:literal) => {
            small_strain_fixed::<$n, $p>(packed, pass, memo)
        };
    }
    match (n, n_pts) {
        (4, 4) => fixed!(4, 4),
        (8, 9) => fixed!(8, 9),
        (8, 4) => fixed!(8, 4),
        (9, 9) => fixed!(9, 9),
        (9, 4) => fixed!(9, 4),
        (6, 3) => fixed!(6, 3),
        // Every kind and rule is above; any other pair would take this general path.
        _ => small_strain_any(n, n_pts, packed, pass, memo),
    }
}

/// [`small_strain`] for `N` nodes and `P` points (fixed trip counts).
fn small_strain_fixed<const N: usize, const P: usize>(
    packed: &[f64],
    pass: PointsPass<'_, '_>,
    memo: (&[Cell<f64>], bool, &[BarTerm]),
) -> Result<(), UpdateError> {
    small_strain_any(N, P, packed, pass, memo)
}

/// [`small_strain`] for `n` nodes and `n_pts` points; inlined into [`small_strain_fixed`]
/// with constant `n` and `n_pts`.
#[inline(always)]
fn small_strain_any(
    n: usize,
    n_pts: usize,
    packed: &[f64],
    pass: PointsPass<'_, '_>,
    (memo, localised, bars): (&[Cell<f64>], bool, &[BarTerm]),
) -> Result<(), UpdateError> {
    let PointsPass {
        thickness,
        mat,
        committed,
        u,
        f,
        mut k,
        trial,
        out,
        time,
        imposed,
        blocks,
    } = pass;
    let nd = 2 * n;
    // One point's values: (∂N/∂x, ∂N/∂y) of every node, then w·det J.
    let s = nd + 1;
    let (u, f) = (&u[..nd], &mut f[..nd]);
    f.iter_mut().for_each(|v| *v = 0.0);
    if let Some(k) = k.as_deref_mut() {
        k[..nd * nd].iter_mut().for_each(|v| *v = 0.0);
    }
    let geo = &packed[..n_pts * s];
    let h = packed[n_pts * s];
    // Size-dependent material constants once per element (same values as per point).
    let local = if localised {
        None
    } else {
        crate::materials::point::for_element(mat, h)?
    };
    let mat = local.as_ref().unwrap_or(mat);
    // Tangents and weights of the points, for the stiffness after all updates.
    let mut tangents = [[[0.0; 3]; 3]; 9];
    let mut weights = [0.0; 9];
    for g in 0..n_pts {
        let pt = &geo[g * s..(g + 1) * s];
        let wdet = pt[nd];
        let mut eps = [0.0; 3];
        for a in 0..n {
            let (dx, dy) = (pt[2 * a], pt[2 * a + 1]);
            let (ux, uy) = (u[2 * a], u[2 * a + 1]);
            eps[0] += dx * ux;
            eps[1] += dy * uy;
            eps[2] += dy * ux + dx * uy;
        }
        // Into the trial slot: no allocation of a new boxed concrete state per point.
        let mech = mechanical(eps, imposed, g);
        let (sig, d) = update_into(mat, &committed[g], &mech, h, time, &mut trial[g])?;
        out[g] = GaussOutput {
            strain: eps,
            stress: sig,
        };
        let w = wdet * thickness;
        // B_a = [[dx, 0], [0, dy], [dy, dx]]; f_a = Bᵀσ; K_ab = B_aᵀ D B_b.
        for a in 0..n {
            let (ax, ay) = (pt[2 * a], pt[2 * a + 1]);
            f[2 * a] += w * (ax * sig[0] + ay * sig[2]);
            f[2 * a + 1] += w * (ay * sig[1] + ax * sig[2]);
        }
        tangents[g] = d;
        weights[g] = w;
    }
    // The embedded bars, in their order: f += g σ A w.
    for bar in bars.iter().filter(|b| !b.row.is_empty()) {
        let g = &bar.row[..nd];
        for r in 0..nd {
            f[r] += g[r] * bar.force;
        }
    }
    let Some(k) = k else {
        return Ok(());
    };
    let k = &mut k[..nd * nd];
    let memo = TangentMemo::of(memo, n, n_pts, blocks, bars.len());
    if let Some(m) = memo {
        if m.holds(&tangents[..n_pts], bars) {
            m.copy_into(k, n, blocks);
            return Ok(());
        }
    }
    // Rows of B_aᵀ D (2×3) of every point and node; then K_ab = Σ_g w B_aᵀ D B_b block
    // by block, summed over the points in their order in registers (the operations of
    // adding point by point into K).
    for a in 0..n {
        let mut rs = [[0.0; 6]; 9];
        for g in 0..n_pts {
            let d = &tangents[g];
            let (ax, ay) = (geo[g * s + 2 * a], geo[g * s + 2 * a + 1]);
            rs[g] = [
                ax * d[0][0] + ay * d[2][0],
                ax * d[0][1] + ay * d[2][1],
                ax * d[0][2] + ay * d[2][2],
                ay * d[1][0] + ax * d[2][0],
                ay * d[1][1] + ax * d[2][1],
                ay * d[1][2] + ax * d[2][2],
            ];
        }
        for b in 0..n {
            if !blocks.has(a, b) {
                continue;
            }
            let mut acc = [0.0; 4];
            for g in 0..n_pts {
                let (r, w) = (&rs[g], weights[g]);
                let (bx, by) = (geo[g * s + 2 * b], geo[g * s + 2 * b + 1]);
                acc[0] += w * (r[0] * bx + r[2] * by);
                acc[1] += w * (r[1] * by + r[2] * bx);
                acc[2] += w * (r[3] * bx + r[5] * by);
                acc[3] += w * (r[4] * by + r[5] * bx);
            }
            let (row0, row1) = (2 * a * nd, (2 * a + 1) * nd);
            k[row0 + 2 * b] = acc[0];
            k[row0 + 2 * b + 1] = acc[1];
            k[row1 + 2 * b] = acc[2];
            k[row1 + 2 * b + 1] = acc[3];
        }
    }
    // The bars' K += g (E_t A w) gᵀ, row by row (rows with a zero factor add nothing).
    for bar in bars.iter().filter(|b| !b.row.is_empty()) {
        let g = &bar.row[..nd];
        for r in 0..nd {
            let gr = g[r] * bar.stiffness;
            if gr != 0.0 {
                for c in 0..nd {
                    k[r * nd + c] += gr * g[c];
                }
            }
        }
    }
    if let Some(m) = memo {
        m.keep(&tangents[..n_pts], bars, k, n, blocks);
    }
    Ok(())
}

/// One small-strain element's tangent memo: its points' tangents D and its bar points'
/// stiffness factors E_t A w ([`BarTerm`]) when its tangent was last formed, and the wanted
/// node blocks of that tangent ([`NodeBlocks`]). In small strain the tangent is a function
/// of the points' D and the bars' factors alone (the geometry, weights, bar strain rows and
/// blocks do not change), so where every D and factor has the memo's bits the tangent has
/// the memo's bits too, and its B_aᵀ D B_b sums and the bars' outer products are skipped:
/// the elastic elements of a cracking model, and IMPL-EX cracked points, whose tangent
/// comes from the committed state, repeat theirs at every iteration of an increment, and an
/// elastic or yielded bar its E_t. An absent bar point (no row) and one of factor zero add
/// nothing to the tangent; both are kept as 0. Layout (f64 values, [`TangentMemo::len`]):
/// a flag (1: filled), the n_pts × 9 entries of the D's, the bars' factors, then 4 entries
/// per wanted block (a, b) in the order a, then b.
#[derive(Clone, Copy)]
pub struct TangentMemo<'a> {
    cells: &'a [Cell<f64>],
    n_pts: usize,
    n_bars: usize,
}

impl<'a> TangentMemo<'a> {
    /// Values of the memo of an element of `n` nodes, `n_pts` points, `n_bars` embedded bar
    /// points and wanted `blocks`.
    pub fn len(n: usize, n_pts: usize, blocks: NodeBlocks, n_bars: usize) -> usize {
        1 + 9 * n_pts + n_bars + 4 * blocks.count(n)
    }

    /// The memo in `cells` if it has the length of one for this element (else none).
    fn of(
        cells: &'a [Cell<f64>],
        n: usize,
        n_pts: usize,
        blocks: NodeBlocks,
        n_bars: usize,
    ) -> Option<Self> {
        (!cells.is_empty() && cells.len() == Self::len(n, n_pts, blocks, n_bars)).then_some(Self {
            cells,
            n_pts,
            n_bars,
        })
    }

    /// A bar's factor as kept: E_t A w, or 0 for an absent point.
    fn factor(bar: &BarTerm) -> f64 {
        if bar.row.is_empty() {
            0.0
        } else {
            bar.stiffness
        }
    }

    /// Whether the memo is filled and its D's and bar factors have the bits of `tangents`
    /// and `bars`.
    fn holds(&self, tangents: &[[[f64; 3]; 3]], bars: &[BarTerm]) -> bool {
        if self.cells[0].get() != 1.0 {
            return false;
        }
        let kept = &self.cells[1..1 + 9 * tangents.len()];
        for (d, c) in tangents.iter().zip(kept.chunks_exact(9)) {
            for i in 0..3 {
                for j in 0..3 {
                    if d[i][j].to_bits() != c[3 * i + j].get().to_bits() {
                        return false;
                    }
                }
            }
        }
        let kept = &self.cells[1 + 9 * self.n_pts..1 + 9 * self.n_pts + self.n_bars];
        bars.iter()
            .zip(kept)
            .all(|(b, c)| Self::factor(b).to_bits() == c.get().to_bits())
    }

    /// Write the kept blocks into the (zeroed) element matrix `k` of `n` nodes.
    fn copy_into(&self, k: &mut [f64], n: usize, blocks: NodeBlocks) {
        let nd = 2 * n;
        let mut kept = self.cells[1 + 9 * self.n_pts + self.n_bars..].chunks_exact(4);
        // Rows 2a and 2a + 1 of K, block by block in the order of [`NodeBlocks::each`].
        for (a, rows) in k[..nd * nd].chunks_exact_mut(2 * nd).enumerate() {
            let (k0, k1) = rows.split_at_mut(nd);
            let mut row = blocks.row(a, n);
            while row != 0 {
                let b = row.trailing_zeros() as usize;
                row &= row - 1;
                let Some(c) = kept.next() else {
                    return;
                };
                k0[2 * b] = c[0].get();
                k0[2 * b + 1] = c[1].get();
                k1[2 * b] = c[2].get();
                k1[2 * b + 1] = c[3].get();
            }
        }
    }

    /// Keep `tangents`, the factors of `bars` and the wanted blocks of the element matrix
    /// `k` formed from them.
    fn keep(
        &self,
        tangents: &[[[f64; 3]; 3]],
        bars: &[BarTerm],
        k: &[f64],
        n: usize,
        blocks: NodeBlocks,
    ) {
        let kept = &self.cells[1..1 + 9 * tangents.len()];
        for (d, c) in tangents.iter().zip(kept.chunks_exact(9)) {
            for i in 0..3 {
                for j in 0..3 {
                    c[3 * i + j].set(d[i][j]);
                }
            }
        }
        let start = 1 + 9 * self.n_pts;
        for (c, b) in self.cells[start..start + self.n_bars].iter().zip(bars) {
            c.set(Self::factor(b));
        }
        let nd = 2 * n;
        let mut kept = self.cells[start + self.n_bars..].chunks_exact(4);
        for (a, rows) in k[..nd * nd].chunks_exact(2 * nd).enumerate() {
            let (k0, k1) = rows.split_at(nd);
            let mut row = blocks.row(a, n);
            while row != 0 {
                let b = row.trailing_zeros() as usize;
                row &= row - 1;
                let Some(c) = kept.next() else {
                    return;
                };
                c[0].set(k0[2 * b]);
                c[1].set(k0[2 * b + 1]);
                c[2].set(k1[2 * b]);
                c[3].set(k1[2 * b + 1]);
            }
        }
        self.cells[0].set(1.0);
    }
}

/// The node blocks (a, b) of an element matrix that are wanted: bit 9a + b (a, b < 9). The
/// assembly adds only the lower triangle of the global matrix, i.e. for a symmetric
/// element matrix one of the blocks (a, b), (b, a) of each node pair; the element forms
/// the blocks it is asked for (the others stay zero) with the operations of the full
/// matrix, so the assembled values are the same bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NodeBlocks(pub u128);

impl NodeBlocks {
    /// Every block.
    pub const ALL: NodeBlocks = NodeBlocks(u128::MAX);

    /// Whether block (a, b) is wanted.
    #[inline]
    pub fn has(self, a: usize, b: usize) -> bool {
        self.0 >> (9 * a + b) & 1 == 1
    }

    /// The wanted blocks (a, b) of row `a` of an element of `n` nodes: bit b.
    #[inline]
    pub fn row(self, a: usize, n: usize) -> u64 {
        (self.0 >> (9 * a)) as u64 & ((1 << n) - 1)
    }

    /// The number of wanted blocks of an element of `n` nodes.
    #[inline]
    pub fn count(self, n: usize) -> usize {
        (0..n)
            .map(|a| ((self.0 >> (9 * a)) as u64 & ((1 << n) - 1)).count_ones() as usize)
            .sum()
    }

    /// Call `f(a, b)` for every wanted block of an element of `n` nodes, a then b
    /// ascending (the order of testing [`NodeBlocks::has`] over a, then b).
    #[inline]
    pub fn each(self, n: usize, mut f: impl FnMut(usize, usize)) {
        for a in 0..n {
            let mut row = (self.0 >> (9 * a)) as u64 & ((1 << n) - 1);
            while row != 0 {
                f(a, row.trailing_zeros() as usize);
                row &= row - 1;
            }
        }
    }
}

/// The strain the material law sees at Gauss point `g`: the total strain `eps` less the
/// imposed normal strain θ_g (1, 1, 0) when there is one (`imposed` empty: `eps` itself).
#[inline]
pub(crate) fn mechanical(eps: [f64; 3], imposed: &[f64], g: usize) -> [f64; 3] {
    match imposed.get(g) {
        Some(&t) if t != 0.0 => [eps[0] - t, eps[1] - t, eps[2]],
        _ => eps,
    }
}

/// Consistent nodal forces [N] of a body force b [N/m³] (e.g. ρ g) over the element.
pub fn body_force(kind: ElementKind, coords: &[[f64; 2]], thickness: f64, b: [f64; 2]) -> Vec<f64> {
    let n = kind.n_nodes();
    let mut f = vec![0.0; 2 * n];
    for p in kind.info().domain.exact_rule() {
        let s = kind.eval(p.0, p.1);
        let (_, det, _) = jacobian(&s, coords);
        let w = det * p.2 * thickness;
        for a in 0..n {
            f[2 * a] += w * s.n_val[a] * b[0];
            f[2 * a + 1] += w * s.n_val[a] * b[1];
        }
    }
    f
}

/// Consistent nodal forces [N] of a uniform line load q [N/m] (per unit length of edge,
/// thickness already included) on an edge with node coordinates ordered (start, end, [mid]).
pub fn edge_force(edge_coords: &[[f64; 2]], q: [f64; 2]) -> Vec<f64> {
    edge_force_partial(edge_coords, q, -1.0, 1.0)
}

/// As [`edge_force`], loading only the part r ∈ [r0, r1] of the edge (r ∈ [−1, 1] the edge's
/// natural coordinate), for line loads that end inside an element edge.
pub fn edge_force_partial(edge_coords: &[[f64; 2]], q: [f64; 2], r0: f64, r1: f64) -> Vec<f64> {
    let m = edge_coords.len();
    let mut f = vec![0.0; 2 * m];
    let r = gauss(3);
    let half = 0.5 * (r1 - r0);
    for (xg, wg) in r.points.iter().zip(&r.weights) {
        let x = &(r0 + half * (xg + 1.0));
        let w = wg * half;
        let (nv, dn) = line_shape(m, *x);
        let (mut dx, mut dy) = (0.0, 0.0);
        for a in 0..m {
            dx += dn[a] * edge_coords[a][0];
            dy += dn[a] * edge_coords[a][1];
        }
        let j = (dx * dx + dy * dy).sqrt();
        for a in 0..m {
            f[2 * a] += w * j * nv[a] * q[0];
            f[2 * a + 1] += w * j * nv[a] * q[1];
        }
    }
    f
}

/// Gauss-point values extrapolated to the element's nodes: the tensor-product Lagrange
/// interpolant through the Gauss points (2×2 or 3×3) evaluated at each node.
pub fn extrapolate_to_nodes(
    kind: ElementKind,
    integration: Integration,
    gp_values: &[[f64; 3]],
) -> Vec<[f64; 3]> {
    let w = extrapolation_weights(kind, integration);
    (0..kind.n_nodes())
        .map(|a| {
            let mut v = [0.0; 3];
            for (g, val) in gp_values.iter().enumerate() {
                for c in 0..3 {
                    v[c] += w[a][g] * val[c];
                }
            }
            v
        })
        .collect()
}

/// Weights of [`extrapolate_to_nodes`]: value at node a = Σ_g w\[a\]\[g\] · value at Gauss
/// point g, from the kind's descriptor. Computed once per element kind and rule (the output
/// loop must not redo it for every element).
pub fn extrapolation_weights(
    kind: ElementKind,
    integration: Integration,
) -> &'static [[f64; 9]; MAX_NODES] {
    static TABLES: std::sync::OnceLock<Vec<[[f64; 9]; MAX_NODES]>> = std::sync::OnceLock::new();
    let tables = TABLES.get_or_init(|| {
        let mut t = Vec::new();
        for kind in crate::fem::kinds::ALL {
            for integration in [Integration::Full, Integration::Reduced] {
                t.push((kind.info().extrapolation)(rule_points(kind, integration)));
            }
        }
        t
    });
    let k = crate::fem::kinds::ALL
        .iter()
        .position(|k| *k == kind)
        .expect("every kind is in ALL");
    &tables[2 * k + usize::from(integration == Integration::Reduced)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::materials::concrete::ConcreteParams;

    /// The element matrix of a distorted Q8 of MC90 concrete under the uniform strain
    /// εx = `ex` (nodal displacements ux = ex x), formed with the memo `memo` (empty: none).
    fn q8_matrix(ex: f64, memo: &[Cell<f64>], blocks: NodeBlocks) -> Vec<f64> {
        q8_matrix_with(ex, memo, blocks, &[])
    }

    /// [`q8_matrix`] with embedded bar terms `bars`.
    fn q8_matrix_with(
        ex: f64,
        memo: &[Cell<f64>],
        blocks: NodeBlocks,
        bars: &[BarTerm],
    ) -> Vec<f64> {
        let kind = ElementKind::Q8;
        let coords: Vec<[f64; 2]> = kind
            .info()
            .node_xi
            .iter()
            .map(|[x, e]| [0.4 + 0.2 * x + 0.03 * x * e, 0.15 * e + 0.01 * x])
            .collect();
        let mat = Material::Concrete {
            params: Box::new(ConcreteParams::from_mc90(38e6, 0.2)),
            density: 0.0,
        };
        let geo = gauss_geometry(kind, Integration::Full, &coords);
        let committed = vec![mat.initial_state(); geo.n_pts];
        let mut trial = committed.clone();
        let mut out = vec![GaussOutput::default(); geo.n_pts];
        let u: Vec<f64> = coords.iter().flat_map(|c| [ex * c[0], 0.0]).collect();
        let (mut f, mut k) = (vec![0.0; 16], vec![f64::NAN; 256]);
        let mut packed = Vec::new();
        geo.pack(8, &mut packed);
        small_strain(
            kind,
            &packed,
            PointsPass {
                thickness: 0.25,
                mat: &mat,
                committed: &committed,
                u: &u,
                f: &mut f,
                k: Some(&mut k),
                trial: &mut trial,
                out: &mut out,
                time: &TimeContext::default(),
                imposed: &[],
                blocks,
            },
            (memo, false, bars),
        )
        .unwrap();
        k
    }

    /// The memo gives the tangent formed without it, bit for bit: filled on an elastic
    /// strain, taken at a second elastic strain (the same D), and not taken once the
    /// points crack (their D changes: the tangent formed anew, not the elastic one kept).
    #[test]
    fn tangent_memo_gives_the_formed_tangent() {
        // The lower triangle of node blocks, as the assembly wants of a symmetric matrix.
        let mut bits = 0u128;
        for a in 0..8 {
            for b in 0..=a {
                bits |= 1 << (9 * a + b);
            }
        }
        let blocks = NodeBlocks(bits);
        // 1 + 9 points × 9 entries of D + 36 blocks × 4.
        let len = TangentMemo::len(8, 9, blocks, 0);
        assert_eq!(len, 1 + 81 + 144);
        let mut store = vec![0.0; len];
        let memo = Cell::from_mut(store.as_mut_slice()).as_slice_of_cells();
        let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        // Elastic (εx = 2e-5, a fifth of the cracking strain of C30-ish concrete).
        let fresh = q8_matrix(2e-5, &[], blocks);
        assert!(same(&q8_matrix(2e-5, memo, blocks), &fresh));
        assert_eq!(memo[0].get(), 1.0, "filled");
        // Another elastic strain: same D, the memo's tangent.
        assert!(same(
            &q8_matrix(-4e-5, memo, blocks),
            &q8_matrix(-4e-5, &[], blocks)
        ));
        // Cracked (εx = 1e-3, ten times the cracking strain): a new D and a new tangent.
        let cracked = q8_matrix(1e-3, &[], blocks);
        assert!(!same(&cracked, &fresh), "cracking changes the tangent");
        assert!(same(&q8_matrix(1e-3, memo, blocks), &cracked));
    }

    /// The lower triangle of node blocks of a Q8, as the assembly wants of a symmetric
    /// matrix.
    fn lower_q8() -> NodeBlocks {
        let mut bits = 0u128;
        for a in 0..8 {
            for b in 0..=a {
                bits |= 1 << (9 * a + b);
            }
        }
        NodeBlocks(bits)
    }

    /// A bar point's terms are in the memo: the memo's tangent with a bar is the one formed
    /// without the memo, and both differ from the concrete's alone by g (E_t A w) gᵀ on
    /// every wanted entry (to 1e-15 of the largest entry: one addition of a value below
    /// it); a bar whose factor changes (yield: E_t drops) takes a new tangent, an absent
    /// one (no row) adds nothing. (With zero initial yield the compressed points flow, so
    /// the concrete's own tangent changes between the strains too.)
    #[test]
    fn tangent_memo_covers_the_bars() {
        let blocks = lower_q8();
        let row: Vec<f64> = (0..16).map(|r| ((r as f64) * 0.7).sin() * 3.0).collect();
        let bar = |stiffness: f64| BarTerm {
            row: &row,
            force: 1e5,
            stiffness,
        };
        let len = TangentMemo::len(8, 9, blocks, 1);
        assert_eq!(len, 1 + 81 + 1 + 144);
        let mut store = vec![0.0; len];
        let memo = Cell::from_mut(store.as_mut_slice()).as_slice_of_cells();
        let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        for (ks, ex) in [(4e6, 2e-5), (4e6, -4e-5), (4e4, -4e-5)] {
            let plain = q8_matrix(ex, &[], blocks);
            let scale = plain.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let fresh = q8_matrix_with(ex, &[], blocks, &[bar(ks)]);
            assert!(same(&q8_matrix_with(ex, memo, blocks, &[bar(ks)]), &fresh));
            assert_eq!(store_factor(memo), ks, "the bar's factor kept");
            blocks.each(8, |a, b| {
                for (r, c) in [
                    (2 * a, 2 * b),
                    (2 * a, 2 * b + 1),
                    (2 * a + 1, 2 * b),
                    (2 * a + 1, 2 * b + 1),
                ] {
                    let added = fresh[16 * r + c] - plain[16 * r + c];
                    let expected = row[r] * ks * row[c];
                    assert!(
                        (added - expected).abs() <= 1e-15 * scale,
                        "entry ({r}, {c})"
                    );
                }
            });
        }
        // An absent bar point: the concrete's tangent alone.
        let absent = BarTerm::default();
        let plain = q8_matrix(2e-5, &[], blocks);
        assert!(same(&q8_matrix_with(2e-5, memo, blocks, &[absent]), &plain));
    }

    /// The kept factor of the first bar of a memo of a Q8 of 9 points.
    fn store_factor(memo: &[Cell<f64>]) -> f64 {
        memo[1 + 81].get()
    }
}
