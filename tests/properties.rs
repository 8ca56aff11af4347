//! Property tests of every element and material (issue #8 item 2): rigid-body motions give
//! no internal force, tangents agree with central finite differences of the internal force
//! (elements) or of the stress update (materials), tangents are symmetric where the theory
//! says so, and results are invariant under a rotation of the model.
//!
//! The concrete material already has finite-difference tangent tests in its elastic, plastic
//! and cracked ranges (src/materials/concrete/tests.rs); here it gets the element-level,
//! symmetry and rotation properties those do not cover.
//!
//! Tolerances are stated beside each check. Central differences with step h have truncation
//! error O(h²·f''') and round-off O(ε_mach·|f|/h); the steps below are chosen so that both
//! are several orders below the tolerance, while a wrong tangent term (a missing geometric
//! stiffness, a sign, a wrong hardening modulus) is of the order of the tangent itself.

use proptest::prelude::*;
use proptest::test_runner::{FileFailurePersistence, RngAlgorithm, RngSeed};
use segfem::elements::bar::{add_bar_point, bar_strain, BarPoint};
use segfem::elements::continuum::{response, GaussOutput, Integration};
use segfem::elements::interface::{InterfaceElement, InterfaceParams};
use segfem::elements::tendon::{DeviatorMode, ExternalTendon, TendonLaw};
use segfem::materials::concrete::{self, ConcreteParams, ConcreteState};
use segfem::materials::point::{update, Material, PointState};
use segfem::materials::steel::{update_uniaxial, HardeningRule, SteelParams, SteelState};
use segfem::model::ElementKind;
use std::cell::Cell;

// ------------------------------------------------------------------------------------------
// Helpers
// ------------------------------------------------------------------------------------------

/// Every property runs from one fixed seed (ChaCha: the same cases on every machine and
/// every run), and a failing case is saved to `proptest-regressions/properties.txt`, which
/// is committed and replayed before the generated cases. `PROPTEST_CASES` and
/// `PROPTEST_RNG_SEED` still override both for exploration.
fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        rng_algorithm: RngAlgorithm::ChaCha,
        rng_seed: RngSeed::Fixed(0x5e6f_e025),
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/proptest-regressions/properties.txt"
        )))),
        ..ProptestConfig::default()
    }
}

/// Fewest of the 64 cases whose finite-difference comparison must run (the rest hit a
/// regime switch inside the stencil and are skipped): well below the count the fixed seed
/// gives, so a change of the generators that skips most cases fails.
const MIN_PLASTIC: usize = 48;
const MIN_INTERFACE: usize = 48;
const MIN_TENDON: usize = 48;
const MIN_BAR: usize = 48;

