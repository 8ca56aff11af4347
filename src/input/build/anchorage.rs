//! Load introduction as members take it: anchor plates of tendons and bearings of point
//! loads spread a force over the nodes under the plate (consistent nodal weights of a
//! uniform pressure), and the local zone behind a plate or under a bearing is made elastic,
//! standing for the spiral or local reinforcement that the anchorage approval (or the
//! bearing's design) provides (docs/theory-prestress.md, "Anchor plates, bearings and local
//! zones").

use crate::elements::continuum::edge_force_partial;
use crate::input::locate;
use crate::materials::point::Material;
use crate::model::{Model, NamedMaterial, Region};

/// Cross-section of one 0.6" (15.7 mm) prestressing strand [m²] (EN 10138-3 Y1860S7,
/// 150 mm²; 140 mm² for the common 15.2 mm strand): the strand count of the default plate.
pub const STRAND_AREA: f64 = 140e-6;

/// Side of a typical ETA bearing plate per √(number of 0.6" strands) [m]: approved
/// multi-strand anchorages (4 to 31 strands) have square bearing plates of about
/// 0.085 √n m (4 strands ≈ 0.17 m, 12 ≈ 0.29 m, 19 ≈ 0.37 m, 31 ≈ 0.47 m), a bearing
/// pressure under the jacking force near 25–30 MPa.
pub const PLATE_SIDE_PER_ROOT_STRAND: f64 = 0.085;

/// The `bearing` key of a point load or support at `key`: None for none (or 0), when its
/// `local_zone` must not be given either (`under` says where the zone would be: "under",
/// "over"); else the bearing length [m], > 0 and finite.
pub(super) fn bearing_length(
    ctx: &crate::input::error::Ctx,
    key: &str,
    bearing: Option<f64>,
    local_zone: Option<bool>,
    under: &str,
) -> super::R<Option<f64>> {
    match bearing {
        None | Some(0.0) => {
            if local_zone.is_some() {
                return Err(ctx.err(
                    format!("{key}.local_zone"),
                    format!("only with a bearing (the local zone is the concrete {under} it)"),
                ));
            }
            Ok(None)
        }
        Some(b) if b.is_finite() && b > 0.0 => Ok(Some(b)),
        Some(b) => Err(ctx.err(
            format!("{key}.bearing"),
            format!("must be a bearing length ≥ 0 in m (got {b})"),
        )),
    }
}

/// Default anchor plate [m] of a tendon of steel area `area` [m²]: n = ⌈area / 140 mm²⌉
/// 0.6" strands, side 0.085 m × √n ([`PLATE_SIDE_PER_ROOT_STRAND`]).
pub fn default_plate(area: f64) -> f64 {
    let n = (area / STRAND_AREA - 1e-9).ceil().max(1.0);
    PLATE_SIDE_PER_ROOT_STRAND * n.sqrt()
}

/// A force spread over the nodes under a plate or bearing: (node, weight), weights summing
/// to 1, and the length of the plate that lies on element edges [m].
pub struct Spread {
    /// Nodes and their shares of the force.
    pub weights: Vec<(usize, f64)>,
    /// Length of the plate on element edges [m] (less than the plate where the mesh ends).
    pub covered: f64,
}

/// The unit vector of the element edge through `node` that is most nearly perpendicular to
/// `axis` (the line a plate bearing along `axis` lies on), or None if no edge has the node.
pub fn plate_line(model: &Model, node: usize, axis: [f64; 2]) -> Option<[f64; 2]> {
    let mut best: Option<([f64; 2], f64)> = None;
    for e in &model.elements {
        if !e.nodes.contains(&node) {
            continue;
        }
        for edge in e.kind.edges() {
            let nodes: Vec<usize> = edge.iter().map(|&l| e.nodes[l]).collect();
            if !nodes.contains(&node) {
                continue;
            }
            let (a, b) = (model.nodes[nodes[0]], model.nodes[nodes[1]]);
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let l = dx.hypot(dy);
            if l == 0.0 {
                continue;
            }
            let t = [dx / l, dy / l];
            let cos = (t[0] * axis[0] + t[1] * axis[1]).abs();
            if best.is_none_or(|(_, c)| cos < c - 1e-12) {
                best = Some((t, cos));
            }
        }
    }
    best.map(|(t, _)| t)
}

