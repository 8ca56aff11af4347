//! Plane-stress concrete material point (docs/theory-concrete.md §1–§5; seed §5.2–5.3).
//!
//! * Uncracked, compression-dominated states (largest principal trial stress
//!   σ1 < r_d f_tm, r_d = ½ by default): isotropic-hardening elastoplasticity on
//!   Ottosen-shaped loading surfaces with the MC90 curve as hardening law
//!   ([`compression`]); crushing when the equivalent curve strain reaches ε_cu.
//! * Uncracked, tension-dominated states (σ1 ≥ r_d f_tm): linear elastic until the Ottosen
//!   failure surface F(σ; f_cm) = 0 is reached, then a smeared crack opens normal to σ1
//!   ([`cracking`]): fixed orthogonal cracks, tension stiffening, shear retention, secant
//!   unloading/closing, second orthogonal crack, no stress when both cracks are open.
//!
//! Units: stresses and moduli in Pa, strains dimensionless (engineering shear strain
//! γxy), lengths in m. Sign convention: tension positive. Voigt order (xx, yy, xy).
//!
//! The update is a pure function of (committed state, total strain): calling it twice with
//! the same arguments gives the same result, so a load step can be retried.

pub mod biaxial;
pub mod compression;
pub mod cracking;
pub mod creep;
pub mod implex;
pub mod ottosen;
pub mod reduction;
pub mod rotating;

pub use crate::materials::error::MaterialError;
use crate::materials::mc90::{self, CompressionCurve, OttosenParams, TensileRef};

/// Post-cracking tension law of seed eq. 21 (Hinton): σ_n = f_tm exp(−(ε_n − ε0)/α) for
/// ε_n > ε0 = f_tm/E.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum TensionSoftening {
    /// Fixed decay strain α [-] (the paper's "softening parameter"; mesh dependent, meant as
    /// a tension-stiffening law for reinforced zones).
    Hinton {
        /// Decay strain α [-].
        alpha: f64,
    },
    /// Crack band (Bažant–Oh): α chosen per element so that the energy dissipated per unit
    /// volume, f_tm α + f_tm²/(2E), equals G_f/h, h = characteristic element length [m]:
    /// α = G_f/(h f_tm) − ε0/2, floored at ε0/10 (elements too large for snap-back-free
    /// softening then dissipate more than G_f).
    CrackBand {
        /// Fracture energy G_f [N/m = J/m²].
        gf: f64,
    },
}

/// Post-peak law of concrete in compression.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum CompressionSoftening {
    /// The MC90 curve beyond the peak, continued by the straight line of
    /// `softening_limit`; the point crushes at ε̄ = ε_cu (stress drops to zero there).
    /// Not regularised: crushing localises in one element row whatever its size.
    #[default]
    Mc90,
    /// Crush band (Feenstra 1993; Feenstra & de Borst 1995): beyond the peak
    /// (ε_c1, f_cm) a parabola σ_c = f_cm (1 − ((ε̄ − ε_c1)/(ε_u − ε_c1))²) that reaches zero
    /// at ε_u = ε_c1 + 1.5 G_c/(h f_cm), so that an element of characteristic length h
    /// [m] dissipates G_c per unit area of the crushing band; the point crushes when the
    /// stress has come down to zero (no jump). ε_u is floored so that the steepest slope,
    /// −2 f_cm/(ε_u − ε_c1) at ε_u, stays within `softening_limit` (large elements then
    /// dissipate more than G_c).
    CrushBand {
        /// Compressive fracture energy G_c [N/m = J/m²].
        gc: f64,
    },
}

/// Shear retention factor of seed eqs. 22–23 (Cervenka): G_c = β G,
/// β = 1 − (ε/ε_ref)^k1, floored at β_min; ε = largest crack-normal strain reached.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ShearRetention {
    /// Exponent k1 [-] (seed: 0.075).
    pub k1: f64,
    /// Crack strain at which β would vanish ε_ref [-] (seed: 0.005).
    pub eps_ref: f64,
    /// Floor β_min [-] keeping the tangent non-singular (a project decision,
    /// docs/theory-concrete.md §5: 1e-3).
    pub beta_min: f64,
}

impl Default for ShearRetention {
    fn default() -> Self {
        ShearRetention {
            k1: 0.075,
            eps_ref: 0.005,
            beta_min: 1e-3,
        }
    }
}

impl ShearRetention {
    /// β(ε) [-] and dβ/dε [-] for crack-normal strain `eps` [-] (β = 1 for ε ≤ 0).
    pub fn beta(&self, eps: f64) -> (f64, f64) {
        if eps <= 0.0 {
            return (1.0, 0.0);
        }
        let x = eps / self.eps_ref;
        let b = 1.0 - x.powf(self.k1);
        if b <= self.beta_min {
            (self.beta_min, 0.0)
        } else {
            (b, -self.k1 / self.eps_ref * x.powf(self.k1 - 1.0))
        }
    }
}

/// Smeared crack model of a concrete point.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum CrackModel {
    /// The seed's model: Ottosen/MC90 compression plasticity while uncracked, fixed
    /// orthogonal cracks with shear retention once cracked ([`cracking`]).
    #[default]
    Fixed,
    /// Rotating (total-strain, coaxial) cracks: uniaxial laws along the principal axes of the
    /// total strain, secant unloading, no shear retention needed ([`rotating`]).
    Rotating,
}

