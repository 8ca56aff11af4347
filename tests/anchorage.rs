//! Load introduction as members take it (docs/theory-prestress.md, "Anchor plates, bearings
//! and local zones"): the seed beam's prestress through its anchor plates on MC90 concrete,
//! a point load over a bearing, the local zones the program generates.

use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::elements::continuum::rule_points;
use segfem::model::Model;

fn seed_concrete_text() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/seed-beam.toml"
    ))
    .unwrap()
}

/// The seed beam (`seed-beam` example) up to the end of its prestress step only.
fn seed_prestress_model() -> Model {
    let text = seed_concrete_text();
    let cut = text
        .find("[[steps]]\nname = \"service\"")
        .expect("service step");
    segfem::input::parse(&text[..cut], "seed-beam.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model
}

/// A Gauss point: position [m], stress (σx, σy, τxy) [Pa], integration weight along the
/// element's η direction times the element's half height (dy of the point) [m], element.
#[derive(Clone, Copy)]
struct Gp {
    x: [f64; 2],
    stress: [f64; 3],
    dy: f64,
    element: usize,
}

/// What the prestress step leaves: the Gauss points, the crushed point count and the
/// tendon force [N] of the first span.
#[derive(Default)]
struct AtPrestress {
    gps: Vec<Gp>,
    crushed: usize,
    tendon_force: f64,
}

impl Observer for AtPrestress {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let sys = s.system;
        let m = sys.model;
        let g = &sys.families.continuum.gauss.committed;
        self.gps.clear();
        for (e, el) in m.elements.iter().enumerate() {
            let coords = m.element_coords(el);
            let rule = rule_points(el.kind, el.integration);
            let first = sys.gp_offset[e];
            assert_eq!(sys.gp_offset[e + 1] - first, rule.len());
            // Rectangular elements of the banded/segmental mesh: dy = w_η × height/2.
            let ys: Vec<f64> = coords.iter().map(|c| c[1]).collect();
            let h = ys.iter().cloned().fold(f64::MIN, f64::max)
                - ys.iter().cloned().fold(f64::MAX, f64::min);
            let n = (rule.len() as f64).sqrt().round() as usize;
            for (k, p) in rule.iter().enumerate() {
                let sh = el.kind.eval(p.0, p.1);
                let mut x = [0.0; 2];
                for (a, c) in coords.iter().enumerate() {
                    x[0] += sh.n_val[a] * c[0];
                    x[1] += sh.n_val[a] * c[1];
                }
                // Tensor rule η-major: the η weight is w / w_ξ; for the 1D Gauss weights
                // of n points, w_ξ of the point's column.
                let w_xi = gauss_1d_weight(n, k % n);
                self.gps.push(Gp {
                    x,
                    stress: g[first + k].stress,
                    dy: p.2 / w_xi * 0.5 * h,
                    element: e,
                });
            }
        }
        self.crushed = sys
            .families
            .continuum
            .points
            .committed
            .iter()
            .filter(|p| p.is_crushed())
            .count();
        let stress = sys.families.tendons.states.committed[0]
            .as_ref()
            .map(|t| t.stresses()[0])
            .unwrap_or(0.0);
        self.tendon_force = stress * m.tendons[0].area;
        Ok(())
    }
}

/// Weight of point `i` of the `n`-point Gauss–Legendre rule on [−1, 1] (n = 2 or 3).
fn gauss_1d_weight(n: usize, i: usize) -> f64 {
    match n {
        2 => 1.0,
        3 => [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0][i],
        _ => panic!("rule of {n} points"),
    }
}

/// Principal compression σ2 [Pa] of a plane stress state.
fn sigma2(s: [f64; 3]) -> f64 {
    let c = 0.5 * (s[0] + s[1]);
    let r = (0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2]).sqrt();
    c - r
}

