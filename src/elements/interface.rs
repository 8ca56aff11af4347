//! Joint contact (interface) element between two precast segments, after the contact element
//! of Habraken & Cescotto (1998) as described in Ribeiro, Campos Filho & Pacheco (2006), §4,
//! with the small-displacement kinematics and penalty/Coulomb law of
//! docs/theory-joints-tendons.md §1.
//!
//! * Face A: 2 or 3 nodes (an edge of a Q4 or Q8/Q9 element of segment A), given in the
//!   counter-clockwise edge order of its element (start, end, \[middle\]), so that body A lies to
//!   the **left** of the face and the normal `n_A = (−t_y, t_x)` points **into body A**.
//! * Face B: 2 or 3 nodes (an edge of the opposite segment), any orientation.
//! * At every integration point ξ_g of face A the opposite point on B is found once, in the
//!   reference configuration, by solving `x_B(ζ_B) − x_A − λ0 n_A = 0` (Newton).
//! * Small displacements (a project decision, docs/theory-joints-tendons.md §1): with Δu = u_B(ζ_B)
//!   − u_A(ξ_g), `λ = λ0 + Δu·n_A` (λ ≥ 0: closed, λ = penetration; λ < 0: open, gap −λ) and
//!   `g_t = Δu·t_A` (tangential relative displacement).
//!
//! Units: coordinates and displacements in m, penalty stiffnesses in Pa/m, stresses in Pa,
//! thickness in m, nodal forces in N.

use crate::fem::quadrature::{gauss, lobatto};
use crate::fem::shape::line_shape;

/// Joint parameters (plain model data, defined in [`crate::model`]).
pub use crate::model::element_data::InterfaceParams;

impl InterfaceParams {
    /// Dry joint with Coulomb friction μ and penalties `kn`, `kt` \[Pa/m\]; Gauss integration,
    /// no cohesion, no tensile strength, no residual stiffness.
    pub fn dry(kn: f64, kt: f64, friction: f64) -> Self {
        Self {
            kn,
            kt,
            friction,
            cohesion: 0.0,
            tensile_strength: 0.0,
            keyed: false,
            lobatto: false,
            residual_ratio: 0.0,
        }
    }

    /// Dry shear-keyed joint (closed → stick, only opening modelled; `keyed` in
    /// docs/theory-joints-tendons.md §1).
    pub fn keyed(kn: f64, kt: f64) -> Self {
        Self {
            keyed: true,
            ..Self::dry(kn, kt, 0.0)
        }
    }

    /// Epoxy joint: bonded with tensile strength `ft` \[Pa\] and cohesion `c` \[Pa\] until the
    /// tensile strength is exceeded, then dry with friction μ.
    pub fn epoxy(kn: f64, kt: f64, friction: f64, cohesion: f64, ft: f64) -> Self {
        Self {
            cohesion,
            tensile_strength: ft,
            ..Self::dry(kn, kt, friction)
        }
    }

    /// Check the admissible ranges.
    pub fn validate(&self) -> Result<(), InterfaceError> {
        let bad = |m: &str| Err(InterfaceError::InvalidParams(m.to_string()));
        if !(self.kn > 0.0 && self.kn.is_finite()) {
            return bad("kn must be positive and finite");
        }
        if !(self.kt >= 0.0 && self.kt.is_finite()) {
            return bad("kt must be non-negative and finite");
        }
        if !(self.friction >= 0.0 && self.friction.is_finite()) {
            return bad("friction must be non-negative");
        }
        if !(self.cohesion >= 0.0 && self.cohesion.is_finite()) {
            return bad("cohesion must be non-negative");
        }
        if !(self.tensile_strength >= 0.0 && self.tensile_strength.is_finite()) {
            return bad("tensile_strength must be non-negative");
        }
        if !(0.0..1.0).contains(&self.residual_ratio) {
            return bad("residual_ratio must be in [0, 1)");
        }
        Ok(())
    }
}

/// Errors of interface-element setup.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InterfaceError {
    /// A face must have 2 or 3 nodes.
    #[error("face {face} has {n} nodes; 2 or 3 expected")]
    BadNodeCount {
        /// 'A' or 'B'.
        face: char,
        /// Number of nodes given.
        n: usize,
    },
    /// Zero-length face (tangent undefined).
    #[error("face {face} is degenerate (zero length)")]
    DegenerateFace {
        /// 'A' or 'B'.
        face: char,
    },
    /// The normal through an integration point of A does not hit face B.
    #[error("integration point {point} of face A does not project onto face B (ζ_B = {zeta}); faces are not facing each other")]
    NoProjection {
        /// Integration point index.
        point: usize,
        /// Natural coordinate reached on B.
        zeta: f64,
    },
    /// Newton projection did not converge (e.g. face B parallel to the normal of A).
    #[error("projection of integration point {point} onto face B did not converge")]
    NoConvergence {
        /// Integration point index.
        point: usize,
    },
    /// Parameter out of range.
    #[error("invalid interface parameters: {0}")]
    InvalidParams(String),
}

/// Geometry of one integration point (fixed after the reference-configuration search).
#[derive(Debug, Clone, PartialEq)]
pub struct InterfacePoint {
    /// Natural coordinate ξ_g on face A \[-\].
    pub xi_a: f64,
    /// Natural coordinate ζ_B of the projected point on face B \[-\].
    pub zeta_b: f64,
    /// Initial signed normal distance λ0 \[m\] (> 0 overlap, < 0 initial gap, 0 match-cast).
    pub lambda0: f64,
    /// Unit normal of face A, pointing into body A.
    pub normal: [f64; 2],
    /// Unit tangent of face A (direction of increasing ξ).
    pub tangent: [f64; 2],
    /// Quadrature weight × line Jacobian |dx_A/dξ| \[m\].
    pub weight: f64,
    /// Global position of the point on face A \[m\].
    pub position: [f64; 2],
    /// Arc length from the first node of face A to the point \[m\].
    pub arc: f64,
    /// Shape function values of face A at ξ_g (first `n_a` used).
    pub n_a: [f64; 3],
    /// Shape function values of face B at ζ_B (first `n_b` used).
    pub n_b: [f64; 3],
}