/// Reduction of the compressive strength (and peak strain) of cracked concrete under a
/// lateral tensile strain ("compression softening").
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum CompressionReduction {
    /// No reduction (the seed).
    #[default]
    None,
    /// Vecchio & Collins (1993), e1/e0 form: β_d = 1/(1 + 0.27 (ε_lat/ε_c1 − 0.37)) ≤ 1,
    /// applied to strength and peak strain (σ = β_d σ_c(ε/β_d)), floored at `beta_min`
    /// ([`reduction`]).
    VecchioCollins1993 {
        /// Lower bound of β_d [-] (default 0.4).
        beta_min: f64,
        /// Mean crack spacing s_rm [m] over which a crack's opening is smeared for β_d
        /// (ε_lat = ε0 + (ε − ε0) h/s_rm where s_rm > h); 0: the crack band h (the seed).
        spacing: f64,
    },
}

/// Shear retention law of fixed cracks.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum ShearRetentionLaw {
    /// The seed's law (eqs. 22–23), parameters in [`ConcreteParams::shear`].
    #[default]
    Seed,
    /// Aggregate interlock tied to the crack width (after Walraven; DIANA's
    /// "aggregate-size based" retention): β = 1 − 2w/d_agg, w = h ε_max (crack band width
    /// h = the element's characteristic length), floored at `shear.beta_min`: the shear
    /// transfer vanishes when the crack has opened to half the aggregate size.
    Aggregate {
        /// Largest aggregate size d_agg [m].
        d_agg: f64,
    },
}

/// Concrete parameters. Build with [`ConcreteParams::from_mc90`] and adjust fields.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ConcreteParams {
    /// Mean compressive strength f_cm [Pa] (> 0, magnitude).
    pub fcm: f64,
    /// Mean tensile strength f_tm [Pa].
    pub ftm: f64,
    /// Elastic modulus E [Pa]; also the initial tangent of the hardening curve (eq. 20).
    pub ec: f64,
    /// Poisson ratio ν [-] (uncracked concrete; neglected after cracking, as in the seed).
    pub nu: f64,
    /// Ottosen parameters α, β, c1, c2 [-].
    pub ottosen: OttosenParams,
    /// Strain at peak of the MC90 curve ε_c1 [-] (0.0022).
    pub eps_c1: f64,
    /// Initial yield ratio σ_c0/f_cm [-] (0 = plastic from the start, the seed's "zeroed
    /// initial yielding stresses"; > 0 shifts the uniaxial curve by κ0, see
    /// [`compression`]).
    pub initial_yield_ratio: f64,
    /// Normalise σ_e by q_c so that uniaxial compression follows the MC90 curve exactly
    /// (a project decision, docs/theory-concrete.md §4; default true).
    pub normalize_equivalent_stress: bool,
    /// Crushing strain ε_cu [-]: when the equivalent curve strain ε̄ reaches it the point is
    /// crushed and carries no stress (default 0.0035; set ε_cu = ε_c1 for "crushed at the
    /// failure surface").
    pub eps_cu: f64,
    /// Post-peak softening limit h [-]: the plastic modulus of the hardening law is bounded
    /// below by −h E (straight line beyond that point, see
    /// [`compression::hardening_curve`]); default 0.25; ≥ 1 disables the limit (raw MC90).
    pub softening_limit: f64,
    /// Crack/crush discrimination ratio r_d [-]: σ1 ≥ r_d f_tm → crack (MC90/seed: 0.5).
    pub crack_ratio: f64,
    /// Post-cracking tension law.
    pub tension: TensionSoftening,
    /// Shear retention law.
    pub shear: ShearRetention,
    /// Residual stiffness ratio [-] for the tangent of points that carry no stress (both
    /// cracks open, crushed): tangent = ratio × elastic stiffness, stress stays 0.
    pub residual_stiffness: f64,
    /// Use secant (non-negative, symmetric) crack-direction stiffness instead of the
    /// consistent tangent for cracked points (robust for modified Newton; default false).
    pub secant_crack_tangent: bool,
    /// The seed's rule for a point with two open cracks: no stress at all (true). Default
    /// false: each crack keeps its own tension-softening law and the shear retention, so the
    /// stress goes to zero only as the cracks open (docs/theory-concrete.md: a point — and
    /// an element whose points all have two open cracks — otherwise loses all stiffness at
    /// once, and refined RC meshes stop before yield).
    #[serde(default)]
    pub zero_double_crack: bool,
    /// IMPL-EX integration of the crack laws (Oliver, Huespe & Cante 2008): within an
    /// increment each crack follows the secant at its largest crack strain extrapolated from
    /// the two previous increments, and cracks form at the end of the increment in which the
    /// converged stress reaches the surface. The tangent of cracked points is then positive
    /// and constant in the increment (no softening, no loading/unloading switch), at the
    /// price of a first-order error in the increment size. Default false (implicit).
    #[serde(default)]
    pub implex: bool,
    /// IMPL-EX integration of the uncracked compression plasticity as well (needs
    /// [`ConcreteParams::implex`]): within an increment an uncracked point takes the elastic
    /// stress of its plastic strain extrapolated from the last increment's flow, with the
    /// elastic tangent, whichever route its implicit update takes, and a cracked point's
    /// crack-axis directions the elastic stress of their 1-D compressive plastic strain
    /// extrapolated the same way (tangent E); the state (plastic strains, hardening
    /// variables, crushing) is the implicit laws' at the same strain. Load increments only (not with creep,
    /// the viscoplastic option or rotating cracks). Default false (docs/theory-concrete.md
    /// §4, "IMPL-EX in compression").
    #[serde(default)]
    pub compression_implex: bool,
    /// Owen–Hinton elasto-viscoplastic compression plasticity (None: rate-independent
    /// return mapping, the default; see [`compression::viscoplastic_update`]).
    #[serde(default)]
    pub viscoplastic: Option<compression::Viscoplastic>,
    /// Post-peak compression law (default: MC90 with the softening limit, crushing at ε_cu).
    #[serde(default)]
    pub compression_softening: CompressionSoftening,
    /// Crush-band ultimate strain ε_u [-] resolved for one element size (set by the update
    /// from the characteristic length; None for [`CompressionSoftening::Mc90`]).
    #[serde(skip)]
    pub(crate) crush_eu: Option<f64>,
    /// Crack model (default fixed, the seed's).
    #[serde(default)]
    pub crack_model: CrackModel,
    /// Compression softening of cracked concrete (default none, the seed's).
    #[serde(default)]
    pub compression_reduction: CompressionReduction,
    /// Shear retention law of fixed cracks (default the seed's β law).
    #[serde(default)]
    pub shear_retention: ShearRetentionLaw,
    /// Upper limit of the shear stress a fixed crack transfers (default none, the seed's).
    #[serde(default)]
    pub crack_shear_limit: cracking::CrackShearLimit,
    /// Limit on the largest principal stress of fixed-cracked points (default none, the
    /// seed's; a stress-locking remedy).
    #[serde(default)]
    pub principal_stress_limit: cracking::PrincipalStressLimit,
    /// MC90 creep and shrinkage in series with cracking and plasticity (None: the
    /// time-independent concrete, the default; see [`creep`]).
    #[serde(skip)]
    pub creep: Option<creep::ConcreteCreep>,
    /// The hardening law of these parameters, evaluated at its first use
    /// ([`compression::HardeningLaw::new`]; a copy of the parameters starts empty).
    #[serde(skip)]
    pub(crate) law_memo: compression::LawMemo,
}

