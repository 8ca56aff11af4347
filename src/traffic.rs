//! Traffic load models as data — EN 1991-2 Load Model 1, AASHTO LRFD HL-93 and user
//! vehicles — reduced to the plane-stress girder, and their envelopes over an influence line
//! (docs/theory-traffic.md).
//!
//! A plane-stress model carries the whole deck width in one plane, so the lanes side by side
//! add up: every lane's axle loads act at the same longitudinal position (the code places
//! the tandems of LM1 side by side, and AASHTO loads every design lane with the same
//! vehicle), and the lane loads per unit length of the lanes and the remaining area add to
//! one line load [N/m]. Units SI: N, m.

/// A vehicle: axles at offsets behind its first axle.
#[derive(Debug, Clone, PartialEq)]
pub struct Vehicle {
    /// Name in the outputs ("tandem", "truck 4.3/6.0 m", …).
    pub name: String,
    /// Axles: (offset behind the first axle [m], ≥ 0, nondecreasing; load [N], ≥ 0).
    pub axles: Vec<(f64, f64)>,
}

impl Vehicle {
    /// Sum of the axle loads [N].
    pub fn total(&self) -> f64 {
        self.axles.iter().map(|a| a.1).sum()
    }

    /// Distance from the first to the last axle [m].
    pub fn length(&self) -> f64 {
        self.axles.last().map_or(0.0, |a| a.0)
    }

    /// The same vehicle driven the other way (offsets mirrored, first axle in front again).
    fn reversed(&self) -> Vehicle {
        let l = self.length();
        let mut axles: Vec<(f64, f64)> = self.axles.iter().map(|&(d, p)| (l - d, p)).collect();
        axles.reverse();
        Vehicle {
            name: format!("{} (reversed)", self.name),
            axles,
        }
    }
}

/// A traffic model on the plane-stress girder: concentrated systems, of which the worst
/// governs, plus a line load on the parts of the influence line where it is unfavourable.
#[derive(Debug, Clone, PartialEq)]
pub struct Traffic {
    /// Name (the `[[influence.traffic]]` name).
    pub name: String,
    /// The concentrated systems (tandem, trucks): alternatives, the worst governs.
    pub vehicles: Vec<Vehicle>,
    /// Factor on the vehicles' axle loads [-]: dynamic allowance (1 + IM), lanes and
    /// multiple presence of AASHTO (LM1 has its lanes in the axle loads and 1 here).
    pub vehicle_factor: f64,
    /// Line load where unfavourable [N/m], lanes and factors included.
    pub lane_load: f64,
    /// How the model was reduced to the girder (for the summary).
    pub note: String,
}

/// EN 1991-2 Table 4.1: number of notional lanes, their width and the remaining area's
/// width [m] on a carriageway of width `w` [m].
pub fn en_lanes(w: f64) -> (usize, f64, f64) {
    if w < 5.4 {
        // One 3 m lane (the carriageway itself if narrower) and the rest.
        let lane = w.min(3.0);
        (1, lane, w - lane)
    } else if w < 6.0 {
        (2, 0.5 * w, 0.0)
    } else {
        let n = (w / 3.0).floor() as usize;
        (n, 3.0, w - 3.0 * n as f64)
    }
}

/// EN 1991-2 Table 4.2, tandem axle loads Q_ik of lanes 1, 2, 3 [N] (none on further lanes).
pub const LM1_AXLE: [f64; 3] = [300e3, 200e3, 100e3];
/// EN 1991-2 Table 4.2, UDL on lane 1 [Pa].
pub const LM1_UDL_LANE1: f64 = 9e3;
/// EN 1991-2 Table 4.2, UDL on the other lanes and the remaining area [Pa].
pub const LM1_UDL_OTHER: f64 = 2.5e3;
/// EN 1991-2 Figure 4.2a: axle spacing of the tandem [m].
pub const LM1_TANDEM_SPACING: f64 = 1.2;

