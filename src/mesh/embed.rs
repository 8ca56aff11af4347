//! Bar paths and their embedding in a mesh (Elwi & Hrudey 1989; docs/theory-bars.md).
//!
//! A bar (or bonded tendon) is described in global coordinates independently of the mesh by a
//! [`BarPath`]. [`embed`] (or [`BarEmbedder::embed`] for many bars on one mesh) cuts the path
//! where it crosses element boundaries ("march and bisect") and returns one [`BarPiece`] per
//! element traversed, each with Gauss points ([`BarPoint`]) in the piece's local coordinate
//! r ∈ [−1, 1]. The response of a bar point (perfect bond: the bar strain is the host's strain
//! projected on the bar direction) is in [`crate::elements::bar`]; this module is geometry only
//! and is used by the model-file builder.
//!
//! Units: lengths in metres (any consistent set works; nothing here depends on the unit
//! system).
//!
//! Two point placements are offered ([`Placement`]):
//! * [`Placement::OnPath`] (default): each Gauss point is the image of its r on the true path
//!   (path parameter linear in r), inverse-mapped into the host; the direction and |dx/dr| come
//!   from the path itself. Lengths of straight and circular bars are exact.
//! * [`Placement::Lagrange3`]: the classic Elwi–Hrudey representation: the entry, middle and exit
//!   points are mapped to (ξ_k, η_k) and the piece is ξ(r) = Σ L_k(r) ξ_k, η(r) = Σ L_k(r) η_k;
//!   direction and |dx/dr| follow from dx/dr = Jᵀ dξ/dr.
//!
//! In both cases the three natural-coordinate nodes (n_b = 3) are stored in
//! [`BarPiece::nat_nodes`]; in the on-path placement they serve as starting guesses for the
//! Newton inverse mapping.

use crate::fem::shape::{jacobian, line_shape, map_point};
use crate::model::BarPoint;
use crate::model::ElementKind;
use serde::{Deserialize, Serialize};

/// Tolerance of the inside test in natural coordinates: a point is in an element when it is
/// in the kind's reference domain grown by `INSIDE_TOL` (on the square |ξ|, |η| ≤ 1 +
/// `INSIDE_TOL`); absorbs the round-off of points found on element edges.
pub const INSIDE_TOL: f64 = 1e-9;

/// Inside tolerance used while marching and bisecting for an exit point: much tighter than
/// [`INSIDE_TOL`] so that the cut lies on the element edge to round-off (a loose tolerance would
/// let a piece run ~1e-9·h past the edge and perturb the nodal forces at that level).
const EXIT_TOL: f64 = 1e-13;

/// Bisection stops when the bracket in the segment parameter t ∈ [0, 1] is below this value
/// (exit points are located to 1e-14 × segment length, far below any engineering tolerance).
const BISECT_TOL_T: f64 = 1e-14;

/// Two candidate exit parameters closer than this are a tie (bar along a shared edge); the
/// element with the lower index is then chosen, so the bar is counted once.
const TIE_TOL_T: f64 = 1e-10;

/// Pieces shorter than this fraction of the host size (e.g. a bar clipping a corner) are dropped.
const SLIVER_REL: f64 = 1e-11;

/// A bar path in global coordinates [m].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum BarPath {
    /// Straight segments through the given points [m] (at least two distinct points).
    Polyline(Vec<[f64; 2]>),
    /// Quadratic curve x(t) = Σ L_k(t) P_k through start P_0 (t = 0), a middle point P_1
    /// (t = ½) and end P_2 (t = 1) [m].
    Quadratic([[f64; 2]; 3]),
    /// Parabola between `start` and `end` [m] whose mid-chord offset is `sag` [m], measured along
    /// the left normal of the chord (positive = to the left when walking from start to end;
    /// a tendon draped downwards from left to right has a negative sag). Same as `Quadratic`
    /// with P_1 = mid-chord + sag·n.
    Parabola {
        /// Start point [m].
        start: [f64; 2],
        /// End point [m].
        end: [f64; 2],
        /// Mid-chord offset along the chord's left normal [m].
        sag: f64,
    },
    /// Circular arc: centre [m], radius [m] and polar angles [rad] of the start and end points;
    /// runs counter-clockwise if `theta_end > theta_start`, clockwise otherwise.
    Arc {
        /// Centre [m].
        center: [f64; 2],
        /// Radius [m] (> 0).
        radius: f64,
        /// Polar angle of the start point [rad].
        theta_start: f64,
        /// Polar angle of the end point [rad].
        theta_end: f64,
    },
    /// Several of the paths above joined end to end (e.g. straight – parabola – straight for
    /// a post-tensioned tendon): each part must start where the previous one ends (within
    /// 1e-9 of the path size); kinks between parts are allowed. Parts may not be chains.
    Chain(Vec<BarPath>),
}

/// A host element: kind and nodal coordinates [m] in VTK order (`kind.n_nodes()` entries).
#[derive(Debug, Clone, Copy)]
pub struct HostElement<'a> {
    /// Element kind.
    pub kind: ElementKind,
    /// Nodal coordinates [m].
    pub coords: &'a [[f64; 2]],
}

/// The part of a bar inside one host element.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BarPiece {
    /// Index of the host element in the slice given to [`embed`].
    pub element: usize,
    /// Gauss points along the piece, ordered with r.
    pub points: Vec<BarPoint>,
    /// Length of the piece [m] (exact arc length of the path between entry and exit).
    pub length: f64,
    /// Arc-length range (entry, exit) from the path start [m].
    pub s_range: (f64, f64),
    /// Index of the path segment (polyline segment; 0 for curves) containing the piece.
    pub segment: usize,
    /// Range of the segment parameter t ∈ [0, 1] covered by the piece [-].
    pub t_range: (f64, f64),
    /// Natural coordinates (ξ, η) of the entry, exit and middle points (the n_b = 3
    /// representation, in `line_shape` order: r = −1, +1, 0).
    pub nat_nodes: [[f64; 2]; 3],
}

/// How Gauss points are placed along a piece (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Placement {
    /// Points on the true path, inverse-mapped (exact length for straight and circular bars).
    #[default]
    OnPath,
    /// Classic Elwi–Hrudey 3-point Lagrange interpolation of (ξ, η) in r.
    Lagrange3,
}

/// Errors of the embedding.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BarError {
    /// A point of the path lies outside every host element.
    #[error("bar path leaves the mesh at x = ({x:.6}, {y:.6}) m (arc length s = {s:.6} m)")]
    OutsideMesh {
        /// x coordinate [m].
        x: f64,
        /// y coordinate [m].
        y: f64,
        /// Arc length from the path start [m].
        s: f64,
    },
    /// The path description is invalid (too few points, non-finite values, zero radius …).
    #[error("invalid bar path: {0}")]
    InvalidPath(String),
    /// A host element is malformed (wrong node count, non-finite or degenerate coordinates).
    #[error("host element {element}: {reason}")]
    BadHost {
        /// Host index.
        element: usize,
        /// What is wrong.
        reason: String,
    },
    /// Invalid option (e.g. zero Gauss points).
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// Newton inverse mapping failed for a point found inside an element (badly shaped element).
    #[error("inverse mapping failed in host element {element} at x = ({x:.6}, {y:.6}) m")]
    InverseMap {
        /// Host index.
        element: usize,
        /// x coordinate [m].
        x: f64,
        /// y coordinate [m].
        y: f64,
    },
}

// ------------------------------------------------------------------------------------------
// Quadrature
// ------------------------------------------------------------------------------------------