impl ConcreteParams {
    /// MC90 defaults from the mean compressive strength `fcm` [Pa] and Poisson ratio `nu`:
    /// f_tm = 10 MPa · 0.14 (f_cm/10 MPa)^(2/3) (eq. 19 corrected), E = E_ci, Ottosen
    /// parameters from k = f_tm/f_cm, ε_c1 = 0.0022, zero initial yield, normalised σ_e,
    /// ε_cu = 0.0035, Hinton tension stiffening with α = 5e-4 (the paper's value is unknown;
    /// docs/theory-concrete.md §5), Cervenka shear retention k1 = 0.075.
    pub fn from_mc90(fcm: f64, nu: f64) -> Self {
        Self::from_mc90_with(fcm, nu, mc90::C_MEAN, TensileRef::Fcm)
    }

    /// As [`ConcreteParams::from_mc90`] with tensile-strength coefficient `c` [-] and
    /// reference strength choice `f_ref`.
    pub fn from_mc90_with(fcm: f64, nu: f64, c: f64, f_ref: TensileRef) -> Self {
        let ftm = mc90::f_tm(fcm, c, f_ref);
        ConcreteParams {
            fcm,
            ftm,
            ec: mc90::eci(fcm),
            nu,
            ottosen: mc90::ottosen_params(ftm, fcm),
            eps_c1: mc90::EPS_C1,
            initial_yield_ratio: 0.0,
            normalize_equivalent_stress: true,
            eps_cu: 0.0035,
            softening_limit: 0.25,
            crack_ratio: 0.5,
            tension: TensionSoftening::Hinton { alpha: 5e-4 },
            shear: ShearRetention::default(),
            residual_stiffness: 1e-6,
            secant_crack_tangent: false,
            zero_double_crack: false,
            implex: false,
            compression_implex: false,
            viscoplastic: None,
            compression_softening: CompressionSoftening::Mc90,
            crush_eu: None,
            crack_model: CrackModel::Fixed,
            compression_reduction: CompressionReduction::None,
            shear_retention: ShearRetentionLaw::Seed,
            crack_shear_limit: cracking::CrackShearLimit::None,
            principal_stress_limit: cracking::PrincipalStressLimit::None,
            creep: None,
            law_memo: compression::LawMemo::default(),
        }
    }

    /// Switch to crack-band softening with the MC90 fracture energy
    /// G_f = 30 N/m (f_cm/10 MPa)^0.7 (d_max = 16 mm).
    pub fn with_crack_band(mut self) -> Self {
        self.tension = TensionSoftening::CrackBand {
            gf: mc90::fracture_energy(self.fcm, 30.0),
        };
        self
    }

    /// Check parameter consistency (positive strengths/moduli, 0 ≤ ν < 0.5, E ε_c1 > f_cm
    /// so that the curve rises, ε_cu > 0).
    pub fn validate(&self) -> Result<(), MaterialError> {
        let bad = |m: &str| Err(MaterialError::InvalidParams(m.to_string()));
        if !(self.fcm > 0.0 && self.ftm > 0.0 && self.ec > 0.0) {
            return bad("fcm, ftm and ec must be positive");
        }
        if !(0.0..0.5).contains(&self.nu) {
            return bad("nu must be in [0, 0.5)");
        }
        if self.ec * self.eps_c1 <= self.fcm {
            return bad("E·eps_c1 must exceed fcm (MC90 curve needs k_p > 1)");
        }
        if self.eps_cu <= 0.0 {
            return bad("eps_cu must be positive");
        }
        match self.tension {
            TensionSoftening::Hinton { alpha } if alpha <= 0.0 => bad("Hinton alpha must be > 0"),
            TensionSoftening::CrackBand { gf } if gf <= 0.0 => bad("G_f must be > 0"),
            _ => match self.compression_softening {
                CompressionSoftening::CrushBand { gc } if !(gc > 0.0 && gc.is_finite()) => {
                    bad("G_c must be > 0")
                }
                _ => self.validate_shear_laws(),
            },
        }
    }

