//! Thermal actions as imposed (stress-free) strains: the temperature change ΔT(y) [K] of a
//! load case over the height of the section and the thermal expansion coefficients α [1/K]
//! of what it heats (docs/theory.md, "Thermal actions"). At factor λ a continuum point at
//! height y takes ε_th = λ α ΔT(y) (1, 1, 0), an embedded bar point λ α_s ΔT(y) along the
//! bar and an external tendon span λ α_p ΔT over its length; each is subtracted from the
//! total strain before the material law (as shrinkage is, docs/theory-time.md).

use serde::Serialize;

/// The temperature field of a thermal load case and the expansion coefficients of what it
/// heats. ΔT(y) = uniform + linear·(y − y_mid)/(top − bottom) + profile(top − y): the
/// uniform component ΔT_N, the linear difference ΔT_M (top fibre minus bottom fibre) and a
/// piecewise linear profile by depth below the top fibre (EN 1991-1-5 6.1.4.2, AASHTO LRFD
/// 3.12.3), zero outside its points.
#[derive(Debug, Clone, Serialize, Default, PartialEq)]
pub struct ThermalAction {
    /// Uniform temperature change ΔT_N [K].
    pub uniform: f64,
    /// Linear temperature difference ΔT_M = T(top) − T(bottom) [K], zero at mid-depth.
    pub linear: f64,
    /// Height of the top fibre of the section [m].
    pub top: f64,
    /// Height of the bottom fibre of the section [m] (< `top`).
    pub bottom: f64,
    /// Piecewise linear profile: (depth below the top fibre [m], ΔT [K]), depths
    /// increasing; zero above the first and below the last point (empty: none).
    pub profile: Vec<[f64; 2]>,
    /// Expansion coefficient α [1/K] of each region's material (index = region).
    pub region_alpha: Vec<f64>,
    /// Expansion coefficient α_s [1/K] of each embedded bar or bonded tendon (index = bar).
    pub bar_alpha: Vec<f64>,
    /// Expansion coefficient α_p [1/K] of each external tendon (index = tendon).
    pub tendon_alpha: Vec<f64>,
    /// Temperature change of the external tendons [K]; None: the field ΔT(y) averaged along
    /// each span.
    pub tendon_temperature: Option<f64>,
}

impl ThermalAction {
    /// Temperature change ΔT [K] at height `y` [m].
    pub fn temperature(&self, y: f64) -> f64 {
        let h = self.top - self.bottom;
        let mid = 0.5 * (self.top + self.bottom);
        let lin = if h > 0.0 {
            self.linear * (y - mid) / h
        } else {
            0.0
        };
        self.uniform + lin + profile_at(&self.profile, self.top - y)
    }

    /// Mean temperature change [K] along the straight span from `a` to `b` [m] (external
    /// tendons), by the trapezoidal rule on 64 pieces (the profile is piecewise linear in y:
    /// its kinks cost at most a few per mille of a kink's jump).
    pub fn span_temperature(&self, a: [f64; 2], b: [f64; 2]) -> f64 {
        if let Some(t) = self.tendon_temperature {
            return t;
        }
        const N: usize = 64;
        let mut s = 0.0;
        for i in 0..=N {
            let w = if i == 0 || i == N { 0.5 } else { 1.0 };
            let y = a[1] + (b[1] - a[1]) * i as f64 / N as f64;
            s += w * self.temperature(y);
        }
        s / N as f64
    }
}

/// Value at depth `d` [m] of a piecewise linear profile of (depth, value) points; zero
/// outside it.
pub fn profile_at(profile: &[[f64; 2]], d: f64) -> f64 {
    let (Some(first), Some(last)) = (profile.first(), profile.last()) else {
        return 0.0;
    };
    if d < first[0] || d > last[0] {
        return 0.0;
    }
    for w in profile.windows(2) {
        let ([d0, t0], [d1, t1]) = (w[0], w[1]);
        if d <= d1 {
            return if d1 > d0 {
                t0 + (t1 - t0) * (d - d0) / (d1 - d0)
            } else {
                t1
            };
        }
    }
    last[1]
}

