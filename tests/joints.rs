//! Joint contact through the whole engine: two blocks pressed, pulled and sheared; the
//! decompression moment of a segmental beam against beam theory; opening after it.

use segfem::analysis::staged::StateBlock;
use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::results::joints::summarise;

/// Two 0.5 × 0.5 m blocks (thickness 0.2 m) side by side with a dry joint at x = 0.5.
fn two_blocks(supports: &str, loads: &str, friction: f64) -> String {
    format!(
        r#"
[[materials]]
name = "c"
kind = "elastic"
E = 30e9
nu = 0.2
[[regions]]
name = "r"
material = "c"
thickness = 0.2
[[joint_materials]]
name = "j"
kind = "dry"
friction = {friction}
kn = 1e12
kt = 4e11
residual_stiffness_ratio = 0.0
[mesh]
type = "segmental"
segments = [0.5, 0.5]
nx_per_segment = 2
element = "Q8"
joint_material = "j"
bands = [{{ region = "r", depth = 0.5, rows = 2 }}]
{supports}
[[load_cases]]
name = "N"
{loads}
[[steps]]
name = "s"
kind = "load"
loads = {{ N = 1.0 }}
"#
    )
}

/// Keeps the last converged state's key numbers.
#[derive(Default)]
struct Keep {
    u: Vec<f64>,
    reaction_x_left: f64,
    reaction_y_right: f64,
    max_opening: f64,
    max_slip: f64,
    sliding: bool,
}

impl Observer for Keep {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let m = s.system.model;
        self.u = s.system.displacements().to_vec();
        let r = |name: &str, d: usize| -> f64 {
            m.supports
                .iter()
                .filter(|sp| sp.name == name)
                .flat_map(|sp| sp.dofs.iter())
                .filter(|(_, dir, _)| dir.index() == d)
                .map(|(n, dir, _)| s.f_int[2 * n + dir.index()] - s.f_ext[2 * n + dir.index()])
                .sum()
        };
        self.reaction_x_left = r("left", 0);
        self.reaction_y_right = r("right", 1);
        let j = summarise(s.system, 0);
        self.max_opening = j.max_opening;
        self.max_slip = j.max_slip;
        self.sliding = s
            .system
            .families
            .joints
            .points
            .committed
            .iter()
            .flatten()
            .any(|p| p.sliding);
        Ok(())
    }
}

fn run(text: &str) -> (segfem::model::Model, Keep) {
    let model = segfem::input::parse(text, "two-blocks.toml").unwrap().model;
    let mut k = Keep::default();
    steps::run(&model, &mut k).unwrap();
    (model, k)
}

const SIGMA: f64 = 5e6; // normal stress across the joint [Pa]
const KN: f64 = 1e12;
const B: f64 = 0.2;
const L: f64 = 0.5;

/// Uniform compression σ: penetration σ/K_n at every joint node, resultant σ b L.
#[test]
fn pressed_blocks_transmit_the_load_with_penetration_sigma_over_kn() {
    let supports = r#"
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.5]]
ux = 0.0
[[supports]]
name = "pin"
point = [0.0, 0.0]
uy = 0.0
"#;
    let loads = format!(
        "line_loads = [{{ line = [[1.0, 0.0], [1.0, 0.5]], q = [{}, 0.0] }}]",
        -SIGMA * B
    );
    let (m, k) = run(&two_blocks(supports, &loads, 0.7));
    // Resultant: the left reaction balances σ b L (equilibrium, round-off).
    assert!(
        (k.reaction_x_left - SIGMA * B * L).abs() < 1e-9 * SIGMA * B * L,
        "{}",
        k.reaction_x_left
    );
    let face = &m.interfaces;
    for i in face {
        for a in 0..i.n_a {
            let (na, nb) = (i.nodes[a], i.nodes[i.n_a + a]);
            let pen = k.u[2 * na] - k.u[2 * nb];
            // Uniform stress is exact in the continuum; only round-off of the stiff penalty.
            assert!(
                (pen - SIGMA / KN).abs() < 1e-6 * SIGMA / KN,
                "penetration {pen}"
            );
        }
    }
    assert_eq!(k.max_opening, 0.0);
}

