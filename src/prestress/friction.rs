//! Friction losses at stressing and anchorage set (draw-in), docs/theory-joints-tendons.md §3 and
//! seed eq. (27):
//!
//! `σ_p(s) = σ_pi · exp[−μ (Σ Δα + k s)]`
//!
//! with σ_pi the stress at the jack \[Pa\], μ the curvature friction coefficient \[-\], Σ Δα the
//! cumulative angular deviation from the jack \[rad\], s the distance from the jack \[m\] and k the
//! wobble coefficient \[rad/m\] (seed: 0.0001 per cm = 0.01 /m).
//!
//! A tendon path is a polyline (straight segments with angle changes at the vertices: between
//! vertices the stress decays exponentially with rate μk, at a vertex it drops by the factor
//! e^{−μ|Δθ|}) or a sampled curve (the angle change between two samples spread evenly over
//! the arc between them: rate μ(k + Δθ/Δs), exact for circular arcs and of second order in
//! the sample spacing for other smooth curves; see [`TendonPath::sampled_curve`]).
//! The profile is stored exactly as pieces σ(s) = c + a·e^{r(s − s0)}, so integrals for the
//! anchorage-set area method are analytic.

/// Friction coefficients.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrictionParams {
    /// Curvature friction coefficient μ \[-\] (seed: 0.50 steel on concrete, 0.30 corrugated
    /// metal sheathing, 0.25 steel on metal sheathing).
    pub mu: f64,
    /// Wobble coefficient k \[rad/m\], multiplied by μ like the angles.
    pub wobble: f64,
}

/// Seed default wobble coefficient: 0.0001 per cm = 0.01 rad/m.
pub const SEED_WOBBLE: f64 = 0.01;

impl FrictionParams {
    /// μ \[-\] with the seed's wobble k = 0.01 rad/m.
    pub fn seed(mu: f64) -> Self {
        Self {
            mu,
            wobble: SEED_WOBBLE,
        }
    }
}

/// Friction factor σ_p/σ_pi = exp\[−μ (α + k s)\] \[-\] for cumulative deviation `alpha` \[rad\]
/// and distance `s` \[m\] from the jack.
pub fn friction_factor(p: &FrictionParams, alpha: f64, s: f64) -> f64 {
    (-p.mu * (alpha + p.wobble * s)).exp()
}

/// Errors of the friction-loss computations.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FrictionError {
    /// Invalid input.
    #[error("friction losses: {0}")]
    Invalid(String),
}

/// Geometry of a tendon for friction losses: arc length of each point and the absolute
/// angle change at each point.
#[derive(Debug, Clone, PartialEq)]
pub struct TendonPath {
    /// Arc length of each point from the first one \[m\] (strictly increasing, s\[0\] = 0).
    pub s: Vec<f64>,
    /// Absolute angle change |Δθ| at each point \[rad\] (0 at the two ends); on a
    /// [`distributed`](Self::distributed) path, the change over the segment that ends there.
    pub turn: Vec<f64>,
    /// The angle change `turn[i + 1]` is spread evenly over the segment from point i to
    /// i + 1 (a sampled smooth curve) instead of lumped at point i + 1 (a polyline's kink).
    pub distributed: bool,
}

impl TendonPath {
    /// Polyline (or sampled curve) through `points` \[m\], ≥ 2 points, no zero-length segment.
    pub fn from_points(points: &[[f64; 2]]) -> Result<Self, FrictionError> {
        if points.len() < 2 {
            return Err(FrictionError::Invalid("at least two points needed".into()));
        }
        let mut s = vec![0.0];
        let mut dirs = Vec::new();
        for w in points.windows(2) {
            let d = [w[1][0] - w[0][0], w[1][1] - w[0][1]];
            let l = d[0].hypot(d[1]);
            if l <= 0.0 {
                return Err(FrictionError::Invalid("zero-length segment".into()));
            }
            s.push(s.last().unwrap() + l);
            dirs.push([d[0] / l, d[1] / l]);
        }
        let mut turn = vec![0.0; points.len()];
        for i in 1..points.len() - 1 {
            let (a, b) = (dirs[i - 1], dirs[i]);
            turn[i] = (a[0] * b[1] - a[1] * b[0])
                .atan2(a[0] * b[0] + a[1] * b[1])
                .abs();
        }
        Ok(Self {
            s,
            turn,
            distributed: false,
        })
    }

