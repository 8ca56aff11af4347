//! Influence lines by superposition on the tangent stiffness at the end of a step
//! (`[[influence]]`, docs/theory-traffic.md): the tangent is assembled and factorised once
//! at the committed state, each path node's unit downward load is one more solve with that
//! factorisation, and each monitor's change is read from a trial assembly at the committed
//! displacements plus the solution. Nothing is committed: the state after is the state
//! before.

use super::staged::StateBlock;
use super::system::System;
use crate::fem::dofs::CONSTRAINED;
use crate::linalg::solver::SparseCholesky;
use crate::materials::point::TimeContext;
use crate::model::{Influence, Model, MonitorKind, Placement};
use crate::traffic::{envelope, unfavourable_stretch};

/// The influence lines of one `[[influence]]` table.
#[derive(Debug, Clone, PartialEq)]
pub struct InfluenceLines {
    /// Index of the table in `Model::influence`.
    pub table: usize,
    /// Positions along the path [m] (distance from its start).
    pub s: Vec<f64>,
    /// Name and unit of each line: the table's monitors, then (with `joints`) each joint's
    /// contact stress at its top and bottom points, "<joint> top"/"<joint> bottom" [Pa,
    /// compression positive].
    pub names: Vec<(String, String)>,
    /// Monitor values at the step's end (the state the lines are taken at), per monitor of
    /// the table [monitor unit].
    pub state: Vec<f64>,
    /// Change of each monitor per newton of downward load at each position [unit/N]:
    /// `values[monitor][position]`.
    pub values: Vec<Vec<f64>>,
}

/// The influence lines of table `table` at the committed state of `sys`, whose external
/// forces are `f_ext` [N] and clock `clock` [d]. The tangent is factorised with `solver`
/// (whose factorisation is then this one: the caller refactorises before the next Newton
/// iteration).
pub fn compute(
    sys: &mut System,
    solver: &mut SparseCholesky,
    f_ext: &[f64],
    clock: f64,
    table: usize,
) -> Result<InfluenceLines, String> {
    let lines = lines_of(sys, solver, f_ext, clock, table);
    // Back to the committed state (trial states of the last assembly thrown away), also
    // when the lines could not be taken.
    sys.families.revert();
    lines
}

/// The work of [`compute`], leaving trial states behind.
fn lines_of(
    sys: &mut System,
    solver: &mut SparseCholesky,
    f_ext: &[f64],
    clock: f64,
    table: usize,
) -> Result<InfluenceLines, String> {
    let model = sys.model;
    let inf: &Influence = &model.influence[table];
    // An instantaneous perturbation: no creep, shrinkage or relaxation over it.
    sys.begin_time_increment(TimeContext::at(clock));
    let u0 = sys.disp.committed.clone();
    let base = sys
        .assemble(&u0, true)
        .map_err(|(e, err)| format!("element {} failed at the committed state: {err:?}", e + 1))?;
    let k = base.k_values.as_ref().expect("tangent requested");
    // The solver's count of negative pivots belongs to the path the steps follow.
    let pivots = solver.negative_pivots;
    let factored = if sys.linear {
        solver.factorize(&sys.asm.pattern, k).map(|_| 0)
    } else {
        solver.factorize_indefinite(&sys.asm.pattern, k)
    };
    solver.negative_pivots = pivots;
    let negative =
        factored.map_err(|e| format!("the tangent stiffness cannot be factorised: {e}"))?;
    if negative > 0 {
        return Err(format!(
            "the tangent stiffness has {negative} negative pivot(s): the structure is past a limit point, where an influence line means nothing"
        ));
    }
    let mut fibres = if inf.joints {
        joint_fibres(sys)
    } else {
        Vec::new()
    };
    if inf.fibres {
        fibres.extend(section_fibres(sys));
    }
    let state = values(sys, inf, &fibres, &u0, &base.f_int, f_ext);
    let mut lines = vec![Vec::with_capacity(inf.path.len()); state.len()];
    let mut f = vec![0.0; model.n_dofs()];
    let mut u = u0.clone();
    for &(node, _) in &inf.path {
        // A unit load down (−y) on the node.
        let d = 2 * node + 1;
        f[d] = -1.0;
        let mut du = sys.to_free(&f);
        solver.solve_in_place(&mut du);
        u.copy_from_slice(&u0);
        for (dof, &q) in sys.dofs.eq.iter().enumerate() {
            if q != CONSTRAINED {
                u[dof] += du[q];
            }
        }
        let a = sys.assemble(&u, false).map_err(|(e, err)| {
            format!(
                "element {} failed under the unit load at node {}: {err:?}",
                e + 1,
                node + 1
            )
        })?;
        let mut fe = f_ext.to_vec();
        fe[d] -= 1.0;
        let v = values(sys, inf, &fibres, &u, &a.f_int, &fe);
        for ((line, v), s) in lines.iter_mut().zip(v).zip(&state) {
            line.push(v - s);
        }
        f[d] = 0.0;
    }
    let mut names: Vec<(String, String)> = inf
        .monitors
        .iter()
        .map(|&m| {
            (
                model.monitors[m].name.clone(),
                model.monitors[m].unit().to_string(),
            )
        })
        .collect();
    names.extend(fibres.iter().map(|f| (f.0.clone(), "Pa".to_string())));
    Ok(InfluenceLines {
        table,
        s: inf.path.iter().map(|p| p.1).collect(),
        names,
        state,
        values: lines,
    })
}

