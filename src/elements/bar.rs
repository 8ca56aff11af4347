//! Embedded reinforcement in isoparametric quadrilaterals: the response of a bar point
//! (Elwi & Hrudey 1989; docs/theory-bars.md). Perfect bond is assumed: the bar strain is the
//! host's strain projected on the bar direction, ε_b = tᵀ ε t = T(φ) B a_e with
//! T = [cos²φ, sin²φ, sinφ cosφ]. The bar points themselves come from cutting a bar path
//! through the mesh ([`crate::mesh::embed`]).
//!
//! Units: lengths in metres, areas in m², stresses and moduli in Pa (any consistent set works;
//! nothing here depends on the unit system).
//!
//! Conventions: element displacement vectors are interleaved `[u_0, v_0, u_1, v_1, …]` in the
//! host's VTK node order; element matrices are dense, row-major, `2n × 2n`.

use crate::fem::shape::{cartesian_derivatives, jacobian, MAX_NODES};
use crate::materials::steel::{update_uniaxial, SteelParams, SteelState};
use crate::model::ElementKind;

/// A bar point (plain model data, defined in [`crate::model`]).
pub use crate::model::element_data::BarPoint;

// ------------------------------------------------------------------------------------------
// Element-level functions
// ------------------------------------------------------------------------------------------

/// Strain along a unit direction t = (cos φ, sin φ) of an engineering strain (εx, εy, γxy):
/// ε_t = tᵀ ε t = εx cos²φ + εy sin²φ + γxy sinφ cosφ [-].
pub fn strain_along(dir: [f64; 2], eps: [f64; 3]) -> f64 {
    let (c, s) = (dir[0], dir[1]);
    c * c * eps[0] + s * s * eps[1] + c * s * eps[2]
}

/// The row vector g = T(φ) B of a bar point (length 2n, interleaved dofs): ε_b = g · a_e.
/// Entries: g_{2i} = cosφ (t·∇N_i), g_{2i+1} = sinφ (t·∇N_i) [1/m].
pub fn bar_strain_vector(kind: ElementKind, coords: &[[f64; 2]], p: &BarPoint) -> Vec<f64> {
    bar_strain_row(kind, coords, p)[..2 * kind.n_nodes()].to_vec()
}

/// As [`bar_strain_vector`] without allocating (the assembly loop calls it for every bar
/// point): the first 2n entries are g, the rest zero.
pub fn bar_strain_row(
    kind: ElementKind,
    coords: &[[f64; 2]],
    p: &BarPoint,
) -> [f64; 2 * MAX_NODES] {
    let n = kind.n_nodes();
    assert_eq!(coords.len(), n, "coords must have {n} entries for {kind:?}");
    let s = kind.eval(p.xi, p.eta);
    let (_, _, inv) = jacobian(&s, coords);
    let d: [[f64; 2]; MAX_NODES] = cartesian_derivatives(&s, &inv);
    let mut g = [0.0; 2 * MAX_NODES];
    for i in 0..n {
        let dn = p.dir[0] * d[i][0] + p.dir[1] * d[i][1];
        g[2 * i] = p.dir[0] * dn;
        g[2 * i + 1] = p.dir[1] * dn;
    }
    g
}