    /// Check the options of compression softening, shear retention and crack model.
    fn validate_shear_laws(&self) -> Result<(), MaterialError> {
        let bad = |m: &str| Err(MaterialError::InvalidParams(m.to_string()));
        if let CompressionReduction::VecchioCollins1993 { beta_min, spacing } =
            self.compression_reduction
        {
            if !(beta_min > 0.0 && beta_min <= 1.0) {
                return bad("the compression reduction floor must lie in (0, 1]");
            }
            if !(spacing >= 0.0 && spacing.is_finite()) {
                return bad("the compression reduction crack spacing must be >= 0");
            }
        }
        if self.creep.is_some() && self.viscoplastic.is_some() {
            return bad("creep and the viscoplastic option are two time laws: choose one");
        }
        if let ShearRetentionLaw::Aggregate { d_agg } = self.shear_retention {
            if !(d_agg > 0.0 && d_agg.is_finite()) {
                return bad("the aggregate size must be > 0");
            }
        }
        if let cracking::CrackShearLimit::VecchioCollins1986 { d_agg } = self.crack_shear_limit {
            if !(d_agg > 0.0 && d_agg.is_finite()) {
                return bad("the aggregate size must be > 0");
            }
        }
        if self.crack_model == CrackModel::Rotating
            && (self.viscoplastic.is_some() || self.initial_yield_ratio > 0.0)
        {
            return bad("the rotating crack model has no viscoplastic or initial-yield option");
        }
        Ok(())
    }

    /// MC90 uniaxial compression curve with this E, f_cm and ε_c1.
    pub fn curve(&self) -> CompressionCurve {
        CompressionCurve::new(self.fcm, self.ec, self.eps_c1)
    }

    /// Normalisation factor of σ_e: q_c if normalised, else 1 [-].
    pub fn q_norm(&self) -> f64 {
        if self.normalize_equivalent_stress {
            ottosen::q_c(&self.ottosen)
        } else {
            1.0
        }
    }

    /// Compression-dominated stress state (routes to plasticity/crushing, docs/theory-concrete.md
    /// §3): largest principal stress σ1 < r_d f_tm and I1 = σx + σy < 0. The I1 condition keeps
    /// small tensile states out of the hardening model, whose loading surfaces pass
    /// through the origin when the initial yield stress is zero. I1 must be below
    /// −1e-9 f_tm: pure shear (I1 = 0) lies on the border, and round-off must not send some
    /// points of a uniformly sheared body into plasticity and others not (a spurious
    /// bifurcation: the points then take different stresses and crack early).
    pub fn compression_dominated(&self, s: &[f64; 3]) -> bool {
        self.compression_dominated_s1(principal_max_value(s), s)
    }

    /// [`Self::compression_dominated`] with σ1 [Pa] of `s` already known
    /// ([`principal_max_value`]).
    fn compression_dominated_s1(&self, s1: f64, s: &[f64; 3]) -> bool {
        s1 < self.crack_ratio * self.ftm && s[0] + s[1] < -1e-9 * self.ftm
    }

    /// Shear retention β [-] and dβ/dε [-] of a fixed crack whose largest normal strain is
    /// `eps` [-], in an element of characteristic length `char_length` [m] (the crack band
    /// width of the aggregate-interlock law).
    pub fn shear_beta(&self, eps: f64, char_length: f64) -> (f64, f64) {
        match self.shear_retention {
            ShearRetentionLaw::Seed => self.shear.beta(eps),
            ShearRetentionLaw::Aggregate { d_agg } => {
                if eps <= 0.0 {
                    return (1.0, 0.0);
                }
                let slope = 2.0 * char_length / d_agg;
                let b = 1.0 - slope * eps;
                if b <= self.shear.beta_min {
                    (self.shear.beta_min, 0.0)
                } else {
                    (b, -slope)
                }
            }
        }
    }

    /// Cracking strain ε0 = f_tm/E [-].
    pub fn eps0(&self) -> f64 {
        self.ftm / self.ec
    }

    /// Switch to crush-band compression softening with G_c = 250 G_f (MC90 G_f with
    /// d_max = 16 mm; the ratio of the Dutch guidelines for nonlinear analysis, RTD 1016).
    pub fn with_crush_band(mut self) -> Self {
        self.compression_softening = CompressionSoftening::CrushBand {
            gc: 250.0 * mc90::fracture_energy(self.fcm, 30.0),
        };
        self
    }

    /// Crush-band ultimate strain ε_u [-] for an element of characteristic length
    /// `char_length` [m] (None for [`CompressionSoftening::Mc90`]): ε_c1 + 1.5 G_c/(h f_cm),
    /// at least ε_c1 + 2 f_cm (1 − s)/(s E) (s = `softening_limit`, if in (0, 1)).
    pub fn crush_band_strain(&self, char_length: f64) -> Option<f64> {
        let CompressionSoftening::CrushBand { gc } = self.compression_softening else {
            return None;
        };
        let mut d = 1.5 * gc / (char_length * self.fcm);
        let s = self.softening_limit;
        if s > 0.0 && s < 1.0 {
            let floor = 2.0 * self.fcm * (1.0 - s) / (s * self.ec);
            d = if d.is_finite() { d.max(floor) } else { floor };
        }
        Some(self.eps_c1 + d)
    }

