//! Segmental-beam generator: a line of precast segments, each meshed as a banded block with
//! its own nodes; neighbouring segments touch at joints, and a joint is the list of facing
//! element-edge pairs between them.

use super::banded::{generate, Band};
use crate::model::ElementKind;

/// One joint face pair: the nodes of the left segment's edge and the right segment's edge at
/// the same height, both ordered bottom to top as (start, end, [mid]).
#[derive(Debug, Clone, PartialEq)]
pub struct JointFace {
    /// Left segment's edge nodes (face A).
    pub a: Vec<usize>,
    /// Right segment's edge nodes (face B).
    pub b: Vec<usize>,
    /// Region index of the band the face lies in (gives the joint's thickness).
    pub region: usize,
}

/// A joint between segment `left` and segment `left + 1` at abscissa `x` [m].
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Index of the segment on the left.
    pub left: usize,
    /// Abscissa of the joint [m].
    pub x: f64,
    /// Facing edge pairs, bottom to top.
    pub faces: Vec<JointFace>,
    /// Cast in place (a wet joint): the two faces share their nodes and no contact element
    /// is made; the joint keeps its place in the numbering (J1, J2, … stay the same).
    pub cast: bool,
}

/// A generated segmental mesh.
#[derive(Debug, Clone, Default)]
pub struct SegmentalMesh {
    /// Node coordinates [m].
    pub nodes: Vec<[f64; 2]>,
    /// Elements: node lists (VTK order), region index, segment index.
    pub elements: Vec<(Vec<usize>, usize, usize)>,
    /// Joints, left to right.
    pub joints: Vec<Joint>,
}

/// Generate segments of the given lengths [m] placed end to end from `x0`, each with
/// `nx[i]` element columns, sharing the band layout (bottom up). A kind without a grid
/// layout (triangles, refused at input) is generated as Q4, as [`generate`] does.
pub fn generate_segments(
    x0: f64,
    y0: f64,
    lengths: &[f64],
    nx: &[usize],
    bands: &[Band],
    kind: ElementKind,
) -> SegmentalMesh {
    let kind = match kind.grid_layout() {
        Some(_) => kind,
        None => ElementKind::Q4,
    };
    let mut out = SegmentalMesh::default();
    let mut x = x0;
    let rows: usize = bands.iter().map(|b| b.rows).sum();
    let mut prev_right: Option<Vec<JointFace>> = None;
    for (s, (&len, &n)) in lengths.iter().zip(nx).enumerate() {
        let g = generate([x, y0], len, n, bands, kind);
        let off = out.nodes.len();
        out.nodes.extend(g.nodes);
        let first = out.elements.len();
        for (el, region) in g.elements {
            out.elements
                .push((el.iter().map(|v| v + off).collect(), region, s));
        }
        // Element (row r, column c) is first + r·n + c; edge 1 is the right edge (nodes 1→2),
        // edge 3 the left edge (nodes 3→0, top to bottom, so reversed here to go upward).
        let edge = |r: usize, c: usize, right: bool| -> (Vec<usize>, usize) {
            let (el, region, _) = &out.elements[first + r * n + c];
            let v: Vec<usize> = if right {
                kind.edge_nodes(1).iter().map(|&l| el[l]).collect()
            } else {
                let e = kind.edge_nodes(3);
                let mut v = vec![el[e[1]], el[e[0]]];
                v.extend(e[2..].iter().map(|&l| el[l]));
                v
            };
            (v, *region)
        };
        if let Some(left_faces) = prev_right.take() {
            let faces = (0..rows)
                .map(|r| {
                    let (b, _) = edge(r, 0, false);
                    JointFace {
                        a: left_faces[r].a.clone(),
                        b,
                        region: left_faces[r].region,
                    }
                })
                .collect();
            out.joints.push(Joint {
                left: s - 1,
                x,
                faces,
                cast: false,
            });
        }
        prev_right = Some(
            (0..rows)
                .map(|r| {
                    let (a, region) = edge(r, n - 1, true);
                    JointFace {
                        a,
                        b: vec![],
                        region,
                    }
                })
                .collect(),
        );
        x += len;
    }
    out
}