/// Gauss–Legendre rule with `n` ≥ 1 points on [−1, 1] (points ascending, weights summing to 2),
/// computed by Newton iteration on the Legendre recurrence (accurate to ~1e-15 for n ≤ 64).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n.div_ceil(2) {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            // p1 = P_n(z), p0 = P_{n−1}(z)
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = -z;
        x[n - 1 - i] = z;
        let wi = 2.0 / ((1.0 - z * z) * dp * dp);
        w[i] = wi;
        w[n - 1 - i] = wi;
    }
    if n % 2 == 1 {
        x[n / 2] = 0.0;
    }
    (x, w)
}

// ------------------------------------------------------------------------------------------
// Path geometry
// ------------------------------------------------------------------------------------------

/// One smooth piece of a path with parameter t ∈ [0, 1].
#[derive(Debug, Clone, Copy)]
enum Seg {
    Line([f64; 2], [f64; 2]),
    /// x(t) = a + b t + c t².
    Quad([f64; 2], [f64; 2], [f64; 2]),
    Arc {
        c: [f64; 2],
        r: f64,
        th0: f64,
        th1: f64,
    },
}

impl Seg {
    fn pos(&self, t: f64) -> [f64; 2] {
        match *self {
            Seg::Line(a, b) => [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])],
            Seg::Quad(a, b, c) => [a[0] + t * (b[0] + t * c[0]), a[1] + t * (b[1] + t * c[1])],
            Seg::Arc { c, r, th0, th1 } => {
                let th = th0 + t * (th1 - th0);
                [c[0] + r * th.cos(), c[1] + r * th.sin()]
            }
        }
    }

    /// dx/dt.
    fn deriv(&self, t: f64) -> [f64; 2] {
        match *self {
            Seg::Line(a, b) => [b[0] - a[0], b[1] - a[1]],
            Seg::Quad(_, b, c) => [b[0] + 2.0 * t * c[0], b[1] + 2.0 * t * c[1]],
            Seg::Arc { r, th0, th1, .. } => {
                let th = th0 + t * (th1 - th0);
                let d = th1 - th0;
                [-r * d * th.sin(), r * d * th.cos()]
            }
        }
    }

    /// Upper bound of |dx/dt| on [0, 1].
    fn max_speed(&self) -> f64 {
        match self {
            // |x'|² is a convex quadratic in t for Quad: maximum at an end.
            Seg::Quad(..) => norm(self.deriv(0.0)).max(norm(self.deriv(1.0))),
            _ => norm(self.deriv(0.0)),
        }
    }

    /// Arc length from t = 0 to t [m].
    fn arc_length(&self, t: f64) -> f64 {
        match self {
            Seg::Line(..) | Seg::Arc { .. } => norm(self.deriv(0.0)) * t,
            Seg::Quad(..) => {
                // Composite 10-point Gauss (4 sub-intervals) of a smooth integrand; |x'| is the
                // square root of a positive quadratic, integrated to ~1e-14 relative.
                let (gx, gw) = gauss_legendre(10);
                let mut s = 0.0;
                let m = 4;
                let h = t / m as f64;
                for j in 0..m {
                    let t0 = j as f64 * h;
                    for (x, w) in gx.iter().zip(&gw) {
                        s += 0.5 * h * w * norm(self.deriv(t0 + 0.5 * h * (x + 1.0)));
                    }
                }
                s
            }
        }
    }
}

fn norm(v: [f64; 2]) -> f64 {
    v[0].hypot(v[1])
}

fn unit(v: [f64; 2]) -> [f64; 2] {
    let l = norm(v);
    [v[0] / l, v[1] / l]
}

/// Unsigned angle between two unit vectors [rad], in [0, π].
fn angle_between(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] * b[1] - a[1] * b[0])
        .atan2(a[0] * b[0] + a[1] * b[1])
        .abs()
}

/// Start data of one smooth segment of a path, for [`TurnTable`].
#[derive(Debug, Clone, Copy, PartialEq)]
struct SegTurn {
    /// Arc length at the segment start [m].
    s: f64,
    /// Cumulative deviation at the segment start, after the kink there [rad].
    alpha: f64,
    /// Unit tangent at the segment start.
    dir: [f64; 2],
    /// Radius of a circular arc [m] (its deviation is Δs/r, which may exceed π).
    radius: Option<f64>,
}

/// Cumulative angular deviation α(s) = ∫|dθ| of a [`BarPath`] from its start [rad]: exact
/// for every segment kind, because within one smooth segment the tangent turns one way
/// only (lines: not at all; quadratic curves: by less than π; arcs: by Δs/r); the kinks
/// between polyline segments or chain parts add their angles.
#[derive(Debug, Clone, PartialEq)]
pub struct TurnTable {
    segments: Vec<SegTurn>,
    /// Total deviation from start to end [rad].
    pub total: f64,
    /// Path length [m].
    pub length: f64,
}

impl TurnTable {
    /// α at a point of path segment `segment` (as in [`BarPiece::segment`]) with arc length
    /// `s` [m] from the path start and unit tangent `dir` (as in [`BarPoint`]) [rad].
    pub fn at(&self, segment: usize, s: f64, dir: [f64; 2]) -> f64 {
        let g = &self.segments[segment];
        match g.radius {
            Some(r) => g.alpha + (s - g.s).max(0.0) / r,
            None => g.alpha + angle_between(g.dir, dir),
        }
    }
}

fn finite2(p: &[f64; 2]) -> bool {
    p[0].is_finite() && p[1].is_finite()
}

