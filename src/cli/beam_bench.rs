//! Shear-critical reinforced concrete beams as a validation series: a simply supported
//! beam under a mid-span point load, half modelled (symmetry at mid-span), banded Q8 mesh,
//! discrete longitudinal bars, smeared stirrups, the load through an elastic steel plate on
//! an elastic concrete pad and the support on an elastic bearing pad, pushed down to failure
//! (docs/validation.md, "Shear beams"). Used by `segfem bench --case beams` and by
//! tests/shear_beams.rs.

use super::panel_bench::csv_fields;
use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::results::ultimate::{Ultimate, UltimateWatch};

/// One layer of longitudinal bars (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct BarRow {
    /// Total bar area of the layer [m²].
    pub area: f64,
    /// Height of the layer above the bottom face [m].
    pub y: f64,
    /// Yield stress [Pa].
    pub fy: f64,
    /// Tensile strength [Pa].
    pub fu: f64,
    /// Strain at the tensile strength [-].
    pub esu: f64,
    /// Modulus [Pa].
    pub es: f64,
    /// Bar diameter [m] (from the area and the bar count of the data).
    pub diameter: f64,
}

/// One beam test: geometry, materials and the measured peak (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct Beam {
    /// Test name.
    pub id: String,
    /// Width [m].
    pub b: f64,
    /// Depth [m].
    pub h: f64,
    /// Span between the supports [m].
    pub span: f64,
    /// Overhang past each support [m].
    pub overhang: f64,
    /// Longitudinal bar layers (bottom and top).
    pub bars: Vec<BarRow>,
    /// Stirrups: area of all legs of one stirrup [m²], spacing [m], yield stress [Pa];
    /// `None` without stirrups.
    pub stirrups: Option<(f64, f64, f64)>,
    /// Stirrup leg diameter [m] (0 without stirrups).
    pub stirrup_diameter: f64,
    /// Concrete strength f_cm [Pa], modulus [Pa] and tensile strength [Pa].
    pub concrete: [f64; 3],
    /// Measured peak load P_u [N] and mid-span deflection there [m].
    pub test: (f64, f64),
    /// Failure mode reported by the test.
    pub test_mode: String,
}

/// The leading whole number of a text such as "2 M30" (1 if none).
fn leading_count(text: &str) -> f64 {
    let digits: String = text
        .trim()
        .chars()
        .take_while(|c| c.is_ascii_digit())
        .collect();
    digits
        .parse::<f64>()
        .ok()
        .filter(|n| *n > 0.0)
        .unwrap_or(1.0)
}

/// Mean spacing of the inclined web cracks [m] from the bar layout, by the CEB-FIP Model
/// Code 1990 (§7.4.3, stabilised cracking: s_rm = (2/3) φ/(3.6 ρ_ef)) in each reinforcement
/// direction and the Modified Compression Field Theory's combination for cracks at θ = 45°,
/// 1/s_θ = cos θ/s_x + sin θ/s_y (Vecchio & Collins 1986; Eurocode 2 eq. 7.15 has the same
/// form). Longitudinal: the bars below mid-depth, φ the mean diameter Σφ²/Σφ, ρ_ef over the
/// effective tension area b·min(2.5 (h − d), (h − x)/3, h/2) with x the cracked elastic
/// neutral axis; vertical: the stirrups' ratio A_v/(b s) and leg diameter (no stirrups:
/// s_y = ∞). Nothing of the test results enters.
pub fn crack_spacing(beam: &Beam) -> f64 {
    let tension: Vec<&BarRow> = beam.bars.iter().filter(|r| r.y < 0.5 * beam.h).collect();
    let area: f64 = tension.iter().map(|r| r.area).sum();
    if area <= 0.0 {
        return f64::INFINITY;
    }
    let d = beam.h - tension.iter().map(|r| r.area * r.y).sum::<f64>() / area;
    let n = tension.iter().map(|r| r.es * r.area).sum::<f64>() / area / beam.concrete[1];
    let rn = area / (beam.b * d) * n;
    let x = d * ((rn * rn + 2.0 * rn).sqrt() - rn);
    let h_ef = (2.5 * (beam.h - d))
        .min((beam.h - x) / 3.0)
        .min(0.5 * beam.h);
    let rho_ef = area / (beam.b * h_ef);
    // Mean diameter Σ n φ² / Σ n φ (n φ² ∝ the area).
    let phi = area / tension.iter().map(|r| r.area / r.diameter).sum::<f64>();
    let sx = 2.0 / 3.0 * phi / (3.6 * rho_ef);
    let inv_sy = match beam.stirrups {
        Some((av, s, _)) => 3.6 * av / (beam.b * s) * 1.5 / beam.stirrup_diameter,
        None => 0.0,
    };
    let c = std::f64::consts::FRAC_1_SQRT_2;
    1.0 / (c / sx + c * inv_sy)
}

