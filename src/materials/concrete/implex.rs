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
use super::ConcreteParams;

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
