//! Bad model files: each case changes one thing in a valid minimal model and checks that
//! both `segfem check` and `segfem run` refuse it with exit status 2 and one clear line
//! `error: <file>[:line]: <key>: <what is wrong>`, without a panic and without leaving output.

mod common;

use common::{code, segfem, stderr, stdout, TempDir};

/// A valid minimal explicit model: two Q4 elements side by side, 2 m × 1 m.
///
/// ```text
///  4 ---- 5 ---- 6      y = 1
///  |      |      |
///  1 ---- 2 ---- 3      y = 0
/// x = 0   1      2
/// ```
const EXPLICIT: &str = r#"title = "two Q4"

[[materials]]
name = "concrete"
kind = "elastic"
E = 30e9
nu = 0.2
density = 2500.0

[[regions]]
name = "web"
material = "concrete"
thickness = 0.2

[mesh]
type = "explicit"
nodes = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0], [1.0, 1.0], [2.0, 1.0]]

[[mesh.blocks]]
region = "web"
element = "Q4"
elements = [[1, 2, 5, 4], [2, 3, 6, 5]]

[[supports]]
name = "left"
node = 1
ux = 0.0
uy = 0.0

[[supports]]
name = "right"
node = 3
uy = 0.0

[[load_cases]]
name = "P"
gravity = [0.0, -9.81]
point_loads = [{ node = 6, force = [0.0, -1.0e3] }]

[[monitors]]
name = "R_left"
kind = "reaction"
support = "left"
component = "y"

[[steps]]
name = "load"
kind = "linear"
loads = { P = 1.0 }
"#;

/// A valid minimal banded model: a 4 m × 0.4 m Q8 beam on a pin and a roller.
const BANDED: &str = r#"[[materials]]
name = "concrete"
kind = "elastic"
E = 30e9
nu = 0.2

[[regions]]
name = "web"
material = "concrete"
thickness = 0.3

[mesh]
type = "banded"
length = 4.0
nx = 8
element = "Q8"
bands = [{ region = "web", depth = 0.4, rows = 2 }]

[[supports]]
name = "pin"
point = [0.0, 0.0]
ux = 0.0
uy = 0.0

[[supports]]
name = "roller"
point = [4.0, 0.0]
uy = 0.0

[[load_cases]]
name = "P"
point_loads = [{ point = [2.0, 0.4], force = [0.0, -1.0e4] }]

[[steps]]
name = "load"
kind = "load"
loads = { P = 1.0 }
increments = 2
"#;

/// `base` with `from` (which must occur exactly once, so that a test never silently stops
/// changing anything) replaced by `to`.
fn edit(base: &str, from: &str, to: &str) -> String {
    assert_eq!(base.matches(from).count(), 1, "{from:?} must occur once");
    base.replace(from, to)
}

/// 1-based line of the first occurrence of `needle` in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    text[..text.find(needle).expect("needle present")]
        .matches('\n')
        .count()
        + 1
}

/// Writes `model` as `bad.toml`, runs `check` and `run` on it and asserts the common
/// contract; returns the error line (identical for both) for case-specific checks.
/// `key` must appear as `: key:` (the key part of the message) and each of `what` in the
/// line.
fn rejects(model: &str, key: &str, what: &[&str]) -> String {
    let tmp = TempDir::new("bad");
    let file = "bad.toml";
    std::fs::write(tmp.join(file), model).unwrap();
    let mut lines = Vec::new();
    for args in [vec!["check", file], vec!["run", file, "-o", "out"]] {
        let o = segfem(tmp.path(), &args);
        let err = stderr(&o);
        let cmd = args[0];
        assert!(!err.contains("panicked"), "{cmd}: panic:\n{err}");
        assert_eq!(code(&o), 2, "{cmd}: exit status; stderr:\n{err}");
        assert_eq!(stdout(&o), "", "{cmd}: nothing on stdout");
        assert_eq!(err.lines().count(), 1, "{cmd}: one line:\n{err}");
        let line = err.trim_end().to_string();
        assert!(
            line.starts_with(&format!("error: {file}")),
            "{cmd}: names the file: {line}"
        );
        assert!(
            line.contains(&format!(": {key}: ")),
            "{cmd}: names the key {key:?}: {line}"
        );
        for w in what {
            assert!(line.contains(w), "{cmd}: says {w:?}: {line}");
        }
        // Nothing written: no output directory, no default output directory, no temporaries.
        assert_eq!(tmp.entries(), vec![file.to_string()], "{cmd}: files left");
        lines.push(line);
    }
    assert_eq!(lines[0], lines[1], "check and run report the same error");
    lines.pop().unwrap()
}