/// A 2+2 or 3+3 (also 2+3 / 3+2) node joint contact element.
#[derive(Debug, Clone, PartialEq)]
pub struct InterfaceElement {
    n_a: usize,
    n_b: usize,
    points: Vec<InterfacePoint>,
}

/// Committed or trial state of one integration point, with its output quantities.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct InterfacePointState {
    /// Tangential plastic slip s_p \[m\] (history variable).
    pub plastic_slip: f64,
    /// Epoxy bond intact (history variable; always `false` for dry joints).
    pub bonded: bool,
    /// Closed (λ ≥ 0) in this state.
    pub closed: bool,
    /// Sliding (Coulomb limit reached) in this state.
    pub sliding: bool,
    /// Signed normal relative displacement λ \[m\] (penetration if > 0, gap if < 0).
    pub lambda: f64,
    /// Tangential relative displacement g_t = Δu·t_A \[m\].
    pub slip: f64,
    /// Normal stress σ_n \[Pa\], compression positive.
    pub normal_stress: f64,
    /// Shear stress τ = K_t (g_t − s_p) \[Pa\] (stick), positive when B has moved along +t_A
    /// relative to A.
    pub shear_stress: f64,
    /// Global position of the point on face A \[m\].
    pub position: [f64; 2],
    /// Arc-length position along face A from its first node \[m\].
    pub arc: f64,
}

impl InterfacePointState {
    /// Joint opening \[m\]: the gap −λ when open, 0 when closed.
    pub fn opening(&self) -> f64 {
        (-self.lambda).max(0.0)
    }
    /// Penetration \[m\]: λ when closed, 0 when open.
    pub fn penetration(&self) -> f64 {
        self.lambda.max(0.0)
    }
    /// Total tangential relative displacement (slip) \[m\].
    pub fn slip(&self) -> f64 {
        self.slip
    }
    /// Normal stress \[Pa\], compression positive.
    pub fn normal_stress(&self) -> f64 {
        self.normal_stress
    }
    /// Shear stress \[Pa\].
    pub fn shear_stress(&self) -> f64 {
        self.shear_stress
    }
    /// Arc-length position along face A \[m\].
    pub fn position_along_face(&self) -> f64 {
        self.arc
    }
    /// Global coordinates of the point on face A \[m\].
    pub fn position(&self) -> [f64; 2] {
        self.position
    }
}

/// A joint element with its law and thickness, as the assembly calls it.
pub struct Joint<'a> {
    /// Contact geometry.
    pub element: &'a InterfaceElement,
    /// Joint law.
    pub params: &'a InterfaceParams,
    /// Out-of-plane thickness [m].
    pub thickness: f64,
    /// Contact status (closed) of every point held for the rest of the increment, or empty
    /// when none is held ([`joint_law`]).
    pub held: &'a [bool],
}

impl super::ElementResponse for Joint<'_> {
    type Committed = [InterfacePointState];
    type Trial<'t> = &'t mut Vec<InterfacePointState>;

    /// [`InterfaceElement::response_with`] with the full (possibly unsymmetric) tangent.
    fn response(
        &self,
        u: &[f64],
        committed: &[InterfacePointState],
        trial: Self::Trial<'_>,
        into: super::Response<'_>,
    ) -> Result<bool, crate::materials::point::UpdateError> {
        let r =
            self.element
                .response_held(self.params, self.thickness, u, committed, self.held, true);
        into.f.copy_from_slice(&r.f_int);
        if let Some(k) = into.k {
            k.copy_from_slice(&r.k);
        }
        *trial = r.states;
        Ok(r.symmetric)
    }
}

/// Internal forces, tangent and updated (trial) states of an interface element.
#[derive(Debug, Clone, PartialEq)]
pub struct InterfaceResponse {
    /// Internal nodal forces \[N\], ordered like `u` (face A nodes then face B nodes, (x, y)).
    pub f_int: Vec<f64>,
    /// Tangent ∂f_int/∂u \[N/m\], dense row-major ndof × ndof.
    pub k: Vec<f64>,
    /// `false` when a sliding point contributes the non-symmetric friction coupling.
    pub symmetric: bool,
    /// Trial state of every integration point.
    pub states: Vec<InterfacePointState>,
}

/// Result of the point constitutive law: tractions, tangent and new state.
#[derive(Debug, Clone, PartialEq)]
pub struct JointLawResult {
    /// Shear stress τ \[Pa\].
    pub tau: f64,
    /// Normal stress σ_n \[Pa\], compression positive.
    pub sigma_n: f64,
    /// Tangent [\[∂τ/∂g_t, ∂τ/∂λ\], \[∂σ_n/∂g_t, ∂σ_n/∂λ\]] \[Pa/m\].
    pub tangent: [[f64; 2]; 2],
    /// New (trial) history: plastic slip, bond, flags.
    pub plastic_slip: f64,
    /// Bond intact after this step.
    pub bonded: bool,
    /// Closed (λ ≥ 0).
    pub closed: bool,
    /// Coulomb limit active.
    pub sliding: bool,
}

