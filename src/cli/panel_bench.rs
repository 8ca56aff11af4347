//! Membrane panels in shear (and shear with biaxial stress) as a validation series: one
//! square panel of Q4 elements with two smeared bar layers along x and y, loaded on its
//! edges by v and the normal stresses σx = r_x v, σy = r_y v, by arc length to the peak
//! (docs/validation.md, "Membrane panels"). Used by `segfem bench --case panels` and by
//! tests/panels.rs.

use segfem::analysis::steps::{self, Observer, Snapshot};

/// One panel test: geometry, materials and the measured strength (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Test name.
    pub id: String,
    /// Test series (laboratory), for the per-laboratory statistics ("" if not known).
    pub lab: String,
    /// Thickness [m].
    pub thickness: f64,
    /// Side of the (square) panel [m].
    pub size: f64,
    /// Concrete cylinder strength, used as the mean strength f_cm [Pa].
    pub fcm: f64,
    /// Reinforcement ratios ρx, ρy [-].
    pub rho: [f64; 2],
    /// Yield stresses f_yx, f_yy [Pa].
    pub fy: [f64; 2],
    /// Steel moduli [Pa].
    pub es: [f64; 2],
    /// Normal stresses per unit shear σx/v, σy/v [-] (tension positive).
    pub normal: [f64; 2],
    /// Largest aggregate size [m] (aggregate-interlock shear retention).
    pub agg: f64,
    /// Measured shear strength v_u [Pa] (NaN if not known).
    pub v_test: f64,
}

/// What one run gives.
#[derive(Debug, Clone, PartialEq)]
pub struct PanelRun {
    /// Peak shear stress v [Pa].
    pub v_peak: f64,
    /// Steel strains over the yield strain at the peak, x and y layers [-].
    pub steel_at_peak: [f64; 2],
    /// Concrete points crushed by the end of the run.
    pub crushed: usize,
    /// Increments run.
    pub increments: usize,
    /// Failure mode at the peak: which layers had yielded, whether the concrete crushed.
    pub mode: String,
}

/// The model options of the series: a name and the concrete keys it adds.
pub fn options() -> Vec<(&'static str, &'static str)> {
    vec![
        ("fixed, seed β", ""),
        (
            "fixed, seed β, VC93",
            "compression_reduction = \"vecchio_collins_1993\"\n",
        ),
        ("fixed, aggregate β", "shear_retention = \"aggregate\"\n"),
        (
            "fixed, aggregate β, VC93",
            "shear_retention = \"aggregate\"\ncompression_reduction = \"vecchio_collins_1993\"\n",
        ),
        (
            "fixed, seed β, VC86 limit, VC93",
            "crack_shear_limit = \"vecchio_collins_1986\"\ncompression_reduction = \"vecchio_collins_1993\"\n",
        ),
        (
            "fixed, seed β, Rankine cut-off",
            "principal_stress_limit = \"tensile_strength\"\n",
        ),
        ("rotating", "crack_model = \"rotating\"\n"),
        (
            "rotating, VC93",
            "crack_model = \"rotating\"\ncompression_reduction = \"vecchio_collins_1993\"\n",
        ),
    ]
}