/// Pulled apart by a prescribed displacement, the joint opens and transmits nothing.
#[test]
fn pulled_blocks_open_and_transmit_nothing() {
    let supports = r#"
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.5]]
ux = 0.0
[[supports]]
name = "pin"
point = [0.0, 0.0]
uy = 0.0
[[supports]]
name = "right"
line = [[1.0, 0.0], [1.0, 0.5]]
ux = 1e-4
[[supports]]
name = "pin_right"
point = [1.0, 0.0]
uy = 0.0
"#;
    let (_, k) = run(&two_blocks(supports, "", 0.7));
    // Below 1e-9 of the compression test's load σ b L.
    assert!(
        k.reaction_x_left.abs() < 1e-9 * SIGMA * B * L,
        "{}",
        k.reaction_x_left
    );
    assert!(
        (k.max_opening - 1e-4).abs() < 1e-12,
        "opening {}",
        k.max_opening
    );
}

/// A block pushed sideways under normal stress sticks below μσ_n and slides at μσ_n.
#[test]
fn sheared_joint_sticks_below_and_slides_at_the_friction_limit() {
    let mu = 0.7;
    let shear = |delta: f64| {
        // The right face is fully prescribed: pushed in by 0.1 mm (normal force N, read from
        // its reaction) and moved up by δ; the support takes the couple of the shear.
        let supports = format!(
            r#"
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.5]]
ux = 0.0
uy = 0.0
[[supports]]
name = "right"
line = [[1.0, 0.0], [1.0, 0.5]]
ux = -1e-4
uy = {delta}
"#
        );
        run(&two_blocks(&supports, "", mu)).1
    };
    // Stick: a tiny δ gives a shear far below μN.
    let stick = shear(1e-7);
    let n = stick.reaction_x_left.abs();
    assert!(n > 1e5, "normal force {n}");
    assert!(!stick.sliding);
    assert!(stick.reaction_y_right.abs() < 0.5 * mu * n && stick.reaction_y_right.abs() > 0.0);
    // Slide: δ = 1 mm cannot be taken by sticking; every closed point slides and the joint
    // carries exactly μ times the normal force (round-off of the penalty terms).
    let slide = shear(1e-3);
    let n = slide.reaction_x_left.abs();
    assert!(slide.sliding);
    assert!(
        (slide.reaction_y_right.abs() - mu * n).abs() < 1e-6 * mu * n,
        "{} vs {}",
        slide.reaction_y_right,
        mu * n
    );
    // Part of δ goes into the blocks' shear and bending; the joint slip takes the rest, far
    // more than the elastic slip of the sticking case.
    assert!(
        slide.max_slip > 100.0 * stick.max_slip,
        "slip {} vs {}",
        slide.max_slip,
        stick.max_slip
    );
}

/// Records, per increment, the Q factor, the bottom normal stress of joint J1, the largest
/// opening and J1's contact depth.
#[derive(Default)]
struct Decompression {
    rows: Vec<(f64, f64, f64, f64)>,
}

impl Observer for Decompression {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let j = summarise(s.system, 0);
        let bottom = j.profile.first().expect("points").normal_stress;
        let open = (0..s.system.model.joints.len())
            .map(|k| summarise(s.system, k).max_opening)
            .fold(0.0, f64::max);
        self.rows
            .push((s.factors[1], bottom, open, j.contact_depth));
        Ok(())
    }
}

