//! Concrete modelled as elastic, checked against its strength (src/results/strength.rs,
//! docs/running.md "Concrete past its strength"). A prism in uniform uniaxial stress: the
//! stress of every Gauss point (and the contact stress of a joint across it) is the applied
//! edge load over the section, exactly, so the increment at which the strength is first
//! passed and the stress there follow by hand.

mod common;

use common::{code, segfem, stderr, stdout, TempDir};

/// Edge load per unit load factor [N/m] on a 0.1 m thick section: σ = 10 MPa per unit.
const Q: f64 = 1e6;
const T: f64 = 0.1;

/// A 1 m × 0.2 m prism of 0.1 m thickness, held at x = 0 (ux on the edge, uy at one corner:
/// free to contract, so the stress is uniaxial) and loaded on the edge x = 1 m by
/// `sign` × Q per unit factor. `segments` > 1: a segmental prism with dry joints. `material`:
/// the keys after `kind = "elastic"`. `steps`: the steps' TOML.
fn prism(material: &str, segments: usize, sign: f64, steps: &str) -> String {
    let mesh = if segments > 1 {
        format!(
            "type = \"segmental\"\nn_segments = {segments}\nnx_per_segment = 2\njoint_material = \"dry\""
        )
    } else {
        "type = \"banded\"\nnx = 4".to_string()
    };
    format!(
        r#"
[[materials]]
name = "c"
kind = "elastic"
E = 35e9
nu = 0.2
{material}

[[regions]]
name = "r"
material = "c"
thickness = {T}

[[joint_materials]]
name = "dry"
kind = "dry"
friction = 0.7

[mesh]
{mesh}
length = 1.0
element = "Q4"
bands = [{{ region = "r", depth = 0.2, rows = 2 }}]

[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.2]]
ux = 0.0

[[supports]]
name = "pin"
point = [0.0, 0.0]
uy = 0.0

[[load_cases]]
name = "P"
line_loads = [{{ line = [[1.0, 0.0], [1.0, 0.2]], q = [{qx}, 0.0] }}]

{steps}
"#,
        qx = sign * Q,
    )
}

/// Runs the model; returns (exit code, stderr then stdout, summary.json).
fn run(name: &str, text: &str) -> (i32, String, serde_json::Value) {
    let (rc, out, s, _) = run_in(name, text);
    (rc, out, s)
}

/// As [`run`], keeping the directory (the run's results in `out/`).
fn run_in(name: &str, text: &str) -> (i32, String, serde_json::Value, TempDir) {
    let tmp = TempDir::new(name);
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out"]);
    let s: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(tmp.join("out/summary.json"))
            .unwrap_or_else(|e| panic!("no summary.json ({e}): {}", stderr(&o))),
    )
    .unwrap();
    (code(&o), format!("{}{}", stderr(&o), stdout(&o)), s, tmp)
}

/// `n` load increments up to factor `lam`.
fn load_step(lam: f64, n: usize) -> String {
    format!(
        "[[steps]]\nname = \"load\"\nkind = \"load\"\nloads = {{ P = {lam} }}\nincrements = {n}\n"
    )
}

/// The first increment k (1-based) of `n` up to `lam` whose stress k/n · lam · Q/T passes
/// `limit` [Pa], and that stress.
fn first_past(lam: f64, n: usize, limit: f64) -> (u64, f64) {
    (1..=n)
        .map(|k| (k as u64, k as f64 / n as f64 * lam * Q / T))
        .find(|&(_, s)| s > limit)
        .expect("the load passes the strength")
}

/// The finding of `kind` in summary.json.
fn finding<'a>(s: &'a serde_json::Value, kind: &str) -> &'a serde_json::Value {
    s["strength_exceeded"]
        .as_array()
        .expect("strength_exceeded")
        .iter()
        .find(|f| f["kind"] == kind)
        .unwrap_or_else(|| panic!("no {kind} finding: {s}"))
}

/// Compression of a segmental prism with fcm = 47 MPa (no increment lands on it: round-off
/// cannot decide) in 12 increments of 5 MPa: first past f_cm at 50 MPa (increment 10) in the concrete and at the joint alike; the worst is the
/// last increment's 60 MPa. Stresses exact to round-off (uniform field, linear elements).
#[test]
fn compression_and_joint_contact_past_fcm_are_reported_where_first_met() {
    let text = prism("fcm = 47e6", 2, -1.0, &load_step(6.0, 12));
    let (rc, err, s) = run("strength-compression", &text);
    assert_eq!(rc, 0, "{err}");
    let (k, stress) = first_past(6.0, 12, 47e6);
    assert_eq!(k, 10);
    for kind in ["compression", "joint_contact"] {
        let f = finding(&s, kind);
        assert_eq!(f["limit_pa"].as_f64().unwrap(), 47e6, "{f}");
        assert_eq!(f["increment"].as_u64().unwrap(), k, "{f}");
        assert_eq!(f["step"], "load", "{f}");
        let first = f["first_pa"].as_f64().unwrap();
        assert!(
            (first - stress).abs() < 1e-9 * stress,
            "{first} vs {stress}"
        );
        let worst = f["worst_pa"].as_f64().unwrap();
        assert!((worst - 60e6).abs() < 1e-9 * 60e6, "{worst}");
    }
    assert_eq!(finding(&s, "joint_contact")["first_at"], "joint J1");
    // No tension anywhere: no tension finding.
    assert_eq!(s["strength_exceeded"].as_array().unwrap().len(), 2, "{s}");
    assert!(
        err.contains("warning: concrete past its strength: compression 50.0 MPa > fcm 47.0 MPa"),
        "{err}"
    );
    assert!(
        s["warnings"].as_array().unwrap().iter().any(|w| w
            .as_str()
            .unwrap()
            .contains("joint contact stress 50.0 MPa")),
        "{s}"
    );
}

