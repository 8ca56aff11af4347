//! Design checks (`[[checks]]`, src/results/design.rs, docs/theory-design.md) against hand
//! results on sections where the demand follows from statics or a closed form.

mod common;

use common::{code, segfem, stderr, stdout, TempDir};

/// Section of the prisms: depth H, thickness B [m].
const H: f64 = 0.6;
const B: f64 = 0.3;

/// A 2 m × H prism of two 1 m segments with a dry joint at x = 1 m, held at x = 0 (ux on the
/// edge, uy at one corner). Load cases: `ecc` an end force P = 1 MN at eccentricity `e`
/// above mid-depth, as two horizontal point loads at the corners of the end x = 2 m
/// (P/2 + P e/H at the top, P/2 − P e/H at the bottom: N = P, M = P e); `press` a uniform
/// end pressure of `p` [Pa] (line load p·B per metre). Extra TOML appended.
fn prism(e: f64, p: f64, extra: &str) -> String {
    let pf = 1e6;
    let top = pf / 2.0 + pf * e / H;
    let bottom = pf / 2.0 - pf * e / H;
    format!(
        r#"
[[materials]]
name = "c"
kind = "elastic"
E = 35e9
nu = 0.2
fcm = 38e6

[[regions]]
name = "r"
material = "c"
thickness = {B}

[[joint_materials]]
name = "dry"
kind = "dry"
friction = 0.7

[mesh]
type = "segmental"
n_segments = 2
nx_per_segment = 4
length = 2.0
element = "Q8"
joint_material = "dry"
bands = [{{ region = "r", depth = {H}, rows = 6 }}]

[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, {H}]]
ux = 0.0

[[supports]]
name = "pin"
point = [0.0, 0.0]
uy = 0.0

[[load_cases]]
name = "ecc"
point_loads = [
  {{ point = [2.0, {H}], force = [{ft}, 0.0] }},
  {{ point = [2.0, 0.0], force = [{fb}, 0.0] }},
]

[[load_cases]]
name = "press"
line_loads = [{{ line = [[2.0, 0.0], [2.0, {H}]], q = [{q}, 0.0] }}]

{extra}
"#,
        ft = -top,
        fb = -bottom,
        q = -p * B,
    )
}

/// Runs the model; returns (exit code, output, summary.json).
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

fn check<'a>(s: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    s["design_checks"]
        .as_array()
        .unwrap_or_else(|| panic!("no design_checks: {s}"))
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("no check {name}: {s}"))
}

fn utilisation(c: &serde_json::Value) -> f64 {
    c["utilisation"].as_f64().unwrap_or_else(|| panic!("{c}"))
}

/// Decompression of the dry joint under N = P at eccentricity e: the uncracked section's
/// fibre stress N/A − M c/I, utilisation M/M_dec = 6e/H for no required compression
/// (closed form for a rectangle). e = H/12 keeps the joint closed (u = 0.5); e = H/4 is
/// outside the kern (H/6), the dry joint opens, and the resultants still give u = 1.5 by
/// statics. AASHTO Type B service: 0.100 ksi of compression required, u = (6Pe/(BH²)) /
/// (P/(BH) − 0.6895 MPa). Tolerance 1e-3: the joint's resultants hold the applied force to
/// the Newton residual (1e-4 of the force scale) and the e = H/4 run passes through an
/// opening joint.
#[test]
fn joint_decompression_by_statics() {
    let steps = r#"
[[steps]]
name = "small"
kind = "load"
loads = { ecc = 1.0 }
increments = 2

[[checks]]
name = "dec_small"
check = "joint_decompression"
step = "small"
combination = "frequent"

[[checks]]
name = "typeb_small"
check = "joint_decompression"
step = "small"
code = "aashto"
combination = "service_iii"
"#;
    let (rc, out, s) = run("dec_small", &prism(H / 12.0, 0.0, steps));
    assert_eq!(rc, 0, "{out}");
    let c = check(&s, "dec_small");
    assert!((utilisation(c) - 0.5).abs() < 1e-3, "{c}");
    assert_eq!(c["verdict"], "pass");
    assert!(c["clause"].as_str().unwrap().contains("EN 1992-2"));
    // The least fibre stress N/A − 6 N e/(B H²) = P/(BH) (1 − 0.5) [MPa].
    let fibre = 1e6 / (B * H) * 0.5 / 1e6;
    let least = c["items"][0]["demand"].as_f64().unwrap();
    assert!(
        (least - fibre).abs() < 1e-3 * fibre,
        "{least} against {fibre}"
    );
    let p_req = 0.100 * 6.894757;
    let mean = 1e6 / (B * H) / 1e6;
    let hand = (mean * 0.5) / (mean - p_req);
    let c = check(&s, "typeb_small");
    assert!(
        (utilisation(c) - hand).abs() < 1e-3 * hand,
        "{c} against {hand}"
    );

    let steps = r#"
[[steps]]
name = "large"
kind = "load"
loads = { ecc = 1.0 }
increments = 4

[[checks]]
name = "dec_large"
check = "joint_decompression"
step = "large"
combination = "frequent"
"#;
    let (rc, out, s) = run("dec_large", &prism(H / 4.0, 0.0, steps));
    assert_eq!(rc, 0, "{out}");
    let c = check(&s, "dec_large");
    assert!((utilisation(c) - 1.5).abs() < 1e-3, "{c}");
    assert_eq!(c["verdict"], "fail");
    assert!(out.contains("check 'dec_large'"), "{out}");
}

