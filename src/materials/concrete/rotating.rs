//! Rotating smeared cracks: a total-strain, coaxial model (docs/theory-concrete.md §5.4).
//!
//! The stress is coaxial with the total strain. In the principal axes of the strain
//! (ε1 ≥ ε2, ε1 at angle θ from x) each direction has a uniaxial law of its equivalent
//! uniaxial strain ε̃ (ε̃ = A ε' with the plane-stress Poisson coupling A while the point
//! has never cracked, ε̃ = ε' after):
//!
//! * tension: the fixed model's envelope ([`super::cracking::tension_envelope`]: E ε up to
//!   f_tm, then Hinton's exponential or the crack band) on loading, secant to the origin on
//!   unloading/reloading below the largest strain reached; the point cracks (ν → 0) when
//!   E ε̃1 reaches f_tm (Rankine);
//! * compression: the uncracked model's uniaxial curve (MC90 with its softening limit, or
//!   the crush band) scaled by the compression-softening factor β_d of the other
//!   direction's tensile strain ([`super::reduction`]), σ = −β_d σ_c(−ε̃/β_d), on loading;
//!   secant to the origin from the largest curve strain reached on unloading; the point
//!   crushes (zero stress for ever) at curve strain ε_cu; when both directions are
//!   compressed, both curves are stretched instead by the biaxial gain K(α) ≥ 1 of the
//!   principal stress ratio ([`super::biaxial`], Kupfer & Gerstle 1973), found by
//!   fixed-point iteration, its derivative in the tangent.
//!
//! Histories are kept per principal direction in the sorted order (1 = larger strain).
//! Tangent: T(θ)ᵀ D'' T(θ), D'' = [[∂σ_i/∂ε'_j], G], with the coaxiality shear term
//! G = (σ1 − σ2)/(2(ε1 − ε2)) (Willam, Pramono & Sture 1987; Rots 1988), which makes it the
//! consistent tangent of the rotating law (its limit 0.25 (D11 − D12 − D21 + D22) for
//! ε1 = ε2).

use super::cracking::{strain_transform, tension_envelope};
use super::{
    biaxial, compression, reduction, ConcreteParams, ConcreteState, MaterialError, UpdateResult,
};

/// Principal strains ε1 ≥ ε2 [-] of (εx, εy, γxy) and the angle of ε1 from x [rad].
pub fn principal_strains(e: &[f64; 3]) -> (f64, f64, f64) {
    let c = 0.5 * (e[0] + e[1]);
    let r = (0.25 * (e[0] - e[1]).powi(2) + 0.25 * e[2] * e[2]).sqrt();
    (c + r, c - r, 0.5 * e[2].atan2(e[0] - e[1]))
}

/// Result of one principal direction's law.
#[derive(Debug, Clone, Copy, Default)]
struct Dir {
    /// Stress [Pa].
    sigma: f64,
    /// ∂σ/∂ε̃ of this direction [Pa].
    k: f64,
    /// ∂σ/∂ε̃_lat [Pa] (compression softening by the other direction's tensile strain).
    d_lateral: f64,
    /// ∂σ/∂(scale of the curve) [Pa] at fixed strain (the biaxial gain's lever).
    d_scale: f64,
    /// Largest tensile strain reached [-].
    emax: f64,
    /// Largest compressive curve strain reached [-].
    xmax: f64,
    /// The direction reached the crushing strain.
    crushed: bool,
}

