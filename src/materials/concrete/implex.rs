//! The tension law of an IMPL-EX crack direction within one increment
//! (docs/theory-concrete.md §5.2), shared by the fixed (`cracking.rs`) and rotating
//! (`rotating.rs`) crack models.
//!
//! Up to the extrapolated largest crack strain ẽ the direction follows the secant of the
//! envelope at ẽ (Oliver, Huespe & Cante 2008). Past ẽ — the crack opens faster than
//! extrapolated — its incremental stiffness is the envelope's secant at the current
//! strain, g(ε) = σ_env(ε)/ε:
//!
//! σ(ε) = σ_env(ẽ) + ∫_ẽ^ε σ_env(x)/x dx,  dσ/dε = g(ε).
//!
//! g is continuous at ẽ (it is the secant there), positive and decreasing, so the law is
//! monotone, C¹ (no kink for Newton to cycle on) and concave; the overshoot above the
//! envelope grows with the logarithm of ε/ẽ, not linearly (the plain secant's stress goes on
//! rising at the secant stiffness, E for a crack in its first increment). No constant is
//! chosen: the stiffness past ẽ is the one the crack has on reloading once its largest strain
//! is ε. For the exponential envelope f_tm exp(−(x − ε0)/α) the integral is
//! f_tm [e^{(ε0−a)/α} S(a/α) − e^{(ε0−b)/α} S(b/α)], S(x) = eˣ E₁(x) (E₁ the exponential
//! integral).

use super::cracking::tension_envelope;
use super::{ConcreteParams, ConcreteState, CrackModel};

/// Stress [Pa] and tangent [Pa] of an IMPL-EX crack direction at crack-normal strain `e` ≥ 0
/// [-], with extrapolated largest strain `ex` [-] (raised to ε0 = f_tm/E) and softening
/// parameter `alpha` [-] of the envelope.
pub fn tension(p: &ConcreteParams, alpha: f64, ex: f64, e: f64) -> (f64, f64) {
    let ex = ex.max(p.eps0());
    let s_ex = tension_envelope(p, alpha, ex).0;
    let k = s_ex / ex;
    if e <= ex {
        return (k * e, k);
    }
    let (s_e, _) = tension_envelope(p, alpha, e);
    (s_ex + secant_integral(p, alpha, ex, e), s_e / e)
}

/// ∫_a^b σ_env(x)/x dx [Pa] for ε0 ≤ a ≤ b on the exponential envelope.
pub fn secant_integral(p: &ConcreteParams, alpha: f64, a: f64, b: f64) -> f64 {
    let e0 = p.eps0();
    let term = |x: f64| ((e0 - x) / alpha).exp() * exp_e1(x / alpha);
    p.ftm * (term(a) - term(b)).max(0.0)
}

/// S(x) = eˣ E₁(x) [-] for x > 0, E₁ the exponential integral ∫_x^∞ e^{−t}/t dt: the power
/// series below 2, the continued fraction (modified Lentz) above (Abramowitz & Stegun 5.1.11
/// and 5.1.22); relative error below 1e-13 on both.
pub fn exp_e1(x: f64) -> f64 {
    const EULER_GAMMA: f64 = 0.577_215_664_901_532_9;
    if x <= 2.0 {
        // E₁(x) = −γ − ln x − Σ_{k≥1} (−x)^k / (k·k!).
        let mut sum = 0.0;
        let mut term = 1.0;
        for k in 1..60 {
            term *= -x / k as f64;
            let add = term / k as f64;
            sum += add;
            if add.abs() <= 1e-17 * sum.abs() {
                break;
            }
        }
        x.exp() * (-EULER_GAMMA - x.ln() - sum)
    } else {
        // eˣ E₁(x) = 1/(x + 1 − 1²/(x + 3 − 2²/(x + 5 − …))).
        let tiny = 1e-300;
        let mut b = x + 1.0;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..200 {
            let an = -((i * i) as f64);
            b += 2.0;
            d = 1.0 / (an * d + b);
            c = b + an / c;
            let del = c * d;
            h *= del;
            if (del - 1.0).abs() <= 1e-16 {
                break;
            }
        }
        h
    }
}

/// IMPL-EX largest crack strain of direction `i` [-] for an increment with extrapolation
/// ratio `ratio` [-] (its size over the last one's): the committed largest strain
/// extrapolated linearly from the last two committed states, never backwards.
pub fn extrapolated_max(committed: &ConcreteState, i: usize, ratio: f64) -> f64 {
    let (m, o) = (committed.crack_max[i], committed.crack_max_old[i]);
    m + ratio.max(0.0) * (m - o).max(0.0)
}

