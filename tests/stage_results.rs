//! Results per construction stage (docs/input.md, "Output files"): stages.csv, the stage
//! names in the field files, the stages in summary.json and the report's stage table with
//! the joints that open during construction.
//! Run with `cargo nextest run --release -E 'binary(stage_results)'`.

use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("segfem-stageres-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Axial compression N [N] on the end face.
const N: f64 = 400e3;
/// Tip load P [N].
const P: f64 = 60e3;
/// Depth h [m] of the section.
const H: f64 = 0.5;
/// Distance [m] from the joint (x = 1 m) to the tip (x = 2 m).
const ARM: f64 = 1.0;

/// Two 1 m dry-jointed segments, 0.5 m deep, clamped at x = 0 and compressed by N on the
/// end face; P pulls the tip down. Stage 1 holds the tip on a temporary prop (the load
/// goes straight into it); stage 2 strikes the prop, so the joint carries M = P·1 m;
/// stage 3 takes P away.
fn propped_model() -> String {
    format!(
        r#"
title = "propped segmental cantilever"

[[materials]]
name = "c"
kind = "elastic"
E = 30e9
nu = 0.2

[[regions]]
name = "r"
material = "c"
thickness = 0.2

[[joint_materials]]
name = "dry"
kind = "dry"
friction = 0.7
kn = 1e12
kt = 4e11
residual_stiffness_ratio = 0.0

[mesh]
type = "segmental"
segments = [1.0, 1.0]
nx_per_segment = 4
element = "Q8"
joint_material = "dry"
origin = [0.0, -0.25]
bands = [{{ region = "r", depth = {H}, rows = 4 }}]

[[supports]]
name = "wall"
line = [[0.0, -0.25], [0.0, 0.25]]
ux = 0.0
uy = 0.0

[[supports]]
name = "prop"
point = [2.0, -0.25]
uy = 0.0

[[load_cases]]
name = "N"
line_loads = [{{ line = [[2.0, -0.25], [2.0, 0.25]], q = [{q}, 0.0] }}]

[[load_cases]]
name = "P"
point_loads = [{{ point = [2.0, 0.0], force = [0.0, {p}] }}]

[[monitors]]
name = "opening"
kind = "joint_opening"
joint = "all"

[[steps]]
name = "erect on prop"
kind = "load"
increments = 2
loads = {{ N = 1.0, P = 1.0 }}
activate = ["prop"]

[[steps]]
name = "strike prop"
kind = "load"
increments = 4
loads = {{ N = 1.0, P = 1.0 }}
remove = ["prop"]

[[steps]]
name = "unload P"
kind = "load"
increments = 2
loads = {{ N = 1.0, P = 0.0 }}
"#,
        q = -N / H,
        p = -P
    )
}

fn run(name: &str, text: &str) -> PathBuf {
    let dir = tmp(name);
    let path = dir.join("model.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.join("out");
    segfem::run::run_file(&path, &out, &mut |_| {}).unwrap_or_else(|e| panic!("{e}"));
    out
}

/// Split a CSV line, honouring quoted fields.
fn split_csv(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                chars.next();
                fields.last_mut().unwrap().push('"');
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(String::new()),
            c => fields.last_mut().unwrap().push(c),
        }
    }
    fields
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    let mut lines = text.lines();
    let header = split_csv(lines.next().expect("header"));
    (header, lines.map(split_csv).collect())
}