/// The bottom fibre of the joints decompresses at M = P (h/6 + e) (beam theory, within 2 %);
/// the joint then opens, the opening grows and the compressed depth shrinks with the load.
#[test]
fn segmental_beam_decompresses_at_the_beam_theory_moment_then_opens() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/segmental-decompression.toml"
    ))
    .unwrap();
    let model = segfem::input::parse(&text, "segmental-decompression.toml")
        .unwrap()
        .model;
    let mut d = Decompression::default();
    steps::run(&model, &mut d).unwrap();
    // Beam theory: P = 600 kN at e = 0.05 m; h = 0.5 m; the joints lie in the constant-moment
    // zone, 1 m (two depths, so St Venant effects of the loads have died out) from the loads.
    let q_dec = 600e3 * (0.5 / 6.0 + 0.05) / 1.0 / 1e3; // load factor (kN per point)
                                                        // While closed the joint is linear: extrapolate the bottom stress to zero from two states.
    let closed: Vec<_> = d.rows.iter().filter(|r| r.0 > 0.0 && r.2 == 0.0).collect();
    let (a, b) = (closed[0], closed[closed.len() - 1]);
    let q0 = a.0 - a.1 * (b.0 - a.0) / (b.1 - a.1);
    assert!(
        ((q0 - q_dec) / q_dec).abs() < 0.02,
        "decompression at Q = {q0:.2} kN, beam theory {q_dec:.2} kN"
    );
    // After opening: opening increases and contact depth decreases monotonically.
    let open: Vec<_> = d.rows.iter().filter(|r| r.2 > 0.0).collect();
    assert!(open.len() >= 5);
    for w in open.windows(2) {
        assert!(w[1].2 > w[0].2 && w[1].3 <= w[0].3, "{w:?}");
    }
    assert!(
        open.last().unwrap().3 < 0.5 * 0.5,
        "compressed depth should fall below half the depth"
    );
}

/// One opened joint between two (nearly) rigid segments: the right block rocks on the joint
/// as a rigid block on a tensionless Winkler foundation of stiffness K_n. Under a normal
/// force N at eccentricity e = M/N > h/6 the contact length is a = 3 (h/2 − e), the largest
/// contact stress 2N/(a b), the rotation θ = 2N/(K_n b a²) and the opening at the far edge
/// θ (h − a).
#[test]
fn single_opened_joint_rocks_like_a_rigid_block() {
    let (h, b, kn, n) = (0.5, 0.2, 1e10, 100e3);
    let v = 30e3; // transverse load 0.5 m from the joint: M = 15 kN·m, e = 0.15 m
    let text = format!(
        r#"
[[materials]]
name = "rigid"
kind = "elastic"
E = 1e13
nu = 0.2
[[regions]]
name = "r"
material = "rigid"
thickness = {b}
[[joint_materials]]
name = "keyed"
kind = "keyed"
kn = {kn}
kt = {kn}
residual_stiffness_ratio = 0.0
[mesh]
type = "segmental"
segments = [0.5, 0.5]
nx_per_segment = 2
element = "Q8"
joint_material = "keyed"
bands = [{{ region = "r", depth = {h}, rows = 20 }}]
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, {h}]]
ux = 0.0
uy = 0.0
[[load_cases]]
name = "N"
line_loads = [{{ line = [[1.0, 0.0], [1.0, {h}]], q = [{qn}, 0.0] }}]
[[load_cases]]
name = "V"
line_loads = [{{ line = [[1.0, 0.0], [1.0, {h}]], q = [0.0, {qv}] }}]
[[steps]]
name = "axial"
kind = "load"
loads = {{ N = 1.0 }}
[[steps]]
name = "bend"
kind = "load"
loads = {{ N = 1.0, V = 1.0 }}
increments = 10
"#,
        qn = -n / h,
        qv = -v / h
    );
    let model = segfem::input::parse(&text, "rocking.toml").unwrap().model;
    #[derive(Default)]
    struct Last(Option<segfem::results::joints::JointSummary>);
    impl Observer for Last {
        fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
            self.0 = Some(summarise(s.system, 0));
            Ok(())
        }
    }
    let mut last = Last::default();
    steps::run(&model, &mut last).unwrap();
    let j = last.0.unwrap();
    let e = v * 0.5 / n;
    let a = 3.0 * (h / 2.0 - e);
    let top = 2.0 * n / (kn * b * a * a) * (h - a);
    // Contact length from the closed points' integration lengths: resolution one element
    // edge (h/20 = 0.025 m).
    assert!(
        (j.contact_depth - a).abs() <= 0.025 + 1e-9,
        "contact {} vs {a}",
        j.contact_depth
    );
    // The opening at the top edge: rigid-block value within 5 % (the contact edge falls
    // between integration points; the blocks are 1000 times stiffer than the joint).
    let open_top = j.profile.last().unwrap().opening;
    assert!(
        ((open_top - top) / top).abs() < 0.05,
        "opening {open_top} vs {top}"
    );
    // The opening grows linearly above the contact zone (rigid rotation θ): within 5 % of
    // the top opening at every open point.
    let theta = 2.0 * n / (kn * b * a * a);
    for p in j.profile.iter().filter(|p| p.opening > 0.0) {
        let expected = theta * (p.x[1] - a);
        assert!(
            (p.opening - expected).abs() < 0.05 * top,
            "y = {}: {} vs {expected}",
            p.x[1],
            p.opening
        );
    }
}