/// EN 1991-2 LM1 on a carriageway of width `w` [m] with adjustment factors α_Q (tandems of
/// lanes 1–3) and α_q (UDL of lane 1, of the other lanes, of the remaining area): one
/// tandem whose two axles carry the sum of the lanes' axle loads, and the sum of the
/// lanes' UDL per unit length.
pub fn lm1(name: &str, w: f64, alpha_big_q: [f64; 3], alpha_q: [f64; 3]) -> Traffic {
    let (n, lane, rest) = en_lanes(w);
    let axle: f64 = (0..n.min(3)).map(|i| alpha_big_q[i] * LM1_AXLE[i]).sum();
    let others = n.saturating_sub(1) as f64;
    let q = alpha_q[0] * LM1_UDL_LANE1 * lane
        + alpha_q[1] * LM1_UDL_OTHER * lane * others
        + alpha_q[2] * LM1_UDL_OTHER * rest;
    Traffic {
        name: name.into(),
        vehicles: vec![Vehicle {
            name: "tandems".into(),
            axles: vec![(0.0, axle), (LM1_TANDEM_SPACING, axle)],
        }],
        vehicle_factor: 1.0,
        lane_load: q,
        note: format!(
            "EN 1991-2 LM1, w = {w} m: {n} lanes of {lane} m, remaining area {rest} m; tandems side by side: 2 axles of {:.1} kN 1.2 m apart; UDL {:.2} kN/m",
            axle / 1e3,
            q / 1e3
        ),
    }
}

/// AASHTO LRFD 3.6.1.2.2: design truck axle loads [N], front to rear.
pub const HL93_TRUCK: [f64; 3] = [35e3, 145e3, 145e3];
/// AASHTO LRFD 3.6.1.2.2: front axle spacing [m] and the range of the rear spacing [m].
pub const HL93_TRUCK_SPACING: (f64, f64, f64) = (4.3, 4.3, 9.0);
/// AASHTO LRFD 3.6.1.2.3: design tandem, axle load [N] and spacing [m].
pub const HL93_TANDEM: (f64, f64) = (110e3, 1.2);
/// AASHTO LRFD 3.6.1.2.4: design lane load [N/m].
pub const HL93_LANE: f64 = 9.3e3;
/// AASHTO LRFD Table 3.6.2.1-1: dynamic load allowance of all other components [-].
pub const HL93_IM: f64 = 0.33;
/// Step of the searched rear spacing of the design truck [m].
pub const HL93_SPACING_STEP: f64 = 0.1;

/// AASHTO LRFD 3.6.1.1.1: design lanes on a roadway of width `w` [m]: INT(w / 3.6 m), two on
/// roadways of 6.0–7.2 m, at least one.
pub fn aashto_lanes(w: f64) -> usize {
    if (6.0..=7.2).contains(&w) {
        2
    } else {
        ((w / 3.6).floor() as usize).max(1)
    }
}

/// AASHTO LRFD Table 3.6.1.1.2-1: multiple presence factor of `k` loaded lanes.
pub fn multiple_presence(k: usize) -> f64 {
    match k {
        0 | 1 => 1.2,
        2 => 1.0,
        3 => 0.85,
        _ => 0.65,
    }
}

/// AASHTO LRFD HL-93 on a roadway of width `w` [m] with dynamic allowance `im` on the
/// truck and tandem (not on the lane load): the larger of the design truck (rear spacing
/// searched over 4.3–9.0 m in 0.1 m steps) and the design tandem, × (1 + IM), plus the
/// lane load, all × k·m(k) for the number k of loaded lanes with the largest k·m(k) (every
/// lane has the same effect on the girder).
pub fn hl93(name: &str, w: f64, im: f64) -> Traffic {
    let n = aashto_lanes(w);
    let (k, km) = (1..=n)
        .map(|k| (k, k as f64 * multiple_presence(k)))
        .fold((1, 0.0), |b, c| if c.1 > b.1 { c } else { b });
    let (front, lo, hi) = HL93_TRUCK_SPACING;
    let steps = ((hi - lo) / HL93_SPACING_STEP).round() as usize;
    let mut vehicles: Vec<Vehicle> = (0..=steps)
        .map(|i| {
            let rear = lo + (hi - lo) * i as f64 / steps as f64;
            Vehicle {
                name: format!("truck {front}/{rear:.1} m"),
                axles: vec![
                    (0.0, HL93_TRUCK[0]),
                    (front, HL93_TRUCK[1]),
                    (front + rear, HL93_TRUCK[2]),
                ],
            }
        })
        .collect();
    vehicles.push(Vehicle {
        name: "tandem".into(),
        axles: vec![(0.0, HL93_TANDEM.0), (HL93_TANDEM.1, HL93_TANDEM.0)],
    });
    Traffic {
        name: name.into(),
        vehicles,
        vehicle_factor: (1.0 + im) * km,
        lane_load: HL93_LANE * km,
        note: format!(
            "AASHTO LRFD HL-93, w = {w} m: {n} design lanes, {k} loaded × m = {:.2}: {km:.2} lanes; truck or tandem × (1 + {im}), lane {:.2} kN/m",
            multiple_presence(k),
            HL93_LANE * km / 1e3
        ),
    }
}