/// The joint of the propped cantilever opens when the prop is struck and only then:
/// beam theory decompresses the joint's top fibre when M = P·1 m exceeds N·h/6
/// (60 > 33.3 kN m after striking; ~0 on the prop, 0 after unloading). stages.csv names
/// the joint and a positive opening in stage 2 (before the last: during construction),
/// its row ranges tile history.csv, the joint opening monitor of those rows agrees, the
/// field files carry the stage names and the report flags the opening in words.
#[test]
fn joint_opened_by_striking_a_prop_is_flagged_as_a_construction_opening() {
    // The test is only meaningful if beam theory puts the three stages on the right sides
    // of the decompression moment.
    const { assert!(P * ARM > N * H / 6.0 && 0.5 * P * ARM < N * H / 6.0) };
    let out = run("propped", &propped_model());
    let (header, rows) = read_csv(&out.join("stages.csv"));
    assert_eq!(
        header,
        [
            "step",
            "name",
            "activated",
            "removed",
            "first_row",
            "last_row",
            "max_joint_opening [m]",
            "joint",
            "support_events"
        ]
    );
    assert_eq!(rows.len(), 3, "one row per step: {rows:?}");
    let names: Vec<&str> = rows.iter().map(|r| r[1].as_str()).collect();
    assert_eq!(names, ["erect on prop", "strike prop", "unload P"]);
    assert_eq!(rows[0][2], "prop", "the prop is placed in stage 1");
    assert_eq!(rows[1][3], "prop", "and removed in stage 2");
    assert_eq!((rows[1][2].as_str(), rows[2][2].as_str()), ("", ""));

    // The row ranges cover history.csv exactly, in order, each as long as its step's
    // increments (2, 4, 2).
    let (_, hist) = read_csv(&out.join("history.csv"));
    let mut next = 1;
    for (r, incs) in rows.iter().zip([2, 4, 2]) {
        let a: usize = r[4].parse().unwrap();
        let b: usize = r[5].parse().unwrap();
        assert_eq!((a, b), (next, next + incs - 1), "{r:?}");
        for h in &hist[a - 1..b] {
            assert_eq!(h[0], r[0], "history row of step {}", r[0]);
        }
        next = b + 1;
    }
    assert_eq!(
        next - 1,
        hist.len(),
        "the ranges end at the last history row"
    );

    // The joint opens in stage 2 only; the opening is that of the joint_opening monitor
    // (same committed state, printed at full precision, hence equal).
    let opening: Vec<f64> = rows.iter().map(|r| r[6].parse().unwrap()).collect();
    assert!(opening[1] > 0.0, "the joint opens when the prop is struck");
    assert_eq!(rows[1][7], "J1");
    assert_eq!((opening[0], opening[2]), (0.0, 0.0), "{rows:?}");
    assert_eq!((rows[0][7].as_str(), rows[2][7].as_str()), ("", ""));
    let (hh, _) = read_csv(&out.join("history.csv"));
    let col = hh.iter().position(|h| h == "opening [m]").unwrap();
    let monitor_max = hist[2..6]
        .iter()
        .map(|h| h[col].parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    assert_eq!(opening[1], monitor_max);

    // summary.json lists the same stages.
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let stages = v["stages"].as_array().expect("stages in summary.json");
    assert_eq!(stages.len(), 3);
    assert_eq!(stages[1]["joint"], "J1");
    assert_eq!(stages[1]["max_joint_opening"].as_f64(), Some(opening[1]));

    // Field files named by stage, listed in results.pvd.
    let pvd = std::fs::read_to_string(out.join("results.pvd")).unwrap();
    for f in [
        "step001_erect-on-prop_inc0002.vtu",
        "step002_strike-prop_inc0004.vtu",
        "step003_unload-P_inc0002.vtu",
        "joints_step002_strike-prop_inc0004.vtu",
    ] {
        assert!(out.join(f).is_file(), "{f}");
        assert!(pvd.contains(&format!("file=\"{f}\"")), "{f} in results.pvd");
        assert!(segfem::run::is_run_file(f), "{f} is cleared by a new run");
    }

    // The report's stage table and the flag in words.
    let html = out.join("report.html");
    segfem::view::report::report(&segfem::view::report::ReportOptions {
        dir: out.clone(),
        out: Some(html.clone()),
        ..Default::default()
    })
    .unwrap_or_else(|e| panic!("{e}"));
    let page = std::fs::read_to_string(html).unwrap();
    assert!(page.contains("<table id=\"stages\">"), "stage table");
    assert!(
        page.contains("Joint 'J1' opens during construction:")
            && page.contains("in stage 2 'strike prop'"),
        "construction opening flagged"
    );
    assert!(
        !page.contains("stage-opening-3"),
        "the last stage is service"
    );
}

/// A model without stages writes no stages.csv, keeps its field file names and lists no
/// stages in summary.json.
#[test]
fn a_model_without_stages_writes_no_stages_csv() {
    let text = propped_model()
        .replace("activate = [\"prop\"]", "")
        .replace("remove = [\"prop\"]", "");
    let out = run("plain", &text);
    assert!(!out.join("stages.csv").exists());
    assert!(out.join("step002_inc0004.vtu").is_file());
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert!(v.get("stages").is_none());
}