/// Green strain along the bar for the total Lagrangian kinematics (docs/theory.md,
/// "Geometric nonlinearity"): with t the bar's unit direction on the undeformed geometry,
/// d_a = t·∇N_a [1/m] and F t = t + Σ_a d_a u_a the stretched tangent,
/// E_b = tᵀ E t = t·(H t) + ½ |H t|² [-], δE_b = g·δu_e with g_a = d_a (F t) [1/m] and
/// δ²E_b = Σ_ab d_a d_b δu_a·δu_b. Returns (E_b, g, d); g has 2n entries, d has n.
/// Force f = g σ A w and tangent K = g E_t A w gᵀ + σ A w (d dᵀ ⊗ I₂) (the second term is
/// the bar's geometric stiffness). Reduces to [`bar_strain_vector`] for u = 0.
pub fn bar_green_strain(
    kind: ElementKind,
    coords: &[[f64; 2]],
    p: &BarPoint,
    u_e: &[f64],
) -> (f64, [f64; 2 * MAX_NODES], [f64; MAX_NODES]) {
    let n = kind.n_nodes();
    let s = kind.eval(p.xi, p.eta);
    let (_, _, inv) = jacobian(&s, coords);
    let dn = cartesian_derivatives(&s, &inv);
    let mut d = [0.0; MAX_NODES];
    let mut ht = [0.0; 2];
    for a in 0..n {
        d[a] = p.dir[0] * dn[a][0] + p.dir[1] * dn[a][1];
        ht[0] += d[a] * u_e[2 * a];
        ht[1] += d[a] * u_e[2 * a + 1];
    }
    // t·(Ht) + ½|Ht|² rather than ½(|Ft|² − 1): no cancellation at small strains.
    let e = p.dir[0] * ht[0] + p.dir[1] * ht[1] + 0.5 * (ht[0] * ht[0] + ht[1] * ht[1]);
    let ft = [p.dir[0] + ht[0], p.dir[1] + ht[1]];
    let mut g = [0.0; 2 * MAX_NODES];
    for a in 0..n {
        g[2 * a] = d[a] * ft[0];
        g[2 * a + 1] = d[a] * ft[1];
    }
    (e, g, d)
}

/// Bar strain ε_b = T(φ) B a_e [-] at point `p` from the host's nodal displacements `u_e` [m]
/// (interleaved, 2·n_nodes entries).
pub fn bar_strain(kind: ElementKind, coords: &[[f64; 2]], p: &BarPoint, u_e: &[f64]) -> f64 {
    let g = bar_strain_vector(kind, coords, p);
    assert_eq!(u_e.len(), g.len(), "u_e must have {} entries", g.len());
    g.iter().zip(u_e).map(|(a, b)| a * b).sum()
}

/// Add one bar point's contribution to the host's internal force vector `f` [N] (2n entries)
/// and tangent stiffness `k` [N/m] (2n × 2n, row-major):
/// f += gᵀ σ_b A_b |dx/dr| w, k += gᵀ E_t A_b g |dx/dr| w, with g = T B,
/// `area` A_b [m²], `stress` σ_b [Pa], `tangent` E_t = dσ_b/dε_b [Pa].
#[allow(clippy::too_many_arguments)]
pub fn add_bar_point(
    kind: ElementKind,
    coords: &[[f64; 2]],
    p: &BarPoint,
    area: f64,
    stress: f64,
    tangent: f64,
    f: &mut [f64],
    k: &mut [f64],
) {
    let g = bar_strain_vector(kind, coords, p);
    let m = g.len();
    assert_eq!(f.len(), m, "f must have {m} entries");
    assert_eq!(k.len(), m * m, "k must have {} entries", m * m);
    let fs = stress * area * p.weight_length;
    let ks = tangent * area * p.weight_length;
    for i in 0..m {
        f[i] += g[i] * fs;
        let gi = g[i] * ks;
        if gi != 0.0 {
            for j in 0..m {
                k[i * m + j] += gi * g[j];
            }
        }
    }
}

/// Kinematics of an embedded bar point, as of its host element.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BarKinematics {
    /// Small strain: ε_b = g·u_e with g = T(φ) B ([`bar_strain_row`]).
    SmallStrain,
    /// Total Lagrangian: Green strain along the bar ([`bar_green_strain`]), with the bar's
    /// geometric stiffness.
    TotalLagrangian,
}

/// A bar point's stage, as its law sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BarStage {
    /// Not there yet (a post-tensioned tendon before stressing): no force, state kept.
    Absent,
    /// Locked off, duct not grouted: carries `stress` [Pa] and no material stiffness; these
    /// are the equivalent prestressing forces (anchor, curvature and friction forces
    /// integrated by parts through the shape functions).
    Locked {
        /// Stress held [Pa].
        stress: f64,
    },
    /// Bonded: strain ε = ε_b − `eps_ref` + `prestrain` − `relax` − `thermal` [-] through
    /// the steel law.
    Bonded {
        /// Bond strain when the point became bonded [-].
        eps_ref: f64,
        /// Bonding stress over the modulus, σ_b,0/E_s [-].
        prestrain: f64,
        /// Relaxation of a tendon's steel, a stress-free strain [-].
        relax: f64,
        /// Thermal strain of the steel α_s ΔT, a stress-free strain [-] (the concrete's own
        /// expansion reaches the bar through ε_b).
        thermal: f64,
    },
}