/// Statics at every converged increment of a run with joints opening: the three-segment
/// beam (pin at x = 0, roller at x = 6 m, on the soffit) under the self-balanced end
/// forces P and the loads Q·1 kN at x = 1 and 5 m. Each reaction against its hand value:
/// R_left,x = 0 (P balances itself), R_right,y = −Σ(x F_y − y F_x)/L = Q·1 kN (the end
/// forces' moments cancel: both act at y = 0.2 m), R_left,y = 2Q·1 kN − R_right,y.
/// Tolerance 1e-8 of the total applied force magnitude (2 × 600 kN + loads): the Newton
/// residual left in the opened joints' nonlinear response.
#[test]
fn reactions_match_statics_at_every_increment_with_joints_opening() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/segmental-decompression.toml"
    ))
    .unwrap();
    let model = segfem::input::parse(&text, "segmental-decompression.toml")
        .unwrap()
        .model;
    let q_case = model
        .load_cases
        .iter()
        .position(|c| c.name == "Q")
        .expect("load case Q");
    struct Eq(Vec<(f64, [f64; 3], f64)>, usize);
    impl Observer for Eq {
        fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
            let m = s.system.model;
            let reaction = |name: &str| -> [f64; 2] {
                let sp = m.supports.iter().find(|sp| sp.name == name).unwrap();
                let mut r = [0.0; 2];
                for &(n, d, _) in &sp.dofs {
                    let k = 2 * n + d.index();
                    r[d.index()] += s.f_int[k] - s.f_ext[k];
                }
                r
            };
            let (l, r) = (reaction("left"), reaction("right"));
            let total: f64 = s.f_ext.iter().map(|f| f.abs()).sum();
            self.0.push((s.factors[self.1], [l[0], l[1], r[1]], total));
            Ok(())
        }
    }
    let mut eq = Eq(Vec::new(), q_case);
    steps::run(&model, &mut eq).unwrap();
    assert!(eq.0.len() > 20);
    for (i, (q, r, total)) in eq.0.iter().enumerate() {
        let want = [0.0, q * 1e3, q * 1e3];
        for c in 0..3 {
            assert!(
                (r[c] - want[c]).abs() <= 1e-8 * total,
                "increment {i}, Q = {q}: reaction {c} = {} N vs statics {} N",
                r[c],
                want[c]
            );
        }
    }
}

