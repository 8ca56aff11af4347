//! The bundled post-tensioned beam example (examples/pt-beam.toml) through the `segfem`
//! binary: it runs to the end, and its camber after stressing has the sign and size of the
//! closed form.

mod common;

use common::{code, segfem, stderr, TempDir};

/// Columns of history.csv by header prefix, one row per increment.
fn history(dir: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let head: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

fn col(head: &[String], name: &str) -> usize {
    head.iter()
        .position(|h| h.starts_with(&format!("{name} ")))
        .unwrap_or_else(|| panic!("no column {name}"))
}

/// Camber at midspan after stressing (self weight and prestress, ungrouted tendon) against
/// the closed form for the statically determinate beam by virtual work (unit load at
/// midspan, m̄ = x/2 and v̄ = ±1/2):
///
/// * prestress: the section moment is P(x) cos θ e(x) and the shear P(x) sin θ, with P(x)
///   the tendon's lock-off force after friction and anchorage set at each of its
///   integration points (itself checked against seed eq. 27 in tests/prestress.rs) and e
///   the point's distance below the centroid: δ_p = Σ [P cos θ e m̄/EI + P |sin θ| v̄/(κGA)]
///   dx, dx = cos θ ds from the tendon's own weights;
/// * self weight w = ρ g b h: δ_g = 5 w L⁴/(384 EI) + w L²/(8 κGA), κ = 5/6.
///
/// Upward (positive) and within 2 % of δ_p − δ_g (the brief's bound; Q8 48 × 8 is within
/// ~0.1 % in bending, the point supports at the soffit add a local settlement of a few
/// hundredths of a millimetre). Then the service load: the grouted tendon's stress at
/// midspan rises by E_p ε_c, and the deflection from the service load is
/// 5 q L⁴/(384 E I_t) + q L²/(8 κGA) on the transformed section within 2 %.
#[test]
fn pt_beam_example_runs_and_cambers_as_the_closed_form() {
    let tmp = TempDir::new("ptbeam");
    let o = segfem(tmp.path(), &["example", "pt-beam", "-o", "pt.toml"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let o = segfem(tmp.path(), &["run", "pt.toml", "-o", "out", "-q"]);
    assert_eq!(code(&o), 0, "{}", stderr(&o));
    let (head, rows) = history(&tmp.join("out"));
    let uy = col(&head, "midspan_uy");
    let stress = col(&head, "stress_mid");

    let model = segfem::input::load(&tmp.join("pt.toml")).unwrap().model;
    let (l, h, b, e, nu, rho) = (12.0, 0.8, 0.4, 35e9, 0.2, 2500.0);
    let ei = e * b * h * h * h / 12.0;
    let kga = 5.0 / 6.0 * e / (2.0 * (1.0 + nu)) * b * h;
    let bar = &model.bars[0];
    let pt = bar.post_tension.as_ref().unwrap();
    let mut dp = 0.0;
    for (gp, s) in bar.points.iter().zip(&pt.point_stress) {
        let p = s * bar.area;
        let [c, sn] = gp.point.dir;
        let x = gp.point.x[0];
        let ecc = 0.5 * h - gp.point.x[1];
        let dx = c.abs() * gp.point.weight_length;
        let mbar = if x < 0.5 * l { 0.5 * x } else { 0.5 * (l - x) };
        dp += (p * c.abs() * ecc * mbar / ei + p * sn.abs() * 0.5 / kga) * dx;
    }
    let w = rho * 9.81 * b * h;
    let dg = 5.0 * w * l.powi(4) / (384.0 * ei) + w * l * l / (8.0 * kga);
    let camber = rows[0][uy];
    eprintln!(
        "pt-beam camber {camber:.5e} m vs closed form {:.5e} (prestress {dp:.5e}, self weight {dg:.5e})",
        dp - dg
    );
    assert!(camber > 0.0, "the beam must camber upwards: {camber}");
    assert!(
        (camber / (dp - dg) - 1.0).abs() < 0.02,
        "{camber} vs {}",
        dp - dg
    );

    // Service load q = 20 kN/m on the grouted beam. The grouted tendon adds n A_p at its
    // eccentricity e(x) = 0.25 [1 − (2x/L − 1)²] below the centroid to the gross concrete
    // (the model does not remove the duct): I_t(x) on the transformed section, bending by
    // virtual work with M = q x (L − x)/2, shear on b h.
    let last = rows.last().unwrap();
    let after_grout = rows.iter().rposition(|r| r[0] == 2.0).unwrap();
    let n = 195e9 / e;
    let ac = b * h;
    let ap = bar.area;
    let it_at = |ecc: f64| {
        let at = ac + n * ap;
        let ybar = n * ap * ecc / at;
        b * h.powi(3) / 12.0 + ac * ybar * ybar + n * ap * (ecc - ybar).powi(2)
    };
    let q = 20e3;
    let steps = 4000;
    let mut want = q * l * l / (8.0 * kga);
    for i in 0..steps {
        let x = (i as f64 + 0.5) * l / steps as f64;
        let ecc = 0.25 * (1.0 - (2.0 * x / l - 1.0).powi(2));
        let mbar = if x < 0.5 * l { 0.5 * x } else { 0.5 * (l - x) };
        want += q * x * (l - x) / 2.0 * mbar / (e * it_at(ecc)) * l / steps as f64;
    }
    let d_q = rows[after_grout][uy] - last[uy];
    let it = it_at(0.25);
    let ybar = n * ap * 0.25 / (ac + n * ap);
    let m_mid = q * l * l / 8.0;
    let ds = last[stress] - rows[after_grout][stress];
    let ds_want = n * m_mid * (0.25 - ybar) / it;
    eprintln!("service: deflection {d_q:.5e} vs {want:.5e}; tendon Δσ {ds:.5e} vs {ds_want:.5e}");
    assert!((d_q / want - 1.0).abs() < 0.02, "{d_q} vs {want}");
    assert!((ds / ds_want - 1.0).abs() < 0.02, "{ds} vs {ds_want}");
}