fn rot(a: f64, v: [f64; 2]) -> [f64; 2] {
    let (s, c) = a.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

/// Rotate an interleaved (x, y) vector node by node.
fn rot_vec(a: f64, v: &[f64]) -> Vec<f64> {
    v.chunks(2).flat_map(|c| rot(a, [c[0], c[1]])).collect()
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Rotate an engineering strain (εx, εy, γxy) by angle a (tensor rotation R ε Rᵀ).
fn rot_strain(a: f64, e: [f64; 3]) -> [f64; 3] {
    let (s, c) = a.sin_cos();
    let (ex, ey, exy) = (e[0], e[1], 0.5 * e[2]);
    [
        c * c * ex + s * s * ey - 2.0 * s * c * exy,
        s * s * ex + c * c * ey + 2.0 * s * c * exy,
        2.0 * (s * c * (ex - ey) + (c * c - s * s) * exy),
    ]
}

/// Rotate a stress (σx, σy, τxy) by angle a.
fn rot_stress(a: f64, t: [f64; 3]) -> [f64; 3] {
    let e = rot_strain(a, [t[0], t[1], 2.0 * t[2]]);
    [e[0], e[1], 0.5 * e[2]]
}

/// Nodes of a distorted quadrilateral in VTK order: corners of a `w` × `h` rectangle moved by
/// up to 15 % of the size (`d` in [−1, 1]), mid-edge nodes on the straight edges moved along
/// the edge by up to 10 % (`m`), centre at the corner mean (Q9). Convex by construction, so
/// det J > 0.
fn quad_nodes(kind: ElementKind, w: f64, h: f64, d: &[f64; 8], m: &[f64; 4]) -> Vec<[f64; 2]> {
    let c0 = [[0.0, 0.0], [w, 0.0], [w, h], [0.0, h]];
    let c: Vec<[f64; 2]> = (0..4)
        .map(|i| {
            [
                c0[i][0] + 0.15 * w * d[2 * i],
                c0[i][1] + 0.15 * h * d[2 * i + 1],
            ]
        })
        .collect();
    let mut x = c.clone();
    if kind != ElementKind::Q4 {
        for i in 0..4 {
            let (a, b) = (c[i], c[(i + 1) % 4]);
            let t = 0.5 + 0.1 * m[i];
            x.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
        }
    }
    if kind == ElementKind::Q9 {
        let mut ctr = [0.0; 2];
        for p in &c {
            ctr[0] += 0.25 * p[0];
            ctr[1] += 0.25 * p[1];
        }
        x.push(ctr);
    }
    x
}

fn kinds() -> impl Strategy<Value = ElementKind> {
    prop_oneof![
        Just(ElementKind::Q4),
        Just(ElementKind::Q8),
        Just(ElementKind::Q9)
    ]
}

fn integrations() -> impl Strategy<Value = Integration> {
    prop_oneof![Just(Integration::Full), Just(Integration::Reduced)]
}

const E: f64 = 30e9;
const FCM: f64 = 38e6;

fn elastic() -> Material {
    Material::Elastic {
        e: E,
        nu: 0.2,
        density: 0.0,
    }
}

fn concrete_params() -> ConcreteParams {
    let mut p = ConcreteParams::from_mc90(FCM, 0.2);
    // Zero residual stiffness: stress-free regimes then have a consistent (zero) tangent too.
    p.residual_stiffness = 0.0;
    p
}

fn concrete() -> Material {
    Material::Concrete {
        params: Box::new(concrete_params()),
        density: 0.0,
    }
}

/// Element response (f, K row-major) from the given committed states.
fn element(
    kind: ElementKind,
    integ: Integration,
    x: &[[f64; 2]],
    mat: &Material,
    committed: &[PointState],
    u: &[f64],
) -> (Vec<f64>, Vec<f64>, Vec<PointState>, Vec<GaussOutput>) {
    let nd = 2 * kind.n_nodes();
    let mut f = vec![0.0; nd];
    let mut k = vec![0.0; nd * nd];
    let mut trial = committed.to_vec();
    let mut out = vec![GaussOutput::default(); committed.len()];
    response(
        kind, integ, x, 0.3, mat, committed, u, &mut f, &mut k, &mut trial, &mut out,
    )
    .expect("element update");
    (f, k, trial, out)
}

fn fresh_states(kind: ElementKind, integ: Integration, mat: &Material) -> Vec<PointState> {
    let n = segfem::elements::continuum::rule_points(kind, integ).len();
    vec![mat.initial_state(); n]
}

/// Displacements of a homogeneous strain field ε (εx, εy, γxy) plus a rigid motion.
fn homogeneous(x: &[[f64; 2]], e: [f64; 3], t: [f64; 2], theta: f64) -> Vec<f64> {
    x.iter()
        .flat_map(|p| {
            [
                e[0] * p[0] + 0.5 * e[2] * p[1] + t[0] - theta * p[1],
                e[1] * p[1] + 0.5 * e[2] * p[0] + t[1] + theta * p[0],
            ]
        })
        .collect()
}

/// Max |K_fd − K| over all entries, with K_fd from central differences of f(u) with step h.
fn fd_gap(
    f_of: &mut dyn FnMut(&[f64]) -> Option<Vec<f64>>,
    u: &[f64],
    k: &[f64],
    h: f64,
) -> Option<f64> {
    let nd = u.len();
    let mut gap: f64 = 0.0;
    for j in 0..nd {
        let mut up = u.to_vec();
        let mut um = u.to_vec();
        up[j] += h;
        um[j] -= h;
        let fp = f_of(&up)?;
        let fm = f_of(&um)?;
        for i in 0..nd {
            gap = gap.max(((fp[i] - fm[i]) / (2.0 * h) - k[i * nd + j]).abs());
        }
    }
    Some(gap)
}

fn asymmetry(k: &[f64], nd: usize) -> f64 {
    let mut a: f64 = 0.0;
    for i in 0..nd {
        for j in 0..i {
            a = a.max((k[i * nd + j] - k[j * nd + i]).abs());
        }
    }
    a
}

// ------------------------------------------------------------------------------------------
// Continuum elements Q4, Q8, Q9
// ------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(config(64))]

    /// Rigid-body motion (translation + infinitesimal rotation: the exact null space of the
    /// small-strain B) gives zero strain, zero stress and zero internal force, for elastic and
    /// concrete material. Tolerance 1e-9 of the force of a unit strain (E t L ≈ 1e10 N): the
    /// strain of a rigid motion is round-off, ε_mach × |u|/L.
    #[test]
    fn continuum_rigid_body_gives_no_force(
        kind in kinds(), integ in integrations(),
        d in prop::array::uniform8(-1.0..1.0f64), m in prop::array::uniform4(-1.0..1.0f64),
        w in 0.05..2.0f64, h in 0.05..2.0f64,
        t in prop::array::uniform2(-1e-2..1e-2f64), theta in -1e-3..1e-3f64,
        conc in any::<bool>(),
    ) {
        let x = quad_nodes(kind, w, h, &d, &m);
        let mat = if conc { concrete() } else { elastic() };
        let st = fresh_states(kind, integ, &mat);
        let u = homogeneous(&x, [0.0; 3], t, theta);
        let (f, _, trial, _) = element(kind, integ, &x, &mat, &st, &u);
        let scale = E * 0.3 * w.max(h);
        prop_assert!(max_abs(&f) < 1e-9 * scale, "f = {f:?}");
        // A rigid motion must not crack concrete either (nor crush it by round-off strains:
        // see `concrete_round_off_strain_does_not_crush`).
        prop_assert!(trial.iter().all(|s| s.n_cracks() == 0 && !s.is_crushed()));
    }

    /// Elastic element: the tangent is the exact derivative of the internal force (the force
    /// is linear in u, so central differences are exact up to round-off: tolerance 1e-7 of
    /// max |K|) and symmetric (B^T D B with symmetric D: 1e-12 of max |K|).
    #[test]
    fn continuum_elastic_tangent_fd_and_symmetric(
        kind in kinds(), integ in integrations(),
        d in prop::array::uniform8(-1.0..1.0f64), m in prop::array::uniform4(-1.0..1.0f64),
        w in 0.05..2.0f64, h in 0.05..2.0f64,
        e in prop::array::uniform3(-1e-3..1e-3f64),
    ) {
        let x = quad_nodes(kind, w, h, &d, &m);
        let mat = elastic();
        let st = fresh_states(kind, integ, &mat);
        let u = homogeneous(&x, e, [0.0; 2], 0.0);
        let (_, k, _, _) = element(kind, integ, &x, &mat, &st, &u);
        let kmax = max_abs(&k);
        let nd = u.len();
        prop_assert!(asymmetry(&k, nd) <= 1e-12 * kmax);
        let step = 1e-6 * w.min(h);
        let gap = fd_gap(&mut |v| Some(element(kind, integ, &x, &mat, &st, v).0), &u, &k, step);
        prop_assert!(gap.unwrap() < 1e-7 * kmax, "gap {gap:?} of {kmax}");
    }

}

/// Concrete element in the plastic (hardening) compression range: from a committed plastic
/// state, a further homogeneous compressive strain; the element tangent (consistent,
/// symmetric with associated flow) must match central differences of the internal force.
/// Tolerance 1e-4 of max |K|: the point-level check allows 1e-5 E at h = 1e-8 in strain;
/// here h = 1e-9 L in displacement gives strains of O(1e-9) and the same bound relative to
/// the element stiffness, with margin for the nonlinear Ottosen surface. Perturbations
/// that switch the regime of any point are skipped.
#[test]
fn continuum_concrete_plastic_tangent_fd() {
    let ran = Cell::new(0usize);
    proptest!(config(64), |(
        kind in kinds(),
        d in prop::array::uniform8(-1.0..1.0f64), m in prop::array::uniform4(-1.0..1.0f64),
        ex in -1.8e-3..-6e-4f64, ry in -0.6..0.2f64, rg in -0.4..0.4f64, f1 in 0.5..0.9f64,
    )| {
        let integ = Integration::Full;
        let x = quad_nodes(kind, 0.2, 0.2, &d, &m);
        let mat = concrete();
        let st0 = fresh_states(kind, integ, &mat);
        let e_end = [ex, ry * ex.abs(), rg * ex.abs()];
        let u1 = homogeneous(&x, e_end.map(|v| v * f1), [0.0; 2], 0.0);
        let (_, _, c, _) = element(kind, integ, &x, &mat, &st0, &u1);
        prop_assume!(c.iter().all(|s| s.n_cracks() == 0 && !s.is_crushed()));
        let u = homogeneous(&x, e_end, [0.0; 2], 0.0);
        let (_, k, t0, _) = element(kind, integ, &x, &mat, &c, &u);
        let sig = |t: &[PointState]| -> Vec<(usize, bool, bool)> {
            t.iter().zip(&c).map(|(a, b)| {
                let (a, b) = (a.concrete().unwrap(), b.concrete().unwrap());
                (a.n_cracks(), a.is_crushed(), a.curve_strain() > b.curve_strain())
            }).collect()
        };
        let s0 = sig(&t0);
        // Only the hardening (pre-peak, plastic) branch: every point loading plastically.
        prop_assume!(s0.iter().all(|s| s.0 == 0 && !s.1 && s.2));
        let kmax = max_abs(&k);
        let nd = u.len();
        prop_assert!(asymmetry(&k, nd) <= 1e-9 * kmax, "plastic tangent not symmetric");
        let gap = fd_gap(&mut |v| {
            let r = element(kind, integ, &x, &mat, &c, v);
            (sig(&r.2) == s0).then_some(r.0)
        }, &u, &k, 2e-10);
        if let Some(g) = gap {
            ran.set(ran.get() + 1);
            prop_assert!(g < 1e-4 * kmax, "gap {g} of {kmax}");
        }
    });
    // A stencil that switches a point's regime is skipped; most must compare.
    eprintln!("FD cases: {}", ran.get());
    assert!(
        ran.get() >= MIN_PLASTIC,
        "only {} of 64 cases compared with finite differences",
        ran.get()
    );
}

proptest! {
    #![proptest_config(config(64))]


    /// Rotating the whole model (coordinates and displacements) rotates the internal forces
    /// and leaves their norm and the principal stresses unchanged: the element formulation
    /// and the materials are isotropic. Concrete is loaded into cracking or plasticity from a
    /// virgin state, so the crack direction must rotate with the model too. Tolerance 1e-9
    /// relative (round-off of the rotated geometry).
    #[test]
    fn continuum_rotation_invariance(
        kind in kinds(), integ in integrations(),
        d in prop::array::uniform8(-1.0..1.0f64), m in prop::array::uniform4(-1.0..1.0f64),
        e in prop::array::uniform3(-2e-3..4e-4f64), a in -3.2..3.2f64, conc in any::<bool>(),
        ua in prop::collection::vec(-1e-4..1e-4f64, 18),
    ) {
        let x = quad_nodes(kind, 0.3, 0.25, &d, &m);
        let mat = if conc { concrete() } else { elastic() };
        let st = fresh_states(kind, integ, &mat);
        let mut u = homogeneous(&x, e, [0.0; 2], 0.0);
        for (ui, r) in u.iter_mut().zip(&ua) {
            *ui += r;
        }
        let (f, _, _, out) = element(kind, integ, &x, &mat, &st, &u);
        let xr: Vec<[f64; 2]> = x.iter().map(|p| rot(a, *p)).collect();
        let ur = rot_vec(a, &u);
        let (fr, _, _, outr) = element(kind, integ, &xr, &mat, &st, &ur);
        let fmax = max_abs(&f).max(1.0);
        prop_assert!((norm(&f) - norm(&fr)).abs() < 1e-9 * fmax);
        let f_back = rot_vec(a, &f);
        for (p, q) in f_back.iter().zip(&fr) {
            prop_assert!((p - q).abs() < 1e-8 * fmax, "{f_back:?} vs {fr:?}");
        }
        for (o, r) in out.iter().zip(&outr) {
            let s = rot_stress(a, o.stress);
            let smax = max_abs(&o.stress).max(1.0);
            for i in 0..3 {
                prop_assert!((s[i] - r.stress[i]).abs() < 1e-8 * smax, "{s:?} vs {:?}", r.stress);
            }
        }
    }
}

// ------------------------------------------------------------------------------------------
// Interface (joint) element
// ------------------------------------------------------------------------------------------

/// Coincident (match-cast) faces of a joint from p0 to p1: face A start, end, [mid]; face B
/// the same points (n = 2 or 3 nodes).
fn joint_faces(p0: [f64; 2], p1: [f64; 2], n: usize) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let mut a = vec![p0, p1];
    if n == 3 {
        a.push([0.5 * (p0[0] + p1[0]), 0.5 * (p0[1] + p1[1])]);
    }
    (a.clone(), a)
}

