//! Stress along a post-tensioned (bonded, grouted later) tendon just after lock-off: friction
//! losses at stressing (seed eq. 27) and the anchorage set (draw-in) with its reverse-friction
//! zone. The tendon is sampled at its integration points (arc length s from the path start
//! and cumulative deviation α(s) = ∫|dθ| from the start, exact for polylines, parabolas and
//! arcs: [`crate::mesh::embed::TurnTable`]).
//!
//! Friction, at each sample, from the jack(s):
//!
//! * jacked at the start: σ(s) = σ_pi exp[−μ(α(s) + k s)];
//! * jacked at the end: σ(s) = σ_pi exp[−μ(α_L − α(s) + k (L − s))];
//! * both ends (to the same σ_pi): the larger of the two.
//!
//! Anchorage set δ at each jacked end: the area method of [`crate::prestress::friction`]
//! (reverse friction equal to forward friction, so the stress after the set is the mirror
//! image σ_after = 2σ_ref − σ in the set zone, with 2∫(σ − σ_ref) ds = E_p δ). The mirror
//! level σ_ref is found on a profile through the samples with the turn between two samples
//! spread evenly over the arc between them ([`TendonPath::sampled_curve`]), exact at the
//! samples; the mirror is then applied to the exact friction values. The remaining
//! approximation is in σ_ref only, from the curvature varying between samples: second order
//! in the sample spacing (≈ 1e-8 σ_pi on the parabolas of the examples).
//!
//! Units: m, rad, Pa.

use super::friction::{
    friction_factor, jacking_profile, AnchorEnd, FrictionError, FrictionParams, Jacking, TendonPath,
};

/// What is done at the jack.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stressing {
    /// Stress at the jack σ_pi \[Pa\].
    pub jacking_stress: f64,
    /// Curvature friction μ \[-\] and wobble k \[rad/m\].
    pub friction: FrictionParams,
    /// Which end(s) are jacked; an anchorage set occurs at each jacked end.
    pub jacking: Jacking,
    /// Anchorage set (wedge draw-in) δ at each jacked end \[m\] (0 = none).
    pub draw_in: f64,
    /// Modulus of the steel E_p \[Pa\] (for the set).
    pub ep: f64,
}

/// The tendon as seen by the loss computation: samples in path order.
#[derive(Debug, Clone, PartialEq)]
pub struct Samples {
    /// Arc length of each sample from the path start \[m\], non-decreasing.
    pub s: Vec<f64>,
    /// Cumulative deviation α at each sample \[rad\], non-decreasing.
    pub alpha: Vec<f64>,
    /// Path length L \[m\].
    pub length: f64,
    /// Total deviation α_L \[rad\].
    pub total_turn: f64,
}

/// Stresses after lock-off, one per sample \[Pa\], and the set lengths.
#[derive(Debug, Clone, PartialEq)]
pub struct LockOff {
    /// Stress after friction only \[Pa\].
    pub after_friction: Vec<f64>,
    /// Stress after friction and anchorage set \[Pa\].
    pub stress: Vec<f64>,
    /// Length affected by the set at the start and at the end \[m\] (0 where not jacked or
    /// no set).
    pub set_length: [f64; 2],
}

/// Friction stress at arc length `s` \[m\] with deviation `alpha` \[rad\] from the start.
pub fn friction_stress(st: &Stressing, smp: &Samples, s: f64, alpha: f64) -> f64 {
    let p = &st.friction;
    let from_start = st.jacking_stress * friction_factor(p, alpha, s);
    let from_end =
        st.jacking_stress * friction_factor(p, smp.total_turn - alpha, (smp.length - s).max(0.0));
    match st.jacking {
        Jacking::Start => from_start,
        Jacking::End => from_end,
        Jacking::Both => from_start.max(from_end),
    }
}