impl BarPath {
    /// Smooth segments of the path.
    fn segments(&self) -> Result<Vec<Seg>, BarError> {
        let quad = |p: [[f64; 2]; 3]| -> Result<Vec<Seg>, BarError> {
            if !p.iter().all(finite2) {
                return Err(BarError::InvalidPath("non-finite coordinate".into()));
            }
            let b = [
                -3.0 * p[0][0] + 4.0 * p[1][0] - p[2][0],
                -3.0 * p[0][1] + 4.0 * p[1][1] - p[2][1],
            ];
            let c = [
                2.0 * p[0][0] - 4.0 * p[1][0] + 2.0 * p[2][0],
                2.0 * p[0][1] - 4.0 * p[1][1] + 2.0 * p[2][1],
            ];
            let s = Seg::Quad(p[0], b, c);
            // Reject curves whose speed vanishes (cusp / folded back): |x'(t)| is the root of a
            // convex quadratic; sample finely against a small fraction of the chord scale.
            let scale = norm([p[2][0] - p[0][0], p[2][1] - p[0][1]])
                .max(norm([p[1][0] - p[0][0], p[1][1] - p[0][1]]));
            let min_speed = (0..=200)
                .map(|i| norm(s.deriv(i as f64 / 200.0)))
                .fold(f64::INFINITY, f64::min);
            if scale == 0.0 || min_speed < 1e-6 * scale {
                return Err(BarError::InvalidPath(
                    "quadratic curve is degenerate (zero length or folds back on itself)".into(),
                ));
            }
            Ok(vec![s])
        };
        match self {
            BarPath::Polyline(pts) => {
                if !pts.iter().all(finite2) {
                    return Err(BarError::InvalidPath("non-finite coordinate".into()));
                }
                let segs: Vec<Seg> = pts
                    .windows(2)
                    .filter(|w| w[0] != w[1])
                    .map(|w| Seg::Line(w[0], w[1]))
                    .collect();
                if segs.is_empty() {
                    return Err(BarError::InvalidPath(
                        "a polyline needs at least two distinct points".into(),
                    ));
                }
                Ok(segs)
            }
            BarPath::Quadratic(p) => quad(*p),
            BarPath::Parabola { start, end, sag } => {
                if !sag.is_finite() {
                    return Err(BarError::InvalidPath("non-finite sag".into()));
                }
                let d = [end[0] - start[0], end[1] - start[1]];
                let l = norm(d);
                if l == 0.0 {
                    return Err(BarError::InvalidPath(
                        "parabola with coincident ends".into(),
                    ));
                }
                let n = [-d[1] / l, d[0] / l];
                let mid = [
                    0.5 * (start[0] + end[0]) + sag * n[0],
                    0.5 * (start[1] + end[1]) + sag * n[1],
                ];
                quad([*start, mid, *end])
            }
            BarPath::Arc {
                center,
                radius,
                theta_start,
                theta_end,
            } => {
                if !(finite2(center)
                    && radius.is_finite()
                    && theta_start.is_finite()
                    && theta_end.is_finite())
                {
                    return Err(BarError::InvalidPath("non-finite arc data".into()));
                }
                if *radius <= 0.0 || theta_start == theta_end {
                    return Err(BarError::InvalidPath(
                        "arc needs a positive radius and distinct angles".into(),
                    ));
                }
                Ok(vec![Seg::Arc {
                    c: *center,
                    r: *radius,
                    th0: *theta_start,
                    th1: *theta_end,
                }])
            }
            BarPath::Chain(parts) => {
                if parts.is_empty() {
                    return Err(BarError::InvalidPath(
                        "a chain needs at least one part".into(),
                    ));
                }
                let mut segs: Vec<Seg> = Vec::new();
                for (i, part) in parts.iter().enumerate() {
                    if matches!(part, BarPath::Chain(_)) {
                        return Err(BarError::InvalidPath(format!(
                            "chain part {i} is itself a chain"
                        )));
                    }
                    let ps = part.segments()?;
                    if let (Some(last), Some(first)) = (segs.last(), ps.first()) {
                        let (a, b) = (last.pos(1.0), first.pos(0.0));
                        let size = norm([a[0] - segs[0].pos(0.0)[0], a[1] - segs[0].pos(0.0)[1]])
                            .max(last.arc_length(1.0))
                            .max(first.arc_length(1.0));
                        let gap = norm([b[0] - a[0], b[1] - a[1]]);
                        if gap > 1e-9 * size {
                            return Err(BarError::InvalidPath(format!(
                                "chain part {i} starts at ({:.6}, {:.6}) m, not where part {} ends ({:.6}, {:.6}) m",
                                b[0],
                                b[1],
                                i - 1,
                                a[0],
                                a[1]
                            )));
                        }
                    }
                    segs.extend(ps);
                }
                Ok(segs)
            }
        }
    }

    /// Cumulative angular deviation Σ|Δθ| of the path's tangent from its start [rad], for
    /// friction losses (seed eq. 27): see [`TurnTable`].
    pub fn turn_table(&self) -> Result<TurnTable, BarError> {
        let segs = self.segments()?;
        let mut starts = Vec::with_capacity(segs.len());
        let (mut s, mut alpha) = (0.0, 0.0);
        let mut prev_end: Option<[f64; 2]> = None;
        for seg in &segs {
            let d0 = unit(seg.deriv(0.0));
            if let Some(e) = prev_end {
                alpha += angle_between(e, d0); // kink at the joint
            }
            let radius = match seg {
                Seg::Arc { r, .. } => Some(*r),
                _ => None,
            };
            starts.push(SegTurn {
                s,
                alpha,
                dir: d0,
                radius,
            });
            alpha += match seg {
                Seg::Line(..) => 0.0,
                Seg::Arc { th0, th1, .. } => (th1 - th0).abs(),
                // A quadratic curve turns monotonically by less than π.
                Seg::Quad(..) => angle_between(d0, unit(seg.deriv(1.0))),
            };
            s += seg.arc_length(1.0);
            prev_end = Some(unit(seg.deriv(1.0)));
        }
        Ok(TurnTable {
            segments: starts,
            total: alpha,
            length: s,
        })
    }

    /// Total length of the path [m] (exact for polylines and arcs, ~1e-14 relative for
    /// quadratic curves). Returns 0 for an invalid path.
    pub fn length(&self) -> f64 {
        self.segments()
            .map(|s| s.iter().map(|g| g.arc_length(1.0)).sum())
            .unwrap_or(0.0)
    }
}

// ------------------------------------------------------------------------------------------
// Inverse mapping
// ------------------------------------------------------------------------------------------

/// Natural coordinates (ξ, η) of the global point `x` [m] in an element, by Newton iteration
/// on Σ N_i(ξ, η) x_i = x starting from `guess` (then from the centre if that fails).
/// Returns `None` if Newton does not converge or runs far outside the element (|ξ|, |η| > 4);
/// the result may lie outside the reference domain (use [`is_inside`]).
pub fn inverse_map(
    kind: ElementKind,
    coords: &[[f64; 2]],
    x: [f64; 2],
    guess: [f64; 2],
) -> Option<[f64; 2]> {
    let h = element_size(kind, coords);
    let centre = kind.info().domain.centre();
    let try_from = |g: [f64; 2]| -> Option<[f64; 2]> {
        let mut p = g;
        for _ in 0..40 {
            let s = kind.eval(p[0], p[1]);
            let xm = map_point(&s, coords);
            let r = [xm[0] - x[0], xm[1] - x[1]];
            let (_, det, inv) = jacobian(&s, coords);
            if !det.is_finite() || det.abs() < 1e-300 {
                return None;
            }
            let dxi = -(inv[0][0] * r[0] + inv[1][0] * r[1]);
            let deta = -(inv[0][1] * r[0] + inv[1][1] * r[1]);
            p[0] += dxi;
            p[1] += deta;
            if !(p[0].abs() <= 4.0 && p[1].abs() <= 4.0) {
                return None;
            }
            if dxi.abs().max(deta.abs()) < 1e-15 || norm(r) < 1e-15 * h {
                // One more step is already included; accept.
                return Some(p);
            }
        }
        // Accept if the residual is tiny even without meeting the step criterion.
        let s = kind.eval(p[0], p[1]);
        let xm = map_point(&s, coords);
        (norm([xm[0] - x[0], xm[1] - x[1]]) < 1e-12 * h).then_some(p)
    };
    try_from(guess).or_else(|| {
        if guess != centre {
            try_from(centre)
        } else {
            None
        }
    })
}

/// Inside test of natural coordinates `p` in the reference domain of `kind` with tolerance
/// [`INSIDE_TOL`].
pub fn is_inside(kind: ElementKind, p: [f64; 2]) -> bool {
    kind.info().domain.inside(p, INSIDE_TOL)
}

/// Characteristic size: largest corner-to-corner distance [m].
fn element_size(kind: ElementKind, coords: &[[f64; 2]]) -> f64 {
    let mut h: f64 = 0.0;
    let nc = kind.n_corners().min(coords.len());
    for i in 0..nc {
        for j in (i + 1)..nc {
            h = h.max(norm([
                coords[i][0] - coords[j][0],
                coords[i][1] - coords[j][1],
            ]));
        }
    }
    h
}