/// A dry joint that slides, opens, closes and opens again, driven through one interface
/// element (faces along y, 0.5 m, thickness 0.2 m, K_n = 1e12, K_t = 4e11 Pa/m, μ = 0.7,
/// no residual stiffness) by uniform relative displacements of face B, each state committed
/// before the next. The law (docs/theory-joints-tendons.md): closed, τ = K_t (g_t − s_p)
/// up to μσ_n; open, no traction and the plastic slip follows g_t, so that the joint
/// re-closes with zero shear wherever it moved while open. Expected at every point, in
/// closed form:
///
/// 1. pressed by λ = 1e-5 m and slid g = 1 mm: σ_n = K_n λ, τ = μσ_n, s_p = g − τ/K_t;
/// 2. opened (λ = −1e-4) and moved to g = 3 mm: σ_n = τ = 0, s_p = 3 mm (the reset);
/// 3. closed again at g = 3 mm: σ_n = K_n λ and τ = 0 (not K_t (3 − 1) mm);
/// 4. moved 1e-7 m while closed: sticks, τ = K_t · 1e-7;
/// 5. reopened: σ_n = τ = 0, s_p = g.
///
/// Tolerance 1e-9 of σ_n (the law is algebraic: round-off only).
#[test]
fn joint_opens_closes_and_reopens_with_the_slip_reset() {
    use segfem::elements::interface::{InterfaceElement, InterfaceParams};
    let prm = InterfaceParams::dry(1e12, 4e11, 0.7);
    let face = [[0.5, 0.0], [0.5, 0.5]];
    let el = InterfaceElement::new(&face, &face, &prm).unwrap();
    let nd = el.n_dofs();
    // Face B (second half of the dofs) moved by (dx, dy); which sign of dx presses the
    // joint is read from the element itself on a virgin state.
    let u = |dx: f64, dy: f64| -> Vec<f64> {
        (0..nd)
            .map(|k| {
                if k < nd / 2 {
                    0.0
                } else if k % 2 == 0 {
                    dx
                } else {
                    dy
                }
            })
            .collect()
    };
    let c0 = el.initial_states(&prm);
    let press = if el.response(&prm, 0.2, &u(-1e-5, 0.0), &c0).states[0].lambda > 0.0 {
        -1.0
    } else {
        1.0
    };
    // Slip sign: g_t of face B moved +y, read the same way.
    let gsign = el.response(&prm, 0.2, &u(press * 1e-5, 1e-9), &c0).states[0]
        .slip
        .signum();
    let (kn, kt, mu, lam) = (1e12, 4e11, 0.7, 1e-5);
    let sn = kn * lam;
    let tol = 1e-9 * sn;
    let mut c = c0;
    let mut go =
        |dx: f64,
         g: f64,
         what: &str,
         check: &dyn Fn(&[segfem::elements::interface::InterfacePointState])| {
            let r = el.response(&prm, 0.2, &u(dx, g), &c);
            check(&r.states);
            for p in &r.states {
                eprintln!(
                    "{what}: λ {:.3e} g {:.3e} s_p {:.4e} σ_n {:.4e} τ {:.4e} closed {} sliding {}",
                    p.lambda,
                    p.slip,
                    p.plastic_slip,
                    p.normal_stress,
                    p.shear_stress,
                    p.closed,
                    p.sliding
                );
            }
            c = r.states;
        };
    // 1. Pressed and slid 1 mm.
    go(press * lam, 1e-3, "slide", &|s| {
        for p in s {
            assert!(p.closed && p.sliding);
            assert!((p.normal_stress - sn).abs() < tol, "{p:?}");
            assert!((p.shear_stress.abs() - mu * sn).abs() < tol, "{p:?}");
            let sp = gsign * (1e-3 - mu * sn / kt);
            assert!((p.plastic_slip - sp).abs() < 1e-12, "{p:?}");
        }
    });
    // 2. Opened and moved to 3 mm.
    go(-press * 1e-4, 3e-3, "open", &|s| {
        for p in s {
            assert!(!p.closed);
            assert!(
                p.normal_stress.abs() < tol && p.shear_stress.abs() < tol,
                "{p:?}"
            );
            assert!((p.plastic_slip - gsign * 3e-3).abs() < 1e-12, "{p:?}");
        }
    });
    // 3. Closed again where it stands: no shear.
    go(press * lam, 3e-3, "reclose", &|s| {
        for p in s {
            assert!(p.closed && !p.sliding);
            assert!((p.normal_stress - sn).abs() < tol, "{p:?}");
            assert!(p.shear_stress.abs() < tol, "{p:?}");
        }
    });
    // 4. A small move sticks with the elastic shear.
    go(press * lam, 3e-3 + 1e-7, "stick", &|s| {
        for p in s {
            assert!(p.closed && !p.sliding);
            assert!((p.shear_stress.abs() - kt * 1e-7).abs() < tol, "{p:?}");
        }
    });
    // 5. Reopened: nothing carried, the slip follows again.
    go(-press * 1e-4, 2e-3, "reopen", &|s| {
        for p in s {
            assert!(!p.closed);
            assert!(
                p.normal_stress.abs() < tol && p.shear_stress.abs() < tol,
                "{p:?}"
            );
            assert!((p.plastic_slip - gsign * 2e-3).abs() < 1e-12, "{p:?}");
        }
    });
}