/// Concrete stress under a uniform end pressure p: σ2 = −p at every Gauss point (a uniform
/// field that the elements reproduce exactly). f_ck = f_cm − 8 MPa = 30 MPa (EN 1992-1-1
/// Table 3.1); characteristic limit 0.6 f_ck = 18 MPa, quasi-permanent 0.45 f_ck = 13.5 MPa.
/// p = 15 MPa: u = 0.8333 (pass) and 1.1111 (fail). Tolerance 1e-6: round-off of a uniform
/// field.
#[test]
fn concrete_stress_limits_of_en_1992_1_1() {
    let steps = r#"
[[steps]]
name = "sls"
kind = "load"
loads = { press = 1.0 }

[[checks]]
name = "char"
check = "concrete_stress"
step = "sls"
combination = "characteristic"

[[checks]]
name = "qp"
check = "concrete_stress"
step = "sls"
combination = "quasi_permanent"
"#;
    let (rc, out, s) = run("stress", &prism(0.0, 15e6, steps));
    assert_eq!(rc, 0, "{out}");
    let c = check(&s, "char");
    assert!((utilisation(c) - 15.0 / 18.0).abs() < 1e-6, "{c}");
    assert_eq!(c["verdict"], "pass");
    let c = check(&s, "qp");
    assert!((utilisation(c) - 15.0 / 13.5).abs() < 1e-6, "{c}");
    assert_eq!(c["verdict"], "fail");
}

/// The disturbed regions: the prism under the end force at e = H/12 from two corner point
/// loads. Within one depth of the loads the stresses follow the point forces (singular at
/// the corners); beyond, beam theory: σ(y) = N/A + M (y − H/2)/I, largest at the top Gauss
/// point of the top element row (y = H − 0.05 (1 − √0.6), 3 × 3 Gauss on 0.1 m rows).
/// Left out by default, the check reads the beam-theory value within 3 % (the Saint-Venant
/// decay of the end disturbance one depth away, and the dry joint's penalty); included,
/// the corner stresses govern, far above it.
#[test]
fn concrete_stress_leaves_out_the_disturbed_regions() {
    let steps = r#"
[[steps]]
name = "load"
kind = "load"
loads = { ecc = 1.0 }

[[checks]]
name = "b"
check = "concrete_stress"
step = "load"
combination = "characteristic"

[[checks]]
name = "all"
check = "concrete_stress"
step = "load"
combination = "characteristic"
include_d_regions = true
"#;
    let (rc, out, s) = run("dregions", &prism(H / 12.0, 0.0, steps));
    assert_eq!(rc, 0, "{out}");
    let (n, e) = (1e6, H / 12.0);
    let y = H - 0.05 * (1.0 - 0.6f64.sqrt());
    let beam = n / (B * H) + n * e * (y - H / 2.0) / (B * H.powi(3) / 12.0);
    let b = check(&s, "b");
    let demand = |c: &serde_json::Value| c["items"][0]["demand"].as_f64().unwrap() * 1e6;
    assert!((demand(b) / beam - 1.0).abs() < 0.03, "{b} against {beam}");
    assert!(b["quantity"]
        .as_str()
        .unwrap()
        .contains("disturbed regions"));
    let all = check(&s, "all");
    assert!(demand(all) > 1.5 * beam, "{all} against {beam}");
}

