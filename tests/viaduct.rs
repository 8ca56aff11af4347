//! The bundled three-span viaduct (examples/viaduct.toml, issue 20 item 5) through its
//! erection, span by span on falsework: the reactions against the statics of the stage
//! sequence (span 1 carries its weight as a simple span, span 2 its weight on two continuous
//! spans), equilibrium at every stage, and no joint opening once its span is stressed.
//! The `[viaduct]` generator: the bundled example (generated) is the same model as the one
//! written out table by table (examples/viaduct-explicit.toml), and a generated two-span
//! girder's erection reactions follow the statics of its stage sequence.
//! Run with `cargo nextest run --release -E 'binary(viaduct)'`.

mod common;

use common::{segfem, TempDir};
use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::model::{Dir, Model};
use segfem::results::stages::largest_opening;

/// The example up to the end of erection (its steps after "strike falsework 3" cut off).
fn erection_text() -> String {
    let text = include_str!("../examples/viaduct.toml");
    assert!(
        text.contains("[viaduct]"),
        "the bundled example uses the generator"
    );
    let cut = text
        .find("# ---- after erection")
        .expect("the example marks the end of erection");
    text[..cut].to_string()
}

/// Per step end: the vertical reaction of every support [N], the largest opening of an
/// acting joint [m] and the Euclidean norm of the internal forces [N].
struct Rec {
    reactions: Vec<f64>,
    opening: f64,
    f_norm: f64,
}

struct Keep<'m> {
    model: &'m Model,
    recs: Vec<Rec>,
}

impl Observer for Keep<'_> {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        if !s.end_of_step {
            return Ok(());
        }
        let reactions = self
            .model
            .supports
            .iter()
            .map(|sp| {
                sp.dofs
                    .iter()
                    .filter(|(_, d, _)| *d == Dir::Y)
                    .map(|(n, _, _)| s.f_int[2 * n + 1] - s.f_ext[2 * n + 1])
                    .sum()
            })
            .collect();
        self.recs.push(Rec {
            reactions,
            opening: largest_opening(s.system).0,
            f_norm: s.f_int.iter().map(|f| f * f).sum::<f64>().sqrt(),
        });
        Ok(())
    }
}

fn run(text: &str) -> (Model, Vec<Rec>) {
    let m = segfem::input::parse(text, "viaduct.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let mut k = Keep {
        model: &m,
        recs: Vec::new(),
    };
    steps::run(&m, &mut k).unwrap_or_else(|e| panic!("{e}"));
    let recs = k.recs;
    (m, recs)
}

fn step(m: &Model, name: &str) -> usize {
    m.steps.iter().position(|s| s.name == name).unwrap()
}

fn support(m: &Model, name: &str) -> usize {
    m.supports.iter().position(|s| s.name == name).unwrap()
}

/// Density [kg/m³] and section of the example: bottom slab 6.0 × 0.25 m, webs 0.80 × 1.90 m,
/// deck 12.0 × 0.25 m.
const RHO: f64 = 2548.4;
const AREA: f64 = 6.0 * 0.25 + 0.80 * 1.90 + 12.0 * 0.25;
const G: f64 = 9.81;

/// Deflection [per unit P/EI] at `x` of a simply supported beam of span `l` under a unit
/// point load at `a` (both from the left support).
fn point_deflection(l: f64, a: f64, x: f64) -> f64 {
    let (x, a) = if x <= a { (x, a) } else { (l - x, l - a) };
    let b = l - a;
    b * x * (l * l - b * b - x * x) / (6.0 * l)
}

