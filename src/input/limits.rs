//! Size limits checked before the mesh is generated (banded, segmental) or right after it is
//! read (explicit, gmsh), so that a huge model is refused with a clear message instead of
//! running the machine out of memory. Documented in docs/errors.md ("Limits").
//!
//! The memory estimate uses the measured peak of the sparse direct solver on banded plane
//! meshes (docs/performance.md: 1.97 GiB for 1.0e6 Q4 dofs, 2.35 GiB for 1.0e6 Q8 dofs), about
//! 2.4 KiB per dof; [`BYTES_PER_DOF`] rounds it up for nonlinear runs, which also keep two
//! copies of every integration-point state.

use super::error::{Ctx, InputError};

/// Largest number of degrees of freedom accepted, whatever the machine [-]. At
/// [`BYTES_PER_DOF`] this is about 26 GiB, more than a workstation of today has; the limit
/// keeps the answer the same on every machine.
pub const MAX_DOFS: f64 = 1e7;

/// Largest number of increments (or time substeps) of one step [-]: far above any real use
/// (the seed beam needs 50), low enough that a typing error does not run for days.
pub const MAX_INCREMENTS: usize = 100_000;

/// Largest `solver.max_iterations` [-].
pub const MAX_ITERATIONS: usize = 10_000;

/// Largest `solver.max_cuts` [-]: 2^-52 of an increment is below double precision.
pub const MAX_CUTS: usize = 52;

/// Largest node coordinate accepted, in absolute value [m]: 1e7 m is the size of the Earth;
/// farther coordinates are a unit or typing error, and their products (areas, det J)
/// overflow double precision before anything else could name them.
pub const MAX_COORDINATE: f64 = 1e7;

/// Why coordinate pair `p` [m] is refused (not finite, or beyond [`MAX_COORDINATE`]), if it
/// is.
pub fn bad_coordinates(p: [f64; 2]) -> Option<String> {
    if !(p[0].is_finite() && p[1].is_finite()) {
        Some(format!(
            "coordinates ({}, {}) are not finite numbers",
            p[0], p[1]
        ))
    } else if p[0].abs().max(p[1].abs()) > MAX_COORDINATE {
        Some(format!(
            "coordinates ({:e}, {:e}) m lie beyond ±{MAX_COORDINATE:e} m (the size of the Earth): metres intended?",
            p[0], p[1]
        ))
    } else {
        None
    }
}

/// Largest model or mesh file read [bytes] (512 MiB). The largest model the dof limit
/// allows (5e6 nodes) written out as an explicit mesh or a Gmsh file takes about 250 MB
/// (about 50 bytes per node and per element); a larger file, or a device such as
/// /dev/zero, is refused after reading this much instead of filling the memory.
pub const MAX_INPUT_BYTES: u64 = 512 << 20;

/// The bytes of file `path`, read up to [`MAX_INPUT_BYTES`]; `Err` with a sentence (without
/// the file name) when it cannot be read or is larger.
pub fn read_bounded(path: &std::path::Path) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let f = std::fs::File::open(path).map_err(|e| format!("cannot read the file: {e}"))?;
    let mut bytes = Vec::new();
    f.take(MAX_INPUT_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read the file: {e}"))?;
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        return Err(format!(
            "larger than the limit of {} MiB for an input file (the largest model segfem runs takes about half of it); not a model or mesh file?",
            MAX_INPUT_BYTES >> 20
        ));
    }
    Ok(bytes)
}

/// Estimated peak memory per degree of freedom of a run [bytes].
pub const BYTES_PER_DOF: f64 = 2800.0;

