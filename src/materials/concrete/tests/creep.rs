//! Creep in series with the concrete law at a crushing point (concrete/creep.rs).

use super::super::creep::{self, ConcreteCreep};
use super::*;
use crate::materials::chain::MaxwellChain;
use crate::materials::mc90_time::{CementClass, CreepShrinkageParams};
use std::sync::Arc;

/// Equal biaxial compression in load steps on 27-year-old creeping concrete, past crushing.
///
/// A load step (no time passes) at that age puts the chain's instantaneous modulus
/// E'' = E_c(t) ≈ 1.13 E_c in series with the law, whose modulus is E_c: the series is
/// ε = ε_m + (1/E'' − 1/E_c) D1⁻¹ σ(ε_m), with 1/E'' − 1/E_c < 0. At crushing σ jumps to
/// zero, so the total strain at which the uncrushed law reaches ε_cu,
/// ε* = ε_m,cu + c (1 − ν) σ_cu (equal biaxial: D1⁻¹σ = (1 − ν) σ per component), lies
/// beyond the total strain the crushed series gives for the same ε_m, by
/// w = |c| (1 − ν) |σ_cu|: a total strain within that window has no uncrushed state and no
/// crushed state of the law below ε_cu (the local iteration used to bounce across the jump
/// and fail, issue 38). The crushing law says: uncrushed with σ = F(ε_m) while ε > ε*,
/// crushed with σ = 0 from the first strain past ε*, and crushed thereafter.
///
/// ε_m,cu and σ_cu come from the time-independent law (bisection on its crushed flag
/// along the same proportional path; backward-Euler return on a fixed stress direction is
/// exact, so one update from the virgin state is the path), E'' from the chain (its
/// instantaneous modulus: the sum of the unit moduli at that age). Steps of 1e-5 are
/// several to a window of w ≈ 6e-5, so some step lands in it.
#[test]
fn creeping_point_crushes_at_the_series_crushing_strain_and_carries_no_stress() {
    let fcm = 48e6;
    let mut p = ConcreteParams::from_mc90(fcm, 0.2);
    let plain = p.clone();
    let cs = CreepShrinkageParams::new(fcm, 0.7, 0.25, CementClass::N, 3.0);
    let chain = MaxwellChain::fit(&cs, 5).expect("chain");
    let age = 10_000.0;
    let e2: f64 = chain.unit_moduli(age).iter().sum();
    p.creep = Some(ConcreteCreep {
        chain: Arc::new(chain),
        cast_day: 0.0,
        shrinkage: false,
        nonlinear: false,
    });
    let cr = p.creep.as_ref().map(|_| 1.0 / e2 - 1.0 / p.ec).unwrap();
    assert!(
        cr < 0.0,
        "the chain is stiffer than E_c at {age} d: c = {cr:e}"
    );
    let nu = p.nu;
    let h = 0.1;

    // The law alone: the crushing strain of the equal biaxial path and the stress there.
    let law = |e: f64| update(&plain, &ConcreteState::new(), &[e, e, 0.0], h).unwrap();
    let (mut lo, mut hi) = (-0.02, -0.001); // crushed at lo, not at hi
    assert!(law(lo).0.is_crushed() && !law(hi).0.is_crushed());
    while hi - lo > 1e-13 {
        let mid = 0.5 * (lo + hi);
        if law(mid).0.is_crushed() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let sigma_cu = law(hi).1[0];
    assert!(
        sigma_cu < -0.5 * fcm,
        "σ_cu = {sigma_cu:e}: a jump to speak of"
    );
    let e_star = hi + cr * (1.0 - nu) * sigma_cu;
    let window = cr.abs() * (1.0 - nu) * sigma_cu.abs();

    // The creeping point, step by step, committed after each step.
    let mut st = ConcreteState::new();
    let step = 1e-5;
    let (mut in_window, mut crushed_at) = (0, None);
    for k in 1..=700 {
        let e = -(k as f64) * step;
        let (next, s, _) = creep::update(&p, &creep_of(&p), &st, &[e, e, 0.0], h, age, age, 1.0)
            .unwrap_or_else(|err| panic!("step {k} (ε = {e:e}): {err}"));
        if e < e_star && e > e_star - window {
            in_window += 1;
        }
        if (e - e_star).abs() > 1e-9 {
            assert_eq!(
                next.is_crushed(),
                e < e_star,
                "step {k}: ε = {e:e}, ε* = {e_star:e}"
            );
        }
        if next.is_crushed() {
            crushed_at.get_or_insert(k);
            assert_eq!(s, [0.0; 3], "step {k}: a crushed point carries no stress");
        } else {
            // Uncrushed: the law's stress at its input (1e-6 f_cm: the return mapping's
            // tolerance), and the series holds: each step solves it to 1e-12 of the
            // strains (≤ 4e-15 here), summed over at most 700 steps ≤ 3e-12; 1e-11.
            let f = update(&plain, &ConcreteState::new(), &next.strain(), h)
                .unwrap()
                .1;
            for i in 0..3 {
                assert!(
                    (s[i] - f[i]).abs() < 1e-6 * fcm,
                    "step {k}: σ {s:?} ≠ F {f:?}"
                );
            }
            let em = next.strain();
            let series = em[0] + cr * (s[0] - nu * s[1]);
            assert!(
                (series - e).abs() < 1e-11,
                "step {k}: series {series:e} ≠ {e:e}"
            );
        }
        st = next;
    }
    assert!(
        in_window >= 1,
        "no step landed in the crushing window {window:e}"
    );
    assert!(crushed_at.is_some(), "never crushed (ε* = {e_star:e})");
    // Crushing is for good: unloading to a small compression keeps zero stress.
    let (_, s, _) = creep::update(
        &p,
        &creep_of(&p),
        &st,
        &[-1e-4, -1e-4, 0.0],
        h,
        age,
        age,
        1.0,
    )
    .unwrap();
    assert_eq!(s, [0.0; 3]);
}

fn creep_of(p: &ConcreteParams) -> ConcreteCreep {
    p.creep.clone().expect("creeping concrete")
}
