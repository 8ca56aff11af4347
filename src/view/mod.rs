//! An engineer's view of a finished run: figures (`segfem plot`) and a self-contained HTML
//! report (`segfem report`) read back from the files a run writes (`history.csv`,
//! `summary.json`, `results.pvd` and its `.vtu` files).
//!
//! Figures whose data a run does not write (crack patterns, joint diagrams) are skipped
//! with a one-line note; they are drawn as soon as the `.vtu` files carry the cell arrays
//! `crack_angle` [rad] and `n_cracks` [-], or line cells with an `opening` [m] array (and
//! optionally `normal_stress` [Pa] and `joint` [-]).

pub mod data;
pub mod envelopes;
pub mod erection;
pub mod figures;
pub mod glyphs;
pub mod report;
pub mod units;

use data::{Grid, Output, Table};
use figures::{
    auto_scale, save, ContourFigure, CrackFigure, CurveFigure, DeformedFigure, FieldValues,
    JointFigure, JointProfile, MeshFigure, Series,
};
use std::path::{Path, PathBuf};
pub use units::UnitOptions;

/// Why a view command failed.
#[derive(Debug, thiserror::Error)]
pub enum ViewError {
    /// Bad arguments or unreadable/missing input files (exit status 2).
    #[error("{0}")]
    Usage(String),
    /// Figures or the report could not be written (exit status 1).
    #[error("{0}")]
    Io(String),
}

impl ViewError {
    /// Process exit status.
    pub fn exit_code(&self) -> u8 {
        match self {
            ViewError::Usage(_) => 2,
            ViewError::Io(_) => 1,
        }
    }
}

/// A scalar stress field for colour maps. Stresses are shown in MPa.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// σx [MPa].
    Sx,
    /// σy [MPa].
    Sy,
    /// τxy [MPa].
    Txy,
    /// Major principal stress σ1 [MPa].
    S1,
    /// Minor principal stress σ2 [MPa].
    S2,
}

impl std::str::FromStr for Field {
    type Err = ViewError;
    fn from_str(s: &str) -> Result<Self, ViewError> {
        Ok(match s.trim().to_ascii_lowercase().as_str() {
            "sx" => Field::Sx,
            "sy" => Field::Sy,
            "txy" => Field::Txy,
            "s1" => Field::S1,
            "s2" => Field::S2,
            o => {
                return Err(ViewError::Usage(format!(
                    "--field: unknown field '{o}' (sx, sy, txy, s1, s2)"
                )))
            }
        })
    }
}

impl Field {
    /// Short name (file names).
    pub fn name(self) -> &'static str {
        match self {
            Field::Sx => "sx",
            Field::Sy => "sy",
            Field::Txy => "txy",
            Field::S1 => "s1",
            Field::S2 => "s2",
        }
    }

    /// Label with unit.
    pub fn label(self) -> &'static str {
        match self {
            Field::Sx => "σx [MPa]",
            Field::Sy => "σy [MPa]",
            Field::Txy => "τxy [MPa]",
            Field::S1 => "σ1 [MPa]",
            Field::S2 => "σ2 [MPa]",
        }
    }

    fn of(self, s: [f64; 3]) -> f64 {
        let c = 0.5 * (s[0] + s[1]);
        let r = (0.5 * (s[0] - s[1])).hypot(s[2]);
        match self {
            Field::Sx => s[0],
            Field::Sy => s[1],
            Field::Txy => s[2],
            Field::S1 => c + r,
            Field::S2 => c - r,
        }
    }
}

/// Options of `segfem plot`.
#[derive(Debug, Clone, Default)]
pub struct PlotOptions {
    /// Run directory.
    pub dir: PathBuf,
    /// x column of the history curve (monitor name); default: the first monitor in m.
    pub x: Option<String>,
    /// y columns; default: the first load-factor monitor (or the last `factor:` column).
    pub y: Vec<String>,
    /// Reference CSV (first two columns: x, y) drawn as markers.
    pub reference: Option<PathBuf>,
    /// Further run directories drawn on the same chart.
    pub runs: Vec<PathBuf>,
    /// Output number (1-based, order of `results.pvd`); default: the last.
    pub step: Option<usize>,
    /// Field for the colour map; default σx.
    pub field: Option<Field>,
    /// Colour map from cell (element-average) values instead of smoothed nodal values.
    pub cells: bool,
    /// Magnification of the deformed shape; default: the largest displacement drawn as
    /// 5 % of the model size.
    pub scale: Option<f64>,
    /// Output directory; default `<dir>/figures`.
    pub out: Option<PathBuf>,
    /// Display units and signs of the curves (default mm, kN, MPa, deflection down).
    pub units: UnitOptions,
}