/// Bounding box [xmin, ymin, xmax, ymax] of the element's region: the convex hull of the
/// control net of its map contains the element (the kind's descriptor gives the net).
fn element_bbox(kind: ElementKind, c: &[[f64; 2]]) -> [f64; 4] {
    let pts = (kind.info().hull)(c);
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for p in pts {
        b[0] = b[0].min(p[0]);
        b[1] = b[1].min(p[1]);
        b[2] = b[2].max(p[0]);
        b[3] = b[3].max(p[1]);
    }
    b
}

// ------------------------------------------------------------------------------------------
// Embedding
// ------------------------------------------------------------------------------------------

/// Embedding options.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EmbedOptions {
    /// Gauss points per piece (1..=64; default 4). 2 are exact for straight bars in
    /// parallelogram hosts; in distorted hosts the error decays spectrally (measured force error
    /// for curved-edge Q8 meshes: 3 points ~2e-3, 4 ~1e-4, 6 ~3e-7, 8 ~1e-9).
    pub n_gauss: usize,
    /// Point placement.
    pub placement: Placement,
}

impl Default for EmbedOptions {
    fn default() -> Self {
        EmbedOptions {
            n_gauss: 4,
            placement: Placement::OnPath,
        }
    }
}

/// A mesh of host elements with a uniform-grid spatial index over element bounding boxes,
/// built once (O(n)) and reused for many bars; a point query touches only the elements whose
/// boxes overlap the point's grid cell.
#[derive(Debug)]
pub struct BarEmbedder<'a> {
    hosts: &'a [HostElement<'a>],
    bbox: Vec<[f64; 4]>,
    size: Vec<f64>,
    origin: [f64; 2],
    cell: [f64; 2],
    n_cells: [usize; 2],
    cell_start: Vec<usize>,
    cell_items: Vec<usize>,
}