/// Penalty/Coulomb joint law (docs/theory-joints-tendons.md §1) for one point: `lambda` \[m\]
/// (penetration positive), `g_t` \[m\], committed plastic slip `sp_c` \[m\] and bond flag
/// `bonded_c`; `held` is the contact status (closed) of a dry point held for the rest of the
/// increment (`None`: decided by the sign of λ).
///
/// * held (Newton cycled on the point opening and closing, docs/theory-joints-tendons.md
///   §1 "Held contact status"): the dry point is closed or open as held, whatever the sign of
///   λ, so the law is one smooth branch for the rest of the increment;
/// * bonded (epoxy intact): σ_n = K_n λ in compression and tension; if −σ_n > f_t the point
///   debonds and is evaluated as dry in the same call;
/// * dry closed (λ ≥ 0): σ_n = K_n λ, τ_trial = K_t (g_t − s_p); slip if
///   |τ_trial| > max(μ σ_n + c, 0) (never if keyed), return τ = sign(τ_trial)(μ σ_n + c);
/// * dry open (λ < 0): σ_n = r K_n λ, τ = r K_t (g_t − s_p), and the plastic slip follows
///   g_t so that a re-closing joint starts from zero shear.
pub fn joint_law(
    p: &InterfaceParams,
    lambda: f64,
    g_t: f64,
    sp_c: f64,
    bonded_c: bool,
    held: Option<bool>,
) -> JointLawResult {
    let mut bonded = bonded_c;
    if bonded && -p.kn * lambda > p.tensile_strength {
        bonded = false;
    }
    // A bond acts in tension and compression alike: only a dry point's status is held.
    let closed = match held {
        Some(h) if !bonded => h,
        _ => lambda >= 0.0,
    };
    if bonded || closed {
        let sigma_n = p.kn * lambda;
        // Cohesion belongs to the bond of an epoxy joint, and to the joint itself if dry.
        let c = if p.tensile_strength > 0.0 && !bonded {
            0.0
        } else {
            p.cohesion
        };
        let tau_trial = p.kt * (g_t - sp_c);
        let limit = p.friction * sigma_n + c;
        if p.keyed || tau_trial.abs() <= limit.max(0.0) {
            return JointLawResult {
                tau: tau_trial,
                sigma_n,
                tangent: [[p.kt, 0.0], [0.0, p.kn]],
                plastic_slip: sp_c,
                bonded,
                closed,
                sliding: false,
            };
        }
        let sgn = tau_trial.signum();
        let (tau, dtau_dl) = if limit > 0.0 {
            (sgn * limit, sgn * p.friction * p.kn)
        } else {
            (0.0, 0.0)
        };
        let plastic_slip = if p.kt > 0.0 { g_t - tau / p.kt } else { g_t };
        return JointLawResult {
            tau,
            sigma_n,
            tangent: [[0.0, dtau_dl], [0.0, p.kn]],
            plastic_slip,
            bonded,
            closed,
            sliding: true,
        };
    }
    // Open dry joint.
    let r = p.residual_ratio;
    let tau = r * p.kt * (g_t - sp_c);
    let plastic_slip = if p.kt > 0.0 { g_t - tau / p.kt } else { g_t };
    JointLawResult {
        tau,
        sigma_n: r * p.kn * lambda,
        tangent: [[r * p.kt, 0.0], [0.0, r * p.kn]],
        plastic_slip,
        bonded: false,
        closed: false,
        sliding: false,
    }
}

fn line_geom(coords: &[[f64; 2]], r: f64) -> ([f64; 3], [f64; 2], [f64; 2]) {
    let (n, dn) = line_shape(coords.len(), r);
    let mut x = [0.0; 2];
    let mut dx = [0.0; 2];
    for (i, c) in coords.iter().enumerate() {
        x[0] += n[i] * c[0];
        x[1] += n[i] * c[1];
        dx[0] += dn[i] * c[0];
        dx[1] += dn[i] * c[1];
    }
    (n, x, dx)
}

/// Arc length of a line element from r = −1 to r (4-point Gauss on \[−1, r\]; exact for
/// straight faces).
fn arc_length(coords: &[[f64; 2]], r: f64) -> f64 {
    let g = gauss(4);
    let half = 0.5 * (r + 1.0);
    g.points
        .iter()
        .zip(&g.weights)
        .map(|(q, w)| {
            let s = -1.0 + half * (q + 1.0);
            let (_, _, dx) = line_geom(coords, s);
            w * half * (dx[0] * dx[0] + dx[1] * dx[1]).sqrt()
        })
        .sum()
}

/// Tolerance on |ζ_B| − 1 accepted as "on face B" (covers round-off at the face ends).
const ZETA_TOL: f64 = 1e-8;

