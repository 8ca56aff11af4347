//! The uniaxial steel law of embedded bars, bar layers and external tendons
//! (docs/theory-bars.md, docs/theory-joints-tendons.md).
//!
//! One law covers both rebar and prestressing steel: linear elastic up to the yield stress
//! f_y, then linear hardening with modulus H (H = 0: perfectly plastic), optionally capped so
//! that the stress never exceeds f_u in magnitude (beyond the cap the law is perfectly plastic
//! at ±f_u). The hardening rule is a parameter ([`HardeningRule`]): **kinematic** for bars
//! (it reproduces the Bauschinger effect on load reversal and keeps the elastic range 2 f_y
//! wide, the usual choice under cyclic/reversed loading) and **isotropic** for external
//! tendons (loaded monotonically in tension; [`crate::elements::tendon::TendonLaw`] adds the
//! slack cut). For monotonic loading the two rules give the same curve. Symmetric in tension
//! and compression.
//!
//! Units: stresses and moduli in Pa, strains dimensionless. The strain passed to
//! [`update_uniaxial`] is the total mechanical strain of the bar *including* any initial
//! (prestressing) strain; the caller adds the prestrain.

/// How the elastic range moves once the steel yields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum HardeningRule {
    /// The elastic range (width 2 f_y) translates with the back stress: Bauschinger effect.
    #[default]
    Kinematic,
    /// The elastic range grows symmetrically to ±min(f_y + H ε̄_p, f_u), ε̄_p = Σ|Δε_p|.
    Isotropic,
}

/// Parameters of the uniaxial steel law.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SteelParams {
    /// Young's modulus E_s [Pa].
    pub es: f64,
    /// Yield stress f_y (rebar) or 0.9 f_ptk (prestressing steel) [Pa].
    pub fy: f64,
    /// Kinematic hardening modulus H (plastic modulus, dσ/dε_p) [Pa]; 0 = perfectly plastic.
    /// The elastoplastic tangent is E_s H/(E_s + H).
    pub hardening: f64,
    /// Stress cap f_u ≥ f_y [Pa]; f64::INFINITY for no cap.
    pub fu: f64,
    /// Hardening rule (kinematic unless set by [`Self::with_rule`]).
    #[serde(default)]
    pub rule: HardeningRule,
}

impl SteelParams {
    /// Reinforcing bar, elastic–perfectly plastic (seed): modulus `es` [Pa], yield `fy` [Pa].
    pub fn rebar(es: f64, fy: f64) -> Self {
        SteelParams {
            es,
            fy,
            hardening: 0.0,
            fu: f64::INFINITY,
            rule: HardeningRule::Kinematic,
        }
    }

    /// Reinforcing bar with linear kinematic hardening of tangent modulus `et` [Pa]
    /// (0 ≤ et < es) after yield; the plastic modulus is H = E_s E_t/(E_s − E_t).
    pub fn rebar_hardening(es: f64, fy: f64, et: f64) -> Self {
        SteelParams {
            es,
            fy,
            hardening: es * et / (es - et),
            fu: f64::INFINITY,
            rule: HardeningRule::Kinematic,
        }
    }

    /// Prestressing steel (seed + a project decision, docs/theory-concrete.md §6): linear elastic
    /// up to 0.9 f_ptk, then perfectly plastic. `ep` [Pa], `fptk` [Pa].
    pub fn prestressing(ep: f64, fptk: f64) -> Self {
        SteelParams {
            es: ep,
            fy: 0.9 * fptk,
            hardening: 0.0,
            fu: f64::INFINITY,
            rule: HardeningRule::Kinematic,
        }
    }

