//! `System::reassemble_after_latch`: after an assembly and the latching of the cracks it
//! formed, the forces at the same displacements from the last assembly's element forces
//! (only the elements of the latched points computed again) are those of a full assembly,
//! to the bit, with the same trial states.

use segfem::analysis::system::System;

#[test]
fn reassembly_after_latching_equals_a_full_assembly() {
    let text = include_str!("../examples/rc-beam.toml");
    let model = segfem::input::parse(text, "rc-beam.toml").unwrap().model;
    let mut sys = System::new(&model);
    // Bending of the whole beam about mid-depth: ε_x = κ (y − y_mid), κ chosen so that the
    // extreme fibres reach ±1e-3, ten times the cracking strain of the concrete
    // (f_tm / E ≈ 1e-4): the tension half cracks, the compression half stays uncracked.
    let (y0, y1) = model
        .nodes
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p[1]), b.max(p[1])));
    let (ym, kappa) = (0.5 * (y0 + y1), 2e-3 / (y1 - y0));
    let u: Vec<f64> = model
        .nodes
        .iter()
        .flat_map(|p| [-kappa * (p[1] - ym) * p[0], 0.5 * kappa * p[0] * p[0]])
        .collect();
    sys.assemble(&u, true).unwrap();
    let latched = sys.latch_cracks();
    assert!(latched > 0, "the bending cracks some points");
    let again = sys
        .reassemble_after_latch(&u)
        .expect("the last assembly was at u")
        .unwrap();
    let trial = sys.families.continuum.points.trial.clone();
    let full = sys.assemble(&u, false).unwrap();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&again.f_int), bits(&full.f_int));
    assert_eq!(again.force_scale.to_bits(), full.force_scale.to_bits());
    assert!(again.k_values.is_none());
    assert!(trial == sys.families.continuum.points.trial);
    // Not at other displacements, nor after the holds changed otherwise.
    let mut v = u.clone();
    v[3] += 1e-9;
    assert!(sys.reassemble_after_latch(&v).is_none());
    sys.unlatch();
    assert!(sys.reassemble_after_latch(&u).is_none());
}