/// Memory available to a new process [bytes]: `MemAvailable` of /proc/meminfo (Linux);
/// None where the platform does not say.
pub fn available_memory() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = s.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Refuse a model of `nodes` nodes and `elements` elements (counts as f64 so that the
/// estimate itself cannot overflow) if its dofs exceed [`MAX_DOFS`] or its estimated memory
/// exceeds `available` [bytes]. `key` names the input that sets the size.
pub fn check_size(
    ctx: &Ctx,
    key: &str,
    nodes: f64,
    elements: f64,
    available: Option<u64>,
) -> Result<(), InputError> {
    let dofs = 2.0 * nodes;
    let bytes = dofs * BYTES_PER_DOF;
    let gib = |b: f64| b / (1u64 << 30) as f64;
    if dofs.is_nan() || dofs > MAX_DOFS {
        return Err(ctx.err(
            key,
            format!(
                "the mesh would have {elements:.3e} elements and {dofs:.3e} dofs, above the limit of {MAX_DOFS:.0e} dofs (estimated memory {:.1} GiB); use a coarser mesh",
                gib(bytes)
            ),
        ));
    }
    if let Some(av) = available {
        if bytes > av as f64 {
            return Err(ctx.err(
                key,
                format!(
                    "the mesh would have {elements:.3e} elements and {dofs:.3e} dofs: the run needs about {:.1} GiB of memory, more than the {:.1} GiB available; use a coarser mesh",
                    gib(bytes),
                    gib(av as f64)
                ),
            ));
        }
    }
    Ok(())
}

/// Number of nodes of a structured grid of `nx` × `ny` quadrilaterals of `kind` (f64: the
/// count is checked before anything is allocated; the kind's descriptor gives its grid
/// layout). 0 for a kind the generators cannot make (refused before this is asked).
pub fn grid_nodes(kind: crate::model::ElementKind, nx: f64, ny: f64) -> f64 {
    kind.grid_nodes(nx, ny).unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::ElementKind;

    fn ctx() -> Ctx {
        Ctx {
            file: "m.toml".into(),
        }
    }

    /// Node counts of small grids counted by hand: 2 × 1 Q4 → 6, Q8 → 13, Q9 → 15.
    #[test]
    fn grid_node_counts() {
        assert_eq!(grid_nodes(ElementKind::Q4, 2.0, 1.0), 6.0);
        assert_eq!(grid_nodes(ElementKind::Q8, 2.0, 1.0), 13.0);
        assert_eq!(grid_nodes(ElementKind::Q9, 2.0, 1.0), 15.0);
    }

    /// Above the dof limit always an error; below it, an error only when the estimate
    /// exceeds the memory available, naming both figures.
    #[test]
    fn size_limits() {
        let c = ctx();
        assert!(check_size(&c, "mesh.nx", 1e3, 1e3, Some(1 << 30)).is_ok());
        let e = check_size(&c, "mesh.nx", 1e7, 1e7, None).unwrap_err();
        assert!(e.message.contains("above the limit"), "{e}");
        // 1e6 nodes = 2e6 dofs ≈ 5.2 GiB, with 1 GiB available.
        let e = check_size(&c, "mesh.nx", 1e6, 1e6, Some(1 << 30)).unwrap_err();
        assert!(e.message.contains("5.2 GiB"), "{e}");
        assert!(e.message.contains("1.0 GiB available"), "{e}");
        assert_eq!(e.key, "mesh.nx");
        // NaN counts (never produced, but must not pass).
        assert!(check_size(&c, "mesh.nx", f64::NAN, 1.0, None).is_err());
    }
}

/// Bounding-box diagonal of a node set [m] (0 for fewer than two distinct points).
pub fn extent(nodes: &[[f64; 2]]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in nodes {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    }
    if nodes.is_empty() {
        0.0
    } else {
        (hi[0] - lo[0]).hypot(hi[1] - lo[1])
    }
}

/// Why an element is degenerate, if it is: a corner edge shorter than 1e-9 of the model size
/// `size` [m], or a corner polygon of area below 1e-12 size² (both far below any meshing
/// intent, far above round-off). The first `nc` nodes are the corners (the kind's
/// descriptor); `ids` are the element's node numbers as the user knows them.
pub fn degenerate(coords: &[[f64; 2]], nc: usize, ids: &[u64], size: f64) -> Option<String> {
    let tol = 1e-9 * size;
    for k in 0..nc {
        let (a, b) = (coords[k], coords[(k + 1) % nc]);
        let len = (b[0] - a[0]).hypot(b[1] - a[1]);
        if len.is_nan() || len <= tol {
            return Some(format!(
                "the edge from node {} to node {} has (nearly) zero length: {len:.3e} m in a model {size:.3e} m across",
                ids[k],
                ids[(k + 1) % nc]
            ));
        }
    }
    // Shoelace area of the corner polygon.
    let area: f64 = (0..nc)
        .map(|k| {
            let (a, b) = (coords[k], coords[(k + 1) % nc]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        * 0.5;
    if area.is_nan() || area.abs() <= 1e-12 * size * size {
        let corners: Vec<String> = ids[..nc].iter().map(|i| i.to_string()).collect();
        return Some(format!(
            "zero area ({area:.3e} m²): its corners (nodes {}) are collinear",
            corners.join(", ")
        ));
    }
    None
}

#[cfg(test)]
mod geometry_tests {
    use super::*;

    /// A unit square is fine; a repeated corner position is a zero-length edge naming both
    /// nodes; four collinear corners have zero area.
    #[test]
    fn degenerate_elements() {
        let ids = [1, 2, 3, 4];
        let sq = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert_eq!(degenerate(&sq, 4, &ids, 10.0), None);
        let pinched = [[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let m = degenerate(&pinched, 4, &ids, 10.0).unwrap();
        assert!(m.contains("node 2 to node 3"), "{m}");
        let flat = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]];
        let m = degenerate(&flat, 4, &ids, 10.0).unwrap();
        assert!(m.contains("zero area"), "{m}");
        let nan = [[f64::NAN, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert!(degenerate(&nan, 4, &ids, 10.0).is_some());
    }
}

/// Pairs of used nodes that coincide (within 1e-9 of the model size `size` [m]) without an
/// interface between them: two parts of the mesh touching there are not connected, which is
/// what a joint missing from the model (a joint face with no opposite face) looks like.
/// `tied[n]` is true for nodes of an interface element. Returns the number of such pairs and
/// the first one (0-based nodes: the pair of the lowest second node, and of its partners
/// the first in cell order). The nodes are sorted by their cell on a grid of the
/// tolerance: a node's partners lie in its own and the adjacent cells, which one walk over
/// the sorted list reaches (a hash map of cells took 0.3 s at 2.5e5 nodes).
pub fn loose_coincident(
    nodes: &[[f64; 2]],
    used: &[bool],
    tied: &[bool],
    size: f64,
) -> (usize, Option<(usize, usize)>) {
    let tol = 1e-9 * size;
    if !(tol > 0.0 && tol.is_finite()) {
        return (0, None);
    }
    let cell = |p: [f64; 2]| ((p[0] / tol).floor() as i64, (p[1] / tol).floor() as i64);
    // (cell, node), sorted: cells by column then row, nodes ascending within a cell.
    let mut sorted: Vec<((i64, i64), usize)> = nodes
        .iter()
        .enumerate()
        .filter(|&(n, _)| used[n])
        .map(|(n, p)| (cell(*p), n))
        .collect();
    // Distinct keys (the node is part of each): the same order on any number of threads.
    rayon::slice::ParallelSliceMut::par_sort_unstable(&mut sorted[..]);
    let (mut count, mut first): (usize, Option<(usize, usize, usize)>) = (0, None);
    let mut pair = |i: usize, j: usize| {
        // i, j: positions in `sorted`; (m, n) the pair's nodes, m < n.
        let (a, b) = (sorted[i].1, sorted[j].1);
        let (im, m, n) = if a < b { (i, a, b) } else { (j, b, a) };
        let (p, q) = (nodes[n], nodes[m]);
        if (p[0] - q[0]).hypot(p[1] - q[1]) <= tol && !(tied[n] && tied[m]) {
            count += 1;
            // The node scan of the definition meets n's partners in cell order.
            if first.is_none_or(|(_, f_im, f_n)| (n, im) < (f_n, f_im)) {
                first = Some((m, im, n));
            }
        }
    };
    // Each unordered pair of neighbouring cells once: from (cx, cy) forward in its column
    // (same cell, cy + 1) and to the next column (cx + 1, cy − 1 ..= cy + 1).
    let mut next_col = 0;
    for i in 0..sorted.len() {
        let (cx, cy) = sorted[i].0;
        for j in i + 1..sorted.len() {
            if sorted[j].0 .0 != cx || sorted[j].0 .1 > cy + 1 {
                break;
            }
            pair(i, j);
        }
        while next_col < sorted.len() && sorted[next_col].0 < (cx + 1, cy - 1) {
            next_col += 1;
        }
        for j in next_col..sorted.len() {
            if sorted[j].0 > (cx + 1, cy + 1) {
                break;
            }
            pair(i, j);
        }
    }
    (count, first.map(|(m, _, n)| (m, n)))
}

#[cfg(test)]
mod coincident_tests {
    use super::*;

    /// Two unit squares side by side with separate nodes on the shared edge: two loose pairs,
    /// none when those nodes are tied by an interface; distinct nodes give none.
    #[test]
    fn loose_pairs_found() {
        let nodes = [
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [1.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
        ];
        let used = [true; 8];
        let mut tied = [false; 8];
        assert_eq!(
            loose_coincident(&nodes, &used, &tied, 2.2),
            (2, Some((1, 4)))
        );
        for n in [1, 2, 4, 7] {
            tied[n] = true;
        }
        assert_eq!(loose_coincident(&nodes, &used, &tied, 2.2), (0, None));
        assert_eq!(loose_coincident(&nodes[..4], &used, &tied, 2.2), (0, None));
    }

    /// The definition scanned directly: nodes in order, each against the earlier nodes of
    /// its own and the eight adjacent cells (column, then row, then node order).
    fn by_scan(
        nodes: &[[f64; 2]],
        used: &[bool],
        tied: &[bool],
        size: f64,
    ) -> (usize, Option<(usize, usize)>) {
        let tol = 1e-9 * size;
        let cell = |p: [f64; 2]| ((p[0] / tol).floor() as i64, (p[1] / tol).floor() as i64);
        let (mut count, mut first) = (0, None);
        for n in 0..nodes.len() {
            let (cx, cy) = cell(nodes[n]);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for m in (0..n).filter(|&m| cell(nodes[m]) == (cx + dx, cy + dy)) {
                        let (p, q) = (nodes[n], nodes[m]);
                        if used[n]
                            && used[m]
                            && (p[0] - q[0]).hypot(p[1] - q[1]) <= tol
                            && !(tied[n] && tied[m])
                        {
                            count += 1;
                            first.get_or_insert((m, n));
                        }
                    }
                }
            }
        }
        (count, first)
    }

    /// The sorted walk finds the pairs of the direct scan, and the same first pair. Points
    /// on a coarse lattice (many exact coincidences), some moved by less and by more than
    /// the tolerance (1e-9 of the size 10 m = 1e-8 m) and across cell borders; some unused
    /// or tied.
    #[test]
    fn same_pairs_as_the_direct_scan() {
        let mut state = 12345u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as usize
        };
        for round in 0..20 {
            let mut nodes = Vec::new();
            for _ in 0..300 {
                let (i, j) = (next() % 8, next() % 8);
                let shift = [0.0, 0.0, 4e-9, -7e-9, 3e-8, 9.9e-9][next() % 6];
                let sign = if next() % 2 == 0 { 1.0 } else { -1.0 };
                nodes.push([i as f64 * 0.5 + shift, j as f64 * 0.5 + sign * shift]);
            }
            let used: Vec<bool> = (0..nodes.len()).map(|_| next() % 7 != 0).collect();
            let tied: Vec<bool> = (0..nodes.len()).map(|_| next() % 5 == 0).collect();
            let expected = by_scan(&nodes, &used, &tied, 10.0);
            assert!(expected.0 > 100, "round {round}: too few pairs to test");
            assert_eq!(
                loose_coincident(&nodes, &used, &tied, 10.0),
                expected,
                "round {round}"
            );
        }
    }
}
