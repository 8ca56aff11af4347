//! The IMPL-EX tension law within an increment (`implex.rs`, docs/theory-concrete.md §5.2).

use super::super::implex::{exp_e1, point_error, point_stress_error, secant_integral, tension};
use super::*;

/// E₁(x) against the exponential integral tabulated to 17 digits (mpmath `e1`), on both
/// sides of the switch from the series to the continued fraction at x = 2. Tolerance 1e-13
/// relative: the accuracy the function documents (double rounding of ~30 terms).
#[test]
fn exp_e1_matches_tabulated_exponential_integral() {
    let table: [(f64, f64); 9] = [
        (0.1, 1.822_923_958_419_390_6),
        (0.5, 0.559_773_594_776_160_8),
        (1.0, 0.219_383_934_395_520_29),
        (2.0, 0.048_900_510_708_061_12),
        (2.5, 0.024_914_917_870_269_736),
        (3.0, 0.013_048_381_094_197_037),
        (5.0, 0.001_148_295_591_275_325_7),
        (10.0, 4.156_968_929_685_325e-6),
        (30.0, 3.021_552_010_688_812_4e-15),
    ];
    for (x, e1) in table {
        let got = (-x).exp() * exp_e1(x);
        assert!(
            ((got - e1) / e1).abs() < 1e-13,
            "E1({x}) = {got:.17e}, want {e1:.17e}"
        );
    }
}

/// Composite Simpson rule of σ_env(x)/x over [a, b] (n even intervals): an independent
/// evaluation of the integral the law has in closed form.
fn simpson(p: &ConcreteParams, alpha: f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let f = |x: f64| super::cracking::tension_envelope(p, alpha, x).0 / x;
    let inner: f64 = (1..n)
        .map(|i| (if i % 2 == 1 { 4.0 } else { 2.0 }) * f(a + i as f64 * h))
        .sum();
    h / 3.0 * (f(a) + inner + f(b))
}

/// The law of an IMPL-EX crack direction in one increment, for fresh (ẽ = ε0) and older
/// cracks and steep (α = ε0) and gentle (α = 20 ε0) softening:
/// * up to ẽ the secant of the envelope at ẽ; past ẽ the closed-form integral of the
///   envelope's secant equals Simpson's rule to 1e-9 f_tm (Simpson's error with 4000
///   intervals on these smooth integrands is ~1e-12 f_tm);
/// * C¹ at ẽ: the slopes just below and just above ẽ agree to 1e-6 (a kink, such as a cap
///   of a fixed fraction of the secant, fails this);
/// * the tangent is the derivative of the stress (central differences with h = 1e-4 ε,
///   1e-5 relative, truncation being ~1e-8, plus the rounding of the stresses, ~10 ulp of
///   f_tm over h, which dominates where the envelope has all but vanished);
/// * monotone and concave: stress rising, tangent positive and not increasing;
/// * bounded: σ ≤ the secant line at ẽ, and σ − σ_env(ẽ) ≤ f_tm ln(ε/ẽ) (σ_env ≤ f_tm);
///   continuing the secant (slope 1) exceeds this bound for a fresh crack past 2 ε0.
#[test]
fn implex_law_is_smooth_monotone_and_its_overshoot_logarithmic() {
    let p = params();
    let (e0, ft) = (p.eps0(), p.ftm);
    for alpha in [e0, 20.0 * e0] {
        for ex in [e0, 3.0 * e0, e0 + 2.0 * alpha] {
            let (s_ex, k) = tension(&p, alpha, ex, ex);
            let sec = super::cracking::tension_envelope(&p, alpha, ex).0 / ex;
            assert!((s_ex - sec * ex).abs() < 1e-9 * ft && (k - sec).abs() < 1e-12 * sec);
            let (_, below) = tension(&p, alpha, ex, ex * (1.0 - 1e-9));
            let (_, above) = tension(&p, alpha, ex, ex * (1.0 + 1e-9));
            assert!(
                (above - below).abs() < 1e-6 * below,
                "kink at ẽ = {ex:.3e}: slopes {below:.6e} / {above:.6e}"
            );
            let (mut s_prev, mut k_prev) = (s_ex, k);
            for i in 1..=60 {
                let e = ex * (1.0 + 0.25 * i as f64);
                let (s, k) = tension(&p, alpha, ex, e);
                let quad = s_ex + simpson(&p, alpha, ex, e, 4000);
                assert!(
                    (s - quad).abs() < 1e-9 * ft,
                    "σ {s:.9e} vs quadrature {quad:.9e} at ε = {e:.3e}"
                );
                assert!((secant_integral(&p, alpha, ex, e) - (s - s_ex)).abs() < 1e-9 * ft);
                let h = 1e-4 * e;
                let fd =
                    (tension(&p, alpha, ex, e + h).0 - tension(&p, alpha, ex, e - h).0) / (2.0 * h);
                assert!(
                    (fd - k).abs() < 1e-5 * k + 1e-15 * ft / h,
                    "tangent {k:.6e} vs FD {fd:.6e} at ε = {e:.3e}"
                );
                // Rising (within the rounding of σ, where the envelope has all but vanished).
                assert!(
                    s > s_prev - 1e-13 * ft && k > 0.0 && k <= k_prev * (1.0 + 1e-12),
                    "σ {s_prev:.9e} → {s:.9e}, k {k_prev:.6e} → {k:.6e} at ε = {e:.3e}"
                );
                assert!(s <= sec * e * (1.0 + 1e-12));
                assert!(s - s_ex <= ft * (e / ex).ln() * (1.0 + 1e-12));
                (s_prev, k_prev) = (s, k);
            }
        }
    }
    // The plain secant continued past a fresh crack's ẽ = ε0 breaks the bound at 2 ε0.
    assert!(ft * (2.0 - 1.0) > ft * 2f64.ln());
}

