//! Banded rectangle generator: a beam of given length split into horizontal bands, each with
//! its own depth, thickness (through its region) and number of element rows — the
//! plane-stress idealisation of I, T and box sections.

use crate::model::ElementKind;
use rayon::prelude::*;

/// One horizontal band, listed from the bottom up.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// Depth of the band [m].
    pub depth: f64,
    /// Element rows through the band.
    pub rows: usize,
    /// Region index the band's elements belong to.
    pub region: usize,
}

/// A generated mesh: node coordinates, and elements as (kind, nodes in VTK order, region).
#[derive(Debug, Clone, Default)]
pub struct GeneratedMesh {
    /// Node coordinates [m].
    pub nodes: Vec<[f64; 2]>,
    /// Elements: node lists (VTK order) and region index.
    pub elements: Vec<(Vec<usize>, usize)>,
}

/// Generate a structured mesh of `nx` columns over [x0, x0 + length] and the bands stacked
/// upward from y0. Quadratic kinds get mid-side nodes (Q9 also centre nodes), each node
/// placed on the grid where its natural coordinates put it (the kind's descriptor). A kind
/// without a grid layout (triangles, refused at input) is generated as Q4.
pub fn generate(
    origin: [f64; 2],
    length: f64,
    nx: usize,
    bands: &[Band],
    kind: ElementKind,
) -> GeneratedMesh {
    let (kind, (order, centre)) = match kind.grid_layout() {
        Some(l) => (kind, l),
        None => (ElementKind::Q4, (1, false)),
    };
    // Grid lines in y (sub-grid for quadratic elements).
    let mut ys = vec![origin[1]];
    let mut row_region = Vec::new();
    for b in bands {
        let y0 = *ys.last().expect("starts with origin");
        let n = b.rows * order;
        for k in 1..=n {
            ys.push(y0 + b.depth * k as f64 / n as f64);
        }
        row_region.extend(std::iter::repeat_n(b.region, b.rows));
    }
    let ncols = nx * order + 1;
    let nrows = ys.len();
    // Node index per grid point; Q8 skips the centre points of elements.
    let mut id = vec![usize::MAX; ncols * nrows];
    let mut nodes = Vec::new();
    for (j, y) in ys.iter().enumerate() {
        for i in 0..ncols {
            if order == 2 && !centre && i % 2 == 1 && j % 2 == 1 {
                continue;
            }
            id[j * ncols + i] = nodes.len();
            nodes.push([origin[0] + length * i as f64 / (ncols - 1) as f64, *y]);
        }
    }
    let g = |i: usize, j: usize| id[j * ncols + i];
    // Row by row, left to right (a node list per element: built on all cores).
    let elements = (0..nx * row_region.len())
        .into_par_iter()
        .map(|k| {
            let (r, c) = (k / nx, k % nx);
            let (i, j) = (c * order, r * order);
            let el = (0..kind.n_nodes())
                .map(|a| {
                    let (di, dj) = kind.grid_offset(a, order);
                    g(i + di, j + dj)
                })
                .collect();
            (el, row_region[r])
        })
        .collect();
    GeneratedMesh { nodes, elements }
}

/// Closed-form section properties of bands with thicknesses `t[i]` (bottom up): area [m²],
/// centroid height above the bottom [m], second moment about the centroid [m⁴].
pub fn section_properties(depths: &[f64], thicknesses: &[f64]) -> (f64, f64, f64) {
    let mut a = 0.0;
    let mut s = 0.0;
    let mut i0 = 0.0;
    let mut y = 0.0;
    for (d, t) in depths.iter().zip(thicknesses) {
        let ab = d * t;
        let yc = y + d / 2.0;
        a += ab;
        s += ab * yc;
        i0 += t * d.powi(3) / 12.0 + ab * yc * yc;
        y += d;
    }
    let c = s / a;
    (a, c, i0 - a * c * c)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Node and element counts of a 3 × (1 + 2)-element grid for each kind.
    #[test]
    fn counts() {
        let bands = [
            Band {
                depth: 0.1,
                rows: 1,
                region: 0,
            },
            Band {
                depth: 0.5,
                rows: 2,
                region: 1,
            },
        ];
        for (kind, n_nodes) in [
            (ElementKind::Q4, 4 * 4),
            (ElementKind::Q8, 7 * 7 - 9),
            (ElementKind::Q9, 7 * 7),
        ] {
            let m = generate([0.0, 0.0], 3.0, 3, &bands, kind);
            assert_eq!(m.nodes.len(), n_nodes, "{kind:?}");
            assert_eq!(m.elements.len(), 9);
            assert_eq!(m.elements[8].1, 1);
        }
    }

    /// A rectangle: A = b h, c = h/2, I = b h³/12.
    #[test]
    fn rectangle_properties() {
        let (a, c, i) = section_properties(&[0.6], &[0.3]);
        assert!((a - 0.18).abs() < 1e-15 && (c - 0.3).abs() < 1e-15);
        assert!((i - 0.3 * 0.216 / 12.0).abs() < 1e-15);
    }
}