fn joint_params(kind: u8, lobatto: bool) -> InterfaceParams {
    let mut p = match kind {
        0 => InterfaceParams::dry(1e12, 4e11, 0.6),
        1 => InterfaceParams::keyed(1e12, 4e11),
        _ => InterfaceParams::epoxy(1e12, 4e11, 0.6, 2e6, 3e6),
    };
    p.lobatto = lobatto;
    p.residual_ratio = 1e-6;
    p
}

proptest! {
    #![proptest_config(config(64))]

    /// A rigid motion of both faces together (translation + infinitesimal rotation) leaves
    /// the relative displacement of coincident points zero: no traction, no force. Tolerance
    /// 1e-9 of K_n t L |u|: the relative displacement is round-off of the interpolation.
    #[test]
    fn interface_rigid_body_gives_no_force(
        n in 2usize..=3, kind in 0u8..3, lobatto in any::<bool>(),
        p0 in prop::array::uniform2(-1.0..1.0f64), a in -3.2..3.2f64, len in 0.1..2.0f64,
        t in prop::array::uniform2(-1e-3..1e-3f64), theta in -1e-3..1e-3f64,
    ) {
        let p1 = [p0[0] + len * a.cos(), p0[1] + len * a.sin()];
        let (fa, fb) = joint_faces(p0, p1, n);
        let prm = joint_params(kind, lobatto);
        let el = InterfaceElement::new(&fa, &fb, &prm).unwrap();
        let u: Vec<f64> = fa.iter().chain(&fb)
            .flat_map(|p| [t[0] - theta * p[1], t[1] + theta * p[0]]).collect();
        let r = el.response(&prm, 0.3, &u, &el.initial_states(&prm));
        let scale = prm.kn * 0.3 * len * 1e-3;
        prop_assert!(max_abs(&r.f_int) < 1e-9 * scale, "{:?}", r.f_int);
    }

}