    /// Path from arc lengths \[m\] and angle changes \[rad\] at each point (e.g. a curved tendon
    /// sampled analytically).
    pub fn from_arc_and_turns(s: Vec<f64>, turn: Vec<f64>) -> Result<Self, FrictionError> {
        if s.len() < 2 || turn.len() != s.len() {
            return Err(FrictionError::Invalid(
                "need ≥ 2 points and one turn angle per point".into(),
            ));
        }
        if s[0] != 0.0 || s.windows(2).any(|w| w[1] <= w[0]) {
            return Err(FrictionError::Invalid(
                "arc lengths must start at 0 and increase".into(),
            ));
        }
        if turn.iter().any(|t| t.is_nan() || *t < 0.0) {
            return Err(FrictionError::Invalid("turn angles must be ≥ 0".into()));
        }
        Ok(Self {
            s,
            turn,
            distributed: false,
        })
    }

    /// A smooth curve sampled at arc lengths `s` \[m\], `turn[i]` \[rad\] the angle change
    /// ∫|dθ| from sample i − 1 to sample i (`turn[0]` = 0): the change is spread evenly over
    /// the arc between the samples, so the friction profile is exact at the samples and
    /// between them follows the curvature (exact for a circular arc). Lumping it at the
    /// samples instead would make ∫σ ds, and with it the anchorage-set level, a staircase
    /// of the smooth one, first-order in the spacing (about σ μ Δθ Δs/2 per interval).
    pub fn sampled_curve(s: Vec<f64>, turn: Vec<f64>) -> Result<Self, FrictionError> {
        let mut path = Self::from_arc_and_turns(s, turn)?;
        if path.turn[0] != 0.0 {
            return Err(FrictionError::Invalid(
                "a sampled curve has no angle change before its first sample".into(),
            ));
        }
        path.distributed = true;
        Ok(path)
    }

    /// Total length \[m\].
    pub fn length(&self) -> f64 {
        *self.s.last().unwrap()
    }
}

/// Which end(s) the tendon is stressed from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Jacking {
    /// From the first point (s = 0).
    Start,
    /// From the last point (s = L).
    End,
    /// From both ends simultaneously to the same σ_pi.
    Both,
}

/// A tendon end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AnchorEnd {
    /// s = 0.
    Start,
    /// s = L.
    End,
}

/// One piece of a stress profile: σ(s) = c + a·exp(r (s − s0)) on \[s0, s1\] (monotone).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Piece {
    s0: f64,
    s1: f64,
    c: f64,
    a: f64,
    r: f64,
}

impl Piece {
    /// The same function restricted to \[x0, x1\] (re-based at x0).
    fn sub(&self, x0: f64, x1: f64) -> Piece {
        Piece {
            s0: x0,
            s1: x1,
            c: self.c,
            a: self.a * (self.r * (x0 - self.s0)).exp(),
            r: self.r,
        }
    }
    fn at(&self, s: f64) -> f64 {
        self.c + self.a * (self.r * (s - self.s0)).exp()
    }
    /// ∫ from x0 to x1 of σ(s) ds.
    fn integral(&self, x0: f64, x1: f64) -> f64 {
        let d = x1 - x0;
        let ex = if self.r.abs() * (self.s1 - self.s0) < 1e-8 {
            // Series of (e^{r(x1−s0)} − e^{r(x0−s0)})/r, accurate for tiny r.
            let e0 = (self.r * (x0 - self.s0)).exp();
            e0 * d * (1.0 + 0.5 * self.r * d + self.r * self.r * d * d / 6.0)
        } else {
            ((self.r * (x1 - self.s0)).exp() - (self.r * (x0 - self.s0)).exp()) / self.r
        };
        self.c * d + self.a * ex
    }
    /// ∫ max(σ − σ_ref, 0) over the piece, and the split point where σ = σ_ref (if inside).
    fn excess(&self, sref: f64) -> f64 {
        let (v0, v1) = (self.at(self.s0), self.at(self.s1));
        if v0 <= sref && v1 <= sref {
            return 0.0;
        }
        if v0 >= sref && v1 >= sref {
            return self.integral(self.s0, self.s1) - sref * (self.s1 - self.s0);
        }
        let x = self.crossing(sref);
        if v0 > sref {
            self.integral(self.s0, x) - sref * (x - self.s0)
        } else {
            self.integral(x, self.s1) - sref * (self.s1 - x)
        }
    }
    /// s where σ(s) = v (assumes a crossing inside the piece).
    fn crossing(&self, v: f64) -> f64 {
        let x = self.s0 + ((v - self.c) / self.a).ln() / self.r;
        x.clamp(self.s0, self.s1)
    }
}