/// The EN 1991-1-5 Figure 6.2c profiles (Type 3, concrete decks; values for 100 mm of
/// surfacing), heating (`heating = true`) or cooling, of a section of depth `h` [m], as
/// (depth below the top, ΔT [K]) points. The code's table values are interpolated linearly
/// in h between its rows (h ≤ 0.2 m, 0.4, 0.6, 0.8 and, cooling, 1.0 and ≥ 1.5 m).
pub fn en1991_profile(h: f64, heating: bool) -> Vec<[f64; 2]> {
    let interp = |rows: &[(f64, [f64; 4])]| -> [f64; 4] {
        if h <= rows[0].0 {
            return rows[0].1;
        }
        for w in rows.windows(2) {
            let ((h0, a), (h1, b)) = (w[0], w[1]);
            if h <= h1 {
                let s = (h - h0) / (h1 - h0);
                return std::array::from_fn(|i| a[i] + s * (b[i] - a[i]));
            }
        }
        rows[rows.len() - 1].1
    };
    if heating {
        // h1 = 0.3h ≤ 0.15 m, h2 = 0.3h within [0.10, 0.25] m, h3 = 0.3h ≤ 0.10 m + 0.1 m
        // of surfacing; T1 at the top, T2 at h1, 0 at h1 + h2; T3 at the bottom, 0 at h3
        // above it.
        let [t1, t2, t3, _] = interp(&[
            (0.2, [8.5, 3.5, 0.5, 0.0]),
            (0.4, [12.0, 3.0, 1.5, 0.0]),
            (0.6, [13.0, 3.0, 2.0, 0.0]),
            (0.8, [13.0, 3.0, 2.5, 0.0]),
        ]);
        let h1 = (0.3 * h).min(0.15);
        let h2 = (0.3 * h).clamp(0.10, 0.25).min(h - h1);
        let h3 = (0.3 * h).min(0.20).min(h - h1 - h2);
        let mut p = vec![[0.0, t1], [h1, t2], [h1 + h2, 0.0]];
        if h3 > 0.0 {
            p.push([h - h3, 0.0]);
            p.push([h, t3]);
        }
        p
    } else {
        // h1 = h4 = 0.20h ≤ 0.25 m, h2 = h3 = 0.25h ≤ 0.20 m; T1 at the top, T2 at h1, 0 at
        // h1 + h2; 0 at h3 + h4 above the bottom, T3 at h4 above it, T4 at the bottom.
        let [t1, t2, t3, t4] = interp(&[
            (0.2, [-2.0, -0.5, -0.5, -1.5]),
            (0.4, [-4.5, -1.4, -1.0, -3.5]),
            (0.6, [-6.5, -1.8, -1.5, -5.0]),
            (0.8, [-7.6, -1.7, -1.5, -6.0]),
            (1.0, [-8.0, -1.5, -1.5, -6.3]),
            (1.5, [-8.4, -0.5, -1.0, -6.5]),
        ]);
        let h1 = (0.2 * h).min(0.25);
        let h2 = (0.25 * h).min(0.20);
        vec![
            [0.0, t1],
            [h1, t2],
            [h1 + h2, 0.0],
            [h - h1 - h2, 0.0],
            [h - h1, t3],
            [h, t4],
        ]
    }
}