/// The top and bottom integration points of every joint: (name, interface element, point).
fn joint_fibres(sys: &System) -> Vec<(String, usize, usize)> {
    let mut out = Vec::new();
    for j in &sys.model.joints {
        let points = j.interfaces.iter().flat_map(|&i| {
            sys.interfaces[i]
                .points()
                .iter()
                .enumerate()
                .map(move |(k, _)| (i, k))
        });
        let y = |&(i, k): &(usize, usize)| sys.families.joints.points.committed[i][k].position[1];
        let top = points.clone().max_by(|a, b| y(a).total_cmp(&y(b)));
        let bottom = points.min_by(|a, b| y(a).total_cmp(&y(b)));
        if let (Some(t), Some(b)) = (top, bottom) {
            out.push((format!("{} top", j.name), t.0, t.1));
            out.push((format!("{} bottom", j.name), b.0, b.1));
        }
    }
    out
}

/// The top and bottom Gauss points of every column of Gauss points (points sharing their x
/// within 1e-9 × the model's extent; columns of one point left out): ("sx top x=…", MAX,
/// Gauss point), in the order of x.
fn section_fibres(sys: &System) -> Vec<(String, usize, usize)> {
    use crate::elements::continuum::rule_points;
    use crate::fem::shape::map_point;
    /// A column: its x, the top and bottom (y, Gauss point), and its number of points.
    type Column = (f64, (f64, usize), (f64, usize), usize);
    let model = sys.model;
    let extent = model
        .nodes
        .iter()
        .fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()))
        .max(1.0);
    let tol = 1e-9 * extent;
    let mut columns: std::collections::BTreeMap<i64, Column> = Default::default();
    for (e, el) in model.elements.iter().enumerate() {
        let coords = model.element_coords(el);
        for (j, &(xi, eta, _)) in rule_points(el.kind, el.integration).iter().enumerate() {
            let p = map_point(&el.kind.eval(xi, eta), &coords);
            let g = sys.gp_offset[e] + j;
            let c = columns.entry((p[0] / tol).round() as i64).or_insert((
                p[0],
                (p[1], g),
                (p[1], g),
                0,
            ));
            if p[1] > c.1 .0 {
                c.1 = (p[1], g);
            }
            if p[1] < c.2 .0 {
                c.2 = (p[1], g);
            }
            c.3 += 1;
        }
    }
    let mut out = Vec::new();
    for (x, top, bottom, n) in columns.into_values() {
        if n > 1 {
            out.push((format!("sx top x={x:.3}"), usize::MAX, top.1));
            out.push((format!("sx bottom x={x:.3}"), usize::MAX, bottom.1));
        }
    }
    out
}