/// The seed's prestress (P ≈ 490 kN on 4 strands) enters through the default anchor plates
/// (0.085 √4 = 0.17 m) on MC90 concrete of f_cm = 45 MPa: no point crushes and no Gauss
/// point anywhere is compressed beyond f_cm. At the first column of Gauss points behind the
/// left plate (9.7 mm from the end face), the mean σx over the plate's height is the plate
/// pressure P cos θ / (a t) (hand value: a = 0.17 m, t = 0.20 m of web, θ the tendon's slope
/// 0.2/2.4), and the σx resultant of that column over the whole depth is −P cos θ
/// (horizontal equilibrium of the slice between the end face and the column: the supports
/// take no horizontal force).
#[test]
fn seed_prestress_through_anchor_plates_leaves_the_anchor_zone_sound() {
    let model = seed_prestress_model();
    let mut at = AtPrestress::default();
    steps::run(&model, &mut at).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(at.crushed, 0, "crushed points after prestress");
    let fcm = 45e6;
    let worst = at
        .gps
        .iter()
        .map(|g| sigma2(g.stress))
        .fold(f64::MAX, f64::min);
    assert!(worst > -fcm, "σ2 = {:.1} MPa", worst / 1e6);
    // The plate pressure by hand.
    let (a, t) = (0.17, 0.20);
    let cos = 2.4 / (2.4f64 * 2.4 + 0.2 * 0.2).sqrt();
    let p = at.tendon_force;
    // The tendon loses its own elastic shortening, E_p ε_c at its level (P/(E_c A) on the
    // 0.27 m² section is 1.1 % of σp0, the eccentric part about as much): within 4 %.
    let p0 = 876e6 * 560e-6;
    assert!(p < p0 && p > 0.96 * p0, "P = {p}");
    let x_min = at.gps.iter().map(|g| g.x[0]).fold(f64::MAX, f64::min);
    let column: Vec<&Gp> = at
        .gps
        .iter()
        .filter(|g| (g.x[0] - x_min).abs() < 1e-9)
        .collect();
    let under: Vec<&&Gp> = column
        .iter()
        .filter(|g| (g.x[1] - 0.30).abs() <= 0.5 * a)
        .collect();
    let mean = under.iter().map(|g| g.stress[0]).sum::<f64>() / under.len() as f64;
    let hand = -p * cos / (a * t);
    eprintln!(
        "P = {:.1} kN, plate pressure {:.2} MPa, mean σx under the plate {:.2} MPa ({} points), worst σ2 {:.1} MPa",
        p / 1e3,
        hand / 1e6,
        mean / 1e6,
        under.len(),
        worst / 1e6
    );
    // 15 %: the Gauss points sample the pressure between the plate's 4 Q8 nodes as the
    // quadratic field through them (the plate's edges at ±85 mm fall inside elements 0.1 m
    // high), and 9.7 mm behind the face the pressure has begun to spread.
    assert!(
        (mean - hand).abs() < 0.15 * hand.abs(),
        "mean σx under the plate {:.2} MPa vs P cos θ/(a t) = {:.2} MPa",
        mean / 1e6,
        hand / 1e6
    );
    // Resultant of the column: Σ σx t dy over every band.
    let resultant: f64 = column
        .iter()
        .map(|g| {
            let region = model.elements[g.element].region;
            g.stress[0] * model.regions[region].thickness * g.dy
        })
        .sum();
    // 3 %: Gauss-point stresses of a coarse mesh satisfy equilibrium only in the weak
    // sense; the column is 9.7 mm from the loaded face.
    assert!(
        (resultant + p * cos).abs() < 0.03 * p * cos,
        "σx resultant {:.1} kN vs −P cos θ = {:.1} kN",
        resultant / 1e3,
        -p * cos / 1e3
    );
}