/// Tangent against central differences of the internal force, from a committed state
/// reached by a first relative displacement (closing, opening, sliding, debonding), for
/// dry, keyed and epoxy joints. The law is piecewise linear, so away from a regime switch
/// central differences are exact up to round-off: tolerance 1e-6 of max |K|; stencils that
/// change a point's regime are skipped. The tangent is symmetric whenever the element
/// reports it (`symmetric`: no sliding point).
#[test]
fn interface_tangent_fd_and_symmetry() {
    let ran = Cell::new(0usize);
    proptest!(config(64), |(
        n in 2usize..=3, kind in 0u8..3, lobatto in any::<bool>(),
        a in -3.2..3.2f64,
        du1 in prop::collection::vec(-2e-5..2e-5f64, 12),
        du2 in prop::collection::vec(-2e-5..2e-5f64, 12),
    )| {
        let p1 = [0.6 * a.cos(), 0.6 * a.sin()];
        let (fa, fb) = joint_faces([0.0, 0.0], p1, n);
        let prm = joint_params(kind, lobatto);
        let el = InterfaceElement::new(&fa, &fb, &prm).unwrap();
        let nd = el.n_dofs();
        let c0 = el.initial_states(&prm);
        let u1 = &du1[..nd];
        let c = el.response(&prm, 0.3, u1, &c0).states;
        let u: Vec<f64> = u1.iter().zip(&du2).map(|(x, y)| x + y).collect();
        let r = el.response(&prm, 0.3, &u, &c);
        let regime = |s: &[segfem::elements::interface::InterfacePointState]| -> Vec<(bool, bool, bool)> {
            s.iter().map(|p| (p.bonded, p.closed, p.sliding)).collect()
        };
        let g0 = regime(&r.states);
        let kmax = max_abs(&r.k).max(1.0);
        if r.symmetric {
            prop_assert!(asymmetry(&r.k, nd) <= 1e-12 * kmax);
        }
        let gap = fd_gap(&mut |v| {
            let rr = el.response(&prm, 0.3, v, &c);
            (regime(&rr.states) == g0).then_some(rr.f_int)
        }, &u, &r.k, 1e-10);
        if let Some(g) = gap {
            ran.set(ran.get() + 1);
            prop_assert!(g < 1e-6 * kmax, "gap {g} of {kmax}");
        }
    });
    // A stencil that switches a point's regime is skipped; most must compare.
    eprintln!("FD cases: {}", ran.get());
    assert!(
        ran.get() >= MIN_INTERFACE,
        "only {} of 64 cases compared with finite differences",
        ran.get()
    );
}