/// Stresses after friction and anchorage set at every sample.
pub fn lock_off(st: &Stressing, smp: &Samples) -> Result<LockOff, FrictionError> {
    let n = smp.s.len();
    if n == 0 || smp.alpha.len() != n || smp.length.is_nan() || smp.length <= 0.0 {
        return Err(FrictionError::Invalid(
            "a tendon needs samples with one angle each and a positive length".into(),
        ));
    }
    if !(st.jacking_stress > 0.0 && st.draw_in >= 0.0 && st.ep > 0.0) {
        return Err(FrictionError::Invalid(
            "jacking stress and E_p must be positive, the draw-in ≥ 0".into(),
        ));
    }
    let after_friction: Vec<f64> = (0..n)
        .map(|i| friction_stress(st, smp, smp.s[i], smp.alpha[i]))
        .collect();
    let mut stress = after_friction.clone();
    let mut set_length = [0.0; 2];
    if st.draw_in > 0.0 {
        // Location of the friction minimum: the set zone of each end stops there.
        let imin = (0..n)
            .min_by(|&a, &b| after_friction[a].total_cmp(&after_friction[b]))
            .unwrap_or(0);
        let ends: &[AnchorEnd] = match st.jacking {
            Jacking::Start => &[AnchorEnd::Start],
            Jacking::End => &[AnchorEnd::End],
            Jacking::Both => &[AnchorEnd::Start, AnchorEnd::End],
        };
        for &end in ends {
            let (sref, len) = mirror_level(st, smp, end)?;
            let range = match (st.jacking, end) {
                (Jacking::Both, AnchorEnd::Start) => 0..imin + 1,
                (Jacking::Both, AnchorEnd::End) => imin..n,
                _ => 0..n,
            };
            for i in range {
                stress[i] = stress[i].min(2.0 * sref - after_friction[i]);
            }
            set_length[match end {
                AnchorEnd::Start => 0,
                AnchorEnd::End => 1,
            }] = len;
        }
        if stress.iter().any(|v| *v < 0.0) {
            return Err(FrictionError::Invalid(
                "anchorage set larger than the tendon's elastic elongation".into(),
            ));
        }
    }
    Ok(LockOff {
        after_friction,
        stress,
        set_length,
    })
}