/// Cast the joints `wet` (0-based indices into `mesh.joints`) in place: the right face's
/// nodes are replaced by the left face's, the nodes left unused are dropped and the rest
/// renumbered in their order. The joints stay in the list, marked `cast`.
pub fn cast_joints(mesh: &mut SegmentalMesh, wet: &[usize]) {
    let mut map: Vec<usize> = (0..mesh.nodes.len()).collect();
    for &j in wet {
        let joint = &mut mesh.joints[j];
        joint.cast = true;
        for f in &joint.faces {
            for (&a, &b) in f.a.iter().zip(&f.b) {
                map[b] = a;
            }
        }
    }
    // Follow chains (a node merged into one that is itself merged) to their end.
    for i in 0..map.len() {
        let mut k = map[i];
        while map[k] != k {
            k = map[k];
        }
        map[i] = k;
    }
    let mut new_id = vec![usize::MAX; mesh.nodes.len()];
    let mut nodes = Vec::new();
    for (i, p) in mesh.nodes.iter().enumerate() {
        if map[i] == i {
            new_id[i] = nodes.len();
            nodes.push(*p);
        }
    }
    let renumber = |n: usize| new_id[map[n]];
    for (el, _, _) in &mut mesh.elements {
        el.iter_mut().for_each(|n| *n = renumber(*n));
    }
    for j in &mut mesh.joints {
        for f in &mut j.faces {
            f.a.iter_mut().for_each(|n| *n = renumber(*n));
            f.b.iter_mut().for_each(|n| *n = renumber(*n));
        }
    }
    mesh.nodes = nodes;
}

/// Lower the soffit to `soffit(x)` [m] (at or below `y0`, the soffit the bands were
/// stacked from): the bands below band `stretch` move down with it, band `stretch` takes
/// the extra depth (its nodes spread linearly between its top, which stays, and its new
/// bottom), the bands above stay. This is how a haunched box deepens its webs towards
/// the piers while its deck stays level.
pub fn lower_soffit(
    mesh: &mut SegmentalMesh,
    y0: f64,
    bands: &[Band],
    stretch: usize,
    soffit: impl Fn(f64) -> f64,
) {
    let bottom = y0 + bands[..stretch].iter().map(|b| b.depth).sum::<f64>();
    let top = bottom + bands[stretch].depth;
    // Round-off only: band boundaries are sums of the same depths as the nodes' ordinates.
    let tol = 1e-9 * (top - y0).max(1.0);
    for p in &mut mesh.nodes {
        let drop = y0 - soffit(p[0]);
        if p[1] <= bottom + tol {
            p[1] -= drop;
        } else if p[1] < top - tol {
            p[1] = top - (top - p[1]) * (top - bottom + drop) / (top - bottom);
        }
    }
}

/// Raise every node by `camber(x)` [m]: the casting curve, the level each section is set
/// at so that the girder reaches its design profile once it has deflected.
pub fn raise(mesh: &mut SegmentalMesh, camber: impl Fn(f64) -> f64) {
    for p in &mut mesh.nodes {
        p[1] += camber(p[0]);
    }
}

/// The piecewise-linear function through `points` (x increasing), constant beyond its ends.
pub fn piecewise_linear(points: &[[f64; 2]]) -> impl Fn(f64) -> f64 + '_ {
    move |x| {
        let i = points.partition_point(|p| p[0] < x);
        if i == 0 {
            points[0][1]
        } else if i == points.len() {
            points[i - 1][1]
        } else {
            let (a, b) = (points[i - 1], points[i]);
            a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three segments: two joints, each with one face pair per element row, the two faces at
    /// the same coordinates but with distinct nodes.
    #[test]
    fn joints_pair_coincident_distinct_nodes() {
        let bands = [
            Band {
                depth: 0.2,
                rows: 1,
                region: 0,
            },
            Band {
                depth: 0.4,
                rows: 2,
                region: 1,
            },
        ];
        for kind in [ElementKind::Q4, ElementKind::Q8, ElementKind::Q9] {
            let m = generate_segments(0.0, 0.0, &[1.0, 1.0, 1.5], &[2, 2, 3], &bands, kind);
            assert_eq!(m.joints.len(), 2);
            assert!((m.joints[1].x - 2.0).abs() < 1e-12);
            for j in &m.joints {
                assert_eq!(j.faces.len(), 3);
                assert_eq!(j.faces[2].region, 1);
                for f in &j.faces {
                    assert_eq!(f.a.len(), f.b.len());
                    for (a, b) in f.a.iter().zip(&f.b) {
                        assert_ne!(a, b);
                        let (pa, pb) = (m.nodes[*a], m.nodes[*b]);
                        assert!(
                            (pa[0] - j.x).abs() < 1e-12
                                && (pa[0] - pb[0]).abs() < 1e-12
                                && (pa[1] - pb[1]).abs() < 1e-12
                        );
                    }
                    // Bottom to top.
                    assert!(m.nodes[f.a[1]][1] > m.nodes[f.a[0]][1]);
                }
            }
        }
    }
}