proptest! {
    #![proptest_config(config(64))]


    /// Rotating the joint and its displacements rotates the forces (norm unchanged).
    /// Tolerance 1e-8 relative (round-off of the rotated geometry and projection).
    #[test]
    fn interface_rotation_invariance(
        n in 2usize..=3, kind in 0u8..3, a in -3.2..3.2f64, b in -3.2..3.2f64,
        du in prop::collection::vec(-2e-5..2e-5f64, 12),
    ) {
        let p1 = [0.6 * a.cos(), 0.6 * a.sin()];
        let (fa, fb) = joint_faces([0.1, 0.2], [0.1 + p1[0], 0.2 + p1[1]], n);
        let prm = joint_params(kind, true);
        let el = InterfaceElement::new(&fa, &fb, &prm).unwrap();
        let nd = el.n_dofs();
        let u = &du[..nd];
        let r = el.response(&prm, 0.3, u, &el.initial_states(&prm));
        let far: Vec<[f64; 2]> = fa.iter().map(|p| rot(b, *p)).collect();
        let fbr: Vec<[f64; 2]> = fb.iter().map(|p| rot(b, *p)).collect();
        let elr = InterfaceElement::new(&far, &fbr, &prm).unwrap();
        let rr = elr.response(&prm, 0.3, &rot_vec(b, u), &elr.initial_states(&prm));
        let fmax = max_abs(&r.f_int).max(1.0);
        for (p, q) in rot_vec(b, &r.f_int).iter().zip(&rr.f_int) {
            prop_assert!((p - q).abs() < 1e-8 * fmax);
        }
    }
}

// ------------------------------------------------------------------------------------------
// External tendon
// ------------------------------------------------------------------------------------------

fn tendon_modes() -> impl Strategy<Value = DeviatorMode> {
    prop_oneof![
        Just(DeviatorMode::Held),
        Just(DeviatorMode::Frictionless),
        (0.0..0.3f64).prop_map(|mu| DeviatorMode::Friction { mu }),
    ]
}

/// Anchor – deviators – anchor polygon of a draped tendon over a span L.
fn tendon_points(l: f64, sag: &[f64]) -> Vec<[f64; 2]> {
    let n = sag.len() + 2;
    (0..n)
        .map(|i| {
            let x = l * i as f64 / (n - 1) as f64;
            let y = if i == 0 || i == n - 1 {
                0.0
            } else {
                -sag[i - 1]
            };
            [x, y]
        })
        .collect()
}

proptest! {
    #![proptest_config(config(64))]

    /// Finite rigid motions (any rotation angle: the tendon is geometrically exact) keep every
    /// span length, so the span forces are unchanged and the nodal forces of a prestressed
    /// tendon just rotate; with no prestress they vanish. The nodal forces are self-balanced
    /// (zero resultant and moment) whatever the motion. Tolerances 1e-9 relative to the
    /// prestress force (lengths change by round-off only).
    #[test]
    fn tendon_rigid_body(
        mode in tendon_modes(), sag in prop::collection::vec(0.05..0.5f64, 0..3),
        sigma0 in prop_oneof![Just(0.0), 5e8..1.2e9f64],
        a in -3.2..3.2f64, t in prop::array::uniform2(-1.0..1.0f64),
    ) {
        let pts = tendon_points(6.0, &sag);
        let law = TendonLaw::prestressing_steel(1.86e9);
        let tdn = ExternalTendon::new(&pts, 1e-3, 195e9, sigma0, law, mode).unwrap();
        let c = tdn.initial_state();
        let zero = vec![[0.0; 2]; pts.len()];
        let r0 = tdn.response(&zero, &c);
        let u: Vec<[f64; 2]> = pts.iter().map(|p| {
            let q = rot(a, *p);
            [q[0] - p[0] + t[0], q[1] - p[1] + t[1]]
        }).collect();
        let r = tdn.response(&u, &c);
        let fref = 1e-3 * sigma0.max(1e6);
        for (s0, s) in r0.state.spans.iter().zip(&r.state.spans) {
            prop_assert!((s0.force - s.force).abs() < 1e-9 * fref);
        }
        let rotated = rot_vec(a, &r0.f_int);
        for (p, q) in rotated.iter().zip(&r.f_int) {
            prop_assert!((p - q).abs() < 1e-9 * fref, "{rotated:?} vs {:?}", r.f_int);
        }
        if sigma0 == 0.0 {
            prop_assert!(max_abs(&r.f_int) < 1e-9 * fref);
        }
        // Equilibrium of the nodal forces in the moved configuration.
        let (mut fx, mut fy, mut mz) = (0.0, 0.0, 0.0);
        for (i, p) in pts.iter().enumerate() {
            let x = [p[0] + u[i][0], p[1] + u[i][1]];
            let (gx, gy) = (r.f_int[2 * i], r.f_int[2 * i + 1]);
            fx += gx;
            fy += gy;
            mz += x[0] * gy - x[1] * gx;
        }
        prop_assert!(fx.abs() < 1e-9 * fref && fy.abs() < 1e-9 * fref && mz.abs() < 1e-8 * fref);
    }

}

