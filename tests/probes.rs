//! Probes of what a user sees last and trusts most (issue 23): files that survive a crash
//! and cannot be corrupted by names, checkpoints that refuse damage, failed runs that keep
//! their last state and figures, verdicts that say what happened, and models held only by
//! numerical stiffness. Each probe asserts the exit status and the message or warning.

mod common;

use common::{code, segfem, stderr, TempDir};
use std::path::Path;

fn read(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&read(&dir.join("summary.json"))).expect("summary.json is JSON")
}

/// (step, increment) of each data row of a history.csv.
fn history_rows(text: &str) -> Vec<(usize, usize)> {
    text.lines()
        .skip(1)
        .map(|l| {
            let mut c = l.split(',');
            let s = c.next().unwrap().parse().unwrap();
            let i = c.next().unwrap().parse().unwrap();
            (s, i)
        })
        .collect()
}

/// (step, increment) of each continuum field file results.pvd lists.
fn pvd_increments(text: &str) -> Vec<(usize, usize)> {
    text.split("file=\"")
        .skip(1)
        .filter_map(|t| {
            let name = &t[..t.find('"')?];
            let rest = name.strip_prefix("step")?;
            let (s, i) = rest.strip_suffix(".vtu")?.split_once("_inc")?;
            Some((s.parse().ok()?, i.parse().ok()?))
        })
        .collect()
}

/// An unreinforced C30 beam (4 m span, 0.4 × 0.3 m) under a midspan point load raised to
/// 200 kN in `n` load-controlled increments. Its cracking load is near 4 f_ctm W / L =
/// 4 × 2.9 MPa × 0.008 m³ / 4 m ≈ 23 kN, and with no reinforcement nothing carries the load
/// after the first crack: the increment that passes 23 kN cannot converge.
fn plain_beam(n: usize, extra: &str) -> String {
    format!(
        r#"title = "plain concrete beam loaded past cracking"

[[materials]]
name = "C30"
kind = "concrete"
fcm = 38e6
nu = 0.2

[[regions]]
name = "beam"
material = "C30"
thickness = 0.3

[mesh]
type = "banded"
length = 4.0
nx = 16
element = "Q4"
bands = [{{ region = "beam", depth = 0.4, rows = 4 }}]

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
point_loads = [{{ point = [2.0, 0.4], force = [0.0, -200e3] }}]

[[monitors]]
name = "midspan_uy"
kind = "displacement"
point = [2.0, 0.0]
component = "y"

[[steps]]
name = "load"
kind = "load"
loads = {{ P = 1.0 }}
increments = {n}

[solver]
max_cuts = 2
{extra}"#
    )
}

/// A run that fails to converge keeps the field output of its last converged increment
/// (listed in results.pvd and present on disk) and reports its real counts and timings.
#[test]
fn failed_run_writes_last_converged_fields_and_real_timings() {
    let tmp = TempDir::new("probe-failed");
    std::fs::write(tmp.join("m.toml"), plain_beam(20, "")).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 3, "{err}");
    assert!(err.contains("did not converge"), "{err}");
    let out = tmp.join("out");
    let rows = history_rows(&read(&out.join("history.csv")));
    // 10 kN per increment: the first two (10 and 20 kN) are below the cracking load.
    assert!(rows.len() >= 2, "{rows:?}");
    let last = *rows.last().unwrap();
    let listed = pvd_increments(&read(&out.join("results.pvd")));
    assert_eq!(
        listed.last(),
        Some(&last),
        "pvd {listed:?}, history {rows:?}"
    );
    let file = format!("step{:03}_inc{:04}.vtu", last.0, last.1);
    assert!(out.join(&file).is_file(), "{file} missing");
    let s = summary(&out);
    assert_eq!(s["status"], "failed");
    let t = &s["timings"];
    assert_eq!(t["increments"].as_u64(), Some(rows.len() as u64), "{t}");
    assert!(
        t["iterations"].as_u64().unwrap() >= rows.len() as u64,
        "{t}"
    );
    assert!(t["assembly_s"].as_f64().unwrap() > 0.0, "{t}");
}