/// Spread over a plate of length `length` [m] centred on `node`, lying along the element
/// edge through the node most nearly perpendicular to `axis` (unit, the way the plate
/// pushes the concrete): the consistent nodal forces of a uniform pressure on the part of
/// the plate on edges of the elements it pushes into, per unit force.
pub fn spread(model: &Model, node: usize, axis: [f64; 2], length: f64) -> Spread {
    let Some(t) = plate_line(model, node, axis) else {
        return Spread {
            weights: vec![(node, 1.0)],
            covered: 0.0,
        };
    };
    let c = model.nodes[node];
    let h = 0.5 * length;
    let a = [c[0] - h * t[0], c[1] - h * t[1]];
    let b = [c[0] + h * t[0], c[1] + h * t[1]];
    // Only the concrete the plate pushes into (+axis): at a joint face, the edges of the
    // segment across the joint lie on the same line.
    let (edges, covered) = locate::edges_on_segment_into(model, a, b, axis);
    if edges.is_empty() || covered <= 0.0 {
        return Spread {
            weights: vec![(node, 1.0)],
            covered: 0.0,
        };
    }
    let mut weights: Vec<(usize, f64)> = Vec::new();
    for (nodes, [r0, r1]) in edges {
        let coords: Vec<[f64; 2]> = nodes.iter().map(|&n| model.nodes[n]).collect();
        let f = edge_force_partial(&coords, [1.0 / covered, 0.0], r0, r1);
        for (k, &n) in nodes.iter().enumerate() {
            match weights.iter_mut().find(|(m, _)| *m == n) {
                Some((_, w)) => *w += f[2 * k],
                None => weights.push((n, f[2 * k])),
            }
        }
    }
    weights.retain(|(_, w)| *w != 0.0);
    weights.sort_by_key(|(n, _)| *n);
    Spread { weights, covered }
}

/// A local zone to make elastic: the box behind a plate (or under a bearing) of length
/// `plate` [m] at `centre`, `depth` [m] deep along `axis` (unit, into the concrete), as
/// wide as the plate.
pub struct LocalZone {
    /// Centre of the plate [m].
    pub centre: [f64; 2],
    /// Direction the plate pushes the concrete (unit).
    pub axis: [f64; 2],
    /// Plate or bearing length [m] (the zone's width).
    pub plate: f64,
    /// What stands on the plate: a tendon's anchorage or a bearing.
    pub kind: ZoneKind,
}

/// What a local zone is behind: its end-block pairing ([`end_blocks`]) joins an anchorage
/// with a bearing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ZoneKind {
    /// A tendon's anchor plate.
    Anchor,
    /// A support's or a point load's bearing.
    Bearing,
}

impl LocalZone {
    /// The zone's box: corners [m] of the rectangle `plate` wide and
    /// [`LOCAL_ZONE_DEPTH`] × `plate` deep behind the plate, counter-clockwise.
    fn corners(&self) -> [[f64; 2]; 4] {
        let (c, a) = (self.centre, self.axis);
        let t = [-a[1], a[0]];
        let (h, d) = (0.5 * self.plate, LOCAL_ZONE_DEPTH * self.plate);
        let at = |s: f64, u: f64| [c[0] + s * a[0] + u * t[0], c[1] + s * a[1] + u * t[1]];
        [at(0.0, -h), at(d, -h), at(d, h), at(0.0, h)]
    }
}