/// What `segfem plot` produced.
#[derive(Debug, Clone, Default)]
pub struct PlotOutcome {
    /// Files written (PNG and SVG of each figure).
    pub files: Vec<PathBuf>,
    /// One-line notes on skipped figures.
    pub notes: Vec<String>,
    /// The history curves drawn (values as read from the CSV files).
    pub curves: Option<CurveFigure>,
    /// Magnification used for the deformed shape.
    pub scale: Option<f64>,
    /// The `.vtu` file the field figures were drawn from.
    pub vtu: Option<PathBuf>,
}

fn run_name(dir: &Path) -> String {
    dir.file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| dir.display().to_string())
}

/// Read `<dir>/history.csv`.
pub fn read_history(dir: &Path) -> Result<Table, ViewError> {
    if !dir.is_dir() {
        return Err(ViewError::Usage(format!(
            "{}: not a directory (give the output directory of `segfem run`)",
            dir.display()
        )));
    }
    Table::read(&dir.join("history.csv"))
}

/// Default (x, y) columns of the load–displacement curve of a history.
pub fn default_columns(h: &Table) -> Result<(String, Vec<String>), ViewError> {
    // The main displacement: the first displacement monitor (summary.json kinds; vertical
    // first), else the first column in m.
    let dir = h.path.parent().unwrap_or(Path::new("."));
    let kinds = units::kinds(dir);
    let is_disp = |c: &data::Column, vertical: bool| {
        kinds.iter().any(|(n, k)| {
            *n == c.name
                && k.kind == "displacement"
                && (!vertical || k.component.as_deref() == Some("y"))
        })
    };
    let x = h
        .monitors()
        .find(|c| is_disp(c, true))
        .or_else(|| h.monitors().find(|c| is_disp(c, false)))
        .or_else(|| h.monitors().find(|c| c.unit == "m"))
        .or_else(|| h.monitors().next())
        .map(|c| c.name.clone())
        .unwrap_or_else(|| "increment".into());
    // The load, never a strain: the force of a displacement control where one acts, else
    // the load factor that varies most, else a reaction.
    let range = |c: &data::Column| {
        let f = c.values.iter().filter(|v| v.is_finite());
        f.clone().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
            - f.fold(f64::INFINITY, |a, &b| a.min(b))
    };
    let control = h
        .columns
        .iter()
        .find(|c| c.name == "control_force" && c.values.iter().any(|v| v.is_finite()));
    let factor = h
        .factors()
        .filter(|c| range(c) > 0.0)
        .max_by(|a, b| range(a).total_cmp(&range(b)));
    // A load_factor monitor shows the same numbers under the user's name: prefer it.
    let factor = factor.map(|f| {
        h.monitors()
            .find(|m| m.unit == "-" && m.values == f.values)
            .unwrap_or(f)
    });
    let y = control
        .or(factor)
        .or_else(|| h.monitors().find(|c| c.unit == "N"))
        .or_else(|| h.factors().last())
        .or_else(|| h.monitors().find(|c| c.name != x))
        .map(|c| c.name.clone())
        .ok_or_else(|| ViewError::Usage(format!("{}: no columns to plot", h.path.display())))?;
    Ok((x, vec![y]))
}