/// Through the material point: a fixed crack updated with IMPL-EX returns the law above in
/// its normal direction, and its tangent is continuous across the extrapolated strain (the
/// point's Newton iterations see no kink there).
#[test]
fn implex_crack_point_has_no_kink_at_the_extrapolated_strain() {
    let mut p = params();
    p.implex = true;
    let alpha = p.softening_alpha(0.1);
    let e0 = p.eps0();
    // Crack along x in three increments of 2 ε0 (formation, then two with extrapolation).
    let mut c = ConcreteState::new();
    for (i, e) in [1.1 * e0, 3.1 * e0, 5.1 * e0].into_iter().enumerate() {
        let ratio = if i > 0 { 1.0 } else { 0.0 };
        c = update_extrapolated(&p, &c, &[e, 0.0, 0.0], 0.1, ratio)
            .unwrap()
            .0;
    }
    assert_eq!(c.n_cracks, 1);
    // Extrapolated largest strain of the next increment of the same size.
    let ex = c.crack_max[0] + (c.crack_max[0] - c.crack_max_old[0]);
    for f in [0.5, 1.0 - 1e-9, 1.0 + 1e-9, 1.5, 3.0] {
        let e = f * ex;
        let (_, s, d) = update_extrapolated(&p, &c, &[e, 0.0, 0.0], 0.1, 1.0).unwrap();
        let (s_law, k_law) = tension(&p, alpha, ex, e);
        assert!(
            (s[0] - s_law).abs() < 1e-9 * p.ftm && (d[0][0] - k_law).abs() < 1e-9 * k_law,
            "at {f} ẽ: σ {:.6e} / {s_law:.6e}, k {:.6e} / {k_law:.6e}",
            s[0],
            d[0][0]
        );
    }
}