    /// These parameters for one element: the crush-band ultimate strain resolved from the
    /// characteristic length `char_length` [m] (and used as the crushing strain); a plain
    /// copy for [`CompressionSoftening::Mc90`].
    pub fn for_element(&self, char_length: f64) -> Result<Self, MaterialError> {
        let mut p = self.clone();
        if let Some(eu) = self.crush_band_strain(char_length) {
            if !(char_length > 0.0 && char_length.is_finite()) {
                return Err(MaterialError::InvalidParams(format!(
                    "crush band needs a positive characteristic length, got {char_length}"
                )));
            }
            p.crush_eu = Some(eu);
            p.eps_cu = eu;
        }
        Ok(p)
    }

    /// These parameters as an element's update uses them: [`ConcreteParams::for_element`]
    /// unless the crush band's ε_u is resolved already or the law has none (MC90), else
    /// these themselves (borrowed).
    pub fn resolved_for(
        &self,
        char_length: f64,
    ) -> Result<std::borrow::Cow<'_, Self>, MaterialError> {
        if self.crush_eu.is_none() && self.compression_softening != CompressionSoftening::Mc90 {
            Ok(std::borrow::Cow::Owned(self.for_element(char_length)?))
        } else {
            Ok(std::borrow::Cow::Borrowed(self))
        }
    }

    /// Decay strain α [-] of the tension-softening law for an element of characteristic
    /// length `char_length` [m] (ignored for [`TensionSoftening::Hinton`]).
    pub fn softening_alpha(&self, char_length: f64) -> f64 {
        match self.tension {
            TensionSoftening::Hinton { alpha } => alpha,
            TensionSoftening::CrackBand { gf } => {
                let e0 = self.eps0();
                let a = gf / (char_length * self.ftm) - 0.5 * e0;
                if a.is_finite() {
                    a.max(0.1 * e0)
                } else {
                    0.1 * e0
                }
            }
        }
    }
}

/// State of a concrete point (committed or trial). Private fields; read through accessors.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ConcreteState {
    pub(crate) strain: [f64; 3],
    pub(crate) stress: [f64; 3],
    pub(crate) plastic_strain: [f64; 3],
    /// Plastic strain of the state before the committed one [-] (IMPL-EX compression:
    /// the last increment's plastic flow is `plastic_strain` minus this).
    #[serde(default)]
    pub(crate) plastic_strain_old: [f64; 3],
    pub(crate) ebar: f64,
    pub(crate) kappa: f64,
    pub(crate) n_cracks: u8,
    pub(crate) crack_angle: f64,
    pub(crate) crack_max: [f64; 2],
    pub(crate) crack_strain: [f64; 2],
    pub(crate) dir_ebar: [f64; 2],
    pub(crate) dir_plastic: [f64; 2],
    /// `dir_plastic` of the state before the committed one [-] (IMPL-EX compression of the
    /// crack-axis directions: the last increment's compressive plastic flow is
    /// `dir_plastic` minus this).
    #[serde(default)]
    pub(crate) dir_plastic_old: [f64; 2],
    pub(crate) crushed: bool,
    /// Crack branch held for the rest of an increment, per crack direction: 0 free,
    /// 1 on the loading envelope, −1 on the unloading secant (see
    /// [`crate::materials::point::freeze_cracks`]); always 0 in committed states.
    #[serde(default)]
    pub(crate) frozen: [i8; 2],
    /// Largest crack strains of the state before the committed one [-] (IMPL-EX
    /// extrapolation; equal to `crack_max` in the increment a crack forms).
    #[serde(default)]
    pub(crate) crack_max_old: [f64; 2],
    /// Held on the compression-plasticity route for the rest of an increment (set on the
    /// base state once the point has flowed in one of its iterations, see
    /// [`crate::materials::point::plastic_base`]); always false in committed states.
    #[serde(default)]
    pub(crate) hold_plastic: bool,
    /// Largest inclined cut-off crack strain reached [-] (the strain the return of the
    /// softening tension cut-off removes along the principal direction,
    /// [`cracking::PrincipalStressLimit::Softening`]; 0 otherwise).
    #[serde(default)]
    pub(crate) cutoff_max: f64,
    /// `cutoff_max` of the state before the committed one [-] (IMPL-EX extrapolation).
    #[serde(default)]
    pub(crate) cutoff_max_old: f64,
    /// Creep state (chain, total strain, shrinkage) of a creeping concrete point (None
    /// without the creep option or before its first update; see [`creep`]). With creep,
    /// `strain` above is the concrete law's input ε_m, not the total strain.
    #[serde(default)]
    pub(crate) creep: Option<Box<creep::CreepState>>,
}

impl Default for ConcreteState {
    fn default() -> Self {
        Self::new()
    }
}