/// The history curve figure: `y` columns against `x` for the run `dir` and the `runs`,
/// with reference markers, in display units and signs (`units`, [`units::shown`]). Columns
/// of different units go to separate panels, one y axis each. Reference points are read
/// in the history's SI units, or as they are when their header gives the display unit.
pub fn curve_figure(
    dir: &Path,
    x: Option<&str>,
    y: &[String],
    runs: &[PathBuf],
    reference: Option<&Path>,
    opts: UnitOptions,
) -> Result<CurveFigure, ViewError> {
    let h = read_history(dir)?;
    let (dx, dy) = default_columns(&h)?;
    let x = x.map(str::to_string).unwrap_or(dx);
    let y: Vec<String> = if y.is_empty() { dy } else { y.to_vec() };
    let xc = h.column(&x)?;
    let ycols = y
        .iter()
        .map(|k| h.column(k))
        .collect::<Result<Vec<_>, _>>()?;
    let kinds = units::kinds(dir);
    let kind_of = |name: &str| kinds.iter().find(|(n, _)| n == name).map(|(_, k)| k);
    let factor_units = units::FactorUnits::read(dir);
    let show = |c: &data::Column| {
        let s = units::shown(&c.name, &c.unit, kind_of(&c.name), &c.values, opts);
        factor_units.apply(&c.name, s, opts)
    };
    let xs_shown = show(xc);
    let ys_shown: Vec<units::Shown> = ycols.iter().map(|c| show(c)).collect();
    let panel_of =
        units::group_by_unit(&ys_shown.iter().map(|s| s.unit.clone()).collect::<Vec<_>>());
    let n_panels = panel_of.iter().copied().max().map_or(1, |m| m + 1);
    let y_labels: Vec<String> = (0..n_panels)
        .map(|p| {
            let members: Vec<usize> = (0..ycols.len()).filter(|&i| panel_of[i] == p).collect();
            if members.len() == 1 {
                ys_shown[members[0]].label.clone()
            } else {
                let unit = &ys_shown[members[0]].unit;
                let names = members
                    .iter()
                    .map(|&i| {
                        ys_shown[i]
                            .label
                            .rsplit_once(" [")
                            .map_or(ys_shown[i].label.as_str(), |l| l.0)
                    })
                    .collect::<Vec<_>>()
                    .join(", ");
                if unit.is_empty() {
                    names
                } else {
                    format!("{names} [{unit}]")
                }
            }
        })
        .collect();
    let several_runs = !runs.is_empty();
    let mut series = Vec::new();
    let mut tables = vec![(dir.to_path_buf(), h.clone())];
    for r in runs {
        tables.push((r.clone(), read_history(r)?));
    }
    for (d, t) in &tables {
        let xs = t.column(&x)?;
        for (k, yc) in ycols.iter().enumerate() {
            let ys = t.column(&yc.name)?;
            let label = match (several_runs, ycols.len() > 1) {
                (true, true) => format!("{}: {}", run_name(d), yc.name),
                (true, false) => run_name(d),
                _ => yc.name.clone(),
            };
            series.push(Series {
                label,
                points: xs
                    .values
                    .iter()
                    .map(|v| v * xs_shown.factor)
                    .zip(ys.values.iter().map(|v| v * ys_shown[k].factor))
                    .collect(),
                panel: panel_of[k],
            });
        }
    }
    let reference = match reference {
        Some(p) => {
            let t = Table::read(p)?;
            if t.columns.len() < 2 {
                return Err(ViewError::Usage(format!(
                    "{}: a reference file needs two columns (x, y)",
                    p.display()
                )));
            }
            let (a, b) = (&t.columns[0], &t.columns[1]);
            // A header in the display unit is taken as drawn; otherwise as the history's.
            let fa = if a.unit == xs_shown.unit {
                1.0
            } else {
                xs_shown.factor
            };
            let fb = if b.unit == ys_shown[0].unit {
                1.0
            } else {
                ys_shown[0].factor
            };
            Some(Series {
                label: format!("reference: {}", run_name(p)),
                points: a
                    .values
                    .iter()
                    .map(|v| v * fa)
                    .zip(b.values.iter().map(|v| v * fb))
                    .collect(),
                panel: 0,
            })
        }
        None => None,
    };
    Ok(CurveFigure {
        title: format!(
            "{} against {}",
            ycols
                .iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
            xc.name
        ),
        x_label: xs_shown.label,
        y_label: y_labels[0].clone(),
        y_labels,
        series,
        reference,
    })
}

/// The output chosen by `step` (1-based; default the last) from `results.pvd`.
pub fn pick_output(dir: &Path, step: Option<usize>) -> Result<(usize, Output), ViewError> {
    let outs = data::read_pvd(dir)?;
    if outs.is_empty() {
        return Err(ViewError::Usage(format!(
            "{}: results.pvd lists no outputs",
            dir.display()
        )));
    }
    let n = step.unwrap_or(outs.len());
    if n == 0 || n > outs.len() {
        return Err(ViewError::Usage(format!(
            "--step: {n} is out of range (this run has outputs 1 to {})",
            outs.len()
        )));
    }
    Ok((n, outs[n - 1].clone()))
}