/// The IMPL-EX error measure (`implex::point_error`, docs/theory-concrete.md §5.2 "Error
/// control") against hand values for a crack along x with the Hinton envelope
/// σ_env(x) = f_tm exp(−(x − ε0)/α) written out here: the crack forms at 1.1 ε0 and opens
/// to 3.1 ε0, so the next increment of the same size extrapolates ẽ = 5.1 ε0.
/// * opening past ẽ (to 8 ε0): the overshoot is σ_env(ẽ) + ∫_ẽ^ε σ_env(x)/x dx − σ_env(ε),
///   the integral by Simpson's rule (error ~1e-12 f_tm); tolerance 1e-9 of f_tm;
/// * between ε_max and ẽ (4 ε0): the secant at ẽ against the envelope (below it);
/// * unloading below ε_max (2 ε0): the secant at ẽ against the committed secant, and no error
///   without extrapolation (ratio 0: both are the committed secant);
/// * compression: no error (both integrations share the compression law);
/// * a crack forming in the increment (elastic in it, at 3 ε0) is not measured (0), and the
///   next increment's opening past ẽ = 3 ε0 (rate 0: no extrapolation) to 5 ε0 is again the
///   integral form.
#[test]
fn implex_error_measure_matches_hand_values() {
    let mut p = params();
    p.implex = true;
    let alpha = p.softening_alpha(0.1);
    let (e0, ft) = (p.eps0(), p.ftm);
    let env = |x: f64| ft * (-(x - e0) / alpha).exp();
    let mut c = ConcreteState::new();
    for (i, e) in [1.1 * e0, 3.1 * e0].into_iter().enumerate() {
        let ratio = if i > 0 { 1.0 } else { 0.0 };
        c = update_extrapolated(&p, &c, &[e, 0.0, 0.0], 0.1, ratio)
            .unwrap()
            .0;
    }
    let (emax, ex) = (3.1 * e0, 5.1 * e0);
    assert!((c.crack_max[0] - emax).abs() < 1e-12 * emax);
    let err = |e: f64, ratio: f64| {
        let t = update_extrapolated(&p, &c, &[e, 0.0, 0.0], 0.1, ratio)
            .unwrap()
            .0;
        point_error(&p, &c, &t, 0.1, ratio, 0.0)
    };
    let want = [
        (
            8.0 * e0,
            (env(ex) + simpson(&p, alpha, ex, 8.0 * e0, 4000) - env(8.0 * e0)) / ft,
        ),
        (
            4.0 * e0,
            (env(ex) / ex * 4.0 * e0 - env(4.0 * e0)).abs() / ft,
        ),
        (
            2.0 * e0,
            (env(ex) / ex - env(emax) / emax).abs() * 2.0 * e0 / ft,
        ),
        (-2.0 * e0, 0.0),
    ];
    for (e, w) in want {
        let got = err(e, 1.0);
        assert!(
            (got - w).abs() < 1e-9,
            "at {} ε0: error {got:.12} f_tm, want {w:.12}",
            e / e0
        );
    }
    // The overshoot past ẽ is positive and larger than between ε_max and ẽ.
    assert!(want[0].1 > want[1].1);
    assert!(
        err(2.0 * e0, 0.0).abs() < 1e-12,
        "no extrapolation, no error"
    );
    // Formation: the point cracks at 3 ε0 in its first increment.
    let v = ConcreteState::new();
    let t = update_extrapolated(&p, &v, &[3.0 * e0, 0.0, 0.0], 0.1, 0.0)
        .unwrap()
        .0;
    assert_eq!(t.n_cracks, 1);
    assert_eq!(
        point_error(&p, &v, &t, 0.1, 0.0, 0.0),
        0.0,
        "formation not measured"
    );
    let n = update_extrapolated(&p, &t, &[5.0 * e0, 0.0, 0.0], 0.1, 1.0)
        .unwrap()
        .0;
    let got = point_error(&p, &t, &n, 0.1, 1.0, 0.0);
    let (a, b) = (3.0 * e0, 5.0 * e0);
    let w = (env(a) + simpson(&p, alpha, a, b, 4000) - env(b)) / ft;
    assert!(
        (got - w).abs() < 1e-9,
        "after formation: {got:.12} f_tm, want {w:.12}"
    );
    // Off without IMPL-EX.
    let mut q = p.clone();
    q.implex = false;
    assert_eq!(point_error(&q, &v, &t, 0.1, 0.0, 0.0), 0.0);
}

/// IMPL-EX in compression (`compression_integration = "implex"`, docs/theory-concrete.md
/// §4): on a prescribed biaxial compression strain path the state is the implicit return
/// mapping's bit for bit (the same updates from the same states), and the stress is the
/// elastic stress of the plastic strain extrapolated from the last increment, with the
/// elastic tangent — computed here by hand from the implicit states.
#[test]
fn implex_compression_keeps_the_implicit_state_and_extrapolates_the_plastic_strain() {
    let mut p = params();
    p.implex = true;
    let mut q = p.clone();
    q.compression_implex = true;
    let d = d_matrix(p.ec, p.nu);
    let (mut a, mut b) = (ConcreteState::new(), ConcreteState::new());
    let mut old = [0.0; 3];
    let mut flowed = 0;
    for k in 1..=40 {
        // Strain increments growing by 5 % a step: ratio 1.05 (the first: 0), to
        // 2.4e-3 in x.
        let ratio = if k == 1 { 0.0 } else { 1.05 };
        let scale = -2e-5 * (1.05f64.powi(k) - 1.0) / 0.05;
        let e = [scale, 0.3 * scale, 0.2 * scale];
        let (sa, _, _) = update_extrapolated(&p, &a, &e, 0.1, ratio).unwrap();
        let (sb, sig, tan) = update_extrapolated(&q, &b, &e, 0.1, ratio).unwrap();
        assert!(
            !sb.is_crushed(),
            "increment {k}: the path stays short of crushing"
        );
        assert_eq!(sa.plastic_strain, sb.plastic_strain, "increment {k}");
        assert_eq!(sa.ebar, sb.ebar, "increment {k}");
        let ep: [f64; 3] = std::array::from_fn(|i| {
            let c = b.plastic_strain[i];
            c + ratio * (c - old[i])
        });
        let want: [f64; 3] =
            std::array::from_fn(|i| (0..3).map(|j| d[i][j] * (e[j] - ep[j])).sum());
        for i in 0..3 {
            assert!(
                (sig[i] - want[i]).abs() <= 1e-9 * want[0].abs(),
                "increment {k}: σ {sig:?}, want {want:?}"
            );
        }
        assert_eq!(tan, d, "increment {k}: the elastic tangent");
        flowed += usize::from(sb.plastic_strain != b.plastic_strain);
        old = b.plastic_strain;
        a = sa;
        b = sb;
    }
    assert!(
        flowed > 20,
        "the path must flow plastically ({flowed} increments)"
    );
}

