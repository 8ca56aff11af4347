//! Q4 with incompatible bending modes (Wilson, Taylor, Doherty & Ghaboussi 1973; Taylor,
//! Beresford & Wilson 1976, "QM6"): `integration = "incompatible"`.
//!
//! The bilinear Q4 cannot bend without shear: a pure moment gives it a parasitic shear
//! strain and it is far too stiff (locks) in slender bending. Two internal modes per
//! direction, N₅ = 1 − ξ² and N₆ = 1 − η², add the missing quadratic displacements:
//! ε = B u + G α with four element parameters α. Taylor's correction evaluates G with the
//! Jacobian at the element centre and scales it by det J₀/det J, so that ∫ G dA = 0 and the
//! element passes the patch test on any shape.
//!
//! α is internal to the element: for the current nodal displacements u it is found by
//! Newton's method on the element's own equilibrium r_α = ∫ Gᵀ σ(B u + G α) t dA = 0 (one
//! step for elastic materials), starting from α = 0, so nothing beyond the Gauss-point
//! states is stored and a cut step retries cleanly. The element then returns
//! f = ∫ Bᵀ σ t dA and the condensed tangent K = K_uu − K_uα K_αα⁻¹ K_αu.

use super::continuum::{
    gauss_geometry, rule_points, GaussGeometry, GaussOutput, Integration, PointsPass,
};
use crate::fem::shape::{jacobian, MAX_NODES};
use crate::materials::point::{update_into, PointState, UpdateError};
use crate::model::ElementKind;

/// Local Newton iterations allowed for α.
const MAX_LOCAL: usize = 30;
/// r_α is converged when below this fraction of Σ |w t Gᵀ σ| (the scale of its terms): far
/// below the global equilibrium tolerance, above the round-off of plastic return mappings.
const LOCAL_TOL: f64 = 1e-9;
/// A local solve that stalls is accepted up to this fraction, its remainder condensed to
/// the nodes (f − K_uα K_αα⁻¹ r_α).
const LOCAL_ACCEPT: f64 = 1e-2;

/// The modes' equations at one α: residual r_α [N], K_αα [N/m] and the scale of r_α's terms.
type LocalSystem = ([f64; 4], [[f64; 4]; 4], f64);

/// Incompatible-mode strain rows at one Gauss point: for each mode k, (∂N_k/∂x, ∂N_k/∂y)
/// with Taylor's centre Jacobian and det J₀/det J scaling [1/m].
fn mode_derivatives(coords: &[[f64; 2]], xi: f64, eta: f64) -> [[f64; 2]; 2] {
    let (_, det0, inv0) = jacobian(&ElementKind::Q4.eval(0.0, 0.0), coords);
    let (_, det, _) = jacobian(&ElementKind::Q4.eval(xi, eta), coords);
    let s = det0 / det;
    // Natural derivatives of 1 − ξ² and 1 − η².
    let nat = [[-2.0 * xi, 0.0], [0.0, -2.0 * eta]];
    nat.map(|[dxi, deta]| {
        [
            s * (inv0[0][0] * dxi + inv0[0][1] * deta),
            s * (inv0[1][0] * dxi + inv0[1][1] * deta),
        ]
    })
}

/// Strain of the compatible and incompatible fields at one point.
fn strain(dn: &[[f64; 2]; MAX_NODES], gm: &[[f64; 2]; 2], u: &[f64], alpha: &[f64; 4]) -> [f64; 3] {
    let mut eps = [0.0; 3];
    for a in 0..4 {
        let (ux, uy) = (u[2 * a], u[2 * a + 1]);
        eps[0] += dn[a][0] * ux;
        eps[1] += dn[a][1] * uy;
        eps[2] += dn[a][1] * ux + dn[a][0] * uy;
    }
    // α = [a_x1, a_y1, a_x2, a_y2]: mode k in x and in y, like a node's (ux, uy).
    for k in 0..2 {
        let (ax, ay) = (alpha[2 * k], alpha[2 * k + 1]);
        eps[0] += gm[k][0] * ax;
        eps[1] += gm[k][1] * ay;
        eps[2] += gm[k][1] * ax + gm[k][0] * ay;
    }
    eps
}

/// Column c of the 3 × 2 B block of a node or mode with derivatives (dx, dy): the strain of
/// a unit displacement in direction c (0 = x, 1 = y).
fn b_col(d: [f64; 2], c: usize) -> [f64; 3] {
    if c == 0 {
        [d[0], 0.0, d[1]]
    } else {
        [0.0, d[1], d[0]]
    }
}