/// The anchors' ties: the default plate 0.17 m spreads each anchor over the nodes of the end
/// face within ±0.085 m of the anchor's height (and the Q8 nodes of the edges it partly
/// covers), with weights summing to 1 whose centroid is the anchor (a centred plate).
#[test]
fn seed_anchor_plate_ties_are_centred_on_the_anchor() {
    let model = seed_prestress_model();
    let t = &model.tendons[0];
    for (p, x_face) in [(0, 0.0), (t.nodes.len() - 1, 7.2)] {
        let tie = &t.ties[p];
        assert!(tie.len() >= 3, "{tie:?}");
        let sum: f64 = tie.iter().map(|(_, w)| w).sum();
        assert!((sum - 1.0).abs() < 1e-12, "Σw = {sum}");
        let mut y = 0.0;
        for &(n, w) in tie {
            let c = model.nodes[n];
            assert!((c[0] - x_face).abs() < 1e-9, "node {c:?} off the end face");
            // The plate's edges lie inside the 0.1 m edges from 0.2 to 0.4 m.
            assert!((0.2 - 1e-9..=0.4 + 1e-9).contains(&c[1]), "node {c:?}");
            y += w * c[1];
        }
        assert!((y - 0.30).abs() < 1e-12, "centroid y = {y}");
    }
    // The deviators stay on their own nodes.
    for tie in &t.ties[1..t.nodes.len() - 1] {
        assert_eq!(tie.len(), 1);
    }
}

/// The local zones of the seed beam (coarse mesh): behind each anchor plate the elements
/// whose centroid lies in the box 0.17 m deep and 0.17 m wide centred on the anchor, and
/// over each support's 0.2 m bearing those within 0.1 m of the support along the soffit
/// and 0.2 m above it; all others keep the MC90 concrete. Counted here from the geometry.
#[test]
fn seed_local_zones_are_the_boxes_behind_plates_and_over_bearings() {
    let model = seed_prestress_model();
    let inside = |c: [f64; 2]| {
        let anchor = |x0: f64| (c[0] - x0).abs() <= 0.17 && (c[1] - 0.30).abs() <= 0.085;
        let support = |x0: f64| (c[0] - x0).abs() <= 0.1 && c[1] <= 0.2;
        anchor(0.0) || anchor(7.2) || support(0.0) || support(7.2)
    };
    let mut zone = 0;
    for e in &model.elements {
        let c = e.nodes.iter().take(4).fold([0.0, 0.0], |a, &n| {
            [
                a[0] + model.nodes[n][0] / 4.0,
                a[1] + model.nodes[n][1] / 4.0,
            ]
        });
        let region = &model.regions[e.region];
        let elastic = model.materials[region.material].law.is_linear();
        assert_eq!(elastic, inside(c), "element at {c:?} in '{}'", region.name);
        zone += usize::from(elastic);
    }
    // Coarse mesh (0.171 m × 0.1 m elements): 2 behind each plate, 2 over each bearing.
    assert_eq!(zone, 8);
}

/// An elastic simply supported beam (L = 4 m) under F = 100 kN at x = 1.5 m on its top face,
/// once as a point load and once over a 0.3 m bearing (its ends inside 0.2 m elements): the
/// bearing's nodal forces have the resultant F and its moment about the left support F x,
/// and the reactions are the statics ones, F (L − x)/L and F x/L, in both runs.
#[test]
fn a_load_over_a_bearing_keeps_its_resultant_and_the_statics_reactions() {
    let text = |bearing: &str| {
        format!(
            r#"
[[materials]]
name = "c"
kind = "elastic"
E = 30e9
nu = 0.2
[[regions]]
name = "web"
material = "c"
thickness = 0.3
[mesh]
type = "banded"
length = 4.0
nx = 20
element = "Q8"
bands = [{{ region = "web", depth = 0.4, rows = 4 }}]
[[supports]]
name = "left"
point = [0.0, 0.0]
ux = 0.0
uy = 0.0
[[supports]]
name = "right"
point = [4.0, 0.0]
uy = 0.0
[[load_cases]]
name = "F"
point_loads = [{{ point = [1.5, 0.4], force = [0.0, -100e3]{bearing} }}]
[[steps]]
name = "load"
kind = "load"
loads = {{ F = 1.0 }}
"#
        )
    };
    let (f, x, l) = (100e3, 1.5, 4.0);
    let mut reactions = Vec::new();
    for b in ["", ", bearing = 0.3"] {
        let model = segfem::input::parse(&text(b), "bearing.toml")
            .unwrap_or_else(|e| panic!("{e}"))
            .model;
        let case = &model.load_cases[0];
        let fy: f64 = case.point_forces.iter().map(|(_, v)| v[1]).sum();
        let mx: f64 = case
            .point_forces
            .iter()
            .map(|(n, v)| v[1] * model.nodes[*n][0])
            .sum();
        // Round-off of the weights' sum (1e-12 relative).
        assert!((fy + f).abs() < 1e-9 * f, "Σ fy = {fy}");
        assert!((mx + f * x).abs() < 1e-9 * f * x, "Σ fy x = {mx}");
        if !b.is_empty() {
            // Spread: the nodes of the top face over [1.35, 1.65] and the edges it cuts.
            assert!(case.point_forces.len() >= 5, "{:?}", case.point_forces);
            for (n, _) in &case.point_forces {
                let c = model.nodes[*n];
                assert!(
                    (c[1] - 0.4).abs() < 1e-12 && (1.2..=1.8).contains(&c[0]),
                    "{c:?}"
                );
            }
        }
        #[derive(Default)]
        struct R(Vec<f64>);
        impl Observer for R {
            fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
                let m = s.system.model;
                self.0 = m
                    .supports
                    .iter()
                    .map(|sp| {
                        sp.dofs
                            .iter()
                            .filter(|(_, d, _)| d.index() == 1)
                            .map(|(n, _, _)| s.f_int[2 * n + 1] - s.f_ext[2 * n + 1])
                            .sum()
                    })
                    .collect();
                Ok(())
            }
        }
        let mut r = R::default();
        steps::run(&model, &mut r).unwrap_or_else(|e| panic!("{e}"));
        reactions.push(r.0);
    }
    for r in &reactions {
        // Statics of a determinate beam; the solver's round-off.
        assert!((r[0] - f * (l - x) / l).abs() < 1e-6 * f, "{r:?}");
        assert!((r[1] - f * x / l).abs() < 1e-6 * f, "{r:?}");
    }
}

