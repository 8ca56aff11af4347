//! Stress monitors against closed forms (issue 23 item 7): σx, τxy and σ1 at the Gauss
//! point nearest a point of an end-loaded cantilever against beam theory (which is the
//! plane-stress elasticity solution here, Timoshenko & Goodier §21), the extremes over a
//! region of a uniformly compressed block, and the peak contact stress of a dry joint under
//! eccentric compression against N/A + N e/W.

use segfem::run::{run_file, Summary};
use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("segfem-stress-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Run model text; the final value of each monitor by name.
fn run(name: &str, text: &str) -> Summary {
    let dir = tmp(name);
    let path = dir.join("m.toml");
    std::fs::write(&path, text).unwrap();
    run_file(&path, &dir.join("out"), &mut |_| {}).expect("runs")
}

fn monitor(s: &Summary, name: &str) -> f64 {
    s.final_monitors
        .iter()
        .find(|(n, _)| n == name)
        .unwrap_or_else(|| panic!("no monitor {name}"))
        .1
}

fn example(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("examples/{name}.toml"));
    std::fs::read_to_string(p).unwrap()
}

/// The cantilever example (L = 4 m, h = 0.5 m, t = 0.1 m, end shear P = 20 kN/m × 0.5 m =
/// 10 kN down, Q8 elements 0.125 × 0.125 m with 3 × 3 Gauss points). The monitors ask for
/// Gauss point positions: element column 16 (x ∈ [2.0, 2.125], ξ = 0 → x = 2.0625), top
/// row (η = +√0.6) and the row above the axis (η = −√0.6).
#[test]
fn cantilever_stresses_at_gauss_points_follow_beam_theory() {
    let g = 0.6f64.sqrt();
    let x = 2.0625;
    let y_top = 0.1875 + 0.0625 * g;
    let y_axis = 0.0625 - 0.0625 * g;
    let text = format!(
        "{}\n{}",
        example("cantilever"),
        format_args!(
            r#"
[[monitors]]
name = "sx_top"
kind = "stress"
component = "sx"
point = [{x}, {y_top}]

[[monitors]]
name = "s1_top"
kind = "stress"
component = "s1"
point = [{x}, {y_top}]

[[monitors]]
name = "txy_axis"
kind = "stress"
component = "txy"
point = [{x}, {y_axis}]
"#
        )
    );
    let s = run("cantilever", &text);
    let (p, l, h, t) = (10e3, 4.0, 0.5, 0.1);
    let i = t * h * h * h / 12.0;
    // Beam theory = the elasticity solution of the end-loaded cantilever: σx = M y / I with
    // the hogging moment M = P (L − x); τxy = −P/(2I) (h²/4 − y²) (the section's shear
    // force acts downwards on the +x face).
    let sx = |y: f64| p * (l - x) * y / i;
    let txy = |y: f64| -p / (2.0 * i) * (h * h / 4.0 - y * y);
    let s1 = {
        let (a, b) = (sx(y_top) / 2.0, txy(y_top));
        a + a.hypot(b)
    };
    // σx 1e-7 (was 1 %; docs/validation.md, tolerance changes; measured 1.8e-11): the Q8
    // field is exact for the linear σx of pure bending at its Gauss points; the fully
    // clamped wall is felt within about h of x = 0, here 2 m away, where its disturbance has
    // decayed like e^(−πx/h) (~1e-11). τxy 1 % (measured 0.67 %): the Q8's shear stress at a
    // Gauss point of a parabolic τ field. σ1 1e-4 (was 1 %; measured 7.3e-6): at the top
    // fibre τ is small and its 0.7 % error enters σ1 only as τ²/σx.
    for (name, got, want, tol) in [
        ("sx_top", monitor(&s, "sx_top"), sx(y_top), 1e-7),
        ("s1_top", monitor(&s, "s1_top"), s1, 1e-4),
        ("txy_axis", monitor(&s, "txy_axis"), txy(y_axis), 1e-2),
    ] {
        eprintln!("{name}: relative error {:.2e}", (got / want - 1.0).abs());
        assert!(
            (got - want).abs() <= tol * want.abs(),
            "{name}: {got:.6e} Pa vs beam theory {want:.6e} Pa"
        );
    }
}