/// The contact status held when Newton cycles (`System::hold_contacts`, issue 38): two
/// blocks, the right one moved rigidly by ±g along x (no strain in either block, so the
/// internal forces on its nodes are the joint's alone). Held closed, the opened joint
/// transmits the penalty tension K_n g b L; held open, the pressed joint transmits nothing
/// (residual stiffness 0); released (a cut: `unlatch`, a revert, a commit) the law is
/// decided by the sign of λ again: 0 open, K_n g b L in compression. A second hold in the
/// same increment does nothing. Tolerance 1e-9 relative: sums of penalty products.
#[test]
fn held_contact_status_transmits_as_held_until_released() {
    use segfem::analysis::system::System;
    let supports = r#"
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.5]]
ux = 0.0
[[supports]]
name = "pin"
point = [0.0, 0.0]
uy = 0.0
"#;
    let text = two_blocks(supports, "point_loads = []", 0.7);
    let m = segfem::input::parse(&text, "two-blocks.toml")
        .unwrap()
        .model;
    // Nodes of the right block: those of elements lying beyond the joint.
    let mut right = vec![false; m.nodes.len()];
    for e in &m.elements {
        let xc = e.nodes.iter().map(|&n| m.nodes[n][0]).sum::<f64>() / e.nodes.len() as f64;
        if xc > L {
            e.nodes.iter().for_each(|&n| right[n] = true);
        }
    }
    let g = 1e-6; // [m], 1 MPa of penalty stress at K_n = 1e12 Pa/m
    let moved = |dx: f64| -> Vec<f64> {
        (0..m.nodes.len())
            .flat_map(|n| [if right[n] { dx } else { 0.0 }, 0.0])
            .collect()
    };
    let mut sys = System::new(&m);
    // Joint force on the right block along x [N].
    let force = |sys: &mut System, dx: f64| -> f64 {
        let f = sys.assemble(&moved(dx), false).unwrap().f_int;
        (0..m.nodes.len())
            .filter(|&n| right[n])
            .map(|n| f[2 * n])
            .sum()
    };
    let full = KN * g * B * L;
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * full;
    // Closed at λ = 0, held closed, then pulled open by g: tension K_n g b L.
    assert!(close(force(&mut sys, 0.0), 0.0));
    let n_points: usize = sys.families.joints.points.trial.iter().map(Vec::len).sum();
    assert_eq!(sys.hold_contacts(), n_points);
    assert!(close(force(&mut sys, g), full), "held closed");
    assert_eq!(sys.hold_contacts(), 0, "one hold per increment");
    // A cut releases it: open again, nothing transmitted.
    sys.unlatch();
    assert!(close(force(&mut sys, g), 0.0), "released by unlatch");
    // Open, held open, then pressed by g: nothing transmitted while held.
    assert_eq!(sys.hold_contacts(), n_points);
    assert!(close(force(&mut sys, -g), 0.0), "held open");
    sys.families.revert();
    assert!(close(force(&mut sys, -g), -full), "released by revert");
    // Released by the drivers' check once an increment converges on held statuses.
    assert_eq!(sys.hold_contacts(), n_points);
    assert!(sys.release_contacts() && !sys.release_contacts());
    assert!(
        close(force(&mut sys, -g), -full),
        "released by release_contacts"
    );
    sys.unlatch();
    // Held closed, committed: the next increment decides by λ again.
    sys.hold_contacts();
    sys.families.commit();
    assert!(sys.families.joints.held.is_empty());
    assert!(close(force(&mut sys, g), 0.0), "released by commit");
}