/// Tangent (material + geometric stiffness, deviator coupling) against central differences
/// of the internal force, elastic and elastic–plastic steel, all deviator modes, from a
/// committed state after a first displacement. Step h = 1e-6 m on spans of metres: the
/// truncation error (geometric term, f''' ≈ N/L³ ≈ 1e5 N/m³) is h²·1e5 ≈ 1e-7 N/m, the
/// round-off ε|N|/h ≈ 2e-16 · 1e6 N / 1e-6 m ≈ 2e-4 N/m and the quantisation of h at
/// coordinates of 6 m (ulp 9e-16 m) 1e-9 of K; tolerance 1e-6 of max |K| (> E A / L ≈ 1e8
/// N/m). A smaller h (1e-9 m, used before) makes the quantisation alone 1e-6 of K. Stencils
/// that change a deviator's stick/slip flag, yield a span or cross a span's slack point
/// are skipped. Symmetric when the element reports it (no slipping friction deviator).
#[test]
fn tendon_tangent_fd_and_symmetry() {
    let ran = Cell::new(0usize);
    proptest!(config(64), |(
        mode in tendon_modes(), sag in prop::collection::vec(0.05..0.5f64, 1..3),
        plastic in any::<bool>(), sigma0 in 8e8..1.3e9f64,
        du1 in prop::collection::vec(-4e-3..4e-3f64, 8),
        du2 in prop::collection::vec(-4e-3..4e-3f64, 8),
    )| {
        let pts = tendon_points(6.0, &sag);
        let law = if plastic {
            TendonLaw::from_steel(&SteelParams { es: 195e9, fy: 1.4e9, hardening: 5e9, fu: f64::INFINITY, rule: HardeningRule::Isotropic })
        } else {
            TendonLaw::Elastic
        };
        let tdn = ExternalTendon::new(&pts, 1e-3, 195e9, sigma0, law, mode).unwrap();
        let np = pts.len();
        let to_u = |v: &[f64]| -> Vec<[f64; 2]> { v.chunks(2).map(|c| [c[0], c[1]]).collect() };
        let c = tdn.response(&to_u(&du1[..2 * np]), &tdn.initial_state()).state;
        let u: Vec<f64> = du1[..2 * np].iter().zip(&du2).map(|(a, b)| a + b).collect();
        let r = tdn.response(&to_u(&u), &c);
        // Regime: stick/slip flags, and per span yielding and slack (the law's kink at zero
        // stress); a stencil across any of them has no derivative to compare.
        let regime = |s: &segfem::elements::tendon::TendonState| -> (Vec<i8>, Vec<(bool, bool)>) {
            (s.slipping.clone(),
             s.spans.iter().zip(&c.spans)
                .map(|(a, b)| (a.law.plastic_strain != b.law.plastic_strain, a.stress > 0.0))
                .collect())
        };
        let g0 = regime(&r.state);
        let nd = 2 * np;
        let kmax = max_abs(&r.k).max(1.0);
        if r.symmetric {
            prop_assert!(asymmetry(&r.k, nd) <= 1e-10 * kmax);
        }
        let gap = fd_gap(&mut |v| {
            let rr = tdn.response(&to_u(v), &c);
            (regime(&rr.state) == g0).then_some(rr.f_int)
        }, &u, &r.k, 1e-6);
        if let Some(g) = gap {
            ran.set(ran.get() + 1);
            prop_assert!(g < 1e-6 * kmax, "gap {g} of {kmax}");
        }
    });
    // A stencil that changes a stick/slip flag or yields a span is skipped; most must compare.
    eprintln!("FD cases: {}", ran.get());
    assert!(
        ran.get() >= MIN_TENDON,
        "only {} of 64 cases compared with finite differences",
        ran.get()
    );
}

// ------------------------------------------------------------------------------------------
// Embedded bar
// ------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(config(64))]

    /// A rigid motion of the host element gives no bar strain and so no bar force, whatever
    /// the bar's direction and position in the host. Tolerance 1e-12 (round-off of ∇N·u).
    #[test]
    fn bar_rigid_body_gives_no_strain(
        kind in kinds(),
        d in prop::array::uniform8(-1.0..1.0f64), m in prop::array::uniform4(-1.0..1.0f64),
        xi in -1.0..1.0f64, eta in -1.0..1.0f64, phi in -3.2..3.2f64,
        t in prop::array::uniform2(-1e-2..1e-2f64), theta in -1e-3..1e-3f64,
    ) {
        let x = quad_nodes(kind, 0.4, 0.3, &d, &m);
        let p = BarPoint { xi, eta, dir: [phi.cos(), phi.sin()], weight_length: 0.1, s: 0.0, x: [0.0; 2] };
        let u = homogeneous(&x, [0.0; 3], t, theta);
        prop_assert!(bar_strain(kind, &x, &p, &u).abs() < 1e-12);
    }

}