/// IMPL-EX in compression follows the MC90 curve to first order in the increment: in
/// uniaxial compression (σy = τ = 0 by iteration) up to 0.9 ε_c1 the largest stress
/// error against the curve falls by at least 2× (first order: 4×) when the increments
/// are 4× finer, and is below 2 % of f_cm at 160 increments.
#[test]
fn implex_compression_follows_the_curve_to_first_order() {
    let mut p = params();
    p.implex = true;
    p.compression_implex = true;
    let worst = |n: usize| {
        let mut st = ConcreteState::new();
        let mut y = [0.0f64; 2];
        let mut err: f64 = 0.0;
        for k in 1..=n {
            let ratio = if k == 1 { 0.0 } else { 1.0 };
            let ex = -0.9 * p.eps_c1 * k as f64 / n as f64;
            let mut out = update_extrapolated(&p, &st, &[ex, y[0], y[1]], 0.1, ratio).unwrap();
            // The tangent is the elastic D: one solve for (εy, γ) is exact.
            for _ in 0..3 {
                let (s, dd) = (out.1, out.2);
                let det = dd[1][1] * dd[2][2] - dd[1][2] * dd[2][1];
                y[0] += (-s[1] * dd[2][2] + s[2] * dd[1][2]) / det;
                y[1] += (-s[2] * dd[1][1] + s[1] * dd[2][1]) / det;
                out = update_extrapolated(&p, &st, &[ex, y[0], y[1]], 0.1, ratio).unwrap();
            }
            let want = -compression::hardening_curve(&p, -ex).0;
            err = err.max((out.1[0] - want).abs());
            st = out.0;
        }
        err / p.fcm
    };
    let (coarse, fine) = (worst(40), worst(160));
    assert!(fine < 0.02, "160 increments: largest error {fine} f_cm");
    assert!(
        coarse > 2.0 * fine,
        "first order: 40 increments {coarse}, 160 increments {fine}"
    );
}

/// IMPL-EX in compression crushes a point at the end of the increment: in the increment in
/// which its implicit state crushes it still answers with the extrapolated stress (elastic
/// tangent), and from the next one with no stress (the crushed route).
#[test]
fn implex_compression_crushes_at_the_end_of_the_increment() {
    let mut p = params();
    p.implex = true;
    p.compression_implex = true;
    let d = d_matrix(p.ec, p.nu);
    let mut st = ConcreteState::new();
    let mut crushed_at = None;
    for k in 1..=60 {
        let ratio = if k == 1 { 0.0 } else { 1.0 };
        let e = [-1e-4 * k as f64, 0.0, 0.0];
        let (next, sig, tan) = update_extrapolated(&p, &st, &e, 0.1, ratio).unwrap();
        if next.is_crushed() && !st.is_crushed() {
            let ep: [f64; 3] = std::array::from_fn(|i| {
                let c = st.plastic_strain[i];
                c + ratio * (c - st.plastic_strain_old[i])
            });
            let want: f64 = (0..3).map(|j| d[0][j] * (e[j] - ep[j])).sum();
            assert!(
                (sig[0] - want).abs() <= 1e-9 * want.abs(),
                "{sig:?} vs {want}"
            );
            assert!(sig[0] < -1e6, "still carrying compression: {sig:?}");
            assert_eq!(tan, d);
            crushed_at = Some(k);
        } else if st.is_crushed() {
            assert_eq!(sig, [0.0; 3], "increment {k} after crushing");
        }
        st = next;
    }
    assert!(crushed_at.is_some_and(|k| k < 60), "the path must crush");
}