/// Width of the loading plate and of the bearing pad [m] (the sources give none: 0.11 m,
/// two element columns of the coarse mesh, a fifth of the depth).
pub const PLATE: f64 = 0.111;

/// Discretisation of a beam with `rows` element rows through the depth: the element
/// length, the number of columns in the half span and in the overhang.
fn layout(beam: &Beam, rows: usize) -> (f64, usize, usize) {
    let target = beam.h / rows as f64;
    let n_half = ((0.5 * beam.span / target).round() as usize).max(1);
    let dx = 0.5 * beam.span / n_half as f64;
    let n_over = ((beam.overhang / dx).round() as usize).max(1);
    (dx, n_half, n_over)
}

/// The bench's plate increment [m]: 0.2 mm. Brittle shear peaks with IMPL-EX crack
/// integration are not converged at this size (docs/validation.md, "IMPL-EX increment
/// study"); `segfem bench --case beams --plate-increment-mm` sets another.
pub const PLATE_INCREMENT: f64 = 2e-4;

/// Input text of the half beam with `rows` element rows through the depth and the extra
/// concrete keys `keys`; the plate on the symmetry line is pushed down by `push` [m] in
/// increments of `increment` [m] (at least 10; `PLATE_INCREMENT` in the bench).
pub fn beam_toml(beam: &Beam, keys: &str, rows: usize, push: f64, increment: f64) -> String {
    // "{s_rm}" in the keys: the beam's crack spacing (`crack_spacing`).
    let keys = &keys.replace("{s_rm}", &format!("{:.4}", crack_spacing(beam)));
    let (dx, n_half, n_over) = layout(beam, rows);
    let len = dx * (n_half + n_over) as f64;
    let xs = dx * n_over as f64;
    let h = beam.h;
    let [fcm, ec, ft] = beam.concrete;
    // The pads are one coarse row deep and a plate wide, whatever the mesh: the same
    // boxes on both meshes (element centroids decide).
    let pad = h / 10.0;
    let mut bars = String::new();
    for (k, r) in beam.bars.iter().enumerate() {
        let et = (r.fu - r.fy) / (r.esu - r.fy / r.es);
        bars.push_str(&format!(
            "\n[[materials]]\nname = \"steel{k}\"\nkind = \"rebar\"\nE = {}\nfy = {}\nEt = {et}\n\n[[bars]]\nname = \"bars{k}\"\npath = [[0.0, {y}], [{len}, {y}]]\narea = {}\nmaterial = \"steel{k}\"\n",
            r.es, r.fy, r.area, y = r.y
        ));
    }
    if let Some((av, s, fy)) = beam.stirrups {
        bars.push_str(&format!(
            "\n[[materials]]\nname = \"stirrup_steel\"\nkind = \"rebar\"\nE = 200e9\nfy = {fy}\n\n[[bar_layers]]\nname = \"stirrups\"\nmaterial = \"stirrup_steel\"\nregion = \"beam\"\ndirection = [0.0, 1.0]\nratio = {ratio}\n",
            ratio = av / (beam.b * s)
        ));
    }
    format!(
        r#"title = "{id} (half beam, {rows} rows)"

[[materials]]
name = "concrete"
kind = "concrete"
fcm = {fcm}
E = {ec}
ftm = {ft}
tension_softening = "crack_band"
compression_softening = "crush_band"
{keys}
[[materials]]
name = "pad"
kind = "elastic"
E = {ec}
nu = 0.2

[[materials]]
name = "plate_steel"
kind = "elastic"
E = 200e9
nu = 0.3

[[materials]]
name = "void"
kind = "elastic"
E = 1e6
nu = 0.0
{bars}
[[regions]]
name = "beam"
material = "concrete"
thickness = {b}

[[regions]]
name = "top_band"
material = "void"
thickness = {b}

[[regions]]
name = "plate"
material = "plate_steel"
thickness = {b}
boxes = [[[{xp}, {h}], [{len}, {htop}]]]

[[regions]]
name = "under_plate"
material = "pad"
thickness = {b}
boxes = [[[{xp}, {hpad}], [{len}, {h}]]]

[[regions]]
name = "bearing"
material = "pad"
thickness = {b}
boxes = [[[{xb0}, 0.0], [{xb1}, {pad}]]]

[mesh]
type = "banded"
length = {len}
nx = {nx}
element = "Q8"
bands = [{{ region = "beam", depth = {h}, rows = {rows} }}, {{ region = "top_band", depth = 0.03, rows = 1 }}]

[[supports]]
name = "support"
point = [{xs}, 0.0]
uy = 0.0

[[supports]]
name = "symmetry"
line = [[{len}, 0.0], [{len}, {htop}]]
ux = 0.0

[[steps]]
name = "load"
kind = "displacement"
control = {{ point = [{len}, {htop}], component = "y", value = {push} }}
increments = {inc}

[solver]
force_tolerance = 1e-4
max_iterations = 40
max_cuts = 8
"#,
        id = beam.id,
        b = beam.b,
        xp = len - 0.5 * PLATE,
        htop = h + 0.03,
        hpad = h - pad,
        xb0 = xs - 0.5 * PLATE,
        xb1 = xs + 0.5 * PLATE,
        nx = n_half + n_over,
        inc = ((push.abs() / increment).ceil() as usize).max(10),
    )
}

