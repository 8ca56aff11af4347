//! CEB-FIP Model Code 1990 short-term concrete functions (docs/theory-concrete.md §1).
//!
//! Units: stresses and moduli in Pa, strains dimensionless, time in days. All functions are
//! pure; none of them panics for finite input (out-of-domain input gives NaN or is clamped,
//! as documented per function).

/// MC90 reference strength f_cko = 10 MPa [Pa].
pub const FCKO: f64 = 10.0e6;
/// MC90 difference between mean and characteristic strength Δf = 8 MPa [Pa].
pub const DELTA_F: f64 = 8.0e6;
/// MC90 strain at peak compressive stress ε_c1 (magnitude) [-].
pub const EPS_C1: f64 = 0.0022;
/// Default tensile-strength coefficient C of seed eq. 19 (mean value) [kN/cm² units, see
/// [`f_tm`]].
pub const C_MEAN: f64 = 0.14;

/// Which compressive strength enters the tensile-strength formula (docs/theory-concrete.md §1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum TensileRef {
    /// f_ref = f_cm (what the seed paper states; default).
    Fcm,
    /// f_ref = f_ck = f_cm − 8 MPa (strict MC90).
    Fck,
}

/// Mean tensile strength f_tm [Pa] from the mean compressive strength `fcm` [Pa].
///
/// Seed eq. 19 with the exponent corrected to 2/3 (docs/theory-concrete.md §1):
/// f_tm [kN/cm²] = C · (f_ref [kN/cm²])^(2/3), i.e. f_tm = 10 MPa · C · (f_ref/10 MPa)^(2/3).
/// `c` is dimensionless in this form (0.095 lower, 0.14 mean, 0.185 upper characteristic).
/// Returns 0 if f_ref ≤ 0.
pub fn f_tm(fcm: f64, c: f64, f_ref: TensileRef) -> f64 {
    let fr = match f_ref {
        TensileRef::Fcm => fcm,
        TensileRef::Fck => fcm - DELTA_F,
    };
    if fr <= 0.0 {
        return 0.0;
    }
    FCKO * c * (fr / FCKO).powf(2.0 / 3.0)
}

/// MC90 tangent modulus at the origin E_ci = 21500 MPa · (f_cm / 10 MPa)^(1/3) [Pa]
/// (`fcm` in Pa).
pub fn eci(fcm: f64) -> f64 {
    21500.0e6 * (fcm / FCKO).cbrt()
}

/// MC90 strength-development coefficient β_cc(t) = exp{s [1 − (28/t)^0.5]} [-].
///
/// `t` = concrete age [days] (> 0), `s` = cement coefficient (0.20 RS, 0.25 N/R, 0.38 SL).
pub fn beta_cc(t: f64, s: f64) -> f64 {
    (s * (1.0 - (28.0 / t).sqrt())).exp()
}

/// Mean compressive strength at age `t` [days]: f_cm(t) = β_cc(t) f_cm [Pa].
pub fn fcm_t(fcm: f64, t: f64, s: f64) -> f64 {
    beta_cc(t, s) * fcm
}

/// Tangent modulus at age `t` [days]: E_ci(t) = β_cc(t)^0.5 E_ci [Pa] (`fcm` = 28-day mean
/// strength [Pa]).
pub fn eci_t(fcm: f64, t: f64, s: f64) -> f64 {
    beta_cc(t, s).sqrt() * eci(fcm)
}

/// Ottosen four-parameter criterion constants (dimensionless), MC90 expressions
/// (docs/theory-concrete.md §1).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OttosenParams {
    /// α (coefficient of J2/f_cm²) [-].
    pub alpha: f64,
    /// β (coefficient of I1/f_cm) [-].
    pub beta: f64,
    /// c1 (size of the deviatoric section) [-].
    pub c1: f64,
    /// c2 (shape of the deviatoric section, 0 ≤ c2 ≤ 1) [-].
    pub c2: f64,
}