impl<'a> BarEmbedder<'a> {
    /// Validate the hosts and build the spatial index.
    pub fn new(hosts: &'a [HostElement<'a>]) -> Result<Self, BarError> {
        if hosts.is_empty() {
            return Err(BarError::BadHost {
                element: 0,
                reason: "no host elements".into(),
            });
        }
        let mut bbox = Vec::with_capacity(hosts.len());
        let mut size = Vec::with_capacity(hosts.len());
        let mut g = [
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        for (e, h) in hosts.iter().enumerate() {
            if h.coords.len() != h.kind.n_nodes() {
                return Err(BarError::BadHost {
                    element: e,
                    reason: format!(
                        "{:?} needs {} nodes, got {}",
                        h.kind,
                        h.kind.n_nodes(),
                        h.coords.len()
                    ),
                });
            }
            if !h.coords.iter().all(finite2) {
                return Err(BarError::BadHost {
                    element: e,
                    reason: "non-finite coordinate".into(),
                });
            }
            let hs = element_size(h.kind, h.coords);
            if hs <= 0.0 {
                return Err(BarError::BadHost {
                    element: e,
                    reason: "zero size".into(),
                });
            }
            let mut b = element_bbox(h.kind, h.coords);
            let pad = 1e-8 * hs;
            b[0] -= pad;
            b[1] -= pad;
            b[2] += pad;
            b[3] += pad;
            g[0] = g[0].min(b[0]);
            g[1] = g[1].min(b[1]);
            g[2] = g[2].max(b[2]);
            g[3] = g[3].max(b[3]);
            bbox.push(b);
            size.push(hs);
        }
        let (w, hh) = ((g[2] - g[0]).max(1e-300), (g[3] - g[1]).max(1e-300));
        let n = hosts.len() as f64;
        // About one cell per element, shaped like the mesh's bounding box.
        let nx = ((n * w / hh).sqrt().ceil() as usize).clamp(1, 4096);
        let ny = ((n / nx as f64).ceil() as usize).clamp(1, 4096);
        let cell = [w / nx as f64, hh / ny as f64];
        let mut counts = vec![0usize; nx * ny + 1];
        let range = |b: &[f64; 4]| -> (usize, usize, usize, usize) {
            let cx = |x: f64| (((x - g[0]) / cell[0]).floor().max(0.0) as usize).min(nx - 1);
            let cy = |y: f64| (((y - g[1]) / cell[1]).floor().max(0.0) as usize).min(ny - 1);
            (cx(b[0]), cx(b[2]), cy(b[1]), cy(b[3]))
        };
        for b in &bbox {
            let (i0, i1, j0, j1) = range(b);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    counts[j * nx + i + 1] += 1;
                }
            }
        }
        for k in 1..counts.len() {
            counts[k] += counts[k - 1];
        }
        let mut fill = counts.clone();
        let mut items = vec![0usize; counts[nx * ny]];
        for (e, b) in bbox.iter().enumerate() {
            let (i0, i1, j0, j1) = range(b);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let c = j * nx + i;
                    items[fill[c]] = e;
                    fill[c] += 1;
                }
            }
        }
        Ok(BarEmbedder {
            hosts,
            bbox,
            size,
            origin: [g[0], g[1]],
            cell,
            n_cells: [nx, ny],
            cell_start: counts,
            cell_items: items,
        })
    }

    /// Elements containing the point x [m] (inside test with [`INSIDE_TOL`]), ascending.
    pub fn locate(&self, x: [f64; 2]) -> Vec<(usize, [f64; 2])> {
        let mut out = Vec::new();
        let fx = (x[0] - self.origin[0]) / self.cell[0];
        let fy = (x[1] - self.origin[1]) / self.cell[1];
        if !(fx.is_finite() && fy.is_finite()) {
            return out;
        }
        let (nx, ny) = (self.n_cells[0] as f64, self.n_cells[1] as f64);
        if fx < -1e-9 || fy < -1e-9 || fx > nx + 1e-9 || fy > ny + 1e-9 {
            return out;
        }
        let i = (fx.floor().max(0.0) as usize).min(self.n_cells[0] - 1);
        let j = (fy.floor().max(0.0) as usize).min(self.n_cells[1] - 1);
        let c = j * self.n_cells[0] + i;
        for &e in &self.cell_items[self.cell_start[c]..self.cell_start[c + 1]] {
            let b = &self.bbox[e];
            if x[0] < b[0] || x[0] > b[2] || x[1] < b[1] || x[1] > b[3] {
                continue;
            }
            let h = &self.hosts[e];
            if let Some(p) = inverse_map(h.kind, h.coords, x, h.kind.info().domain.centre()) {
                if is_inside(h.kind, p) {
                    out.push((e, p));
                }
            }
        }
        out.sort_by_key(|a| a.0);
        out.dedup_by_key(|a| a.0);
        out
    }

    fn contains(&self, e: usize, x: [f64; 2], guess: &mut [f64; 2]) -> bool {
        let b = &self.bbox[e];
        if x[0] < b[0] || x[0] > b[2] || x[1] < b[1] || x[1] > b[3] {
            return false;
        }
        let h = &self.hosts[e];
        match inverse_map(h.kind, h.coords, x, *guess) {
            Some(p) if h.kind.info().domain.inside(p, EXIT_TOL) => {
                *guess = p;
                true
            }
            _ => false,
        }
    }

    /// Largest t reached from t0 while staying in element e (march, then bisect).
    fn march(&self, e: usize, seg: &Seg, t0: f64, guess: [f64; 2]) -> f64 {
        let speed = seg.max_speed();
        let dt = (0.25 * self.size[e] / speed).max(1e-9);
        let mut g = guess;
        let mut t_in = t0;
        loop {
            let t = (t_in + dt).min(1.0);
            if self.contains(e, seg.pos(t), &mut g) {
                t_in = t;
                if t >= 1.0 {
                    return 1.0;
                }
            } else {
                let mut t_out = t;
                while t_out - t_in > BISECT_TOL_T {
                    let tm = 0.5 * (t_in + t_out);
                    if tm <= t_in || tm >= t_out {
                        break;
                    }
                    if self.contains(e, seg.pos(tm), &mut g) {
                        t_in = tm;
                    } else {
                        t_out = tm;
                    }
                }
                return t_in;
            }
        }
    }

    /// Cut `path` into pieces, one per element traversed, with `opts.n_gauss` points each.
    /// Errors if part of the path lies outside the mesh.
    pub fn embed(&self, path: &BarPath, opts: &EmbedOptions) -> Result<Vec<BarPiece>, BarError> {
        if opts.n_gauss == 0 || opts.n_gauss > 64 {
            return Err(BarError::InvalidOption(format!(
                "n_gauss must be in 1..=64, got {}",
                opts.n_gauss
            )));
        }
        let segs = path.segments()?;
        let (gx, gw) = gauss_legendre(opts.n_gauss);
        let mut pieces = Vec::new();
        let mut s_base = 0.0;
        for (k, seg) in segs.iter().enumerate() {
            let seg_len = seg.arc_length(1.0);
            let mut t0 = 0.0;
            while t0 < 1.0 {
                let x0 = seg.pos(t0);
                let cands = self.locate(x0);
                if cands.is_empty() {
                    return Err(BarError::OutsideMesh {
                        x: x0[0],
                        y: x0[1],
                        s: s_base + seg.arc_length(t0),
                    });
                }
                let mut best: Option<(usize, f64)> = None;
                for (e, p) in cands {
                    let te = self.march(e, seg, t0, p);
                    match best {
                        Some((_, tb)) if te <= tb + TIE_TOL_T => {}
                        _ => best = Some((e, te)),
                    }
                }
                let (e, t1) = best.expect("non-empty candidates");
                if t1 <= t0 {
                    // Only touching elements: the path leaves the mesh right after t0.
                    let ta = (t0 + 1e-9).min(1.0);
                    let xa = seg.pos(ta);
                    return Err(BarError::OutsideMesh {
                        x: xa[0],
                        y: xa[1],
                        s: s_base + seg.arc_length(ta),
                    });
                }
                let len = seg.arc_length(t1) - seg.arc_length(t0);
                if len > SLIVER_REL * self.size[e] {
                    pieces.push(self.make_piece(
                        e,
                        k,
                        seg,
                        (t0, t1),
                        s_base,
                        opts.placement,
                        &gx,
                        &gw,
                    )?);
                }
                // Guarantee progress even if bisection stalls at a representable limit.
                t0 = if t1 >= 1.0 - BISECT_TOL_T { 1.0 } else { t1 };
            }
            s_base += seg_len;
        }
        Ok(pieces)
    }

    #[allow(clippy::too_many_arguments)]
    fn make_piece(
        &self,
        e: usize,
        seg_index: usize,
        seg: &Seg,
        (ta, tb): (f64, f64),
        s_base: f64,
        placement: Placement,
        gx: &[f64],
        gw: &[f64],
    ) -> Result<BarPiece, BarError> {
        let h = &self.hosts[e];
        let map = |x: [f64; 2], guess: [f64; 2]| -> Result<[f64; 2], BarError> {
            inverse_map(h.kind, h.coords, x, guess).ok_or(BarError::InverseMap {
                element: e,
                x: x[0],
                y: x[1],
            })
        };
        let tm = 0.5 * (ta + tb);
        let na = map(seg.pos(ta), h.kind.info().domain.centre())?;
        let nb = map(seg.pos(tb), na)?;
        let nm = map(seg.pos(tm), [0.5 * (na[0] + nb[0]), 0.5 * (na[1] + nb[1])])?;
        let nat = [na, nb, nm];
        let half = 0.5 * (tb - ta);
        let mut points = Vec::with_capacity(gx.len());
        for (&r, &w) in gx.iter().zip(gw) {
            let (l, dl) = line_shape(3, r);
            let interp = [
                l[0] * na[0] + l[1] * nb[0] + l[2] * nm[0],
                l[0] * na[1] + l[1] * nb[1] + l[2] * nm[1],
            ];
            let t = tm + half * r;
            let p = match placement {
                Placement::OnPath => {
                    let x = seg.pos(t);
                    let d = seg.deriv(t);
                    let sp = norm(d);
                    let nat_p = map(x, interp)?;
                    BarPoint {
                        xi: nat_p[0],
                        eta: nat_p[1],
                        dir: [d[0] / sp, d[1] / sp],
                        weight_length: sp * half * w,
                        s: s_base + seg.arc_length(t),
                        x,
                    }
                }
                Placement::Lagrange3 => {
                    let dxi = [
                        dl[0] * na[0] + dl[1] * nb[0] + dl[2] * nm[0],
                        dl[0] * na[1] + dl[1] * nb[1] + dl[2] * nm[1],
                    ];
                    let sv = h.kind.eval(interp[0], interp[1]);
                    let (j, _, _) = jacobian(&sv, h.coords);
                    // dx/dr = Jᵀ dξ/dr.
                    let dx = [
                        j[0][0] * dxi[0] + j[1][0] * dxi[1],
                        j[0][1] * dxi[0] + j[1][1] * dxi[1],
                    ];
                    let sp = norm(dx);
                    BarPoint {
                        xi: interp[0],
                        eta: interp[1],
                        dir: [dx[0] / sp, dx[1] / sp],
                        weight_length: sp * w,
                        s: s_base + seg.arc_length(t),
                        x: map_point(&sv, h.coords),
                    }
                }
            };
            points.push(p);
        }
        let (sa, sb) = (seg.arc_length(ta), seg.arc_length(tb));
        Ok(BarPiece {
            element: e,
            points,
            length: sb - sa,
            s_range: (s_base + sa, s_base + sb),
            segment: seg_index,
            t_range: (ta, tb),
            nat_nodes: nat,
        })
    }
}