impl InterfaceElement {
    /// Build the element from the reference coordinates \[m\] of face A (2 or 3 nodes, order
    /// start, end, \[middle\], body A on the left) and face B (2 or 3 nodes). Performs the
    /// contact search once; fails if a point of A does not project onto B.
    pub fn new(
        face_a: &[[f64; 2]],
        face_b: &[[f64; 2]],
        params: &InterfaceParams,
    ) -> Result<Self, InterfaceError> {
        params.validate()?;
        for (face, f) in [('A', face_a), ('B', face_b)] {
            if !(2..=3).contains(&f.len()) {
                return Err(InterfaceError::BadNodeCount { face, n: f.len() });
            }
        }
        let len =
            |f: &[[f64; 2]]| ((f[1][0] - f[0][0]).powi(2) + (f[1][1] - f[0][1]).powi(2)).sqrt();
        let scale = len(face_a).max(len(face_b));
        for (face, f) in [('A', face_a), ('B', face_b)] {
            if len(f) <= 1e-12 * scale.max(f64::MIN_POSITIVE) {
                return Err(InterfaceError::DegenerateFace { face });
            }
        }
        let n_a = face_a.len();
        let rule = if params.lobatto {
            lobatto(n_a)
        } else {
            gauss(n_a)
        };
        let mut points = Vec::with_capacity(n_a);
        for (g, (&xi, &w)) in rule.points.iter().zip(&rule.weights).enumerate() {
            let (na, xa, dxa) = line_geom(face_a, xi);
            let j = (dxa[0] * dxa[0] + dxa[1] * dxa[1]).sqrt();
            if j <= 1e-14 * scale {
                return Err(InterfaceError::DegenerateFace { face: 'A' });
            }
            let t = [dxa[0] / j, dxa[1] / j];
            let n = [-t[1], t[0]];
            // Newton on R(ζ, λ) = x_B(ζ) − x_A − λ n = 0, Jacobian [dx_B/dζ, −n].
            let (_, xb0, _) = line_geom(face_b, 0.0);
            let mut zeta = 0.0;
            let mut lam = (xb0[0] - xa[0]) * n[0] + (xb0[1] - xa[1]) * n[1];
            let mut converged = false;
            for _ in 0..50 {
                let (_, xb, dxb) = line_geom(face_b, zeta);
                let r = [xb[0] - xa[0] - lam * n[0], xb[1] - xa[1] - lam * n[1]];
                let det = dxb[0] * (-n[1]) - (-n[0]) * dxb[1];
                if det.abs() <= 1e-12 * (dxb[0].hypot(dxb[1])) {
                    return Err(InterfaceError::NoConvergence { point: g });
                }
                // Solve [dxb, −n] [dζ, dλ]ᵀ = −r.
                let dz = (-r[0] * (-n[1]) - (-n[0]) * (-r[1])) / det;
                let dl = (dxb[0] * (-r[1]) - dxb[1] * (-r[0])) / det;
                zeta += dz;
                lam += dl;
                if !zeta.is_finite() || zeta.abs() > 1e3 {
                    return Err(InterfaceError::NoProjection { point: g, zeta });
                }
                // Round-off floor: coordinates of size |x| carry ~1e-16 |x| noise, which on a
                // short face is ~1e-13 in ζ; 1e-11 is far below any geometric meaning.
                if dz.abs() < 1e-11 && dl.abs() <= 1e-11 * scale {
                    converged = true;
                    break;
                }
            }
            if !converged {
                return Err(InterfaceError::NoConvergence { point: g });
            }
            if zeta.abs() > 1.0 + ZETA_TOL {
                return Err(InterfaceError::NoProjection { point: g, zeta });
            }
            let zeta = zeta.clamp(-1.0, 1.0);
            let (nb, _) = line_shape(face_b.len(), zeta);
            points.push(InterfacePoint {
                xi_a: xi,
                zeta_b: zeta,
                lambda0: lam,
                normal: n,
                tangent: t,
                weight: w * j,
                position: xa,
                arc: arc_length(face_a, xi),
                n_a: na,
                n_b: nb,
            });
        }
        Ok(Self {
            n_a,
            n_b: face_b.len(),
            points,
        })
    }

    /// Number of integration points.
    pub fn n_points(&self) -> usize {
        self.points.len()
    }

    /// Number of degrees of freedom (2 per node of A and B).
    pub fn n_dofs(&self) -> usize {
        2 * (self.n_a + self.n_b)
    }

    /// Integration-point geometry.
    pub fn points(&self) -> &[InterfacePoint] {
        &self.points
    }

    /// Initial (virgin) state of every point: no slip, bonded iff `tensile_strength > 0`,
    /// closed iff λ0 ≥ 0, zero tractions (the penalty forces of an initial overlap λ0 > 0 appear
    /// only in the first `response`).
    pub fn initial_states(&self, params: &InterfaceParams) -> Vec<InterfacePointState> {
        self.points
            .iter()
            .map(|p| InterfacePointState {
                plastic_slip: 0.0,
                bonded: params.tensile_strength > 0.0,
                closed: p.lambda0 >= 0.0,
                sliding: false,
                lambda: p.lambda0,
                slip: 0.0,
                normal_stress: 0.0,
                shear_stress: 0.0,
                position: p.position,
                arc: p.arc,
            })
            .collect()
    }

    /// Relative displacement (g_t, λ) at point `p` for element displacements `u`.
    fn kinematics(&self, p: &InterfacePoint, u: &[f64]) -> (f64, f64) {
        let mut du = [0.0; 2];
        for i in 0..self.n_a {
            du[0] -= p.n_a[i] * u[2 * i];
            du[1] -= p.n_a[i] * u[2 * i + 1];
        }
        for j in 0..self.n_b {
            let k = 2 * (self.n_a + j);
            du[0] += p.n_b[j] * u[k];
            du[1] += p.n_b[j] * u[k + 1];
        }
        let gt = du[0] * p.tangent[0] + du[1] * p.tangent[1];
        let lam = p.lambda0 + du[0] * p.normal[0] + du[1] * p.normal[1];
        (gt, lam)
    }

    /// Internal forces f_int = Σ_g w_g j_g b Bᵀ(τ, σ_n), tangent K = Σ_g w_g j_g b Bᵀ C B and
    /// trial states for displacements `u` \[m\] (face-A nodes then face-B nodes, (ux, uy) per
    /// node), thickness `thickness` \[m\] and the committed point states.
    ///
    /// Panics if `u` or `committed` have the wrong length.
    pub fn response(
        &self,
        params: &InterfaceParams,
        thickness: f64,
        u: &[f64],
        committed: &[InterfacePointState],
    ) -> InterfaceResponse {
        self.response_with(params, thickness, u, committed, false)
    }

    /// As [`Self::response`]; with `symmetric_tangent` the friction coupling term of sliding
    /// points (∂τ/∂λ = μ K_n) is dropped, which keeps the tangent symmetric and positive
    /// semi-definite for a Cholesky solver (docs/theory-joints-tendons.md §1); Newton then
    /// converges linearly while points slide, to the same answer.
    pub fn response_with(
        &self,
        params: &InterfaceParams,
        thickness: f64,
        u: &[f64],
        committed: &[InterfacePointState],
        symmetric_tangent: bool,
    ) -> InterfaceResponse {
        self.response_held(params, thickness, u, committed, &[], symmetric_tangent)
    }