/// Nodal displacements (ux, uy) [m] of a grid (zero when absent).
pub fn displacements(g: &Grid) -> Vec<[f64; 2]> {
    match g.point_array("displacement").filter(|a| a.components >= 2) {
        Some(a) => (0..g.points.len())
            .map(|i| [a.get(i, 0), a.get(i, 1)])
            .collect(),
        None => vec![[0.0; 2]; g.points.len()],
    }
}

/// Values of `field` in MPa, nodal (`principal_stress` for σ1/σ2 when present, else from
/// `stress`) or per cell (from the cell `stress`).
pub fn field_values(g: &Grid, field: Field, cells: bool) -> Result<FieldValues, ViewError> {
    let missing = |what: &str| {
        ViewError::Usage(format!(
            "{}: no {what} 'stress' array for the colour map",
            g.path.display()
        ))
    };
    let from = |a: &data::Array, n: usize| -> Vec<f64> {
        (0..n)
            .map(|i| field.of([a.get(i, 0), a.get(i, 1), a.get(i, 2)]) / 1e6)
            .collect()
    };
    if cells {
        let a = g
            .cell_array("stress")
            .filter(|a| a.components >= 3)
            .ok_or_else(|| missing("cell"))?;
        return Ok(FieldValues::Cell(from(a, g.cells.len())));
    }
    if let (Some(p), Field::S1 | Field::S2) = (
        g.point_array("principal_stress")
            .filter(|a| a.components >= 2),
        field,
    ) {
        let c = if field == Field::S1 { 0 } else { 1 };
        return Ok(FieldValues::Nodal(
            (0..g.points.len()).map(|i| p.get(i, c) / 1e6).collect(),
        ));
    }
    let a = g
        .point_array("stress")
        .filter(|a| a.components >= 3)
        .ok_or_else(|| missing("point"))?;
    Ok(FieldValues::Nodal(from(a, g.points.len())))
}

/// Crack data per cell (angle of the crack line [rad], count): from the `crack_normal` vectors segfem
/// writes, else from `crack_angle` with `n_cracks`/`cracks` (angles larger than 2π in
/// magnitude are taken as degrees).
pub fn cracks(g: &Grid) -> Option<Vec<(f64, usize)>> {
    if let (Some(v), Some(n)) = (g.cell_array("crack_normal"), g.cell_array("cracks")) {
        return Some(
            (0..g.cells.len())
                // The crack runs perpendicular to its normal.
                .map(|i| {
                    let normal = v.get(i, 1).atan2(v.get(i, 0));
                    (
                        normal + std::f64::consts::FRAC_PI_2,
                        n.get(i, 0).max(0.0) as usize,
                    )
                })
                .collect(),
        );
    }
    let a = g.cell_array("crack_angle")?;
    let n = g
        .cell_array("n_cracks")
        .or_else(|| g.cell_array("cracks"))?;
    let degrees = a
        .values
        .iter()
        .any(|v| v.abs() > std::f64::consts::TAU + 1e-9);
    Some(
        (0..g.cells.len())
            .map(|i| {
                let t = a.get(i, 0);
                (
                    if degrees { t.to_radians() } else { t },
                    n.get(i, 0).max(0.0) as usize,
                )
            })
            .collect(),
    )
}