    /// Prestressing steel with linear hardening from (0.9 f_ptk/E_p, 0.9 f_ptk) to
    /// (ε_uk, f_ptk), perfectly plastic at f_ptk beyond ε_uk (no rupture modelled).
    /// `ep` [Pa], `fptk` [Pa], `eps_uk` [-] (> 0.9 f_ptk/E_p).
    pub fn prestressing_hardening(ep: f64, fptk: f64, eps_uk: f64) -> Self {
        let fy = 0.9 * fptk;
        let eps_y = fy / ep;
        let et = (fptk - fy) / (eps_uk - eps_y).max(f64::MIN_POSITIVE);
        SteelParams {
            es: ep,
            fy,
            hardening: ep * et / (ep - et),
            fu: fptk,
            rule: HardeningRule::Kinematic,
        }
    }

    /// The same law with hardening rule `rule`.
    pub fn with_rule(self, rule: HardeningRule) -> Self {
        SteelParams { rule, ..self }
    }
}

/// State of a uniaxial steel point (committed or trial).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct SteelState {
    /// Plastic strain ε_p [-].
    pub plastic_strain: f64,
    /// Back stress (centre of the elastic range) [Pa]; stays 0 under isotropic hardening.
    pub back_stress: f64,
    /// Accumulated plastic strain Σ|Δε_p| [-] (the isotropic hardening variable ε̄_p).
    pub acc_plastic: f64,
}

impl SteelState {
    /// Virgin state (no plastic strain, no back stress).
    pub fn new() -> Self {
        Self::default()
    }
}

/// Stress update of the uniaxial steel law (closed-form return mapping).
///
/// From the `committed` state and the total `strain` [-] returns the trial state, the stress
/// [Pa] and the consistent tangent dσ/dε [Pa] (E_s elastic, E_s H/(E_s + H) hardening,
/// 0 perfectly plastic or at the cap). Pure function; never panics for finite input.
pub fn update_uniaxial(
    p: &SteelParams,
    committed: &SteelState,
    strain: f64,
) -> (SteelState, f64, f64) {
    match p.rule {
        HardeningRule::Kinematic => kinematic(p, committed, strain),
        HardeningRule::Isotropic => isotropic(p, committed, strain),
    }
}

/// True for a point that has flowed and whose trial stress lies on its yield surface to
/// round-off (`f` the yield function, ≤ 0): its committed stress met again with no strain
/// increment (the first assembly of an increment), where the elastic modulus is the tangent
/// of unloading and the plastic one that of continued loading, the better predictor for a
/// point that goes on flowing.
fn on_surface(p: &SteelParams, c: &SteelState, f: f64) -> bool {
    c.acc_plastic > 0.0 && f >= -1e-12 * p.fy
}

/// Return mapping with linear kinematic hardening up to the back stress f_u − f_y.
fn kinematic(p: &SteelParams, committed: &SteelState, strain: f64) -> (SteelState, f64, f64) {
    let e = p.es;
    let sig_tr = e * (strain - committed.plastic_strain);
    let xi = sig_tr - committed.back_stress;
    let f = xi.abs() - p.fy;
    let sgn = xi.signum();
    let h = p.hardening.max(0.0);
    // Room left for hardening in the flow direction before the back stress reaches the cap.
    let alpha_max = (p.fu - p.fy).max(0.0);
    let room = alpha_max - sgn * committed.back_stress;
    if f <= 0.0 {
        if on_surface(p, committed, f) {
            let t = if h > 0.0 && room > 0.0 {
                e * h / (e + h)
            } else {
                0.0
            };
            return (*committed, sig_tr, t);
        }
        return (*committed, sig_tr, e);
    }
    let (dgamma, tangent, back) = if h > 0.0 && room > 0.0 {
        let dg = f / (e + h);
        if h * dg <= room {
            (dg, e * h / (e + h), committed.back_stress + sgn * h * dg)
        } else {
            // Harden until the cap, then perfectly plastic.
            let dg1 = room / h;
            let rest = f - (e + h) * dg1;
            (dg1 + rest / e, 0.0, sgn * alpha_max)
        }
    } else {
        (f / e, 0.0, committed.back_stress)
    };
    let state = SteelState {
        plastic_strain: committed.plastic_strain + sgn * dgamma,
        back_stress: back,
        acc_plastic: committed.acc_plastic + dgamma,
    };
    (state, sig_tr - sgn * e * dgamma, tangent)
}