    /// As [`Self::response_with`], with the contact status (closed) of every point held as
    /// `held` says (empty: none held; see [`joint_law`]).
    ///
    /// Panics if `held` is neither empty nor one entry per point.
    pub fn response_held(
        &self,
        params: &InterfaceParams,
        thickness: f64,
        u: &[f64],
        committed: &[InterfacePointState],
        held: &[bool],
        symmetric_tangent: bool,
    ) -> InterfaceResponse {
        let nd = self.n_dofs();
        assert!(
            held.is_empty() || held.len() == self.points.len(),
            "interface: {} held statuses for {} points",
            held.len(),
            self.points.len()
        );
        assert_eq!(
            u.len(),
            nd,
            "interface: u has {} entries, {nd} expected",
            u.len()
        );
        assert_eq!(
            committed.len(),
            self.points.len(),
            "interface: wrong number of committed states"
        );
        let mut f = vec![0.0; nd];
        let mut k = vec![0.0; nd * nd];
        let mut symmetric = true;
        let mut states = Vec::with_capacity(self.points.len());
        // Rows of B: bt (tangential), bn (normal), each of length nd.
        let mut bt = vec![0.0; nd];
        let mut bn = vec![0.0; nd];
        for (g, (p, c)) in self.points.iter().zip(committed).enumerate() {
            let (gt, lam) = self.kinematics(p, u);
            let r = joint_law(
                params,
                lam,
                gt,
                c.plastic_slip,
                c.bonded,
                held.get(g).copied(),
            );
            for i in 0..self.n_a {
                for d in 0..2 {
                    bt[2 * i + d] = -p.n_a[i] * p.tangent[d];
                    bn[2 * i + d] = -p.n_a[i] * p.normal[d];
                }
            }
            for j in 0..self.n_b {
                for d in 0..2 {
                    bt[2 * (self.n_a + j) + d] = p.n_b[j] * p.tangent[d];
                    bn[2 * (self.n_a + j) + d] = p.n_b[j] * p.normal[d];
                }
            }
            let wb = p.weight * thickness;
            let mut cm = r.tangent;
            if symmetric_tangent {
                cm[0][1] = 0.0;
                cm[1][0] = 0.0;
            }
            if cm[0][1] != 0.0 || cm[1][0] != 0.0 {
                symmetric = false;
            }
            for a in 0..nd {
                f[a] += wb * (bt[a] * r.tau + bn[a] * r.sigma_n);
                // (C B)_a-column pieces: ct = C[0]·(bt, bn), cn = C[1]·(bt, bn).
                let (ta, na) = (bt[a], bn[a]);
                if ta == 0.0 && na == 0.0 {
                    continue;
                }
                for b in 0..nd {
                    let ct = cm[0][0] * bt[b] + cm[0][1] * bn[b];
                    let cn = cm[1][0] * bt[b] + cm[1][1] * bn[b];
                    k[a * nd + b] += wb * (ta * ct + na * cn);
                }
            }
            states.push(InterfacePointState {
                plastic_slip: r.plastic_slip,
                bonded: r.bonded,
                closed: r.closed,
                sliding: r.sliding,
                lambda: lam,
                slip: gt,
                normal_stress: r.sigma_n,
                shear_stress: r.tau,
                position: p.position,
                arc: p.arc,
            });
        }
        InterfaceResponse {
            f_int: f,
            k,
            symmetric,
            states,
        }
    }
}

/// One neighbouring element layer for [`suggest_normal_stiffness`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointNeighbour {
    /// Young's modulus of the neighbouring concrete element \[Pa\].
    pub e: f64,
    /// Its size normal to the joint \[m\].
    pub h: f64,
    /// Its thickness \[m\].
    pub thickness: f64,
}

/// Default penalty factor of [`suggest_normal_stiffness`]: the joint's penetration is 1/100 of
/// the elastic shortening of the two adjacent element layers (docs/theory-joints-tendons.md §1:
/// 10…1000).
pub const DEFAULT_PENALTY_FACTOR: f64 = 100.0;

/// Suggested normal penalty K_n \[Pa/m\] for a joint of thickness `joint_thickness` \[m\] between
/// the element layers `a` and `b`.
///
/// Guideline: the two adjacent layers act as springs in series with line stiffness E·b/h per
/// unit joint length; K_n is chosen so that the joint spring (K_n·b_joint) is `factor` times
/// stiffer than that series pair:
///
/// `K_n = factor / (b_joint · (h_A/(E_A b_A) + h_B/(E_B b_B)))`.
///
/// The penetration under a uniform stress is then 1/`factor` of the layers' shortening, so the
/// joint adds ~1/`factor` to the local compliance. `factor` = 10…1000 (default 100); larger
/// values make the global matrix ill-conditioned with little gain. K_t = K_n is a reasonable
/// companion for keyed joints, K_t ≈ 0.1…1 K_n for dry friction joints.
pub fn suggest_normal_stiffness(
    a: JointNeighbour,
    b: JointNeighbour,
    joint_thickness: f64,
    factor: f64,
) -> f64 {
    let flex = a.h / (a.e * a.thickness) + b.h / (b.e * b.thickness);
    factor / (joint_thickness * flex)
}

#[cfg(test)]
mod tests {
    use super::*;

    const L: f64 = 0.6; // joint length [m]
    const B: f64 = 0.25; // thickness [m]
    const KN: f64 = 1e12; // Pa/m
    const KT: f64 = 4e11;