/// Joint profiles from line cells carrying `opening` [m] (cell or point data), with
/// `normal_stress` [Pa] where present. Joints are told apart by a `joint` cell array, or
/// else by the x of the cell's mid-point.
pub fn joint_profiles(g: &Grid) -> Vec<JointProfile> {
    let lines: Vec<usize> = (0..g.cells.len()).filter(|&i| g.is_line(i)).collect();
    let cell_open = g.cell_array("opening");
    let point_open = g.point_array("opening");
    if lines.is_empty() || (cell_open.is_none() && point_open.is_none()) {
        return Vec::new();
    }
    let cell_sn = g.cell_array("normal_stress");
    let point_sn = g.point_array("normal_stress");
    let id = g.cell_array("joint");
    let (lo, hi) = g.bounds();
    let tol = 1e-6 * (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-12);
    // (key, name, points (y, opening, normal stress))
    type Group = (f64, String, Vec<(f64, f64, f64)>);
    let mut groups: Vec<Group> = Vec::new();
    for &i in &lines {
        let c = &g.cells[i];
        let mid = |k: usize| c.iter().map(|&n| g.points[n][k]).sum::<f64>() / c.len() as f64;
        let (xm, ym) = (mid(0), mid(1));
        let mut samples: Vec<(f64, f64, f64)> = Vec::new();
        if let Some(o) = cell_open {
            let sn = cell_sn.map_or(f64::NAN, |s| s.get(i, 0) / 1e6);
            samples.push((ym, o.get(i, 0) * 1e3, sn));
        } else if let Some(o) = point_open {
            for &n in c {
                let sn = point_sn.map_or(f64::NAN, |s| s.get(n, 0) / 1e6);
                samples.push((g.points[n][1], o.get(n, 0) * 1e3, sn));
            }
        }
        let (key, name) = match id {
            Some(a) => {
                let k = a.get(i, 0);
                (k, format!("joint {}", k as i64))
            }
            None => (xm, format!("joint at x = {xm:.3} m")),
        };
        match groups.iter_mut().find(|gr| (gr.0 - key).abs() <= tol) {
            Some(gr) => gr.2.extend(samples),
            None => groups.push((key, name, samples)),
        }
    }
    groups.sort_by(|a, b| a.0.total_cmp(&b.0));
    groups
        .into_iter()
        .map(|(_, name, mut points)| {
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            points.dedup_by(|a, b| (a.0 - b.0).abs() <= tol && a.1 == b.1);
            JointProfile { name, points }
        })
        .collect()
}

/// Joint profiles from the joints' integration points (part 4 of results.pvd: vertices with
/// `joint`, `opening` [m] and `normal_stress` [Pa] arrays): every point, so the diagrams
/// reach the true extremes. Joints named from `names` (summary.json `joints`), else
/// `joint k`.
pub fn joint_point_profiles(path: &Path, names: &[String]) -> Result<Vec<JointProfile>, ViewError> {
    let g = Grid::read(path)?;
    let (Some(id), Some(open)) = (g.point_array("joint"), g.point_array("opening")) else {
        return Ok(Vec::new());
    };
    let sn = g.point_array("normal_stress");
    let mut out: Vec<(i64, JointProfile)> = Vec::new();
    for (i, p) in g.points.iter().enumerate() {
        let k = id.get(i, 0) as i64;
        let point = (
            p[1],
            open.get(i, 0) * 1e3,
            sn.map_or(f64::NAN, |a| a.get(i, 0) / 1e6),
        );
        match out.iter_mut().find(|o| o.0 == k) {
            Some(o) => o.1.points.push(point),
            None => {
                let name = names
                    .get((k - 1).max(0) as usize)
                    .map_or_else(|| format!("joint {k}"), |n| format!("joint {n}"));
                let x = p[0];
                out.push((
                    k,
                    JointProfile {
                        name: format!("{name} (x = {x:.3} m)"),
                        points: vec![point],
                    },
                ))
            }
        }
    }
    out.sort_by_key(|o| o.0);
    Ok(out
        .into_iter()
        .map(|(_, mut j)| {
            j.points.sort_by(|a, b| a.0.total_cmp(&b.0));
            j
        })
        .collect())
}

/// The joint profiles of an output: from the joints' integration points when the run wrote
/// them, else from the line cells of its grid `g`.
pub fn output_joint_profiles(
    output: &Output,
    g: &Grid,
    dir: &Path,
) -> Result<Vec<JointProfile>, ViewError> {
    match &output.joint_points {
        Some(p) => joint_point_profiles(p, &units::joint_names(dir)),
        None => Ok(joint_profiles(g)),
    }
}

/// Most joints drawn in one joint figure.
pub const MAX_JOINTS: usize = 8;

/// Further history curves for `segfem plot --also COL[,COL]`: each column against the x
/// column of `opts`, in its own figure `curves_<COL>` (other units than the main curve's,
/// e.g. the tendon stress beside the deflection), with the `opts.runs`; no reference
/// markers. Returns the files written.
pub fn extra_curves(opts: &PlotOptions, cols: &[String]) -> Result<Vec<PathBuf>, ViewError> {
    let out_dir = opts.out.clone().unwrap_or_else(|| opts.dir.join("figures"));
    std::fs::create_dir_all(&out_dir)
        .map_err(|e| ViewError::Io(format!("{}: {e}", out_dir.display())))?;
    let mut files = Vec::new();
    for c in cols {
        let fig = curve_figure(
            &opts.dir,
            opts.x.as_deref(),
            std::slice::from_ref(c),
            &opts.runs,
            None,
            opts.units,
        )?;
        // File names from the column name only (a header such as "σ [Pa]" is not a name).
        let stem: String = c
            .split(' ')
            .next()
            .unwrap_or("")
            .chars()
            .map(|ch| {
                if ch.is_ascii_alphanumeric() || ch == '_' {
                    ch
                } else {
                    '_'
                }
            })
            .collect();
        files.extend(save(&fig, &out_dir, &format!("curves_{stem}"))?);
    }
    Ok(files)
}