impl OttosenParams {
    /// MC90 parameters from k = f_tm/f_cm [-]:
    /// α = 1/(9 k^1.4), β = 1/(3.7 k^1.1), c1 = 1/(0.7 k^0.9), c2 = 1 − 6.8 (k − 0.07)².
    ///
    /// c2 is stored unmodified; the evaluation of λ(θ) guards c2 → 1 (see
    /// [`crate::materials::concrete::ottosen`]).
    pub fn from_k(k: f64) -> Self {
        OttosenParams {
            alpha: 1.0 / (9.0 * k.powf(1.4)),
            beta: 1.0 / (3.7 * k.powf(1.1)),
            c1: 1.0 / (0.7 * k.powf(0.9)),
            c2: 1.0 - 6.8 * (k - 0.07).powi(2),
        }
    }
}

/// MC90 uniaxial compression curve (docs/theory-concrete.md §1) in magnitudes: ε, σ > 0 in
/// compression.
///
/// Ascending branch (η = ε/ε_c1 ≤ η_lim): σ = f_cm (k_p η − η²)/(1 + (k_p − 2) η),
/// k_p = E ε_c1 / f_cm; descending branch (η > η_lim):
/// σ = f_cm / [(ξ/η_lim − 2/η_lim²) η² + (4/η_lim − ξ) η].
/// This is seed eq. 20 with its sign slip corrected ("+ (ε/0.0022)²" in the numerator for
/// signed ε < 0). The curve passes through (ε_c1, f_cm) and (ε_lim, f_cm/2) continuously
/// (value and, by construction of ξ, slope).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CompressionCurve {
    /// Peak stress f_cm [Pa].
    pub fcm: f64,
    /// Initial tangent modulus E [Pa] (E_ci in MC90; the material's elastic modulus here).
    pub e: f64,
    /// Strain at peak ε_c1 (magnitude) [-].
    pub eps_c1: f64,
    /// k_p = E ε_c1 / f_cm [-] (> 1 for a meaningful curve).
    pub kp: f64,
    /// η_lim, end of the ascending branch (σ = f_cm/2 on the descending side) [-].
    pub eta_lim: f64,
    /// ξ, shape factor of the descending branch [-].
    pub xi: f64,
}

impl CompressionCurve {
    /// Curve for peak stress `fcm` [Pa], initial modulus `e` [Pa] and peak strain `eps_c1` [-].
    pub fn new(fcm: f64, e: f64, eps_c1: f64) -> Self {
        let kp = e * eps_c1 / fcm;
        let a = 0.5 * kp + 1.0;
        let eta_lim = 0.5 * a + (0.25 * a * a - 0.5).sqrt();
        let xi = 4.0 * (eta_lim * eta_lim * (kp - 2.0) + 2.0 * eta_lim - kp)
            / (eta_lim * (kp - 2.0) + 1.0).powi(2);
        CompressionCurve {
            fcm,
            e,
            eps_c1,
            kp,
            eta_lim,
            xi,
        }
    }

    /// Strain limit of the ascending branch ε_lim = η_lim ε_c1 [-].
    pub fn eps_lim(&self) -> f64 {
        self.eta_lim * self.eps_c1
    }

    /// Compressive stress magnitude σ(ε) [Pa] and tangent dσ/dε [Pa] for a compressive
    /// strain magnitude `eps` [-]. For eps ≤ 0 the linear continuation σ = E ε is returned.
    pub fn eval(&self, eps: f64) -> (f64, f64) {
        if eps <= 0.0 {
            return (self.e * eps, self.e);
        }
        let eta = eps / self.eps_c1;
        let kp = self.kp;
        if eta <= self.eta_lim {
            let num = kp * eta - eta * eta;
            let den = 1.0 + (kp - 2.0) * eta;
            let s = self.fcm * num / den;
            let ds = self.fcm * ((kp - 2.0 * eta) * den - num * (kp - 2.0)) / (den * den);
            (s, ds / self.eps_c1)
        } else {
            let el = self.eta_lim;
            let a = self.xi / el - 2.0 / (el * el);
            let b = 4.0 / el - self.xi;
            let den = a * eta * eta + b * eta;
            let s = self.fcm / den;
            let ds = -self.fcm * (2.0 * a * eta + b) / (den * den);
            (s, ds / self.eps_c1)
        }
    }