/// End blocks: the convex hull of an anchorage's zone and a bearing's zone whose boxes come
/// closer than the bearing's length. Between them the anchorage's spread meets the
/// reaction; a real member has its end diaphragm there, reinforced for both, so the
/// concrete between the two zones is no plain concrete either. Without it a row of
/// elements between the boxes carries the crossing flows as unreinforced concrete and
/// crushes, one mesh row or another depending on the element size (docs/theory-prestress.md,
/// "End blocks").
pub(super) fn end_blocks(zones: &[LocalZone]) -> Vec<Vec<[f64; 2]>> {
    let mut blocks = Vec::new();
    for a in zones.iter().filter(|z| z.kind == ZoneKind::Anchor) {
        for b in zones.iter().filter(|z| z.kind == ZoneKind::Bearing) {
            let (pa, pb) = (a.corners(), b.corners());
            if polygon_gap(&pa, &pb) < b.plate {
                let mut pts: Vec<[f64; 2]> = pa.iter().chain(pb.iter()).copied().collect();
                blocks.push(convex_hull(&mut pts));
            }
        }
    }
    blocks
}

/// Distance between two convex polygons [m] (0 where they overlap).
fn polygon_gap(p: &[[f64; 2]], q: &[[f64; 2]]) -> f64 {
    if p.iter().any(|&x| inside_convex(q, x, 0.0)) || q.iter().any(|&x| inside_convex(p, x, 0.0)) {
        return 0.0;
    }
    let seg = |x: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l2 = dx * dx + dy * dy;
        let t = if l2 > 0.0 {
            (((x[0] - a[0]) * dx + (x[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (x[0] - a[0] - t * dx).hypot(x[1] - a[1] - t * dy)
    };
    let one_way = |p: &[[f64; 2]], q: &[[f64; 2]]| {
        let mut d = f64::INFINITY;
        for &x in p {
            for i in 0..q.len() {
                d = d.min(seg(x, q[i], q[(i + 1) % q.len()]));
            }
        }
        d
    };
    // Two convex polygons that do not overlap are nearest at a vertex of one.
    one_way(p, q).min(one_way(q, p))
}

/// Counter-clockwise convex hull of `pts` (Andrew's monotone chain).
fn convex_hull(pts: &mut [[f64; 2]]) -> Vec<[f64; 2]> {
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &x in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], x) <= 0.0
            {
                hull.pop();
            }
            hull.push(x);
        }
        hull.pop();
    }
    hull
}