/// `segfem plot`: write the figures of a run into the output directory.
pub fn plot(opts: &PlotOptions) -> Result<PlotOutcome, ViewError> {
    if let Some(s) = opts.scale {
        if !(s.is_finite() && s > 0.0) {
            return Err(ViewError::Usage(format!(
                "--scale: {s} is not a positive number"
            )));
        }
    }
    let curves = curve_figure(
        &opts.dir,
        opts.x.as_deref(),
        &opts.y,
        &opts.runs,
        opts.reference.as_deref(),
        opts.units,
    )?;
    let out_dir = opts.out.clone().unwrap_or_else(|| opts.dir.join("figures"));
    std::fs::create_dir_all(&out_dir)
        .map_err(|e| ViewError::Io(format!("{}: {e}", out_dir.display())))?;
    let mut outcome = PlotOutcome::default();
    outcome.files.extend(save(&curves, &out_dir, "curves")?);
    outcome.curves = Some(curves);
    outcome
        .files
        .extend(envelopes::envelope_figures(&opts.dir, &out_dir)?);
    outcome
        .files
        .extend(erection::erection_figure(&opts.dir, &out_dir)?);
    let (n, output) = match pick_output(&opts.dir, opts.step) {
        Ok(o) => o,
        Err(e) if opts.step.is_none() => {
            outcome
                .notes
                .push(format!("mesh and field figures: skipped ({e})"));
            return Ok(outcome);
        }
        Err(e) => return Err(e),
    };
    let g = output.grid()?;
    let file = run_name(&output.file);
    let tag = format!("output {n}, {file}");
    outcome.vtu = Some(output.file.clone());
    outcome.files.extend(save(
        &MeshFigure {
            grid: &g,
            regions: units::region_names(&opts.dir),
            tendons: output.tendon_spans()?,
            title: format!("Mesh: {} points, {} cells", g.points.len(), g.cells.len()),
        },
        &out_dir,
        "mesh",
    )?);
    let disp = displacements(&g);
    let scale = opts.scale.unwrap_or_else(|| auto_scale(&g, &disp));
    outcome.scale = Some(scale);
    outcome.files.extend(save(
        &DeformedFigure {
            grid: &g,
            disp,
            scale,
            title: format!("Deformed shape ×{} ({tag})", fmt_scale(scale)),
        },
        &out_dir,
        "deformed",
    )?);
    let field = opts.field.unwrap_or(Field::Sx);
    let values = field_values(&g, field, opts.cells)?;
    let kind = if opts.cells { "cell averages" } else { "nodal" };
    outcome.files.extend(save(
        &ContourFigure {
            grid: &g,
            values,
            label: field.label().into(),
            title: format!("{} ({kind}, {tag})", field.label()),
        },
        &out_dir,
        &format!("field_{}", field.name()),
    )?);
    let joints = output_joint_profiles(&output, &g, &opts.dir)?;
    let has_joints = expects_joints(&g, &opts.dir);
    extra_figures(&g, joints, has_joints, &tag, &out_dir, &mut outcome)?;
    Ok(outcome)
}

/// Whether a run's model has joints: summary.json names some, or the grid has line cells.
/// A model without joints gets no "joint diagrams: skipped" note (it would be noise).
pub fn expects_joints(g: &Grid, dir: &Path) -> bool {
    !units::joint_names(dir).is_empty() || (0..g.cells.len()).any(|i| g.is_line(i))
}