/// Uniaxial law of one principal direction at equivalent strain `e` [-] with lateral
/// strain `lat` [-] (the other direction's), histories `emax`, `xmax` and held branch
/// `frozen` (1 envelope, −1 secant, 0 free; see [`super::ConcreteState`]), the biaxial
/// gain `gain` [-] and, with IMPL-EX, the extrapolated largest tensile strain `ex` [-];
/// `h` [m] is the crack band width (for the crack spacing of the compression softening).
fn direction(
    p: &ConcreteParams,
    (alpha, h): (f64, f64),
    (emax, xmax, frozen): (f64, f64, i8),
    e: f64,
    (lat, gain, ex): (f64, f64, Option<f64>),
) -> Dir {
    let mut r = Dir {
        emax,
        xmax,
        ..Dir::default()
    };
    if e >= 0.0 {
        if let Some(ex) = ex {
            // IMPL-EX (as the fixed cracks): the secant at the extrapolated largest strain
            // up to it, then its smooth continuation (`implex::tension`); e_max itself is
            // updated implicitly for the next extrapolation.
            (r.sigma, r.k) = super::implex::tension(p, alpha, ex, e);
            r.emax = e.max(emax);
        } else if frozen > 0 || (frozen == 0 && e >= emax) || emax <= 0.0 {
            let (s, k) = tension_envelope(p, alpha, e);
            r.sigma = s;
            r.k = k;
            r.emax = e.max(emax);
        } else {
            let sec = tension_envelope(p, alpha, emax).0 / emax;
            r.sigma = sec * e;
            r.k = sec;
        }
        return r;
    }
    // Compression softening by a tensile lateral strain, or the biaxial gain K ≥ 1 when
    // both directions are compressed (never both: K > 1 needs a compressed lateral).
    let (beta, dbeta) = if lat > 0.0 {
        reduction::factor(p, lat, h)
    } else {
        (gain, 0.0)
    };
    let x = -e / beta;
    if x >= xmax {
        let (s0, ds0) = compression::hardening_curve(p, x);
        r.sigma = -beta * s0;
        r.k = ds0;
        // ∂(−β σ_c(−e/β))/∂β = −σ_c(x) + x σ_c'(x).
        r.d_scale = -s0 + x * ds0;
        r.d_lateral = r.d_scale * dbeta;
        r.xmax = x;
        r.crushed = x >= p.eps_cu || (x > p.eps_c1 && s0 <= 0.0);
    } else {
        let sec = if xmax > 0.0 {
            compression::hardening_curve(p, xmax).0 / xmax
        } else {
            p.ec
        };
        r.sigma = sec * e;
        r.k = sec;
    }
    r
}

/// Stress update of a rotating-crack point from the committed state and the total strain
/// (εx, εy, γxy) [-]; `char_length` [m] is the crack band width (crack band only).
/// `ratio` [-] is the IMPL-EX extrapolation ratio (size of this increment over the
/// previous one; only with `p.implex`).
pub fn update(
    p: &ConcreteParams,
    committed: &ConcreteState,
    strain: &[f64; 3],
    char_length: f64,
    ratio: f64,
) -> UpdateResult {
    if matches!(p.tension, super::TensionSoftening::CrackBand { .. })
        && !(char_length > 0.0 && char_length.is_finite())
    {
        return Err(MaterialError::InvalidParams(format!(
            "crack band needs a positive characteristic length, got {char_length}"
        )));
    }
    let alpha = p.softening_alpha(char_length);
    let (e1, e2, theta) = principal_strains(strain);
    let mut cracked = committed.n_cracks > 0;
    let mut out = evaluate(p, committed, (alpha, char_length), [e1, e2], cracked, ratio);
    // IMPL-EX decides cracking on the committed state (explicitly): in the increment the
    // point cracks its law stays the uncracked one, capped past f_tm.
    if p.implex && !cracked && out.0[0].max(out.0[1]) >= p.eps0() {
        cracked = true;
    } else if !cracked && out.0[0].max(out.0[1]) >= p.eps0() {
        // The point cracks: the Poisson coupling goes (as in the fixed model) and the laws
        // are re-evaluated at the same strain.
        cracked = true;
        out = evaluate(p, committed, (alpha, char_length), [e1, e2], cracked, ratio);
    }
    let (et, d, mut dp) = out;
    if p.secant_crack_tangent && cracked {
        // Secant tangent (symmetric, non-negative): σ_i/ε̃_i per direction, no cross terms,
        // floored at the residual stiffness; the coaxial shear term below is a secant too.
        for i in 0..2 {
            let sec = if et[i].abs() > 1e-14 {
                d[i].sigma / et[i]
            } else {
                d[i].k
            };
            dp[i] = [0.0, 0.0];
            dp[i][i] = sec.max(p.residual_stiffness * p.ec);
        }
    }
    let mut st = committed.clone();
    st.strain = *strain;
    st.crack_angle = theta;
    st.crack_max = [d[0].emax, d[1].emax];
    st.crack_max_old = committed.crack_max;
    if p.implex && committed.n_cracks == 0 && cracked {
        // Formation: the strain reached is e_max with zero rate (as the fixed cracks).
        st.crack_max_old = st.crack_max;
    }
    st.crack_strain = et;
    st.dir_ebar = [d[0].xmax, d[1].xmax];
    if d[0].crushed || d[1].crushed {
        st.crushed = true;
        return Ok(super::crushed(p, &st, strain));
    }
    let open = d.iter().filter(|r| r.emax > p.eps0()).count() as u8;
    st.n_cracks = if cracked {
        open.max(committed.n_cracks).max(1)
    } else {
        0
    };
    // Coaxiality: the shear modulus that keeps the stress on the rotating axes.
    let de = e1 - e2;
    let g = if de > 1e-12 * (e1.abs() + e2.abs()) && de > 0.0 {
        (d[0].sigma - d[1].sigma) / (2.0 * de)
    } else {
        0.25 * (dp[0][0] - dp[0][1] - dp[1][0] + dp[1][1])
    };
    let dl = [
        [dp[0][0], dp[0][1], 0.0],
        [dp[1][0], dp[1][1], 0.0],
        [0.0, 0.0, g],
    ];
    let sl = [d[0].sigma, d[1].sigma, 0.0];
    let t = strain_transform(theta);
    let (s, tan) = super::cracking::to_global(&t, &sl, &dl);
    st.stress = s;
    Ok((st, s, tan))
}

