//! `[[regions]]`: material and thickness of parts of the mesh, boxes that move elements to
//! a region, casting days of creep regions and their ages at the start.

use super::fields::{index_by_name, positive, unique_names};
use super::R;
use crate::input::error::Ctx;
use crate::input::schema::{MeshIn, RegionIn};
use crate::input::units;
use crate::materials::steel::SteelParams;
use crate::mesh::segmental;
use crate::model::{Element, Model, NamedMaterial, Region};
use std::collections::HashMap;

/// The `[[regions]]`: a name, a continuum material and a thickness each.
pub(super) fn build(
    ctx: &Ctx,
    list: &[RegionIn],
    materials: &[NamedMaterial],
    steels: &[(String, SteelParams)],
    warnings: &mut Vec<String>,
) -> R<Vec<Region>> {
    unique_names(ctx, "regions", list.iter().map(|r| r.name.as_str()))?;
    let mut regions = Vec::new();
    for (i, r) in list.iter().enumerate() {
        if steels.iter().any(|(n, _)| *n == r.material) {
            return Err(ctx.err(
                format!("regions[{i}].material"),
                format!(
                    "'{}' is a steel material (for [[bars]]); a region needs an elastic or concrete material",
                    r.material
                ),
            ));
        }
        let material = index_by_name(
            ctx,
            &format!("regions[{i}].material"),
            "material",
            materials.iter().map(|m| m.name.as_str()),
            &r.material,
        )?;
        let thickness = positive(ctx, &format!("regions[{i}].thickness"), r.thickness)?;
        units::thickness(warnings, ctx, &format!("regions[{i}].thickness"), thickness);
        regions.push(Region {
            name: r.name.clone(),
            material,
            thickness,
        });
    }
    Ok(regions)
}

/// `regions[i].boxes`: elements whose centroid (mean of the corner nodes) lies inside one of
/// the region's boxes [[x0, y0], [x1, y1]] (m) are moved to that region, whatever the mesh
/// generator gave them (anchor blocks, loading plates). Later regions win where boxes overlap.
pub(super) fn region_boxes(
    ctx: &Ctx,
    regions: &[RegionIn],
    nodes: &[[f64; 2]],
    elements: &mut [crate::model::Element],
) -> R<()> {
    for (i, r) in regions.iter().enumerate() {
        let Some(boxes) = &r.boxes else { continue };
        for (j, [[x0, y0], [x1, y1]]) in boxes.iter().enumerate() {
            let key = format!("regions[{i}].boxes[{j}]");
            if !(x0.is_finite()
                && y0.is_finite()
                && x1 > x0
                && y1 > y0
                && x1.is_finite()
                && y1.is_finite())
            {
                return Err(ctx.err(
                    key,
                    format!("must be [[x0, y0], [x1, y1]] with x1 > x0 and y1 > y0 (got [[{x0}, {y0}], [{x1}, {y1}]])"),
                ));
            }
            let mut hit = 0;
            for e in elements.iter_mut() {
                let nc = e.kind.n_corners();
                let k = e.nodes.len().min(nc) as f64;
                let (cx, cy) = e.nodes.iter().take(nc).fold((0.0, 0.0), |(a, b), &n| {
                    (a + nodes[n][0] / k, b + nodes[n][1] / k)
                });
                if (*x0..=*x1).contains(&cx) && (*y0..=*y1).contains(&cy) {
                    e.region = i;
                    hit += 1;
                }
            }
            if hit == 0 {
                return Err(ctx.err(key, "no element centroid lies inside the box"));
            }
        }
    }
    Ok(())
}

/// Give every region with an `elastic_creep` material its casting day: regions cast on
/// different days get copies of the material (sharing the chain and its per-age cache) that
/// differ only in `cast_day`.
pub(super) fn assign_cast_days(
    ctx: &Ctx,
    input: &[Option<f64>],
    regions: &mut [Region],
    materials: &mut Vec<NamedMaterial>,
    warnings: &mut Vec<String>,
) -> R<()> {
    let mut seen = std::collections::HashSet::new();
    let mut warned = std::collections::HashSet::new();
    let mut copies: HashMap<(usize, u64), usize> = HashMap::new();
    for (i, (r, region)) in input.iter().zip(regions.iter_mut()).enumerate() {
        let m = region.material;
        let creep = materials[m].law.cast_day().is_some();
        let day = r.unwrap_or(0.0);
        if !day.is_finite() {
            return Err(ctx.err(
                format!("regions[{i}].cast_day"),
                "must be a finite number of days",
            ));
        }
        if !creep {
            // Once per material: a segmental mesh gives every segment's regions a day.
            if r.is_some() && warned.insert(m) {
                warnings.push(format!(
                    "{}: regions[{i}].cast_day: ignored, material '{}' is not time dependent",
                    ctx.file, materials[m].name
                ));
            }
            continue;
        }
        let key = (m, day.to_bits());
        if let Some(&idx) = copies.get(&key) {
            region.material = idx;
            continue;
        }
        let idx = if seen.insert(m) {
            m
        } else {
            let mut copy = materials[m].clone();
            copy.name = format!("{}{CAST_DAY_COPY}{day})", materials[m].name);
            materials.push(copy);
            materials.len() - 1
        };
        if let Some(cast_day) = materials[idx].law.cast_day_mut() {
            *cast_day = day;
        }
        copies.insert(key, idx);
        region.material = idx;
    }
    Ok(())
}