/// Input text of a panel on an `n` × `n` Q4 mesh with the extra concrete keys `keys`.
/// Loads: 1 MPa of shear per unit load factor on every edge, plus the normal stresses.
pub fn panel_toml(p: &Panel, keys: &str, n: usize) -> String {
    let l = p.size;
    let mut nodes = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            nodes.push(format!(
                "[{}, {}]",
                l * i as f64 / n as f64,
                l * j as f64 / n as f64
            ));
        }
    }
    let mut els = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i + 1;
            els.push(format!("[{}, {}, {}, {}]", a, a + 1, a + n + 2, a + n + 1));
        }
    }
    let q = 1e6 * p.thickness;
    let (qx, qy) = (q * p.normal[0], q * p.normal[1]);
    let agg = if keys.contains("aggregate") || keys.contains("crack_shear_limit") {
        format!("aggregate_size = {}\n", p.agg)
    } else {
        String::new()
    };
    format!(
        r#"
[[materials]]
name = "c"
kind = "concrete"
fcm = {fcm}
crack_integration = "implicit"
{keys}{agg}
[[materials]]
name = "sx"
kind = "rebar"
E = {esx}
fy = {fyx}

[[materials]]
name = "sy"
kind = "rebar"
E = {esy}
fy = {fyy}

[[regions]]
name = "p"
material = "c"
thickness = {t}

[mesh]
type = "explicit"
nodes = [{nodes}]
blocks = [{{ region = "p", element = "Q4", elements = [{els}] }}]

[[bar_layers]]
name = "x"
material = "sx"
region = "p"
direction = [1.0, 0.0]
ratio = {rx}

[[bar_layers]]
name = "y"
material = "sy"
region = "p"
direction = [0.0, 1.0]
ratio = {ry}

[[supports]]
name = "pin"
point = [0.0, 0.0]
ux = 0.0
uy = 0.0

[[supports]]
name = "roller"
point = [{l}, 0.0]
uy = 0.0

[[load_cases]]
name = "shear"
line_loads = [
  {{ line = [[0.0, {l}], [{l}, {l}]], q = [{q}, {qy}] }},
  {{ line = [[0.0, 0.0], [{l}, 0.0]], q = [{mq}, {mqy}] }},
  {{ line = [[{l}, 0.0], [{l}, {l}]], q = [{qx}, {q}] }},
  {{ line = [[0.0, 0.0], [0.0, {l}]], q = [{mqx}, {mq}] }},
]

[[steps]]
name = "shear"
kind = "arc_length"
loads = {{ shear = 1.0 }}
initial_increment = 0.1
max_growth = 4.0
stop_displacement = {{ point = [{l}, {l}], component = "x", value = {stop} }}
increments = 4000
"#,
        fcm = p.fcm,
        esx = p.es[0],
        esy = p.es[1],
        fyx = p.fy[0],
        fyy = p.fy[1],
        t = p.thickness,
        nodes = nodes.join(", "),
        els = els.join(", "),
        rx = p.rho[0],
        ry = p.rho[1],
        mq = -q,
        mqx = -qx,
        mqy = -qy,
        // A shear strain of 2 % ends the run (panel tests end well before).
        stop = 0.02 * l,
    )
}

/// Observer of a panel run: (v [Pa], steel strains [-], crushed points) per increment.
struct Trace {
    l: f64,
    n: usize,
    rows: Vec<(f64, [f64; 2], usize)>,
}

impl Observer for Trace {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let u = s.system.displacements();
        // Uniform strain: ε_x from the roller corner (L, 0), ε_y from the corner (0, L).
        let ex = u[2 * self.n] / self.l;
        let ey = u[2 * self.n * (self.n + 1) + 1] / self.l;
        let crushed = (s.system.point_states().iter())
            .filter(|p| p.is_crushed())
            .count();
        self.rows.push((1e6 * s.factors[0], [ex, ey], crushed));
        Ok(())
    }
}