/// Bar tangent against central differences of the bar force, with the rebar law in its
/// elastic, hardening and perfectly plastic ranges; the bar stiffness gᵀ E_t A g is
/// symmetric. Tolerance 1e-6 of max |K| (the force is piecewise linear in u); stencils
/// that cross the yield point are skipped. Also: the strain of a homogeneous field along
/// the bar equals tᵀ ε t, which is invariant when bar and field are rotated together.
#[test]
fn bar_tangent_fd_and_rotation() {
    let ran = Cell::new(0usize);
    proptest!(config(64), |(
        kind in kinds(),
        d in prop::array::uniform8(-1.0..1.0f64), m in prop::array::uniform4(-1.0..1.0f64),
        xi in -1.0..1.0f64, eta in -1.0..1.0f64, phi in -3.2..3.2f64, a in -3.2..3.2f64,
        e in prop::array::uniform3(-4e-3..4e-3f64), hard in any::<bool>(),
    )| {
        let x = quad_nodes(kind, 0.4, 0.3, &d, &m);
        let p = BarPoint { xi, eta, dir: [phi.cos(), phi.sin()], weight_length: 0.1, s: 0.0, x: [0.0; 2] };
        let steel = if hard { SteelParams::rebar_hardening(200e9, 500e6, 2e9) } else { SteelParams::rebar(200e9, 500e6) };
        let u = homogeneous(&x, e, [0.0; 2], 0.0);
        let nd = u.len();
        let force = |v: &[f64]| -> (Vec<f64>, Vec<f64>, bool) {
            let eps = bar_strain(kind, &x, &p, v);
            let (st, s, et) = update_uniaxial(&steel, &SteelState::new(), eps);
            let mut f = vec![0.0; nd];
            let mut k = vec![0.0; nd * nd];
            add_bar_point(kind, &x, &p, 5e-4, s, et, &mut f, &mut k);
            (f, k, st.acc_plastic > 0.0)
        };
        let (_, k, yielded) = force(&u);
        // Floor at the elastic bar stiffness E A / L: on the perfectly plastic branch K = 0
        // and the finite-difference round-off (≈ A f_y · 1e-16 / 1e-10 m) is measured
        // against that scale.
        let kmax = max_abs(&k).max(200e9 * 5e-4 / 0.4);
        prop_assert!(asymmetry(&k, nd) <= 1e-12 * kmax);
        let gap = fd_gap(&mut |v| { let r = force(v); (r.2 == yielded).then_some(r.0) }, &u, &k, 1e-10);
        if let Some(g) = gap {
            ran.set(ran.get() + 1);
            prop_assert!(g < 1e-6 * kmax, "gap {g} of {kmax}");
        }
        // Rotation: bar direction and strain field rotated together.
        let eps = bar_strain(kind, &x, &p, &u);
        let xr: Vec<[f64; 2]> = x.iter().map(|q| rot(a, *q)).collect();
        let pr = BarPoint { dir: rot(a, p.dir), ..p };
        let ur = rot_vec(a, &u);
        let epsr = bar_strain(kind, &xr, &pr, &ur);
        prop_assert!((eps - epsr).abs() < 1e-12, "{eps} vs {epsr}");
    });
    // A stencil that crosses the yield point is skipped; most must compare.
    eprintln!("FD cases: {}", ran.get());
    assert!(
        ran.get() >= MIN_BAR,
        "only {} of 64 cases compared with finite differences",
        ran.get()
    );
}

// ------------------------------------------------------------------------------------------
// Materials: elastic, rebar, prestressing steel, concrete
// ------------------------------------------------------------------------------------------

/// Random uniaxial strain path (3 points) of the steel laws.
fn steel_params() -> impl Strategy<Value = SteelParams> {
    prop_oneof![
        Just(SteelParams::rebar(200e9, 500e6)),
        Just(SteelParams::rebar_hardening(200e9, 500e6, 2e9)),
        Just(SteelParams::prestressing(195e9, 1.86e9)),
        Just(SteelParams::prestressing_hardening(195e9, 1.86e9, 0.035)),
    ]
}