/// history.csv is never behind results.pvd, whenever the process dies: SIGKILL at an
/// arbitrary moment of a run that writes fields at every increment.
#[test]
fn history_is_never_behind_the_fields_after_sigkill() {
    let tmp = TempDir::new("probe-kill");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/cantilever.toml"),
    )
    .unwrap();
    let text = text.replace(
        "kind = \"linear\"",
        "kind = \"load\"\nincrements = 400\noutput = \"increments\"",
    );
    std::fs::write(tmp.join("c.toml"), text).unwrap();
    for delay_ms in [150, 400] {
        let out = format!("out{delay_ms}");
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_segfem"))
            .args(["run", "c.toml", "-o", &out])
            .current_dir(tmp.path())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = child.kill();
        let _ = child.wait();
        let dir = tmp.join(&out);
        let (Ok(h), Ok(p)) = (
            std::fs::read_to_string(dir.join("history.csv")),
            std::fs::read_to_string(dir.join("results.pvd")),
        ) else {
            continue; // killed before the first increment: nothing to compare
        };
        let rows = history_rows(&h);
        for inc in pvd_increments(&p) {
            assert!(
                rows.contains(&inc),
                "pvd lists {inc:?}, history has {} rows",
                rows.len()
            );
        }
    }
}

/// A monitor name with a comma (or a newline) would break history.csv: refused, naming the
/// field.
#[test]
fn monitor_name_with_comma_or_newline_is_an_input_error() {
    let tmp = TempDir::new("probe-names");
    for (name, shown) in [("tip,uy", "','"), ("tip\\nuy", "'\\n'")] {
        let text = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/cantilever.toml"),
        )
        .unwrap()
        .replace("name = \"tip_uy\"", &format!("name = \"{name}\""));
        std::fs::write(tmp.join("c.toml"), text).unwrap();
        let o = segfem(tmp.path(), &["run", "c.toml", "-o", "out"]);
        let err = stderr(&o);
        assert_eq!(code(&o), 2, "{err}");
        assert!(
            err.contains(&format!(
                "monitors[0].name: {shown} is not allowed in a name"
            )),
            "{err}"
        );
        assert!(!tmp.join("out/history.csv").exists());
    }
}

/// A checkpoint with any one byte changed is refused with a clear message (exit 2), never
/// restarted from a silently different state.
#[test]
fn damaged_checkpoint_is_refused() {
    let tmp = TempDir::new("probe-checkpoint");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/cantilever.toml"),
    )
    .unwrap()
        + "\n[[steps]]\nname = \"again\"\nkind = \"linear\"\nloads = { tip = 2.0 }\n";
    std::fs::write(tmp.join("c.toml"), text).unwrap();
    let o = segfem(
        tmp.path(),
        &["run", "c.toml", "-o", "out", "--stop-after-step", "1"],
    );
    assert_eq!(code(&o), 4, "{}", stderr(&o));
    let cp = tmp.join("out/checkpoint.bin");
    let good = std::fs::read(&cp).unwrap();
    // Bytes spread over the file: header, body (state, history) and the checksum itself.
    let n = good.len();
    for at in [20, n / 5, n / 2, 4 * n / 5, n - 3] {
        let mut bad = good.clone();
        bad[at] ^= 0x10;
        std::fs::write(&cp, &bad).unwrap();
        let o = segfem(tmp.path(), &["run", "--restart", "out"]);
        let err = stderr(&o);
        assert_eq!(code(&o), 2, "byte {at}: {err}");
        assert!(
            err.contains("checkpoint is damaged") || err.contains("not a segfem checkpoint"),
            "byte {at}: {err}"
        );
    }
    // The intact file still restarts.
    std::fs::write(&cp, &good).unwrap();
    let o = segfem(tmp.path(), &["run", "--restart", "out"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
}

fn example(name: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("examples/{name}.toml")),
    )
    .unwrap()
}