/// The stress [Pa] the implicit crack law gives at crack strain `e` ≥ 0 [-] from the
/// committed largest strain `emax` [-]: on the envelope if `e` passes `emax` (or nothing has
/// opened), else on the committed secant.
pub fn implicit_tension(p: &ConcreteParams, alpha: f64, emax: f64, e: f64) -> f64 {
    if e >= emax || emax <= 0.0 {
        tension_envelope(p, alpha, e).0
    } else {
        tension_envelope(p, alpha, emax).0 / emax * e
    }
}

/// IMPL-EX error of one crack direction [Pa]: |σ_implex − σ_implicit| at crack strain `e`
/// [-], extrapolated largest strain `ex` [-] and committed largest strain `emax` [-] (0 for
/// a compressed direction, which both integrations treat alike).
pub fn direction_error(p: &ConcreteParams, alpha: f64, (ex, emax): (f64, f64), e: f64) -> f64 {
    direction_difference(p, alpha, (ex, emax), e).abs()
}

/// Signed IMPL-EX error of one crack direction [Pa]: σ_implex − σ_implicit at crack strain
/// `e` [-] (arguments as [`direction_error`]; 0 for a compressed direction).
pub fn direction_difference(p: &ConcreteParams, alpha: f64, (ex, emax): (f64, f64), e: f64) -> f64 {
    if e <= 0.0 {
        return 0.0;
    }
    tension(p, alpha, ex, e).0 - implicit_tension(p, alpha, emax, e)
}

/// The crack-normal stress differences σ_implex − σ_implicit [Pa] of a concrete point's two
/// crack directions at the end of an increment, and the angle φ [rad] of the first
/// direction's normal from x (the second's is φ + 90°): the directions and laws of
/// [`point_error`] (arguments as there), signed; zero where that measure is zero.
pub fn direction_differences(
    p: &ConcreteParams,
    committed: &ConcreteState,
    trial: &ConcreteState,
    char_length: f64,
    ratio: f64,
) -> ([f64; 2], f64) {
    let mut d = [0.0; 2];
    if !p.implex || trial.crushed || committed.crushed {
        return (d, 0.0);
    }
    let alpha = p.softening_alpha(char_length);
    let extrapolated = |i: usize| extrapolated_max(committed, i, ratio);
    match p.crack_model {
        CrackModel::Rotating => {
            // Before the point has cracked its law is the one capped past ε0
            // (`rotating::evaluate`), so the extrapolated strain is ε0.
            for (i, di) in d.iter_mut().enumerate() {
                let ex = if committed.n_cracks > 0 {
                    extrapolated(i)
                } else {
                    p.eps0()
                };
                let e = trial.crack_strain[i];
                *di = direction_difference(p, alpha, (ex, committed.crack_max[i]), e);
            }
        }
        CrackModel::Fixed => {
            // A crack formed in this increment (elastic in it) is not measured: where it
            // forms at a jump of the strain, the jump does not shrink with the increment.
            let n = trial.n_cracks.min(committed.n_cracks).min(2) as usize;
            for (i, di) in d.iter_mut().enumerate().take(n) {
                let e = trial.crack_strain[i];
                let emax = committed.crack_max[i];
                *di = direction_difference(p, alpha, (extrapolated(i), emax), e);
            }
        }
    }
    (d, trial.crack_angle)
}

/// The IMPL-EX compression's part of a point's stress error (docs/theory-concrete.md §4):
/// where the compression extrapolation acted in the increment, σ_implex − σ_implicit at the
/// converged strain from the compressive plastic strain's extrapolation alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CompressionDifference {
    /// The option did not act (off, a time increment, a crushed point, or a point that
    /// cracks in the increment): no difference.
    None,
    /// An uncracked point: Δσ = D (εᵖ_impl − ε̃ᵖ) [Pa] (σ_xx, σ_yy, τ_xy), εᵖ_impl the
    /// implicit update's plastic strain, ε̃ᵖ = εᵖ_n + r (εᵖ_n − εᵖ_n−1) the extrapolation.
    Uncracked([f64; 3]),
    /// A cracked point: per crack-axis direction the IMPL-EX compression law's stress minus
    /// the implicit 1-D law's [Pa], in the axes of the point's first crack.
    Cracked([f64; 2]),
}