// ---------------------------------------------------------------------------------------
// The base models are valid: every case below fails because of its one change.
// ---------------------------------------------------------------------------------------

#[test]
fn base_models_are_valid() {
    for (name, model) in [("explicit", EXPLICIT), ("banded", BANDED)] {
        let tmp = TempDir::new("good");
        std::fs::write(tmp.join("m.toml"), model).unwrap();
        let o = segfem(tmp.path(), &["check", "m.toml"]);
        assert_eq!(code(&o), 0, "{name}: {}", stderr(&o));
        assert_eq!(stderr(&o), "", "{name}: no warnings");
        let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
        assert_eq!(code(&o), 0, "{name}: {}", stderr(&o));
        assert!(tmp.join("out/summary.json").is_file());
    }
}

// ---------------------------------------------------------------------------------------
// File and TOML level.
// ---------------------------------------------------------------------------------------

#[test]
fn nonexistent_file() {
    let tmp = TempDir::new("missing");
    for args in [
        vec!["check", "no/such/model.toml"],
        vec!["run", "no/such/model.toml", "-o", "out"],
    ] {
        let o = segfem(tmp.path(), &args);
        let err = stderr(&o);
        assert_eq!(code(&o), 2, "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with("error: no/such/model.toml: "),
            "path in the message: {err}"
        );
        assert!(err.contains("cannot read"), "{err}");
        assert!(tmp.entries().is_empty(), "nothing written");
    }
}

#[test]
fn malformed_toml_gives_the_line() {
    // A unit after a number is not TOML.
    let model = edit(EXPLICIT, "E = 30e9\n", "E = 30e9 Pa\n");
    let line = line_of(&model, "E = 30e9 Pa");
    let tmp = TempDir::new("malformed");
    std::fs::write(tmp.join("bad.toml"), &model).unwrap();
    for args in [
        vec!["check", "bad.toml"],
        vec!["run", "bad.toml", "-o", "out"],
    ] {
        let o = segfem(tmp.path(), &args);
        let err = stderr(&o);
        assert_eq!(code(&o), 2, "{err}");
        assert!(!err.contains("panicked"), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.starts_with(&format!("error: bad.toml:{line}: ")),
            "line {line} named: {err}"
        );
        assert_eq!(tmp.entries(), vec!["bad.toml".to_string()]);
    }
}

#[test]
fn unclosed_table_header_gives_the_line() {
    let model = edit(EXPLICIT, "[[regions]]", "[[regions]");
    let line = line_of(&model, "[[regions]");
    let err = rejects_any_key(&model);
    assert!(
        err.starts_with(&format!("error: bad.toml:{line}: ")),
        "{err}"
    );
}