/// AASHTO LRFD 3.6.1.3.1: the smallest distance between the lead axle of one truck and the
/// rear axle of the other in the two-truck load for negative moment and interior reactions [m].
pub const HL93_TWO_TRUCK_GAP: f64 = 15.0;
/// AASHTO LRFD 3.6.1.3.1: the factor on the two trucks and the lane load [-].
pub const HL93_TWO_TRUCK_FACTOR: f64 = 0.9;
/// Step of the searched gap between the two trucks [m].
pub const HL93_GAP_STEP: f64 = 0.5;

/// AASHTO LRFD 3.6.1.3.1 for negative moment between points of contraflexure and interior
/// pier reactions: 90 % of two design trucks (145 kN axles 4.3 m apart) with at least
/// 15 m from the lead axle of one to the rear axle of the other (gaps searched from 15 m to
/// the path's length `path_length` [m] in 0.5 m steps), × (1 + IM), with 90 % of the lane
/// load, all × k·m(k) as [`hl93`]. The designer reads it for those effects only (the code
/// does not ask it elsewhere).
pub fn hl93_two_trucks(name: &str, w: f64, im: f64, path_length: f64) -> Traffic {
    let one = hl93(name, w, im);
    let km = one.lane_load / HL93_LANE;
    let truck = [
        (0.0, HL93_TRUCK[0]),
        (4.3, HL93_TRUCK[1]),
        (8.6, HL93_TRUCK[2]),
    ];
    let longest = (path_length - HL93_TWO_TRUCK_GAP).max(0.0);
    let n = (longest / HL93_GAP_STEP).floor() as usize;
    let vehicles = (0..=n)
        .map(|i| {
            let gap = HL93_TWO_TRUCK_GAP + i as f64 * HL93_GAP_STEP;
            let mut axles = truck.to_vec();
            axles.extend(truck.iter().map(|&(d, p)| (8.6 + gap + d, p)));
            Vehicle {
                name: format!("two trucks {gap:.1} m apart"),
                axles,
            }
        })
        .collect();
    Traffic {
        name: name.into(),
        vehicles,
        vehicle_factor: HL93_TWO_TRUCK_FACTOR * (1.0 + im) * km,
        lane_load: HL93_TWO_TRUCK_FACTOR * HL93_LANE * km,
        note: format!(
            "AASHTO LRFD HL-93 two trucks (3.6.1.3.1: negative moment, interior reactions), w = {w} m: {km:.2} lanes; 90 % of two trucks (4.3/4.3 m) at least 15 m apart × (1 + {im}), 90 % lane {:.2} kN/m",
            HL93_TWO_TRUCK_FACTOR * HL93_LANE * km / 1e3
        ),
    }
}

/// A user vehicle: axle `loads` [N] at `spacings` [m] (one fewer), × (1 + `impact`), with
/// a line load `lane_load` [N/m] where unfavourable, all × `lanes`.
pub fn user_vehicle(
    name: &str,
    loads: &[f64],
    spacings: &[f64],
    impact: f64,
    lane_load: f64,
    lanes: f64,
) -> Traffic {
    let mut d = 0.0;
    let mut axles = vec![(0.0, loads[0])];
    for (s, p) in spacings.iter().zip(&loads[1..]) {
        d += s;
        axles.push((d, *p));
    }
    Traffic {
        name: name.into(),
        vehicles: vec![Vehicle {
            name: "vehicle".into(),
            axles,
        }],
        vehicle_factor: (1.0 + impact) * lanes,
        lane_load: lane_load * lanes,
        note: format!(
            "user vehicle: {} axles, {:.1} kN, × (1 + {impact}) × {lanes}; lane load {:.2} kN/m",
            loads.len(),
            loads.iter().sum::<f64>() / 1e3,
            lane_load * lanes / 1e3
        ),
    }
}

/// The value of an influence line (`eta` at the increasing positions `s` [m]) at `x`:
/// linear between positions (a load between two path nodes is shared between them by the
/// lever rule), zero off the path.
pub fn eta_at(s: &[f64], eta: &[f64], x: f64) -> f64 {
    let n = s.len();
    if n == 0 || x < s[0] || x > s[n - 1] {
        return 0.0;
    }
    let i = s.partition_point(|&v| v <= x);
    if i >= n {
        return eta[n - 1];
    }
    if i == 0 {
        return eta[0];
    }
    let t = (x - s[i - 1]) / (s[i] - s[i - 1]);
    eta[i - 1] + t * (eta[i] - eta[i - 1])
}