/// The AASHTO LRFD 3.12.3 positive vertical gradient of a concrete superstructure of depth
/// `h` [m] in solar radiation zone `zone` (1–4, Table 3.12.3-1), as (depth below the top,
/// ΔT [K]) points: T1 at the top, T2 at 0.10 m, 0 at A = 0.30 m (h − 0.10 m for h < 0.40 m),
/// T3 = 0 at the bottom. The negative gradient is this times −0.30 (plain deck) or −0.20
/// (with asphalt overlay), the `factor` given. None for a zone outside 1–4.
pub fn aashto_profile(h: f64, zone: u8, factor: f64) -> Option<Vec<[f64; 2]>> {
    let (t1, t2) = match zone {
        1 => (30.0, 7.8),
        2 => (25.0, 6.7),
        3 => (23.0, 6.0),
        4 => (21.0, 5.0),
        _ => return None,
    };
    let a = if h >= 0.40 { 0.30 } else { h - 0.10 };
    Some(vec![
        [0.0, factor * t1],
        [0.10, factor * t2],
        [a.max(0.10), 0.0],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// EN 1991-1-5 Figure 6.2c (concrete decks, 100 mm surfacing) at depths between its
    /// rows, interpolated by hand from the code's table (heating h ≤ 0.2: T1, T2, T3 = 8.5,
    /// 3.5, 0.5; 0.4: 12.0, 3.0, 1.5; cooling h ≤ 0.2: −2.0, −0.5, −0.5, −1.5; 0.4: −4.5, −1.4, −1.0, −3.5; 0.6: −6.5, −1.8,
    /// −1.5, −5.0; 0.8: −7.6, −1.7, −1.5, −6.0; 1.0: −8.0, −1.5, −1.5, −6.3; ≥ 1.5: −8.4,
    /// −0.5, −1.0, −6.5) with the figure's depths h1, h2, h3 (h = 0.2: h3 limited by
    /// h − h1 − h2). Exact arithmetic: 1e-12.
    #[test]
    fn en1991_profiles_between_table_rows() {
        let cases: [(f64, bool, Vec<[f64; 2]>); 7] = [
            (
                0.2,
                false,
                vec![
                    [0.0, -2.0],
                    [0.04, -0.5],
                    [0.09, 0.0],
                    [0.11, 0.0],
                    [0.16, -0.5],
                    [0.2, -1.5],
                ],
            ),
            (
                0.2,
                true,
                vec![
                    [0.0, 8.5],
                    [0.06, 3.5],
                    [0.16, 0.0],
                    [0.16, 0.0],
                    [0.2, 0.5],
                ],
            ),
            (
                0.3,
                true,
                vec![
                    [0.0, 10.25],
                    [0.09, 3.25],
                    [0.19, 0.0],
                    [0.21, 0.0],
                    [0.3, 1.0],
                ],
            ),
            (
                0.5,
                false,
                vec![
                    [0.0, -5.5],
                    [0.1, -1.6],
                    [0.225, 0.0],
                    [0.275, 0.0],
                    [0.4, -1.25],
                    [0.5, -4.25],
                ],
            ),
            (
                0.9,
                false,
                vec![
                    [0.0, -7.8],
                    [0.18, -1.6],
                    [0.38, 0.0],
                    [0.52, 0.0],
                    [0.72, -1.5],
                    [0.9, -6.15],
                ],
            ),
            (
                1.25,
                false,
                vec![
                    [0.0, -8.2],
                    [0.25, -1.0],
                    [0.45, 0.0],
                    [0.8, 0.0],
                    [1.0, -1.25],
                    [1.25, -6.4],
                ],
            ),
            (
                2.0,
                false,
                vec![
                    [0.0, -8.4],
                    [0.25, -0.5],
                    [0.45, 0.0],
                    [1.55, 0.0],
                    [1.75, -1.0],
                    [2.0, -6.5],
                ],
            ),
        ];
        for (h, heating, expect) in cases {
            let got = en1991_profile(h, heating);
            assert_eq!(
                got.len(),
                expect.len(),
                "h = {h}, heating {heating}: {got:?}"
            );
            for (g, e) in got.iter().zip(&expect) {
                assert!(
                    (g[0] - e[0]).abs() < 1e-12 && (g[1] - e[1]).abs() < 1e-12,
                    "h = {h}, heating {heating}: {got:?}"
                );
            }
        }
    }

    /// The mean temperature along an inclined external-tendon span: the trapezoidal rule is
    /// exact for the linear field, so a span from y = 0.6 to 1.0 m in a section 0 … 1 m with
    /// ΔT_M = 10 K (ΔT = 10 (y − 0.5)) averages ΔT(0.8) = 3 K (1e-12).
    #[test]
    fn span_temperature_is_the_mean_along_an_inclined_span() {
        let t = ThermalAction {
            linear: 10.0,
            top: 1.0,
            bottom: 0.0,
            ..ThermalAction::default()
        };
        let m = t.span_temperature([0.0, 0.6], [10.0, 1.0]);
        assert!((m - 3.0).abs() < 1e-12, "{m}");
    }

    /// The profile is piecewise linear and zero outside its points.
    #[test]
    fn profile_interpolates_and_vanishes_outside() {
        let p = [[0.0, 10.0], [0.1, 4.0], [0.3, 0.0]];
        assert_eq!(profile_at(&p, 0.0), 10.0);
        assert!((profile_at(&p, 0.05) - 7.0).abs() < 1e-12);
        assert!((profile_at(&p, 0.2) - 2.0).abs() < 1e-12);
        assert_eq!(profile_at(&p, 0.4), 0.0);
        assert_eq!(profile_at(&p, -0.1), 0.0);
    }

    /// EN 1991-1-5 Fig. 6.2c heating, h = 0.6 m: T1 = 13, T2 = 3, T3 = 2 K; h1 = 0.15 m,
    /// h2 = 0.18 m, h3 = 0.18 m (the code's rules at 0.3h).
    #[test]
    fn en1991_heating_at_600_mm() {
        let p = en1991_profile(0.6, true);
        assert_eq!(p[0], [0.0, 13.0]);
        assert!((p[1][0] - 0.15).abs() < 1e-12 && (p[1][1] - 3.0).abs() < 1e-12);
        assert!((p[2][0] - 0.33).abs() < 1e-12 && p[2][1] == 0.0);
        assert!((p[3][0] - 0.42).abs() < 1e-12);
        assert!((p[4][1] - 2.0).abs() < 1e-12);
    }

    /// AASHTO zone 1: 30 °C at the top, 7.8 °C at 0.10 m, 0 at 0.30 m.
    #[test]
    fn aashto_zone_1() {
        let p = aashto_profile(1.0, 1, 1.0).unwrap();
        assert_eq!(p, vec![[0.0, 30.0], [0.10, 7.8], [0.30, 0.0]]);
        assert!(aashto_profile(1.0, 5, 1.0).is_none());
    }
}