/// Mirror level σ_ref \[Pa\] and set length \[m\] of the set at `end`, from a profile oriented
/// from that end with the turn of each sample interval spread over it (exact at the
/// samples).
fn mirror_level(
    st: &Stressing,
    smp: &Samples,
    end: AnchorEnd,
) -> Result<(f64, f64), FrictionError> {
    let l = smp.length;
    // (distance from `end`, deviation from `end`), increasing.
    let mut pts: Vec<(f64, f64)> = smp
        .s
        .iter()
        .zip(&smp.alpha)
        .map(|(&s, &a)| match end {
            AnchorEnd::Start => (s, a),
            AnchorEnd::End => (l - s, smp.total_turn - a),
        })
        .collect();
    if end == AnchorEnd::End {
        pts.reverse();
    }
    pts.insert(0, (0.0, 0.0));
    pts.push((l, smp.total_turn));
    let tol = 1e-12 * l;
    let mut s = Vec::with_capacity(pts.len());
    let mut turn = Vec::with_capacity(pts.len());
    let mut last_alpha = 0.0;
    for (x, a) in pts {
        let da = (a - last_alpha).max(0.0);
        if let Some(&prev) = s.last() {
            if x <= prev + tol {
                // Coincident sample: its turn joins the previous point.
                *turn.last_mut().unwrap() += da;
                last_alpha = a.max(last_alpha);
                continue;
            }
        }
        s.push(x.min(l));
        turn.push(da);
        last_alpha = a.max(last_alpha);
    }
    // The last point must be the far end exactly.
    if let Some(v) = s.last_mut() {
        *v = l;
    }
    let path = TendonPath::sampled_curve(s, turn)?;
    let jack = match (st.jacking, end) {
        (Jacking::Both, _) => Jacking::Both,
        _ => Jacking::Start,
    };
    let set = jacking_profile(&path, st.jacking_stress, &st.friction, jack).with_anchorage_set(
        AnchorEnd::Start,
        st.draw_in,
        st.ep,
    )?;
    Ok((set.reference_stress, set.set_length))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn samples_line(l: f64, n: usize) -> Samples {
        let s: Vec<f64> = (0..n).map(|i| l * (i as f64 + 0.5) / n as f64).collect();
        Samples {
            alpha: vec![0.0; n],
            s,
            length: l,
            total_turn: 0.0,
        }
    }

    /// Check 19 values (docs/theory-joints-tendons.md §4) through the tendon formula: a sample at
    /// s = 10 m with α = 0.1 rad, μ = 0.2, seed wobble → 0.960789 σ_pi; jacked at the other end the
    /// same sample sees α_L − α and L − s. Tolerance 1e-6 rel (table digits).
    #[test]
    fn friction_at_samples_matches_check_values() {
        let smp = Samples {
            s: vec![10.0],
            alpha: vec![0.1],
            length: 35.0,
            total_turn: 0.3,
        };
        let mut st = Stressing {
            jacking_stress: 1400e6,
            friction: FrictionParams::seed(0.2),
            jacking: Jacking::Start,
            draw_in: 0.0,
            ep: 195e9,
        };
        let v = lock_off(&st, &smp).unwrap().stress[0];
        assert!((v / 1400e6 / 0.960789 - 1.0).abs() < 1e-6, "{v}");
        // From the end: α = 0.2, s = 25 m with μ = 0.05 → 0.977751.
        st.jacking = Jacking::End;
        st.friction = FrictionParams::seed(0.05);
        let v = lock_off(&st, &smp).unwrap().stress[0];
        assert!((v / 1400e6 / 0.977751 - 1.0).abs() < 1e-6, "{v}");
    }

    /// Straight tendon with wobble friction and a set at the start: the samples reproduce
    /// the exact piecewise result of the friction module (the lumping is exact without
    /// curvature). Tolerance 1e-9 of σ_pi.
    #[test]
    fn set_on_straight_tendon_matches_friction_module() {
        let smp = samples_line(60.0, 240);
        let st = Stressing {
            jacking_stress: 1395e6,
            friction: FrictionParams::seed(0.2),
            jacking: Jacking::Start,
            draw_in: 6e-3,
            ep: 195e9,
        };
        let r = lock_off(&st, &smp).unwrap();
        let path = TendonPath::from_points(&[[0.0, 0.0], [60.0, 0.0]]).unwrap();
        let exact = jacking_profile(&path, 1395e6, &st.friction, Jacking::Start)
            .with_anchorage_set(AnchorEnd::Start, 6e-3, 195e9)
            .unwrap();
        for (s, v) in smp.s.iter().zip(&r.stress) {
            assert!((v - exact.profile.at(*s)).abs() < 1e-9 * 1395e6, "s = {s}");
        }
        assert!((r.set_length[0] - exact.set_length).abs() < 1e-9 * exact.set_length);
    }

    /// Jacked at both ends with sets at both: symmetric, the middle untouched by a short set,
    /// and equal to the one-end result near each end. Tolerance 1e-9 rel.
    #[test]
    fn both_ends_symmetric() {
        let smp = samples_line(80.0, 400);
        let st = Stressing {
            jacking_stress: 1395e6,
            friction: FrictionParams::seed(0.2),
            jacking: Jacking::Both,
            draw_in: 6e-3,
            ep: 195e9,
        };
        let r = lock_off(&st, &smp).unwrap();
        let n = r.stress.len();
        for i in 0..n {
            assert!((r.stress[i] - r.stress[n - 1 - i]).abs() < 1e-9 * 1395e6);
        }
        assert_eq!(r.stress[n / 2], r.after_friction[n / 2]);
        let one = lock_off(
            &Stressing {
                jacking: Jacking::Start,
                ..st
            },
            &smp,
        )
        .unwrap();
        assert!((r.stress[0] - one.stress[0]).abs() < 1e-9 * 1395e6);
        assert!((r.set_length[1] - one.set_length[0]).abs() < 1e-9 * one.set_length[0]);
    }
}