/// ∫ max(η, 0) ds and ∫ min(η, 0) ds of the piecewise-linear line [value × m], exact (each
/// piece split at its zero).
pub fn signed_areas(s: &[f64], eta: &[f64]) -> (f64, f64) {
    let (mut pos, mut neg) = (0.0, 0.0);
    for i in 1..s.len() {
        let (a, b, h) = (eta[i - 1], eta[i], s[i] - s[i - 1]);
        if a >= 0.0 && b >= 0.0 {
            pos += 0.5 * (a + b) * h;
        } else if a <= 0.0 && b <= 0.0 {
            neg += 0.5 * (a + b) * h;
        } else {
            // One sign change at t = a / (a − b) of the piece.
            let t = a / (a - b);
            let (first, second) = (0.5 * a * t * h, 0.5 * b * (1.0 - t) * h);
            if a > 0.0 {
                pos += first;
                neg += second;
            } else {
                neg += first;
                pos += second;
            }
        }
    }
    (pos, neg)
}

/// One extreme of a traffic model's effect.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Extreme {
    /// Total: vehicle part + lane part [monitor unit].
    pub value: f64,
    /// Part of the governing vehicle, factors included.
    pub vehicle: f64,
    /// Part of the lane load on the unfavourable stretches.
    pub lane: f64,
    /// Name of the governing vehicle (empty when no position is unfavourable).
    pub vehicle_name: String,
    /// Positions of its axles along the path [m] (empty when the traffic is absent).
    pub axles: Vec<f64>,
    /// Their loads, factors included [N] (downward).
    pub axle_loads: Vec<f64>,
}

/// The most favourable to the largest (`max`) and smallest (`min`) value of the traffic's
/// effect on the influence line `eta` at path positions `s` (per N of downward load).
/// A variable action is absent where favourable, so max ≥ 0 ≥ min. The vehicle part is
/// exact for the piecewise-linear line: its sum over axles is piecewise linear in the
/// vehicle's position, with kinks where an axle crosses a path position, so the extremes
/// are at positions that put some axle on a path position, and all those are tried, in
/// both directions of travel.
pub fn envelope(t: &Traffic, s: &[f64], eta: &[f64]) -> (Extreme, Extreme) {
    let mut min = Extreme::default();
    let mut max = Extreme::default();
    let mut best = (0.0_f64, 0.0_f64);
    for v in &t.vehicles {
        let back = v.reversed();
        let both = [v, &back];
        let ways = if back.axles == v.axles { 1 } else { 2 };
        for w in &both[..ways] {
            for &si in s {
                for &(d, _) in &w.axles {
                    let p = si - d;
                    let e = t.vehicle_factor
                        * w.axles
                            .iter()
                            .map(|&(dk, pk)| pk * eta_at(s, eta, p + dk))
                            .sum::<f64>();
                    let at = || w.axles.iter().map(|a| p + a.0).collect::<Vec<_>>();
                    let loads = || w.axles.iter().map(|a| t.vehicle_factor * a.1).collect();
                    if e > best.1 {
                        best.1 = e;
                        max.vehicle_name = w.name.clone();
                        max.axles = at();
                        max.axle_loads = loads();
                    }
                    if e < best.0 {
                        best.0 = e;
                        min.vehicle_name = w.name.clone();
                        min.axles = at();
                        min.axle_loads = loads();
                    }
                }
            }
        }
    }
    let (pos, neg) = signed_areas(s, eta);
    max.vehicle = best.1;
    max.lane = t.lane_load * pos;
    max.value = max.vehicle + max.lane;
    min.vehicle = best.0;
    min.lane = t.lane_load * neg;
    min.value = min.vehicle + min.lane;
    (min, max)
}