/// Stress along a tendon after stressing \[Pa\], exact piecewise representation.
#[derive(Debug, Clone, PartialEq)]
pub struct StressProfile {
    pieces: Vec<Piece>,
    points: Vec<f64>,
}

/// Result of an anchorage-set computation.
#[derive(Debug, Clone, PartialEq)]
pub struct AnchorageSet {
    /// Stress profile after the set \[Pa\].
    pub profile: StressProfile,
    /// Length affected by the set, measured from the anchored end \[m\].
    pub set_length: f64,
    /// Stress at the anchored end after the set \[Pa\].
    pub anchor_stress: f64,
    /// Mirror level σ_ref \[Pa\]: σ_after = min(σ, 2σ_ref − σ) in the affected zone.
    pub reference_stress: f64,
}

/// Stress profile after stressing to `sigma_pi` \[Pa\] from the given end(s).
pub fn jacking_profile(
    path: &TendonPath,
    sigma_pi: f64,
    p: &FrictionParams,
    jacking: Jacking,
) -> StressProfile {
    let n = path.s.len();
    // Decay rate [1/m] on segment i: wobble, plus the spread turn of a sampled curve.
    let rate_of = |i: usize| {
        let spread = if path.distributed {
            path.turn[i + 1] / (path.s[i + 1] - path.s[i])
        } else {
            0.0
        };
        p.mu * (p.wobble + spread)
    };
    // Cumulative angle from the start including the turn at each point (value after it).
    let mut a_start = vec![0.0; n];
    for i in 1..n {
        a_start[i] = a_start[i - 1] + path.turn[i];
    }
    let total_turn = a_start[n - 1];
    let len = path.length();
    let mut pieces = Vec::new();
    for (i, w) in path.s.windows(2).enumerate() {
        let (s0, s1) = (w[0], w[1]);
        let rate = rate_of(i);
        // From the start: value just after point i, decaying (a spread turn at i + 1 is
        // passed on the way to it, a lumped one at it).
        let fs = Piece {
            s0,
            s1,
            c: 0.0,
            a: sigma_pi * friction_factor(p, a_start[i], s0),
            r: -rate,
        };
        // From the end, growing: the angles passed when arriving just before point i+1
        // from the end (s < s1) are the turns at points i+1 … n−2 if lumped; a spread turn
        // i+1 is still ahead, passed over this segment.
        let alpha_end = total_turn - a_start[if path.distributed { i + 1 } else { i }];
        let fe = Piece {
            s0,
            s1,
            c: 0.0,
            a: sigma_pi * friction_factor(p, alpha_end, len - s1) * (-rate * (s1 - s0)).exp(),
            r: rate,
        };
        match jacking {
            Jacking::Start => pieces.push(fs),
            Jacking::End => pieces.push(fe),
            Jacking::Both => {
                // fs − fe is decreasing: at most one crossing.
                let (d0, d1) = (fs.at(s0) - fe.at(s0), fs.at(s1) - fe.at(s1));
                if d1 >= 0.0 {
                    pieces.push(fs);
                } else if d0 <= 0.0 {
                    pieces.push(fe);
                } else {
                    // a_s e^{−r x} = a_e e^{r x}, x = s − s0.
                    let x = s0 + (fs.a / fe.a).ln() / (2.0 * rate);
                    pieces.push(Piece { s1: x, ..fs });
                    pieces.push(Piece {
                        s0: x,
                        a: fe.a * (rate * (x - s0)).exp(),
                        ..fe
                    });
                }
            }
        }
    }
    StressProfile {
        pieces,
        points: path.s.clone(),
    }
}

impl StressProfile {
    /// Stress at arc length `s` \[m\]; at a vertex with a jump the lower value (after the
    /// deviation, seen from the jack) is returned.
    pub fn at(&self, s: f64) -> f64 {
        self.pieces
            .iter()
            .filter(|q| s >= q.s0 - 1e-12 && s <= q.s1 + 1e-12)
            .map(|q| q.at(s.clamp(q.s0, q.s1)))
            .fold(f64::INFINITY, f64::min)
    }

