//! Time-dependent analysis through the engine: MC90 creep and shrinkage of concrete by the
//! ageing Maxwell chain, relaxation of external tendons, prestress losses over time.
//! Run with `cargo test --release --test time` (the beam tests take a few seconds).

use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::materials::mc90_time::{compliance, shrinkage_strain, CementClass, CreepShrinkageParams};
use segfem::model::LossPart;

/// One record per converged increment.
#[derive(Debug, Clone, Default)]
struct Rec {
    time: f64,
    strain: [f64; 3],
    stress: [f64; 3],
    u: Vec<f64>,
    forces: Vec<f64>,
    losses: Vec<[f64; 4]>,
}

#[derive(Default)]
struct Keep(Vec<Rec>);

impl Observer for Keep {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let sys = s.system;
        let parts = [
            LossPart::Total,
            LossPart::Elastic,
            LossPart::CreepShrinkage,
            LossPart::Relaxation,
        ];
        self.0.push(Rec {
            time: sys.time.t_to,
            strain: sys.gauss[0].strain,
            stress: sys.gauss[0].stress,
            u: sys.u.clone(),
            forces: sys
                .tendon_committed
                .iter()
                .map(|t| t.as_ref().map(|t| t.forces()[0]).unwrap_or(0.0))
                .collect(),
            losses: sys
                .tendon_time
                .iter()
                .map(|t| {
                    t.as_ref()
                        .map(|t| parts.map(|p| t.loss(p)))
                        .unwrap_or_default()
                })
                .collect(),
        });
        Ok(())
    }
}

fn run(text: &str) -> Vec<Rec> {
    let model = segfem::input::parse(text, "time.toml")
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let mut k = Keep::default();
    steps::run(&model, &mut k).unwrap();
    k.0
}

/// The MC90 data of MODEL.md's checks: fcm 45 MPa, RH 70 %, h = 200 mm, cement N.
fn params(drying_start: f64) -> CreepShrinkageParams {
    CreepShrinkageParams::new(45e6, 0.70, 0.200, CementClass::N, drying_start)
}

const CONCRETE: &str = r#"
[[materials]]
name = "c"
kind = "elastic_creep"
fcm = 45e6
rh = 0.70
h0 = 0.200
cement = "N"
nu = 0.2
"#;

/// A 0.1 m square Q4 specimen, 0.1 m thick, held on its left edge (ux) and at its
/// bottom-left corner (uy): free to contract laterally, so the stress is uniaxial.
fn specimen(shrinkage: bool, stress: f64, t0: f64, steps: &str) -> String {
    format!(
        r#"{CONCRETE}shrinkage = {shrinkage}
drying_start = 7.0
[[regions]]
name = "r"
material = "c"
thickness = 0.1
cast_day = 0.0
[mesh]
type = "banded"
length = 0.1
nx = 1
element = "Q4"
bands = [{{ region = "r", depth = 0.1, rows = 1 }}]
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 0.1]]
ux = 0.0
[[supports]]
name = "corner"
point = [0.0, 0.0]
uy = 0.0
[[load_cases]]
name = "P"
line_loads = [{{ line = [[0.1, 0.0], [0.1, 0.1]], q = [{q}, 0.0] }}]
[[steps]]
name = "load"
kind = "load"
loads = {{ P = 1.0 }}
[[steps]]
name = "creep"
kind = "time"
from = {t0}
{steps}
"#,
        q = stress * 0.1
    )
}

#[test]
fn creep_under_constant_stress_follows_mc90() {
    // σ = −4 MPa < 0.4 fcm (linear creep). ε(t)/(σ J(t, t0)) within 2 % from 1 to 1e4 days
    // after loading for t0 = 7, 28, 365 d: the chain itself reproduces J within 0.6 % at
    // 10 steps/decade (docs/theory-time.md §2); the default 5 substeps/decade adds < 0.7 %
    // at 1e4 d; 2 % leaves room for both but fails for a missing creep term (φ ≈ 1.5–2.8)
    // or a wrong loading age (J(1e4, 7) vs J(1e4, 28) differ by 20 %).
    let sigma = -4e6;
    let p = params(7.0);
    for t0 in [7.0, 28.0, 365.0] {
        let rec = run(&specimen(false, sigma, t0, "duration = 1e4"));
        let load = &rec[0];
        assert_eq!(load.time, t0);
        assert!((load.stress[0] / sigma - 1.0).abs() < 1e-9, "{:?}", load.stress);
        let mut checked = 0;
        let mut worst: f64 = 0.0;
        for r in &rec[1..] {
            let d = r.time - t0;
            assert!((r.stress[0] / sigma - 1.0).abs() < 1e-8, "stress held constant");
            if d < 0.999 {
                continue;
            }
            let want = sigma * compliance(&p, r.time, t0);
            let ratio = r.strain[0] / want;
            assert!(
                (ratio - 1.0).abs() < 0.02,
                "t0 = {t0} d, t − t0 = {d} d: ε/(σJ) = {ratio}"
            );
            worst = worst.max((ratio - 1.0).abs());
            checked += 1;
        }
        eprintln!("t0 = {t0} d: worst |ε/(σJ) − 1| = {worst:.4} over {checked} substeps");
        assert!(checked >= 20, "checked {checked} substeps");
        // Creep really happened: ε(1e4 d) ≥ 2 × the elastic strain.
        assert!(rec.last().unwrap().strain[0] / load.strain[0] > 2.0);
    }
}

#[test]
fn free_shrinkage_follows_mc90() {
    // No load: the specimen shrinks freely, stress-free, by ε_cs(t) − ε_cs(t_start) in both
    // directions. The imposed strain enters exactly, so the tolerance is round-off (1e-9
    // relative), and the stress must stay ≈ 0 (1 Pa).
    let p = params(7.0);
    let rec = run(&specimen(true, 0.0, 7.0, "to = 10007.0"));
    let mut n = 0;
    for r in &rec[1..] {
        let want = shrinkage_strain(&p, r.time) - shrinkage_strain(&p, 7.0);
        assert!(want < 0.0);
        for c in 0..2 {
            assert!(
                (r.strain[c] / want - 1.0).abs() < 1e-9,
                "t = {}: ε = {:?}, ε_cs = {want}",
                r.time,
                r.strain
            );
        }
        assert!(r.stress.iter().all(|s| s.abs() < 1.0), "{:?}", r.stress);
        n += 1;
    }
    assert!(n > 20);
    // 1e4 days of drying at RH 70 %: ε_cs ≈ −0.3 ‰ (MC90 ε_cso = −3.9e-4 × β_s ≈ 0.8).
    let last = rec.last().unwrap().strain[0];
    assert!(last < -2.5e-4 && last > -4e-4, "{last}");
}