/// What one beam run gives.
#[derive(Debug, Clone, PartialEq)]
pub struct BeamRun {
    /// Peak load P (both halves) [N].
    pub p_peak: f64,
    /// Mid-span deflection at the peak (bottom face) [m].
    pub deflection: f64,
    /// Load at the end of the run over the peak [-] (the drop after the peak).
    pub end_ratio: f64,
    /// The run's ultimate verdict (mode, events), as `segfem run` writes it.
    pub ultimate: Option<Ultimate>,
    /// Increments run.
    pub increments: usize,
    /// Wall time [s].
    pub seconds: f64,
    /// Stress locking of the cracked concrete at the peak increment.
    pub locking: Locking,
    /// The error controls' counts (None when the run ended without equilibrium: the
    /// driver returns only the error then).
    pub controls: Option<ControlCounts>,
}

/// What the error controls of a beam run did (summary.json `timings`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlCounts {
    /// `implex_tolerance`: increments cut, kept above the tolerance, largest kept error [-].
    pub implex: (usize, usize, f64),
    /// `implex_force_tolerance`: the same for the global measure [-].
    pub implex_force: (usize, usize, f64),
    /// `increment_tolerance`: pairs rejected.
    pub pairs_rejected: usize,
}

/// Stress locking measure of the cracked concrete points of one committed state: how far
/// the largest principal stress of points that already have a crack exceeds f_tm, and at
/// what angle to their crack axes (docs/theory-concrete.md §5.5).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Locking {
    /// Cracked (not crushed) concrete points [-].
    pub cracked: usize,
    /// Largest principal stress of a cracked point over f_tm [-].
    pub max_ratio: f64,
    /// Angle between that point's largest principal stress direction and the nearest crack
    /// axis (normal of crack 1 or its orthogonal) [deg].
    pub angle_at_max: f64,
    /// Largest σ1/f_tm [-] of the cracked points whose principal direction is inclined by
    /// 15° or more to their crack axes (along the axes σ1 is a crack-law stress, which
    /// IMPL-EX may let overshoot: not locking).
    pub max_ratio_inclined: f64,
    /// Cracked points with σ1 > 1.1 f_tm [-].
    pub over: usize,
    /// Mean angle of the principal direction to the nearest crack axis over the points
    /// with σ1 > 1.1 f_tm [deg].
    pub mean_angle_over: f64,
}

