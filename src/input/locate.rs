//! Geometric queries used while validating a model: which element contains a point, the
//! nearest node, nodes and element edges on a line segment.

use crate::model::Model;
use rayon::prelude::*;

pub use crate::model::model_size;

/// True if `p` lies inside or on the boundary (within `tol` [m]) of the straight-edged polygon
/// of an element's corners.
fn in_corners(corners: &[[f64; 2]], p: [f64; 2], tol: f64) -> bool {
    let n = corners.len();
    (0..n).all(|i| {
        let a = corners[i];
        let b = corners[(i + 1) % n];
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        let len = (ex * ex + ey * ey).sqrt();
        // Counter-clockwise element: inside is to the left of every edge.
        (ex * (p[1] - a[1]) - ey * (p[0] - a[0])) / len >= -tol
    })
}

/// True if `p` lies in some element of the mesh (within a tolerance of 1e-6 × model size).
pub fn inside_mesh(model: &Model, p: [f64; 2]) -> bool {
    let tol = 1e-6 * model_size(model);
    model.elements.par_iter().any(|e| {
        let nc = e.kind.n_corners();
        let mut c = [[0.0; 2]; 4];
        for (k, &n) in e.nodes[..nc].iter().enumerate() {
            c[k] = model.nodes[n];
        }
        in_corners(&c[..nc], p, tol)
    })
}

/// The node nearest to `p`, among nodes used by elements.
pub fn nearest_node(model: &Model, used: &[bool], p: [f64; 2]) -> usize {
    let mut best = (f64::INFINITY, 0);
    for (i, q) in model.nodes.iter().enumerate() {
        if !used[i] {
            continue;
        }
        let d = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
        if d < best.0 {
            best = (d, i);
        }
    }
    best.1
}

/// Distance from `p` to the segment a–b [m].
pub fn dist_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
    let l2 = ex * ex + ey * ey;
    let t = if l2 == 0.0 {
        0.0
    } else {
        (((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / l2).clamp(0.0, 1.0)
    };
    let (cx, cy) = (a[0] + t * ex, a[1] + t * ey);
    ((p[0] - cx).powi(2) + (p[1] - cy).powi(2)).sqrt()
}

/// Used nodes lying on the segment a–b (within 1e-6 × model size).
pub fn nodes_on_segment(model: &Model, used: &[bool], a: [f64; 2], b: [f64; 2]) -> Vec<usize> {
    let tol = 1e-6 * model_size(model);
    (0..model.nodes.len())
        .filter(|&i| used[i] && dist_to_segment(model.nodes[i], a, b) <= tol)
        .collect()
}

/// An element edge (nodes start, end, [mid]) and the loaded range of its natural coordinate.
pub type EdgePart = (Vec<usize>, [f64; 2]);

/// Element edges lying along the segment a–b: every node of the edge on the line through
/// a and b (within 1e-6 × model size) and the edge overlapping the segment. Returns the edge
/// nodes (start, end, [mid]) with the overlapped range of the edge's natural coordinate, and
/// the total overlapped length [m]. Each geometric edge is taken once.
pub fn edges_on_segment(model: &Model, a: [f64; 2], b: [f64; 2]) -> (Vec<EdgePart>, f64) {
    edges_on_segment_of(model, a, b, |_| true)
}

/// As [`edges_on_segment`], keeping only the edges of elements on the `into` side of the
/// segment (their centroid beyond it along the unit vector `into`): a plate bears on the
/// concrete behind it, not on the segment across a joint whose face lies on the same line.
pub fn edges_on_segment_into(
    model: &Model,
    a: [f64; 2],
    b: [f64; 2],
    into: [f64; 2],
) -> (Vec<EdgePart>, f64) {
    edges_on_segment_of(model, a, b, |e| {
        let n = e.nodes.len() as f64;
        let (cx, cy) = e.nodes.iter().fold((0.0, 0.0), |(x, y), &k| {
            (x + model.nodes[k][0] / n, y + model.nodes[k][1] / n)
        });
        (cx - a[0]) * into[0] + (cy - a[1]) * into[1] > 0.0
    })
}

fn edges_on_segment_of(
    model: &Model,
    a: [f64; 2],
    b: [f64; 2],
    keep: impl Fn(&crate::model::Element) -> bool,
) -> (Vec<EdgePart>, f64) {
    let tol = 1e-6 * model_size(model);
    let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
    let len = (ex * ex + ey * ey).sqrt();
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let mut covered = 0.0;
    if len == 0.0 {
        return (out, 0.0);
    }
    let param = |p: [f64; 2]| ((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / len; // [m] along a→b
    let off_line = |p: [f64; 2]| ((p[0] - a[0]) * ey - (p[1] - a[1]) * ex).abs() / len;
    // The edges on the line, found on all cores (kept in element and edge order), then
    // walked in that order.
    let on_line: Vec<(usize, usize)> = model
        .elements
        .par_iter()
        .enumerate()
        .flat_map_iter(|(k, e)| {
            e.kind
                .edges()
                .iter()
                .enumerate()
                .filter_map(move |(q, local)| {
                    local
                        .iter()
                        .all(|&l| off_line(model.nodes[e.nodes[l]]) <= tol)
                        .then_some((k, q))
                })
        })
        .collect();
    for (k, q) in on_line {
        let e = &model.elements[k];
        if !keep(e) {
            continue;
        }
        let nodes: Vec<usize> = e.kind.edges()[q].iter().map(|&l| e.nodes[l]).collect();
        let mut key = [nodes[0], nodes[1]];
        key.sort_unstable();
        if !seen.insert(key) {
            continue;
        }
        let (s0, s1) = (param(model.nodes[nodes[0]]), param(model.nodes[nodes[1]]));
        let (lo, hi) = (s0.min(s1).max(0.0), s0.max(s1).min(len));
        if hi - lo <= tol {
            continue;
        }
        // Straight edge: r is linear in the distance along it.
        let to_r = |s: f64| -1.0 + 2.0 * (s - s0) / (s1 - s0);
        let (r0, r1) = (to_r(lo), to_r(hi));
        out.push((nodes, [r0.min(r1), r0.max(r1)]));
        covered += hi - lo;
    }
    (out, covered)
}