    /// Stress at each path point \[m\] (lower value at jumps).
    pub fn at_points(&self) -> Vec<f64> {
        self.points.iter().map(|&s| self.at(s)).collect()
    }

    /// Mean stress over each segment (path point i to i+1) \[Pa\], e.g. initial span stresses
    /// of an [`crate::elements::tendon::ExternalTendon`] with the same points.
    pub fn segment_means(&self) -> Vec<f64> {
        self.points
            .windows(2)
            .map(|w| self.mean(w[0], w[1]))
            .collect()
    }

    /// Mean stress over \[x0, x1\] \[Pa\].
    pub fn mean(&self, x0: f64, x1: f64) -> f64 {
        let tot: f64 = self
            .pieces
            .iter()
            .filter_map(|q| {
                let (a, b) = (q.s0.max(x0), q.s1.min(x1));
                (b > a).then(|| q.integral(a, b))
            })
            .sum();
        tot / (x1 - x0)
    }

    /// Tendon length \[m\].
    pub fn length(&self) -> f64 {
        *self.points.last().unwrap()
    }

    /// Location \[m\] of the minimum of the profile (far end for one-end jacking).
    fn argmin(&self) -> f64 {
        let mut best = (f64::INFINITY, 0.0);
        for q in &self.pieces {
            for s in [q.s0, q.s1] {
                let v = q.at(s);
                if v < best.0 {
                    best = (v, s);
                }
            }
        }
        best.1
    }