/// Tension in 20 increments of 0.25 MPa. f_tm from f_cm = 45 MPa by the `concrete` kind's
/// formula, 10 MPa · 0.14 · 4.5^(2/3) = 3.8165 MPa: first past at 4.00 MPa (increment 16);
/// from class C40/50, EN 1992-1-1 f_ctm = 0.30 · 40^(2/3) = 3.5088 MPa: at 3.75 MPa
/// (increment 15). No compression: the class's f_cm = 48 MPa is never reached.
#[test]
fn tension_past_ftm_from_fcm_or_from_the_class() {
    let ftm_45 = 1e7 * 0.14 * 4.5f64.powf(2.0 / 3.0);
    let ftm_c40 = 0.30 * 40f64.powf(2.0 / 3.0) * 1e6;
    for (material, ftm, k_expected) in [
        ("fcm = 45e6", ftm_45, 16),
        ("class = \"C40/50\"", ftm_c40, 15),
    ] {
        let text = prism(material, 1, 1.0, &load_step(0.5, 20));
        let (rc, err, s) = run("strength-tension", &text);
        assert_eq!(rc, 0, "{err}");
        let (k, stress) = first_past(0.5, 20, ftm);
        assert_eq!(k, k_expected);
        let f = finding(&s, "tension");
        assert!(
            (f["limit_pa"].as_f64().unwrap() - ftm).abs() < 1e-9 * ftm,
            "{f}"
        );
        assert_eq!(f["increment"].as_u64().unwrap(), k, "{f}");
        let first = f["first_pa"].as_f64().unwrap();
        assert!(
            (first - stress).abs() < 1e-9 * stress,
            "{first} vs {stress}"
        );
        assert_eq!(s["strength_exceeded"].as_array().unwrap().len(), 1, "{s}");
    }
}

/// Below its strength, or without one, nothing is reported.
#[test]
fn no_finding_below_the_strength_or_without_one() {
    for (material, lam) in [("fcm = 45e6", 4.0), ("", 6.0)] {
        let text = prism(material, 2, -1.0, &load_step(lam, 8));
        let (rc, err, s) = run("strength-none", &text);
        assert_eq!(rc, 0, "{err}");
        assert_eq!(s["strength_exceeded"].as_array().unwrap().len(), 0, "{s}");
        assert!(!err.contains("past its strength"), "{err}");
    }
}

/// A run to failure (arc length on P) whose compression passes f_cm before its end: the
/// verdict is an upper bound, naming the stress, the strength and the load factor where it
/// was first passed (σ = 10 MPa per unit factor: the factor there is σ/10 MPa).
#[test]
fn a_run_to_failure_past_fcm_reads_as_an_upper_bound() {
    let steps = r#"
[[steps]]
name = "push"
kind = "arc_length"
loads = { P = 1.0 }
initial_increment = 0.5
max_growth = 1.0
stop_displacement = { point = [1.0, 0.0], component = "x", value = -2e-3 }
increments = 40
"#;
    let text = prism("fcm = 45e6", 2, -1.0, steps);
    let (rc, err, s, tmp) = run_in("strength-upper-bound", &text);
    assert_eq!(rc, 0, "{err}");
    let u = &s["ultimate"];
    let ub = u["upper_bound"].as_str().expect("upper_bound");
    assert!(ub.starts_with("concrete compression"), "{u}");
    assert!(ub.contains("> fcm 45.0 MPa"), "{u}");
    let f = finding(&s, "compression");
    let first = f["first_pa"].as_f64().unwrap();
    let at = f["at_factor"].as_f64().unwrap();
    assert!((at * Q / T - first).abs() < 1e-9 * first, "{f}");
    assert!(first > 45e6, "{f}");
    assert!(ub.ends_with(&format!("P = {at:.4}")), "{ub}");
    assert!(err.contains("; upper bound: concrete"), "{err}");
    // The report flags it under the verdict.
    let o = segfem(tmp.path(), &["report", "out"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let html = std::fs::read_to_string(tmp.join("out/report.html")).unwrap();
    assert!(
        html.contains("<div id=\"strength\" class=\"bad\">"),
        "no flag"
    );
    assert!(
        html.contains("Concrete past its strength (2 checks failed)"),
        "flag text"
    );
    // The verdict's factor said as the force it stands for: the edge load Q × 0.2 m of
    // edge = 200 kN per unit factor (issue 40 item 7).
    let line = format!(
        "P is a factor of the case's 200.0 kN in all: none reached at {:.1} kN, peak {:.1} kN",
        u["at_factor"].as_f64().unwrap() * Q * 0.2 / 1e3,
        u["peak_factor"].as_f64().unwrap() * Q * 0.2 / 1e3
    );
    assert!(
        html.contains(&line),
        "no force line in the headline: {line}"
    );
}
