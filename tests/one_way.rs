//! One-way supports (docs/theory-stages.md, "One-way supports"; issue 39 item 1): a prop
//! under a beam cambered by prestress lifts off when the upward equivalent load exceeds the
//! self-weight and touches down again when the prestress goes; a two-way prop (a hold-down)
//! pulls instead; the statuses survive a restart bit for bit.
//! Run with `cargo nextest run --release --test one_way`.

mod common;

use common::TempDir;
use segfem::run::{run_file_opts, RunOptions};
use std::path::Path;

/// Beam length [m], depth [m], thickness [m].
const L: f64 = 10.0;
const H: f64 = 0.5;
const T: f64 = 0.3;
/// Young's modulus [Pa] and Poisson's ratio.
const E: f64 = 30e9;
const NU: f64 = 0.2;
/// Self-weight as a uniform load [N/m] (a line load, so its value is exact).
const W: f64 = 20e3;

/// A 10 m × 0.5 m beam (40 × 4 Q8) on a pin and a roller at its bottom corners and a prop
/// at mid-span. Load case `g`: the self-weight W down; `p`: the prestress as its upward
/// equivalent load (a parabolic tendon: w_p = 8 P e / L², P e / L² chosen so that p = 1
/// balances the self-weight). Steps: the self-weight alone; the prestress from 0 to 2 W in
/// eight increments (balance at p = 1, lift-off after it); the prestress taken away again
/// in eight increments (the beam comes back onto the prop).
fn beam(prop: &str) -> String {
    format!(
        r#"
title = "beam on a mid-span prop, cambered by prestress"

[[materials]]
name = "c"
kind = "elastic"
E = {E}
nu = {NU}

[[regions]]
name = "web"
material = "c"
thickness = {T}

[mesh]
type = "banded"
length = {L}
nx = 40
element = "Q8"
bands = [{{ region = "web", depth = {H}, rows = 4 }}]

[[supports]]
name = "pin"
point = [0.0, 0.0]
ux = 0.0
uy = 0.0

[[supports]]
name = "roller"
point = [{L}, 0.0]
uy = 0.0

[[supports]]
name = "prop"
point = [{m}, 0.0]
uy = 0.0
{prop}

[[load_cases]]
name = "g"
line_loads = [{{ line = [[0.0, {H}], [{L}, {H}]], q = [0.0, {wd}] }}]

[[load_cases]]
name = "p"
line_loads = [{{ line = [[0.0, {H}], [{L}, {H}]], q = [0.0, {W}] }}]

[[monitors]]
name = "R_prop"
kind = "reaction"
support = "prop"
component = "y"

[[monitors]]
name = "uy_mid"
kind = "displacement"
point = [{m}, 0.0]
component = "y"

[[steps]]
name = "self weight"
kind = "load"
increments = 1
loads = {{ g = 1.0 }}

[[steps]]
name = "stress"
kind = "load"
increments = 8
loads = {{ g = 1.0, p = 2.0 }}

[[steps]]
name = "destress"
kind = "load"
increments = 8
loads = {{ g = 1.0, p = 0.0 }}
"#,
        m = L / 2.0,
        wd = -W,
    )
}

/// Beam-theory flexibilities of the simply supported span at mid-span (Timoshenko: bending
/// and shear, κ = 5/6 of the rectangle): per unit uniform load [m per N/m] and per unit
/// point load at mid-span [m/N].
fn flexibilities() -> (f64, f64) {
    let i = T * H.powi(3) / 12.0;
    let ga = 5.0 / 6.0 * E / (2.0 * (1.0 + NU)) * T * H;
    let uniform = 5.0 * L.powi(4) / (384.0 * E * i) + L * L / (8.0 * ga);
    let point = L.powi(3) / (48.0 * E * i) + L / (4.0 * ga);
    (uniform, point)
}

/// history.csv as its header and rows of numbers.
fn history(out: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    (header, rows)
}

fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h.starts_with(name))
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