/// Run a panel with the concrete keys `keys` on an `n` × `n` mesh.
pub fn run_panel(p: &Panel, keys: &str, n: usize) -> Result<PanelRun, String> {
    let text = panel_toml(p, keys, n);
    let built =
        segfem::input::parse(&text, &format!("panel {}", p.id)).map_err(|e| e.to_string())?;
    let mut tr = Trace {
        l: p.size,
        n,
        rows: Vec::new(),
    };
    // The run ends at the stop displacement or where no equilibrium is found (a mechanism
    // once the steel has yielded, or crushing): the peak is the result either way.
    match steps::run(&built.model, &mut tr) {
        Ok(_)
        | Err(steps::AnalysisError::NotConverged(_))
        | Err(steps::AnalysisError::Mechanism(_)) => {}
        Err(e) => return Err(e.to_string()),
    }
    let (ipk, &(v_peak, strains, _)) = tr
        .rows
        .iter()
        .enumerate()
        .max_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
        .ok_or_else(|| format!("panel {}: no increment converged", p.id))?;
    let steel: [f64; 2] = std::array::from_fn(|i| strains[i] * p.es[i] / p.fy[i]);
    let crushed = tr.rows.last().map_or(0, |r| r.2);
    let yielded: Vec<&str> = ["x", "y"]
        .iter()
        .zip(steel)
        .filter(|(_, s)| *s >= 0.999)
        .map(|(n, _)| *n)
        .collect();
    let after = &tr.rows[ipk..];
    let dropped = after.iter().any(|r| r.0 < 0.95 * v_peak);
    let crush_after = after.iter().any(|r| r.2 > 0);
    let mut mode = match yielded.len() {
        2 => "both steels yield".to_string(),
        1 => format!("{} steel yields", yielded[0]),
        _ => "no steel yields".to_string(),
    };
    if crush_after || (yielded.len() < 2 && dropped) {
        mode.push_str(if yielded.is_empty() {
            ": concrete crushing"
        } else {
            ", then concrete crushing"
        });
    }
    Ok(PanelRun {
        v_peak,
        steel_at_peak: steel,
        crushed,
        increments: tr.rows.len(),
        mode,
    })
}

/// Split one CSV line (fields may be quoted and contain commas).
pub(crate) fn csv_fields(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

/// Read the panel series from a CSV file with the columns (by header name) `id`,
/// `thickness_mm`, `size_mm` (`AxB`), `fc_MPa`, `rho_x`, `fy_x_MPa`, `Es_x_MPa`, `rho_y`,
/// `fy_y_MPa`, `Es_y_MPa`, `sx_over_v`, `sy_over_v`, `v_u_MPa`, `agg_mm`, and optionally
/// `series` (the laboratory). Rows without v_u are kept (v_test = NaN); a missing E_s is
/// 200 GPa, a missing aggregate size 16 mm.
pub fn read_panels(path: &std::path::Path) -> Result<Vec<Panel>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    let header = csv_fields(lines.next().ok_or(format!("{}: empty", path.display()))?);
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or(format!("{}: no column '{name}'", path.display()))
    };
    let cols: Vec<usize> = [
        "id",
        "thickness_mm",
        "size_mm",
        "fc_MPa",
        "rho_x",
        "fy_x_MPa",
        "Es_x_MPa",
        "rho_y",
        "fy_y_MPa",
        "Es_y_MPa",
        "sx_over_v",
        "sy_over_v",
        "v_u_MPa",
        "agg_mm",
    ]
    .iter()
    .map(|c| col(c))
    .collect::<Result<_, _>>()?;
    let lab_col = header.iter().position(|h| h == "series");
    let mut out = Vec::new();
    for (k, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let f = csv_fields(line);
        let row = k + 2;
        let get = |i: usize| f.get(cols[i]).map(|s| s.trim()).unwrap_or("");
        let num = |i: usize, default: Option<f64>| -> Result<f64, String> {
            let s = get(i);
            if s.is_empty() {
                return default.ok_or(format!(
                    "{}: row {row}: {} missing",
                    path.display(),
                    header[cols[i]]
                ));
            }
            s.parse::<f64>().map_err(|_| {
                format!(
                    "{}: row {row}: {} = '{s}' is not a number",
                    path.display(),
                    header[cols[i]]
                )
            })
        };
        let size = get(2)
            .split('x')
            .next()
            .and_then(|s| s.trim().parse::<f64>().ok())
            .ok_or(format!(
                "{}: row {row}: size_mm '{}' is not AxB",
                path.display(),
                get(2)
            ))?;
        out.push(Panel {
            id: get(0).to_string(),
            lab: lab_col
                .and_then(|i| f.get(i))
                .map(|s| s.trim().to_string())
                .unwrap_or_default(),
            thickness: 1e-3 * num(1, None)?,
            size: 1e-3 * size,
            fcm: 1e6 * num(3, None)?,
            rho: [num(4, None)?, num(7, None)?],
            fy: [1e6 * num(5, None)?, 1e6 * num(8, None)?],
            es: [1e6 * num(6, Some(200e3))?, 1e6 * num(9, Some(200e3))?],
            normal: [num(10, Some(0.0))?, num(11, Some(0.0))?],
            v_test: 1e6 * num(12, Some(f64::NAN))?,
            agg: 1e-3 * num(13, Some(16.0))?,
        });
    }
    Ok(out)
}

