//! `segfem report`: one self-contained HTML page (no network, no external files) with the
//! model summary, key numbers of the history, the figures (curves as inline SVG, the
//! model drawings as base64 PNG) and, given a reference CSV, a comparison table.

use super::data::{Grid, Table};
use super::figures::{
    png_bytes, svg_string, CurveFigure, DeformedFigure, JointProfile, MeshFigure, StageFigure,
};
use super::{
    auto_scale, crack_figure, curve_figure, displacements, field_values, fmt_scale, joint_figure,
    pick_output, read_history, run_name, Field, ViewError, CRACK_NOTE, JOINT_NOTE,
};
use base64::Engine;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Options of `segfem report`.
#[derive(Debug, Clone, Default)]
pub struct ReportOptions {
    /// Run directory.
    pub dir: PathBuf,
    /// HTML file to write; default `<dir>/report.html`.
    pub out: Option<PathBuf>,
    /// Reference CSV (x, y) compared with the computed curve.
    pub reference: Option<PathBuf>,
    /// x column of the curve (default as in `plot`).
    pub x: Option<String>,
    /// y column of the curve (default as in `plot`).
    pub y: Option<String>,
    /// Output number for the field figures (1-based; default the last).
    pub step: Option<usize>,
    /// Display units and signs of the curve and the peak load.
    pub units: super::UnitOptions,
}

/// A row of the comparison table.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Reference x.
    pub x: f64,
    /// Reference y.
    pub y_ref: f64,
    /// Computed y at x (linear interpolation along the history), if x is within the curve.
    pub y_calc: Option<f64>,
}

/// Computed y at `x` on a polyline: the first segment that brackets `x`.
pub fn interpolate(points: &[(f64, f64)], x: f64) -> Option<f64> {
    for w in points.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if (x0 <= x && x <= x1) || (x1 <= x && x <= x0) {
            if x1 == x0 {
                return Some(y0);
            }
            return Some(y0 + (y1 - y0) * (x - x0) / (x1 - x0));
        }
    }
    if points.len() == 1 && points[0].0 == x {
        return Some(points[0].1);
    }
    None
}

/// Compare the reference points of a curve figure with its first computed series.
pub fn compare(fig: &CurveFigure) -> Vec<Comparison> {
    let Some(r) = &fig.reference else {
        return Vec::new();
    };
    let calc = fig
        .series
        .first()
        .map(|s| s.points.as_slice())
        .unwrap_or(&[]);
    r.points
        .iter()
        .map(|&(x, y)| Comparison {
            x,
            y_ref: y,
            y_calc: interpolate(calc, x),
        })
        .collect()
}

/// HTML-escape text.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A number for tables: 4 significant digits.
fn num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if !v.is_finite() {
        "—".into()
    } else if (1e-3..1e5).contains(&v.abs()) {
        let d = (3 - v.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{v:.d$}")
    } else {
        format!("{v:.3e}")
    }
}