impl Locking {
    /// The measure over the points `pts` for tensile strength `ftm` [Pa].
    pub fn of(pts: &[segfem::materials::point::PointState], ftm: f64) -> Locking {
        let mut l = Locking::default();
        let mut sum = 0.0;
        for c in pts.iter().filter_map(|p| p.concrete()) {
            if c.n_cracks() == 0 || c.is_crushed() {
                continue;
            }
            l.cracked += 1;
            let (s1, phi) = segfem::materials::concrete::principal_max(&c.stress());
            // Deviation from the crack axes, folded into [0, 45°].
            let q = std::f64::consts::FRAC_PI_2;
            let d = (phi - c.crack_angle()).rem_euclid(q);
            let dev = d.min(q - d).to_degrees();
            let r = s1 / ftm;
            if r > l.max_ratio {
                l.max_ratio = r;
                l.angle_at_max = dev;
            }
            if dev >= 15.0 {
                l.max_ratio_inclined = l.max_ratio_inclined.max(r);
            }
            if r > 1.1 {
                l.over += 1;
                sum += dev;
            }
        }
        if l.over > 0 {
            l.mean_angle_over = sum / l.over as f64;
        }
        l
    }
}

struct Watch {
    mid: usize,
    ftm: f64,
    rows: Vec<(f64, f64, Locking)>,
    ultimate: UltimateWatch,
}

impl Observer for Watch {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        // Half model: the control force carries half the load.
        let p = -2.0 * s.control_force.unwrap_or(0.0);
        let lock = Locking::of(s.system.point_states(), self.ftm);
        self.rows
            .push((p, -s.system.displacements()[2 * self.mid + 1], lock));
        self.ultimate.increment(s);
        Ok(())
    }
}

/// Run a beam with the concrete keys `keys` and `rows` element rows through the depth,
/// pushed down to `push` [m] (negative) or to failure in plate increments of `increment`
/// [m] (`PLATE_INCREMENT` in the bench).
pub fn run_beam(
    beam: &Beam,
    keys: &str,
    rows: usize,
    push: f64,
    increment: f64,
) -> Result<BeamRun, String> {
    run_beam_solver(beam, keys, rows, push, increment, "")
}