fn run(tmp: &TempDir, name: &str, text: &str, opts: &RunOptions) -> segfem::run::Summary {
    let model = tmp.join(&format!("{name}.toml"));
    std::fs::write(&model, text).unwrap();
    run_file_opts(Some(&model), &tmp.join(name), &mut |_| {}, opts)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The prop of a beam cambered by prestress: before the upward load p·W exceeds the
/// self-weight W, the prop carries the two-span continuous beam's reaction
/// R = (1 − p) W f_w / f_P (compatibility of the simply supported span: f_w, f_P its
/// mid-span flexibilities for a uniform and a point load); past it the prop lifts off
/// (R = 0) and the mid-span rises as the simply supported span, (p − 1) W f_w; taking the
/// prestress away brings the beam back onto the prop, whose reaction is then that of the
/// start again. Tolerance 1 %: the plane-stress continuum differs from Timoshenko's beam
/// by the local flexibility under the prop and the supports (0.05 % estimated from the
/// half-plane under a point load) and the shear correction κ (of order (h/L)² ≈ 0.25 % of
/// the deflection); the zero reaction after lift-off is asserted to 1e-6 W L (the Newton
/// residual).
#[test]
fn prop_lifts_off_under_camber_and_touches_down_again() {
    let tmp = TempDir::new("oneway-prop");
    let s = run(
        &tmp,
        "oneway",
        &beam("one_way = \"+y\""),
        &RunOptions::default(),
    );
    assert_eq!(s.status, "completed");
    let (fw, fp) = flexibilities();
    let (h, rows) = history(&tmp.join("oneway"));
    let (cp, cr, cu) = (col(&h, "factor:p"), col(&h, "R_prop"), col(&h, "uy_mid"));
    assert_eq!(rows.len(), 17, "1 + 8 + 8 increments");
    let r_g = W * fw / fp;
    let mut lifted = 0;
    for (k, r) in rows.iter().enumerate() {
        let p = r[cp];
        let (reaction, uy) = (r[cr], r[cu]);
        if p < 1.0 - 1e-9 {
            let want = (1.0 - p) * r_g;
            assert!(
                (reaction - want).abs() <= 0.01 * r_g,
                "row {}: p = {p}: R = {reaction} N, continuous beam {want} N",
                k + 1
            );
            assert!(
                uy.abs() <= 1e-3 * W * fw,
                "row {}: on the prop, uy = {uy}",
                k + 1
            );
        } else if p > 1.0 + 1e-9 {
            lifted += 1;
            assert!(
                reaction.abs() <= 1e-6 * W * L,
                "row {}: p = {p}: the prop pulls with {reaction} N instead of lifting off",
                k + 1
            );
            let want = (p - 1.0) * W * fw;
            assert!(
                (uy - want).abs() <= 0.01 * want,
                "row {}: p = {p}: uy = {uy} m, simply supported span {want} m",
                k + 1
            );
        }
    }
    assert_eq!(
        lifted, 7,
        "p = 1.25 … 2 and back down to 1.25: off the prop"
    );
    // Back on the prop at the end (p = 0): the reaction of the start, to the tolerance.
    let last = rows.last().unwrap();
    assert_eq!(last[cp], 0.0);
    assert!((last[cr] - r_g).abs() <= 0.01 * r_g);
    // Said in summary.json: one lift-off in 'stress', one touch-down in 'destress'.
    let summary: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(tmp.join("oneway").join("summary.json")).unwrap(),
    )
    .unwrap();
    let warnings: Vec<&str> = summary["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|w| w.as_str())
        .filter(|w| w.contains("prop"))
        .collect();
    assert_eq!(
        warnings,
        [
            "step 'stress': prop lifts off (history row 6)",
            "step 'destress': prop touches down (history row 14)"
        ]
    );
    assert!(summary["timings"]["support_switches"].as_u64().unwrap() >= 2);
}

/// A two-way prop is a hold-down: it pulls the beam down with the continuous beam's
/// reaction, negative once the prestress passes the self-weight ((1 − p) W f_w / f_P,
/// −W f_w / f_P at p = 2), and the mid-span does not move. Same tolerance as above.
#[test]
fn a_two_way_prop_holds_down() {
    let tmp = TempDir::new("oneway-hold");
    run(&tmp, "twoway", &beam(""), &RunOptions::default());
    let (fw, fp) = flexibilities();
    let (h, rows) = history(&tmp.join("twoway"));
    let (cp, cr, cu) = (col(&h, "factor:p"), col(&h, "R_prop"), col(&h, "uy_mid"));
    let r_g = W * fw / fp;
    for r in &rows {
        let want = (1.0 - r[cp]) * r_g;
        assert!((r[cr] - want).abs() <= 0.01 * r_g, "{r:?}: {want}");
        assert_eq!(r[cu], 0.0, "a held dof does not move");
    }
    let top = rows.iter().map(|r| r[cr]).fold(f64::INFINITY, f64::min);
    assert!(top < -0.99 * r_g, "the hold-down pulls: {top} N");
}

/// Stopped after the step in which the prop lifted off and restarted, the run writes the
/// same history, bit for bit, as without the stop: the checkpoint carries the statuses
/// (the prop off its seat, touching down in the step after the restart).
#[test]
fn restart_with_the_prop_lifted_is_bit_identical() {
    let tmp = TempDir::new("oneway-restart");
    let text = beam("one_way = \"+y\"");
    run(&tmp, "straight", &text, &RunOptions::default());
    let model = tmp.join("stop.toml");
    std::fs::write(&model, &text).unwrap();
    let stop = RunOptions {
        stop_after_step: Some(2),
        ..Default::default()
    };
    let e = run_file_opts(Some(&model), &tmp.join("stop"), &mut |_| {}, &stop).unwrap_err();
    assert_eq!(e.exit_code(), 4, "{e}");
    let again = RunOptions {
        restart: true,
        ..Default::default()
    };
    let s = run_file_opts(None, &tmp.join("stop"), &mut |_| {}, &again).unwrap();
    assert_eq!(s.status, "completed");
    let read = |d: &str| std::fs::read_to_string(tmp.join(d).join("history.csv")).unwrap();
    assert_eq!(read("straight"), read("stop"));
}

/// A staged model (the prop placed by the first step) reports the lift-off and the
/// touch-down as events of their steps in stages.csv, with the history rows of summary.json.
#[test]
fn stages_csv_lists_the_lift_off_and_the_touch_down() {
    let tmp = TempDir::new("oneway-stages");
    let text = beam("one_way = \"+y\"").replace(
        "increments = 1\nloads = { g = 1.0 }",
        "increments = 1\nloads = { g = 1.0 }\nactivate = [\"prop\"]",
    );
    assert!(text.contains("activate"));
    run(&tmp, "staged", &text, &RunOptions::default());
    let csv = std::fs::read_to_string(tmp.join("staged").join("stages.csv")).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert!(lines[0].ends_with(",joint,support_events"), "{}", lines[0]);
    assert_eq!(lines.len(), 4, "{csv}");
    assert!(
        lines[1].ends_with(",,"),
        "no event in the first step: {}",
        lines[1]
    );
    assert!(
        lines[2].ends_with(",prop lifts off (history row 6)"),
        "{}",
        lines[2]
    );
    assert!(
        lines[3].ends_with(",prop touches down (history row 14)"),
        "{}",
        lines[3]
    );
}

/// A beam on one-way supports only, lifted by an upward load beyond its weight, has nothing
/// left to hold it: a mechanism, which the run reports naming the supports that lifted off
/// (it fails at p = 1, where the net load vanishes, at the latest).
#[test]
fn lifting_off_every_support_is_a_mechanism_said_so() {
    let tmp = TempDir::new("oneway-mechanism");
    let text = beam("one_way = \"+y\"")
        .replace(
            "point = [0.0, 0.0]\nux = 0.0\nuy = 0.0\n",
            "point = [0.0, 0.0]\nux = 0.0\nuy = 0.0\none_way = \"+y\"\n",
        )
        .replace(
            &format!("point = [{L}, 0.0]\nuy = 0.0\n"),
            &format!("point = [{L}, 0.0]\nuy = 0.0\none_way = \"+y\"\n"),
        );
    assert_eq!(text.matches("one_way").count(), 3);
    let model = tmp.join("m.toml");
    std::fs::write(&model, &text).unwrap();
    let e = run_file_opts(
        Some(&model),
        &tmp.join("out"),
        &mut |_| {},
        &RunOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("step 'stress' did not converge")
            && e.contains("one-way supports lifted off in this attempt: 'pin', 'roller'"),
        "{e}"
    );
    // Up to the balance the beam stood on its supports: rows with p < 1 were kept.
    let (h, rows) = history(&tmp.join("out"));
    let p = col(&h, "factor:p");
    assert!(
        rows.iter().all(|r| r[p] < 1.0) && rows.len() > 4,
        "{rows:?}"
    );
}

/// The same beam cambered by a real tendon: a bonded post-tensioned parabola through the
/// centroid at the ends with sag e = 0.15 m at mid-span, stressed without friction to
/// P = 1.5 W L² / (8 e) and not grouted (it keeps its lock-off force P all along). Its
/// equivalent load on the span is the curvature force q(x) = P y'' / (1 + y'²)^{3/2}
/// (8 P e / L² = 1.5 W in the small-angle limit, 0.4 % less here on average at slopes up
/// to 4 e / L = 0.06); the anchors at the centroid over the end supports add no moment.
/// The mid-span deflection it gives the simply supported span, δ_p = ∫ q(x) G(x) dx with
/// G the mid-span influence line (Timoshenko: bending a (3L² − 4a²)/(48 EI) and shear
/// a/(2 κGA) for a load at a ≤ L/2), is integrated here by Simpson's rule. Stressed on the
/// prop, the beam lifts off it and rises δ_p − W f_w; a finishing load W more brings it back
/// onto the prop, which then carries (2 W f_w − δ_p)/f_P. Tolerance 1.5 %: both figures
/// are the difference of the tendon's effect and the weight's, δ_p ≈ 3 × the rise, so the
/// 0.5 % allowed on δ_p (beam theory against the continuum, as above, and the tendon's
/// equivalent forces through the shape functions) is tripled; measured −0.78 % (rise
/// 13.82 mm against 13.93 mm) and +0.85 % (R 63.13 kN against 62.60 kN).
#[test]
fn a_tendon_cambers_the_beam_off_its_prop() {
    let e = 0.15;
    let p = 1.5 * W * L * L / (8.0 * e);
    let area = 2e-3;
    // δ_p by Simpson's rule over the span (2000 intervals: the integrand is smooth).
    let i = T * H.powi(3) / 12.0;
    let ga = 5.0 / 6.0 * E / (2.0 * (1.0 + NU)) * T * H;
    let influence = |x: f64| {
        let a = x.min(L - x);
        a * (3.0 * L * L - 4.0 * a * a) / (48.0 * E * i) + a / (2.0 * ga)
    };
    let q = |x: f64| {
        let slope = 4.0 * e * (L - 2.0 * x) / (L * L);
        p * (8.0 * e / (L * L)) / (1.0 + slope * slope).powf(1.5)
    };
    let n = 2000;
    let dx = L / n as f64;
    let delta_p = (0..=n)
        .map(|k| {
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let x = k as f64 * dx;
            w * q(x) * influence(x)
        })
        .sum::<f64>()
        * dx
        / 3.0;
    let text = beam("one_way = \"+y\"");
    let at = text.find("[[steps]]").unwrap();
    let model = format!(
        r#"{}
[[tendons]]
name = "P"
kind = "bonded"
parabola = {{ start = [0.0, {c}], end = [{L}, {c}], sag = {sag} }}
area = {area}
Ep = 195e9
fptk = 1860e6
jacking_force = {p}
jacking = "both"
friction = 0.0
wobble = 0.0
anchorage_set = 0.0
stressed_in_step = "stress"

[[steps]]
name = "self weight"
kind = "load"
increments = 1
loads = {{ g = 1.0 }}

[[steps]]
name = "stress"
kind = "load"
increments = 4
loads = {{ g = 1.0 }}

[[steps]]
name = "finishes"
kind = "load"
increments = 4
loads = {{ g = 2.0 }}
"#,
        &text[..at],
        c = H / 2.0,
        sag = -e,
    );
    let tmp = TempDir::new("oneway-tendon");
    run(&tmp, "tendon", &model, &RunOptions::default());
    let (fw, fp) = flexibilities();
    let (h, rows) = history(&tmp.join("tendon"));
    let (cs, cr, cu) = (col(&h, "step"), col(&h, "R_prop"), col(&h, "uy_mid"));
    let end = |step: f64| rows.iter().rfind(|r| r[cs] == step).unwrap().clone();
    let stressed = end(2.0);
    let rise = delta_p - W * fw;
    assert!(
        stressed[cr].abs() <= 1e-6 * W * L,
        "stressed: R_prop = {} N",
        stressed[cr]
    );
    assert!(
        (stressed[cu] - rise).abs() <= 0.015 * rise,
        "stressed: uy = {} m, simply supported span {rise} m",
        stressed[cu]
    );
    let finished = end(3.0);
    let r = (2.0 * W * fw - delta_p) / fp;
    assert!(
        (finished[cr] - r).abs() <= 0.015 * r,
        "finished: R_prop = {} N, continuous beam {r} N",
        finished[cr]
    );
    assert!(
        finished[cu].abs() <= 1e-9,
        "back on its seat: {}",
        finished[cu]
    );
}