/// Return mapping with linear isotropic hardening: yield radius min(f_y + H ε̄_p, f_u).
fn isotropic(p: &SteelParams, c: &SteelState, strain: f64) -> (SteelState, f64, f64) {
    let (e, h, cap) = (p.es, p.hardening, p.fu);
    let trial = e * (strain - c.plastic_strain);
    let f = trial.abs() - (p.fy + h * c.acc_plastic).min(cap);
    if f <= 0.0 {
        if on_surface(p, c, f) {
            let below_cap = p.fy + h * c.acc_plastic < cap;
            let t = if h > 0.0 && below_cap {
                e * h / (e + h)
            } else {
                0.0
            };
            return (*c, trial, t);
        }
        return (*c, trial, e);
    }
    // Return on the hardening line, or onto the cap if that line passes it.
    let mut dg = f / (e + h);
    let mut tangent = e * h / (e + h);
    if p.fy + h * (c.acc_plastic + dg) > cap {
        dg = (trial.abs() - cap) / e;
        tangent = 0.0;
    }
    let s = trial.signum();
    let state = SteelState {
        plastic_strain: c.plastic_strain + s * dg,
        back_stress: c.back_stress,
        acc_plastic: c.acc_plastic + dg,
    };
    (state, trial - s * e * dg, tangent)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ES: f64 = 200e9;
    const FY: f64 = 500e6;

    /// Drive a strain history, committing after each step; returns the stresses.
    fn drive(p: &SteelParams, strains: &[f64]) -> Vec<(f64, f64, SteelState)> {
        let mut st = SteelState::new();
        strains
            .iter()
            .map(|&e| {
                let (s, sig, et) = update_uniaxial(p, &st, e);
                st = s;
                (sig, et, s)
            })
            .collect()
    }

    /// A bar that yielded, met again at its committed strain (the first assembly of an
    /// increment), keeps its stress and answers with the tangent of continued loading:
    /// 0 on the seed's plateau, E_s H/(E_s + H) with hardening (kinematic and isotropic),
    /// 0 at the cap; unloading by a small strain gives E_s. Closed forms (1e-12 relative:
    /// round-off of the order of the operations).
    #[test]
    fn yielded_bar_at_its_committed_strain_answers_with_the_loading_tangent() {
        let h = 2e9;
        let hard = |rule| SteelParams {
            es: ES,
            fy: FY,
            hardening: h,
            fu: 600e6,
            rule,
        };
        let cases = [
            (SteelParams::rebar(ES, FY), 0.0),
            (hard(HardeningRule::Kinematic), ES * h / (ES + h)),
            (hard(HardeningRule::Isotropic), ES * h / (ES + h)),
        ];
        for (p, loading) in cases {
            for eps in [0.01, -0.01] {
                let (c, sig, _) = update_uniaxial(&p, &SteelState::new(), eps);
                let (_, again, t) = update_uniaxial(&p, &c, eps);
                // The stress recomputed as E (ε − ε_p): round-off of the return.
                assert!(
                    (again - sig).abs() <= 1e-12 * FY,
                    "{:?}: {again} vs {sig}",
                    p.rule
                );
                // The same closed form, summed in another order: 1e-12 relative.
                assert!(
                    (t - loading).abs() <= 1e-12 * ES,
                    "{:?} at {eps}: {t} vs {loading}",
                    p.rule
                );
                let (_, _, t_back) = update_uniaxial(&p, &c, eps * (1.0 - 1e-6));
                assert_eq!(t_back, ES, "{:?}: unloading", p.rule);
            }
        }
        // At the cap (ε = 0.1 reaches f_u in one step): 0.
        let p = hard(HardeningRule::Kinematic);
        let (c, _, _) = update_uniaxial(&p, &SteelState::new(), 0.1);
        assert_eq!(update_uniaxial(&p, &c, 0.1).2, 0.0);
        // A virgin bar at zero strain is elastic.
        assert_eq!(update_uniaxial(&p, &SteelState::new(), 0.0).2, ES);
    }

    /// Kinematic hardening past its cap in one step (E_s = 200 GPa, f_y = 500 MPa,
    /// H = 2 GPa, f_u = 600 MPa: the back stress reaches f_u − f_y = 100 MPa at ε_p =
    /// 0.05): from zero to ε = 0.1 at once the stress is f_u, the tangent 0, the plastic
    /// strain ε − f_u/E_s = 0.097 and the back stress 100 MPa; from there, unloading by
    /// 0.001 is elastic (σ = 400 MPa). Hand values, 1e-9 relative (closed form).
    #[test]
    fn kinematic_hardening_past_the_cap_in_one_step() {
        let p = SteelParams {
            es: ES,
            fy: FY,
            hardening: 2e9,
            fu: 600e6,
            rule: HardeningRule::Kinematic,
        };
        let r = drive(&p, &[0.1, 0.099]);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1.0);
        assert!(close(r[0].0, 600e6), "{}", r[0].0);
        assert_eq!(r[0].1, 0.0);
        assert!(close(r[0].2.plastic_strain, 0.097), "{:?}", r[0].2);
        assert!(close(r[0].2.back_stress, 100e6), "{:?}", r[0].2);
        assert!(close(r[1].0, 400e6) && close(r[1].1, ES), "{:?}", r[1]);
    }

    /// Elastic–perfectly plastic rebar: yield at f_y, plateau, elastic unloading with E_s,
    /// reverse yield at −f_y. Hand values; tolerance 1e-9 rel (closed form, round-off only).
    #[test]
    fn rebar_yield_unload_reverse() {
        let p = SteelParams::rebar(ES, FY);
        let r = drive(&p, &[0.001, 0.003, 0.01, 0.008, -0.01]);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs().max(1.0);
        assert!(close(r[0].0, 200e6) && close(r[0].1, ES));
        assert!(close(r[1].0, FY) && r[1].1 == 0.0);
        assert!(close(r[2].0, FY));
        assert!(close(r[2].2.plastic_strain, 0.01 - 0.0025));
        // unloading by 0.002 from the plateau: σ = f_y − E_s·0.002 = 100 MPa, elastic
        assert!(close(r[3].0, FY - ES * 0.002) && close(r[3].1, ES));
        // reverse: yields in compression at −f_y (elastic range 2 f_y)
        assert!(close(r[4].0, -FY));
        assert!(close(r[4].2.plastic_strain, -0.01 + 0.0025));
    }

    /// Kinematic hardening: E_t after yield, Bauschinger effect on reversal (reverse yield at
    /// σ_max − 2 f_y, not at −σ_max as isotropic hardening would give). Hand values.
    #[test]
    fn rebar_kinematic_hardening() {
        let et = 2e9; // 1 % of E_s
        let p = SteelParams::rebar_hardening(ES, FY, et);
        let eps_y = FY / ES;
        let r = drive(&p, &[0.02, 0.0]);
        let smax = FY + et * (0.02 - eps_y);
        assert!(((r[0].0 - smax) / smax).abs() < 1e-12);
        assert!(((r[0].1 - et) / et).abs() < 1e-12);
        // unloading to ε = 0: elastic range from smax down to smax − 2 f_y = 25 MPa·… ;
        // ε change to reach it: 2 f_y/E_s = 0.005 < 0.02 → reverse yielding happens
        let rev_yield = smax - 2.0 * FY;
        let eps_rev = 0.02 - 2.0 * FY / ES;
        let want = rev_yield - et * (eps_rev - 0.0);
        assert!(
            ((r[1].0 - want) / want).abs() < 1e-12,
            "{} vs {want}",
            r[1].0
        );
    }

    /// Isotropic hardening: the elastic range grows to ±σ_max, so reverse yield happens at
    /// −σ_max (not at σ_max − 2 f_y as with the kinematic rule); the cap f_u bounds the
    /// radius. Hand values, 1e-12 rel (closed form, round-off only).
    #[test]
    fn isotropic_hardening_reverse_and_cap() {
        let et = 2e9;
        let p = SteelParams::rebar_hardening(ES, FY, et).with_rule(HardeningRule::Isotropic);
        let eps_y = FY / ES;
        let r = drive(&p, &[0.02, 0.0, -0.05]);
        let smax = FY + et * (0.02 - eps_y);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        assert!(close(r[0].0, smax) && close(r[0].1, et));
        // Unloading by 0.02 is elastic while 2 σ_max/E_s = 0.0103 < 0.02 of strain: reverse
        // yield at −σ_max, then hardening again along E_t.
        let eps_rev = 0.02 - 2.0 * smax / ES;
        let want = -smax - et * (eps_rev - 0.0);
        assert!(close(r[1].0, want), "{} vs {want}", r[1].0);
        assert_eq!(r[1].2.back_stress, 0.0);
        // With a cap the radius stops at f_u.
        let fu = FY + 10e6;
        let pc = SteelParams { fu, ..p };
        let rc = drive(&pc, &[0.02, -0.02]);
        assert!(close(rc[0].0, fu) && rc[0].1 == 0.0);
        assert!(close(rc[1].0, -fu) && rc[1].1 == 0.0);
    }

    /// Prestressing steel: elastic to 0.9 f_ptk, plastic; hardening variant reaches f_ptk at
    /// ε_uk and stays there. Hand values (1e-9 rel).
    #[test]
    fn prestressing_laws() {
        let ep = 195e9;
        let fptk = 1860e6;
        let p = SteelParams::prestressing(ep, fptk);
        let (_, s, t) = update_uniaxial(&p, &SteelState::new(), 0.007);
        assert!((s - ep * 0.007).abs() < 1e-3 && t == ep);
        let (_, s, t) = update_uniaxial(&p, &SteelState::new(), 0.02);
        assert!((s - 0.9 * fptk).abs() < 1e-3 && t == 0.0);

        let eps_uk = 0.035;
        let ph = SteelParams::prestressing_hardening(ep, fptk, eps_uk);
        let eps_y = 0.9 * fptk / ep;
        let et = 0.1 * fptk / (eps_uk - eps_y);
        let (_, s, t) = update_uniaxial(&ph, &SteelState::new(), 0.02);
        let want = 0.9 * fptk + et * (0.02 - eps_y);
        assert!(((s - want) / want).abs() < 1e-9 && ((t - et) / et).abs() < 1e-9);
        let (st, s, t) = update_uniaxial(&ph, &SteelState::new(), eps_uk);
        assert!(((s - fptk) / fptk).abs() < 1e-9, "{s}");
        assert!(t > 0.0);
        let (_, s, t) = update_uniaxial(&ph, &st, 0.05);
        assert!(((s - fptk) / fptk).abs() < 1e-9 && t == 0.0);
        // In two steps (with a commit in between) the same: path independence under
        // monotonic loading.
        let (st1, _, _) = update_uniaxial(&ph, &SteelState::new(), 0.01);
        let (_, s2, _) = update_uniaxial(&ph, &st1, 0.02);
        assert!(((s2 - want) / want).abs() < 1e-9);
    }

    /// Tangent equals the central difference of the stress away from kinks (1e-6 rel:
    /// piecewise-linear law, FD exact up to round-off).
    #[test]
    fn steel_tangent_fd() {
        let p = SteelParams::rebar_hardening(ES, FY, 5e9);
        let (st, _, _) = update_uniaxial(&p, &SteelState::new(), 0.01);
        for e in [0.012, 0.009, 0.0, -0.01] {
            let (_, _, t) = update_uniaxial(&p, &st, e);
            let h = 1e-8;
            let fd =
                (update_uniaxial(&p, &st, e + h).1 - update_uniaxial(&p, &st, e - h).1) / (2.0 * h);
            assert!((fd - t).abs() < 1e-6 * ES, "{e}: {fd} vs {t}");
        }
    }
}