/// The IMPL-EX compression's stress difference of a concrete point at the end of an
/// increment of `dt` [d] (only load-type increments, `dt` = 0, extrapolate; arguments as
/// [`point_error`]): [`CompressionDifference::None`] unless `compression_integration =
/// "implex"` acted — a point uncracked in its committed and trial states (not crushed), or
/// a point cracked in its committed state whose trial is not crushed.
pub fn compression_difference(
    p: &ConcreteParams,
    committed: &ConcreteState,
    trial: &ConcreteState,
    char_length: f64,
    ratio: f64,
    dt: f64,
) -> CompressionDifference {
    if !(p.implex && p.compression_implex && dt == 0.0)
        || p.crack_model != CrackModel::Fixed
        || trial.crushed
        || committed.crushed
    {
        return CompressionDifference::None;
    }
    if committed.n_cracks == 0 {
        if trial.n_cracks > 0 {
            return CompressionDifference::None;
        }
        let dp: [f64; 3] = std::array::from_fn(|i| {
            let c = committed.plastic_strain[i];
            trial.plastic_strain[i] - (c + ratio * (c - committed.plastic_strain_old[i]))
        });
        if dp == [0.0; 3] {
            return CompressionDifference::Uncracked([0.0; 3]);
        }
        let d = super::d_matrix(p.ec, p.nu);
        return CompressionDifference::Uncracked(std::array::from_fn(|i| {
            (0..3).map(|j| d[i][j] * dp[j]).sum()
        }));
    }
    // The element's parameters, as in the update (the crush band's ε_u).
    let Ok(local) = p.resolved_for(char_length) else {
        return CompressionDifference::None;
    };
    CompressionDifference::Cracked(super::cracking::implex_compression_differences(
        &local,
        committed,
        &trial.strain,
        char_length,
        ratio,
    ))
}

/// The IMPL-EX stress error of a concrete point as a stress [Pa] (σ_xx, σ_yy, τ_xy):
/// Δσ = Σ_i (σ_implex,i − σ_implicit,i) n_i ⊗ n_i over its two crack directions
/// ([`direction_differences`], n_1 at φ from x, n_2 at φ + 90°). In the crack axes the two
/// integrations differ only in the crack-normal stresses at the same strain (the shear
/// retention's β(ε̃) is not compared, as in [`point_error`]), so this is the stress the
/// implicit law would remove from (add to) the point at the converged strain. With
/// `compression_integration = "implex"` in a load-type increment (`dt` = 0 [d]) the
/// compression extrapolation's difference ([`compression_difference`]) is included: a
/// cracked point's is added to each direction's crack difference before the rotation, an
/// uncracked point's Δσ = D (εᵖ_impl − ε̃ᵖ) is the whole error.
pub fn point_stress_error(
    p: &ConcreteParams,
    committed: &ConcreteState,
    trial: &ConcreteState,
    char_length: f64,
    ratio: f64,
    dt: f64,
) -> [f64; 3] {
    let ([mut d1, mut d2], phi) = direction_differences(p, committed, trial, char_length, ratio);
    match compression_difference(p, committed, trial, char_length, ratio, dt) {
        CompressionDifference::None => {}
        CompressionDifference::Uncracked(ds) => return ds,
        CompressionDifference::Cracked([c1, c2]) => {
            d1 += c1;
            d2 += c2;
        }
    }
    let (s, c) = phi.sin_cos();
    // n_1 = (c, s), n_2 = (−s, c): n n = [[c², cs], [cs, s²]] and [[s², −cs], [−cs, c²]].
    [
        d1 * c * c + d2 * s * s,
        d1 * s * s + d2 * c * c,
        (d1 - d2) * c * s,
    ]
}

/// IMPL-EX error of a concrete point at the end of an increment of `dt` [d]: the largest
/// |σ_implex − σ_implicit| / f_tm over its crack directions (docs/theory-concrete.md §5.2,
/// "Error control"), `committed` the state the increment started from, `trial` its converged
/// state, `char_length` [m] the crack band width and `ratio` [-] the extrapolation ratio the
/// increment used. σ_implicit is the stress the implicit crack law would give at the same
/// crack strain from the committed history. Only the directions cracked in the committed
/// state are measured (a fixed crack forming in the increment, elastic in it, is not; a
/// rotating point's first increment past ε0 is, against the envelope). With
/// `compression_integration = "implex"` in a load-type increment (`dt` = 0) the compression
/// extrapolation's difference ([`compression_difference`]) is measured as well, relative to
/// f_cm (docs/theory-concrete.md §4): a cracked point's per crack-axis direction, an
/// uncracked point's as the largest absolute principal value of its Δσ; the point's error
/// is the larger of the two parts [-]. 0 without IMPL-EX and for crushed points.
pub fn point_error(
    p: &ConcreteParams,
    committed: &ConcreteState,
    trial: &ConcreteState,
    char_length: f64,
    ratio: f64,
    dt: f64,
) -> f64 {
    let (d, _) = direction_differences(p, committed, trial, char_length, ratio);
    let cracks = d[0].abs().max(d[1].abs()) / p.ftm;
    let compression = match compression_difference(p, committed, trial, char_length, ratio, dt) {
        CompressionDifference::None => return cracks,
        CompressionDifference::Uncracked(ds) => {
            // Largest |principal value| of the symmetric Δσ.
            let m = 0.5 * (ds[0] + ds[1]);
            let r = (0.25 * (ds[0] - ds[1]).powi(2) + ds[2] * ds[2]).sqrt();
            m.abs() + r
        }
        CompressionDifference::Cracked(c) => c[0].abs().max(c[1].abs()),
    };
    cracks.max(compression / p.fcm)
}