/// As [`run_beam`], with the lines `solver` added to the model's `[solver]` table (say
/// `increment_tolerance = 0.05\n`: the increment objectivity measurements,
/// docs/validation.md).
pub fn run_beam_solver(
    beam: &Beam,
    keys: &str,
    rows: usize,
    push: f64,
    increment: f64,
    solver: &str,
) -> Result<BeamRun, String> {
    let t0 = std::time::Instant::now();
    // The `[solver]` table is the model text's last.
    let text = beam_toml(beam, keys, rows, push, increment) + solver;
    let built =
        segfem::input::parse(&text, &format!("beam {}", beam.id)).map_err(|e| e.to_string())?;
    let model = &built.model;
    let (dx, n_half, n_over) = layout(beam, rows);
    let len = dx * (n_half + n_over) as f64;
    let mid = model
        .nodes
        .iter()
        .position(|p| (p[0] - len).abs() < 1e-9 && p[1].abs() < 1e-9)
        .ok_or("no node at mid-span")?;
    let mut w = Watch {
        mid,
        ftm: beam.concrete[2],
        rows: Vec::new(),
        ultimate: UltimateWatch::new(),
    };
    // A brittle shear failure ends the run where no equilibrium is found: the peak is the
    // result either way.
    let (converged, timings) = match steps::run(model, &mut w) {
        Ok(t) => (
            true,
            Some(ControlCounts {
                implex: (t.implex_cuts, t.implex_over_tolerance, t.implex_max_error),
                implex_force: (
                    t.implex_force_cuts,
                    t.implex_force_over_tolerance,
                    t.implex_force_max_error,
                ),
                pairs_rejected: t.increments_rejected,
            }),
        ),
        Err(steps::AnalysisError::NotConverged(_)) | Err(steps::AnalysisError::Mechanism(_)) => {
            (false, None)
        }
        Err(e) => return Err(e.to_string()),
    };
    let &(p_peak, deflection, locking) = w
        .rows
        .iter()
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .ok_or_else(|| format!("beam {}: no increment converged", beam.id))?;
    let end = w.rows.last().map_or(0.0, |r| r.0);
    Ok(BeamRun {
        p_peak,
        deflection,
        end_ratio: end / p_peak,
        ultimate: w.ultimate.finish(model, converged),
        increments: w.rows.len(),
        seconds: t0.elapsed().as_secs_f64(),
        locking,
        controls: timings,
    })
}

/// The model options of the beam series: a name and the concrete keys. All with IMPL-EX
/// crack integration: with implicit crack laws the rotating model stalls in the first
/// increments of diagonal cracking (OA1, 10 rows: Newton gives up at 150 kN).
pub fn options() -> Vec<(&'static str, &'static str)> {
    vec![
        (
            "fixed, seed β",
            "crack_integration = \"implex\"\n",
        ),
        (
            "fixed, aggregate β, VC93",
            "crack_integration = \"implex\"\nshear_retention = \"aggregate\"\ncompression_reduction = \"vecchio_collins_1993\"\n",
        ),
        (
            "fixed, seed β, VC86 limit, VC93",
            "crack_integration = \"implex\"\ncrack_shear_limit = \"vecchio_collins_1986\"\ncompression_reduction = \"vecchio_collins_1993\"\n",
        ),
        (
            "fixed, seed β, Rankine cut-off",
            "crack_integration = \"implex\"\nprincipal_stress_limit = \"tensile_strength\"\n",
        ),
        (
            "fixed, seed β, softening cut-off",
            "crack_integration = \"implex\"\nprincipal_stress_limit = \"softening\"\n",
        ),
        (
            "rotating, VC93",
            "crack_integration = \"implex\"\ncrack_model = \"rotating\"\ncompression_reduction = \"vecchio_collins_1993\"\n",
        ),
        (
            "rotating, VC93 over s_rm",
            "crack_integration = \"implex\"\ncrack_model = \"rotating\"\ncompression_reduction = \"vecchio_collins_1993\"\ncompression_reduction_spacing = {s_rm}\n",
        ),
    ]
}