/// What one bar point's law gives: its trial steel state and output values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BarPointResult {
    /// Trial steel state.
    pub state: SteelState,
    /// Bar strain including the prestrain [-].
    pub strain: f64,
    /// Bar stress [Pa].
    pub stress: f64,
    /// Plastic strain [-].
    pub plastic_strain: f64,
}

/// The steel law of a bar point at `stage` for the bar strain `eps_b` [-] (without the
/// prestrain, relaxation and thermal strain that `stage` adds): its result and tangent
/// E_t [Pa]; None for an absent point (no force, state kept).
fn bar_law(
    steel: &SteelParams,
    stage: BarStage,
    committed: &SteelState,
    eps_b: f64,
) -> Option<(BarPointResult, f64)> {
    match stage {
        BarStage::Absent => None,
        BarStage::Locked { stress } => Some((
            BarPointResult {
                state: *committed,
                strain: stress / steel.es,
                stress,
                plastic_strain: 0.0,
            },
            0.0,
        )),
        BarStage::Bonded {
            eps_ref,
            prestrain,
            relax,
            thermal,
        } => {
            let eps = eps_b - eps_ref + prestrain - relax - thermal;
            let (state, sig, et) = update_uniaxial(steel, committed, eps);
            Some((
                BarPointResult {
                    state,
                    strain: eps,
                    stress: sig,
                    plastic_strain: state.plastic_strain,
                },
                et,
            ))
        }
    }
}

/// The law part of [`bar_point_response`] under small strain with the point's strain row
/// `g` ([`bar_strain_row`]) and weight `weight_length` [m]: the point's result and, unless
/// it is absent, the factors σ A w [N] and E_t A w [N] of its force g σ A w and tangent
/// g E_t A w gᵀ, which the host adds ([`crate::elements::continuum::BarTerm`]; the values
/// and additions of [`bar_point_response`]).
#[allow(clippy::too_many_arguments)]
pub fn bar_point_small_strain(
    g: &[f64; 2 * MAX_NODES],
    weight_length: f64,
    steel: &SteelParams,
    area: f64,
    stage: BarStage,
    committed: &SteelState,
    u_e: &[f64],
) -> (BarPointResult, Option<(f64, f64)>) {
    let eps_b = g.iter().zip(u_e).map(|(a, b)| a * b).sum::<f64>();
    match bar_law(steel, stage, committed, eps_b) {
        None => (
            BarPointResult {
                state: *committed,
                strain: 0.0,
                stress: 0.0,
                plastic_strain: 0.0,
            },
            None,
        ),
        Some((res, et)) => {
            let factors = (res.stress * area * weight_length, et * area * weight_length);
            (res, Some(factors))
        }
    }
}