/// The 1-D compression law of a crack-axis direction in closed form, for the crush band of
/// `p` on an element of size `h` [m]: the MC90 curve up to the peak,
/// σ_c = f_cm (k η − η²)/(1 + (k − 2) η), η = ε̄/ε_c1, k = E ε_c1/f_cm, then the parabola
/// f_cm (1 − x²), x = (ε̄ − ε_c1)/(ε_u − ε_c1), ε_u = ε_c1 + max(1.5 G_c/(h f_cm),
/// 2 f_cm (1 − s)/(s E)) (s the softening limit). In 1-D with zero initial yield the curve
/// strain of a flowing direction is its compressive strain, ε̄ = −e, and below the largest
/// one reached, ε̄_m, the direction unloads with E from the plastic strain
/// ε̄_m − σ_c(ε̄_m)/E: σ = −σ_c(ε̄_m) + E (e + ε̄_m) (docs/theory-concrete.md §5).
fn crack_axis_law(p: &ConcreteParams, h: f64) -> (impl Fn(f64) -> f64, f64) {
    let CompressionSoftening::CrushBand { gc } = p.compression_softening else {
        panic!("the crush band is needed");
    };
    let s = p.softening_limit;
    let eu = p.eps_c1 + (1.5 * gc / (h * p.fcm)).max(2.0 * p.fcm * (1.0 - s) / (s * p.ec));
    let (fcm, ec1, k) = (p.fcm, p.eps_c1, p.ec * p.eps_c1 / p.fcm);
    let curve = move |eb: f64| {
        if eb <= ec1 {
            let eta = eb / ec1;
            fcm * (k * eta - eta * eta) / (1.0 + (k - 2.0) * eta)
        } else {
            let x = (eb - ec1) / (eu - ec1);
            fcm * (1.0 - x * x)
        }
    };
    (curve, eu)
}

/// A point cracked along x (crack normal x, opened to 3 ε0 and held), then compressed
/// along y — parallel to the crack, so the t direction's 1-D compression law alone — to
/// 1.2 ε_c1 (past the peak), unloaded to 0.8 ε_c1 and reloaded to 3 ε_c1 on the crush
/// band's parabola, in equal increments (ratio 1, the first 0). With IMPL-EX compression:
/// * the state is the implicit update's bit for bit (plastic strains, curve strains, crack
///   strains; the same updates from the same states);
/// * σ_y is E (e + p̃) with p̃ = p_n + (p_n − p_n−1) (by hand from the committed states),
///   and its tangent is E (positive), with no coupling to the crack direction;
/// * σ_y follows the closed-form law ([`crack_axis_law`]) to first order: the largest
///   error falls by more than 3.5× (first order: 4×) for 4× finer increments. It is the
///   reversal at 1.2 ε_c1, where the extrapolated flow goes on while the strain unloads:
///   one increment's flow E Δp, between E Δe and 1.5 E Δe there (Δp = Δe − Δσ_c/E with
///   σ_c falling gently past the peak; 2.2 % f_cm at 304 increments). The implicit update
///   follows the same law to 1e-6 f_cm (its closed-form return; the check of the law here).
#[test]
fn implex_compression_of_a_crack_direction_is_linear_in_the_increment() {
    let h = 0.1;
    let mut p = params().with_crush_band();
    p.implex = true;
    let mut q = p.clone();
    q.compression_implex = true;
    let (law, eu) = crack_axis_law(&p, h);
    assert!(
        3.0 * p.eps_c1 < 0.9 * eu,
        "the path stays short of crushing"
    );
    let ex = 3.0 * p.eps0();
    let run = |n: usize| {
        let mut a = update_extrapolated(&p, &ConcreteState::new(), &[ex, 0.0, 0.0], h, 0.0)
            .unwrap()
            .0;
        assert_eq!(a.n_cracks, 1);
        assert_eq!(a.crack_angle, 0.0);
        let mut b = a.clone();
        let (mut err, mut err_implicit): (f64, f64) = (0.0, 0.0);
        let mut ebar_m: f64 = 0.0;
        for k in 1..=n {
            let ratio = if k == 1 { 0.0 } else { 1.0 };
            // Path parameter in ε_c1: 0 → 1.2 → 0.8 (1.6) → 3.0 (3.8).
            let t = 3.8 * k as f64 / n as f64;
            let c = if t <= 1.2 {
                t
            } else if t <= 1.6 {
                2.4 - t
            } else {
                t - 0.8
            };
            let e = -c * p.eps_c1;
            let strain = [ex, e, 0.0];
            let (sa, siga, _) = update_extrapolated(&p, &a, &strain, h, ratio).unwrap();
            let (sb, sig, tan) = update_extrapolated(&q, &b, &strain, h, ratio).unwrap();
            assert_eq!(sa.dir_plastic, sb.dir_plastic, "increment {k}");
            assert_eq!(sa.dir_ebar, sb.dir_ebar, "increment {k}");
            assert_eq!(sa.crack_strain, sb.crack_strain, "increment {k}");
            assert_eq!(sa.crack_max, sb.crack_max, "increment {k}");
            assert!(!sb.is_crushed() && sb.n_cracks == 1, "increment {k}");
            let pt = b.dir_plastic[1] + ratio * (b.dir_plastic[1] - b.dir_plastic_old[1]);
            let want = p.ec * (e + pt);
            assert!(
                (sig[1] - want).abs() <= 1e-9 * p.fcm,
                "increment {k}: σy {} want {want}",
                sig[1]
            );
            assert_eq!(tan[1][1], p.ec, "increment {k}: tangent E");
            assert_eq!((tan[0][1], tan[1][0]), (0.0, 0.0), "increment {k}");
            ebar_m = ebar_m.max(-e);
            let exact = -law(ebar_m) + p.ec * (e + ebar_m);
            err = err.max((sig[1] - exact).abs());
            err_implicit = err_implicit.max((siga[1] - exact).abs());
            a = sa;
            b = sb;
        }
        assert!(
            err_implicit < 1e-6 * p.fcm,
            "the implicit law: {err_implicit}"
        );
        err / p.fcm
    };
    let (coarse, fine) = (run(76), run(304));
    // The reversal's error is the flow of one increment, E Δp ≥ E Δe = 3.8 E ε_c1/304
    // = 2.2 % f_cm (Δp > Δe past the peak, where σ_c falls).
    let reversal = 3.8 * p.ec * p.eps_c1 / 304.0 / p.fcm;
    assert!(
        fine > reversal && fine < 1.5 * reversal,
        "304 increments: largest error {fine} f_cm (E Δe = {reversal})"
    );
    assert!(
        coarse > 3.5 * fine,
        "first order: 76 increments {coarse}, 304 increments {fine}"
    );
}