/// Reactions [per unit q] at the bearings 0, `l1` and `l1 + l2` of a two-span beam of
/// uniform EI under a uniform load on [`a`, l1 + l2 + `c`] (`a` ≥ 0; the last `c` beyond
/// the end bearing): the middle reaction by compatibility (the deflection at `l1` of the
/// simple span l1 + l2, Simpson's rule over the load, cancelled by the middle reaction), the
/// others by statics.
fn two_span_reactions(l1: f64, l2: f64, a: f64, c: f64) -> [f64; 3] {
    let l = l1 + l2;
    let n = 2000;
    let h = (l - a) / n as f64;
    let mut d = 0.0;
    for k in 0..=n {
        let w = if k == 0 || k == n {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        d += w * point_deflection(l, a + k as f64 * h, l1);
    }
    d *= h / 3.0;
    // The overhang's hogging moment M = q c²/2 at the end bearing lifts x = l1 by
    // M x (l² − x²)/(6 l).
    d -= c * c / 2.0 * l1 * (l * l - l1 * l1) / (6.0 * l);
    let r_mid = d / point_deflection(l, l1, l1);
    // Moments about the end bearing.
    let r_left = ((l - a) * (l - a) / 2.0 - c * c / 2.0 - l2 * r_mid) / l;
    let r_end = (l + c - a) - r_left - r_mid;
    [r_left, r_mid, r_end]
}

#[test]
fn erection_reactions_follow_the_statics_of_the_stage_sequence() {
    let text = erection_text();
    let (m, rec) = run(&text);
    let w = RHO * G * AREA;
    let (a1, p1, p2) = (support(&m, "A1"), support(&m, "P1"), support(&m, "P2"));

    // Equilibrium at every stage: the supports (falsework included while it stands) carry
    // the weight of the segments placed so far, no more (inactive segments weigh nothing),
    // no less (a struck falsework's reaction is released in full). Tendons are internal.
    // Newton stops at a residual norm of 1e-6 ‖f_int‖ (docs/input.md, [solver]); ‖f_int‖
    // is large here (tendon anchors of 40 MN, 12 m wide slabs), and the out-of-balance of
    // the many free dofs adds up in a sum of reactions: tolerance 1e-5 ‖f_int‖ [N].
    let tol = |r: &Rec| 1e-5 * r.f_norm;
    let placed = |k: usize| {
        if k < step(&m, "place and stress span 2") {
            42.0 // S1 … S12: x = −0.5 … 41.5 m
        } else if k < step(&m, "place and stress span 3") {
            82.0
        } else {
            121.0
        }
    };
    for (k, r) in rec.iter().enumerate() {
        let total: f64 = r.reactions.iter().sum();
        let want = w * placed(k);
        assert!(
            (total - want).abs() < tol(r),
            "step '{}': supports carry {total:.0} N, the placed segments weigh {want:.0} N (tolerance {:.0} N)",
            m.steps[k].name,
            tol(r)
        );
    }

    // Span 1 (x = −0.5 … 41.5 m on bearings at 0 and 40 m) is statically determinate once
    // its falsework is struck: its tendon moves no reaction, nor does 14 days of creep.
    // R_A1 = w · 42 m · (40 − 20.5)/40 whatever the prestress. 5e-4 of R_A1: the external
    // tendon pulls along its deformed spans while the concrete is small-displacement
    // (docs/input.md), so its 40 MN leave a moment of P times the ≈ 0.3 mm its spans move
    // sideways, ≈ 12 kN·m over the 40 m span: 300 N, 1e-4 of the reaction.
    // The bearings and falsework push up only (issue 39): stressing span 1 cambers it off
    // its falsework, so in "place and stress span 1" already it hangs on A1 and P1 as the
    // simple span (a two-way falsework made A1 pull there with −1.28 MN).
    let r_a1 = w * 42.0 * (40.0 - 20.5) / 40.0;
    let tol1 = 5e-4 * r_a1;
    for name in [
        "place and stress span 1",
        "strike falsework 1",
        "span 1 creeps",
    ] {
        let r = &rec[step(&m, name)];
        assert!(
            (r.reactions[a1] - r_a1).abs() < tol1,
            "{name}: R_A1 = {:.0} N, statics {r_a1:.0} N",
            r.reactions[a1]
        );
        assert!(
            (r.reactions[p1] - (w * 42.0 - r_a1)).abs() < tol1,
            "{name}: R_P1 = {:.0} N, statics {:.0} N",
            r.reactions[p1],
            w * 42.0 - r_a1
        );
    }

    // No bearing or falsework pulls at any step end (a reaction below zero by more than
    // the equilibrium tolerance above).
    for (k, r) in rec.iter().enumerate() {
        for (s, &reaction) in r.reactions.iter().enumerate() {
            assert!(
                reaction > -tol(r),
                "step '{}': support '{}' pulls with {reaction:.0} N",
                m.steps[k].name,
                m.supports[s].name
            );
        }
    }

    // No joint opens once its span is stressed: the tendon is stressed in the step that
    // places the segments, so every acting joint is in contact at every step end. 5 µm:
    // the penalty joint's own penetration under the ≈ 5 MPa of prestress is about
    // σ h / (100 E) = 5e6 · 1.85 / (100 · 36e9) ≈ 2.6 µm (docs/input.md, penalty_factor);
    // a point "open" by less is within the contact law's resolution, not a gap.
    for (k, r) in rec.iter().enumerate() {
        assert!(
            r.opening < 5e-6,
            "step '{}': a joint opens by {:.2e} m during erection",
            m.steps[k].name,
            r.opening
        );
    }

    // Span 2 is continuous with span 1 when its falsework is struck: its own weight goes to
    // two continuous spans, while span 1 keeps carrying its weight as a simple span. The
    // part of the reactions due to self weight alone is isolated by a second run with the
    // density 10 % higher (everything else equal; all joints stay closed, so the response
    // is linear and the prestress cancels in the difference).
    let heavier = text.replace("density = 2548.4", "density = 2803.24");
    assert_ne!(heavier, text);
    let (_, rec_h) = run(&heavier);
    let dw = 0.1 * w;
    let [ra, rp, rb] = two_span_reactions(40.0, 40.0, 41.5, 1.5);
    let simple = [r_a1 / w, 42.0 - r_a1 / w, 0.0];
    let k = step(&m, "strike falsework 2");
    let fe: Vec<f64> = [a1, p1, p2]
        .iter()
        .map(|&s| (rec_h[k].reactions[s] - rec[k].reactions[s]) / dw)
        .collect();
    let beam = [simple[0] + ra, simple[1] + rp, simple[2] + rb];
    eprintln!(
        "reactions per w [m] after striking falsework 2: FE {fe:.3?}, beam theory {beam:.3?}"
    );
    // 2 % of the pier reaction: beam theory leaves out shear deformation (≈ 1 % of the
    // deflection of the released 80 m span of a 2.4 m deep box), the slightly stiffer older
    // span-1 segments (E grows ≈ 0.5 % between 89 and 104 days) and the joints' penalty
    // flexibility (uniform: it cancels); the tendon forces change by a few kN between runs.
    let tol = 0.02 * beam[1];
    for (i, name) in ["A1", "P1", "P2"].iter().enumerate() {
        assert!(
            (fe[i] - beam[i]).abs() < tol,
            "{name}: self-weight reaction {:.3} w, beam theory of the stage sequence {:.3} w",
            fe[i],
            beam[i]
        );
    }
    // Built in one go, the two spans would carry all their weight continuously: A1 15.5 w·m,
    // P1 50.0 w·m (the same beam theory) against 18.0 and 45.0 here — 3 to 6 times the
    // tolerance, so the check tells the stage sequence apart.
}

/// Every part of a model, `{:?}`-printed (shortest round-trip floats: equal strings are
/// equal numbers), by name.
fn parts(m: &Model) -> Vec<(&'static str, String)> {
    vec![
        ("nodes", format!("{:?}", m.nodes)),
        ("elements", format!("{:?}", m.elements)),
        ("regions", format!("{:?}", m.regions)),
        ("materials", format!("{:?}", m.materials)),
        ("interfaces", format!("{:?}", m.interfaces)),
        ("joints", format!("{:?}", m.joints)),
        ("tendons", format!("{:?}", m.tendons)),
        ("supports", format!("{:?}", m.supports)),
        ("load_cases", format!("{:?}", m.load_cases)),
        ("monitors", format!("{:?}", m.monitors)),
        ("steps", format!("{:?}", m.steps)),
        ("controls", format!("{:?}", m.controls)),
        ("geometry", format!("{:?}", m.geometry)),
        ("bars", format!("{:?}", m.bars)),
        ("staging", format!("{:?}", m.staging)),
        ("checks", format!("{:?}", m.checks)),
    ]
}

#[test]
fn generated_viaduct_is_the_explicit_one() {
    let parse = |text: &str, label: &str| {
        segfem::input::parse(text, label)
            .unwrap_or_else(|e| panic!("{e}"))
            .model
    };
    let generated = parse(include_str!("../examples/viaduct.toml"), "viaduct.toml");
    let explicit = parse(
        include_str!("../examples/viaduct-explicit.toml"),
        "viaduct-explicit.toml",
    );
    // The same model to the last bit (nodes, casting days, tendon nodes and friction
    // losses, stage lifetimes, steps): the analysis of one is the analysis of the other.
    for ((name, g), (_, e)) in parts(&generated).iter().zip(parts(&explicit).iter()) {
        assert!(
            g == e,
            "{name} differ between the generated and the explicit viaduct"
        );
    }
}

/// `hold_down` makes the named bearings and falsework two-way; the others stay one-way
/// (pushing up). Naming all seven gives the two-way model of before issue 39: the explicit
/// example with its `one_way` keys taken out, to the last bit.
#[test]
fn hold_down_makes_named_supports_two_way() {
    use segfem::model::Push;
    let parse = |text: &str| {
        segfem::input::parse(text, "viaduct.toml")
            .unwrap_or_else(|e| panic!("{e}"))
            .model
    };
    let example = include_str!("../examples/viaduct.toml");
    let with = |names: &str| {
        assert_eq!(example.matches("segment_length = 3.7").count(), 1);
        example.replace(
            "segment_length = 3.7",
            &format!("hold_down = [{names}]\nsegment_length = 3.7"),
        )
    };
    let m = parse(&with(r#""A1", "falsework 1""#));
    let push = |name: &str| {
        let s = m.supports.iter().position(|s| s.name == name).unwrap();
        m.staging.push(s)
    };
    assert_eq!(push("A1"), None);
    assert_eq!(push("falsework 1"), None);
    for name in ["P1", "P2", "A2", "falsework 2", "falsework 3"] {
        assert_eq!(push(name), Some(Push::PlusY), "{name}");
    }
    let all = parse(&with(
        r#""A1", "P1", "P2", "A2", "falsework 1", "falsework 2", "falsework 3""#,
    ));
    assert!(!all.staging.has_one_way());
    let two_way =
        parse(&include_str!("../examples/viaduct-explicit.toml").replace("one_way = \"+y\"\n", ""));
    for ((name, g), (_, e)) in parts(&all).iter().zip(parts(&two_way).iter()) {
        assert!(g == e, "{name} differ");
    }
}

/// A generated two-span girder: spans 16 + 16 m, 1.5 m segments, a 0.4 × 0.6 m rectangle,
/// elastic concrete, epoxy joints (bonded in tension and shear: the girder is continuous
/// without prestress).
fn two_span_girder() -> String {
    r#"
[[materials]]
name = "c"
kind = "elastic"
E = 30e9
nu = 0.2
density = 100.0

[[joint_materials]]
name = "epoxy"
kind = "epoxy"
tensile_strength = 3e6
cohesion = 6e6
friction = 0.6

[viaduct]
sequence = "span_by_span"
spans = [16.0, 16.0]
segment_length = 1.5
pier_segment = 2.0
end_segment = 2.0
overhang = 0.5
concrete = "c"
joint_material = "epoxy"
nx_per_segment = 2
section = [{ name = "web", width = 0.4, depth = 0.6, rows = 3 }]
cast_start = [-60.0, -40.0]
cast_interval = 1.0
span_interval = 14.0
"#
    .to_string()
}

#[test]
fn generated_two_span_girder_follows_the_statics_of_its_stage_sequence() {
    let (m, rec) = run(&two_span_girder());
    let w = 100.0 * G * 0.4 * 0.6;
    // What the generator built: 2 m end segments, 9 typical segments a span, a pier
    // segment over P1; bearings, a falsework per span; three steps per span.
    assert_eq!(m.joints.len(), 20, "21 segments, 20 joints");
    let names: Vec<&str> = m.supports.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names[..5], ["A1", "P1", "A2", "falsework 1", "falsework 2"]);
    assert_eq!(m.steps.len(), 6);
    let (a1, p1, a2) = (support(&m, "A1"), support(&m, "P1"), support(&m, "A2"));

    // Span 1 (x = −0.5 … 17 m: S1 … S9, the pier segment reaching 1 m past P1) on bearings
    // at 0 and 16 m is statically determinate once its falsework is struck. 1e-4 of the
    // reaction: Newton leaves a residual of 1e-6 of the forces (docs/input.md, [solver]).
    let r_a1 = w * 17.5 * (16.0 - 8.25) / 16.0;
    let r = &rec[step(&m, "strike falsework 1")];
    eprintln!(
        "after striking falsework 1 [N]: FE A1 {:.3}, P1 {:.3}; statics {r_a1:.3}, {:.3}",
        r.reactions[a1],
        r.reactions[p1],
        w * 17.5 - r_a1
    );
    for (s, want) in [(a1, r_a1), (p1, w * 17.5 - r_a1)] {
        assert!(
            (r.reactions[s] - want).abs() < 1e-4 * want,
            "{}: {:.3} N after striking falsework 1, statics {want:.3} N",
            m.supports[s].name,
            r.reactions[s]
        );
    }
    // Span 2 (x = 17 … 32.5 m) is placed stress-free on the standing span 1 and carries its
    // weight on two continuous spans; span 1 keeps its simple-span reactions (linear
    // elastic: the two add up). 1 % of the pier reaction: beam theory leaves out shear
    // deformation, (E/κG)(48/5)(h²/12)/L² ≈ 0.3 % of the deflection at L/h = 27, and the
    // epoxy joints' penalty flexibility (1 % of the neighbouring elements').
    let [ra, rp, rb] = two_span_reactions(16.0, 16.0, 17.0, 0.5);
    let want = [r_a1 + w * ra, w * 17.5 - r_a1 + w * rp, w * rb];
    let r = &rec[step(&m, "strike falsework 2")];
    eprintln!(
        "after striking falsework 2 [N]: FE {:.1?}, beam theory {want:.1?}",
        [r.reactions[a1], r.reactions[p1], r.reactions[a2]]
    );
    for (i, s) in [a1, p1, a2].into_iter().enumerate() {
        assert!(
            (r.reactions[s] - want[i]).abs() < 0.01 * want[1],
            "{}: {:.1} N after striking falsework 2, beam theory of the stage sequence {:.1} N",
            m.supports[s].name,
            r.reactions[s],
            want[i]
        );
    }
    // Built in one go the same girder would put 15 % more on P1 (the whole weight on two
    // continuous spans: 1.25·w·16 = 20 w against 17.8 w here), many times the tolerance.
    assert!((want[1] - 1.25 * w * 16.0).abs() > 5.0 * 0.01 * want[1]);
}

#[test]
fn generated_layout_of_unequal_spans() {
    // Spans 30 + 39 + 30 m with 3 m segments: 9, 12 and 9 typical segments between the 2 m
    // end segments (0.5 m overhang) and the 3 m pier segments; Q4, 4 columns a segment.
    let text = r#"
[[materials]]
name = "c"
kind = "elastic"
E = 30e9
nu = 0.2
density = 2500.0

[[materials]]
name = "y1860"
kind = "prestressing_steel"
Ep = 195e9
fptk = 1860e6

[[joint_materials]]
name = "dry"
kind = "keyed"

[viaduct]
sequence = "span_by_span"
spans = [30.0, 39.0, 30.0]
segment_length = 3.0
pier_segment = 3.0
end_segment = 2.0
overhang = 0.5
concrete = "c"
joint_material = "dry"
strand = "y1860"
element = "Q4"
nx_per_segment = 4
section = [
  { name = "slab", width = 5.0, depth = 0.3, rows = 1 },
  { name = "webs", width = 0.8, depth = 1.5, rows = 3 },
  { name = "deck", width = 10.0, depth = 0.2, rows = 1 },
]
cast_start = [-60.0, -40.0, -20.0]
cast_interval = 1.0
span_interval = 10.0

[viaduct.span_tendons]
area = 0.02
end_anchor_height = 0.8
pier_anchor_height = 1.3
deviators = [{ segment = 3, height = 0.3 }, { segment = 7, height = 0.3 }]
jacking_stress = 1300e6

[viaduct.continuity_tendons]
area = 0.005
height = 1.8
reach = 6.0
jacking_stress = 1300e6
"#;
    let built = segfem::input::parse(text, "unequal.toml").unwrap_or_else(|e| panic!("{e}"));
    let m = built.model;
    // Every point the generator wrote is a node (a bearing or a tendon point between node
    // columns would be moved with a warning); the one warning says the elastic concrete
    // does not use the casting days.
    assert_eq!(built.warnings.len(), 1, "{:?}", built.warnings);
    assert!(built.warnings[0].contains("not time dependent"));
    assert_eq!(
        m.joints.len(),
        1 + 9 + 1 + 12 + 1 + 9,
        "34 segments, 33 joints"
    );
    let at = |n: usize| m.nodes[n];
    // Bearings at the soffit, at 0, 30, 69 and 99 m.
    for (name, x) in [("A1", 0.0), ("P1", 30.0), ("P2", 69.0), ("A2", 99.0)] {
        let s = &m.supports[support(&m, name)];
        assert!(
            s.dofs.iter().all(|(n, _, _)| at(*n) == [x, 0.0]),
            "{name}: {:?}",
            s.dofs
        );
    }
    // T2: pier axis P1, centres of span 2's 3rd and 7th typical segments (the first starts
    // at 30 + 1.5 m), pier axis P2; C1 straight over P1, 6 m either side.
    let tendon = |name: &str| {
        let t = m.tendons.iter().find(|t| t.name == name).unwrap();
        t.nodes.iter().map(|&n| at(n)).collect::<Vec<_>>()
    };
    assert_eq!(
        tendon("T2"),
        [
            [30.0, 1.3],
            [31.5 + 7.5, 0.3],
            [31.5 + 19.5, 0.3],
            [69.0, 1.3]
        ]
    );
    assert_eq!(tendon("T1")[0], [-0.5, 0.8]);
    assert_eq!(tendon("T3")[3], [99.5, 0.8]);
    assert_eq!(tendon("C1"), [[24.0, 1.8], [36.0, 1.8]]);
    // Nine steps, the last creep step ending on day 30.
    assert_eq!(m.steps.len(), 9);
    assert_eq!(m.steps[8].name, "span 3 creeps");
}

/// The example's traffic case is EN 1991-2 Load Model 1 (Table 4.2, α factors 1) on its
/// 11 m carriageway (three notional lanes of 3 m and 2 m of remaining area, 4.2.3): the
/// tandems of lanes 1–3 (axle loads 300, 200 and 100 kN, two axles each) give 1200 kN in
/// all, and the UDL 9 kN/m² on lane 1 and 2.5 kN/m² on the other 8 m gives 47 kN/m over
/// both end spans (2 × 40 m). Totals exact to round-off.
#[test]
fn traffic_case_is_lm1_of_en_1991_2() {
    let text = include_str!("../examples/viaduct.toml");
    let model = segfem::input::parse(text, "viaduct.toml")
        .expect("the example is valid")
        .model;
    let lc = model
        .load_cases
        .iter()
        .find(|c| c.name == "traffic")
        .expect("a traffic case");
    // Table 4.2: Q_ik per axle [N] of lanes 1, 2, 3; q_ik [N/m²] of lane 1 and the rest.
    let (q_axle, q1, q_rest) = ([300e3, 200e3, 100e3], 9e3, 2.5e3);
    let (w, lane): (f64, f64) = (11.0, 3.0);
    let n_lanes = (w / lane).floor();
    assert_eq!(n_lanes, 3.0);
    let tandems: f64 = 2.0 * q_axle.iter().sum::<f64>();
    let udl = q1 * lane + q_rest * (w - lane);
    let fy: f64 = lc.point_forces.iter().map(|(_, f)| f[1]).sum();
    assert!((fy + tandems).abs() < 1e-9 * tandems, "tandems {fy} N");
    assert!(lc.point_forces.iter().all(|(_, f)| f[0] == 0.0));
    let udl_total: f64 = lc
        .edge_loads
        .iter()
        .map(|e| {
            let (a, b) = (model.nodes[e.nodes[0]], model.nodes[e.nodes[1]]);
            let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
            e.q[1] * len * (e.range[1] - e.range[0]) / 2.0
        })
        .sum();
    let expected = udl * 2.0 * 40.0;
    assert!(
        (udl_total + expected).abs() < 1e-9 * expected,
        "UDL {udl_total} N against {expected} N"
    );
}

/// The generator's permanent bearings are `viaduct.bearing` = 0.6 m long by default
/// (docs/input.md, "[viaduct]"): each still holds its one node (a pin), and on `kind =
/// "concrete"` the concrete over it becomes a local zone, the elements whose centroid lies
/// in the box 0.3 m either side of the bearing and 0.6 m up (or, where none does, the
/// elements at the bearing's node). Over A1 (x = 0) these are the end segment's first
/// element column (x −0.5 … 0.5) in the bottom slab (centroid 0.125 m up) and the webs' first
/// row (0.4875 m), not the next column (centroid x = 1.0 m); over P1 (x = 40, element
/// columns 1.5 m long) the two bottom-slab elements at the node. With `bearing = 0` none of
/// them is (the reaction on its node alone, before issue 38 item 2's end-block change).
/// End blocks (docs/theory-prestress.md): over P1 the span tendons' anchor boxes (1.28 m
/// plates, from 0.93 m up, 1.28 m deep into each span) come within 0.33 m of the bearing's
/// box, less than the bearing, so the hull of each pair is an end block: it reaches the
/// webs' first row of the columns beside the bearing (centroids x = 39.25 and 40.75,
/// 0.4875 m up: the hull's edge from the bearing's corner (39.7, 0) to the anchor box's
/// (38.77, 0.93) passes x = 39.21 at that height), not the next segments' columns (x = 37.575, 42.425).
/// On A1 the hull's edge from (0.3, 0) to (0.74, 0.72) stays left of x = 1.0.
#[test]
fn generated_bearings_make_the_concrete_over_them_a_local_zone() {
    let text = include_str!("../examples/viaduct-concrete.toml");
    let key = "segment_length = 3.7";
    assert_eq!(text.matches(key).count(), 1);
    let parse = |text: &str| {
        segfem::input::parse(text, "viaduct-concrete.toml")
            .unwrap_or_else(|e| panic!("{e}"))
            .model
    };
    let zoned = |m: &Model, x: f64, y: f64| -> bool {
        let e = m
            .elements
            .iter()
            .find(|e| {
                let c = e.nodes.iter().take(4).fold([0.0, 0.0], |c, &n| {
                    [c[0] + m.nodes[n][0] / 4.0, c[1] + m.nodes[n][1] / 4.0]
                });
                (c[0] - x).abs() < 1e-6 && (c[1] - y).abs() < 1e-6
            })
            .unwrap_or_else(|| panic!("no element centred at ({x}, {y})"));
        m.regions[e.region].name.ends_with("(local zone)")
    };
    let over_bearings = [(0.0, 0.125), (0.0, 0.4875), (39.25, 0.125), (40.75, 0.125)];
    let end_blocks = [(39.25, 0.4875), (40.75, 0.4875)];
    let beside = [
        (1.0, 0.125),
        (1.0, 0.4875),
        (37.575, 0.125),
        (37.575, 0.4875),
        (42.425, 0.4875),
    ];
    let m = parse(text);
    for (x, y) in over_bearings {
        assert!(zoned(&m, x, y), "element at ({x}, {y}) not in a local zone");
    }
    for (x, y) in end_blocks {
        assert!(zoned(&m, x, y), "element at ({x}, {y}) not in an end block");
    }
    for (x, y) in beside {
        assert!(!zoned(&m, x, y), "element at ({x}, {y}) in a local zone");
    }
    let a1 = &m.supports[support(&m, "A1")];
    assert_eq!(
        a1.dofs.len(),
        2,
        "A1 holds one node in x and y: {:?}",
        a1.dofs
    );
    assert_eq!(m.nodes[a1.dofs[0].0], [0.0, 0.0]);
    let none = parse(&text.replace(key, &format!("bearing = 0.0\n{key}")));
    for (x, y) in over_bearings.iter().chain(&end_blocks) {
        assert!(
            !zoned(&none, *x, *y),
            "bearing = 0: ({x}, {y}) in a local zone"
        );
    }
    let bad = segfem::input::parse(
        &text.replace(key, &format!("bearing = -0.6\n{key}")),
        "viaduct-concrete.toml",
    )
    .err()
    .expect("a negative bearing is refused")
    .to_string();
    assert!(bad.contains("viaduct.bearing"), "{bad}");
}

/// The viaduct on cracking, crushing, creeping concrete (examples/viaduct-concrete.toml,
/// issue 38 item 2) runs every stage, the 30 years, the gradient and the traffic by arc
/// length to a named failure: tendon T1 yields (its stress at 0.9 f_ptk = 1674 MPa, the
/// yield of EN 1992-1-1 3.3.6(7)'s bilinear law, Y1860) and the step reaches its stop,
/// L/100 = 0.4 m under the tandem, within its increments. Before the arc length's far
/// root was restricted to tangents with a negative pivot the step used all 300 increments
/// shuttling between two points at 5.02 × LM1, the tendon at 1550 MPa.
#[test]
fn viaduct_on_concrete_runs_to_tendon_yield_and_l_over_100() {
    let tmp = TempDir::new("viaduct-concrete");
    std::fs::write(
        tmp.join("v.toml"),
        include_str!("../examples/viaduct-concrete.toml"),
    )
    .unwrap();
    let o = segfem(tmp.path(), &["run", "v.toml", "-o", "out", "-q"]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(tmp.join("out/summary.json")).unwrap())
            .unwrap();
    let ultimate = &summary["ultimate"];
    assert_eq!(ultimate["mode"], "tendon yield", "{ultimate}");
    assert_eq!(ultimate["ended"], "completed", "{ultimate}");
    assert!(
        ultimate["unfinished"].as_array().unwrap().is_empty(),
        "{ultimate}"
    );
    let last = |name: &str| -> f64 {
        summary["final_monitors"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m[0] == name)
            .unwrap_or_else(|| panic!("no monitor {name}"))[1]
            .as_f64()
            .unwrap()
    };
    // Yielded: at or past 0.9 f_ptk (hardening goes on towards f_ptk).
    let t1 = last("T1_stress");
    assert!((0.9 * 1860e6..1860e6).contains(&t1), "T1 at {t1:e} Pa");
    // The soffit under the tandem came down by L/100 from where the step started (a few
    // mm below zero after the service traffic): at or beyond −0.4 m.
    let uy = last("uy_span1");
    assert!(uy <= -0.4, "uy under the tandem {uy} m");
}

/// Arc-size objectivity of the concrete viaduct (issue 38 item 3; heavy: three runs of the
/// whole example, about 7 s CPU each): with the failure step's `initial_increment` at
/// 0.125, 0.25 (the example's) and 0.5, the run reaches tendon yield of T1 and the yield
/// load agrees within 1 % (the task's bound; measured 5.670, 5.651, 5.683 × LM1, a spread of
/// 0.56 %, with end blocks; 5.681, 5.664, 5.712, 0.85 %, on one-way supports with 0.6 m
/// bearings before them; 5.684, 5.677, 5.689, 0.21 %, on the
/// two-way supports without bearing length of before, whose one-way version stopped at
/// 5.23–5.56 × LM1 with the end block over A1 crushing). Before the joints' contact status
/// was held when Newton cycles, 0.125 stopped at 5.05 × LM1 with a dry-joint point at J7
/// opening and closing on alternate iterations.
#[test]
fn viaduct_on_concrete_yields_within_1_percent_for_three_arc_sizes_heavy() {
    let text = include_str!("../examples/viaduct-concrete.toml");
    let key = "initial_increment = 0.25";
    assert_eq!(text.matches(key).count(), 1, "the failure step's arc size");
    let tmp = TempDir::new("viaduct-concrete-arc");
    let loads: Vec<f64> = ["0.125", "0.25", "0.5"]
        .iter()
        .map(|a| {
            let file = format!("v{a}.toml");
            let out = format!("out{a}");
            let model = text.replace(key, &format!("initial_increment = {a}"));
            std::fs::write(tmp.join(&file), model).unwrap();
            let o = segfem(tmp.path(), &["run", &file, "-o", &out, "-q"]);
            assert_eq!(
                o.status.code(),
                Some(0),
                "arc size {a}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            let summary: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(tmp.join(&out).join("summary.json")).unwrap(),
            )
            .unwrap();
            let ultimate = &summary["ultimate"];
            assert_eq!(ultimate["mode"], "tendon yield", "arc size {a}: {ultimate}");
            ultimate["at_factor"].as_f64().unwrap()
        })
        .collect();
    let (lo, hi) = loads
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), &x| (l.min(x), h.max(x)));
    eprintln!("tendon yield at {loads:?} x LM1");
    assert!(hi - lo <= 0.01 * lo, "yield at {loads:?} x LM1");
}