/// The table's monitors, then the joint fibres' contact stresses, from the trial side of
/// the last assembly at displacements `u` (internal forces `f_int`, external `f_ext`)
/// [monitor units; Pa]. Only the kinds linear in the displacements
/// (`input::build::influence::linear`) reach here.
fn values(
    sys: &System,
    inf: &Influence,
    fibres: &[(String, usize, usize)],
    u: &[f64],
    f_int: &[f64],
    f_ext: &[f64],
) -> Vec<f64> {
    let model = sys.model;
    let fam = &sys.families;
    // Joint points (interface element, point) or, with `usize::MAX` for the element,
    // continuum Gauss points (σx).
    let joints = fibres.iter().map(|&(_, i, k)| {
        if i == usize::MAX {
            fam.continuum.gauss.trial[k].stress[0]
        } else {
            fam.joints.points.trial[i][k].normal_stress
        }
    });
    inf.monitors
        .iter()
        .map(|&m| match &model.monitors[m].kind {
            MonitorKind::Displacement { node, dir, .. } => u[2 * node + dir.index()],
            MonitorKind::Reaction { support, dir } => model.supports[*support]
                .dofs
                .iter()
                .filter(|(_, d, _)| d == dir)
                .map(|(n, d, _)| {
                    let k = 2 * n + d.index();
                    f_int[k] - f_ext[k]
                })
                .sum(),
            MonitorKind::StressAtPoint {
                component,
                gauss_point,
            } => component.of(fam.continuum.gauss.trial[*gauss_point].stress),
            MonitorKind::TendonStress { tendon, span } => fam.tendons.states.trial[*tendon]
                .as_ref()
                .map_or(0.0, |st| st.stresses()[span.unwrap_or(0)]),
            MonitorKind::TendonForce { tendon, span } => fam.tendons.states.trial[*tendon]
                .as_ref()
                .map_or(0.0, |st| st.forces()[span.unwrap_or(0)]),
            MonitorKind::BarStress { bar, point } | MonitorKind::BarForce { bar, point } => {
                let area = match model.monitors[m].kind {
                    MonitorKind::BarForce { .. } => model.bars[*bar].area,
                    _ => 1.0,
                };
                sys.bar_gps
                    .iter()
                    .position(|&(b, p)| b == *bar && Some(p) == *point)
                    .map_or(0.0, |i| area * fam.bars.out.trial[i].stress)
            }
            // Refused by the input (not linear in the displacements).
            _ => f64::NAN,
        })
        .chain(joints)
        .collect()
}

/// The load vector [N] (all dofs) of placement `p` of the table of `lines`: the governing
/// vehicle's axles at their positions and the lane load on the stretches where the line
/// has the extreme's sign, as downward nodal forces on the path nodes, shared between the
/// two nodes around each load by the lever rule — the distribution the influence line
/// interpolates, so that on the tangent the case gives the envelope's value.
pub fn placed_load(model: &Model, lines: &InfluenceLines, p: &Placement) -> Vec<f64> {
    let inf = &model.influence[lines.table];
    let (s, eta) = (&lines.s, &lines.values[p.monitor]);
    let t = &inf.traffic[p.traffic];
    let (min, max) = envelope(t, s, eta);
    let e = if p.max { max } else { min };
    let mut f = vec![0.0; model.n_dofs()];
    let node = |i: usize| 2 * inf.path[i].0 + 1;
    for (&x, &load) in e.axles.iter().zip(&e.axle_loads) {
        // Axles off the path carry nothing onto the structure.
        if x < s[0] || x > s[s.len() - 1] {
            continue;
        }
        let i = s.partition_point(|&v| v <= x).clamp(1, s.len() - 1);
        let h = s[i] - s[i - 1];
        let r = if h > 0.0 { (x - s[i - 1]) / h } else { 0.0 };
        f[node(i - 1)] -= load * (1.0 - r);
        f[node(i)] -= load * r;
    }
    for i in 1..s.len() {
        let h = s[i] - s[i - 1];
        let Some((a, b)) = unfavourable_stretch(eta[i - 1], eta[i], h, p.max) else {
            continue;
        };
        // A uniform load q over (a, b) of the piece: lever-rule shares q ∫ (1 − u/h) du and
        // q ∫ u/h du.
        let right = t.lane_load * (b * b - a * a) / (2.0 * h);
        f[node(i - 1)] -= t.lane_load * (b - a) - right;
        f[node(i)] -= right;
    }
    f
}