    /// Anchorage set (wedge draw-in) `draw_in` \[m\] at `end`, tendon modulus `e_p` \[Pa\], by
    /// the standard area method: with reverse friction equal to forward friction the stress
    /// after the set is the mirror image σ_after = 2σ_ref − σ in the set zone, and σ_ref is
    /// found from  `2 ∫ max(σ − σ_ref, 0) ds = E_p · δ`  (the shortening of the tendon equals
    /// the draw-in). The zone is limited to the part between `end` and the profile minimum;
    /// if it covers all of it (short tendon), the whole part is lowered (σ_ref below the
    /// minimum). Errors if the set would make a stress negative.
    pub fn with_anchorage_set(
        &self,
        end: AnchorEnd,
        draw_in: f64,
        e_p: f64,
    ) -> Result<AnchorageSet, FrictionError> {
        if !(draw_in >= 0.0 && e_p > 0.0) {
            return Err(FrictionError::Invalid(
                "draw-in must be ≥ 0 and E_p > 0".into(),
            ));
        }
        let len = self.length();
        let smin = self.argmin();
        let (lo, hi) = match end {
            AnchorEnd::Start => (0.0, if smin > 0.0 { smin } else { len }),
            AnchorEnd::End => (if smin < len { smin } else { 0.0 }, len),
        };
        // Pieces of the domain (split at lo/hi).
        let dom: Vec<Piece> = self
            .pieces
            .iter()
            .filter_map(|q| {
                let (a, b) = (q.s0.max(lo), q.s1.min(hi));
                (b > a).then(|| q.sub(a, b))
            })
            .collect();
        let target = e_p * draw_in;
        let area = |sref: f64| 2.0 * dom.iter().map(|q| q.excess(sref)).sum::<f64>();
        let vals: Vec<f64> = dom.iter().flat_map(|q| [q.at(q.s0), q.at(q.s1)]).collect();
        let vmax = vals.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let vmin = vals.iter().cloned().fold(f64::INFINITY, f64::min);
        let (mut a, mut b) = (vmin - target / (2.0 * (hi - lo)) - 1.0, vmax);
        for _ in 0..300 {
            let m = 0.5 * (a + b);
            if area(m) > target {
                a = m;
            } else {
                b = m;
            }
            if b - a <= 1e-15 * vmax.abs() {
                break;
            }
        }
        let sref = 0.5 * (a + b);
        // New pieces: split the domain pieces at σ = σ_ref, mirror the parts above it.
        let mut pieces = Vec::new();
        let mut set_length: f64 = 0.0;
        for q in &self.pieces {
            if q.s1 <= lo || q.s0 >= hi {
                pieces.push(*q);
                continue;
            }
            // Parts outside the domain stay.
            if q.s0 < lo {
                pieces.push(q.sub(q.s0, lo));
            }
            let d = q.sub(q.s0.max(lo), q.s1.min(hi));
            let (v0, v1) = (d.at(d.s0), d.at(d.s1));
            let mirror = |p: Piece| Piece {
                c: 2.0 * sref - p.c,
                a: -p.a,
                ..p
            };
            let mut mark = |p: &Piece| {
                set_length = set_length.max(match end {
                    AnchorEnd::Start => p.s1 - lo,
                    AnchorEnd::End => hi - p.s0,
                });
            };
            if v0 >= sref && v1 >= sref {
                mark(&d);
                pieces.push(mirror(d));
            } else if v0 <= sref && v1 <= sref {
                pieces.push(d);
            } else {
                let x = d.crossing(sref);
                let (p1, p2) = (d.sub(d.s0, x), d.sub(x, d.s1));
                if v0 > sref {
                    mark(&p1);
                    pieces.push(mirror(p1));
                    pieces.push(p2);
                } else {
                    mark(&p2);
                    pieces.push(p1);
                    pieces.push(mirror(p2));
                }
            }
            if q.s1 > hi {
                pieces.push(q.sub(hi, q.s1));
            }
        }
        let profile = StressProfile {
            pieces,
            points: self.points.clone(),
        };
        if profile
            .pieces
            .iter()
            .any(|q| q.at(q.s0) < 0.0 || q.at(q.s1) < 0.0)
        {
            return Err(FrictionError::Invalid(
                "anchorage set larger than the tendon's elastic elongation".into(),
            ));
        }
        let anchor_stress = profile.at(match end {
            AnchorEnd::Start => 0.0,
            AnchorEnd::End => len,
        });
        Ok(AnchorageSet {
            profile,
            set_length,
            anchor_stress,
            reference_stress: sref,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mutants missed by the friction tests (docs/validation.md, "Mutation testing"): a path
    /// that does not start at s = 0, or whose arc lengths do not increase, is refused each
    /// on its own (not only when both are wrong).
    #[test]
    fn arc_path_needs_a_start_at_zero_and_increasing_lengths() {
        let turns = vec![0.0, 0.1];
        assert!(TendonPath::from_arc_and_turns(vec![1.0, 2.0], turns.clone()).is_err());
        assert!(TendonPath::from_arc_and_turns(vec![0.0, 0.0], turns.clone()).is_err());
        assert!(TendonPath::from_arc_and_turns(vec![0.0, 2.0], turns).is_ok());
    }

    /// A piece's integral and its excess over a level, against closed forms: σ = e^s on
    /// [0, 1] above 2 from s = ln 2: ∫ (e^s − 2) = e − 4 + 2 ln 2; σ = e^(−s) above 0.5 up to
    /// s = ln 2: ∫ (e^(−s) − 0.5) = 0.5 − 0.5 ln 2; a nearly flat exponential (r = 1e-9, the
    /// series branch): ∫_0^1 e^(r s) ds = expm1(r)/r. Tolerances 1e-12 and 1e-15 (round-off;
    /// the series' truncation is r³/24 ≈ 4e-29).
    #[test]
    fn piece_integral_and_excess_follow_closed_forms() {
        let rising = Piece {
            s0: 0.0,
            s1: 1.0,
            c: 0.0,
            a: 1.0,
            r: 1.0,
        };
        let want = std::f64::consts::E - 4.0 + 2.0 * 2f64.ln();
        assert!(
            (rising.excess(2.0) - want).abs() < 1e-12,
            "{}",
            rising.excess(2.0)
        );
        let falling = Piece { r: -1.0, ..rising };
        let want = 0.5 - 0.5 * 2f64.ln();
        assert!((falling.excess(0.5) - want).abs() < 1e-12);
        let flat = Piece { r: 1e-9, ..rising };
        let want = 1e-9f64.exp_m1() / 1e-9;
        assert!(
            (flat.integral(0.0, 1.0) - want).abs() < 1e-15,
            "{}",
            flat.integral(0.0, 1.0)
        );
    }

    /// Check 19 (docs/theory-joints-tendons.md §4): μ = 0.2, Δα = 0.1 rad, s = 1000 cm → 0.960789;
    /// μ = 0.05, Δα = 0.2 rad, s = 2500 cm → 0.977751. The table gives 6 digits, so the
    /// tolerance is 1e-6 rel (§9 #19).
    #[test]
    fn check_19_friction_factors() {
        let f1 = friction_factor(&FrictionParams::seed(0.2), 0.1, 10.0);
        let f2 = friction_factor(&FrictionParams::seed(0.05), 0.2, 25.0);
        assert!((f1 / 0.960789 - 1.0).abs() < 1e-6, "{f1}");
        assert!((f2 / 0.977751 - 1.0).abs() < 1e-6, "{f2}");
    }

    /// The same values through a polyline profile: a kink of 0.1 rad at 4 m and the point at
    /// 10 m from the jack (arc length); jacking from the other end mirrors it; both ends:
    /// symmetric with the minimum in the middle. Tolerance 1e-6 rel (check 19) for the table
    /// values, 1e-12 for exact identities.
    #[test]
    fn polyline_profiles() {
        let (d, th) = (4.0, 0.1f64);
        let pts = vec![[0.0, 0.0], [d, 0.0], [d + 6.0 * th.cos(), -6.0 * th.sin()]];
        let path = TendonPath::from_points(&pts).unwrap();
        assert!((path.length() - 10.0).abs() < 1e-12);
        assert!((path.turn[1] - th).abs() < 1e-12);
        let p = FrictionParams::seed(0.2);
        let sp = 1400e6;
        let prof = jacking_profile(&path, sp, &p, Jacking::Start);
        let v = prof.at_points();
        assert!((v[0] - sp).abs() < 1e-12 * sp);
        assert!((v[2] / sp / 0.960789 - 1.0).abs() < 1e-6);
        // Just before the kink: wobble only; at the kink: the lower (after) value.
        assert!((prof.at(d - 1e-9) / sp - (-0.2f64 * 0.01 * (d - 1e-9)).exp()).abs() < 1e-12);
        assert!((prof.at(d) / sp - (-0.2f64 * (0.1 + 0.01 * d)).exp()).abs() < 1e-12);
        let pe = jacking_profile(&path, sp, &p, Jacking::End);
        assert!((pe.at(10.0) - sp).abs() < 1e-12 * sp);
        assert!((pe.at(0.0) / sp / 0.960789 - 1.0).abs() < 1e-6);
        let pb = jacking_profile(&path, sp, &p, Jacking::Both);
        // (At the kink itself "the lower value" of a max of two profiles is convention.)
        for s in [0.0, 1.0, 3.9, 3.999, 4.001, 4.1, 7.0, 10.0] {
            let e = prof.at(s).max(pe.at(s));
            assert!((pb.at(s) - e).abs() < 1e-9 * sp, "s = {s}");
        }
        // Segment means: exact mean of an exponential over the first segment.
        let m = prof.segment_means()[0];
        let r = 0.2 * 0.01;
        assert!((m - sp * (1.0 - (-r * d).exp()) / (r * d)).abs() < 1e-12 * sp);
    }

    /// Anchorage set on a frictionless short tendon: uniform loss E_p δ/L (hand computation:
    /// the whole tendon shortens by δ). Tolerance 1e-10 rel (bisection to 1e-15).
    #[test]
    fn anchorage_set_short_frictionless() {
        let path = TendonPath::from_points(&[[0.0, 0.0], [12.0, 0.0]]).unwrap();
        let p = FrictionParams {
            mu: 0.0,
            wobble: 0.0,
        };
        let prof = jacking_profile(&path, 1300e6, &p, Jacking::Start);
        let r = prof
            .with_anchorage_set(AnchorEnd::Start, 6e-3, 195e9)
            .unwrap();
        let expect = 1300e6 - 195e9 * 6e-3 / 12.0;
        for s in [0.0, 5.0, 12.0] {
            assert!((r.profile.at(s) - expect).abs() < 1e-10 * 1300e6);
        }
        assert!((r.set_length - 12.0).abs() < 1e-12);
    }

    /// Anchorage set on a straight tendon with wobble friction, σ = σ0 e^{−βs}: the set length
    /// x solves 2σ0\[(1 − e^{−βx})/β − x e^{−βx}\] = E_p δ (solved here by an independent Newton
    /// iteration) and σ(0) = 2σ0 e^{−βx} − σ0 (tolerance 1e-9 rel). The textbook linear
    /// approximation x ≈ √(E_p δ/(σ0 β)) = 20.48 m, loss ≈ 2σ0βx = 114.3 MPa for
    /// σ0 = 1395 MPa, μ = 0.2, k = 0.01/m, δ = 6 mm, E_p = 195 GPa agrees within 2 % (the
    /// neglected curvature of the exponential is of order βx ≈ 4 %, half of it on x).
    #[test]
    fn anchorage_set_exponential_hand_check() {
        let (s0, e, dlt) = (1395e6, 195e9, 6e-3);
        let p = FrictionParams::seed(0.2);
        let beta = p.mu * p.wobble;
        let path = TendonPath::from_points(&[[0.0, 0.0], [30.0, 0.0], [60.0, 0.0]]).unwrap();
        let prof = jacking_profile(&path, s0, &p, Jacking::Start);
        let r = prof.with_anchorage_set(AnchorEnd::Start, dlt, e).unwrap();
        let g = |x: f64| {
            2.0 * s0 * ((1.0 - (-beta * x).exp()) / beta - x * (-beta * x).exp()) - e * dlt
        };
        let dg = |x: f64| 2.0 * s0 * beta * x * (-beta * x).exp();
        let mut x = (e * dlt / (s0 * beta)).sqrt();
        for _ in 0..50 {
            x -= g(x) / dg(x);
        }
        assert!((r.set_length - x).abs() < 1e-9 * x);
        let a0 = 2.0 * s0 * (-beta * x).exp() - s0;
        assert!((r.anchor_stress - a0).abs() < 1e-9 * s0);
        let xl = (e * dlt / (s0 * beta)).sqrt();
        assert!((r.set_length / xl - 1.0).abs() < 0.02);
        assert!(((s0 - r.anchor_stress) / (2.0 * s0 * beta * xl) - 1.0).abs() < 0.02);
        // Beyond the set zone nothing changes; continuity at x.
        assert!((r.profile.at(45.0) - prof.at(45.0)).abs() < 1e-12 * s0);
        assert!((r.profile.at(x) - prof.at(x)).abs() < 1e-6 * s0);
        // The area method identity: the stress lost integrates to E_p δ.
        let lost = (prof.mean(0.0, 60.0) - r.profile.mean(0.0, 60.0)) * 60.0;
        assert!((lost - e * dlt).abs() < 1e-9 * e * dlt);
    }

    /// A circular arc of radius R sampled at n points as a [`TendonPath::sampled_curve`]:
    /// the friction profile is σ0 e^{−μ(k + 1/R)s} everywhere, not only at the samples, so
    /// the set length and anchor stress equal the straight tendon's closed form with wobble
    /// k + 1/R (the Newton solution of `anchorage_set_exponential_hand_check`), whatever n.
    /// Tolerance 1e-9 rel (bisection to 1e-15, the exponential's round-off).
    #[test]
    fn sampled_arc_is_exact_between_samples() {
        let (s0, e, dlt, r) = (1395e6, 195e9, 6e-3, 40.0);
        let p = FrictionParams::seed(0.2);
        let beta = p.mu * (p.wobble + 1.0 / r);
        let len = 30.0;
        let g = |x: f64| {
            2.0 * s0 * ((1.0 - (-beta * x).exp()) / beta - x * (-beta * x).exp()) - e * dlt
        };
        let dg = |x: f64| 2.0 * s0 * beta * x * (-beta * x).exp();
        let mut x = (e * dlt / (s0 * beta)).sqrt();
        for _ in 0..50 {
            x -= g(x) / dg(x);
        }
        assert!(x < len, "the set zone must end inside the tendon");
        for n in [3, 7, 40] {
            let s: Vec<f64> = (0..=n).map(|i| len * i as f64 / n as f64).collect();
            let turn: Vec<f64> = (0..=n)
                .map(|i| if i == 0 { 0.0 } else { len / n as f64 / r })
                .collect();
            let path = TendonPath::sampled_curve(s, turn).unwrap();
            let set = jacking_profile(&path, s0, &p, Jacking::Start)
                .with_anchorage_set(AnchorEnd::Start, dlt, e)
                .unwrap();
            assert!((set.set_length - x).abs() < 1e-9 * x, "n = {n}");
            let a0 = 2.0 * s0 * (-beta * x).exp() - s0;
            assert!((set.anchor_stress - a0).abs() < 1e-9 * s0, "n = {n}");
            for q in [0.3, 11.1, 29.0] {
                let v = set.profile.at(q);
                let exact = if q < x {
                    2.0 * s0 * (-beta * x).exp() - s0 * (-beta * q).exp()
                } else {
                    s0 * (-beta * q).exp()
                };
                assert!((v - exact).abs() < 1e-9 * s0, "n = {n}, s = {q}");
            }
        }
    }

    /// A parabola y = c(x − L/2)² (L = 12 m, sag 0.25 m) jacked at its start with a set
    /// long enough to lower the whole tendon: σ_ref = (∫σ ds − E_p δ/2)/L_s in closed form
    /// (Simpson's rule on the exact σ(x) = σ0 exp[−μ(α(x) + k s(x))], 20,000 intervals,
    /// error ~1e-14). Sampled at n + 1 points with exact s and α, the spread turns converge
    /// at second order (the error falls ≥ 3.5× per halving of the spacing, the exponent-2
    /// rate being 4) and are within 1e-7 σ0 at n = 16 already; the turns lumped at the
    /// samples converge at first order only and are ≥ 100× further off at n = 64.
    #[test]
    fn sampled_parabola_set_level_converges_at_second_order() {
        let (l, sag, s0, e, dlt) = (12.0, 0.25, 1400e6, 195e9, 8e-3);
        let p = FrictionParams::seed(0.2);
        let c = 4.0 * sag / (l * l);
        let slope = |x: f64| 2.0 * c * (x - 0.5 * l);
        let f = |u: f64| (u * u.hypot(1.0) + u.asinh()) / (4.0 * c);
        let s_of = |x: f64| f(slope(x)) - f(slope(0.0));
        let a_of = |x: f64| slope(x).atan() - slope(0.0).atan();
        let sigma = |x: f64| s0 * friction_factor(&p, a_of(x), s_of(x));
        let m = 20_000;
        let h = l / m as f64;
        let gx = |x: f64| sigma(x) * slope(x).hypot(1.0);
        let mut acc = gx(0.0) + gx(l);
        for i in 1..m {
            acc += gx(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        let ls = s_of(l);
        let exact = (acc * h / 3.0 - 0.5 * e * dlt) / ls;
        assert!(exact < sigma(l), "the set must lower the whole tendon");
        let level = |n: usize, spread: bool| {
            let xs: Vec<f64> = (0..=n).map(|i| l * i as f64 / n as f64).collect();
            let s: Vec<f64> = xs.iter().map(|&x| s_of(x)).collect();
            let turn: Vec<f64> = (0..=n)
                .map(|i| {
                    if i == 0 {
                        0.0
                    } else {
                        a_of(xs[i]) - a_of(xs[i - 1])
                    }
                })
                .collect();
            let path = if spread {
                TendonPath::sampled_curve(s, turn).unwrap()
            } else {
                // Lumped at the far sample of each interval (exact at the samples too).
                TendonPath::from_arc_and_turns(s, turn).unwrap()
            };
            let set = jacking_profile(&path, s0, &p, Jacking::Start)
                .with_anchorage_set(AnchorEnd::Start, dlt, e)
                .unwrap();
            (set.reference_stress - exact).abs()
        };
        let errs: Vec<f64> = [4, 8, 16, 32].iter().map(|&n| level(n, true)).collect();
        for w in errs.windows(2) {
            assert!(w[1] < w[0] / 3.5, "not second order: {errs:?}");
        }
        assert!(errs[2] < 1e-7 * s0, "{errs:?}");
        let lumped = level(64, false);
        eprintln!("σ_ref error, spread n = 4…32: {errs:?} Pa; lumped n = 64: {lumped} Pa");
        assert!(lumped > 100.0 * errs[3], "lumped {lumped}, spread {errs:?}");
    }

    /// Anchorage set at the far end mirrors the start case (symmetric tendon jacked from the
    /// end). Tolerance 1e-9 rel.
    #[test]
    fn anchorage_set_at_end_mirrors_start() {
        let path = TendonPath::from_points(&[[0.0, 0.0], [10.0, 1.0], [20.0, 0.0]]).unwrap();
        let p = FrictionParams::seed(0.25);
        let a = jacking_profile(&path, 1300e6, &p, Jacking::Start)
            .with_anchorage_set(AnchorEnd::Start, 5e-3, 195e9)
            .unwrap();
        let b = jacking_profile(&path, 1300e6, &p, Jacking::End)
            .with_anchorage_set(AnchorEnd::End, 5e-3, 195e9)
            .unwrap();
        assert!((a.set_length - b.set_length).abs() < 1e-9 * a.set_length);
        let l = path.length();
        for s in [0.0, 3.0, 9.9, 10.0, 15.0, l] {
            assert!((a.profile.at(s) - b.profile.at(l - s)).abs() < 1e-9 * 1300e6);
        }
    }
}
