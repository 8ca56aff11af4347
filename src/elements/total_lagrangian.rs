//! Total Lagrangian (TL) plane-stress continuum: Green–Lagrange strain and second
//! Piola–Kirchhoff stress on the undeformed configuration (small strain, large rotation;
//! Bathe, Finite Element Procedures, 1996, §6.2.3; Crisfield, Non-linear Finite Element
//! Analysis of Solids and Structures, vol. 1, 1991, ch. 5). Used when the model's
//! `[analysis] geometry = "nonlinear"`; the geometrically linear elements are in
//! [`super::continuum`] and stay a separate code path (no cost to linear runs).
//!
//! At a Gauss point, with H = ∂u/∂X the displacement gradient on the reference geometry and
//! F = I + H:
//! - E = ½(H + Hᵀ + HᵀH), fed to the material as the small-strain ε is in the linear
//!   elements (materials are small-strain laws; their stress is read as S);
//! - δE = B_L(u) δu with B_L,a = [[F₁₁N_a,₁, F₂₁N_a,₁], [F₁₂N_a,₂, F₂₂N_a,₂],
//!   [F₁₁N_a,₂ + F₁₂N_a,₁, F₂₁N_a,₂ + F₂₂N_a,₁]];
//! - f = ∫ B_Lᵀ S t dA₀; K = ∫ B_Lᵀ D B_L t dA₀ + ∫ (∇N_aᵀ Ŝ ∇N_b) I₂ t dA₀ (the
//!   initial-stress matrix), areas and thickness of the undeformed element.

use super::continuum::{GaussOutput, PointsPass};
use crate::materials::point::{update_into, UpdateError};
use crate::model::ElementKind;

/// Green–Lagrange strain (E₁₁, E₂₂, 2E₁₂) [-] of a displacement gradient
/// `h[i][j] = ∂u_i/∂X_j` [-].
#[inline]
pub fn green_lagrange(h: &[[f64; 2]; 2]) -> [f64; 3] {
    [
        h[0][0] + 0.5 * (h[0][0] * h[0][0] + h[1][0] * h[1][0]),
        h[1][1] + 0.5 * (h[0][1] * h[0][1] + h[1][1] * h[1][1]),
        h[0][1] + h[1][0] + h[0][0] * h[0][1] + h[1][0] * h[1][1],
    ]
}

/// Displacement gradient ∂u_i/∂X_j [-] from the Cartesian shape-function derivatives
/// `dn` [1/m] and the nodal displacements `u` (ux, uy per node) [m] of `n` nodes.
#[inline]
pub fn displacement_gradient(dn: &[[f64; 2]], u: &[f64], n: usize) -> [[f64; 2]; 2] {
    let mut h = [[0.0; 2]; 2];
    for a in 0..n {
        let (ux, uy) = (u[2 * a], u[2 * a + 1]);
        h[0][0] += dn[a][0] * ux;
        h[0][1] += dn[a][1] * ux;
        h[1][0] += dn[a][0] * uy;
        h[1][1] += dn[a][1] * uy;
    }
    h
}