/// Read the beams of a CSV file (columns by header name, see validation/beams/sources.md);
/// rows without bar data are skipped (data not found), as are rows whose `use` column is
/// not `yes`.
pub fn read_beams(path: &std::path::Path) -> Result<Vec<Beam>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = text.lines();
    let header = csv_fields(lines.next().ok_or(format!("{}: empty", path.display()))?);
    let mut out = Vec::new();
    for (k, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let f = csv_fields(line);
        let row = k + 2;
        let get = |name: &str| -> Result<&str, String> {
            let i = header
                .iter()
                .position(|h| h == name)
                .ok_or(format!("{}: no column '{name}'", path.display()))?;
            Ok(f.get(i).map(|s| s.trim()).unwrap_or(""))
        };
        if get("use")? != "yes" {
            continue;
        }
        let num = |name: &str| -> Result<f64, String> {
            let s = get(name)?;
            s.parse::<f64>().map_err(|_| {
                format!(
                    "{}: row {row}: {name} = '{s}' is not a number",
                    path.display()
                )
            })
        };
        let opt = |name: &str| -> Result<Option<f64>, String> {
            if get(name)?.is_empty() {
                Ok(None)
            } else {
                num(name).map(Some)
            }
        };
        let mut bars = Vec::new();
        for (pre, from_top) in [("bot1", false), ("bot2", false), ("top", true)] {
            let Some(a) = opt(&format!("{pre}_As_mm2"))?.filter(|a| *a > 0.0) else {
                continue;
            };
            let y = 1e-3 * num(&format!("{pre}_y_mm"))?;
            let n = leading_count(get(&format!("{pre}_bars"))?);
            bars.push(BarRow {
                diameter: (4e-6 * a / (n * std::f64::consts::PI)).sqrt(),
                area: 1e-6 * a,
                y: if from_top { 1e-3 * num("h_mm")? - y } else { y },
                fy: 1e6 * num(&format!("{pre}_fy_MPa"))?,
                fu: 1e6 * num(&format!("{pre}_fu_MPa"))?,
                esu: num(&format!("{pre}_esu"))?,
                es: 1e6 * opt(&format!("{pre}_Es_MPa"))?.unwrap_or(200e3),
            });
        }
        let stirrups = match opt("stirrup_Av_mm2")?.filter(|a| *a > 0.0) {
            Some(av) => Some((
                1e-6 * av,
                1e-3 * num("stirrup_s_mm")?,
                1e6 * num("stirrup_fy_MPa")?,
            )),
            None => None,
        };
        // Legs of one stirrup: "... 2 legs" in the data (2 if not stated).
        let text = get("stirrups")?;
        let legs = text
            .find("legs")
            .map(|i| leading_count(text[..i].rsplit([' ', ',']).nth(1).unwrap_or("")))
            .unwrap_or(2.0);
        let stirrup_diameter = stirrups.map_or(0.0, |(av, _, _)| {
            (4.0 * av / (legs * std::f64::consts::PI)).sqrt()
        });
        let span = 1e-3 * num("span_mm")?;
        out.push(Beam {
            id: get("id")?.to_string(),
            b: 1e-3 * num("b_mm")?,
            h: 1e-3 * num("h_mm")?,
            span,
            overhang: 0.5 * (1e-3 * num("L_total_mm")? - span),
            bars,
            stirrups,
            stirrup_diameter,
            concrete: [
                1e6 * num("fc_MPa")?,
                1e6 * num("Ec_MPa")?,
                1e6 * num("ft_MPa")?,
            ],
            test: (1e3 * num("P_u_kN")?, 1e-3 * num("defl_at_peak_mm")?),
            test_mode: get("failure_mode")?.to_string(),
        });
    }
    Ok(out)
}

/// What `series` runs: the plate increment, the meshes and the model options.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesSettings {
    /// Plate increment [m] (`PLATE_INCREMENT` by default).
    pub plate_increment: f64,
    /// Element rows through the depth of each run (10 and 20 by default).
    pub rows: Vec<usize>,
    /// Names of the options of `options()` to run (all if empty).
    pub options: Vec<String>,
}

impl Default for SeriesSettings {
    fn default() -> Self {
        SeriesSettings {
            plate_increment: PLATE_INCREMENT,
            rows: vec![10, 20],
            options: Vec::new(),
        }
    }
}