impl ConcreteState {
    /// Virgin state: no strain, no plastic strain, no cracks.
    pub fn new() -> Self {
        ConcreteState {
            strain: [0.0; 3],
            stress: [0.0; 3],
            plastic_strain: [0.0; 3],
            plastic_strain_old: [0.0; 3],
            ebar: 0.0,
            kappa: 0.0,
            n_cracks: 0,
            crack_angle: 0.0,
            crack_max: [0.0; 2],
            crack_strain: [0.0; 2],
            dir_ebar: [0.0; 2],
            dir_plastic: [0.0; 2],
            dir_plastic_old: [0.0; 2],
            crushed: false,
            frozen: [0; 2],
            crack_max_old: [0.0; 2],
            hold_plastic: false,
            cutoff_max: 0.0,
            cutoff_max_old: 0.0,
            creep: None,
        }
    }

    /// Number of smeared cracks (0, 1 or 2).
    pub fn n_cracks(&self) -> usize {
        self.n_cracks as usize
    }

    /// Angle of the first crack's normal from the x axis [rad] (meaningful if cracked); the
    /// second crack's normal is at +π/2.
    pub fn crack_angle(&self) -> f64 {
        self.crack_angle
    }

    /// Current crack-normal strains [-] of crack 1 and 2 (0 for absent cracks; negative when
    /// the crack is closed).
    pub fn crack_strains(&self) -> [f64; 2] {
        self.crack_strain
    }

    /// Largest crack-normal strains reached [-].
    pub fn max_crack_strains(&self) -> [f64; 2] {
        self.crack_max
    }

    /// Largest inclined cut-off crack strain reached [-] (softening tension cut-off,
    /// [`cracking::PrincipalStressLimit::Softening`]; 0 without it).
    pub fn max_cutoff_strain(&self) -> f64 {
        self.cutoff_max
    }

    /// Equivalent plastic strain [-]: κ of the uncracked plasticity plus the compressive
    /// plastic strains of the crack-axis directions.
    pub fn equivalent_plastic_strain(&self) -> f64 {
        self.kappa + self.dir_plastic[0] + self.dir_plastic[1]
    }

    /// Equivalent uniaxial curve strain ε̄ of the uncracked plasticity [-].
    pub fn curve_strain(&self) -> f64 {
        self.ebar
    }

    /// Plastic strain (εx, εy, γxy) of the uncracked plasticity [-] (frozen after cracking).
    pub fn plastic_strain(&self) -> [f64; 3] {
        self.plastic_strain
    }

    /// Whether the point is crushed (carries no stress).
    pub fn is_crushed(&self) -> bool {
        self.crushed
    }

    /// Total strain (εx, εy, γxy) [-] at which this state was computed.
    pub fn strain(&self) -> [f64; 3] {
        self.strain
    }

    /// Stress (σx, σy, τxy) [Pa] of this state.
    pub fn stress(&self) -> [f64; 3] {
        self.stress
    }
}

/// Plane-stress isotropic elasticity matrix [Pa] for modulus `e` [Pa] and Poisson `nu`.
pub fn d_matrix(e: f64, nu: f64) -> [[f64; 3]; 3] {
    let f = e / (1.0 - nu * nu);
    [
        [f, f * nu, 0.0],
        [f * nu, f, 0.0],
        [0.0, 0.0, 0.5 * e / (1.0 + nu)],
    ]
}

/// Largest principal stress σ1 [Pa] and the angle of its direction from x [rad].
pub fn principal_max(s: &[f64; 3]) -> (f64, f64) {
    (principal_max_value(s), principal_angle(s))
}

/// Largest principal stress σ1 [Pa] alone (the value of [`principal_max`], without the
/// arctangent of its direction).
pub fn principal_max_value(s: &[f64; 3]) -> f64 {
    let c = 0.5 * (s[0] + s[1]);
    let r = (0.25 * (s[0] - s[1]).powi(2) + s[2] * s[2]).sqrt();
    c + r
}

/// Angle [rad] of the direction of σ1 from x (that of [`principal_max`]).
fn principal_angle(s: &[f64; 3]) -> f64 {
    0.5 * (2.0 * s[2]).atan2(s[0] - s[1])
}

fn matvec(d: &[[f64; 3]; 3], v: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|j| d[i][j] * v[j]).sum())
}

/// Result of [`update`]: (trial state, stress (σx, σy, τxy) [Pa], tangent [[Pa; 3]; 3]).
pub type UpdateResult = Result<(ConcreteState, [f64; 3], [[f64; 3]; 3]), MaterialError>;

/// Stress update from the committed state and the total strain (εx, εy, γxy) [-].
///
/// `char_length` [m] is the element's characteristic length (used by crack-band
/// softening only). Returns the trial state, the stress (σx, σy, τxy) [Pa] and the tangent
/// [[Pa; 3]; 3]: consistent for elastic and plastic (uncracked) points; for cracked points
/// the consistent tangent of the crack-axis laws (non-symmetric when shear retention
/// decreases with an opening crack; negative on the softening branch), or the secant
/// stiffness if `secant_crack_tangent`; for points without stress the residual stiffness.
/// At regime changes (crack formation, second crack, crushing) the tangent is that of the
/// new regime.
pub fn update(
    p: &ConcreteParams,
    committed: &ConcreteState,
    strain: &[f64; 3],
    char_length: f64,
) -> UpdateResult {
    update_full(p, committed, strain, char_length, 0.0, 1.0)
}

/// As [`update`] with the IMPL-EX extrapolation ratio `ratio` [-] = size of this increment /
/// size of the previous one (0 = no extrapolation: the cracks keep their committed
/// secant); used only when `p.implex`.
pub fn update_extrapolated(
    p: &ConcreteParams,
    committed: &ConcreteState,
    strain: &[f64; 3],
    char_length: f64,
    ratio: f64,
) -> UpdateResult {
    update_full(p, committed, strain, char_length, 0.0, ratio)
}