/// Mean and coefficient of variation (sample standard deviation / mean) [-].
pub fn mean_cov(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, var.sqrt() / m)
}

/// Run every panel with a measured strength under every option; returns a Markdown
/// report (one table of test/predicted ratios, mean and COV per option, then mean and COV
/// per laboratory) and the total time [s].
pub fn series(path: &std::path::Path) -> Result<(String, f64), String> {
    let start = std::time::Instant::now();
    let panels: Vec<Panel> = read_panels(path)?
        .into_iter()
        .filter(|p| p.v_test.is_finite())
        .collect();
    let opts = options();
    let mut ratios = vec![Vec::new(); opts.len()];
    // Per laboratory: (lab, ratios per option), in the order the labs first appear.
    let mut by_lab: Vec<(String, Vec<Vec<f64>>)> = Vec::new();
    let mut s = String::from("| panel | v_test [MPa] |");
    for (name, _) in &opts {
        s.push_str(&format!(" {name} |"));
    }
    s.push_str("\n|---|---|");
    s.push_str(&"---|".repeat(opts.len()));
    s.push('\n');
    let mut modes = String::new();
    for p in &panels {
        let lab = match by_lab.iter().position(|(l, _)| *l == p.lab) {
            Some(i) => i,
            None => {
                by_lab.push((p.lab.clone(), vec![Vec::new(); opts.len()]));
                by_lab.len() - 1
            }
        };
        s.push_str(&format!("| {} | {:.2} |", p.id, p.v_test / 1e6));
        for (k, (name, keys)) in opts.iter().enumerate() {
            match run_panel(p, keys, 1) {
                Ok(r) => {
                    let ratio = p.v_test / r.v_peak;
                    ratios[k].push(ratio);
                    by_lab[lab].1[k].push(ratio);
                    s.push_str(&format!(" {ratio:.2} |"));
                    modes.push_str(&format!(
                        "{} / {name}: v = {:.2} MPa, {} ({} increments)\n",
                        p.id,
                        r.v_peak / 1e6,
                        r.mode,
                        r.increments
                    ));
                }
                Err(e) => {
                    s.push_str(" failed |");
                    modes.push_str(&format!("{} / {name}: {e}\n", p.id));
                }
            }
        }
        s.push('\n');
    }
    s.push_str("| **mean** | |");
    for r in &ratios {
        s.push_str(&format!(" **{:.3}** |", mean_cov(r).0));
    }
    s.push_str("\n| **COV** | |");
    for r in &ratios {
        s.push_str(&format!(" **{:.1} %** |", 100.0 * mean_cov(r).1));
    }
    s.push_str("\n\nPer laboratory (mean / COV of test/predicted):\n\n| series | panels |");
    for (name, _) in &opts {
        s.push_str(&format!(" {name} |"));
    }
    s.push_str("\n|---|---|");
    s.push_str(&"---|".repeat(opts.len()));
    for (lab, r) in &by_lab {
        let label = if lab.is_empty() { "(not given)" } else { lab };
        s.push_str(&format!("\n| {label} | {} |", r[0].len()));
        for x in r {
            let (m, c) = mean_cov(x);
            s.push_str(&format!(" {m:.3} / {:.1} % |", 100.0 * c));
        }
    }
    s.push_str("\n\nPredicted peak and failure mode per run:\n\n```\n");
    s.push_str(&modes);
    s.push_str("```\n");
    Ok((s, start.elapsed().as_secs_f64()))
}