/// A cracked point whose compressed direction crushes is crushed at the end of the
/// increment: in that increment it answers with E (e + p̃) in that direction (not zero),
/// from the next with no stress.
#[test]
fn implex_compression_crushes_a_cracked_point_at_the_end_of_the_increment() {
    let h = 0.1;
    let mut p = params().with_crush_band();
    p.implex = true;
    p.compression_implex = true;
    let (_, eu) = crack_axis_law(&p, h);
    let ex = 3.0 * p.eps0();
    let mut st = update_extrapolated(&p, &ConcreteState::new(), &[ex, 0.0, 0.0], h, 0.0)
        .unwrap()
        .0;
    let n = 50;
    let mut crushed_at = None;
    for k in 1..=n {
        let ratio = if k == 1 { 0.0 } else { 1.0 };
        let e = -1.2 * eu * k as f64 / n as f64;
        let (next, sig, tan) = update_extrapolated(&p, &st, &[ex, e, 0.0], h, ratio).unwrap();
        if next.is_crushed() && !st.is_crushed() {
            let pt = st.dir_plastic[1] + ratio * (st.dir_plastic[1] - st.dir_plastic_old[1]);
            let want = p.ec * (e + pt);
            assert!((sig[1] - want).abs() <= 1e-9 * p.fcm, "{sig:?} vs {want}");
            assert_eq!(tan[1][1], p.ec);
            crushed_at = Some(k);
        } else if st.is_crushed() {
            assert_eq!(sig, [0.0; 3], "increment {k} after crushing");
        }
        st = next;
    }
    // The implicit state crushes at ε̄ = ε_u: in the increment reaching it.
    let k = crushed_at.expect("the path must crush");
    let reach = (eu / (1.2 * eu / n as f64)).ceil() as usize;
    assert!(
        k == reach || k == reach + 1,
        "crushed at {k}, ε_u reached at {reach}"
    );
}

/// The MC90 curve σ_c(ε̄) [Pa] up to and past the peak, in closed form:
/// f_cm (k η − η²)/(1 + (k − 2) η), η = ε̄/ε_c1, k = E ε_c1/f_cm; and its compressive
/// plastic strain magnitude in uniaxial compression with zero initial yield,
/// p = ε̄ − σ_c(ε̄)/E (docs/theory-concrete.md §4: κ = ε̄ − σ_c/E − κ0, κ0 = 0).
fn mc90_plastic(p: &ConcreteParams, eb: f64) -> f64 {
    let (k, eta) = (p.ec * p.eps_c1 / p.fcm, eb / p.eps_c1);
    let s = p.fcm * (k * eta - eta * eta) / (1.0 + (k - 2.0) * eta);
    eb - s / p.ec
}