/// The general update: increment of `dt` days (only the viscoplastic option of the
/// compression plasticity depends on it; 0 = a load increment) and IMPL-EX extrapolation
/// ratio `ratio` (see [`update_extrapolated`]).
pub fn update_full(
    p: &ConcreteParams,
    committed: &ConcreteState,
    strain: &[f64; 3],
    char_length: f64,
    dt: f64,
    ratio: f64,
) -> UpdateResult {
    let mut st = committed.clone();
    let (s, d) = update_full_into(p, committed, strain, char_length, dt, ratio, &mut st)?;
    Ok((st, s, d))
}

/// Stress (σx, σy, τxy) [Pa] and tangent [Pa] of [`update_full`], its new state written
/// into `out` (the trial slot of the point: no state is built and moved per update). On an
/// error `out` holds no meaningful state.
// long: the routes of a point (crushed, rotating, cracked, compression plasticity, crack formation, elastic) read as one decision; each route's own work is in its module
pub fn update_full_into(
    p: &ConcreteParams,
    committed: &ConcreteState,
    strain: &[f64; 3],
    char_length: f64,
    dt: f64,
    ratio: f64,
    out: &mut ConcreteState,
) -> Result<([f64; 3], [[f64; 3]; 3]), MaterialError> {
    // The other routes build their state; it is moved into `out`.
    let moved = |out: &mut ConcreteState, r: UpdateResult| {
        r.map(|(st, s, d)| {
            *out = st;
            (s, d)
        })
    };
    if !strain.iter().all(|v| v.is_finite()) {
        return Err(MaterialError::NonFiniteStrain(*strain));
    }
    // Crush band: the post-peak law depends on the element size.
    let local = p.resolved_for(char_length)?;
    let p: &ConcreteParams = &local;
    if committed.crushed {
        return moved(out, Ok(crushed(p, committed, strain)));
    }
    if p.crack_model == CrackModel::Rotating {
        return moved(
            out,
            rotating::update(p, committed, strain, char_length, ratio),
        );
    }
    // IMPL-EX compression on every uncracked route and in the crack-axis directions of
    // cracked points (load increments only).
    let implex_c = p.compression_implex && dt == 0.0;
    if committed.n_cracks > 0 {
        return cracking::update_cracked_into(
            p,
            committed,
            strain,
            char_length,
            ratio,
            implex_c,
            out,
        );
    }
    let d = d_matrix(p.ec, p.nu);
    let ee: [f64; 3] = std::array::from_fn(|i| strain[i] - committed.plastic_strain[i]);
    let s_tr = matvec(&d, &ee);
    // σ1 once; its direction only where a crack forms (the same bits as before).
    let s1 = principal_max_value(&s_tr);
    // Plastic (compression) branch: if the trial stress is compression-dominated, or if the
    // trial would yield and the returned stress is compression-dominated. Routing on the
    // returned stress as well avoids sending a plastically flowing point to the elastic
    // branch only because its elastic trial shows lateral tension (uniaxial compression
    // with dilatancy does exactly that).
    let trial_cd = p.compression_dominated_s1(s1, &s_tr);
    // A virgin state stores ε̄ = 0; the hardening variable starts at initial yield ε̄0.
    let law = compression::HardeningLaw::new(p);
    let ebar0 = law.initial_yield_strain();
    let ebar_n = committed.ebar.max(ebar0);
    // σ̂_e alone (the value of `compression::sigma_hat`, without its gradient), evaluated
    // only when the route is not already plastic.
    let yields = || {
        ottosen::equivalent_stress(&p.ottosen, &s_tr) / p.q_norm()
            > law.at(ebar_n).sigma_c * (1.0 + 1e-13)
    };
    // The returned-stress route is only open to points that have flowed already: a
    // virgin point whose trial is tension-dominated stays elastic (else the Ottosen
    // loading surface, which reaches into tension at ~0.3 f_tm, would pull a cracking
    // point back into plasticity and make the response jump between iterations). Such a
    // point's return mapping would be thrown away whatever it gives, so it is not run,
    // nor its yield check (the same routes and bits as running and rejecting it).
    let flowed = committed.ebar > ebar0 + 1e-12;
    let held = committed.hold_plastic;
    if trial_cd || held || (flowed && yields()) {
        let res = compression::update_rate_with_law(
            p,
            &law,
            dt,
            &committed.strain,
            &committed.plastic_strain,
            ebar_n,
            strain,
        );
        let accept = match &res {
            Ok(u) => {
                held || trial_cd || (flowed && u.plastic && p.compression_dominated(&u.stress))
            }
            Err(_) => held || trial_cd,
        };
        if accept {
            let u = res?;
            assign(out, committed);
            out.strain = *strain;
            out.plastic_strain = u.plastic_strain;
            out.plastic_strain_old = committed.plastic_strain;
            out.ebar = u.ebar;
            let h = law.at(u.ebar);
            out.kappa = h.kappa.max(0.0);
            // σ_c = 0 means crushed only past the peak: with zero initial yield the curve
            // also starts at σ_c = 0, where a round-off strain must not crush the point.
            let spent = u.ebar > p.eps_c1 && h.sigma_c <= 0.0;
            if u.ebar >= p.eps_cu || spent {
                out.crushed = true;
                if implex_c {
                    // Crushed at the end of the increment, as an IMPL-EX crack forms: the
                    // extrapolated stress within it (no jump to zero at fixed strain).
                    return Ok(implex_compression(p, committed, strain, ratio, out));
                }
                let r = crushed(p, out, strain);
                return moved(out, Ok(r));
            }
            if implex_c {
                return Ok(implex_compression(p, committed, strain, ratio, out));
            }
            out.stress = u.stress;
            return Ok((u.stress, u.tangent));
        }
    }
    // Tension-dominated: elastic until the Ottosen failure surface, then crack.
    if s1 >= p.crack_ratio * p.ftm && ottosen::equivalent_stress(&p.ottosen, &s_tr) >= p.fcm {
        let phi = principal_angle(&s_tr);
        assign(out, committed);
        let st = &mut *out;
        st.n_cracks = 1;
        st.crack_angle = phi;
        st.crack_max = [0.0; 2];
        st.dir_ebar = [ebar_n; 2];
        st.dir_plastic = [0.0; 2];
        st.dir_plastic_old = [0.0; 2];
        if p.implex {
            // Explicit formation: the stress stays elastic in this increment; the crack
            // carries its strain at formation as e_max with zero rate.
            let t = cracking::strain_transform(phi);
            let e_n: f64 = (0..3).map(|j| t[0][j] * ee[j]).sum();
            st.crack_max = [e_n, 0.0];
            st.crack_max_old = st.crack_max;
            st.crack_strain = [e_n, 0.0];
            st.strain = *strain;
            st.plastic_strain_old = committed.plastic_strain;
            if implex_c {
                // The stress of the uncracked routes (no jump where the crack forms).
                return Ok(implex_compression(p, committed, strain, ratio, st));
            }
            st.stress = s_tr;
            return Ok((s_tr, d));
        }
        let r = cracking::update_cracked(p, out, strain, char_length, ratio, implex_c);
        return moved(out, r);
    }
    assign(out, committed);
    out.strain = *strain;
    out.plastic_strain_old = committed.plastic_strain;
    if implex_c {
        // The same extrapolated stress whichever route the implicit state takes: no jump
        // where a point that flowed last increment leaves the plastic route.
        return Ok(implex_compression(p, committed, strain, ratio, out));
    }
    out.stress = s_tr;
    Ok((s_tr, d))
}