/// xᵀ D y for 3-vectors.
fn bilinear(x: &[f64; 3], d: &[[f64; 3]; 3], y: &[f64; 3]) -> f64 {
    let mut s = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            s += x[i] * d[i][j] * y[j];
        }
    }
    s
}

/// Solve the 4 × 4 system a x = b in place (partial pivoting); None if singular.
fn solve4(mut a: [[f64; 4]; 4], mut b: [f64; 4]) -> Option<[f64; 4]> {
    let scale = a.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
    for c in 0..4 {
        let p = (c..4).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        let pivot = a[p][c].abs();
        if pivot.is_nan() || pivot <= 1e-14 * scale {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..4 {
            let m = a[r][c] / a[c][c];
            for k in c..4 {
                a[r][k] -= m * a[c][k];
            }
            b[r] -= m * b[c];
        }
    }
    for c in (0..4).rev() {
        let s: f64 = (c + 1..4).map(|k| a[c][k] * b[k]).sum();
        b[c] = (b[c] - s) / a[c][c];
    }
    Some(b)
}

/// Force and condensed tangent of a Q4 with incompatible modes; arguments as
/// [`super::continuum::response_at`].
// long: the local Newton on the modes α and the static condensation share the per-point stresses and tangents it fills; split, they would pass them all
pub fn response_at(coords: &[[f64; 2]], pass: PointsPass<'_, '_>) -> Result<(), UpdateError> {
    let PointsPass {
        thickness,
        mat,
        committed,
        u,
        f,
        k,
        trial,
        out,
        time,
        imposed,
        blocks: _,
    } = pass;
    let pts = rule_points(ElementKind::Q4, Integration::Full);
    let GaussGeometry {
        n_pts,
        points: geo,
        h,
    } = gauss_geometry(ElementKind::Q4, Integration::Full, coords);
    let mut gm = [[[0.0; 2]; 2]; 4];
    for g in 0..n_pts {
        gm[g] = mode_derivatives(coords, pts[g].0, pts[g].1);
    }
    let mut sig = [[0.0; 3]; 4];
    let mut dmat = [[[0.0; 3]; 3]; 4];
    // Material points at α: r_α, K_αα and the scale of r_α's terms; states and outputs are
    // left in `trial`, `out`, `sig`, `dmat`.
    let eval = |alpha: &[f64; 4],
                trial: &mut [PointState],
                out: &mut [GaussOutput],
                sig: &mut [[f64; 3]; 4],
                dmat: &mut [[[f64; 3]; 3]; 4]|
     -> Result<LocalSystem, UpdateError> {
        let mut r = [0.0; 4];
        let mut scale = 0.0;
        let mut kaa = [[0.0; 4]; 4];
        for g in 0..n_pts {
            let (dn, wdet) = geo[g];
            let eps = strain(&dn, &gm[g], u, alpha);
            let mech = super::continuum::mechanical(eps, imposed, g);
            let (s, d) = update_into(mat, &committed[g], &mech, h, time, &mut trial[g])?;
            out[g] = GaussOutput {
                strain: eps,
                stress: s,
            };
            sig[g] = s;
            dmat[g] = d;
            let w = wdet * thickness;
            for i in 0..4 {
                let bi = b_col(gm[g][i / 2], i % 2);
                r[i] += w * (bi[0] * s[0] + bi[1] * s[1] + bi[2] * s[2]);
                scale += w * ((bi[0] * s[0]).abs() + (bi[1] * s[1]).abs() + (bi[2] * s[2]).abs());
                for j in 0..4 {
                    kaa[i][j] += w * bilinear(&bi, &d, &b_col(gm[g][j / 2], j % 2));
                }
            }
        }
        Ok((r, kaa, scale))
    };
    let norm = |r: &[f64; 4]| r.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut alpha = [0.0; 4];
    let (mut r, mut kaa, mut scale) = eval(&alpha, trial, out, &mut sig, &mut dmat)?;
    let mut converged = false;
    for _ in 0..MAX_LOCAL {
        if norm(&r) <= LOCAL_TOL * scale || scale == 0.0 {
            converged = true;
            break;
        }
        let da = solve4(kaa, r).ok_or_else(|| {
            UpdateError::NotConverged("incompatible-mode Q4: singular internal stiffness".into())
        })?;
        // Newton step with backtracking on |r_α|: the material's tangent jumps where points
        // start to flow or a crack closes, and a full step can then overshoot.
        let mut step = 1.0;
        loop {
            let trial_alpha: [f64; 4] = std::array::from_fn(|i| alpha[i] - step * da[i]);
            let (r1, k1, s1) = eval(&trial_alpha, trial, out, &mut sig, &mut dmat)?;
            if norm(&r1) < norm(&r) || step < 1.0 / 64.0 {
                let moved = da.iter().fold(0.0_f64, |m, v| m.max((step * v).abs()));
                let size = trial_alpha.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                (alpha, r, kaa, scale) = (trial_alpha, r1, k1, s1);
                // A step at round-off of α: the stresses' own tolerance (return mapping) is
                // the floor of r_α.
                if moved <= 1e-12 * size {
                    converged = true;
                }
                break;
            }
            step *= 0.5;
        }
        if converged {
            break;
        }
    }
    if !(converged || norm(&r) <= LOCAL_TOL * scale) {
        // The stress response can be non-smooth in α (a point switching between its elastic
        // and plastic route within the increment), and the local Newton may then stall. A
        // small remainder is carried to the nodes by the condensation below; a large one
        // cuts the increment.
        if norm(&r).is_nan() || norm(&r) > LOCAL_ACCEPT * scale {
            return Err(UpdateError::NotConverged(format!(
                "incompatible-mode Q4: internal modes not in equilibrium after {MAX_LOCAL} iterations (|r_α| = {:.3e} N of {scale:.3e} N)",
                norm(&r)
            )));
        }
    }
    f[..8].iter_mut().for_each(|v| *v = 0.0);
    let mut kuu = [[0.0; 8]; 8];
    let mut kua = [[0.0; 4]; 8];
    let mut kau = [[0.0; 8]; 4];
    let mut kaa = [[0.0; 4]; 4];
    for g in 0..n_pts {
        let (dn, wdet) = geo[g];
        let w = wdet * thickness;
        let s = &sig[g];
        let d = &dmat[g];
        let bu: [[f64; 3]; 8] = std::array::from_fn(|i| b_col(dn[i / 2], i % 2));
        let ba: [[f64; 3]; 4] = std::array::from_fn(|i| b_col(gm[g][i / 2], i % 2));
        for i in 0..8 {
            f[i] += w * (bu[i][0] * s[0] + bu[i][1] * s[1] + bu[i][2] * s[2]);
        }
        for i in 0..8 {
            if k.is_some() {
                for j in 0..8 {
                    kuu[i][j] += w * bilinear(&bu[i], d, &bu[j]);
                }
            }
            for j in 0..4 {
                kua[i][j] += w * bilinear(&bu[i], d, &ba[j]);
                kau[j][i] += w * bilinear(&ba[j], d, &bu[i]);
            }
        }
        for i in 0..4 {
            for j in 0..4 {
                kaa[i][j] += w * bilinear(&ba[i], d, &ba[j]);
            }
        }
    }
    let singular =
        || UpdateError::NotConverged("incompatible-mode Q4: singular internal stiffness".into());
    // Condensed force f − K_uα K_αα⁻¹ r_α: the first-order effect at the nodes of what is
    // left of the modes' equilibrium (zero to round-off when the local solve converged).
    if r.iter().any(|v| *v != 0.0) {
        let x = solve4(kaa, r).ok_or_else(singular)?;
        for i in 0..8 {
            f[i] -= (0..4).map(|m| kua[i][m] * x[m]).sum::<f64>();
        }
    }
    let Some(k) = k else {
        return Ok(());
    };
    // K = K_uu − K_uα K_αα⁻¹ K_αu, one column of K_αα⁻¹ K_αu at a time.
    for j in 0..8 {
        let col = [kau[0][j], kau[1][j], kau[2][j], kau[3][j]];
        let x = solve4(kaa, col).ok_or_else(singular)?;
        for i in 0..8 {
            let c: f64 = (0..4).map(|m| kua[i][m] * x[m]).sum();
            k[i * 8 + j] = kuu[i][j] - c;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::continuum::NodeBlocks;
    use crate::materials::point::{Material, TimeContext};

    fn elastic() -> Material {
        Material::Elastic {
            e: 30e9,
            nu: 0.2,
            density: 0.0,
        }
    }

    /// A distorted quadrilateral [m].
    const SKEW: [[f64; 2]; 4] = [[0.0, 0.0], [2.1, 0.3], [2.4, 1.9], [-0.2, 1.4]];

    fn run(coords: &[[f64; 2]], u: &[f64]) -> ([f64; 8], [f64; 64], [GaussOutput; 4]) {
        let mat = elastic();
        let committed = vec![mat.initial_state(); 4];
        let mut trial = committed.clone();
        let mut out = [GaussOutput::default(); 4];
        let (mut f, mut k) = ([0.0; 8], [0.0; 64]);
        response_at(
            coords,
            PointsPass {
                thickness: 0.25,
                mat: &mat,
                committed: &committed,
                u,
                f: &mut f,
                k: Some(&mut k),
                trial: &mut trial,
                out: &mut out,
                time: &TimeContext::default(),
                imposed: &[],
                blocks: NodeBlocks::ALL,
            },
        )
        .unwrap();
        (f, k, out)
    }

    /// Patch test: a linear displacement field gives its constant strain at every Gauss point
    /// on a distorted element (the incompatible modes stay at zero: ∫ G dA = 0).
    #[test]
    fn distorted_element_passes_the_patch_test() {
        let (a, b, c, d, e, g) = (1e-3, -4e-4, 2e-4, 7e-4, 3e-4, -5e-4);
        let u: Vec<f64> = SKEW
            .iter()
            .flat_map(|&[x, y]| [a * x + b * y + e, c * x + d * y + g])
            .collect();
        let (_, _, out) = run(&SKEW, &u);
        for o in out {
            let want = [a, d, b + c];
            for i in 0..3 {
                assert!(
                    (o.strain[i] - want[i]).abs() < 1e-15,
                    "{:?} vs {want:?}",
                    o.strain
                );
            }
        }
    }

    /// Pure bending of a rectangular element: u = κ x y, v = −κ x²/2 at the nodes. The
    /// incompatible modes reproduce the exact field (ε_x = κ y, no shear), so the element's
    /// bending energy is the beam's M²L/(2EI) with M = E I κ (plane stress, ν acts through
    /// the free ε_y = −ν κ y, which the η mode supplies): uᵀ K u = E I κ² L, exactly. The
    /// plain Q4 would give the parasitic shear and a stiffer answer.
    #[test]
    fn rectangle_bends_without_parasitic_shear() {
        let (l, hgt, t) = (2.0, 0.5, 0.25);
        let coords = [
            [-l / 2.0, -hgt / 2.0],
            [l / 2.0, -hgt / 2.0],
            [l / 2.0, hgt / 2.0],
            [-l / 2.0, hgt / 2.0],
        ];
        let kappa = 1e-3;
        let u: Vec<f64> = coords
            .iter()
            .flat_map(|&[x, y]| [kappa * x * y, -kappa * x * x / 2.0])
            .collect();
        let (f, k, out) = run(&coords, &u);
        for o in out {
            assert!(o.strain[2].abs() < 1e-15, "no shear: {:?}", o.strain);
        }
        let i = t * hgt.powi(3) / 12.0;
        let exact = 30e9 * i * kappa * kappa * l;
        let energy: f64 = (0..8).map(|r| u[r] * f[r]).sum();
        assert!((energy - exact).abs() < 1e-9 * exact, "{energy} vs {exact}");
        // The condensed tangent gives the same (linear material).
        let ku: f64 = (0..8)
            .map(|r| u[r] * (0..8).map(|c| k[r * 8 + c] * u[c]).sum::<f64>())
            .sum();
        assert!((ku - exact).abs() < 1e-9 * exact, "{ku} vs {exact}");
    }

    /// The condensed tangent is the derivative of the force (finite differences, elastic: the
    /// local solve is exact, so the match is to round-off of the differences).
    #[test]
    fn condensed_tangent_matches_finite_differences() {
        let u: Vec<f64> = (0..8).map(|i| 1e-4 * ((i * 7 % 5) as f64 - 2.0)).collect();
        let (f0, k, _) = run(&SKEW, &u);
        for j in 0..8 {
            let mut up = u.clone();
            up[j] += 1e-7;
            let (f1, _, _) = run(&SKEW, &up);
            for i in 0..8 {
                let fd = (f1[i] - f0[i]) / 1e-7;
                let scale = k.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                assert!((fd - k[i * 8 + j]).abs() < 1e-6 * scale, "K[{i}][{j}]");
            }
        }
    }
}