/// A bonded post-tensioned tendon (the `pt-beam` example, its concrete made MC90): the
/// local zones behind both anchors are the elements whose centroid lies in the box as wide
/// and as deep as the default plate (1500 mm² = 11 strands of 140 mm²: 0.085 √11 =
/// 0.282 m), along the parabola's end tangent (slope ∓4 × 0.25/12 at the ends, from the
/// parabola y = 0.4 − 4 s x (L − x)/L² with sag s = 0.25 m, L = 12 m), counted here from the
/// geometry.
#[test]
fn bonded_tendon_anchors_get_local_zones_along_the_end_tangent() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/pt-beam.toml"
    ))
    .unwrap();
    let concrete = text.replacen(
        "kind = \"elastic\"\nE = 35e9",
        "kind = \"concrete\"\nfcm = 45e6",
        1,
    );
    assert_ne!(concrete, text, "pt-beam.toml changed");
    let model = segfem::input::parse(&concrete, "pt.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let a = 0.085 * 11f64.sqrt();
    let slope: f64 = 4.0 * 0.25 / 12.0;
    let n = (1.0 + slope * slope).sqrt();
    // Anchor, unit direction into the member.
    let ends = [
        ([0.0, 0.4], [1.0 / n, -slope / n]),
        ([12.0, 0.4], [-1.0 / n, -slope / n]),
    ];
    let inside = |c: [f64; 2]| {
        ends.iter().any(|(p, d)| {
            let (dx, dy) = (c[0] - p[0], c[1] - p[1]);
            let s = dx * d[0] + dy * d[1];
            let t = -dx * d[1] + dy * d[0];
            (-1e-9..=a + 1e-9).contains(&s) && t.abs() <= 0.5 * a + 1e-9
        })
    };
    let mut zone = [0, 0];
    for e in &model.elements {
        let c = e.nodes.iter().take(4).fold([0.0, 0.0], |s, &k| {
            [
                s[0] + model.nodes[k][0] / 4.0,
                s[1] + model.nodes[k][1] / 4.0,
            ]
        });
        let elastic = model.materials[model.regions[e.region].material]
            .law
            .is_linear();
        assert_eq!(elastic, inside(c), "element at {c:?}");
        if elastic {
            zone[usize::from(c[0] > 6.0)] += 1;
        }
    }
    // Both anchors have a zone, mirror images of each other.
    assert!(zone[0] > 0 && zone[0] == zone[1], "{zone:?}");
}