/// Mesh objectivity of the concrete viaduct's end blocks (issue 38 item 2; heavy: the
/// example and its webs in 8 element rows instead of 4, about 10 and 25 s of CPU): before
/// the end-block rule (docs/theory-prestress.md, "End blocks") the finer mesh left a web row
/// of plain concrete between the bearing's and the anchor's boxes over A1, which crushed in
/// the 30 years (the run stopped at 116.7 d). With it both meshes live through every stage
/// and reach a named failure in the push (4 rows: tendon T1 yields; 8 rows: measured
/// crushing at the opened joint J7 at 5.689 × LM1, beside T1's yield at 5.651 on 4 rows),
/// with peaks within 2 % (the objectivity bound of issue 38 item 3; measured −1.1 %).
#[test]
fn viaduct_on_concrete_fails_alike_with_the_webs_in_8_rows_heavy() {
    let text = include_str!("../examples/viaduct-concrete.toml");
    let key = "depth = 1.90, rows = 4 }";
    assert_eq!(text.matches(key).count(), 1, "the webs' band");
    let tmp = TempDir::new("viaduct-concrete-rows");
    let peaks: Vec<f64> = ["4", "8"]
        .iter()
        .map(|rows| {
            let file = format!("v{rows}.toml");
            let out = format!("out{rows}");
            let model = text.replace(key, &format!("depth = 1.90, rows = {rows} }}"));
            std::fs::write(tmp.join(&file), model).unwrap();
            let o = segfem(tmp.path(), &["run", &file, "-o", &out, "-q"]);
            let summary: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(tmp.join(&out).join("summary.json")).unwrap(),
            )
            .unwrap();
            let u = &summary["ultimate"];
            eprintln!("{rows} rows: exit {:?}, {u}", o.status.code());
            assert_eq!(u["peak_step"], "failure", "{rows} rows: {u}");
            let mode = u["mode"].as_str().unwrap();
            assert!(
                mode == "tendon yield" || mode.starts_with("crushing"),
                "{rows} rows: {u}"
            );
            u["peak_factor"].as_f64().unwrap()
        })
        .collect();
    assert!(
        (peaks[1] / peaks[0] - 1.0).abs() <= 0.02,
        "peaks {peaks:?} x LM1"
    );
}