/// Like [`rejects`] for errors where the parser names no key (pure syntax errors).
fn rejects_any_key(model: &str) -> String {
    let tmp = TempDir::new("syntax");
    std::fs::write(tmp.join("bad.toml"), model).unwrap();
    let o = segfem(tmp.path(), &["check", "bad.toml"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 2, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    err.trim_end().to_string()
}

#[test]
fn unknown_key_is_named_with_its_line() {
    let model = edit(EXPLICIT, "thickness = 0.2", "thicknes = 0.2");
    let line = rejects(&model, "thicknes", &["unknown field"]);
    let n = line_of(&model, "thicknes");
    assert!(
        line.starts_with(&format!("error: bad.toml:{n}: ")),
        "{line}"
    );
}

#[test]
fn unknown_top_level_table_is_named() {
    let model = format!("{EXPLICIT}\n[[cables]]\nname = \"t1\"\n");
    rejects(&model, "cables", &["unknown field"]);
}

// ---------------------------------------------------------------------------------------
// Materials and regions.
// ---------------------------------------------------------------------------------------

#[test]
fn missing_material_name_in_region() {
    let model = edit(EXPLICIT, "material = \"concrete\"\n", "");
    let line = rejects_any_key(&model);
    assert!(line.contains("material"), "names the missing key: {line}");
    assert!(line.contains("missing"), "{line}");
}

#[test]
fn misspelled_material_name() {
    let model = edit(
        EXPLICIT,
        "material = \"concrete\"",
        "material = \"concret\"",
    );
    rejects(
        &model,
        "regions[0].material",
        &["no material named 'concret'", "concrete"],
    );
}

#[test]
fn zero_thickness() {
    let model = edit(EXPLICIT, "thickness = 0.2", "thickness = 0.0");
    rejects(&model, "regions[0].thickness", &["positive", "0"]);
}

#[test]
fn negative_thickness_banded() {
    let model = edit(BANDED, "thickness = 0.3", "thickness = -0.3");
    rejects(&model, "regions[0].thickness", &["positive", "-0.3"]);
}

#[test]
fn zero_modulus() {
    let model = edit(EXPLICIT, "E = 30e9", "E = 0.0");
    rejects(&model, "materials[0].E", &["positive"]);
}

#[test]
fn negative_modulus() {
    let model = edit(BANDED, "E = 30e9", "E = -30e9");
    rejects(&model, "materials[0].E", &["positive", "-30000000000"]);
}

#[test]
fn poisson_ratio_one_half() {
    let model = edit(EXPLICIT, "nu = 0.2", "nu = 0.5");
    rejects(&model, "materials[0].nu", &["(-1, 0.5)", "0.5"]);
}

#[test]
fn poisson_ratio_minus_one() {
    let model = edit(EXPLICIT, "nu = 0.2", "nu = -1.0");
    rejects(&model, "materials[0].nu", &["(-1, 0.5)", "-1"]);
}

// ---------------------------------------------------------------------------------------
// Mesh.
// ---------------------------------------------------------------------------------------

#[test]
fn element_with_unknown_node() {
    let model = edit(EXPLICIT, "[2, 3, 6, 5]", "[2, 3, 7, 5]");
    rejects(
        &model,
        "mesh.blocks[0].elements[1]",
        &["unknown node 7", "1..=6"],
    );
}

#[test]
fn element_with_node_zero() {
    // Node numbers are 1-based: 0 is not a node.
    let model = edit(EXPLICIT, "[1, 2, 5, 4]", "[0, 1, 4, 3]");
    rejects(&model, "mesh.blocks[0].elements[0]", &["unknown node 0"]);
}

#[test]
fn element_with_repeated_node() {
    let model = edit(EXPLICIT, "[2, 3, 6, 5]", "[2, 3, 6, 6]");
    rejects(
        &model,
        "mesh.blocks[0].elements[1]",
        &["node 6 is repeated"],
    );
}

#[test]
fn inverted_element() {
    // Clockwise node order.
    let model = edit(EXPLICIT, "[2, 3, 6, 5]", "[2, 5, 6, 3]");
    rejects(
        &model,
        "mesh.blocks[0].elements[1]",
        &["inverted or degenerate", "counter-clockwise"],
    );
}

#[test]
fn degenerate_element_all_nodes_collinear() {
    // A fourth node on the line y = 0; the second element lies flat on that line.
    let model = edit(EXPLICIT, "[2.0, 1.0]]", "[2.0, 1.0], [3.0, 0.0]]");
    let model = edit(&model, "[2, 3, 6, 5]", "[1, 2, 3, 7]");
    rejects(
        &model,
        "mesh.blocks[0].elements[1]",
        &["zero area", "nodes 1, 2, 3, 7", "collinear"],
    );
}

#[test]
fn degenerate_element_three_corners_collinear() {
    // Corners 2, 3 and 6' in line: a 180° corner angle, det J = 0 at that corner.
    let model = edit(EXPLICIT, "[2.0, 1.0]]", "[2.0, 2.0]]");
    let model = edit(&model, "[2, 3, 6, 5]", "[2, 3, 6, 1]");
    // Element 2 is now (1,0) (2,0) (2,2) (0,0): corner (0,0)→(1,0)→(2,0) is straight.
    rejects(
        &model,
        "mesh.blocks[0].elements[1]",
        &["inverted or degenerate"],
    );
}

#[test]
fn unknown_element_type_explicit() {
    let model = edit(EXPLICIT, "element = \"Q4\"", "element = \"T3\"");
    rejects(
        &model,
        "mesh.blocks[0].element",
        &["unknown element type 'T3'", "Q4, Q8, Q9 or T6"],
    );
}

#[test]
fn unknown_element_type_banded() {
    let model = edit(BANDED, "element = \"Q8\"", "element = \"Q6\"");
    rejects(&model, "mesh.element", &["unknown element type 'Q6'"]);
}

#[test]
fn wrong_node_count_for_element_type() {
    let model = edit(EXPLICIT, "element = \"Q4\"", "element = \"Q8\"");
    rejects(
        &model,
        "mesh.blocks[0].elements[0]",
        &["needs 8 nodes, got 4"],
    );
}

// ---------------------------------------------------------------------------------------
// Supports.
// ---------------------------------------------------------------------------------------

#[test]
fn no_supports() {
    let supports = "[[supports]]\nname = \"left\"\nnode = 1\nux = 0.0\nuy = 0.0\n\n[[supports]]\nname = \"right\"\nnode = 3\nuy = 0.0\n\n";
    let model = edit(EXPLICIT, supports, "");
    // Without supports the monitor on "left" would be wrong too; supports are checked first.
    rejects(&model, "supports", &["no supports", "mechanism"]);
}

#[test]
fn supports_leaving_a_rigid_body_motion() {
    // Only uy along the bottom line: the beam can still slide in x.
    let supports = "[[supports]]\nname = \"left\"\nnode = 1\nux = 0.0\nuy = 0.0\n\n[[supports]]\nname = \"right\"\nnode = 3\nuy = 0.0\n";
    let model = edit(
        EXPLICIT,
        supports,
        "[[supports]]\nname = \"left\"\nline = [[0.0, 0.0], [2.0, 0.0]]\nuy = 0.0\n",
    );
    rejects(&model, "supports", &["rigid body", "2 of its 3"]);
}

#[test]
fn supports_leaving_rotation_free() {
    // A single pinned node: both translations held, rotation about it free.
    let model = edit(
        BANDED,
        "[[supports]]\nname = \"roller\"\npoint = [4.0, 0.0]\nuy = 0.0\n",
        "",
    );
    rejects(&model, "supports", &["rigid body", "2 of its 3"]);
}

#[test]
fn support_restraining_nothing() {
    let model = edit(EXPLICIT, "node = 3\nuy = 0.0\n", "node = 3\n");
    rejects(&model, "supports[1]", &["restrains nothing"]);
}

#[test]
fn support_point_outside_the_mesh() {
    let model = edit(BANDED, "point = [4.0, 0.0]", "point = [4.5, 0.0]");
    rejects(&model, "supports[1].point", &["outside the mesh"]);
}

// ---------------------------------------------------------------------------------------
// Loads, steps, monitors.
// ---------------------------------------------------------------------------------------

#[test]
fn point_load_outside_the_mesh() {
    let model = edit(BANDED, "point = [2.0, 0.4]", "point = [2.0, 1.4]");
    rejects(
        &model,
        "load_cases[0].point_loads[0].point",
        &["outside the mesh"],
    );
}

#[test]
fn point_load_on_unknown_node() {
    let model = edit(EXPLICIT, "{ node = 6,", "{ node = 60,");
    rejects(&model, "load_cases[0].point_loads[0].node", &["node 60"]);
}

#[test]
fn step_with_unknown_load_case() {
    let model = edit(EXPLICIT, "loads = { P = 1.0 }", "loads = { Q = 1.0 }");
    rejects(&model, "steps[0].loads.Q", &["no load case named 'Q'", "P"]);
}

#[test]
fn unknown_step_kind() {
    let model = edit(EXPLICIT, "kind = \"linear\"", "kind = \"dynamic\"");
    rejects(
        &model,
        "steps[0].kind",
        &["unknown step kind 'dynamic'", "linear", "load"],
    );
}

#[test]
fn time_step_with_loads() {
    let model = edit(EXPLICIT, "kind = \"linear\"", "kind = \"time\"\nto = 100.0");
    rejects(
        &model,
        "steps[0].loads",
        &["holds the loads at their previous factors"],
    );
}

#[test]
fn time_step_ending_before_it_starts() {
    let model = edit(
        EXPLICIT,
        "kind = \"linear\"\nloads = { P = 1.0 }",
        "kind = \"time\"\nfrom = 28.0\nto = 20.0",
    );
    rejects(&model, "steps[0].to", &["must be later than from = 28 d"]);
}

#[test]
fn creep_key_on_elastic_material() {
    // fcm is an elastic material's strength to check against; the creep keys are not its.
    let model = edit(EXPLICIT, "nu = 0.2", "nu = 0.2\nrh = 0.7");
    rejects(&model, "materials[0].rh", &["not a key of kind 'elastic'"]);
}

#[test]
fn monitor_naming_unknown_support() {
    let model = edit(EXPLICIT, "support = \"left\"", "support = \"middle\"");
    rejects(
        &model,
        "monitors[0].support",
        &["no support named 'middle'", "left", "right"],
    );
}

#[test]
fn duplicate_support_name() {
    let model = edit(EXPLICIT, "name = \"right\"", "name = \"left\"");
    rejects(&model, "supports[1].name", &["'left' is already used"]);
}

#[test]
fn zero_increments() {
    let model = edit(BANDED, "increments = 2", "increments = 0");
    rejects(&model, "steps[0].increments", &["at least 1"]);
}

#[test]
fn unknown_output_value() {
    let model = edit(
        BANDED,
        "increments = 2",
        "increments = 2\noutput = \"every\"",
    );
    rejects(
        &model,
        "steps[0].output",
        &["unknown value 'every'", "end, increments or none"],
    );
}

// ---------------------------------------------------------------------------------------
// Known source bugs (see the report): these document the expected behaviour.
// ---------------------------------------------------------------------------------------

#[test]
fn wrong_value_type_names_the_key() {
    let model = edit(EXPLICIT, "thickness = 0.2", "thickness = \"0.2\"");
    let line = rejects_any_key(&model);
    // The key (in whatever path form) must come before the message, as for other errors.
    let (head, _) = line.split_once("invalid type").expect("a type error");
    assert!(head.contains("thickness"), "{line}");
}

#[test]
fn non_finite_gravity() {
    let model = edit(EXPLICIT, "gravity = [0.0, -9.81]", "gravity = [nan, -9.81]");
    rejects(&model, "load_cases[0].gravity", &["finite"]);
}

#[test]
fn non_finite_line_load() {
    let model = edit(
        BANDED,
        "name = \"P\"\n",
        "name = \"P\"\nline_loads = [{ line = [[0.0, 0.4], [4.0, 0.4]], q = [0.0, inf] }]\n",
    );
    rejects(&model, "load_cases[0].line_loads[0].q", &["finite"]);
}

#[test]
fn non_finite_prescribed_displacement() {
    let model = edit(BANDED, "ux = 0.0", "ux = nan");
    rejects(&model, "supports[0].ux", &["finite"]);
}

#[test]
fn non_finite_origin_is_named() {
    let model = edit(BANDED, "nx = 8", "nx = 8\norigin = [nan, 0.0]");
    rejects(&model, "mesh.origin", &["finite"]);
}

// ---------------------------------------------------------------------------------------
// Bonded post-tensioned tendons.
// ---------------------------------------------------------------------------------------

/// BANDED with a bonded tendon (`extra` lines added to its table) and a second step.
fn bonded(extra: &str) -> String {
    let m = edit(
        BANDED,
        "[[supports]]\nname = \"pin\"",
        &format!(
            "[[tendons]]\nname = \"T\"\nkind = \"bonded\"\narea = 1e-3\nEp = 195e9\nfptk = 1860e6\n{extra}\n\n[[supports]]\nname = \"pin\""
        ),
    );
    format!("{m}\n[[steps]]\nname = \"later\"\nkind = \"load\"\nloads = {{ P = 1.0 }}\n")
}

const STRAIGHT: &str = "points = [[0.0, 0.1], [4.0, 0.1]]\njacking_stress = 1000e6";

#[test]
fn bonded_tendon_valid_base() {
    let tmp = TempDir::new("bonded");
    std::fs::write(
        tmp.join("ok.toml"),
        bonded(&format!("{STRAIGHT}\ngrouted_in_step = \"later\"")),
    )
    .unwrap();
    let o = segfem(tmp.path(), &["check", "ok.toml"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
}

#[test]
fn bonded_tendon_grouted_before_stressing() {
    rejects(
        &bonded(&format!("{STRAIGHT}\ngrouted_in_step = \"load\"")),
        "tendons[0].grouted_in_step",
        &["grouted after stressing"],
    );
}

#[test]
fn bonded_tendon_set_larger_than_elongation() {
    // Elastic elongation 1000 MPa / 195 GPa × 4 m = 20.5 mm < 40 mm.
    rejects(
        &bonded(&format!(
            "{STRAIGHT}\njacking = \"start\"\nanchorage_set = 0.04"
        )),
        "tendons[0].anchorage_set",
        &["elastic elongation"],
    );
}

#[test]
fn bonded_tendon_leaves_the_mesh() {
    rejects(
        &bonded("points = [[0.0, 0.1], [4.5, 0.1]]\njacking_stress = 1000e6"),
        "tendons[0]",
        &["tendon 'T'", "leaves the mesh"],
    );
}

#[test]
fn bonded_tendon_without_jacking() {
    rejects(
        &bonded("points = [[0.0, 0.1], [4.0, 0.1]]"),
        "tendons[0].jacking_stress",
        &["jacking_force"],
    );
}

#[test]
fn bonded_tendon_with_initial_stress() {
    rejects(
        &bonded(&format!("{STRAIGHT}\ninitial_stress = 900e6")),
        "tendons[0].initial_stress",
        &["pretensioned"],
    );
}

#[test]
fn pretensioned_tendon_without_initial_stress() {
    rejects(
        &bonded("points = [[0.0, 0.1], [4.0, 0.1]]").replace("\"bonded\"", "\"pretensioned\""),
        "tendons[0].initial_stress",
        &["missing", "before release"],
    );
}

#[test]
fn pretensioned_tendon_with_jacking() {
    rejects(
        &bonded(STRAIGHT).replace("\"bonded\"", "\"pretensioned\""),
        "tendons[0].jacking_stress",
        &["pre-tensioned"],
    );
}

#[test]
fn pretensioned_tendon_above_yield() {
    rejects(
        &bonded("points = [[0.0, 0.1], [4.0, 0.1]]\ninitial_stress = 1700e6")
            .replace("\"bonded\"", "\"pretensioned\""),
        "tendons[0].initial_stress",
        &["0.9 fptk"],
    );
}

#[test]
fn bonded_tendon_chain_with_a_gap() {
    rejects(
        &bonded("segments = [{ points = [[0.0, 0.1], [2.0, 0.1]] }, { points = [[2.5, 0.1], [4.0, 0.1]] }]\njacking_stress = 1000e6"),
        "tendons[0]",
        &["chain part 1"],
    );
}

#[test]
fn tendon_monitor_span_out_of_range() {
    let m = edit(
        BANDED,
        "[[supports]]\nname = \"pin\"",
        "[[tendons]]\nname = \"T\"\nkind = \"external\"\npoints = [[0.0, 0.2], [4.0, 0.2]]\narea = 1e-3\nEp = 195e9\nfptk = 1860e6\ninitial_stress = 1e9\n\n[[monitors]]\nname = \"F\"\nkind = \"tendon_force\"\ntendon = \"T\"\nspan = 2\n\n[[supports]]\nname = \"pin\"",
    );
    rejects(&m, "monitors[0].span", &["spans 1 to 1"]);
}

#[test]
fn external_tendon_with_a_parabola() {
    let m = edit(
        BANDED,
        "[[supports]]\nname = \"pin\"",
        "[[tendons]]\nname = \"T\"\nkind = \"external\"\nparabola = { start = [0.0, 0.2], end = [4.0, 0.2], sag = -0.1 }\narea = 1e-3\nEp = 195e9\nfptk = 1860e6\ninitial_stress = 1e9\n\n[[supports]]\nname = \"pin\"",
    );
    rejects(&m, "tendons[0].parabola", &["bonded"]);
}

/// `regions[i].boxes`: elements whose centroid lies in a box move to that region; an empty
/// or inverted box is refused with the key.
#[test]
fn region_boxes_move_elements_and_bad_boxes_are_refused() {
    let base = edit(
        EXPLICIT,
        "[mesh]",
        "[[regions]]\nname = \"block\"\nmaterial = \"concrete\"\nthickness = 0.5\nboxes = [[[1.2, 0.1], [1.8, 0.9]]]\n\n[mesh]",
    );
    let m = segfem::input::parse(&base, "m.toml").unwrap().model;
    let names: Vec<&str> = m
        .elements
        .iter()
        .map(|e| m.regions[e.region].name.as_str())
        .collect();
    // Centroids at x = 0.5 (outside) and 1.5 (inside the box).
    assert_eq!(names, ["web", "block"]);
    rejects(
        &edit(
            &base,
            "[[1.2, 0.1], [1.8, 0.9]]",
            "[[1.8, 0.1], [1.2, 0.9]]",
        ),
        "regions[1].boxes[0]",
        &["x1 > x0"],
    );
    rejects(
        &edit(
            &base,
            "[[1.2, 0.1], [1.8, 0.9]]",
            "[[3.0, 0.1], [4.0, 0.9]]",
        ),
        "regions[1].boxes[0]",
        &["no element centroid"],
    );
}

#[test]
fn incompatible_modes_are_for_q4_and_small_displacements() {
    rejects(
        &edit(
            BANDED,
            "element = \"Q8\"",
            "element = \"Q8\"\nintegration = \"incompatible\"",
        ),
        "mesh.integration",
        &["Q4 elements only", "Q8"],
    );
    let q4i = edit(
        BANDED,
        "element = \"Q8\"",
        "element = \"Q4\"\nintegration = \"incompatible\"",
    );
    rejects(
        &format!("{q4i}\n[analysis]\ngeometry = \"nonlinear\"\n"),
        "analysis.geometry",
        &["incompatible-mode Q4", "Q8 or Q9"],
    );
}

/// Input files are read up to a cap (512 MiB): /dev/zero as the model file or as a Gmsh
/// mesh file is refused once that much is read, naming the file, instead of reading on
/// until the memory runs out.
#[test]
fn endless_input_files_are_refused_at_the_cap() {
    let tmp = TempDir::new("endless");
    let o = segfem(tmp.path(), &["check", "/dev/zero"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert_eq!(
        stderr(&o).trim_end(),
        "error: /dev/zero: larger than the limit of 512 MiB for an input file (the largest model segfem runs takes about half of it); not a model or mesh file?"
    );
    let model = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/gmsh-tapered.toml"),
    )
    .unwrap()
    .replace("file = \"gmsh-tapered.msh\"", "file = \"/dev/zero\"");
    std::fs::write(tmp.join("m.toml"), model).unwrap();
    let o = segfem(tmp.path(), &["check", "m.toml"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(
        stderr(&o).starts_with(
            "error: m.toml: mesh.file: /dev/zero: larger than the limit of 512 MiB for an input file"
        ),
        "{}",
        stderr(&o)
    );
}