proptest! {
    #![proptest_config(config(128))]

    /// Elastic plane stress: tangent equals D (central differences exact for a linear map,
    /// tolerance 1e-6 E for round-off at h = 1e-9), D symmetric, and σ(R ε Rᵀ) = R σ Rᵀ
    /// (isotropy, tolerance 1e-9 of |σ|).
    #[test]
    fn elastic_material(e in prop::array::uniform3(-1e-3..1e-3f64), a in -3.2..3.2f64, nu in 0.0..0.45f64) {
        let mat = Material::Elastic { e: E, nu, density: 0.0 };
        let (_, s, d) = update(&mat, &PointState::Elastic, &e, 0.1).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                prop_assert_eq!(d[i][j], d[j][i]);
                let mut ep = e;
                let mut em = e;
                ep[j] += 1e-9;
                em[j] -= 1e-9;
                let sp = update(&mat, &PointState::Elastic, &ep, 0.1).unwrap().1;
                let sm = update(&mat, &PointState::Elastic, &em, 0.1).unwrap().1;
                prop_assert!(((sp[i] - sm[i]) / 2e-9 - d[i][j]).abs() < 1e-6 * E);
            }
        }
        let sr = update(&mat, &PointState::Elastic, &rot_strain(a, e), 0.1).unwrap().1;
        let want = rot_stress(a, s);
        for i in 0..3 {
            prop_assert!((sr[i] - want[i]).abs() < 1e-9 * max_abs(&s).max(1.0));
        }
    }

    /// Rebar and prestressing steel (with and without hardening and cap): along a random
    /// path of three strains (loading, reversal, reloading) the returned tangent equals the
    /// central difference of the stress, away from the kinks (tolerance 1e-6 E at h = 1e-10:
    /// the law is piecewise linear); the stress never exceeds the cap.
    #[test]
    fn steel_tangent_fd(p in steel_params(), path in prop::collection::vec(-0.03..0.03f64, 3)) {
        let mut c = SteelState::new();
        for &eps in &path {
            let (t, s, et) = update_uniaxial(&p, &c, eps);
            prop_assert!(s.abs() <= p.fu * (1.0 + 1e-12));
            let h = 1e-10;
            let (tp, sp, _) = update_uniaxial(&p, &c, eps + h);
            let (tm, sm, _) = update_uniaxial(&p, &c, eps - h);
            let same = |a: &SteelState| (a.acc_plastic > c.acc_plastic) == (t.acc_plastic > c.acc_plastic)
                && (a.back_stress.abs() >= p.fu - p.fy) == (t.back_stress.abs() >= p.fu - p.fy);
            if same(&tp) && same(&tm) {
                prop_assert!(((sp - sm) / (2.0 * h) - et).abs() < 1e-6 * p.es, "eps {eps}: fd {} vs {et}", (sp - sm) / (2.0 * h));
            }
            c = t;
        }
    }

    /// Tendon steel law (elastic–plastic with isotropic hardening, no compression): tangent
    /// against central differences, as above.
    #[test]
    fn tendon_law_tangent_fd(path in prop::collection::vec(-0.01..0.03f64, 3), hard in 0.0..1e10f64) {
        let law = TendonLaw::from_steel(&SteelParams { es: 195e9, fy: 1.674e9, hardening: hard, fu: f64::INFINITY, rule: HardeningRule::Isotropic });
        let mut c = Default::default();
        for &eps in &path {
            let (s, et, st) = law.update(195e9, eps, &c);
            prop_assert!(s >= 0.0, "a tendon carries no compression");
            let h = 1e-10;
            let (sp, _, stp) = law.update(195e9, eps + h, &c);
            let (sm, _, stm) = law.update(195e9, eps - h, &c);
            let yielded = |x: &segfem::materials::steel::SteelState| x.plastic_strain != c.plastic_strain;
            let slack = |v: f64| v <= 0.0;
            if yielded(&stp) == yielded(&st) && yielded(&stm) == yielded(&st)
                && slack(sp) == slack(s) && slack(sm) == slack(s) {
                prop_assert!(((sp - sm) / (2.0 * h) - et).abs() < 1e-6 * 195e9);
            }
            c = st;
        }
    }

    /// Concrete from the virgin state is isotropic: σ(R ε Rᵀ) = R σ(ε) Rᵀ in the elastic,
    /// plastic and cracked ranges (one step from zero; the crack direction follows the
    /// principal direction), and the regime (cracks, crushing) is the same. Tolerance 1e-7 of
    /// |σ| + 1 Pa: the return mapping converges to 1e-11 f_cm and the crack angle is an
    /// atan2 of rotated components.
    #[test]
    fn concrete_rotation_invariance(e in prop::array::uniform3(-3e-3..1e-3f64), a in -3.2..3.2f64) {
        let p = concrete_params();
        let c = ConcreteState::new();
        let r = concrete::update(&p, &c, &e, 0.1);
        let rr = concrete::update(&p, &c, &rot_strain(a, e), 0.1);
        let ((t, s, _), (tr, sr, _)) = (r.unwrap(), rr.unwrap());
        prop_assert_eq!(t.n_cracks(), tr.n_cracks());
        prop_assert_eq!(t.is_crushed(), tr.is_crushed());
        let want = rot_stress(a, s);
        for i in 0..3 {
            prop_assert!((sr[i] - want[i]).abs() < 1e-7 * max_abs(&s) + 1.0, "{want:?} vs {sr:?} (regime {})", t.n_cracks());
        }
    }

    /// Symmetry where the theory gives it: the elastic and plastic (associated flow, work
    /// hardening) tangents of uncracked concrete, and the secant crack tangent
    /// (`secant_crack_tangent = true`) of cracked concrete. Tolerance 1e-9 E (round-off;
    /// a non-symmetric term would be O(0.01 E) or more).
    #[test]
    fn concrete_tangent_symmetry(
        e in prop::array::uniform3(-3e-3..1e-3f64), f1 in 0.3..1.0f64, secant in any::<bool>(),
    ) {
        let mut p = concrete_params();
        p.secant_crack_tangent = secant;
        let c = concrete::update(&p, &ConcreteState::new(), &e.map(|v| v * f1), 0.1).unwrap().0;
        let (t, _, d) = concrete::update(&p, &c, &e, 0.1).unwrap();
        prop_assume!(!t.is_crushed());
        if t.n_cracks() == 0 || secant {
            let mut asym: f64 = 0.0;
            for i in 0..3 {
                for j in 0..i {
                    asym = asym.max((d[i][j] - d[j][i]).abs());
                }
            }
            prop_assert!(asym <= 1e-9 * p.ec, "asymmetry {asym} with {} cracks, d = {d:?}", t.n_cracks());
        }
    }
}

/// Strains at round-off level (what a rigid motion of a concrete element produces: |ε| ≈
/// ε_mach |u|/L) must leave a virgin concrete point elastic. Found by the rigid-body property
/// above: an equal-biaxial compressive strain of 1e-16 (up to about 1e-14) takes the plastic
/// return, whose ε̄ rounds to 0, and `update` (src/materials/concrete/mod.rs, the test
/// `hardening(p, ε̄).sigma_c <= 0.0` after the return) declares the point crushed because with
/// the default zero initial yield the hardening curve starts at σ_c = 0. A crushed point
/// carries no stress for the rest of the analysis.
#[test]
fn concrete_round_off_strain_does_not_crush() {
    let p = concrete_params();
    for s in [1e-18, 1e-16, 1e-14] {
        let e = [-s, -s, 0.0];
        let (t, _, _) = concrete::update(&p, &ConcreteState::new(), &e, 0.1).unwrap();
        assert!(!t.is_crushed(), "strain {e:?} crushed a virgin point");
    }
}