/// The stretch of the path piece from 0 to `h` [m] (values `a` at 0 and `b` at `h`) where
/// the line has the sign wanted (`positive`; zero values excluded), as (from, to) [m].
pub fn unfavourable_stretch(a: f64, b: f64, h: f64, positive: bool) -> Option<(f64, f64)> {
    let (a, b) = if positive { (a, b) } else { (-a, -b) };
    if a <= 0.0 && b <= 0.0 {
        None
    } else if a >= 0.0 && b >= 0.0 {
        Some((0.0, h))
    } else {
        let z = h * a / (a - b);
        Some(if a > 0.0 { (0.0, z) } else { (z, h) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// EN 1991-2 Table 4.1 and 4.2 by hand: 11 m carriageway = 3 lanes of 3 m + 2 m;
    /// tandem axles 300 + 200 + 100 = 600 kN; UDL 9·3 + 2.5·3·2 + 2.5·2 = 47 kN/m (the
    /// viaduct example's figure). Exact arithmetic on round numbers: 1e-9 relative.
    #[test]
    fn lm1_on_eleven_metres() {
        let t = lm1("LM1", 11.0, [1.0; 3], [1.0; 3]);
        assert_eq!(en_lanes(11.0), (3, 3.0, 2.0));
        let v = &t.vehicles[0];
        assert_eq!(v.axles.len(), 2);
        assert!((v.axles[0].1 - 600e3).abs() < 1e-9 * 600e3);
        assert!((v.axles[1].0 - 1.2).abs() < 1e-12);
        assert!((v.total() - 1200e3).abs() < 1e-6);
        assert!((t.lane_load - 47e3).abs() < 1e-9 * 47e3);
    }

    /// Table 4.1's narrow cases: 5 m → one 3 m lane + 2 m (TS 2 × 300 kN, UDL 27 + 5 =
    /// 32 kN/m); 5.7 m → two lanes of 2.85 m, no remaining area (axles 500 kN, UDL
    /// 9·2.85 + 2.5·2.85 = 32.775 kN/m); 7 m → 2 lanes + 1 m; α factors scale their parts.
    #[test]
    fn lm1_lane_rules_and_factors() {
        let t = lm1("a", 5.0, [1.0; 3], [1.0; 3]);
        assert!((t.vehicles[0].axles[0].1 - 300e3).abs() < 1e-6);
        assert!((t.lane_load - 32e3).abs() < 1e-6);
        let t = lm1("b", 5.7, [1.0; 3], [1.0; 3]);
        assert!((t.vehicles[0].axles[0].1 - 500e3).abs() < 1e-6);
        assert!((t.lane_load - 32.775e3).abs() < 1e-6);
        assert_eq!(en_lanes(7.0), (2, 3.0, 1.0));
        // α_Q1 = 0.8, α_Q2 = 0.8 (some national annexes), α_q1 = 0.7, α_qi = α_qr = 1.
        let t = lm1("c", 7.0, [0.8, 0.8, 1.0], [0.7, 1.0, 1.0]);
        assert!((t.vehicles[0].axles[0].1 - 0.8 * 500e3).abs() < 1e-6);
        assert!((t.lane_load - (0.7 * 27e3 + 7.5e3 + 2.5e3)).abs() < 1e-6);
    }

    /// AASHTO LRFD: truck 35 + 145 + 145 = 325 kN (72 kip), 4.3 m then 4.3–9.0 m; tandem
    /// 2 × 110 kN at 1.2 m; lane 9.3 kN/m; IM 33 % on truck and tandem only. One 3.6 m lane:
    /// m = 1.2. 11 m roadway: 3 lanes; 3 × 0.85 = 2.55 governs over 2 × 1.0 and 1.2.
    #[test]
    fn hl93_axles_lanes_and_factors() {
        let t = hl93("HL-93", 3.6, HL93_IM);
        let trucks: Vec<_> = t.vehicles.iter().filter(|v| v.axles.len() == 3).collect();
        assert_eq!(trucks.len(), 48);
        for v in &trucks {
            assert!((v.total() - 325e3).abs() < 1e-6);
            assert!((v.axles[1].0 - 4.3).abs() < 1e-12);
        }
        assert!((trucks[0].length() - 8.6).abs() < 1e-12);
        assert!((trucks[47].length() - 13.3).abs() < 1e-12);
        let tandem = t.vehicles.last().expect("tandem");
        assert!((tandem.total() - 220e3).abs() < 1e-6 && (tandem.length() - 1.2).abs() < 1e-12);
        assert!((t.vehicle_factor - 1.33 * 1.2).abs() < 1e-12);
        assert!((t.lane_load - 9.3e3 * 1.2).abs() < 1e-9);
        assert_eq!(aashto_lanes(11.0), 3);
        assert_eq!(aashto_lanes(6.5), 2);
        let t = hl93("HL-93", 11.0, HL93_IM);
        assert!((t.vehicle_factor - 1.33 * 2.55).abs() < 1e-12);
        assert!((t.lane_load - 9.3e3 * 2.55).abs() < 1e-9);
    }

    /// The influence line of the moment at midspan of a simply supported span L = 10 m
    /// (triangle, peak L/4 = 2.5 m per N): one 100 kN axle gives 250 kN·m at midspan; the
    /// LM1 tandem of one lane (2 × 300 kN at 1.2 m) gives 300·(2.5 + 2.5 − 0.6) = 1320 kN·m
    /// (one axle at midspan, the other 1.2 m off: η = 2.5 − 1.2/2); UDL q L²/8. Linear line
    /// on a 0.1 m grid: exact to rounding (1e-9).
    #[test]
    fn envelope_of_a_simple_span_moment() {
        let l = 10.0;
        let s: Vec<f64> = (0..=100).map(|i| i as f64 * 0.1).collect();
        let eta: Vec<f64> = s
            .iter()
            .map(|&x| if x <= l / 2.0 { x / 2.0 } else { (l - x) / 2.0 })
            .collect();
        let one = user_vehicle("P", &[100e3], &[], 0.0, 0.0, 1.0);
        let (min, max) = envelope(&one, &s, &eta);
        assert!((max.value - 250e3).abs() < 1e-6 && min.value == 0.0);
        assert!((max.axles[0] - 5.0).abs() < 1e-9);
        let t = lm1("LM1", 3.0, [1.0; 3], [1.0; 3]);
        let (_, max) = envelope(&t, &s, &eta);
        assert!((max.vehicle - 1320e3).abs() < 1e-6, "{}", max.vehicle);
        assert!((max.lane - 27e3 * l * l / 8.0).abs() < 1e-6);
    }

    /// The two-truck load: six axles, 2 × 325 kN, at the smallest gap 15 m from the rear
    /// axle of the truck in front to the lead axle of the one behind; 0.9 × (1 + IM) × k·m(k)
    /// on the axles and 0.9 × 9.3 kN/m × k·m(k); on one lane (m = 1.2) and a 40 m path,
    /// gaps 15–40 m in 0.5 m steps: 51 pairs.
    /// Over a pier of two equal 20 m spans (η of the reaction peaked at the pier), the two
    /// trucks straddle it: the envelope exceeds one truck's.
    #[test]
    fn hl93_two_trucks_for_negative_moment() {
        let t = hl93_two_trucks("2T", 3.6, HL93_IM, 40.0);
        assert_eq!(t.vehicles.len(), 51);
        let v = &t.vehicles[0];
        assert_eq!(v.axles.len(), 6);
        assert!((v.total() - 650e3).abs() < 1e-6);
        // Lead axle of the second truck 15 m behind the rear axle of the first.
        assert!((v.axles[3].0 - v.axles[2].0 - 15.0).abs() < 1e-12);
        assert!((t.vehicle_factor - 0.9 * 1.33 * 1.2).abs() < 1e-12);
        assert!((t.lane_load - 0.9 * 9.3e3 * 1.2).abs() < 1e-9);
        // Middle reaction of two 20 m spans, Euler–Bernoulli: ξ(3 − ξ²)/2 each side.
        let s: Vec<f64> = (0..=400).map(|i| i as f64 * 0.1).collect();
        let eta: Vec<f64> = s
            .iter()
            .map(|&x| {
                let xi = if x <= 20.0 {
                    x / 20.0
                } else {
                    (40.0 - x) / 20.0
                };
                xi * (3.0 - xi * xi) / 2.0
            })
            .collect();
        let (_, two) = envelope(&t, &s, &eta);
        let (_, one) = envelope(&hl93("1T", 3.6, HL93_IM), &s, &eta);
        assert!(two.vehicle > one.vehicle, "{} {}", two.vehicle, one.vehicle);
        // Astride the pier: one truck on each span.
        assert!(
            two.axles[0] < 20.0 && two.axles[5] > 20.0,
            "{:?}",
            two.axles
        );
    }

    /// Signed areas of a line crossing zero: η from −1 to 3 over 4 m: zero at 1 m,
    /// negative area −0.5, positive 4.5 (exact).
    #[test]
    fn signed_areas_split_at_zero() {
        let (p, n) = signed_areas(&[0.0, 4.0], &[-1.0, 3.0]);
        assert!((p - 4.5).abs() < 1e-12 && (n + 0.5).abs() < 1e-12);
    }
}