    /// Horizontal match-cast joint at y = 0, body A below: face A runs right→left (CCW order
    /// of the lower element's top edge) so n_A = (0, −1) points into A.
    fn faces(n: usize) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
        let a = if n == 2 {
            vec![[L, 0.0], [0.0, 0.0]]
        } else {
            vec![[L, 0.0], [0.0, 0.0], [0.5 * L, 0.0]]
        };
        let b = if n == 2 {
            vec![[0.0, 0.0], [L, 0.0]]
        } else {
            vec![[0.0, 0.0], [L, 0.0], [0.5 * L, 0.0]]
        };
        (a, b)
    }

    /// Dense Gaussian elimination with partial pivoting (test helper).
    fn solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
        let n = b.len();
        for c in 0..n {
            let p = (c..n)
                .max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))
                .unwrap();
            for j in 0..n {
                a.swap(c * n + j, p * n + j);
            }
            b.swap(c, p);
            for r in c + 1..n {
                let m = a[r * n + c] / a[c * n + c];
                for j in c..n {
                    a[r * n + j] -= m * a[c * n + j];
                }
                b[r] -= m * b[c];
            }
        }
        let mut x = vec![0.0; n];
        for r in (0..n).rev() {
            let s: f64 = (r + 1..n).map(|j| a[r * n + j] * x[j]).sum();
            x[r] = (b[r] - s) / a[r * n + r];
        }
        x
    }

    /// Check 18: uniform compression σ; A fixed, consistent nodal loads on B (pushing B into
    /// A, i.e. along n_A = −y). Penetration must be σ/K_n at every point and the resultant of
    /// the contact forces σ·b·L. Tolerance 1e-8 rel (check 18, docs/theory-joints-tendons.md §4;
    /// round-off of a 4×4…6×6 dense solve with entries ~1e11 is ~1e-15 rel).
    #[test]
    fn uniform_compression_penetration_and_resultant() {
        let sigma = 12e6;
        for n in [2, 3] {
            for lob in [false, true] {
                let (fa, fb) = faces(n);
                let mut p = InterfaceParams::dry(KN, KT, 0.6);
                p.lobatto = lob;
                let el = InterfaceElement::new(&fa, &fb, &p).unwrap();
                let st = el.initial_states(&p);
                let nd = el.n_dofs();
                let k0 = el.response(&p, B, &vec![0.0; nd], &st).k;
                // Consistent nodal loads of a uniform traction on B.
                let wts: Vec<f64> = if n == 2 {
                    vec![0.5, 0.5]
                } else {
                    vec![1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0]
                };
                let nb = 2 * n;
                let off = 2 * n;
                let mut kbb = vec![0.0; nb * nb];
                for i in 0..nb {
                    for j in 0..nb {
                        kbb[i * nb + j] = k0[(off + i) * nd + off + j];
                    }
                }
                let mut fbv = vec![0.0; nb];
                for (j, w) in wts.iter().enumerate() {
                    fbv[2 * j + 1] = -sigma * B * L * w;
                }
                let ub = solve(kbb, fbv);
                let mut u = vec![0.0; nd];
                u[off..].copy_from_slice(&ub);
                let r = el.response(&p, B, &u, &st);
                for s in &r.states {
                    assert!(s.closed && !s.sliding);
                    assert!((s.penetration() - sigma / KN).abs() < 1e-8 * sigma / KN);
                    assert!((s.normal_stress() - sigma).abs() < 1e-8 * sigma);
                    assert!(s.shear_stress().abs() < 1e-8 * sigma);
                }
                let fy_b: f64 = (0..n).map(|j| r.f_int[off + 2 * j + 1]).sum();
                let fy_a: f64 = (0..n).map(|i| r.f_int[2 * i + 1]).sum();
                assert!((fy_b + sigma * B * L).abs() < 1e-8 * sigma * B * L, "n={n}");
                assert!((fy_a - sigma * B * L).abs() < 1e-8 * sigma * B * L);
                // Equilibrium with the applied loads on B.
                for (j, w) in wts.iter().enumerate() {
                    assert!(
                        (r.f_int[off + 2 * j + 1] + sigma * B * L * w).abs() < 1e-8 * sigma * B * L
                    );
                }
            }
        }
    }

    /// Pulled apart: zero force (< 1e-9 of the compression load used above, relative; exactly
    /// zero without residual stiffness), and with residual ratio r the force is r·K_n·gap.
    #[test]
    fn open_joint_transmits_no_force() {
        let load = 12e6 * B * L;
        for n in [2, 3] {
            let (fa, fb) = faces(n);
            let p = InterfaceParams::dry(KN, KT, 0.6);
            let el = InterfaceElement::new(&fa, &fb, &p).unwrap();
            let st = el.initial_states(&p);
            let mut u = vec![0.0; el.n_dofs()];
            for j in 0..n {
                u[2 * n + 2 * j + 1] = 1e-3; // B moves up, away from A
                u[2 * n + 2 * j] = 2e-4; // and sideways
            }
            let r = el.response(&p, B, &u, &st);
            assert!(r.f_int.iter().all(|f| f.abs() < 1e-9 * load));
            assert!(r.k.iter().all(|k| *k == 0.0));
            for s in &r.states {
                assert!(!s.closed);
                assert!((s.opening() - 1e-3).abs() < 1e-15);
            }
        }
    }

    /// Shear below μσ_n sticks (τ = K_t g), above slides (τ = μσ_n); keyed never slides.
    /// Tolerance 1e-8 rel (exact arithmetic up to round-off).
    #[test]
    fn stick_slip_switch_and_keyed() {
        let mu = 0.6;
        let sigma = 10e6;
        let lam = sigma / KN;
        let limit_g = mu * sigma / KT;
        let (fa, fb) = faces(3);
        for keyed in [false, true] {
            // The keyed joint through its constructor (friction set for the comparison).
            let p = if keyed {
                InterfaceParams {
                    friction: mu,
                    ..InterfaceParams::keyed(KN, KT)
                }
            } else {
                InterfaceParams::dry(KN, KT, mu)
            };
            let el = InterfaceElement::new(&fa, &fb, &p).unwrap();
            let st = el.initial_states(&p);
            for (g, expect_slide) in [(0.9 * limit_g, false), (1.5 * limit_g, true)] {
                let mut u = vec![0.0; el.n_dofs()];
                for j in 0..3 {
                    u[6 + 2 * j + 1] = -lam;
                    u[6 + 2 * j] = -g; // t_A = (−1, 0)
                }
                let r = el.response(&p, B, &u, &st);
                for s in &r.states {
                    assert!((s.slip() - g).abs() < 1e-12 * g);
                    let slides = expect_slide && !keyed;
                    assert_eq!(s.sliding, slides);
                    let tau = if slides { mu * sigma } else { KT * g };
                    assert!((s.shear_stress() - tau).abs() < 1e-8 * tau);
                }
                assert_eq!(r.symmetric, !expect_slide || keyed);
            }
        }
    }

    /// Arc length along a curved 3-node face (ends (−1, 0), (1, 0), midside (0, h), so
    /// x = r, y = h (1 − r²)) against the closed form ∫ √(1 + a² x²) dx, a = 2h:
    /// F(x) = x/2 √(1 + a² x²) + asinh(a x)/(2a), from −1 to r. h = 0.1: the integrand is
    /// smooth and the 4-point rule is within 1e-7 of it (asserted 1e-6 relative).
    #[test]
    fn arc_length_of_a_curved_face_follows_the_closed_form() {
        let h = 0.1;
        let a = 2.0 * h;
        let f = |x: f64| 0.5 * x * (1.0 + a * a * x * x).sqrt() + (a * x).asinh() / (2.0 * a);
        let coords = [[-1.0, 0.0], [1.0, 0.0], [0.0, h]];
        for r in [-0.5, 0.0, 0.3, 1.0] {
            let exact = f(r) - f(-1.0);
            let got = arc_length(&coords, r);
            assert!(
                (got - exact).abs() < 1e-6 * exact,
                "r = {r}: {got} vs {exact}"
            );
        }
    }

    /// Rigid-body translation and small rotation of both faces together produce no force
    /// (match-cast faces, λ0 = 0): the interpolated relative displacement vanishes exactly, so
    /// the tolerance is round-off: 1e-9 of the force K_n·|u|·b·L the same u would cause as a
    /// relative motion.
    #[test]
    fn rigid_body_motion_gives_no_force() {
        for n in [2, 3] {
            // Inclined joint to exercise both components.
            let rot = |x: [f64; 2]| {
                let (c, s) = (0.6f64, 0.8f64);
                [c * x[0] - s * x[1] + 1.0, s * x[0] + c * x[1] - 2.0]
            };
            let (fa, fb) = faces(n);
            let fa: Vec<_> = fa.into_iter().map(rot).collect();
            let fb: Vec<_> = fb.into_iter().map(rot).collect();
            let p = InterfaceParams::dry(KN, KT, 0.6);
            let el = InterfaceElement::new(&fa, &fb, &p).unwrap();
            let st = el.initial_states(&p);
            let theta = 1e-4;
            let (tx, ty) = (3e-4, -2e-4);
            let mut u = Vec::new();
            for x in fa.iter().chain(&fb) {
                u.push(tx - theta * x[1]);
                u.push(ty + theta * x[0]);
            }
            let r = el.response(&p, B, &u, &st);
            let scale = KN * 3e-4 * B * L;
            assert!(
                r.f_int.iter().all(|f| f.abs() < 1e-9 * scale),
                "{:?}",
                r.f_int
            );
        }
    }

    /// Consistent tangent vs central finite differences of f_int in stick, slip and open
    /// states. f_int is piecewise linear in u, so away from the switch points the central
    /// difference is exact up to round-off; h = 1e-8 m keeps the round-off (|f|·1e-16/h ≈ 1 N/m)
    /// far below the tolerance 1e-6 of max |K| (≈ 1e5 N/m).
    #[test]
    fn tangent_matches_finite_differences() {
        let mu = 0.6;
        let lam = 1e-5;
        let (fa, fb) = faces(3);
        // Slightly curved, inclined faces with a small initial gap (λ0 < 0) for generality.
        let fa: Vec<_> = fa.iter().map(|x| [x[0], x[1] + 0.1 * x[0]]).collect();
        let mut fb: Vec<_> = fb.iter().map(|x| [x[0], x[1] + 0.1 * x[0]]).collect();
        fb[2][1] += 1e-3;
        let mut p = InterfaceParams::dry(KN, KT, mu);
        p.cohesion = 0.5e6;
        p.residual_ratio = 1e-3;
        let el = InterfaceElement::new(&fa, &fb, &p).unwrap();
        let mut st = el.initial_states(&p);
        st[1].plastic_slip = 1e-6;
        let lam0: Vec<f64> = el.points().iter().map(|q| q.lambda0).collect();
        let lam0max = lam0.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        let (nv, tv) = (el.points()[0].normal, el.points()[0].tangent);
        for (case, (dn, dt)) in [
            ("stick", (lam + lam0max, 1e-7)),
            ("slip", (lam + lam0max, 1e-2)),
            ("open", (-lam, 3e-5)),
        ] {
            let n = el.n_points();
            let mut u = vec![0.0; el.n_dofs()];
            for j in 0..3 {
                // Move B along n_A (into A) or against it, and along t_A.
                for d in 0..2 {
                    u[6 + 2 * j + d] =
                        dn * (1.0 + 0.1 * j as f64) * nv[d] + dt * (1.0 + 0.2 * j as f64) * tv[d];
                }
            }
            u[0] = 1e-7;
            u[3] = -2e-7;
            let r = el.response(&p, B, &u, &st);
            match case {
                "stick" => assert!(r.states.iter().all(|s| s.closed && !s.sliding)),
                "slip" => assert!(r.states.iter().all(|s| s.closed && s.sliding)),
                _ => assert!(r.states.iter().all(|s| !s.closed)),
            }
            let nd = el.n_dofs();
            let kmax = r.k.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            let h = 1e-3 * lam;
            for b in 0..nd {
                let mut up = u.clone();
                let mut um = u.clone();
                up[b] += h;
                um[b] -= h;
                let fp = el.response(&p, B, &up, &st).f_int;
                let fm = el.response(&p, B, &um, &st).f_int;
                for a in 0..nd {
                    let fd = (fp[a] - fm[a]) / (2.0 * h);
                    assert!(
                        (fd - r.k[a * nd + b]).abs() < 1e-6 * kmax,
                        "{case} K[{a},{b}] = {} fd {fd} (n={n})",
                        r.k[a * nd + b]
                    );
                }
            }
        }
    }

    /// A held contact status overrides the sign of λ for a dry point (closed: σ_n = K_n λ
    /// even with λ < 0; open: σ_n = r K_n λ even with λ > 0), a bonded point ignores it, and
    /// no hold is the plain law to the bit. Exact comparisons: one product each.
    #[test]
    fn held_status_overrides_the_sign_of_lambda_on_dry_points_only() {
        let mut p = InterfaceParams::dry(KN, KT, 0.6);
        p.residual_ratio = 1e-3;
        let lam = 1e-6;
        for (l, held, closed, sigma) in [
            (-lam, Some(true), true, -KN * lam),
            (lam, Some(false), false, 1e-3 * KN * lam),
            (-lam, Some(false), false, -1e-3 * KN * lam),
            (lam, Some(true), true, KN * lam),
        ] {
            let r = joint_law(&p, l, 0.0, 0.0, false, held);
            assert_eq!(
                (r.closed, r.sigma_n),
                (closed, sigma),
                "λ {l}, held {held:?}"
            );
            assert_eq!(r.tangent[1][1], if closed { KN } else { 1e-3 * KN });
        }
        // Without a hold the law is unchanged: held at the status λ gives is the same law.
        for l in [-lam, lam] {
            assert_eq!(
                joint_law(&p, l, 2e-7, 1e-7, false, None),
                joint_law(&p, l, 2e-7, 1e-7, false, Some(l >= 0.0))
            );
        }
        // An intact epoxy bond acts in tension: the hold does not apply.
        let e = InterfaceParams::epoxy(KN, KT, 0.6, 2e6, 3e6);
        let r = joint_law(&e, -lam, 0.0, 0.0, true, Some(false));
        assert!(r.bonded && r.sigma_n == -KN * lam);
    }

    /// Epoxy joint: carries tension up to f_t, then debonds and is dry (no tension, no
    /// cohesion). Tolerance 1e-9 rel (closed-form values).
    #[test]
    fn epoxy_joint_debonds_in_tension() {
        let p = InterfaceParams::epoxy(KN, KT, 0.6, 2e6, 3e6);
        let r = joint_law(&p, -2e6 / KN, 0.0, 0.0, true, None);
        assert!(r.bonded && (r.sigma_n + 2e6).abs() < 1e-9 * 2e6);
        let r = joint_law(&p, -4e6 / KN, 0.0, 0.0, true, None);
        assert!(!r.bonded && r.sigma_n == 0.0 && r.tau == 0.0);
        // Re-closed after debonding: cohesion lost, friction only.
        let g = 1e-3;
        let r = joint_law(&p, 5e6 / KN, g, 0.0, false, None);
        assert!(r.sliding && (r.tau - 0.6 * 5e6).abs() < 1e-9 * 3e6);
        // Bonded: cohesion adds to friction.
        let r = joint_law(&p, 5e6 / KN, g, 0.0, true, None);
        assert!(r.sliding && (r.tau - (0.6 * 5e6 + 2e6)).abs() < 1e-9 * 5e6);
    }

    /// A face B beside A (not facing it) is rejected; a face B parallel to the normal too.
    #[test]
    fn non_facing_faces_are_rejected() {
        let p = InterfaceParams::dry(KN, KT, 0.6);
        let fa = vec![[L, 0.0], [0.0, 0.0]];
        let fb = vec![[2.0 * L, 0.0], [3.0 * L, 0.0]];
        assert!(matches!(
            InterfaceElement::new(&fa, &fb, &p),
            Err(InterfaceError::NoProjection { .. })
        ));
        let fb = vec![[0.3, 0.0], [0.3, 1.0]];
        assert!(InterfaceElement::new(&fa, &fb, &p).is_err());
        let fb = vec![[0.3, 0.0]];
        assert!(matches!(
            InterfaceElement::new(&fa, &fb, &p),
            Err(InterfaceError::BadNodeCount { face: 'B', n: 1 })
        ));
    }

    /// Gap and arc position from the search: parallel faces 2 mm apart give λ0 = −2 mm, and
    /// the points' arc positions are those of the rule on face A (exact for straight faces).
    #[test]
    fn search_finds_gap_and_positions() {
        let p = InterfaceParams::dry(KN, KT, 0.6);
        let fa = vec![[L, 0.0], [0.0, 0.0]];
        let fb = vec![[0.0, 0.002], [L, 0.002]];
        let el = InterfaceElement::new(&fa, &fb, &p).unwrap();
        let a = 1.0 / 3f64.sqrt();
        for (q, xi) in el.points().iter().zip([-a, a]) {
            assert!((q.lambda0 + 0.002).abs() < 1e-14);
            assert!((q.arc - 0.5 * (xi + 1.0) * L).abs() < 1e-14);
            assert!((q.position[0] - (L - q.arc)).abs() < 1e-14);
        }
    }

    /// The penalty guideline: equal layers E = 30 GPa, h = 0.1 m, b = 0.2 m, factor 100 →
    /// K_n = 100·E/(2h) = 1.5e13 Pa/m (hand computation; 1e-12 rel round-off).
    #[test]
    fn penalty_guideline() {
        let nb = JointNeighbour {
            e: 30e9,
            h: 0.1,
            thickness: 0.2,
        };
        let k = suggest_normal_stiffness(nb, nb, 0.2, DEFAULT_PENALTY_FACTOR);
        assert!((k - 1.5e13).abs() < 1e-12 * 1.5e13);
    }
}