/// A straight concentric external tendon anchored at the prism's ends over plates as deep
/// as the section (a uniform end pressure) and stressed to σ0: the prism shortens by
/// P L_e/(E_c A_c), so σ_p = σ0 / (1 + E_p A_p L_e / (E_c A_c L)) (closed form, the elastic
/// shortening the tendon loses in its own stressing step). L_e = L + 2 · 0.25/100: the
/// closed dry joint's penalty spring in series (penetration 1/penalty_factor = 1/100 of the
/// shortening of the two 0.25 m element layers beside it, docs/input.md). The EN 1992-1-1
/// 7.2(5) limit is 0.75 f_pk. Tolerance 1e-6: a linear problem solved to round-off.
#[test]
fn tendon_stress_after_elastic_shortening() {
    let (ap, ep, s0, fpk) = (2000e-6, 195e9, 1300e6, 1860e6);
    let extra = format!(
        r#"
[[tendons]]
name = "T"
kind = "external"
points = [[0.0, {y}], [2.0, {y}]]
area = {ap}
Ep = {ep}
fptk = {fpk}
initial_stress = {s0}
anchor_plate = {H}

[[steps]]
name = "stress"
kind = "load"
loads = {{ }}

[[checks]]
name = "tendon"
check = "tendon_stress"
step = "stress"
combination = "characteristic"
"#,
        y = H / 2.0
    );
    let (rc, out, s) = run("tendon", &prism(0.0, 0.0, &extra));
    assert_eq!(rc, 0, "{out}");
    let (l, le) = (2.0, 2.0 + 2.0 * 0.25 / 100.0);
    let sigma = s0 / (1.0 + ep * ap * le / (35e9 * B * H * l));
    let c = check(&s, "tendon");
    let hand = sigma / (0.75 * fpk);
    assert!(
        (utilisation(c) - hand).abs() < 1e-6 * hand,
        "{c} against {hand}"
    );
}

/// The seed beam (elastic, fcm 45 MPa) to failure, with the unbonded-tendon checks at the
/// failure step's peak: EN 1992-1-1 5.10.8(2) f_pe + 100 MPa, and AASHTO LRFD 5.6.3.1.2
/// worked here by hand at midspan: d_p = 0.6 − 0.1 = 0.5 m below the top, ℓ_i the
/// tendon's length (2 · √(2.4² + 0.2²) + 2.4 m), N_s = 0, f'c = f_ck = 37 MPa (α1 = 0.85,
/// β1 = 0.85 − 0.05 (37/6.894757 − 4) = 0.7817), top flange 1.2 m wide: with the block in
/// the flange, c = A_p (f_pe + k d_p) / (α1 f'c β1 b + A_p k), k = 900 ksi/ℓ_e. f_pe is the
/// analysis's tendon stress at the end of the prestress step (history.csv). Tolerance 1e-6
/// on the code value (the bisection); the analysis stress at the peak is the tendon's yield
/// 0.9 f_ptk (the example's failure), above both code estimates.
#[test]
fn unbonded_tendon_stress_at_ultimate_beside_the_codes() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/seed-beam-elastic.toml"
    ))
    .unwrap();
    let extra = r#"
[[checks]]
name = "aashto"
check = "unbonded_tendon_ultimate"
step = "failure"
code = "aashto"
tendon = "T1"
x = 3.6
fpe_step = "prestress"