/// What a per-cast-day copy of a creep material adds to its name: "concrete (cast day -90)".
const CAST_DAY_COPY: &str = " (cast day ";

/// The `[[materials]]` name a model material comes from (a cast-day copy names its source).
pub(super) fn file_material_name(name: &str) -> &str {
    name.split(CAST_DAY_COPY).next().unwrap_or(name)
}

/// Check that every creep region exists (is cast) when the analysis starts at `start` [d],
/// or, in a staged model, when the step that activates it starts (`start_of(region)` [d]).
pub(super) fn check_ages(
    ctx: &Ctx,
    model: &Model,
    start: f64,
    start_of: impl Fn(usize) -> f64,
    warnings: &mut Vec<String>,
) -> R<()> {
    let mut used = vec![false; model.regions.len()];
    model.elements.iter().for_each(|e| used[e.region] = true);
    for (i, r) in model.regions.iter().enumerate() {
        if !used[i] {
            continue;
        }
        if let Some(cast_day) = model.materials[r.material].law.cast_day() {
            let placed = start_of(i);
            let age = placed - cast_day;
            if age < 0.0 && placed > start {
                return Err(ctx.err(
                    format!("regions[{i}].cast_day"),
                    format!(
                        "region '{}' is cast on day {cast_day} but activated on day {placed} (the start of the step that activates it)",
                        r.name
                    ),
                ));
            }
            if age < 0.0 {
                return Err(ctx.err(
                    format!("regions[{i}].cast_day"),
                    format!(
                        "region '{}' is cast on day {cast_day} but the analysis starts on day {start} (set the first time step's from, or an earlier cast_day)",
                        r.name
                    ),
                ));
            }
            if age < 1.0 {
                warnings.push(format!(
                    "{}: regions[{i}].cast_day: region '{}' is {age} d old at the start; ages below 1 d are taken as 1 d",
                    ctx.file, r.name
                ));
            }
        }
    }
    Ok(())
}

/// `mesh.segment_cast_days`: one casting day per segment of a segmental mesh. Each band
/// region is split into one region per segment ("webs@S2"), carrying that segment's day.
#[allow(clippy::too_many_arguments)]
pub(super) fn segment_regions(
    ctx: &Ctx,
    mesh: &MeshIn,
    days: &[f64],
    joints: &[segmental::Joint],
    nodes: &[[f64; 2]],
    elements: &mut [Element],
    regions: &mut Vec<Region>,
    cast_days: &mut Vec<Option<f64>>,
) -> R<()> {
    if mesh.kind != "segmental" {
        return Err(ctx.err(
            "mesh.segment_cast_days",
            "only for type = \"segmental\" (give cast_day per region otherwise)",
        ));
    }
    let n_seg = joints.len() + 1;
    if days.len() != n_seg {
        return Err(ctx.err(
            "mesh.segment_cast_days",
            format!(
                "give one day per segment: {} for {n_seg} segments",
                days.len()
            ),
        ));
    }
    if let Some(i) = days.iter().position(|d| !d.is_finite()) {
        return Err(ctx.err(
            format!("mesh.segment_cast_days[{i}]"),
            "must be a finite number of days",
        ));
    }
    let n_base = regions.len();
    let mut map: HashMap<(usize, usize), usize> = HashMap::new();
    for el in elements.iter_mut() {
        let xc = el.nodes.iter().map(|&n| nodes[n][0]).sum::<f64>() / el.nodes.len() as f64;
        let seg = joints.iter().filter(|j| j.x < xc).count();
        let key = (el.region, seg);
        let idx = *map.entry(key).or_insert_with(|| {
            let base = &regions[el.region];
            regions.push(Region {
                name: format!("{}@S{}", base.name, seg + 1),
                material: base.material,
                thickness: base.thickness,
            });
            cast_days.push(Some(days[seg]));
            regions.len() - 1
        });
        el.region = idx;
    }
    // The band regions keep their names for monitors and output but no longer own elements;
    // their own cast_day (if any) is superseded.
    for d in cast_days.iter_mut().take(n_base) {
        *d = None;
    }
    Ok(())
}

/// Place the regions on the mesh: one region per segment where `mesh.segment_cast_days` is
/// given, `regions[i].boxes`, and the casting day of each creep region (copies of its
/// material where regions of one material are cast on different days).
#[allow(clippy::too_many_arguments)]
pub(super) fn place(
    ctx: &Ctx,
    list: &[RegionIn],
    mesh: &MeshIn,
    joints: &[segmental::Joint],
    nodes: &[[f64; 2]],
    elements: &mut [Element],
    mut regions: Vec<Region>,
    mut materials: Vec<NamedMaterial>,
    warnings: &mut Vec<String>,
) -> R<(Vec<Region>, Vec<NamedMaterial>)> {
    let mut cast_days: Vec<Option<f64>> = list.iter().map(|r| r.cast_day).collect();
    if let Some(days) = &mesh.segment_cast_days {
        segment_regions(
            ctx,
            mesh,
            days,
            joints,
            nodes,
            elements,
            &mut regions,
            &mut cast_days,
        )?;
    }
    region_boxes(ctx, list, nodes, elements)?;
    assign_cast_days(ctx, &cast_days, &mut regions, &mut materials, warnings)?;
    Ok((regions, materials))
}