/// Replace `from` (present exactly once) by `to`.
fn edit(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "{from}");
    text.replacen(from, to, 1)
}

/// Frictionless dry joints without prestress cannot carry bending: the segments stand only
/// on the open joints' residual stiffness. The run converges (3.4 m of deflection on the
/// 6 m span), and must not end "completed": exit 5, status "implausible", both findings.
#[test]
fn model_held_by_residual_stiffness_is_implausible() {
    let tmp = TempDir::new("probe-dry");
    let text = example("segmental-decompression");
    let text = edit(&text, "friction = 0.7", "friction = 0.0");
    let text = edit(&text, "loads = { P = 1.0 }\n", "loads = { P = 0.0 }\n");
    let text = edit(
        &text,
        "loads = { P = 1.0, Q = 150.0 }",
        "loads = { Q = 150.0 }",
    );
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 5, "{err}");
    assert!(err.contains("not physically meaningful"), "{err}");
    assert!(
        err.contains("through the residual stiffness of its open points"),
        "{err}"
    );
    let s = summary(&tmp.join("out"));
    assert_eq!(s["status"], "implausible");
    let found = s["plausibility"].as_array().unwrap();
    assert!(found[0].as_str().unwrap().contains("joint J"), "{found:?}");
    // The deflection that gave it away: over a tenth of the model size (6.02 m diagonal).
    assert!(
        found
            .iter()
            .any(|f| f.as_str().unwrap().contains("of the model size")),
        "{found:?}"
    );
    // The same model with its prestress and friction is a plausible result.
    std::fs::write(tmp.join("ok.toml"), example("segmental-decompression")).unwrap();
    let o = segfem(tmp.path(), &["run", "ok.toml", "-o", "ok", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    assert_eq!(
        summary(&tmp.join("ok"))["plausibility"],
        serde_json::json!([])
    );
}

/// A time step to 1e300 days is a typing slip: refused, naming the field.
#[test]
fn absurd_time_is_an_input_error() {
    let tmp = TempDir::new("probe-time");
    let text = edit(&example("creep-beam"), "to = 10000.0", "to = 1e300");
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["check", "m.toml"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 2, "{err}");
    assert!(
        err.contains("steps[1].to: 1e300 d is beyond 1e6 d"),
        "{err}"
    );
}

/// An arc-length step that uses its increments before its stop_displacement says so.
/// Elastic cantilever: 3 increments of Δλ = 0.1 cannot move the tip 1 m.
#[test]
fn arc_length_out_of_increments_says_so() {
    let tmp = TempDir::new("probe-arc");
    let text = edit(
        &example("cantilever"),
        "kind = \"linear\"\nloads = { tip = 1.0 }",
        "kind = \"arc_length\"\nloads = { tip = 1.0 }\ninitial_increment = 0.1\nmax_growth = 1.0\nincrements = 3\nstop_displacement = { point = [4.0, 0.0], component = \"y\", value = -1.0 }",
    );
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 0, "{err}");
    assert!(
        err.contains("warning: step 'load' used all its 3 increments before its stop_displacement"),
        "{err}"
    );
    let s = summary(&tmp.join("out"));
    let ended = s["ultimate"]["ended"].as_str().unwrap();
    assert!(ended.contains("used up their increments"), "{ended}");
}

/// Newton stalling while the load still rises is "no convergence", not a limit point:
/// the plain beam driven down in 0.1 mm increments, 4 iterations and no cuts allowed, stops
/// when cracking starts; the load measure peaks at the last converged increment.
#[test]
fn stall_while_load_rises_is_no_convergence() {
    let tmp = TempDir::new("probe-stall");
    let text = edit(
        &plain_beam(100, "max_iterations = 4\n"),
        "kind = \"load\"\nloads = { P = 1.0 }",
        "kind = \"displacement\"\ncontrol = { point = [2.0, 0.4], component = \"y\", value = -0.01 }",
    );
    let text = edit(&text, "max_cuts = 2", "max_cuts = 0");
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 3, "{err}");
    assert!(
        err.contains("ultimate: no convergence at control force"),
        "{err}"
    );
    assert!(!err.contains("loss of equilibrium"), "{err}");
    let u = &summary(&tmp.join("out"))["ultimate"];
    assert_eq!(u["mode"], "no convergence");
    let rows = history_rows(&read(&tmp.join("out/history.csv")));
    assert_eq!(
        u["peak_increment"].as_u64(),
        Some(rows.last().unwrap().1 as u64)
    );
}