    /// Compressive stress magnitude σ(ε) [Pa] (see [`CompressionCurve::eval`]).
    pub fn stress(&self, eps: f64) -> f64 {
        self.eval(eps).0
    }

    /// Signed form of the curve: `eps` < 0 in compression returns σ < 0 [Pa]; for eps ≥ 0
    /// the linear branch E ε is returned (the curve says nothing about tension).
    pub fn signed_stress(&self, eps: f64) -> f64 {
        if eps >= 0.0 {
            self.e * eps
        } else {
            -self.stress(-eps)
        }
    }
}

/// Ottosen/MC90 parameters for the tensile/compressive strength ratio of the given
/// strengths (`ftm`, `fcm` in Pa).
pub fn ottosen_params(ftm: f64, fcm: f64) -> OttosenParams {
    OttosenParams::from_k(ftm / fcm)
}

/// MC90 fracture energy G_f = G_f0 (f_cm/10 MPa)^0.7 [N/m] for the base value `gf0` [N/m]
/// (MC90: 25, 30, 38, 58 N/m for d_max = 8, 16, 32 mm … ; 30 N/m is the default used by
/// [`crate::materials::concrete::ConcreteParams::from_mc90`] for crack-band scaling).
pub fn fracture_energy(fcm: f64, gf0: f64) -> f64 {
    gf0 * (fcm / FCKO).powf(0.7)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    /// Check 1 (docs/theory-concrete.md §7): f_tm by the formula of §1 (tolerance 1e-5 rel:
    /// the hand values have 6 significant digits).
    #[test]
    fn check1_ftm_table() {
        let fcm = 45e6;
        let cases = [
            (0.14, TensileRef::Fcm, 3.81595e6),
            (0.14, TensileRef::Fck, 3.34911e6),
            (0.095, TensileRef::Fcm, 2.58940e6),
            (0.185, TensileRef::Fcm, 5.04251e6),
        ];
        for (c, r, want) in cases {
            let got = f_tm(fcm, c, r);
            assert!(rel(got, want) < 1e-5, "{c} {r:?}: {got} vs {want}");
        }
        assert!(rel(f_tm(fcm, 0.14, TensileRef::Fcm) / fcm, 0.084799) < 1e-5);
        assert!(rel(f_tm(fcm, 0.14, TensileRef::Fck) / fcm, 0.074425) < 1e-5);
        // The seed's literal exponent 2.3 would give ≈ 44.5 MPa here: make sure we are far
        // from that.
        assert!(f_tm(fcm, 0.14, TensileRef::Fcm) < 5e6);
    }

    /// Check 2 (docs/theory-concrete.md §7): α, β, c1, c2 (1e-5 rel; hand values to 6 digits).
    #[test]
    fn check2_ottosen_params() {
        let table = [
            (0.06, 5.70618, 5.96804, 17.97073, 0.999320),
            (0.08, 3.81445, 4.34910, 13.87142, 0.999320),
            (0.084799, 3.51569, 4.07914, 13.16287, 0.998511),
            (0.1, 2.79098, 3.40250, 11.34755, 0.993880),
        ];
        for (k, a, b, c1, c2) in table {
            let p = OttosenParams::from_k(k);
            assert!(rel(p.alpha, a) < 1e-5, "alpha k={k}: {}", p.alpha);
            assert!(rel(p.beta, b) < 1e-5, "beta k={k}: {}", p.beta);
            assert!(rel(p.c1, c1) < 1e-5, "c1 k={k}: {}", p.c1);
            assert!(rel(p.c2, c2) < 1e-5, "c2 k={k}: {}", p.c2);
        }
    }

    /// Check 8 (docs/theory-concrete.md §7): E_ci, β_cc, f_cm(t), E_ci(t) (1e-5 rel; hand values
    /// have 5–6 significant digits, the t = 3 d β_cc only 5, hence 2e-5 there).
    #[test]
    fn check8_moduli_and_ageing() {
        let fcm = 45e6;
        assert!(rel(eci(fcm), 35495.72e6) < 1e-6);
        assert!(rel(0.85 * eci(fcm), 30171.36e6) < 1e-6);
        assert!(rel(eci(fcm) / (fcm / EPS_C1), 1.735346) < 1e-6);
        let table = [
            (3.0, 0.59824, 26.921e6, 27454.5e6),
            (7.0, 0.77880, 35.046e6, 31324.9e6),
            (28.0, 1.0, 45.0e6, 35495.7e6),
            (90.0, 1.11690, 50.260e6, 37513.1e6),
            (365.0, 1.19812, 53.916e6, 38853.2e6),
        ];
        for (t, b, f, e) in table {
            assert!(rel(beta_cc(t, 0.25), b) < 2e-5, "beta_cc({t})");
            assert!(rel(fcm_t(fcm, t, 0.25), f) < 2e-5, "fcm({t})");
            assert!(rel(eci_t(fcm, t, 0.25), e) < 2e-5, "eci({t})");
        }
    }

    /// Check 9 (docs/theory-concrete.md §7): MC90 σ–ε curve, η_lim, ξ, continuity at η_lim
    /// (1e-4 rel; the hand values have 6 digits).
    #[test]
    fn check9_compression_curve() {
        let fcm = 45e6;
        let c = CompressionCurve::new(fcm, 35495.72e6, EPS_C1);
        assert!(rel(c.eta_lim, 1.543796) < 1e-5);
        assert!(rel(c.eps_lim(), 0.0033964) < 1e-4);
        assert!(rel(c.xi, 8.250662) < 1e-5);
        let table = [
            (-0.0005, -16.4106e6),
            (-0.001, -29.7807e6),
            (-0.0015, -39.4411e6),
            (-0.0022, -45.0e6),
            (-0.003, -35.6895e6),
            (-0.0033964, -22.5e6),
            (-0.005, -4.3236e6),
        ];
        for (e, s) in table {
            let got = c.signed_stress(e);
            assert!(rel(got, s) < 1e-4, "σ({e}) = {got}, want {s}");
        }
        // Continuity of value and slope at η_lim (both branches evaluated just either side;
        // 1e-6 step → relative jump must be O(step) only).
        let el = c.eps_lim();
        let (s1, d1) = c.eval(el * (1.0 - 1e-9));
        let (s2, d2) = c.eval(el * (1.0 + 1e-9));
        assert!(rel(s1, s2) < 1e-7, "value jump {s1} {s2}");
        assert!(rel(d1, d2) < 1e-4, "slope jump {d1} {d2}");
        assert!(rel(s1, 0.5 * fcm) < 1e-7);
        // Peak: zero slope at ε_c1.
        let (sp, dp) = c.eval(EPS_C1);
        assert!(rel(sp, fcm) < 1e-12 && dp.abs() < 1e-6 * c.e);
        // Initial tangent equals E.
        assert!(rel(c.eval(1e-12).1, c.e) < 1e-6);
        // Tangent against a central difference on both branches.
        for e in [0.0004, 0.0015, 0.0030, 0.0045] {
            let h = 1e-9;
            let fd = (c.stress(e + h) - c.stress(e - h)) / (2.0 * h);
            assert!((fd - c.eval(e).1).abs() < 1e-5 * c.e, "tangent at {e}");
        }
    }
}