/// Crack pattern and joint diagrams, or notes when their data is absent (the joint note
/// only when `has_joints`).
fn extra_figures(
    g: &Grid,
    joints: Vec<JointProfile>,
    has_joints: bool,
    tag: &str,
    out_dir: &Path,
    outcome: &mut PlotOutcome,
) -> Result<(), ViewError> {
    match crack_figure(g, tag) {
        Some(f) => outcome.files.extend(save(&f, out_dir, "cracks")?),
        None => outcome.notes.push(CRACK_NOTE.into()),
    }
    match joint_figure(joints, tag, &mut outcome.notes) {
        Some(f) => outcome.files.extend(save(&f, out_dir, "joints")?),
        None if has_joints => outcome.notes.push(JOINT_NOTE.into()),
        None => {}
    }
    Ok(())
}

/// Note for a skipped crack pattern.
pub const CRACK_NOTE: &str =
    "crack pattern: skipped (no cracked cells, or no crack_angle/n_cracks cell arrays)";
/// Note for skipped joint diagrams.
pub const JOINT_NOTE: &str =
    "joint diagrams: skipped (the results carry no joint line cells with an opening array)";

/// The crack pattern figure, when the grid has crack data.
pub fn crack_figure<'g>(g: &'g Grid, tag: &str) -> Option<CrackFigure<'g>> {
    let cracks = cracks(g)?;
    let n = cracks.iter().filter(|c| c.1 > 0).count();
    if n == 0 {
        // Uncracked (or elastic) results: nothing to draw.
        return None;
    }
    Some(CrackFigure {
        grid: g,
        cracks,
        title: format!("Crack pattern: {n} cracked cells ({tag})"),
    })
}

/// The joint figure, when the grid has joint data. Up to [`MAX_JOINTS`] joints are all
/// drawn; of more, the [`MAX_JOINTS`] most stressed by [`joint_rank`] (so the joint with the
/// largest contact stress and the one with the largest opening are always drawn), in their
/// order along the model, with a note and a title line saying how many are hidden.
pub fn joint_figure(
    joints: Vec<JointProfile>,
    tag: &str,
    notes: &mut Vec<String>,
) -> Option<JointFigure> {
    if joints.is_empty() {
        return None;
    }
    let total = joints.len();
    let mut title = format!("Joints: opening and normal stress over the height ({tag})");
    let joints = if total > MAX_JOINTS {
        let hidden = total - MAX_JOINTS;
        let note = format!(
            "the {MAX_JOINTS} most stressed of {total} joints (largest contact stress or opening); {hidden} hidden"
        );
        notes.push(format!("joint diagrams: {note}"));
        title.push_str(&format!("\n{note}"));
        let mut keep = joint_rank(&joints);
        keep.truncate(MAX_JOINTS);
        keep.sort_unstable();
        let mut joints: Vec<Option<JointProfile>> = joints.into_iter().map(Some).collect();
        keep.into_iter().filter_map(|i| joints[i].take()).collect()
    } else {
        joints
    };
    Some(JointFigure { joints, title })
}

/// Indices of `joints`, most stressed first. A joint's score is the larger of its largest
/// contact (compressive normal) stress over the largest of all joints and its largest
/// opening over the largest of all joints: both ranks count alike, so the joint with the
/// largest contact stress and the one with the largest opening both score 1 and lead.
/// Ties (e.g. unloaded joints) keep the order along the model.
pub fn joint_rank(joints: &[JointProfile]) -> Vec<usize> {
    let peak = |j: &JointProfile, f: fn(&(f64, f64, f64)) -> f64| {
        j.points
            .iter()
            .map(f)
            .filter(|v| v.is_finite())
            .fold(0.0_f64, f64::max)
    };
    let open: Vec<f64> = joints.iter().map(|j| peak(j, |p| p.1)).collect();
    let stress: Vec<f64> = joints.iter().map(|j| peak(j, |p| p.2)).collect();
    let max_open = open.iter().copied().fold(0.0, f64::max);
    let max_stress = stress.iter().copied().fold(0.0, f64::max);
    let ratio = |v: f64, m: f64| if m > 0.0 { v / m } else { 0.0 };
    let score: Vec<f64> = (0..joints.len())
        .map(|i| ratio(open[i], max_open).max(ratio(stress[i], max_stress)))
        .collect();
    let mut idx: Vec<usize> = (0..joints.len()).collect();
    // Stable sort: equal scores keep the order along the model.
    idx.sort_by(|&a, &b| score[b].total_cmp(&score[a]));
    idx
}

/// A magnification written with 3 significant digits.
pub fn fmt_scale(s: f64) -> String {
    if s >= 100.0 {
        format!("{s:.0}")
    } else {
        let d = (2 - s.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{s:.d$}")
    }
}
