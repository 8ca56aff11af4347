// Temporary diagnostic (not committed): state of the seed beam at given Q.
use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::results::joints::summarise;

struct D {
    qs: Vec<f64>,
    done: Vec<bool>,
    u0: Option<f64>,
    mid: usize,
}
impl Observer for D {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let sys = s.system;
        let m = sys.model;
        if s.step == 0 {
            self.u0 = Some(sys.u[2 * self.mid + 1]);
        }
        let q = s.factors[1];
        let d = (self.u0.unwrap_or(0.0) - sys.u[2 * self.mid + 1]) * 1e3;
        let ts = sys.tendon_committed[0]
            .as_ref()
            .map_or(0.0, |t| t.stresses().into_iter().fold(0.0, f64::max));
        println!(
            "Q {q:8.2} d {d:7.2} mm σp {:7.1} negpiv {}",
            ts / 1e6,
            s.negative_pivots
        );
        for (k, &qq) in self.qs.iter().enumerate() {
            if self.done[k] || (q - qq).abs() > 0.3 {
                continue;
            }
            self.done[k] = true;
            println!(
                "=== Q = {q:.2} kN deflection {d:.2} mm tendon {:.1} MPa",
                ts / 1e6
            );
            for j in 0..m.joints.len() {
                let sm = summarise(sys, j);
                let smax = sm
                    .profile
                    .iter()
                    .map(|p| p.normal_stress)
                    .fold(0.0, f64::max);
                println!(
                    "  joint {} open {:.2} mm contact {:.3} m max σn {:.1} MPa",
                    m.joints[j].name,
                    sm.max_opening * 1e3,
                    sm.contact_depth,
                    smax / 1e6
                );
            }
            // per region: cracked points, crushed, max plastic strain (+ where), min σx
            let mut rows: Vec<(f64, usize, usize, f64, f64, f64)> = vec![]; // eps_p, el, gp, x, y, sx
            let mut per_reg = vec![(0usize, 0usize, 0.0f64, 0.0f64); m.regions.len()];
            for (e, el) in m.elements.iter().enumerate() {
                let cx = el.nodes.iter().take(4).map(|&n| m.nodes[n][0]).sum::<f64>() / 4.0;
                let cy = el.nodes.iter().take(4).map(|&n| m.nodes[n][1]).sum::<f64>() / 4.0;
                for g in sys.gp_offset[e]..sys.gp_offset[e + 1] {
                    let p = &sys.committed[g];
                    let r = &mut per_reg[el.region];
                    if p.n_cracks() > 0 {
                        r.0 += 1;
                    }
                    if p.is_crushed() {
                        r.1 += 1;
                    }
                    r.2 = r.2.max(p.equivalent_plastic_strain());
                    r.3 = r.3.min(sys.gauss[g].stress[0]);
                    rows.push((
                        p.equivalent_plastic_strain(),
                        e,
                        g,
                        cx,
                        cy,
                        sys.gauss[g].stress[0],
                    ));
                    if p.n_cracks() > 0 && std::env::var("CRACKS").is_ok() {
                        println!(
                            "    crack el {} ({cx:.3},{cy:.3}) n {} ecr {:.2e} angle {:.0}",
                            e + 1,
                            p.n_cracks(),
                            p.crack_strain(),
                            p.crack_angle().to_degrees()
                        );
                    }
                }
            }
            for (i, r) in per_reg.iter().enumerate() {
                println!("  region {:14} cracked pts {:4} crushed {:3} max eps_p {:.2e} min sx {:.1} MPa", m.regions[i].name, r.0, r.1, r.2, r.3/1e6);
            }
            let mut pr: Vec<(f64, usize, f64, f64, [f64; 3])> = vec![];
            for (e, el) in m.elements.iter().enumerate() {
                let cx = el.nodes.iter().take(4).map(|&n| m.nodes[n][0]).sum::<f64>() / 4.0;
                let cy = el.nodes.iter().take(4).map(|&n| m.nodes[n][1]).sum::<f64>() / 4.0;
                for g in sys.gp_offset[e]..sys.gp_offset[e + 1] {
                    let s = sys.gauss[g].stress;
                    let c = 0.5 * (s[0] + s[1]);
                    let r = (0.5 * (s[0] - s[1])).hypot(s[2]);
                    pr.push((c + r, e, cx, cy, s));
                }
            }
            pr.sort_by(|a, b| b.0.total_cmp(&a.0));
            for r in pr.iter().take(12) {
                println!(
                    "    s1 {:.2} MPa el {} ({:.3},{:.3}) s {:.2} {:.2} {:.2}",
                    r.0 / 1e6,
                    r.1 + 1,
                    r.2,
                    r.3,
                    r.4[0] / 1e6,
                    r.4[1] / 1e6,
                    r.4[2] / 1e6
                );
            }
            rows.sort_by(|a, b| b.0.total_cmp(&a.0));
            for r in rows.iter().take(8) {
                println!(
                    "    eps_p {:.2e} el {} ({:.3},{:.3}) sx {:.1} MPa",
                    r.0,
                    r.1 + 1,
                    r.3,
                    r.4,
                    r.5 / 1e6
                );
            }
            // min sx near midspan joints: top flange elements, x within 0.3 of the joint at 3.086/4.114
            let mut ss: Vec<_> = rows
                .iter()
                .filter(|r| r.4 > 0.4)
                .map(|r| (r.5, r.3, r.4))
                .collect();
            ss.sort_by(|a, b| a.0.total_cmp(&b.0));
            for r in ss.iter().take(5) {
                println!("    min sx {:.1} MPa at ({:.3},{:.3})", r.0 / 1e6, r.1, r.2);
            }
        }
        Ok(())
    }
}

fn main() {
    let f = std::env::args().nth(1).unwrap();
    let text = std::fs::read_to_string(&f).unwrap();
    let model = segfem::input::parse(&text, &f).unwrap().model;
    let mid = model
        .nodes
        .iter()
        .position(|p| (p[0] - 3.6).abs() < 1e-9 && p[1].abs() < 1e-9)
        .unwrap();
    let qs: Vec<f64> = std::env::args()
        .skip(2)
        .map(|s| s.parse().unwrap())
        .collect();
    let n = qs.len();
    let mut d = D {
        qs,
        done: vec![false; n],
        u0: None,
        mid,
    };
    let t = std::time::Instant::now();
    let r = steps::run(&model, &mut d);
    println!(
        "end {:?} in {:.1} s",
        r.err()
            .map(|e| e.to_string().lines().next().unwrap().to_string()),
        t.elapsed().as_secs_f64()
    );
}