/// IMPL-EX stress of an uncracked point (`compression_integration = "implex"`; Oliver,
/// Huespe & Cante 2008): the elastic stress of the plastic strain extrapolated from the
/// last increment's flow, ε̃ᵖ = εᵖ_n + r (εᵖ_n − εᵖ_n−1) (`ratio` r = this increment's
/// size over the last's), with the elastic tangent: linear in the strain within the
/// increment. `out` already holds the implicit state at `strain` (what the next
/// extrapolation starts from); its stress is set to the IMPL-EX one.
fn implex_compression(
    p: &ConcreteParams,
    committed: &ConcreteState,
    strain: &[f64; 3],
    ratio: f64,
    out: &mut ConcreteState,
) -> ([f64; 3], [[f64; 3]; 3]) {
    let ee: [f64; 3] = std::array::from_fn(|i| {
        let c = committed.plastic_strain[i];
        strain[i] - (c + ratio * (c - committed.plastic_strain_old[i]))
    });
    let d = d_matrix(p.ec, p.nu);
    let s = matvec(&d, &ee);
    out.stress = s;
    (s, d)
}

/// `*out = c.clone()` field by field (a creep box is reused; no whole-state temporary).
fn assign(out: &mut ConcreteState, c: &ConcreteState) {
    let ConcreteState {
        strain,
        stress,
        plastic_strain,
        plastic_strain_old,
        ebar,
        kappa,
        n_cracks,
        crack_angle,
        crack_max,
        crack_strain,
        dir_ebar,
        dir_plastic,
        dir_plastic_old,
        crushed,
        frozen,
        crack_max_old,
        hold_plastic,
        cutoff_max,
        cutoff_max_old,
        creep,
    } = c;
    out.strain = *strain;
    out.stress = *stress;
    out.plastic_strain = *plastic_strain;
    out.plastic_strain_old = *plastic_strain_old;
    out.ebar = *ebar;
    out.kappa = *kappa;
    out.n_cracks = *n_cracks;
    out.crack_angle = *crack_angle;
    out.crack_max = *crack_max;
    out.crack_strain = *crack_strain;
    out.dir_ebar = *dir_ebar;
    out.dir_plastic = *dir_plastic;
    out.dir_plastic_old = *dir_plastic_old;
    out.crushed = *crushed;
    out.frozen = *frozen;
    out.crack_max_old = *crack_max_old;
    out.hold_plastic = *hold_plastic;
    out.cutoff_max = *cutoff_max;
    out.cutoff_max_old = *cutoff_max_old;
    out.creep.clone_from(creep);
}

/// Response of a crushed point: zero stress, residual tangent.
fn crushed(
    p: &ConcreteParams,
    committed: &ConcreteState,
    strain: &[f64; 3],
) -> (ConcreteState, [f64; 3], [[f64; 3]; 3]) {
    let mut st = committed.clone();
    st.strain = *strain;
    st.stress = [0.0; 3];
    st.crushed = true;
    let d = d_matrix(p.ec, p.nu).map(|r| r.map(|v| v * p.residual_stiffness));
    (st, [0.0; 3], d)
}

#[cfg(test)]
mod tests;