/// Cut a bar path through a mesh given as a list of host elements, with `n_gauss` Gauss points
/// per piece placed on the path ([`Placement::OnPath`]); error if part of the path lies outside
/// the mesh. Builds a spatial index each call: use [`BarEmbedder`] for many bars.
pub fn embed(
    path: &BarPath,
    hosts: &[HostElement],
    n_gauss: usize,
) -> Result<Vec<BarPiece>, BarError> {
    BarEmbedder::new(hosts)?.embed(
        path,
        &EmbedOptions {
            n_gauss,
            placement: Placement::OnPath,
        },
    )
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::elements::bar::{add_bar_point, bar_strain, strain_along};
    use crate::fem::quadrature::gauss;

    /// Deterministic pseudo-random number in [−1, 1].
    pub(crate) fn rnd(k: usize) -> f64 {
        let x = ((k as f64 + 1.0) * 12.9898).sin() * 43758.5453;
        2.0 * (x - x.floor()) - 1.0
    }

    /// Structured mesh of [0, lx] × [0, ly] with nx × ny elements; interior lattice points are
    /// moved by up to `amp` × lattice spacing (edges of quadratic kinds become curved); the
    /// boundary stays straight. A triangle kind (T6) is the Q9 mesh with each cell split along
    /// its diagonal from corner 0 to corner 2 into two T6 (2 nx ny elements). Returns
    /// (lattice coordinates, element node lists in VTK order).
    pub(crate) fn mesh(
        kind: ElementKind,
        nx: usize,
        ny: usize,
        lx: f64,
        ly: f64,
        amp: f64,
    ) -> (Vec<[f64; 2]>, Vec<Vec<usize>>) {
        // Grid order and centre node (a triangle kind: the Q9 grid, split below).
        let (m, centre) = kind.grid_layout().unwrap_or((2, true));
        let split = kind.grid_layout().is_none();
        let (px, py) = (m * nx + 1, m * ny + 1);
        let (hx, hy) = (lx / (m * nx) as f64, ly / (m * ny) as f64);
        let mut nodes = Vec::with_capacity(px * py);
        for j in 0..py {
            for i in 0..px {
                let mut x = [i as f64 * hx, j as f64 * hy];
                if i % m == 0 && j % m == 0 {
                    if i > 0 && i < px - 1 {
                        x[0] += amp * hx * m as f64 * rnd(2 * (j * px + i));
                    }
                    if j > 0 && j < py - 1 {
                        x[1] += amp * hy * m as f64 * rnd(2 * (j * px + i) + 1);
                    }
                }
                nodes.push(x);
            }
        }
        // Quadratic meshes: mid-side and centre nodes at the average of their corners, then
        // moved by up to amp/3 of the lattice spacing (gently curved edges).
        if m == 2 {
            let get = |n: &Vec<[f64; 2]>, i: usize, j: usize| n[j * px + i];
            for pass in 0..2 {
                for j in 0..py {
                    for i in 0..px {
                        let (oi, oj) = (i % 2 == 1, j % 2 == 1);
                        let avg = match (oi, oj, pass) {
                            (true, false, 0) => {
                                let (a, b) = (get(&nodes, i - 1, j), get(&nodes, i + 1, j));
                                [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
                            }
                            (false, true, 0) => {
                                let (a, b) = (get(&nodes, i, j - 1), get(&nodes, i, j + 1));
                                [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
                            }
                            (true, true, 1) => {
                                let c = [
                                    get(&nodes, i - 1, j - 1),
                                    get(&nodes, i + 1, j - 1),
                                    get(&nodes, i + 1, j + 1),
                                    get(&nodes, i - 1, j + 1),
                                ];
                                [
                                    0.25 * (c[0][0] + c[1][0] + c[2][0] + c[3][0]),
                                    0.25 * (c[0][1] + c[1][1] + c[2][1] + c[3][1]),
                                ]
                            }
                            _ => continue,
                        };
                        let mut x = avg;
                        if i > 0 && i < px - 1 {
                            x[0] += amp / 3.0 * hx * rnd(2 * (j * px + i));
                        }
                        if j > 0 && j < py - 1 {
                            x[1] += amp / 3.0 * hy * rnd(2 * (j * px + i) + 1);
                        }
                        nodes[j * px + i] = x;
                    }
                }
            }
        }
        let id = |i: usize, j: usize| j * px + i;
        let mut elems = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let (a, b) = (m * i, m * j);
                let mut e = vec![id(a, b), id(a + m, b), id(a + m, b + m), id(a, b + m)];
                if m == 2 {
                    e.extend([
                        id(a + 1, b),
                        id(a + 2, b + 1),
                        id(a + 1, b + 2),
                        id(a, b + 1),
                    ]);
                    if centre {
                        e.push(id(a + 1, b + 1));
                    }
                }
                if split {
                    elems.push(vec![e[0], e[1], e[2], e[4], e[5], e[8]]);
                    elems.push(vec![e[0], e[2], e[3], e[8], e[6], e[7]]);
                } else {
                    elems.push(e);
                }
            }
        }
        (nodes, elems)
    }

    pub(crate) fn coords_of(nodes: &[[f64; 2]], elems: &[Vec<usize>]) -> Vec<Vec<[f64; 2]>> {
        elems
            .iter()
            .map(|e| e.iter().map(|&n| nodes[n]).collect())
            .collect()
    }

    pub(crate) fn hosts_of(kind: ElementKind, coords: &[Vec<[f64; 2]>]) -> Vec<HostElement<'_>> {
        coords
            .iter()
            .map(|c| HostElement { kind, coords: c })
            .collect()
    }

    /// Displacement of the uniform strain field (εx, εy, γxy) (no rotation).
    pub(crate) fn u_uniform(x: [f64; 2], eps: [f64; 3]) -> [f64; 2] {
        [
            eps[0] * x[0] + 0.5 * eps[2] * x[1],
            0.5 * eps[2] * x[0] + eps[1] * x[1],
        ]
    }

    pub(crate) const KINDS: [ElementKind; 4] = crate::fem::kinds::ALL;

    /// Our Gauss–Legendre rule reproduces the tabulated 1–4 point rules (round-off 1e-14) and
    /// integrates x^k exactly up to k = 2n − 1 for larger n.
    #[test]
    fn gauss_legendre_is_correct() {
        for n in 1..=4 {
            let (x, w) = gauss_legendre(n);
            let r = gauss(n);
            for i in 0..n {
                assert!((x[i] - r.points[i]).abs() < 1e-14);
                assert!((w[i] - r.weights[i]).abs() < 1e-14);
            }
        }
        for n in [5, 8, 12, 20] {
            let (x, w) = gauss_legendre(n);
            for k in 0..(2 * n) {
                let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k as i32)).sum();
                let exact = if k % 2 == 0 {
                    2.0 / (k as f64 + 1.0)
                } else {
                    0.0
                };
                assert!((q - exact).abs() < 1e-13, "n={n} k={k}");
            }
        }
    }

    /// Global nodal force vector of a bar with constant stress σ, assembled over its pieces.
    pub(super) fn assemble(
        kind: ElementKind,
        coords: &[Vec<[f64; 2]>],
        elems: &[Vec<usize>],
        n_nodes: usize,
        pieces: &[BarPiece],
        sigma_a: f64,
    ) -> Vec<f64> {
        let mut fg = vec![0.0; 2 * n_nodes];
        for pc in pieces {
            let c = &coords[pc.element];
            let m = 2 * kind.n_nodes();
            let mut f = vec![0.0; m];
            let mut k = vec![0.0; m * m];
            for p in &pc.points {
                add_bar_point(kind, c, p, 1.0, sigma_a, 0.0, &mut f, &mut k);
            }
            for (a, &n) in elems[pc.element].iter().enumerate() {
                fg[2 * n] += f[2 * a];
                fg[2 * n + 1] += f[2 * a + 1];
            }
        }
        fg
    }

    /// Exact nodal forces of a straight bar with constant force σA: by virtual work
    /// f·δa = σA t·(δu(x_end) − δu(x_start)), i.e. σA t N_i at the end minus the start.
    pub(super) fn exact_straight(
        emb: &BarEmbedder,
        elems: &[Vec<usize>],
        n_nodes: usize,
        a: [f64; 2],
        b: [f64; 2],
        sigma_a: f64,
    ) -> Vec<f64> {
        let l = norm([b[0] - a[0], b[1] - a[1]]);
        let t = [(b[0] - a[0]) / l, (b[1] - a[1]) / l];
        let mut fg = vec![0.0; 2 * n_nodes];
        for (x, sign) in [(a, -1.0), (b, 1.0)] {
            let (e, p) = emb.locate(x)[0];
            let s = emb.hosts[e].kind.eval(p[0], p[1]);
            for (i, &n) in elems[e].iter().enumerate() {
                fg[2 * n] += sign * sigma_a * s.n_val[i] * t[0];
                fg[2 * n + 1] += sign * sigma_a * s.n_val[i] * t[1];
            }
        }
        fg
    }

    pub(super) fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
        let d: f64 = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt();
        let n: f64 = b.iter().map(|y| y * y).sum::<f64>().sqrt();
        d / n
    }

    /// A straight bar at an arbitrary angle across distorted Q4/Q8/Q9 meshes under a uniform
    /// strain field: the total length is exact (round-off, 1e-12 rel), each point's strain is
    /// tᵀεt (round-off, 1e-12 rel), and the assembled nodal forces equal the exact,
    /// mesh-independent σA·t·(N(end) − N(start)) to 1e-8 rel. The last tolerance is the
    /// quadrature error: along a straight line in a distorted host, (ξ, η)(s) is not polynomial
    /// (a hyperbola for Q4), so Gauss integration is not exact but converges spectrally:
    /// measured errors with 3 / 4 / 6 / 8 / 12 points: Q4 6e-7 / 2e-9 / 2e-13 / – / –;
    /// Q8 2.5e-3 / 1.2e-4 / 3e-7 / 9e-10 / 8e-13; Q9 (3×2) 1.6e-3 / 4e-5 / 5e-8 / 7e-11 / 5e-13
    /// and up to 3e-2 with 3 points on the 7×5 Q9 mesh. The 1e-8 check uses 16 points; 3
    /// points are checked against 5e-2 (the convergence rate is a property of the host map).
    #[test]
    fn straight_bar_in_distorted_meshes_is_mesh_independent() {
        let eps = [1.2e-3, -3e-4, 7e-4];
        let (a, b) = ([0.13, 0.37], [2.71, 1.58]);
        let l = norm([b[0] - a[0], b[1] - a[1]]);
        let t = [(b[0] - a[0]) / l, (b[1] - a[1]) / l];
        let eb = strain_along(t, eps);
        let sigma_a = 2e5 * 1e-4 * eb;
        for kind in KINDS {
            for (nx, ny) in [(3, 2), (7, 5)] {
                let (nodes, elems) = mesh(kind, nx, ny, 3.0, 2.0, 0.15);
                let coords = coords_of(&nodes, &elems);
                let hosts = hosts_of(kind, &coords);
                let emb = BarEmbedder::new(&hosts).unwrap();
                let exact = exact_straight(&emb, &elems, nodes.len(), a, b, sigma_a);
                for (ng, tol) in [(3, 5e-2), (16, 1e-8)] {
                    let opts = EmbedOptions {
                        n_gauss: ng,
                        placement: Placement::OnPath,
                    };
                    let pieces = emb.embed(&BarPath::Polyline(vec![a, b]), &opts).unwrap();
                    assert!(
                        pieces.len() >= nx.min(ny),
                        "{kind:?}: {} pieces",
                        pieces.len()
                    );
                    let len: f64 = pieces.iter().map(|p| p.length).sum();
                    let wl: f64 = pieces
                        .iter()
                        .flat_map(|p| p.points.iter().map(|q| q.weight_length))
                        .sum();
                    assert!((len - l).abs() < 1e-12 * l && (wl - l).abs() < 1e-12 * l);
                    // Pieces are contiguous in s.
                    for w in pieces.windows(2) {
                        assert!((w[0].s_range.1 - w[1].s_range.0).abs() < 1e-12 * l);
                    }
                    for pc in &pieces {
                        let c = &coords[pc.element];
                        let u: Vec<f64> = c.iter().flat_map(|x| u_uniform(*x, eps)).collect();
                        for p in &pc.points {
                            assert!(is_inside(kind, [p.xi, p.eta]));
                            let e = bar_strain(kind, c, p, &u);
                            assert!((e - eb).abs() < 1e-12 * eb.abs(), "{kind:?}");
                        }
                    }
                    let fg = assemble(kind, &coords, &elems, nodes.len(), &pieces, sigma_a);
                    let r = rel_diff(&fg, &exact);
                    assert!(r < tol, "{kind:?} {nx}x{ny} n_gauss={ng}: rel diff {r:e}");
                }
            }
        }
    }

    /// In undistorted (rectangular) hosts the map along a straight bar is affine, so Gauss
    /// quadrature is exact: 2 points give the exact forces (round-off, 5e-12), and the classic
    /// Lagrange3 placement coincides with the on-path one.
    #[test]
    fn rectangular_mesh_is_exact_and_placements_agree() {
        let (a, b) = ([0.0, 0.2], [3.0, 1.9]);
        for kind in KINDS {
            let (nodes, elems) = mesh(kind, 6, 4, 3.0, 2.0, 0.0);
            let coords = coords_of(&nodes, &elems);
            let hosts = hosts_of(kind, &coords);
            let emb = BarEmbedder::new(&hosts).unwrap();
            let exact = exact_straight(&emb, &elems, nodes.len(), a, b, 1.0);
            let mut opts = EmbedOptions {
                n_gauss: 2,
                placement: Placement::OnPath,
            };
            let p1 = emb.embed(&BarPath::Polyline(vec![a, b]), &opts).unwrap();
            opts.placement = Placement::Lagrange3;
            let p2 = emb.embed(&BarPath::Polyline(vec![a, b]), &opts).unwrap();
            let fg = assemble(kind, &coords, &elems, nodes.len(), &p1, 1.0);
            // Round-off: measured 1.5e-12 on T6 (12 pieces), below 1e-12 on the quads.
            let r = rel_diff(&fg, &exact);
            assert!(r < 5e-12, "{kind:?}: {r:e}, {} pieces", p1.len());
            assert_eq!(p1.len(), p2.len());
            for (x, y) in p1.iter().zip(&p2) {
                for (p, q) in x.points.iter().zip(&y.points) {
                    assert!((p.xi - q.xi).abs() < 1e-10 && (p.eta - q.eta).abs() < 1e-10);
                    assert!((p.weight_length - q.weight_length).abs() < 1e-12);
                    assert!((p.dir[0] - q.dir[0]).abs() < 1e-12);
                }
            }
        }
    }

    /// The Lagrange3 placement in distorted hosts approximates the curve; its length error is
    /// small but not round-off (measured 1.2e-5 for Q4, 2e-6 / 3e-5 for curved Q8 / Q9;
    /// bound 1e-3).
    #[test]
    fn lagrange3_placement_is_close_in_distorted_hosts() {
        let (a, b) = ([0.13, 0.37], [2.71, 1.58]);
        let l = norm([b[0] - a[0], b[1] - a[1]]);
        for kind in KINDS {
            let (nodes, elems) = mesh(kind, 5, 4, 3.0, 2.0, 0.15);
            let coords = coords_of(&nodes, &elems);
            let hosts = hosts_of(kind, &coords);
            let emb = BarEmbedder::new(&hosts).unwrap();
            let opts = EmbedOptions {
                n_gauss: 3,
                placement: Placement::Lagrange3,
            };
            let pieces = emb.embed(&BarPath::Polyline(vec![a, b]), &opts).unwrap();
            let wl: f64 = pieces
                .iter()
                .flat_map(|p| p.points.iter().map(|q| q.weight_length))
                .sum();
            assert!((wl - l).abs() < 1e-3 * l, "{kind:?}: {wl} vs {l}");
        }
    }

    /// Bars along a shared edge, along the boundary and through nodes are counted once
    /// (length exact to round-off).
    #[test]
    fn edges_and_nodes_are_not_double_counted() {
        for kind in KINDS {
            let (nodes, elems) = mesh(kind, 4, 4, 4.0, 4.0, 0.0);
            let coords = coords_of(&nodes, &elems);
            let hosts = hosts_of(kind, &coords);
            for path in [
                vec![[0.0, 2.0], [4.0, 2.0]], // interior mesh line
                vec![[1.0, 0.0], [1.0, 4.0]], // interior mesh line
                vec![[0.0, 0.0], [4.0, 4.0]], // diagonal through nodes
                vec![[0.0, 0.0], [4.0, 0.0]], // boundary
                vec![[0.5, 0.5], [2.0, 2.0], [3.0, 1.0], [3.0, 3.5]], // polyline via a node
            ] {
                let l: f64 = path
                    .windows(2)
                    .map(|w| norm([w[1][0] - w[0][0], w[1][1] - w[0][1]]))
                    .sum();
                let pieces = embed(&BarPath::Polyline(path.clone()), &hosts, 2).unwrap();
                let len: f64 = pieces.iter().map(|p| p.length).sum();
                assert!(
                    (len - l).abs() < 1e-12 * l,
                    "{kind:?} {path:?}: {len} vs {l}"
                );
                // No element carries two overlapping pieces of the same segment.
                for w in pieces.windows(2) {
                    assert!(w[0].s_range.1 <= w[1].s_range.0 + 1e-12);
                }
            }
        }
    }

    /// Curved paths: a circular arc has exact length (round-off) and points on the circle with
    /// tangent directions; a parabola's length matches the closed form (1e-12 rel: quadrature
    /// of a smooth integrand).
    #[test]
    fn curved_paths() {
        let (nodes, elems) = mesh(ElementKind::Q8, 8, 6, 4.0, 3.0, 0.1);
        let coords = coords_of(&nodes, &elems);
        let hosts = hosts_of(ElementKind::Q8, &coords);
        let (c, r) = ([2.0, 0.2], 1.9);
        let arc = BarPath::Arc {
            center: c,
            radius: r,
            theta_start: 0.3,
            theta_end: 2.9,
        };
        let pieces = embed(&arc, &hosts, 3).unwrap();
        let len: f64 = pieces.iter().map(|p| p.length).sum();
        let wl: f64 = pieces
            .iter()
            .flat_map(|p| p.points.iter().map(|q| q.weight_length))
            .sum();
        let exact = r * 2.6;
        assert!((len - exact).abs() < 1e-12 * exact && (wl - exact).abs() < 1e-12 * exact);
        for pc in &pieces {
            for p in &pc.points {
                let d = [p.x[0] - c[0], p.x[1] - c[1]];
                assert!((norm(d) - r).abs() < 1e-12);
                assert!((d[0] * p.dir[0] + d[1] * p.dir[1]).abs() < 1e-12);
                // (ξ, η) maps back to x.
                let s = ElementKind::Q8.eval(p.xi, p.eta);
                let xm = map_point(&s, &coords[pc.element]);
                assert!(norm([xm[0] - p.x[0], xm[1] - p.x[1]]) < 1e-12);
            }
        }
        // Parabola y = 0.5 + 4 f x (L − x)/L² over x ∈ [0.5, 3.5] (L = 3, sag f = −0.8 ⇒ the
        // curve bulges upwards: left normal of a left-to-right chord points up, so sag > 0 is
        // upwards; use f = 0.8).
        let (l, f) = (3.0f64, 0.8f64);
        let par = BarPath::Parabola {
            start: [0.5, 0.5],
            end: [3.5, 0.5],
            sag: f,
        };
        let pieces = embed(&par, &hosts, 3).unwrap();
        let len: f64 = pieces.iter().map(|p| p.length).sum();
        // Closed form for y = 4 f x(L−x)/L²: with k = 4f/L, length = L/2 √(1+k²) + asinh(k)/(2k)·L/2.
        let k = 4.0 * f / l;
        let exact = 0.5 * l * (1.0 + k * k).sqrt() + (l / 2.0) * k.asinh() / k;
        assert!((len - exact).abs() < 1e-12 * exact, "{len} vs {exact}");
        assert!((par.length() - exact).abs() < 1e-12 * exact);
        let top = pieces
            .iter()
            .flat_map(|p| p.points.iter())
            .map(|p| p.x[1])
            .fold(f64::MIN, f64::max);
        assert!(top > 1.2 && top <= 1.3 + 1e-12);
    }

    /// Paths leaving the mesh (or lying outside) are errors naming the position.
    #[test]
    fn outside_paths_are_errors() {
        let (nodes, elems) = mesh(ElementKind::Q4, 3, 3, 3.0, 3.0, 0.1);
        let coords = coords_of(&nodes, &elems);
        let hosts = hosts_of(ElementKind::Q4, &coords);
        match embed(&BarPath::Polyline(vec![[0.5, 1.0], [4.0, 1.0]]), &hosts, 2) {
            Err(BarError::OutsideMesh { x, s, .. }) => {
                assert!((x - 3.0).abs() < 1e-6 && (s - 2.5).abs() < 1e-6, "{x} {s}")
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            embed(&BarPath::Polyline(vec![[-1.0, 1.0], [1.0, 1.0]]), &hosts, 2),
            Err(BarError::OutsideMesh { .. })
        ));
        // Mesh with a gap: two blocks [0,1]² and [2,3]×[0,1].
        let c1 = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let c2 = [[2.0, 0.0], [3.0, 0.0], [3.0, 1.0], [2.0, 1.0]];
        let hosts = [
            HostElement {
                kind: ElementKind::Q4,
                coords: &c1,
            },
            HostElement {
                kind: ElementKind::Q4,
                coords: &c2,
            },
        ];
        assert!(matches!(
            embed(&BarPath::Polyline(vec![[0.5, 0.5], [2.5, 0.5]]), &hosts, 2),
            Err(BarError::OutsideMesh { .. })
        ));
        assert!(matches!(
            embed(&BarPath::Polyline(vec![[0.5, 0.5]]), &hosts, 2),
            Err(BarError::InvalidPath(_))
        ));
        assert!(matches!(
            embed(&BarPath::Polyline(vec![[0.5, 0.5], [0.7, 0.5]]), &hosts, 0),
            Err(BarError::InvalidOption(_))
        ));
        let bad = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]];
        assert!(matches!(
            embed(
                &BarPath::Polyline(vec![[0.5, 0.5], [0.7, 0.5]]),
                &[HostElement {
                    kind: ElementKind::Q4,
                    coords: &bad
                }],
                2
            ),
            Err(BarError::BadHost { .. })
        ));
    }

    /// The spatial index keeps embedding fast on a 1e5-element mesh (many long bars).
    #[test]
    fn many_bars_in_large_mesh() {
        let (nodes, elems) = mesh(ElementKind::Q4, 400, 250, 40.0, 2.5, 0.2);
        let coords = coords_of(&nodes, &elems);
        let hosts = hosts_of(ElementKind::Q4, &coords);
        let t0 = std::time::Instant::now();
        let emb = BarEmbedder::new(&hosts).unwrap();
        let mut n = 0;
        for i in 0..10 {
            let y = 0.1 + 0.23 * i as f64;
            let path = BarPath::Polyline(vec![[0.0, y], [40.0, 2.4 - 0.2 * i as f64]]);
            let pieces = emb.embed(&path, &EmbedOptions::default()).unwrap();
            let len: f64 = pieces.iter().map(|p| p.length).sum();
            assert!((len - path.length()).abs() < 1e-10 * len);
            n += pieces.len();
        }
        eprintln!("1e5 elements, 10 bars, {n} pieces: {:?}", t0.elapsed());
        assert!(n > 4000);
    }
}