/// The two direction laws at principal strains `e` [-]: equivalent strains, results and
/// ∂σ_i/∂ε'_j [Pa].
fn evaluate(
    p: &ConcreteParams,
    c: &ConcreteState,
    alpha: (f64, f64),
    e: [f64; 2],
    cracked: bool,
    ratio: f64,
) -> ([f64; 2], [Dir; 2], [[f64; 2]; 2]) {
    let nu = if cracked { 0.0 } else { p.nu };
    let f = 1.0 / (1.0 - nu * nu);
    let a = [[f, f * nu], [f * nu, f]];
    let et = [
        a[0][0] * e[0] + a[0][1] * e[1],
        a[1][0] * e[0] + a[1][1] * e[1],
    ];
    // IMPL-EX: e_max extrapolated linearly from the last two committed states (ε0 before
    // the point has cracked: elastic up to f_tm, then the capped line).
    let ex = |i: usize| {
        p.implex.then(|| {
            if c.n_cracks > 0 {
                super::implex::extrapolated_max(c, i, ratio)
            } else {
                p.eps0()
            }
        })
    };
    let dirs = |gain: f64| -> [Dir; 2] {
        std::array::from_fn(|i| {
            let h = (c.crack_max[i], c.dir_ebar[i], c.frozen[i]);
            direction(p, alpha, h, et[i], (et[1 - i], gain, ex(i)))
        })
    };
    let mut d = dirs(1.0);
    // Biaxial compression: K(α) of the stresses it produces, by fixed-point iteration (a
    // contraction: |dK/dα| ≤ 0.25 and α moves little with K).
    let mut kg = None;
    if et[0] < 0.0 && et[1] < 0.0 {
        let mut k = 1.0;
        for _ in 0..100 {
            let Some((r, _)) = biaxial::ratio([d[0].sigma, d[1].sigma]) else {
                break;
            };
            let k_new = biaxial::gain(r).0;
            let done = (k_new - k).abs() <= 1e-13;
            k = k_new;
            d = dirs(k);
            if done {
                break;
            }
        }
        kg = biaxial::ratio([d[0].sigma, d[1].sigma]).map(|(r, dr)| (biaxial::gain(r).1, dr));
    }
    let mut dp: [[f64; 2]; 2] = std::array::from_fn(|i| {
        let j = 1 - i;
        let lat_on = if et[j] > 0.0 { 1.0 } else { 0.0 };
        std::array::from_fn(|m| d[i].k * a[i][m] + d[i].d_lateral * lat_on * a[j][m])
    });
    if let Some((dk, dr)) = kg {
        // dσ = A dε + s dK, dK = gᵀ dσ (g = K'(α) ∂α/∂σ, s = ∂σ/∂K): dσ/dε = A +
        // s (gᵀA)/(1 − gᵀs) (Sherman–Morrison).
        let s = [d[0].d_scale, d[1].d_scale];
        let g = [dk * dr[0], dk * dr[1]];
        let den = 1.0 - (g[0] * s[0] + g[1] * s[1]);
        if den.abs() > 1e-12 {
            let ga: [f64; 2] = std::array::from_fn(|m| g[0] * dp[0][m] + g[1] * dp[1][m]);
            for (i, row) in dp.iter_mut().enumerate() {
                for (m, v) in row.iter_mut().enumerate() {
                    *v += s[i] * ga[m] / den;
                }
            }
        }
    }
    (et, d, dp)
}
