//! A joint as a cross-section: its resultants from the contact stresses and the stresses
//! of the equivalent uncracked section (docs/theory-design.md, "Joints").
//!
//! A dry joint carries no tension, so once it opens its contact stresses no longer say how
//! far it is from decompression. Its resultants (N, M about the centroid of the whole joint
//! section) still hold by equilibrium; the linear stress N/A + M s/I of the uncracked
//! section is what the codes' decompression check reads, and |M|/M_dec its utilisation.

/// One contact point of a joint.
#[derive(Debug, Clone, Copy)]
pub struct ContactPoint {
    /// Coordinate along the joint [m].
    pub s: f64,
    /// Area it stands for: quadrature length × thickness [m²].
    pub area: f64,
    /// Normal stress, compression positive [Pa].
    pub normal: f64,
    /// Shear stress [Pa].
    pub shear: f64,
}

/// A straight piece of the joint section: from `s0` to `s1` along the joint [m], of
/// thickness `t` [m].
#[derive(Debug, Clone, Copy)]
pub struct Piece {
    /// Start and end along the joint [m].
    pub s0: f64,
    /// End along the joint [m].
    pub s1: f64,
    /// Thickness [m].
    pub t: f64,
}

/// Section properties and resultants of a joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointSection {
    /// Gross area [m²].
    pub area: f64,
    /// Centroid along the joint [m].
    pub centroid: f64,
    /// Second moment of area about the centroid [m⁴].
    pub inertia: f64,
    /// Extreme fibres along the joint [m].
    pub s_min: f64,
    /// Extreme fibre along the joint [m].
    pub s_max: f64,
    /// Normal force, compression positive [N].
    pub n: f64,
    /// Moment of the normal stresses about the centroid, Σ σ A (s − s_c) [N·m].
    pub m: f64,
    /// Shear force [N].
    pub v: f64,
}

impl JointSection {
    /// Properties exactly from the pieces (piecewise-constant thickness), resultants by the
    /// joint's own quadrature of its contact stresses.
    pub fn new(pieces: &[Piece], points: &[ContactPoint]) -> Self {
        let area: f64 = pieces.iter().map(|p| (p.s1 - p.s0).abs() * p.t).sum();
        let centroid = pieces
            .iter()
            .map(|p| (p.s1 - p.s0).abs() * p.t * 0.5 * (p.s0 + p.s1))
            .sum::<f64>()
            / area;
        let inertia = pieces
            .iter()
            .map(|p| {
                let l = (p.s1 - p.s0).abs();
                let d = 0.5 * (p.s0 + p.s1) - centroid;
                p.t * (l.powi(3) / 12.0 + l * d * d)
            })
            .sum();
        let s_min = pieces
            .iter()
            .map(|p| p.s0.min(p.s1))
            .fold(f64::INFINITY, f64::min);
        let s_max = pieces
            .iter()
            .map(|p| p.s0.max(p.s1))
            .fold(f64::NEG_INFINITY, f64::max);
        let n = points.iter().map(|q| q.normal * q.area).sum();
        let m = points
            .iter()
            .map(|q| q.normal * q.area * (q.s - centroid))
            .sum();
        let v = points.iter().map(|q| q.shear * q.area).sum();
        JointSection {
            area,
            centroid,
            inertia,
            s_min,
            s_max,
            n,
            m,
            v,
        }
    }

    /// Mean compression N/A [Pa].
    pub fn mean(&self) -> f64 {
        self.n / self.area
    }

    /// The least fibre stress of the uncracked section, N/A + M (s − s_c)/I at the fibre
    /// on the decompressed side (compression positive) [Pa].
    pub fn least_fibre(&self) -> f64 {
        let at = |s: f64| self.mean() + self.m * (s - self.centroid) / self.inertia;
        at(self.s_min).min(at(self.s_max))
    }

    /// Utilisation of a minimum compression `p_req` [Pa] at the extreme fibre: the moment
    /// over the moment at which that fibre reaches `p_req` under the same normal force,
    /// (N/A − σ_fibre)/(N/A − p_req). Infinite when the mean compression is at or below
    /// `p_req` (no moment is allowed).
    pub fn decompression_utilisation(&self, p_req: f64) -> f64 {
        let room = self.mean() - p_req;
        if room <= 0.0 {
            return f64::INFINITY;
        }
        (self.mean() - self.least_fibre()) / room
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rectangle b × h under N at eccentricity e, by hand: the stress N/(bh) (1 ± 6e/h);
    /// u = 6e/h for p_req = 0. The contact stresses here are the linear ones sampled at
    /// two-point Gauss points of four pieces (exact for a linear field).
    #[test]
    fn rectangle_under_eccentric_force() {
        let (b, h, n, e) = (0.3, 0.8, 1.0e6, 0.1);
        let pieces: Vec<Piece> = (0..4)
            .map(|i| Piece {
                s0: i as f64 * h / 4.0,
                s1: (i + 1) as f64 * h / 4.0,
                t: b,
            })
            .collect();
        let sigma = |s: f64| n / (b * h) + n * e * (s - h / 2.0) / (b * h.powi(3) / 12.0);
        let g = 0.5 / 3f64.sqrt();
        let points: Vec<ContactPoint> = pieces
            .iter()
            .flat_map(|p| {
                let mid = 0.5 * (p.s0 + p.s1);
                let l = p.s1 - p.s0;
                [mid - g * l, mid + g * l].map(|s| ContactPoint {
                    s,
                    area: 0.5 * l * b,
                    normal: sigma(s),
                    shear: 0.0,
                })
            })
            .collect();
        let sec = JointSection::new(&pieces, &points);
        assert!((sec.area - b * h).abs() < 1e-12);
        assert!((sec.inertia - b * h.powi(3) / 12.0).abs() < 1e-12);
        assert!((sec.n - n).abs() < 1e-6 * n);
        assert!((sec.m - n * e).abs() < 1e-6 * n * e);
        let u = sec.decompression_utilisation(0.0);
        assert!((u - 6.0 * e / h).abs() < 1e-9, "u = {u}");
        // With a required compression p: u = (6 N e/(b h²)) / (N/(bh) − p).
        let p = 0.5e6;
        let hand = (6.0 * n * e / (b * h * h)) / (n / (b * h) - p);
        assert!((sec.decompression_utilisation(p) - hand).abs() < 1e-9);
    }

    /// An I section of bands (flanges 1.0 × 0.2 m, web 0.3 × 0.6 m): I by hand about the
    /// mid-depth centroid = 2 (1.0·0.2³/12 + 0.2·0.4²) + 0.3·0.6³/12 = 0.070733 m⁴.
    #[test]
    fn banded_section_properties() {
        let pieces = [
            Piece {
                s0: 0.0,
                s1: 0.2,
                t: 1.0,
            },
            Piece {
                s0: 0.2,
                s1: 0.8,
                t: 0.3,
            },
            Piece {
                s0: 0.8,
                s1: 1.0,
                t: 1.0,
            },
        ];
        let sec = JointSection::new(&pieces, &[]);
        assert!((sec.area - 0.58).abs() < 1e-12);
        assert!((sec.centroid - 0.5).abs() < 1e-12);
        let hand = 2.0 * (0.2f64.powi(3) / 12.0 + 0.2 * 0.16) + 0.3 * 0.216 / 12.0;
        assert!((sec.inertia - hand).abs() < 1e-12);
    }
}