/// The IMPL-EX error measures see the compression extrapolation (docs/theory-concrete.md
/// §4, "IMPL-EX in compression"): an uncracked point in uniaxial compression past
/// the MC90 peak (ν = 0, so σ_x = E (ε_x − εᵖ_x) whatever the lateral strain), two committed
/// increments of equal size Δ, then one of size r Δ with extrapolation ratio r. In 1-D
/// ε̄ = −ε_x and the plastic strain is −p(ε̄), p = ε̄ − σ_c(ε̄)/E ([`mc90_plastic`]), so the
/// stress difference at the converged strain is Δσ_x = E (p̃ − p(ε̄_k)),
/// p̃ = p_n + r (p_n − p_n−1) — computed here from the curve's formula. Δσ_y = E (ε_y,k −
/// ε̃_y) (σ_y = 0 makes the lateral plastic strain the lateral strain of the path), τ 0.
/// The point error is the largest of |Δσ_x|, |Δσ_y| over f_cm. Tolerance 1e-6 of the
/// difference: the return mapping's tolerance (1e-11 scaled) and the path's σ_y = 0 to
/// 1e-10 f_cm, against differences of 9e-4 to 0.05 f_cm (Δσ_y, the Ottosen flow's
/// dilatancy, is 3.3× Δσ_x here).
/// No difference with the option off, in a time increment (dt > 0) and in an elastic
/// increment (a point that flowed in neither).
#[test]
fn implex_compression_error_of_an_uncracked_point_is_its_extrapolated_flow() {
    let mut p = ConcreteParams::from_mc90(FCM, 0.0);
    p.implex = true;
    let mut q = p.clone();
    q.compression_implex = true;
    // To 1.09 ε_c1 in 39 increments; the last one measured reaches 1.15 ε_c1 at most.
    let n = 40;
    let step = -1.12 * p.eps_c1 / n as f64;
    // The implicit uniaxial path (the state under the option is the same bit for bit).
    let mut states = vec![ConcreteState::new()];
    let mut lateral = vec![0.0];
    let mut y = [0.0; 2];
    for k in 1..n {
        let ((st, _, _), yk) = uniaxial_x(&p, &states[k - 1], step * k as f64, y);
        y = yk;
        states.push(st);
        lateral.push(y[0]);
    }
    let k = n - 1;
    let eb = |ex: f64| -ex;
    // Past the peak and short of the softening limit's straight line (tangent −E/3).
    let slope = |e: f64| {
        let de = 1e-7;
        let s = |x: f64| (x - mc90_plastic(&p, x)) * p.ec;
        (s(e + de) - s(e - de)) / (2.0 * de)
    };
    assert!(eb(step * (k - 1) as f64) > p.eps_c1);
    assert!(slope(eb(step * (k as f64 + 2.0))) > -p.ec / 3.0);
    let c = &states[k];
    let (pn, po) = (
        mc90_plastic(&p, eb(step * k as f64)),
        mc90_plastic(&p, eb(step * (k - 1) as f64)),
    );
    for r in [0.0f64, 0.5, 1.0, 2.0] {
        let ex = step * (k as f64 + r.max(0.25));
        let ((_, sig_impl, _), yk) = uniaxial_x(&p, c, ex, [lateral[k], 0.0]);
        assert!(sig_impl[1].abs() < 1e-9 * p.fcm);
        let strain = [ex, yk[0], yk[1]];
        let t = update_extrapolated(&q, c, &strain, 0.1, r).unwrap().0;
        assert!(t.n_cracks == 0 && !t.is_crushed());
        let want_x = p.ec * (pn + r * (pn - po) - mc90_plastic(&p, eb(ex)));
        let want_y = p.ec * (yk[0] - (lateral[k] + r * (lateral[k] - lateral[k - 1])));
        let got = point_stress_error(&q, c, &t, 0.1, r, 0.0);
        assert!(
            (got[0] - want_x).abs() <= 1e-6 * want_x.abs(),
            "r = {r}: Δσx {} want {want_x}",
            got[0]
        );
        assert!(
            (got[1] - want_y).abs() <= 1e-6 * want_x.abs().max(want_y.abs()),
            "r = {r}: Δσy {} want {want_y}",
            got[1]
        );
        assert!(got[2].abs() <= 1e-9 * p.fcm, "r = {r}: τ {}", got[2]);
        let err = point_error(&q, c, &t, 0.1, r, 0.0);
        let want = want_x.abs().max(want_y.abs()) / p.fcm;
        assert!(
            (err - want).abs() <= 1e-6 * want,
            "r = {r}: {err} f_cm, want {want}"
        );
        assert!(err > 1e-4, "r = {r}: a real difference ({err} f_cm)");
        // Off, and in a time increment: the crack measure alone (no crack: 0).
        let ti = update_extrapolated(&p, c, &strain, 0.1, r).unwrap().0;
        assert_eq!(point_stress_error(&p, c, &ti, 0.1, r, 0.0), [0.0; 3]);
        assert_eq!(point_error(&p, c, &ti, 0.1, r, 0.0), 0.0);
        assert_eq!(point_stress_error(&q, c, &t, 0.1, r, 1.0), [0.0; 3]);
        assert_eq!(point_error(&q, c, &t, 0.1, r, 1.0), 0.0);
    }
    // An elastic increment: a virgin point stretched below the tensile strength twice.
    let e0 = p.eps0();
    let a = update_extrapolated(&q, &ConcreteState::new(), &[0.3 * e0, 0.0, 0.0], 0.1, 0.0)
        .unwrap()
        .0;
    let b = update_extrapolated(&q, &a, &[0.6 * e0, 0.0, 0.0], 0.1, 1.0)
        .unwrap()
        .0;
    assert_eq!(b.n_cracks, 0);
    assert_eq!(point_stress_error(&q, &a, &b, 0.1, 1.0, 0.0), [0.0; 3]);
    assert_eq!(point_error(&q, &a, &b, 0.1, 1.0, 0.0), 0.0);
}