/// Run every beam under every option (or those of `set`) on each mesh of `set` (10 and 20
/// rows by default); returns a Markdown report (test/predicted peak per run, the mesh
/// difference of the first and the last mesh, the verdicts) and the total time [s].
pub fn series(path: &std::path::Path, set: &SeriesSettings) -> Result<(String, f64), String> {
    let start = std::time::Instant::now();
    let beams = read_beams(path)?;
    let all = options();
    if let Some(o) = set.options.iter().find(|o| !all.iter().any(|a| a.0 == *o)) {
        let names: Vec<&str> = all.iter().map(|a| a.0).collect();
        return Err(format!(
            "no beam option {o:?} (options: {})",
            names.join("; ")
        ));
    }
    if set.rows.is_empty() || set.rows.contains(&0) {
        return Err("rows: at least one mesh of one or more rows".into());
    }
    if !set.plate_increment.is_finite() || set.plate_increment <= 0.0 {
        return Err(format!(
            "plate increment {} m: must be positive",
            set.plate_increment
        ));
    }
    let chosen: Vec<(&str, &str)> = all
        .into_iter()
        .filter(|o| set.options.is_empty() || set.options.iter().any(|n| n == o.0))
        .collect();
    let rows = &set.rows;
    let mut s = String::from("| beam | P_test [kN] | model |");
    for r in rows {
        s.push_str(&format!(" P {r} rows [kN] | test/pred {r} |"));
    }
    let two = rows.len() >= 2;
    if two {
        s.push_str(&format!(" {} vs {} rows |", rows[rows.len() - 1], rows[0]));
    }
    s.push_str("\n|---|---|---|");
    s.push_str(&"---|---|".repeat(rows.len()));
    if two {
        s.push_str("---|");
    }
    s.push('\n');
    let mut notes = String::new();
    for b in &beams {
        // Pushed to twice the measured peak deflection, at least 20 mm.
        let push = -(2.0 * b.test.1).max(0.02);
        for &(name, keys) in &chosen {
            let runs: Vec<Result<BeamRun, String>> = rows
                .iter()
                .map(|&r| {
                    let out = run_beam(b, keys, r, push, set.plate_increment);
                    // Progress on stderr: a series takes minutes.
                    match &out {
                        Ok(x) => eprintln!(
                            "{} / {name} / {r} rows: {:.1} kN, {} increments, {:.1} s",
                            b.id,
                            x.p_peak / 1e3,
                            x.increments,
                            x.seconds
                        ),
                        Err(e) => eprintln!("{} / {name} / {r} rows: {e}", b.id),
                    }
                    out
                })
                .collect();
            let cell = |r: &Result<BeamRun, String>| match r {
                Ok(r) => format!("{:.0} | {:.2}", r.p_peak / 1e3, b.test.0 / r.p_peak),
                Err(_) => "failed | –".into(),
            };
            s.push_str(&format!("| {} | {:.0} | {name} |", b.id, b.test.0 / 1e3));
            for r in &runs {
                s.push_str(&format!(" {} |", cell(r)));
            }
            if two {
                let diff = match (&runs[0], &runs[runs.len() - 1]) {
                    (Ok(a), Ok(c)) => format!("{:+.1} %", 100.0 * (c.p_peak / a.p_peak - 1.0)),
                    _ => "–".into(),
                };
                s.push_str(&format!(" {diff} |"));
            }
            s.push('\n');
            for (rows, r) in rows.iter().zip(&runs) {
                match r {
                    Ok(r) => notes.push_str(&format!(
                        "{} / {name} / {rows} rows: P = {:.1} kN at {:.1} mm (test {:.0} kN at {:.1} mm, {}); end of run {:.0} % of the peak; {}; {} increments, {:.1} s\n",
                        b.id,
                        r.p_peak / 1e3,
                        r.deflection * 1e3,
                        b.test.0 / 1e3,
                        b.test.1 * 1e3,
                        b.test_mode,
                        100.0 * r.end_ratio,
                        r.ultimate.as_ref().map_or("no verdict".into(), |u| format!("{} [{}]", u.mode, u.events.iter().map(|e| format!("{} at {:.0} kN", e.0, 2.0 * e.1 / 1e3)).collect::<Vec<_>>().join(", "))),
                        r.increments,
                        r.seconds
                    )),
                    Err(e) => notes.push_str(&format!("{} / {name} / {rows} rows: {e}\n", b.id)),
                }
            }
        }
    }
    s.push_str(&format!(
        "\nRuns (peak, deflection, drop after the peak, verdict), plate increments of {} mm:\n\n```\n",
        set.plate_increment * 1e3
    ));
    s.push_str(&notes);
    s.push_str("```\n");
    Ok((s, start.elapsed().as_secs_f64()))
}