/// As [`super::continuum::response_at`] with the total Lagrangian kinematics: internal force
/// `f` [N] and (if `k` is given) tangent `k` [N/m] at the nodal displacements `u` [m]; the
/// Gauss outputs hold E [-] and S [Pa]. Only the node blocks `blocks` of the tangent are
/// formed (the others are zero; see [`NodeBlocks`]).
pub fn response_tl(
    kind: ElementKind,
    geometry: &super::continuum::GaussGeometry,
    pass: PointsPass<'_, '_>,
) -> Result<(), UpdateError> {
    let PointsPass {
        thickness,
        mat,
        committed,
        u,
        f,
        mut k,
        trial,
        out,
        time,
        imposed,
        blocks,
    } = pass;
    let n = kind.n_nodes();
    let nd = 2 * n;
    f[..nd].iter_mut().for_each(|v| *v = 0.0);
    if let Some(k) = k.as_deref_mut() {
        k[..nd * nd].iter_mut().for_each(|v| *v = 0.0);
    }
    // Characteristic length of the undeformed element (strains are referred to it).
    let (n_pts, geo, h_len) = (geometry.n_pts, &geometry.points, geometry.h);
    // Size-dependent material constants once per element (same values as per point).
    let local = crate::materials::point::for_element(mat, h_len)?;
    let mat = local.as_ref().unwrap_or(mat);
    // The 4 × 4 matrices C of the points (see below), for the stiffness after all updates.
    let mut cs = [[[0.0; 4]; 4]; 9];
    for g in 0..n_pts {
        let (dn, wdet) = geo[g];
        let h = displacement_gradient(&dn, u, n);
        let e = green_lagrange(&h);
        // Small strains: the thermal strain is subtracted from the Green strain.
        let mech = super::continuum::mechanical(e, imposed, g);
        let (s, d) = update_into(mat, &committed[g], &mech, h_len, time, &mut trial[g])?;
        out[g] = GaussOutput {
            strain: e,
            stress: s,
        };
        let w = wdet * thickness;
        let fm = [[1.0 + h[0][0], h[0][1]], [h[1][0], 1.0 + h[1][1]]];
        // f += w B_L,aᵀ S with B_L,a (3 × 2) of each node.
        for a in 0..n {
            let (ax, ay) = (dn[a][0], dn[a][1]);
            let b = [
                [fm[0][0] * ax, fm[1][0] * ax],
                [fm[0][1] * ay, fm[1][1] * ay],
                [fm[0][0] * ay + fm[0][1] * ax, fm[1][0] * ay + fm[1][1] * ax],
            ];
            for i in 0..2 {
                f[2 * a + i] += w * (b[0][i] * s[0] + b[1][i] * s[1] + b[2][i] * s[2]);
            }
        }
        if k.is_none() {
            continue;
        }
        // With δE = S(F) δh, δh = (δH₁₁, δH₁₂, δH₂₁, δH₂₂) and δH_ik = N_a,k δu_a,i, both
        // terms of K are ∇N_aᵀ C_ij ∇N_b with the 4 × 4 C = w (Sᵀ D S + I₂ ⊗ Ŝ): about half
        // the operations of B_Lᵀ D B_L node pair by node pair. Column 2i + k of S is
        // ∂E/∂H_ik: (F_i1, 0, F_i2) for k = 1, (0, F_i2, F_i1) for k = 2.
        let mut sm = [[0.0; 3]; 4];
        for i in 0..2 {
            sm[2 * i] = [fm[i][0], 0.0, fm[i][1]];
            sm[2 * i + 1] = [0.0, fm[i][1], fm[i][0]];
        }
        let mut ds = [[0.0; 3]; 4];
        for q in 0..4 {
            for r in 0..3 {
                ds[q][r] = d[r][0] * sm[q][0] + d[r][1] * sm[q][1] + d[r][2] * sm[q][2];
            }
        }
        let shat = [[s[0], s[2]], [s[2], s[1]]];
        let c = &mut cs[g];
        for p in 0..4 {
            for q in 0..4 {
                let mut v = sm[p][0] * ds[q][0] + sm[p][1] * ds[q][1] + sm[p][2] * ds[q][2];
                if p / 2 == q / 2 {
                    v += shat[p % 2][q % 2];
                }
                c[p][q] = w * v;
            }
        }
    }
    let Some(k) = k else {
        return Ok(());
    };
    // t_jl = Σ_k N_a,k C[2i + k][2j + l] of every point, node and row i; then
    // K[(a,i), (b,j)] = Σ_g Σ_l t_jl N_b,l block by block, summed over the points in
    // their order in registers (the operations of adding point by point into K).
    for a in 0..n {
        let mut ts = [[0.0; 8]; 9];
        for g in 0..n_pts {
            let (dn, c) = (&geo[g].0, &cs[g]);
            for i in 0..2 {
                let (p0, p1) = (2 * i, 2 * i + 1);
                for q in 0..4 {
                    ts[g][4 * i + q] = dn[a][0] * c[p0][q] + dn[a][1] * c[p1][q];
                }
            }
        }
        for bn in 0..n {
            if !blocks.has(a, bn) {
                continue;
            }
            let mut acc = [0.0; 4];
            for g in 0..n_pts {
                let t = &ts[g];
                let (bx, by) = (geo[g].0[bn][0], geo[g].0[bn][1]);
                acc[0] += t[0] * bx + t[1] * by;
                acc[1] += t[2] * bx + t[3] * by;
                acc[2] += t[4] * bx + t[5] * by;
                acc[3] += t[6] * bx + t[7] * by;
            }
            let (r0, r1) = (2 * a * nd, (2 * a + 1) * nd);
            k[r0 + 2 * bn] = acc[0];
            k[r0 + 2 * bn + 1] = acc[1];
            k[r1 + 2 * bn] = acc[2];
            k[r1 + 2 * bn + 1] = acc[3];
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::elements::continuum::{
        gauss_geometry, response_at, rule_points, Integration, NodeBlocks,
    };
    use crate::materials::point::{Material, PointState, TimeContext};

    const KINDS: [ElementKind; 4] = crate::fem::kinds::ALL;

    /// A distorted element: the natural node positions mapped through a skewed, stretched map
    /// with a quadratic term (curved edges for the quadratic kinds) [m].
    fn coords(kind: ElementKind) -> Vec<[f64; 2]> {
        (0..kind.n_nodes())
            .map(|a| {
                // A triangle's (ξ, η) ∈ [0, 1] stretched to the quadrilaterals' [−1, 1].
                let [x, y] = match kind.info().domain {
                    crate::fem::kinds::Domain::Square => kind.info().node_xi[a],
                    crate::fem::kinds::Domain::Triangle => {
                        kind.info().node_xi[a].map(|v| 2.0 * v - 1.0)
                    }
                };
                [
                    0.6 * x + 0.1 * y + 0.03 * y * y + 1.0,
                    0.25 * y - 0.05 * x + 0.02 * x * x - 0.4,
                ]
            })
            .collect()
    }

    /// Deterministic pseudo-random numbers in [−1, 1) (xorshift; no dependency needed).
    fn rand(seed: &mut u64) -> f64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    fn elastic() -> Material {
        Material::Elastic {
            e: 30e9,
            nu: 0.2,
            density: 0.0,
        }
    }

    fn tl(kind: ElementKind, u: &[f64], tangent: bool) -> (Vec<f64>, Vec<f64>, Vec<GaussOutput>) {
        let nd = 2 * kind.n_nodes();
        let c = coords(kind);
        let mat = elastic();
        let ngp = rule_points(kind, Integration::Full).len();
        let committed = vec![PointState::Elastic; ngp];
        let mut trial = committed.clone();
        let mut out = vec![GaussOutput::default(); ngp];
        let (mut f, mut k) = (vec![0.0; nd], vec![0.0; nd * nd]);
        response_tl(
            kind,
            &gauss_geometry(kind, Integration::Full, &c),
            PointsPass {
                thickness: 0.3,
                mat: &mat,
                committed: &committed,
                u,
                f: &mut f,
                k: tangent.then_some(&mut k[..]),
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

    /// A tangent formed on some node blocks only (what the assembly asks for) equals the
    /// full tangent bit for bit in those blocks and is zero elsewhere, for the total
    /// Lagrangian and the small-strain element: the assembled matrix cannot change. Exact
    /// equality is the claim (the same operations in the same order).
    #[test]
    fn tangent_blocks_are_those_of_the_full_tangent() {
        let mut seed = 11u64;
        for kind in KINDS {
            let n = kind.n_nodes();
            let nd = 2 * n;
            let u: Vec<f64> = (0..nd).map(|_| 0.01 * rand(&mut seed)).collect();
            // The lower node blocks and, of the upper ones, every third: an irregular mask.
            let mut mask = 0u128;
            for a in 0..n {
                for b in 0..n {
                    if b <= a || (a + 2 * b) % 3 == 0 {
                        mask |= 1 << (9 * a + b);
                    }
                }
            }
            let blocks = NodeBlocks(mask);
            let c = coords(kind);
            let ngp = rule_points(kind, Integration::Full).len();
            let committed = vec![PointState::Elastic; ngp];
            for tl in [true, false] {
                let run = |blocks: NodeBlocks| {
                    let (mut trial, mut out) =
                        (committed.clone(), vec![GaussOutput::default(); ngp]);
                    let (mut f, mut k) = (vec![0.0; nd], vec![7.0; nd * nd]);
                    let respond = if tl {
                        response_tl
                    } else {
                        crate::elements::continuum::response_at
                    };
                    respond(
                        kind,
                        &gauss_geometry(kind, Integration::Full, &c),
                        PointsPass {
                            thickness: 0.3,
                            mat: &elastic(),
                            committed: &committed,
                            u: &u,
                            f: &mut f,
                            k: Some(&mut k),
                            trial: &mut trial,
                            out: &mut out,
                            time: &TimeContext::default(),
                            imposed: &[],
                            blocks,
                        },
                    )
                    .unwrap();
                    (f, k)
                };
                let (f_all, k_all) = run(NodeBlocks::ALL);
                let (f_some, k_some) = run(blocks);
                assert_eq!(f_all, f_some);
                for r in 0..nd {
                    for s in 0..nd {
                        let want = if blocks.has(r / 2, s / 2) {
                            k_all[r * nd + s]
                        } else {
                            0.0
                        };
                        assert_eq!(k_some[r * nd + s].to_bits(), want.to_bits(), "{kind:?}");
                    }
                }
            }
        }
    }

    /// The TL tangent is the derivative of the TL internal force: central differences at
    /// random displacement states with gradients of a few per cent (strains and rotations
    /// well beyond the linear range). Central differences with step 1e-7 m on displacements
    /// of ~1e-2 m have a truncation error ~1e-14 relative plus round-off ~1e-16/1e-7·‖f‖:
    /// 1e-6 of the tangent's largest entry is far above both and far below any
    /// missing or wrong term (the initial-stress matrix alone is ~1e-2 of it here).
    #[test]
    fn tangent_matches_central_differences() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        for kind in KINDS {
            let nd = 2 * kind.n_nodes();
            for _ in 0..4 {
                let u: Vec<f64> = (0..nd).map(|_| 0.02 * rand(&mut seed)).collect();
                let (_, k, _) = tl(kind, &u, true);
                let kmax = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let step = 1e-7;
                for j in 0..nd {
                    let (mut up, mut um) = (u.clone(), u.clone());
                    up[j] += step;
                    um[j] -= step;
                    let (fp, _, _) = tl(kind, &up, false);
                    let (fm, _, _) = tl(kind, &um, false);
                    for i in 0..nd {
                        let fd = (fp[i] - fm[i]) / (2.0 * step);
                        assert!(
                            (k[i * nd + j] - fd).abs() < 1e-6 * kmax,
                            "{kind:?} K[{i}][{j}] = {} vs FD {fd}",
                            k[i * nd + j]
                        );
                    }
                }
                // An elastic law derives from a strain energy: its TL tangent is symmetric.
                for i in 0..nd {
                    for j in 0..i {
                        assert!((k[i * nd + j] - k[j * nd + i]).abs() < 1e-9 * kmax);
                    }
                }
            }
        }
    }

    /// A rigid rotation by 30° (u = (R − I) X) strains nothing with the TL kinematics: zero
    /// Green strain, stress and nodal forces to round-off. The linear elements see a
    /// spurious strain of cos 30° − 1 ≈ −0.134 in both directions and large forces.
    #[test]
    fn rigid_rotation_is_stress_free() {
        let th = 30f64.to_radians();
        let (c, s) = (th.cos(), th.sin());
        for kind in KINDS {
            let x = coords(kind);
            let u: Vec<f64> = x
                .iter()
                .flat_map(|p| [c * p[0] - s * p[1] - p[0], s * p[0] + c * p[1] - p[1]])
                .collect();
            let (f, _, out) = tl(kind, &u, false);
            for o in &out {
                for v in o.strain {
                    assert!(v.abs() < 1e-14, "{kind:?} strain {v}");
                }
                for v in o.stress {
                    // E ~ 3e10 Pa times round-off 1e-15: ~1e-4 Pa.
                    assert!(v.abs() < 1e-3, "{kind:?} stress {v}");
                }
            }
            assert!(f.iter().all(|v| v.abs() < 1e-3), "{kind:?} f = {f:?}");
            // The geometrically linear element does not pass this test.
            let nd = u.len();
            let ngp = rule_points(kind, Integration::Full).len();
            let committed = vec![PointState::Elastic; ngp];
            let (mut trial, mut out) = (committed.clone(), vec![GaussOutput::default(); ngp]);
            let mut fl = vec![0.0; nd];
            response_at(
                kind,
                &gauss_geometry(kind, Integration::Full, &x),
                PointsPass {
                    thickness: 0.3,
                    mat: &elastic(),
                    committed: &committed,
                    u: &u,
                    f: &mut fl,
                    k: None,
                    trial: &mut trial,
                    out: &mut out,
                    time: &TimeContext::default(),
                    imposed: &[],
                    blocks: NodeBlocks::ALL,
                },
            )
            .unwrap();
            assert!((out[0].strain[0] - (c - 1.0)).abs() < 1e-12);
            assert!(fl.iter().fold(0.0f64, |m, v| m.max(v.abs())) > 1e8);
        }
    }

    /// Small displacements: the TL element reduces to the linear one (difference of second
    /// order in the displacement gradient, here 1e-6 → relative 1e-6).
    #[test]
    fn small_displacements_match_the_linear_element() {
        let mut seed = 7u64;
        for kind in KINDS {
            let nd = 2 * kind.n_nodes();
            let u: Vec<f64> = (0..nd).map(|_| 1e-6 * rand(&mut seed)).collect();
            let (f, _, _) = tl(kind, &u, false);
            let ngp = rule_points(kind, Integration::Full).len();
            let committed = vec![PointState::Elastic; ngp];
            let (mut trial, mut out) = (committed.clone(), vec![GaussOutput::default(); ngp]);
            let mut fl = vec![0.0; nd];
            response_at(
                kind,
                &gauss_geometry(kind, Integration::Full, &coords(kind)),
                PointsPass {
                    thickness: 0.3,
                    mat: &elastic(),
                    committed: &committed,
                    u: &u,
                    f: &mut fl,
                    k: None,
                    trial: &mut trial,
                    out: &mut out,
                    time: &TimeContext::default(),
                    imposed: &[],
                    blocks: NodeBlocks::ALL,
                },
            )
            .unwrap();
            let fmax = fl.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in f.iter().zip(&fl) {
                assert!((a - b).abs() < 1e-5 * fmax, "{kind:?}: {a} vs {b}");
            }
        }
    }
}