/// Whether `x` lies in the counter-clockwise convex polygon `p`, within `tol` [m] of it.
fn inside_convex(p: &[[f64; 2]], x: [f64; 2], tol: f64) -> bool {
    (0..p.len()).all(|i| {
        let (a, b) = (p[i], p[(i + 1) % p.len()]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l = dx.hypot(dy);
        l == 0.0 || (dx * (x[1] - a[1]) - dy * (x[0] - a[0])) / l >= -tol
    })
}

/// Depth of a local zone per plate length [-]: AASHTO LRFD 5.8.4.1 takes the local zone
/// at least as long as the plate's largest lateral dimension (and at most 1.5 times it);
/// EN 1992-1-1 6.7 spreads a partially loaded area over a depth h ≥ b2 − b1 with b2 ≤ 3 b1.
/// The lower bound keeps the zone within the spiral of an approved anchorage.
pub const LOCAL_ZONE_DEPTH: f64 = 1.0;

/// Make the concrete of the local zones elastic: every element whose centroid (mean of its
/// corner nodes) lies in a zone's box (and, if none does, the elements at the plate's
/// centre on the zone's side) and whose material is `concrete` moves to a copy of its
/// region with an elastic material of the concrete's initial modulus, Poisson ratio and
/// density. Elastic and creep regions are left alone (they cannot fail locally). The copy
/// keeps the region's construction stage and thermal coefficient.
pub(super) fn apply_local_zones(model: &mut Model, zones: &[LocalZone], used: &[bool]) {
    let centroid = |model: &Model, e: &crate::model::Element| {
        let nc = e.kind.n_corners();
        let k = e.nodes.len().min(nc) as f64;
        e.nodes.iter().take(nc).fold([0.0, 0.0], |c, &n| {
            [c[0] + model.nodes[n][0] / k, c[1] + model.nodes[n][1] / k]
        })
    };
    let tol = 1e-9 * locate::model_size(model);
    // The elements of each zone, then of each end block, in that order.
    let mut sets: Vec<Vec<usize>> = Vec::new();
    for z in zones {
        let n = locate::nearest_node(model, used, z.centre);
        let local = |p: [f64; 2]| {
            let d = [p[0] - z.centre[0], p[1] - z.centre[1]];
            let s = d[0] * z.axis[0] + d[1] * z.axis[1];
            let t = -d[0] * z.axis[1] + d[1] * z.axis[0];
            (s, t)
        };
        let depth = LOCAL_ZONE_DEPTH * z.plate;
        let mut hits: Vec<usize> = (0..model.elements.len())
            .filter(|&e| {
                let (s, t) = local(centroid(model, &model.elements[e]));
                s >= -tol && s <= depth + tol && t.abs() <= 0.5 * z.plate + tol
            })
            .collect();
        if hits.is_empty() {
            hits = (0..model.elements.len())
                .filter(|&e| {
                    model.elements[e].nodes.contains(&n)
                        && local(centroid(model, &model.elements[e])).0 > 0.0
                })
                .collect();
        }
        sets.push(hits);
    }
    for block in end_blocks(zones) {
        sets.push(
            (0..model.elements.len())
                .filter(|&e| inside_convex(&block, centroid(model, &model.elements[e]), tol))
                .collect(),
        );
    }
    let n_regions = model.regions.len();
    // Copy of region r (index into model.regions), made on first use.
    let mut copy_of: Vec<Option<usize>> = vec![None; n_regions];
    for hits in sets {
        for e in hits {
            let r = model.elements[e].region;
            let r = if r < n_regions { r } else { continue };
            let host = &model.regions[r];
            let Material::Concrete { params, density } = &model.materials[host.material].law else {
                continue;
            };
            let target = match copy_of[r] {
                Some(c) => c,
                None => {
                    let mat = NamedMaterial {
                        name: format!("{} (local zone)", model.materials[host.material].name),
                        law: Material::Elastic {
                            e: params.ec,
                            nu: params.nu,
                            density: *density,
                        },
                        // Stands for the confined concrete of the anchorage's approval:
                        // not checked against the unconfined strength.
                        strength: None,
                    };
                    model.materials.push(mat);
                    let region = Region {
                        name: format!("{} (local zone)", host.name),
                        material: model.materials.len() - 1,
                        thickness: host.thickness,
                    };
                    model.regions.push(region);
                    let c = model.regions.len() - 1;
                    if !model.staging.regions.is_empty() {
                        let life = model.staging.regions[r];
                        model.staging.regions.push(life);
                    }
                    for case in model.load_cases.iter_mut() {
                        if let Some(th) = case.thermal.as_mut() {
                            if let Some(&a) = th.region_alpha.get(r) {
                                th.region_alpha.push(a);
                            }
                        }
                    }
                    copy_of[r] = Some(c);
                    c
                }
            };
            model.elements[e].region = target;
        }
    }
}

/// The local zone of a support over a bearing of length `bearing` [m] at `node` that holds
/// the direction `held` (unit): the bearing lies along the element edge through the node
/// most nearly perpendicular to `held`, and the zone reaches into the concrete on the side
/// of the elements at the node.
pub fn support_zone(model: &Model, node: usize, held: [f64; 2], bearing: f64) -> LocalZone {
    let c = model.nodes[node];
    let t = plate_line(model, node, held).unwrap_or([-held[1], held[0]]);
    let normal = [-t[1], t[0]];
    let side: f64 = model
        .elements
        .iter()
        .filter(|e| e.nodes.contains(&node))
        .map(|e| {
            let nc = e.kind.n_corners();
            let k = e.nodes.len().min(nc) as f64;
            let m = e.nodes.iter().take(nc).fold([0.0, 0.0], |a, &n| {
                [a[0] + model.nodes[n][0] / k, a[1] + model.nodes[n][1] / k]
            });
            (m[0] - c[0]) * normal[0] + (m[1] - c[1]) * normal[1]
        })
        .sum();
    let axis = if side >= 0.0 {
        normal
    } else {
        [-normal[0], -normal[1]]
    };
    LocalZone {
        centre: c,
        axis,
        plate: bearing,
        kind: ZoneKind::Bearing,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn zone(centre: [f64; 2], axis: [f64; 2], plate: f64, kind: ZoneKind) -> LocalZone {
        LocalZone {
            centre,
            axis,
            plate,
            kind,
        }
    }

    fn area(p: &[[f64; 2]]) -> f64 {
        (0..p.len())
            .map(|i| {
                let (a, b) = (p[i], p[(i + 1) % p.len()]);
                0.5 * (a[0] * b[1] - b[0] * a[1])
            })
            .sum()
    }

    /// An anchor plate 1.2 m high centred 1.0 m up the end face x = 0 (box x 0…1.2,
    /// y 0.4…1.6) and a 0.6 m bearing at x = 0.5 on the soffit (box x 0.2…0.8, y 0…0.6):
    /// the boxes overlap, so they form an end block, the hull of their eight corners —
    /// the union (1.44 + 0.36 − 0.12 overlap of 0.6 × 0.2) plus the two triangles that
    /// fill the notches: (0, 0.4)–(0.2, 0)–(0.2, 0.4), 0.04, and (0.8, 0)–(1.2, 0.4)–
    /// (0.8, 0.4), 0.08; area 1.80 m² in all (closed form, round-off only).
    #[test]
    fn overlapping_anchor_and_bearing_make_one_block_the_hull_of_both() {
        let a = zone([0.0, 1.0], [1.0, 0.0], 1.2, ZoneKind::Anchor);
        let b = zone([0.5, 0.0], [0.0, 1.0], 0.6, ZoneKind::Bearing);
        let blocks = end_blocks(&[a, b]);
        assert_eq!(blocks.len(), 1);
        let expect = 1.44 + 0.36 - 0.12 + 0.04 + 0.08;
        assert!(
            (area(&blocks[0]) - expect).abs() < 1e-12,
            "{}",
            area(&blocks[0])
        );
        // The notch corner between them is in the block; a point beyond it is not.
        assert!(inside_convex(&blocks[0], [0.15, 0.35], 0.0));
        assert!(!inside_convex(&blocks[0], [0.05, 0.1], 0.0));
    }

    /// The gap rule: an anchor box starting 0.5 m above a 0.6 m bearing's box (gap 0.5 <
    /// 0.6) joins it; 0.7 m above (gap 0.7 > 0.6) it does not; two anchors or two bearings
    /// never join (an end block pairs an anchorage with a bearing).
    #[test]
    fn zones_join_only_an_anchor_to_a_bearing_closer_than_the_bearing() {
        let b = zone([0.5, 0.0], [0.0, 1.0], 0.6, ZoneKind::Bearing);
        let near = zone([0.0, 1.1 + 0.6], [1.0, 0.0], 1.2, ZoneKind::Anchor);
        let far = zone([0.0, 1.3 + 0.6], [1.0, 0.0], 1.2, ZoneKind::Anchor);
        assert!((polygon_gap(&near.corners(), &b.corners()) - 0.5).abs() < 1e-12);
        assert!((polygon_gap(&far.corners(), &b.corners()) - 0.7).abs() < 1e-12);
        assert_eq!(end_blocks(&[near, b]).len(), 1);
        let b = zone([0.5, 0.0], [0.0, 1.0], 0.6, ZoneKind::Bearing);
        let far = zone([0.0, 1.9], [1.0, 0.0], 1.2, ZoneKind::Anchor);
        assert!(end_blocks(&[far, b]).is_empty());
        let a1 = zone([0.0, 1.0], [1.0, 0.0], 1.2, ZoneKind::Anchor);
        let a2 = zone([0.0, 1.0], [1.0, 0.0], 0.4, ZoneKind::Anchor);
        assert!(end_blocks(&[a1, a2]).is_empty());
    }
}