/// A peak that is the first crack of the model is named as such: a one-row plain beam
/// under displacement control loses its load when its midspan element cracks.
#[test]
fn cracking_peak_is_named() {
    let tmp = TempDir::new("probe-crack");
    let text = edit(
        &plain_beam(40, ""),
        "kind = \"load\"\nloads = { P = 1.0 }",
        "kind = \"displacement\"\ncontrol = { point = [2.0, 0.4], component = \"y\", value = -0.002 }",
    );
    let text = edit(&text, "rows = 4", "rows = 1");
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let u = &summary(&tmp.join("out"))["ultimate"];
    assert_eq!(u["mode"], "first cracking", "{u}");
    assert!(
        u["detail"].as_str().unwrap().contains("cracking load"),
        "{u}"
    );
}

/// Every bundled example file is offered by `segfem example`, and one that reads a mesh
/// file gets it written beside it, so that it checks as written.
#[test]
fn every_shipped_example_is_offered_and_checks() {
    let tmp = TempDir::new("probe-examples");
    let o = segfem(tmp.path(), &["example"]);
    assert_eq!(code(&o), 0);
    let list = common::stdout(&o);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            let name = p.file_stem().unwrap().to_string_lossy().to_string();
            assert!(
                list.lines()
                    .any(|l| l.split_whitespace().next() == Some(&name)),
                "{name} not listed:\n{list}"
            );
        }
    }
    let o = segfem(tmp.path(), &["example", "gmsh-tapered", "-o", "g.toml"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let o = segfem(tmp.path(), &["check", "g.toml"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
}

/// `--stop-after-step 0` names no step: an error, not a run that never stops.
#[test]
fn stop_after_step_zero_is_an_error() {
    let tmp = TempDir::new("probe-stop0");
    std::fs::write(tmp.join("c.toml"), example("cantilever")).unwrap();
    let o = segfem(
        tmp.path(),
        &["run", "c.toml", "-o", "out", "--stop-after-step", "0"],
    );
    let err = stderr(&o);
    assert_eq!(code(&o), 2, "{err}");
    assert!(
        err.contains("--stop-after-step: steps are numbered from 1"),
        "{err}"
    );
}

/// The report's default curve and peak are the load (here the control force), never a
/// crack strain listed among the monitors.
#[test]
fn report_peak_is_the_load_not_a_crack_strain() {
    let tmp = TempDir::new("probe-report");
    let text = edit(
        &plain_beam(40, ""),
        "kind = \"load\"\nloads = { P = 1.0 }",
        "kind = \"displacement\"\ncontrol = { point = [2.0, 0.4], component = \"y\", value = -0.002 }",
    );
    let text = edit(
        &text,
        "[[steps]]",
        "[[monitors]]\nname = \"crack_max\"\nkind = \"max_crack_strain\"\n\n[[steps]]",
    );
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let o = segfem(tmp.path(), &["report", "out"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let html = read(&tmp.join("out/report.html"));
    assert!(
        html.contains("<b>Peak load:</b> control_force = "),
        "peak line"
    );
    assert!(
        !html.contains("Peak load factor:</b> crack_max"),
        "crack strain as load"
    );
}

/// A fresh run into a used output directory removes the files an earlier run left there
/// (a field file of a step the new run does not have, its report), keeps other files, and
/// says so in a warning.
#[test]
fn used_output_directory_is_cleared_of_stale_files() {
    let tmp = TempDir::new("probe-stale");
    std::fs::write(tmp.join("m.toml"), example("cantilever")).unwrap();
    let out = tmp.join("out");
    std::fs::create_dir_all(&out).unwrap();
    for f in [
        "step009_inc0042.vtu",
        "lines_step009_inc0042.vtu",
        "report.html",
    ] {
        std::fs::write(out.join(f), "stale").unwrap();
    }
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 0, "{err}");
    assert!(
        err.contains("warning: out: removed 3 files of an earlier run"),
        "{err}"
    );
    assert!(!out.join("step009_inc0042.vtu").exists());
    assert!(!out.join("report.html").exists());
    assert_eq!(read(&out.join("notes.txt")), "mine");
    assert!(out.join("step001_inc0001.vtu").is_file());
}

/// A band with too many rows is named by its `rows` key, and a count of the wrong type reads
/// "a whole number", not a Rust type name.
#[test]
fn too_many_rows_names_rows_and_counts_are_whole_numbers() {
    let tmp = TempDir::new("probe-rows");
    let text = edit(&plain_beam(2, ""), "rows = 4", "rows = 100000000");
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["check", "m.toml"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 2, "{err}");
    assert!(
        err.contains("mesh.bands[0].rows: the mesh would have"),
        "{err}"
    );
    let text = edit(&plain_beam(2, ""), "nx = 16", "nx = 2.5");
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["check", "m.toml"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 2, "{err}");
    assert!(err.contains("expected a whole number ≥ 0"), "{err}");
    assert!(!err.contains("usize"), "{err}");
}

/// A tendon prestress given in MPa (876 instead of 876e6) warns of the unit slip.
#[test]
fn tendon_prestress_in_mpa_warns() {
    let tmp = TempDir::new("probe-prestress-unit");
    let text = edit(
        &example("seed-beam-elastic"),
        "initial_stress = 876e6",
        "initial_stress = 876.0",
    );
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["check", "m.toml"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 0, "{err}");
    assert!(
        err.contains("tendons[0].initial_stress: 876 Pa looks like MPa"),
        "{err}"
    );
}

/// The report of a failed run leads with its status and counts its converged increments
/// (the rows of history.csv), and the stress monitors are history columns in Pa.
#[test]
fn failed_run_report_counts_converged_increments() {
    let tmp = TempDir::new("probe-failed-report");
    let text = edit(
        &plain_beam(20, ""),
        "[[steps]]",
        "[[monitors]]\nname = \"s2_min\"\nkind = \"stress\"\ncomponent = \"s2\"\n\n[[steps]]",
    );
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 3, "{}", stderr(&o));
    let history = read(&tmp.join("out/history.csv"));
    assert!(history.lines().next().unwrap().contains(",s2_min [Pa]"));
    let rows = history_rows(&history).len();
    let o = segfem(tmp.path(), &["report", "out"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let html = read(&tmp.join("out/report.html"));
    assert!(
        html.contains(&format!(
            "Run failed: {rows} converged increments before the failure"
        )),
        "headline"
    );
}

/// `plot --units` takes display or si only (exit 2 otherwise); `--units si --sign raw` draws
/// the file's values.
#[test]
fn plot_units_option() {
    let tmp = TempDir::new("probe-plot-units");
    std::fs::write(tmp.join("m.toml"), example("cantilever")).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let o = segfem(tmp.path(), &["plot", "out", "--units", "imperial"]);
    assert_eq!(code(&o), 2, "{}", stderr(&o));
    assert!(stderr(&o).contains("--units"), "{}", stderr(&o));
    let o = segfem(
        tmp.path(),
        &["plot", "out", "--units", "si", "--sign", "raw"],
    );
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let svg = read(&tmp.join("out/figures/curves.svg"));
    assert!(svg.contains("tip_uy [m]"), "SI label");
}

/// A 1 × 0.2 m strip (0.2 m thick) of creeping C30 concrete (`creep = "mc90"`) held for
/// 1000 days under an axial compression of 15 MPa = 0.5 f_cm, with `extra` keys on the
/// material.
fn sustained_strip(extra: &str) -> String {
    format!(
        r#"title = "strip under sustained compression"

[[materials]]
name = "C30"
kind = "concrete"
creep = "mc90"
fcm = 30e6
nu = 0.2
rh = 0.7
h0 = 0.1
cement = "N"
{extra}

[[regions]]
name = "strip"
material = "C30"
thickness = 0.2

[mesh]
type = "banded"
length = 1.0
nx = 4
element = "Q4"
bands = [{{ region = "strip", depth = 0.2, rows = 1 }}]

[[supports]]
name = "end"
line = [[0.0, 0.0], [0.0, 0.2]]
ux = 0.0

[[supports]]
name = "corner"
point = [0.0, 0.0]
uy = 0.0

[[load_cases]]
name = "N"
line_loads = [{{ line = [[1.0, 0.0], [1.0, 0.2]], q = [-3.0e6, 0.0] }}]

[[monitors]]
name = "shortening"
kind = "displacement"
point = [1.0, 0.0]
component = "x"

[[steps]]
name = "load"
kind = "load"
loads = {{ N = 1.0 }}

[[steps]]
name = "hold"
kind = "time"
from = 28.0
duration = 1000.0
"#
    )
}

/// Sustained compression above MC90's linear creep limit (0.4 f_cm) with linear creep
/// warns once, naming the region and suggesting `nonlinear_creep`; with the option on there
/// is no warning. The stress is q t / (h t) = 3e6 N/m / 0.2 m = 15 MPa = 0.5 f_cm (uniform
/// axial stress in a free-to-expand strip: the ratio is exact up to round-off).
#[test]
fn sustained_stress_above_linear_creep_warns() {
    let tmp = TempDir::new("probe-sustained");
    std::fs::write(tmp.join("lin.toml"), sustained_strip("")).unwrap();
    let o = segfem(tmp.path(), &["run", "lin.toml", "-o", "lin"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 0, "{err}");
    assert_eq!(err.matches("linear creep range").count(), 1, "{err}");
    assert!(err.contains("region 'strip'"), "{err}");
    assert!(err.contains("material 'C30'"), "{err}");
    assert!(err.contains("|σ_c| = 0.50 f_cm"), "{err}");
    assert!(err.contains("nonlinear_creep = true"), "{err}");
    let s = summary(&tmp.join("lin"));
    let w = s["warnings"].as_array().expect("warnings");
    assert_eq!(
        w.iter()
            .filter(|w| w.as_str().unwrap().contains("linear creep range"))
            .count(),
        1,
        "{w:?}"
    );

    std::fs::write(
        tmp.join("nl.toml"),
        sustained_strip("nonlinear_creep = true"),
    )
    .unwrap();
    let o = segfem(tmp.path(), &["run", "nl.toml", "-o", "nl"]);
    let err = stderr(&o);
    assert_eq!(code(&o), 0, "{err}");
    assert!(!err.contains("linear creep range"), "{err}");
}

/// The report says how sure the path is when an increment error control ran: the plain beam
/// with `[solver] increment_tolerance` shows the largest kept path error and the pairs
/// rejected, as summary.json gives them, and the error kept is a fraction (0 < e < 1).
#[test]
fn report_states_the_estimated_path_error() {
    let tmp = TempDir::new("probe-path-error");
    let text = plain_beam(10, "increment_tolerance = 0.05");
    std::fs::write(tmp.join("m.toml"), text).unwrap();
    let o = segfem(tmp.path(), &["run", "m.toml", "-o", "out", "-q"]);
    assert!(matches!(code(&o), 0 | 3), "{}", stderr(&o));
    let t = &summary(&tmp.join("out"))["timings"];
    let e = t["increment_max_error"]
        .as_f64()
        .expect("a path error estimated");
    assert!(e > 0.0 && e < 1.0, "{t}");
    let o = segfem(tmp.path(), &["report", "out"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let html = read(&tmp.join("out/report.html"));
    assert!(
        html.contains("estimated path error (increment_tolerance)")
            && html.contains(&format!("largest kept {e:.3}")),
        "no path-error row"
    );
}