fn png_img(bytes: &[u8], alt: &str) -> String {
    format!(
        r#"<img alt="{}" src="data:image/png;base64,{}">"#,
        esc(alt),
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

const STYLE: &str = "body{font-family:'DejaVu Sans',Arial,sans-serif;margin:24px auto;max-width:1400px;color:#222;padding:0 16px}
h1{font-size:24px;border-bottom:2px solid #1f5aa6;padding-bottom:6px}h2{font-size:19px;margin-top:28px;color:#1f5aa6}
table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #bbb;padding:4px 10px;text-align:right}
th{background:#eef2f8}td:first-child,th:first-child{text-align:left}
figure{margin:12px 0}figure img,figure svg{max-width:100%;height:auto;border:1px solid #ddd}
figcaption{font-size:14px;color:#555}.note{color:#8a5a00;font-size:14px}.bad{color:#b00}";

/// Unit and scale a report table shows a column of SI unit `unit` in: the design units of
/// [`super::units::display_unit`] (mm, kN, kN·m, MPa), or SI with `--units si`.
fn table_unit(unit: &str, units: super::UnitOptions) -> (String, f64) {
    if units.si {
        (unit.to_string(), 1.0)
    } else {
        let (u, k) = super::units::display_unit(unit);
        (u.to_string(), k)
    }
}

/// Smallest joint opening the events count as an opening [m] (0.01 mm, as the stages'): a
/// 1.5 µm creep parting was reported as the first opening.
const OPENING_THRESHOLD: f64 = crate::results::stages::OPENING_THRESHOLD;

/// Key numbers of a history: one table row per factor and monitor column, in design units.
fn key_numbers(h: &Table, units: super::UnitOptions) -> String {
    let mut s = String::from(
        "<table><tr><th>quantity</th><th>unit</th><th>final</th><th>min</th><th>max</th><th>largest |value|</th><th>at step / increment</th></tr>\n",
    );
    let step = h.column("step").ok();
    let inc = h.column("increment").ok();
    for c in h.factors().chain(h.monitors()) {
        if c.values.is_empty() {
            continue;
        }
        let min = c.values.iter().copied().fold(f64::INFINITY, f64::min);
        let max = c.values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let (k, big) = c
            .values
            .iter()
            .copied()
            .enumerate()
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
            .expect("not empty");
        let at = match (step, inc) {
            (Some(s), Some(i)) => format!("{} / {}", s.values[k], i.values[k]),
            _ => format!("row {}", k + 1),
        };
        let (unit, f) = table_unit(&c.unit, units);
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            esc(&c.name),
            esc(&unit),
            num(f * c.values.last().expect("not empty")),
            num(f * min),
            num(f * max),
            num(f * big),
            at
        );
    }
    s.push_str("</table>\n");
    s
}

/// Engineering events read off the history, against the load measure (the load-case factor
/// that grows most): the first joint opening (first row where a monitor named
/// `*opening*` becomes positive), the largest opening, the tendon stress increase
/// (`*tendon_stress*` monitors, last minus first value) and the decompression bracket.
fn events(h: &Table, units: super::UnitOptions) -> String {
    let Some(load) = h
        .factors()
        .chain(h.monitors().filter(|c| c.unit == "-"))
        .max_by(|a, b| {
            let span = |c: &super::data::Column| {
                c.values.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                    - c.values.iter().copied().fold(f64::INFINITY, f64::min)
            };
            span(a).total_cmp(&span(b))
        })
    else {
        return String::new();
    };
    let mut items = Vec::new();
    // A load factor with its load case's name, e.g. `Q` for `factor:Q`.
    let load_name = load.name.strip_prefix("factor:").unwrap_or(&load.name);
    for c in h.monitors().filter(|c| c.name.contains("opening")) {
        let (unit, f) = table_unit(&c.unit, units);
        // In metres (the opening monitors' unit) the threshold applies; other units as given.
        let threshold = if c.unit == "m" {
            OPENING_THRESHOLD
        } else {
            0.0
        };
        if let Some(k) = c.values.iter().position(|v| *v > threshold) {
            let before = if k > 0 {
                format!(" (closed at {})", num(load.values[k - 1]))
            } else {
                String::new()
            };
            items.push(format!(
                "first opening above {} mm ({}): {} = {}{before}",
                OPENING_THRESHOLD * 1e3,
                esc(&c.name),
                esc(load_name),
                num(load.values[k])
            ));
            let max = c.values.iter().copied().fold(0.0, f64::max);
            items.push(format!(
                "largest {}: {} {}",
                esc(&c.name),
                num(f * max),
                esc(&unit)
            ));
        } else {
            items.push(format!(
                "{}: no opening above {} mm in this run",
                esc(&c.name),
                OPENING_THRESHOLD * 1e3
            ));
        }
    }
    for c in h.monitors().filter(|c| c.name.contains("tendon_stress")) {
        if let (Some(first), Some(last)) = (c.values.iter().find(|v| **v != 0.0), c.values.last()) {
            let (unit, f) = table_unit(&c.unit, units);
            items.push(format!(
                "{}: {} → {} {} (increase {} {})",
                esc(&c.name),
                num(f * first),
                num(f * last),
                esc(&unit),
                num(f * (last - first)),
                esc(&unit)
            ));
        }
    }
    if items.is_empty() {
        return String::new();
    }
    let mut s = String::from("<h2>Events</h2>\n<ul>\n");
    for i in items {
        let _ = writeln!(s, "<li>{i}</li>");
    }
    s.push_str("</ul>\n");
    s
}

/// The verdict at the top of the report: how the run ended, with its converged increments
/// counted from the history, and the `ultimate` verdict (failure mode, load, what yielded
/// or crushed) of a run to failure.
pub fn headline(dir: &Path, h: &Table) -> String {
    let v: serde_json::Value = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or(serde_json::Value::Null);
    let status = v["status"].as_str().unwrap_or("unknown (no summary.json)");
    let n = h.rows();
    let ended = match status {
        "completed" => format!("Run completed: {n} converged increments."),
        "failed" => format!(
            "Run failed: {n} converged increments before the failure; the results shown are those of the last converged increment."
        ),
        "implausible" => format!(
            "Run ended with an implausible result ({n} converged increments): check the model before any use."
        ),
        s => format!("Run {s}: {n} converged increments."),
    };
    let class = if status == "completed" {
        ""
    } else {
        " class=\"bad\""
    };
    let mut s = format!("<p id=\"headline\"{class}><b>{}</b></p>\n", esc(&ended));
    let ultimate =
        serde_json::from_value::<crate::results::ultimate::Ultimate>(v["ultimate"].clone());
    if let Ok(u) = ultimate {
        let _ = writeln!(s, "<p id=\"ultimate\"><b>{}</b></p>", esc(&u.to_string()));
        // The verdict's load measure is a factor: said as the force it stands for when its
        // load case holds forces only (the seed beam's Q: 2 kN in all per unit factor).
        if let Some(f) =
            super::units::FactorUnits::read(dir).force_of(&format!("factor:{}", u.load_case))
        {
            let (unit, scale) = super::units::display_unit("N");
            let kn = |x: f64| format!("{:.1} {unit}", x * f.abs() * scale);
            let _ = writeln!(
                s,
                "<p id=\"ultimate-force\">{} is a factor of the case's {} in all: {} at {}, peak {}</p>",
                esc(&u.load_case),
                kn(1.0),
                esc(&u.mode),
                kn(u.at_factor),
                kn(u.peak_factor)
            );
        }
    }
    // Elastic concrete past its strength: flagged under the verdict, never only in the
    // warnings table.
    let findings = serde_json::from_value::<Vec<crate::results::strength::StrengthFinding>>(
        v["strength_exceeded"].clone(),
    )
    .unwrap_or_default();
    if !findings.is_empty() {
        let _ = writeln!(
            s,
            "<div id=\"strength\" class=\"bad\"><p><b>Concrete past its strength ({} checks failed): the concrete is modelled as elastic.</b></p><ul>",
            findings.len()
        );
        for f in &findings {
            let _ = writeln!(s, "<li>{}</li>", esc(&f.text));
        }
        s.push_str("</ul></div>\n");
    }
    s
}

fn summary_section(dir: &Path) -> (String, String) {
    let path = dir.join("summary.json");
    let Ok(text) = std::fs::read_to_string(&path) else {
        return (
            run_name(dir),
            format!(
                "<p class=\"note\">{}: not found; no model summary.</p>\n",
                esc(&path.display().to_string())
            ),
        );
    };
    let Ok(v) = serde_json::from_str::<serde_json::Value>(&text) else {
        return (
            run_name(dir),
            format!(
                "<p class=\"note\">{}: not valid JSON.</p>\n",
                esc(&path.display().to_string())
            ),
        );
    };
    let title = v["title"].as_str().unwrap_or("segfem run").to_string();
    let mut s = String::from("<table>\n");
    let mut row = |k: &str, val: String| {
        let _ = writeln!(s, "<tr><th>{k}</th><td>{}</td></tr>", esc(&val));
    };
    let status = v["status"].as_str().unwrap_or("?").to_string();
    row("status", status);
    if let Some(e) = v["error"].as_str() {
        row("error", e.to_string());
    }
    let size = &v["size"];
    for k in ["nodes", "elements", "dofs", "equations"] {
        if let Some(n) = size[k].as_u64() {
            row(k, n.to_string());
        }
    }
    let t = &v["timings"];
    if let Some(n) = t["increments"].as_u64() {
        row("converged increments", n.to_string());
    }
    if let Some(n) = t["iterations"].as_u64() {
        row("iterations", n.to_string());
    }
    if let Some(w) = v["wall_s"].as_f64() {
        row("wall time [s]", format!("{w:.3}"));
    }
    // How sure the path is: the error estimates of the increment controls that ran.
    if let Some(e) = t["increment_max_error"].as_f64() {
        row(
            "estimated path error (increment_tolerance)",
            format!(
                "largest kept {e:.3} of the displacement change over a pair; {} pairs rejected; {} kept above the tolerance (a crack or joint jumping open inside them: the size does not control their error)",
                t["increments_rejected"].as_u64().unwrap_or(0),
                t["increments_over_tolerance"].as_u64().unwrap_or(0)
            ),
        );
    }
    if let Some(e) = t["implex_max_error"].as_f64() {
        row(
            "IMPL-EX error (implex_tolerance)",
            format!(
                "largest kept {e:.3} f_tm (of f_cm for IMPL-EX compression); {} increments cut \
                 for it",
                t["implex_cuts"].as_u64().unwrap_or(0)
            ),
        );
    }
    if let Some(e) = t["implex_force_max_error"].as_f64() {
        row(
            "IMPL-EX out-of-balance force (implex_force_tolerance)",
            format!(
                "largest kept {e:.2e} of the force scale; {} increments cut for it; {} kept above the tolerance",
                t["implex_force_cuts"].as_u64().unwrap_or(0),
                t["implex_force_over_tolerance"].as_u64().unwrap_or(0)
            ),
        );
    }
    let p = &v["ultimate"]["path_error"];
    if let (Some(at), Some(largest), Some(limit)) = (
        p["at_peak"].as_f64(),
        p["largest"].as_f64(),
        p["limit"].as_f64(),
    ) {
        row(
            "IMPL-EX path error (energy norm)",
            format!(
                "{at:.1e} at the peak ({}: flagged above {limit:.0e}); largest {largest:.1e}",
                if at > limit {
                    "the peak may depend on the increment size"
                } else {
                    "not flagged"
                }
            ),
        );
    }
    if let Some(m) = v["peak_memory_bytes"].as_f64() {
        row("peak memory [MiB]", format!("{:.1}", m / 1048576.0));
    }
    if let Some(ws) = v["warnings"].as_array() {
        for w in ws {
            row("warning", w.as_str().unwrap_or("").to_string());
        }
    }
    s.push_str("</table>\n");
    (title, s)
}

/// The construction stages of a staged run (summary.json `stages`, as in stages.csv): a
/// table of the stages with their history rows and largest joint opening, and a warning in
/// words for each joint that opened in a stage before the last one (during construction).
/// Empty for a run without stages.
/// The design checks of summary.json (`design_checks`): one row per check, its governing
/// item, utilisation and verdict; failures marked.
fn design_section(dir: &Path) -> String {
    let Some(v) = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
    else {
        return String::new();
    };
    let Some(checks) = v["design_checks"].as_array().filter(|c| !c.is_empty()) else {
        return String::new();
    };
    let mut s = String::from(
        "<h2>Design checks</h2>\n<table id=\"design\">\n<tr><th>check</th><th>clause</th><th>step</th><th>governing</th><th>demand</th><th>limit</th><th>utilisation</th><th>verdict</th></tr>\n",
    );
    for c in checks {
        let text = |k: &str| c[k].as_str().unwrap_or("").to_string();
        let verdict = text("verdict");
        let item = c["items"]
            .as_array()
            .and_then(|items| items.iter().find(|i| i["item"] == c["governing"]));
        let unit = text("unit");
        let value = |k: &str| {
            item.and_then(|i| i[k].as_f64())
                .map_or("–".to_string(), |x| format!("{} {unit}", num(x)))
        };
        let u = match &c["utilisation"] {
            serde_json::Value::Number(n) => format!("{:.3}", n.as_f64().unwrap_or(0.0)),
            serde_json::Value::Null if verdict == "not_evaluated" => "–".into(),
            _ => "∞".into(),
        };
        let class = if verdict == "fail" {
            " class=\"bad\""
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "<tr{class}><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{u}</td><td>{}</td></tr>",
            esc(&text("name")),
            esc(&text("clause")),
            esc(&text("step")),
            esc(&text("governing")),
            value("demand"),
            value("limit"),
            esc(&verdict.replace('_', " ")),
        );
    }
    s.push_str("</table>\n<p class=\"note\">Every item of each check is in summary.json (<code>design_checks</code>); docs/theory-design.md gives the formulas.</p>\n");
    s
}

fn stages_section(dir: &Path) -> String {
    let Some(v) = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
    else {
        return String::new();
    };
    let Ok(stages) =
        serde_json::from_value::<Vec<crate::results::stages::StageResult>>(v["stages"].clone())
    else {
        return String::new();
    };
    if stages.is_empty() {
        return String::new();
    }
    let mut s = String::from(
        "<h2>Construction stages</h2>\n<table id=\"stages\">\n<tr><th>step</th><th>name</th><th>placed</th><th>removed</th><th>history rows</th><th>largest joint opening [mm]</th><th>joint</th><th>supports lifted off / touched down</th></tr>\n",
    );
    for st in &stages {
        let rows = st
            .history_rows
            .map_or("(not run)".to_string(), |(a, b)| format!("{a}–{b}"));
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            st.step,
            esc(&st.name),
            esc(&st.activated.join(", ")),
            esc(&st.removed.join(", ")),
            rows,
            num(st.max_joint_opening * 1e3),
            esc(st.joint.as_deref().unwrap_or("–")),
            if st.support_events.is_empty() {
                "–".to_string()
            } else {
                esc(&st.support_events.join("; "))
            },
        );
    }
    s.push_str("</table>\n");
    let mut any = false;
    for st in crate::results::stages::construction_openings(&stages) {
        any = true;
        let _ = writeln!(
            s,
            "<p class=\"bad\" id=\"stage-opening-{}\"><b>Joint '{}' opens during construction:</b> {} mm in stage {} '{}'.</p>",
            st.step,
            esc(st.joint.as_deref().unwrap_or("")),
            num(st.max_joint_opening * 1e3),
            st.step,
            esc(&st.name)
        );
    }
    if !any {
        let n = crate::results::stages::construction_stages(&stages);
        let _ = writeln!(
            s,
            "<p id=\"stage-openings\">No joint opens by more than {} mm during construction (stages 1–{n}, up to the last that places or removes a part; later stages are service).</p>",
            crate::results::stages::OPENING_THRESHOLD * 1e3
        );
    }
    if let Some(fig) = StageFigure::new(&stages) {
        match svg_string(&fig) {
            Ok(svg) => {
                let _ = writeln!(
                    s,
                    "<figure id=\"stage-history\">{svg}<figcaption>{}: a bar per stage over its rows of history.csv, as high as the largest joint opening reached during it (the table above); grey lines mark the stage boundaries.</figcaption></figure>",
                    esc(&fig.title)
                );
            }
            Err(e) => {
                let _ = writeln!(
                    s,
                    "<p class=\"note\">stage history figure: skipped ({})</p>",
                    esc(&e.to_string())
                );
            }
        }
    }
    s
}

/// The influence tables of the run (summary.json `influence`): per table the traffic
/// models as reduced to the girder, the envelopes with their governing axles and the
/// combinations, in the report's units. Empty for a run without them.
fn influence_section(dir: &Path, units: super::UnitOptions) -> String {
    use crate::results::envelopes::{ExtremeOut, InfluenceSummary};
    let Some(v) = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
    else {
        return String::new();
    };
    let Ok(tables) = serde_json::from_value::<Vec<InfluenceSummary>>(v["influence"].clone()) else {
        return String::new();
    };
    let mut s = String::new();
    for t in &tables {
        let _ = writeln!(
            s,
            "<h2>Influence lines '{}' (after step '{}')</h2>",
            esc(&t.name),
            esc(&t.after_step)
        );
        if let Some(e) = &t.error {
            let _ = writeln!(s, "<p class=\"bad\">Not taken: {}</p>", esc(e));
            continue;
        }
        let _ = writeln!(
            s,
            "<p>{} load positions; files {}.</p>",
            t.positions,
            esc(&t.files.join(", "))
        );
        for n in &t.traffic {
            let _ = writeln!(s, "<p class=\"note\">{}</p>", esc(n));
        }
        let at = |x: &ExtremeOut| {
            if x.axles_x.is_empty() {
                "–".to_string()
            } else {
                esc(&format!(
                    "{} at x = {} m",
                    x.vehicle_name,
                    x.axles_x
                        .iter()
                        .map(|v| format!("{v:.2}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            }
        };
        if !t.envelopes.is_empty() {
            s.push_str("<table class=\"envelopes\">\n<tr><th>monitor</th><th>traffic</th><th>unit</th><th>state</th><th>min</th><th>governing</th><th>max</th><th>governing</th></tr>\n");
            for e in &t.envelopes {
                let (u, k) = table_unit(&e.unit, units);
                let _ = writeln!(
                    s,
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                    esc(&e.monitor),
                    esc(&e.traffic),
                    esc(&u),
                    num(e.state * k),
                    num(e.min.value * k),
                    at(&e.min),
                    num(e.max.value * k),
                    at(&e.max)
                );
            }
            s.push_str("</table>\n");
        }
        if !t.combinations.is_empty() {
            s.push_str("<table class=\"combinations\">\n<tr><th>combination</th><th>monitor</th><th>unit</th><th>min</th><th>max</th></tr>\n");
            for c in &t.combinations {
                let (u, k) = table_unit(&c.unit, units);
                let _ = writeln!(
                    s,
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                    esc(&c.combination),
                    esc(&c.monitor),
                    esc(&u),
                    num(c.min * k),
                    num(c.max * k)
                );
            }
            s.push_str("</table>\n");
        }
    }
    s
}

/// `segfem report`: write the HTML page; returns its path and the notes on skipped parts.
pub fn report(opts: &ReportOptions) -> Result<(PathBuf, Vec<String>), ViewError> {
    let h = read_history(&opts.dir)?;
    let y: Vec<String> = opts.y.iter().cloned().collect();
    let curves = curve_figure(
        &opts.dir,
        opts.x.as_deref(),
        &y,
        &[],
        opts.reference.as_deref(),
        opts.units,
    )?;
    let out = opts
        .out
        .clone()
        .unwrap_or_else(|| opts.dir.join("report.html"));
    let mut notes = Vec::new();
    let (title, summary) = summary_section(&opts.dir);
    let mut html = String::new();
    let _ = write!(
        html,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{t}</title><style>{STYLE}</style></head><body>\n<h1>{t}</h1>\n{head}<p>Run directory: <code>{d}</code></p>\n<h2>Model and run</h2>\n{summary}",
        t = esc(&title),
        head = headline(&opts.dir, &h),
        d = esc(&opts.dir.display().to_string())
    );
    html.push_str(&stages_section(&opts.dir));
    html.push_str(&design_section(&opts.dir));
    html.push_str(&influence_section(&opts.dir, opts.units));
    let _ = write!(
        html,
        "<h2>Key numbers of the history ({} converged increments)</h2>\n{}",
        h.rows(),
        key_numbers(&h, opts.units)
    );
    html.push_str(&events(&h, opts.units));
    // The peak of the load the curve shows (its first y column), by magnitude.
    let load_name = match opts.y.as_ref() {
        Some(y) => y.clone(),
        None => super::default_columns(&h)?.1.remove(0),
    };
    let load = h.column(&load_name)?;
    let peak = load
        .values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .max_by(|a, b| a.abs().total_cmp(&b.abs()));
    if let Some(v) = peak {
        let kinds = super::units::kinds(&opts.dir);
        let kind = kinds.iter().find(|(n, _)| *n == load.name).map(|(_, k)| k);
        let shown = super::units::shown(&load.name, &load.unit, kind, &load.values, opts.units);
        // A factor of a load case of forces only: its unit and the force it reaches.
        let fu = super::units::FactorUnits::read(&opts.dir);
        let force = fu.force_of(&load.name).map(|f| {
            let s = fu.apply(&load.name, shown.clone(), opts.units);
            let (u, scale) = if opts.units.si {
                ("N", 1.0)
            } else {
                super::units::display_unit("N")
            };
            format!(" ({}: {} {u})", esc(&s.unit), num(v.abs() * f * scale))
        });
        // Only a load is called one: a deflection or a stress on the curve's y axis is its
        // largest magnitude ("Peak load: deflection_Q = 122.4 mm" named a deflection a load).
        let what = match load.unit.as_str() {
            "-" => "Peak load factor",
            "N" | "N·m" => "Peak load",
            _ => "Largest magnitude on the curve",
        };
        let _ = writeln!(
            html,
            "<p id=\"peak\"><b>{what}:</b> {} = {}{}</p>",
            esc(&load.name),
            num(v * shown.factor),
            if let Some(f) = &force {
                f.clone()
            } else if shown.unit.is_empty() || shown.unit == "-" {
                String::new()
            } else {
                format!(" {}", esc(&shown.unit))
            }
        );
    }
    html.push_str("<h2>History</h2>\n<figure>");
    html.push_str(&svg_string(&curves)?);
    let _ = writeln!(
        html,
        "<figcaption>{}; a dot per converged increment.</figcaption></figure>",
        esc(&curves.title)
    );
    let cmp = compare(&curves);
    if let Some(r) = &curves.reference {
        let _ = writeln!(
            html,
            "<h2>Comparison with the reference</h2>\n<p>{} against {}: the computed value is interpolated linearly along the history at each reference x.</p>\n<table><tr><th>{}</th><th>reference {}</th><th>computed</th><th>computed − reference</th><th>computed / reference</th></tr>",
            esc(&r.label),
            esc(&curves.series.first().map(|s| s.label.clone()).unwrap_or_default()),
            esc(&curves.x_label),
            esc(&curves.y_label)
        );
        for c in &cmp {
            let (calc, diff, ratio) = match c.y_calc {
                Some(v) => (
                    num(v),
                    num(v - c.y_ref),
                    if c.y_ref != 0.0 {
                        format!("{:.3}", v / c.y_ref)
                    } else {
                        "—".into()
                    },
                ),
                None => ("outside the run".into(), "—".into(), "—".into()),
            };
            let _ = writeln!(
                html,
                "<tr><td>{}</td><td>{}</td><td>{calc}</td><td>{diff}</td><td>{ratio}</td></tr>",
                num(c.x),
                num(c.y_ref)
            );
        }
        html.push_str("</table>\n");
    }
    html.push_str("<h2>Model drawings</h2>\n");
    match pick_output(&opts.dir, opts.step) {
        Ok((n, output)) => {
            let g = output.grid()?;
            let tag = format!("output {n}, {}", run_name(&output.file));
            let joints = super::output_joint_profiles(&output, &g, &opts.dir)?;
            let from_points = output.joint_points.is_some();
            let has_joints = super::expects_joints(&g, &opts.dir);
            let tendons = output.tendon_spans()?;
            fields_section(&mut html, &opts.dir, &g, tendons, &tag, &mut notes)?;
            joints_section(&mut html, joints, from_points, has_joints, &tag, &mut notes)?;
        }
        Err(e) if opts.step.is_none() => notes.push(format!("model drawings: skipped ({e})")),
        Err(e) => return Err(e),
    }
    for n in &notes {
        let _ = writeln!(html, "<p class=\"note\">{}</p>", esc(n));
    }
    html.push_str(
        "<p style=\"font-size:12px;color:#888\">Written by segfem report.</p>\n</body></html>\n",
    );
    std::fs::write(&out, html).map_err(|e| ViewError::Io(format!("{}: {e}", out.display())))?;
    Ok((out, notes))
}

fn figure(html: &mut String, png: &[u8], caption: &str) {
    let _ = writeln!(
        html,
        "<figure>{}<figcaption>{}</figcaption></figure>",
        png_img(png, caption),
        esc(caption)
    );
}

fn fields_section(
    html: &mut String,
    dir: &Path,
    g: &Grid,
    tendons: Vec<[[f64; 2]; 2]>,
    tag: &str,
    notes: &mut Vec<String>,
) -> Result<(), ViewError> {
    let mesh = MeshFigure {
        grid: g,
        regions: super::units::region_names(dir),
        tendons,
        title: format!("Mesh: {} points, {} cells", g.points.len(), g.cells.len()),
    };
    figure(
        html,
        &png_bytes(&mesh)?,
        "Mesh, cells coloured by region, joints in red, tendons in green",
    );
    let disp = displacements(g);
    let scale = auto_scale(g, &disp);
    let def = DeformedFigure {
        grid: g,
        disp,
        scale,
        title: format!("Deformed shape ×{} ({tag})", fmt_scale(scale)),
    };
    figure(
        html,
        &png_bytes(&def)?,
        &format!(
            "Deformed mesh magnified {} times over the undeformed outline (grey)",
            fmt_scale(scale)
        ),
    );
    for field in [Field::Sx, Field::S1, Field::S2] {
        let fig = super::figures::ContourFigure {
            grid: g,
            values: field_values(g, field, false)?,
            label: field.label().into(),
            title: format!("{} (nodal, {tag})", field.label()),
        };
        let (lo, hi) = fig.range();
        figure(
            html,
            &png_bytes(&fig)?,
            &format!(
                "{}: from {} to {} MPa (blue compression, red tension)",
                field.label(),
                num(lo),
                num(hi)
            ),
        );
    }
    match crack_figure(g, tag) {
        Some(f) => figure(
            html,
            &png_bytes(&f)?,
            "Crack pattern: a line along each crack",
        ),
        None => notes.push(CRACK_NOTE.into()),
    }
    Ok(())
}

/// Joint diagrams along the depth and a table of their extremes: the largest opening and
/// the largest contact (compressive normal) stress of each joint, with the height where
/// they occur, read from the joints' integration points when the run wrote them.
fn joints_section(
    html: &mut String,
    joints: Vec<JointProfile>,
    from_points: bool,
    has_joints: bool,
    tag: &str,
    notes: &mut Vec<String>,
) -> Result<(), ViewError> {
    if joints.is_empty() {
        if has_joints {
            notes.push(JOINT_NOTE.into());
        }
        return Ok(());
    }
    let source = if from_points {
        "at the joints' integration points"
    } else {
        "element means of the joint line cells (the run wrote no joint integration points)"
    };
    let _ = writeln!(
        html,
        "<h2>Joints</h2>\n<p>Opening and contact stress along the depth, {source} ({}).</p>\n<table><tr><th>joint</th><th>largest opening [mm]</th><th>at y [m]</th><th>largest contact stress [MPa]</th><th>at y [m]</th></tr>",
        esc(tag)
    );
    for j in &joints {
        let pick = |f: &dyn Fn(&(f64, f64, f64)) -> f64| {
            j.points
                .iter()
                .filter(|p| f(p).is_finite())
                .max_by(|a, b| f(a).total_cmp(&f(b)))
                .map(|p| (f(p), p.0))
        };
        let cell = |v: Option<(f64, f64)>| match v {
            Some((v, y)) => format!("<td>{}</td><td>{}</td>", num(v.max(0.0)), num(y)),
            None => "<td>—</td><td>—</td>".into(),
        };
        let _ = writeln!(
            html,
            "<tr><td>{}</td>{}{}</tr>",
            esc(&j.name),
            cell(pick(&|p| p.1)),
            cell(pick(&|p| p.2))
        );
    }
    html.push_str("</table>\n");
    if let Some(f) = joint_figure(joints, tag, notes) {
        figure(
            html,
            &png_bytes(&f)?,
            "Joints: opening [mm] and normal stress (compression positive) [MPa] along the height",
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_brackets() {
        let p = [(0.0, 0.0), (1.0, 10.0), (2.0, 20.0)];
        assert_eq!(interpolate(&p, 0.5), Some(5.0));
        assert_eq!(interpolate(&p, 2.0), Some(20.0));
        assert_eq!(interpolate(&p, 3.0), None);
        let neg = [(0.0, 0.0), (-1.0, 10.0)];
        assert_eq!(interpolate(&neg, -0.25), Some(2.5));
    }

    #[test]
    fn escaping() {
        assert_eq!(esc("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;");
    }
}