[[checks]]
name = "en"
check = "unbonded_tendon_ultimate"
step = "failure"
tendon = "T1"
x = 3.6
fpe_step = "prestress"
"#;
    let (rc, out, s, tmp) = run_in("unbonded", &format!("{text}\n{extra}"));
    assert_eq!(rc, 0, "{out}");
    // f_pe: the tendon stress at the end of step 'prestress' (history.csv).
    let hist = std::fs::read_to_string(tmp.join("out/history.csv")).unwrap();
    let mut lines = hist.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| h.starts_with(n)).unwrap();
    let (c_step, c_ts) = (col("step"), col("tendon_stress"));
    let fpe = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .rfind(|r| r[c_step] == "1")
        .map(|r| r[c_ts].parse::<f64>().unwrap())
        .expect("rows of step 1");
    let en = check(&s, "en");
    let en_code = en["items"][0]["limit"].as_f64().unwrap() * 1e6;
    assert!(
        (en_code - (fpe + 100e6)).abs() < 1e-6 * en_code,
        "{en}, fpe {fpe}"
    );
    assert_eq!(en["verdict"], "info");

    let ksi = 6.894757e6;
    let li = 2.0 * (2.4f64.powi(2) + 0.2f64.powi(2)).sqrt() + 2.4;
    let k = 900.0 * ksi / li;
    let fc = 37e6;
    let beta1 = 0.85 - 0.05 * (fc / ksi - 4.0);
    let (ap, dp, b) = (560e-6, 0.5, 1.2);
    let c = ap * (fpe + k * dp) / (0.85 * fc * beta1 * b + ap * k);
    assert!(
        beta1 * c < 0.1,
        "block within the top flange: a = {}",
        beta1 * c
    );
    let fps = (fpe + k * (dp - c)).min(0.9 * 1900e6);
    let aashto = check(&s, "aashto");
    let code_value = aashto["items"][0]["limit"].as_f64().unwrap() * 1e6;
    assert!(
        (code_value - fps).abs() < 1e-6 * fps,
        "{aashto} against {fps}"
    );
    let analysis = aashto["items"][0]["demand"].as_f64().unwrap() * 1e6;
    assert!((analysis - 0.9 * 1900e6).abs() < 1e-3 * 1710e6, "{aashto}");
    assert!(analysis > fps && analysis > en_code, "{aashto}");
}

/// The report lists the checks with their verdict; a failed check's row is marked.
#[test]
fn report_lists_the_checks() {
    let steps = r#"
[[steps]]
name = "large"
kind = "load"
loads = { ecc = 1.0 }
increments = 4

[[checks]]
name = "dec_large"
check = "joint_decompression"
step = "large"
combination = "frequent"
"#;
    let (rc, out, _, tmp) = run_in("design_report", &prism(H / 4.0, 0.0, steps));
    assert_eq!(rc, 0, "{out}");
    let o = segfem(tmp.path(), &["report", "out", "-o", "r.html"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let html = std::fs::read_to_string(tmp.join("r.html")).unwrap();
    let table = &html[html.find("<table id=\"design\">").expect("design table")..];
    // The check's row: its header row, then the one row of the single check.
    let row = &table[..table.find("</table>").expect("end of the table")];
    assert!(
        row.contains("<tr class=\"bad\"><td>dec_large</td>"),
        "{row}"
    );
    assert!(row.contains("EN 1992-2 7.3.1"), "{row}");
    assert!(row.contains("<td>1.500</td><td>fail</td>"), "{row}");
}

/// Misplaced, missing and unknown keys are refused with the key named.
#[test]
fn bad_checks_are_refused() {
    let cases = [
        (
            "name = \"a\"\ncheck = \"tendon_sress\"\nstep = \"s\"\n",
            "checks[0].check: unknown check 'tendon_sress'",
        ),
        (
            "name = \"a\"\ncheck = \"concrete_stress\"\nstep = \"s\"\ncombination = \"characteristic\"\nkey_area = 0.1\n",
            "checks[0].key_area: not a key of check 'concrete_stress'",
        ),
        (
            "name = \"a\"\ncheck = \"concrete_stress\"\nstep = \"s\"\n",
            "checks[0].combination: missing",
        ),
        (
            "name = \"a\"\ncheck = \"joint_decompression\"\nstep = \"nope\"\ncombination = \"frequent\"\n",
            "checks[0].step: no step named 'nope'",
        ),
        (
            "name = \"a\"\ncheck = \"shear_keys\"\nstep = \"s\"\nkey_area = 0.01\n",
            "checks[0].code: shear_keys follows the AASHTO",
        ),
    ];
    for (i, (table, want)) in cases.iter().enumerate() {
        let text = prism(
            0.0,
            1e6,
            &format!("[[steps]]\nname = \"s\"\nkind = \"load\"\nloads = {{ press = 1.0 }}\n\n[[checks]]\n{table}"),
        );
        let tmp = TempDir::new(&format!("bad_check_{i}"));
        std::fs::write(tmp.join("m.toml"), text).unwrap();
        let o = segfem(tmp.path(), &["check", "m.toml"]);
        assert_ne!(code(&o), 0);
        assert!(stderr(&o).contains(want), "{}\nwanted: {want}", stderr(&o));
    }
}