/// The bar-point law, the one place an embedded bar point turns its host's displacements
/// `u_e` [m] into a force: uniaxial steel `steel` at the point's stage, f += g σ A w into
/// `f` [N] and, if given, K += g E_t A w gᵀ (+ σ A w (d dᵀ ⊗ I₂) under the total Lagrangian
/// kinematics) into `k` [N/m]; `area` A [m²]. With a host of `kind` and node coordinates
/// `coords` [m]; `row` is the point's strain row g ([`bar_strain_row`]) if already known
/// (small strain: it depends on the undeformed geometry only).
#[allow(clippy::too_many_arguments)]
pub fn bar_point_response(
    kinematics: BarKinematics,
    kind: ElementKind,
    coords: &[[f64; 2]],
    p: &BarPoint,
    row: Option<&[f64; 2 * MAX_NODES]>,
    steel: &SteelParams,
    area: f64,
    stage: BarStage,
    committed: &SteelState,
    u_e: &[f64],
    f: &mut [f64],
    k: Option<&mut [f64]>,
) -> BarPointResult {
    let nd = u_e.len();
    let (eps_b, g, d) = match kinematics {
        BarKinematics::SmallStrain => {
            let g = match row {
                Some(g) => *g,
                None => bar_strain_row(kind, coords, p),
            };
            let e = g.iter().zip(u_e).map(|(a, b)| a * b).sum::<f64>();
            (e, g, None)
        }
        BarKinematics::TotalLagrangian => {
            let (e, g, d) = bar_green_strain(kind, coords, p, u_e);
            (e, g, Some(d))
        }
    };
    let Some((res, et)) = bar_law(steel, stage, committed, eps_b) else {
        return BarPointResult {
            state: *committed,
            strain: 0.0,
            stress: 0.0,
            plastic_strain: 0.0,
        };
    };
    // The two kinematics keep their own rounding order of σ A w (the histories of cracking
    // models branch on a last-bit change: one order would move the total Lagrangian ones).
    let (fs, ks) = if d.is_some() {
        let aw = area * p.weight_length;
        (res.stress * aw, et * aw)
    } else {
        (
            res.stress * area * p.weight_length,
            et * area * p.weight_length,
        )
    };
    for r in 0..nd {
        f[r] += g[r] * fs;
    }
    let Some(k) = k else {
        return res;
    };
    for r in 0..nd {
        let gr = g[r] * ks;
        match d {
            None if gr != 0.0 => {
                for c in 0..nd {
                    k[r * nd + c] += gr * g[c];
                }
            }
            None => {}
            Some(d) => {
                let dr = d[r / 2] * fs;
                for c in 0..nd {
                    let mut v = gr * g[c];
                    if r % 2 == c % 2 {
                        v += dr * d[c / 2];
                    }
                    k[r * nd + c] += v;
                }
            }
        }
    }
    res
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::embed::tests::{coords_of, mesh, rnd, u_uniform, KINDS};
    use crate::mesh::embed::{embed, BarPath, HostElement};

    /// Check 17: φ = 30°, (εx, εy, γxy) = (1e-3, −2e-4, 5e-4) → ε_b = 9.165064e-4. Tolerance
    /// 1e-10: the reference value has 7 significant digits (rounding error ≤ 5e-11).
    #[test]
    fn check17_bar_strain_at_30_degrees() {
        let phi = 30f64.to_radians();
        let dir = [phi.cos(), phi.sin()];
        let eps = [1e-3, -2e-4, 5e-4];
        assert!((strain_along(dir, eps) - 9.165064e-4).abs() < 1e-10);
        // The same through the element: B a_e of a uniform field in distorted Q4/Q8/Q9 hosts.
        for kind in KINDS {
            let (nodes, elems) = mesh(kind, 1, 1, 1.0, 1.0, 0.0);
            let mut c = coords_of(&nodes, &elems).remove(0);
            for (i, x) in c.iter_mut().enumerate() {
                // Distort while keeping edges straight enough (shift of one corner + mids).
                x[0] += 0.1 * x[0] * x[1] + 0.02 * (i as f64 % 3.0) * x[1] * (1.0 - x[1]);
            }
            let u: Vec<f64> = c.iter().flat_map(|x| u_uniform(*x, eps)).collect();
            let p = BarPoint {
                xi: 0.2,
                eta: -0.4,
                dir,
                weight_length: 1.0,
                s: 0.0,
                x: [0.0; 2],
            };
            assert!(
                (bar_strain(kind, &c, &p, &u) - 9.165064e-4).abs() < 1e-10,
                "{kind:?}"
            );
        }
    }

    /// Patch test: horizontal bar at mid-height of a unit-square Q4 under uniform εx = ε0:
    /// nodal forces ∓E A ε0/2 at the left/right nodes, zero vertical forces (round-off 1e-12).
    #[test]
    fn patch_test_unit_square_q4() {
        let c = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let hosts = [HostElement {
            kind: ElementKind::Q4,
            coords: &c,
        }];
        let pieces = embed(&BarPath::Polyline(vec![[0.0, 0.5], [1.0, 0.5]]), &hosts, 2).unwrap();
        assert_eq!(pieces.len(), 1);
        let (e, a, eps0) = (200e9, 1e-4, 1e-3);
        let u: Vec<f64> = c.iter().flat_map(|x| [eps0 * x[0], 0.0]).collect();
        let mut f = vec![0.0; 8];
        let mut k = vec![0.0; 64];
        for p in &pieces[0].points {
            let eb = bar_strain(ElementKind::Q4, &c, p, &u);
            assert!((eb - eps0).abs() < 1e-15);
            add_bar_point(ElementKind::Q4, &c, p, a, e * eb, e, &mut f, &mut k);
        }
        let half = e * a * eps0 / 2.0;
        let expect = [-half, 0.0, half, 0.0, half, 0.0, -half, 0.0];
        for i in 0..8 {
            assert!((f[i] - expect[i]).abs() < 1e-12 * half, "dof {i}: {}", f[i]);
        }
        // K a = f for the linear material.
        for i in 0..8 {
            let ku: f64 = (0..8).map(|j| k[i * 8 + j] * u[j]).sum();
            assert!((ku - f[i]).abs() < 1e-12 * half);
        }
    }

    /// Tangent stiffness equals central finite differences of the internal force for a
    /// nonlinear bar law σ = E ε + c ε² (FD truncation ~h², tolerance 1e-6 relative).
    #[test]
    fn stiffness_matches_finite_differences() {
        let (e, cc, area) = (2e5, 4e7, 1e-3);
        let law = |eps: f64| (e * eps + cc * eps * eps, e + 2.0 * cc * eps);
        for kind in KINDS {
            let (nodes, elems) = mesh(kind, 1, 1, 1.2, 0.9, 0.0);
            let mut c = coords_of(&nodes, &elems).remove(0);
            c[2][0] += 0.15;
            c[2][1] += 0.1;
            // Quadratic kinds: the mid-side nodes of edges 1 and 2 off their edges' middles.
            if kind.info().order == 2 {
                let (e1, e2) = (kind.edge_nodes(1), kind.edge_nodes(2));
                let mid = |e: &[usize]| {
                    [
                        0.5 * (c[e[0]][0] + c[e[1]][0]),
                        0.5 * (c[e[0]][1] + c[e[1]][1]),
                    ]
                };
                let (m1, m2) = (mid(e1), mid(e2));
                c[e1[2]] = [m1[0] + 0.03, m1[1]];
                c[e2[2]] = [m2[0], m2[1] - 0.02];
            }
            if kind == ElementKind::Q9 {
                c[8] = [0.62, 0.48];
            }
            let hosts = [HostElement { kind, coords: &c }];
            // A curved path inside the host (a triangle: the cell's lower-right half).
            let path = match kind.info().domain {
                crate::fem::kinds::Domain::Square => [[0.1, 0.2], [0.6, 0.5], [1.1, 0.6]],
                crate::fem::kinds::Domain::Triangle => [[0.3, 0.05], [0.8, 0.25], [1.2, 0.5]],
            };
            let pieces = embed(&BarPath::Quadratic(path), &hosts, 3).unwrap();
            let m = 2 * kind.n_nodes();
            let force = |u: &[f64]| -> (Vec<f64>, Vec<f64>) {
                let mut f = vec![0.0; m];
                let mut k = vec![0.0; m * m];
                for p in &pieces[0].points {
                    let (s, et) = law(bar_strain(kind, &c, p, u));
                    add_bar_point(kind, &c, p, area, s, et, &mut f, &mut k);
                }
                (f, k)
            };
            let u0: Vec<f64> = (0..m).map(|i| 1e-3 * rnd(100 + i)).collect();
            let (_, k) = force(&u0);
            let h = 1e-7;
            let kmax = k.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            for j in 0..m {
                let mut up = u0.clone();
                let mut um = u0.clone();
                up[j] += h;
                um[j] -= h;
                let (fp, _) = force(&up);
                let (fm, _) = force(&um);
                for i in 0..m {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    assert!((fd - k[i * m + j]).abs() < 1e-6 * kmax, "{kind:?} {i},{j}");
                }
            }
            // Symmetry.
            for i in 0..m {
                for j in 0..m {
                    assert!((k[i * m + j] - k[j * m + i]).abs() < 1e-12 * kmax);
                }
            }
        }
    }

    /// TL bar kinematics: a bar point inside a distorted Q8 (curved edges) at an oblique
    /// direction.
    fn tl_bar_host() -> (Vec<[f64; 2]>, BarPoint) {
        let c: Vec<[f64; 2]> = (0..8)
            .map(|a| {
                let [x, y] = crate::fem::shape::NODE_XI[a];
                [0.5 * x + 0.1 * y + 0.02 * y * y, 0.3 * y - 0.04 * x * x]
            })
            .collect();
        let p = BarPoint {
            xi: 0.3,
            eta: -0.2,
            dir: [0.8, 0.6],
            weight_length: 0.4,
            s: 0.0,
            x: [0.0, 0.0],
        };
        (c, p)
    }

    /// Force and tangent of one TL bar point with an elastic law σ = σ0 + E E_b.
    fn tl_bar_response(c: &[[f64; 2]], p: &BarPoint, u: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let (es, s0, area) = (200e9, 1e9, 1e-3);
        let (e, g, d) = bar_green_strain(ElementKind::Q8, c, p, u);
        let sig = s0 + es * e;
        let nd = u.len();
        let (mut f, mut k) = (vec![0.0; nd], vec![0.0; nd * nd]);
        let aw = area * p.weight_length;
        for r in 0..nd {
            f[r] = g[r] * sig * aw;
            for col in 0..nd {
                k[r * nd + col] = g[r] * es * aw * g[col];
                if r % 2 == col % 2 {
                    k[r * nd + col] += sig * aw * d[r / 2] * d[col / 2];
                }
            }
        }
        (f, k)
    }

    /// The TL bar's g and geometric stiffness are the derivatives of its strain and force:
    /// central differences (step 1e-7 m on displacements ~1e-2 m; truncation ~1e-14,
    /// round-off ~1e-9 relative) at random states, to 1e-6 of the largest entry. The
    /// prestress σ0 = 1 GPa makes the geometric term ~1 % of the material one, so leaving it
    /// out fails the check.
    #[test]
    fn tl_bar_tangent_matches_central_differences() {
        let (c, p) = tl_bar_host();
        for s in 0..4 {
            let u: Vec<f64> = (0..16).map(|i| 0.02 * rnd(100 * s + i)).collect();
            let (_, k) = tl_bar_response(&c, &p, &u);
            let kmax = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let h = 1e-7;
            for j in 0..16 {
                let (mut up, mut um) = (u.clone(), u.clone());
                up[j] += h;
                um[j] -= h;
                let (fp, _) = tl_bar_response(&c, &p, &up);
                let (fm, _) = tl_bar_response(&c, &p, &um);
                for i in 0..16 {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    assert!(
                        (k[i * 16 + j] - fd).abs() < 1e-6 * kmax,
                        "K[{i}][{j}] = {} vs {fd}",
                        k[i * 16 + j]
                    );
                }
            }
        }
    }

    /// Green strain along the bar: zero for a rigid rotation by 30° (the linear bar strain is
    /// cos²30°·(cos 30° − 1) + … ≠ 0), and equal to the linear strain for u = 0 (g = T B).
    #[test]
    fn tl_bar_rigid_rotation_and_small_limit() {
        let (c, p) = tl_bar_host();
        let th = 30f64.to_radians();
        let (co, si) = (th.cos(), th.sin());
        let u: Vec<f64> = c
            .iter()
            .flat_map(|x| [co * x[0] - si * x[1] - x[0], si * x[0] + co * x[1] - x[1]])
            .collect();
        let (e, _, _) = bar_green_strain(ElementKind::Q8, &c, &p, &u);
        assert!(e.abs() < 1e-15, "{e}");
        assert!((bar_strain(ElementKind::Q8, &c, &p, &u) - (co - 1.0)).abs() < 1e-12);
        let (_, g, _) = bar_green_strain(ElementKind::Q8, &c, &p, &[0.0; 16]);
        let g0 = bar_strain_vector(ElementKind::Q8, &c, &p);
        for (a, b) in g0.iter().zip(&g) {
            assert!((a - b).abs() < 1e-15 * g0.iter().fold(0.0f64, |m, v| m.max(v.abs())));
        }
    }
}