/// A 1 m × 1 m block, 0.2 m thick, under a uniform top line load of 1 MN/m: σy = −q/t =
/// −5 MPa, σx = τxy = 0 everywhere (free sides, one point held in x). The extremes over the
/// region: σ2 (default min) = −5 MPa, σ1 (default max) = 0, σy min = −5 MPa, σx "abs" = 0;
/// and σy at a point equals it.
#[test]
fn compressed_block_extremes_over_a_region() {
    let text = r#"
title = "uniformly compressed block"

[[materials]]
name = "c"
kind = "elastic"
E = 30e9
nu = 0.2

[[regions]]
name = "block"
material = "c"
thickness = 0.2

[mesh]
type = "banded"
length = 1.0
nx = 4
element = "Q8"
bands = [{ region = "block", depth = 1.0, rows = 4 }]

[[supports]]
name = "base"
line = [[0.0, 0.0], [1.0, 0.0]]
uy = 0.0

[[supports]]
name = "pin"
point = [0.0, 0.0]
ux = 0.0

[[load_cases]]
name = "q"
line_loads = [{ line = [[0.0, 1.0], [1.0, 1.0]], q = [0.0, -1e6] }]

[[monitors]]
name = "s2_min"
kind = "stress"
component = "s2"
region = "block"

[[monitors]]
name = "s1_max"
kind = "stress"
component = "s1"

[[monitors]]
name = "sy_min"
kind = "stress"
component = "sy"
region = "block"
extreme = "min"

[[monitors]]
name = "sx_abs"
kind = "stress"
component = "sx"
extreme = "abs"

[[monitors]]
name = "sy_point"
kind = "stress"
component = "sy"
point = [0.4, 0.6]

[[steps]]
name = "load"
kind = "linear"
loads = { q = 1.0 }
"#;
    let s = run("block", text);
    let sy: f64 = -1e6 / 0.2;
    // 1e-6 of 5 MPa: a uniform stress is reproduced exactly by the elements; only
    // round-off of the solve remains.
    let tol = 1e-6 * sy.abs();
    for (name, want) in [
        ("s2_min", sy),
        ("s1_max", 0.0),
        ("sy_min", sy),
        ("sx_abs", 0.0),
        ("sy_point", sy),
    ] {
        let got = monitor(&s, name);
        assert!((got - want).abs() <= tol, "{name}: {got:.6e} vs {want:.6e}");
    }
    let units: Vec<&str> = s.monitors.iter().map(|m| m.unit.as_str()).collect();
    assert!(units.iter().all(|u| *u == "Pa"), "{units:?}");
}

/// The segmental-decompression example after its prestress step: P = 600 kN over the lower
/// 0.4 m of the 0.5 m × 0.3 m end faces (e = 0.05 m below the centroid). At the joints, 2 m
/// (4 h) from the ends, the contact stress is N/A + N e/W at the bottom fibre:
/// 600e3/0.15 + 600e3 × 0.05/(0.3 × 0.5²/6) = 4.0 + 2.4 = 6.4 MPa, where the joint's
/// Lobatto integration has a point; nothing opens.
#[test]
fn joint_contact_stress_under_eccentric_compression() {
    let ex = example("segmental-decompression");
    // The prestress step only: cut the file before the bending step.
    let cut = ex.match_indices("[[steps]]").nth(1).unwrap().0;
    let text = format!(
        "{}\n{}",
        &ex[..cut],
        r#"
[[monitors]]
name = "J1_sn"
kind = "joint_contact_stress"
joint = "J1"

[[monitors]]
name = "all_sn"
kind = "joint_contact_stress"
joint = "all"
"#
    );
    let s = run("joint", &text);
    let (n, b, h, e) = (600e3, 0.3, 0.5, 0.05);
    let want = n / (b * h) + n * e / (b * h * h / 6.0);
    // 1e-5 (was 1 %; docs/validation.md, tolerance changes; measured 1.13e-6): the linear
    // stress distribution is exact for the Q8 segments; the end load's local distribution
    // has decayed 4 depths away (Saint-Venant, ~e^(−4π)); what remains is of the order of
    // the Newton force tolerance (1e-6 of the load).
    for name in ["J1_sn", "all_sn"] {
        let got = monitor(&s, name);
        eprintln!("{name}: relative error {:.2e}", (got / want - 1.0).abs());
        assert!(
            (got - want).abs() <= 1e-5 * want,
            "{name}: {got:.6e} Pa vs N/A + Ne/W = {want:.6e} Pa"
        );
    }
    assert_eq!(monitor(&s, "opening"), 0.0, "nothing opens under prestress");
}