/// The same for a cracked point (docs/theory-concrete.md §4): cracked along x (opened to
/// 3 ε0), then compressed along a crack axis — y, parallel to the crack (the crack held
/// open), or x, the crack's normal (the crack closed) — the 1-D crush-band law of
/// [`crack_axis_law`] in both, past the peak in equal increments Δ, then one increment of
/// r Δ with ratio r. The direction's implicit stress is −σ_c(ε̄) = E (e + p(ε̄)), ε̄ = −e,
/// p = ε̄ − σ_c(ε̄)/E, its IMPL-EX one E (e + p̃), so its difference is E (p̃ − p(ε̄_k))
/// from the closed-form law; the crack adds nothing (held at its largest strain, or closed),
/// nor does the other direction (unstrained, elastic), and with the crack at 0° Δσ is that
/// difference on the compressed axis alone. The point error is its magnitude over f_cm.
/// Tolerance 1e-6 of the difference (the 1-D return is closed form; the law is checked at
/// 1e-6 f_cm in `implex_compression_of_a_crack_direction_is_linear_in_the_increment`,
/// against differences of 1e-3 to 0.06 f_cm here). None with the option off or in a time
/// increment.
#[test]
fn implex_compression_error_of_a_crack_direction_is_its_extrapolated_flow() {
    let h = 0.1;
    let mut p = params().with_crush_band();
    p.implex = true;
    let mut q = p.clone();
    q.compression_implex = true;
    let (law, eu) = crack_axis_law(&p, h);
    let plastic = |eb: f64| eb - law(eb) / p.ec;
    let ex = 3.0 * p.eps0();
    let n = 12;
    let step = -1.5 * p.eps_c1 / n as f64;
    assert!(
        1.5 * p.eps_c1 + 2.0 * step.abs() < 0.9 * eu,
        "short of crushing"
    );
    for axis in [1, 0] {
        // The strain with `e` on the compressed axis: y with the crack open at 3 ε0, or
        // x (the crack closed) with y unstrained.
        let strain = |e: f64| {
            if axis == 1 {
                [ex, e, 0.0]
            } else {
                [e, 0.0, 0.0]
            }
        };
        let mut st = update_extrapolated(&q, &ConcreteState::new(), &[ex, 0.0, 0.0], h, 0.0)
            .unwrap()
            .0;
        assert_eq!((st.n_cracks, st.crack_angle), (1, 0.0));
        for k in 1..n {
            let ratio = if k == 1 { 0.0 } else { 1.0 };
            st = update_extrapolated(&q, &st, &strain(step * k as f64), h, ratio)
                .unwrap()
                .0;
        }
        let k = n - 1;
        assert!(-step * (k - 1) as f64 > p.eps_c1, "past the peak");
        let (pn, po) = (plastic(-step * k as f64), plastic(-step * (k - 1) as f64));
        for r in [0.0f64, 0.5, 1.0, 2.0] {
            let e = step * (k as f64 + r.max(0.25));
            let t = update_extrapolated(&q, &st, &strain(e), h, r).unwrap().0;
            assert!(t.n_cracks == 1 && !t.is_crushed());
            let want = p.ec * (pn + r * (pn - po) - plastic(-e));
            let got = point_stress_error(&q, &st, &t, h, r, 0.0);
            assert!(
                got[1 - axis].abs() <= 1e-9 * p.fcm,
                "axis {axis}, r = {r}: the other direction {got:?}"
            );
            assert!(
                (got[axis] - want).abs() <= 1e-6 * want.abs(),
                "axis {axis}, r = {r}: Δσ {} want {want}",
                got[axis]
            );
            assert!(got[2].abs() <= 1e-9 * p.fcm, "r = {r}: τ {}", got[2]);
            let err = point_error(&q, &st, &t, h, r, 0.0);
            assert!(
                (err - want.abs() / p.fcm).abs() <= 1e-6 * want.abs() / p.fcm,
                "axis {axis}, r = {r}: {err} f_cm, want {}",
                want.abs() / p.fcm
            );
            let ti = update_extrapolated(&p, &st, &strain(e), h, r).unwrap().0;
            assert_eq!(point_stress_error(&p, &st, &ti, h, r, 0.0), [0.0; 3]);
            assert_eq!(point_stress_error(&q, &st, &t, h, r, 1.0), [0.0; 3]);
            assert_eq!(point_error(&q, &st, &t, h, r, 1.0), 0.0);
        }
    }
}
