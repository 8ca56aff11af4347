//! Balanced-cantilever erection by the `[viaduct]` generator (issue 39 item 2;
//! docs/theory-stages.md §6b): the cantilevers carry their segments, travellers and
//! tendons as statics says at every stage before closure; the closures make the girder
//! continuous; a casting curve taken from one run closes the deck's profile in a rerun.
//! Run with `cargo nextest run --release --test cantilever`.

mod common;

use common::TempDir;
use segfem::run::{run_file_opts, RunOptions};
use std::path::Path;

/// Section bands bottom up: (out-of-plane width [m], depth [m], element rows).
const BANDS: [(f64, f64, usize); 3] = [(6.5, 0.30, 1), (0.90, 1.95, 4), (12.0, 0.25, 1)];
/// Concrete density [kg/m³] and the generator's gravity [m/s²].
const RHO: f64 = 2500.0;
const G: f64 = 9.81;
/// Segment, pier segment, closure, end segment [m]; overhang [m]; pairs per pier.
const SEG: f64 = 3.5;
const PIER: f64 = 6.0;
const CLOSURE: f64 = 3.0;
const PAIRS: usize = 3;
/// Traveller weight [N]; cantilever tendon area [m²] and height [m].
const TRAVELLER: f64 = 300e3;
const AREA: f64 = 0.002;
const HEIGHT: f64 = 2.375;

/// A 18 + 30 + 18 m girder of constant depth, three pairs per pier (side spans: the end
/// segment and the closure only). `extra` is appended (monitors, steps).
fn model(extra: &str) -> String {
    let section: Vec<String> = BANDS
        .iter()
        .zip(["bottom", "webs", "deck"])
        .map(|((w, d, r), n)| format!("{{ name = \"{n}\", width = {w}, depth = {d}, rows = {r} }}"))
        .collect();
    format!(
        r#"
title = "balanced cantilever, three pairs"

[[materials]]
name = "concrete"
kind = "elastic_creep"
fcm = 48e6
rh = 0.70
h0 = 0.30
cement = "N"
nu = 0.2
density = {RHO}
n_units = 5

[[materials]]
name = "strand"
kind = "prestressing_steel"
Ep = 195e9
fptk = 1860e6

[[joint_materials]]
name = "dry"
kind = "keyed"

[viaduct]
sequence = "balanced_cantilever"
spans = [18.0, 30.0, 18.0]
segment_length = {SEG}
pier_segment = {PIER}
end_segment = 2.0
overhang = 0.5
concrete = "concrete"
joint_material = "dry"
strand = "strand"
nx_per_segment = 2
segment_age = 60.0
section = [{section}]

[viaduct.cantilever]
pairs = [{PAIRS}, {PAIRS}]
closure = {CLOSURE}
pair_interval = 7.0
traveller = {TRAVELLER}
tendons = {{ area = {AREA}, height = {HEIGHT}, jacking_stress = 1200e6, wobble = 0.0 }}
{extra}
"#,
        section = section.join(", ")
    )
}

/// history.csv as its header and rows of numbers.
fn history(out: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(out.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    (header, rows)
}

fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name || h.starts_with(&format!("{name} [")))
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

fn run(tmp: &TempDir, name: &str, text: &str) -> std::path::PathBuf {
    let path = tmp.join(&format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let out = tmp.join(name);
    run_file_opts(Some(&path), &out, &mut |_| {}, &RunOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    out
}

/// Height [m] of the resultant of a cantilever tendon's anchor force: the documented
/// default plate (docs/input.md, `anchor_plate`: 0.085 √n m for n = ⌈A / 140 mm²⌉ strands)
/// centred on the anchor, a uniform pressure over the part of it on the member (the deck's
/// top at the section's depth cuts it).
fn anchor_height() -> f64 {
    let strands = (AREA / 140e-6).ceil();
    let plate = 0.085 * strands.sqrt();
    let depth: f64 = BANDS.iter().map(|b| b.1).sum();
    let (lo, hi) = (
        (HEIGHT - plate / 2.0).max(0.0),
        (HEIGHT + plate / 2.0).min(depth),
    );
    (lo + hi) / 2.0
}

/// Gauss points of a 3 × 3 rule on [−1, 1]: abscissae and weights.
const GAUSS: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

/// Every Gauss point of the section's rows at abscissa x: (y [m], weight × width [m²]).
fn section_points() -> Vec<(f64, f64)> {
    let mut pts = Vec::new();
    let mut y0 = 0.0;
    for (w, d, rows) in BANDS {
        let h = d / rows as f64;
        for r in 0..rows {
            let yc = y0 + (r as f64 + 0.5) * h;
            for (eta, wt) in GAUSS {
                pts.push((yc + eta * h / 2.0, wt * h / 2.0 * w));
            }
        }
        y0 += d;
    }
    pts
}

/// The cantilevers of P1 at every stage from the first pair to the closure, cut through
/// the middle of the right arm's second segment (5.25 m from the pier segment's face, clear
/// of the pier segment's disturbance): the section forces integrated from the Gauss-point
/// stresses there (3 × 3 rule over each element row, exact for the Q8's polynomial field
/// through the depth) against the statics of everything outboard — the segments' weight
/// ρ g A per metre, the traveller one node column in from the tip, and the cantilever
/// tendons anchored outboard at their monitored forces:
///   N = −Σ P_j,  M = w L²/2 + W (x_T − x_s) − Σ P_j (y_t − y_c),  V = w L + W
/// (M = ∫σx (y − y_c) dA, positive with the deck in tension), and the fixity's vertical
/// reactions against the weight of the whole T. The tendons' anchor forces act at the
/// centre of their default plates ([`anchor_height`]). The cantilever is statically
/// determinate, so creep between pairs changes only the tendon forces, which the statics
/// reads from the monitors. Tolerances: N 0.2 % of the prestress (measured 0.05 %); M 2 % of
/// the moment scale w L²/2 + W L and V 3 % (measured 1.3 % and 0.3 % for M, 0.8 % and
/// 2.4 % for V with two and three pairs): the section is a Gauss column 0.875 m from a dry
/// joint, whose keyed contact passes the shear at its Lobatto points, between the
/// traveller's point load and the anchors; Gauss-point stresses of 1.75 m Q8 elements there
/// are not pointwise in equilibrium. The fixity's reactions are global equilibrium: 1e-6
/// (the solver's tolerance).
#[test]
fn cantilever_section_forces_follow_statics_at_every_stage() {
    let tmp = TempDir::new("cantilever-statics");
    let xp = 18.0; // P1
    let face = xp + PIER / 2.0;
    let x_s = face + SEG + SEG / 4.0; // centre of the second segment's first element
    let pts = section_points();
    let mut extra = String::new();
    for (i, (y, _)) in pts.iter().enumerate() {
        for c in ["sx", "txy"] {
            extra += &format!(
                "\n[[monitors]]\nname = \"{c}{i}\"\nkind = \"stress\"\ncomponent = \"{c}\"\npoint = [{x_s}, {y}]\n"
            );
        }
    }
    for j in 1..=PAIRS {
        extra += &format!(
            "\n[[monitors]]\nname = \"P{j}\"\nkind = \"tendon_force\"\ntendon = \"P1-{j}\"\n"
        );
    }
    for side in ["left", "right"] {
        extra += &format!(
            "\n[[monitors]]\nname = \"R{side}\"\nkind = \"reaction\"\nsupport = \"fixity P1 {side}\"\ncomponent = \"y\"\n"
        );
    }
    let out = run(&tmp, "bc", &model(&extra));
    let (h, rows) = history(&out);
    let stages = std::fs::read_to_string(out.join("stages.csv")).unwrap();

    let area: f64 = BANDS.iter().map(|(w, d, _)| w * d).sum();
    let mut y0 = 0.0;
    let mut first_moment = 0.0;
    for (w, d, _) in BANDS {
        first_moment += w * d * (y0 + d / 2.0);
        y0 += d;
    }
    let yc = first_moment / area;
    let w = RHO * G * area;
    let spacing = SEG / 4.0; // node columns of a Q8 segment with nx_per_segment = 2
    let mut checked = 0;
    for line in stages.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (name, last) = (f[1], f[5].parse::<usize>().unwrap());
        let pairs = if let Some(j) = name.strip_prefix("place pair ") {
            j.parse::<usize>().unwrap()
        } else if let Some(j) = name.strip_prefix("cantilevers creep ") {
            j.parse::<usize>().unwrap() - 1
        } else if name == "closures harden" {
            PAIRS
        } else {
            continue;
        };
        if pairs < 2 {
            continue; // the section is in the second pair
        }
        let r = &rows[last - 1];
        let (mut n, mut m, mut v) = (0.0, 0.0, 0.0);
        for (i, (y, wa)) in pts.iter().enumerate() {
            let sx = r[col(&h, &format!("sx{i}"))];
            n += wa * sx;
            m += wa * sx * (y - yc);
            v += wa * r[col(&h, &format!("txy{i}"))];
        }
        let tip = face + pairs as f64 * SEG;
        let l = tip - x_s;
        let x_t = tip - spacing;
        let forces: Vec<f64> = (2..=pairs).map(|j| r[col(&h, &format!("P{j}"))]).collect();
        let p: f64 = forces.iter().sum();
        let n_ref = -p;
        let m_ref = w * l * l / 2.0 + TRAVELLER * (x_t - x_s) - p * (anchor_height() - yc);
        let v_ref = w * l + TRAVELLER;
        let scale = w * l * l / 2.0 + TRAVELLER * l;
        assert!(
            (n - n_ref).abs() <= 2e-3 * p,
            "{name}: N = {n:.1} N against −ΣP = {n_ref:.1} N"
        );
        assert!(
            (m - m_ref).abs() <= 2e-2 * scale,
            "{name}: M = {m:.1} N·m against statics {m_ref:.1} N·m (scale {scale:.1})"
        );
        // τxy on the cut face of the outboard part carries its load upwards: V = −∫τ dA
        // with the outward normal −x.
        assert!(
            (-v - v_ref).abs() <= 3e-2 * v_ref,
            "{name}: V = {:.1} N against w L + W = {v_ref:.1} N",
            -v
        );
        let reaction = r[col(&h, "Rleft")] + r[col(&h, "Rright")];
        let weight = w * (PIER + 2.0 * pairs as f64 * SEG) + 2.0 * TRAVELLER;
        assert!(
            (reaction - weight).abs() <= 1e-6 * weight,
            "{name}: fixity reactions {reaction:.1} N against the T's weight {weight:.1} N"
        );
        checked += 1;
    }
    // Pairs 2 and 3 placed, the two creep periods between and after them, the closures'
    // hardening.
    assert_eq!(checked, 4, "stages checked");
}

/// Segment lengths of the test girder, left to right [m]: end segment, closure, the arms and
/// pier segments of P1 and P2 with the main span's closure between, closure, end segment.
fn segment_lengths() -> Vec<f64> {
    let mut l = vec![2.0, CLOSURE];
    for _ in 0..2 {
        l.extend([SEG; PAIRS]);
        l.push(PIER);
        l.extend([SEG; PAIRS]);
        l.push(CLOSURE);
    }
    l.push(2.0);
    l
}

/// The casting curve closes the profile: the deck's deflection at 30 years in a run without
/// camber, taken as the camber c(x) = −u(x) (one point per element column) of a rerun,
/// leaves the rerun's deck within 2 mm of its design level everywhere (the issue's
/// tolerance; what remains is the change of geometry the camber makes — the raised girder
/// is a slightly different structure), and within 5 % of the largest camber. The camber is
/// 5.6 mm at most here (the deck without it misses its level by more than the tolerance);
/// measured: the rerun's deck within 0.0074 mm of its level.
#[test]
fn casting_curve_closes_the_deck_profile_in_a_rerun() {
    let tmp = TempDir::new("cantilever-camber");
    let depth: f64 = BANDS.iter().map(|b| b.1).sum();
    let mut xs = Vec::new();
    let mut x = -0.5;
    for len in segment_lengths() {
        for k in 0..2 {
            xs.push(x + len * k as f64 / 2.0);
        }
        x += len;
    }
    xs.push(x);
    assert!(
        (x - 66.5).abs() < 1e-9,
        "the girder ends at 66.5 m, not {x}"
    );
    let monitors = |camber: &dyn Fn(f64) -> f64| -> String {
        xs.iter()
            .enumerate()
            .map(|(i, x)| {
                format!(
                    "\n[[monitors]]\nname = \"u{i}\"\nkind = \"displacement\"\npoint = [{x}, {}]\ncomponent = \"y\"\n",
                    depth + camber(*x)
                )
            })
            .collect()
    };
    let years = "\n[[steps]]\nname = \"30 years\"\nkind = \"time\"\nto = 10958.0\n";
    let deck = |out: &Path| -> Vec<f64> {
        let (h, rows) = history(out);
        let last = rows.last().unwrap();
        (0..xs.len())
            .map(|i| last[col(&h, &format!("u{i}"))])
            .collect()
    };
    let plain = model(&format!("{}{years}", monitors(&|_| 0.0)));
    let u0 = deck(&run(&tmp, "plain", &plain));
    let camber: Vec<[f64; 2]> = xs.iter().zip(&u0).map(|(x, u)| [*x, -u]).collect();
    let largest = u0.iter().fold(0.0_f64, |a, u| a.max(u.abs()));
    // Without the camber the deck would miss its level by more than the tolerance.
    assert!(
        largest > 4e-3,
        "the deck moves {largest} m at most: no test"
    );
    let c = |x: f64| {
        let i = xs.iter().position(|&xi| (xi - x).abs() < 1e-9).unwrap();
        camber[i][1]
    };
    let list: Vec<String> = camber
        .iter()
        .map(|p| format!("[{}, {}]", p[0], p[1]))
        .collect();
    let cambered = model(&format!("{}{years}", monitors(&c))).replace(
        "segment_age = 60.0",
        &format!("segment_age = 60.0\ncamber = [{}]", list.join(", ")),
    );
    let u1 = deck(&run(&tmp, "cambered", &cambered));
    let mut worst = 0.0_f64;
    for (i, x) in xs.iter().enumerate() {
        let level = c(*x) + u1[i];
        worst = worst.max(level.abs());
        assert!(
            level.abs() <= 2e-3 && level.abs() <= 0.05 * largest,
            "x = {x}: the deck ends {:.2} mm off its design level (camber {:.2} mm)",
            level * 1e3,
            c(*x) * 1e3
        );
    }
}

/// The moment creep moves into a girder made continuous (the change of statical system):
/// the cantilevers and the side spans' ends are loaded at t0 (segments 7 days old, the pairs
/// placed within 0.003 d), the closures join them at t1 = t0 + 7 d, the fixities and the
/// falsework go. For homogeneous creep every support reaction then drifts as ΔR(t) = C X(t),
/// where the restraint X builds up against the mismatch the loads of t0 keep creating on the
/// old system: ∫ J(t, s) dX(s) = J(t, t0) − J(t1, t0) from t1, C depending only on the
/// statics. So the drift's ratios at two times are X's ratios. Two references, both with
/// J (and the relaxation function) from tests/common/mc90.rs, MC90 typed again from the code
/// text, not the library: that integral equation solved step by step (trapezoidal rule,
/// 40 points a decade), and the ageing-coefficient method of Trost and Bažant,
/// X = [J(t, t0) − J(t1, t0)] / J̃(t, t1), J̃ = [1 + χ φ(t, t1)] / E(t1), χ from R(t, t1)
/// (docs/theory-stages.md §5). Glued joints (no prestress needed), 0.5 m closures so that
/// their younger concrete (7 d at t1 against 14) is 2 % of the main span. Tolerances: 3 %
/// against the creep integral (the program's chain fits J to a few per cent, the closures
/// are younger; measured +2.1 % and +2.5 % at 300 and 3000 d over 30 d); 7 % against the
/// ageing-coefficient method, an approximation of that integral which the test's own
/// solution puts 2.5 % and 3.7 % below it here (measured +4.7 % and +6.5 %).
#[test]
fn creep_after_closure_follows_the_ageing_coefficient_method() {
    use common::mc90;
    use segfem::materials::mc90_time::{CementClass, CreepShrinkageParams};
    let tmp = TempDir::new("cantilever-closure-creep");
    let (a0, close_after) = (7.0, 7.0);
    let days = [30.0, 300.0, 3000.0];
    let mut extra = String::from(
        r#"
[[monitors]]
name = "R_P1"
kind = "reaction"
support = "P1"
component = "y"

[[monitors]]
name = "R_A1"
kind = "reaction"
support = "A1"
component = "y"
"#,
    );
    let t1 = 3.0 * 0.001 + close_after;
    for (k, d) in days.iter().enumerate() {
        extra += &format!(
            "\n[[steps]]\nname = \"creep {k}\"\nkind = \"time\"\nto = {}\n",
            t1 + d
        );
    }
    let text = model(&extra)
        .replace("spans = [18.0, 30.0, 18.0]", "spans = [15.5, 27.5, 15.5]")
        .replace(&format!("closure = {CLOSURE}"), "closure = 0.5")
        .replace("segment_age = 60.0", &format!("segment_age = {a0}"))
        .replace(
            "pair_interval = 7.0",
            &format!("pair_interval = 0.001\nclosure_age = {close_after}"),
        )
        .replace(&format!("traveller = {TRAVELLER}\n"), "")
        .replace(
            &format!(
                "tendons = {{ area = {AREA}, height = {HEIGHT}, jacking_stress = 1200e6, wobble = 0.0 }}\n"
            ),
            "",
        )
        .replace(
            "kind = \"keyed\"",
            "kind = \"epoxy\"\ntensile_strength = 100e6\ncohesion = 100e6\nfriction = 1.0",
        );
    assert!(text.contains("closure = 0.5") && !text.contains("tendons ="));
    let out = run(&tmp, "closure", &text);
    let (h, rows) = history(&out);
    let stages = std::fs::read_to_string(out.join("stages.csv")).unwrap();
    let last_row = |step: &str| -> usize {
        let line = stages
            .lines()
            .find(|l| l.split(',').nth(1) == Some(step))
            .unwrap_or_else(|| panic!("no step {step}"));
        line.split(',').nth(5).unwrap().parse().unwrap()
    };
    let at = |step: &str, name: &str| rows[last_row(step) - 1][col(&h, name)];

    // The reference: MC90 for the model's concrete (fcm 48 MPa, RH 70 %, h0 0.30 m, N).
    let p = CreepShrinkageParams::new(48e6, 0.70, 0.30, CementClass::N, 3.0);
    let (age0, age1) = (a0, a0 + t1);
    let xi = |d: f64| -> f64 {
        let age = age1 + d;
        let e1 = 1.0 / mc90::compliance(&p, age1, age1);
        let phi = e1 * mc90::compliance(&p, age, age1) - 1.0;
        // R on a geometric grid of 40 points per decade from 0.01 d to d.
        let n = (40.0 * (d / 0.01).log10()).ceil() as usize;
        let grid: Vec<f64> = (1..=n)
            .map(|k| 0.01 * (d / 0.01).powf(k as f64 / n as f64))
            .collect();
        let r = *mc90::relaxation_function(&p, age1, &grid).last().unwrap();
        let chi = e1 / (e1 - r) - 1.0 / phi;
        let j_adj = (1.0 + chi * phi) / e1;
        (mc90::compliance(&p, age, age0) - mc90::compliance(&p, age1, age0)) / j_adj
    };
    // The same restraint history without the ageing-coefficient approximation: the
    // Volterra equation ∫ J(t, s) dX(s) = J(t, t0) − J(t1, t0) from t1, trapezoidal rule on
    // a geometric grid (as mc90::relaxation_function solves its own).
    let exact = |d: f64| -> f64 {
        let n = (40.0 * (d / 0.01).log10()).ceil() as usize;
        let mut s = vec![age1];
        s.extend((0..=n).map(|k| age1 + 0.01 * (d / 0.01).powf(k as f64 / n as f64)));
        let mut x = vec![0.0];
        for k in 1..s.len() {
            let target = mc90::compliance(&p, s[k], age0) - mc90::compliance(&p, age1, age0);
            let mut lhs = 0.0;
            for j in 1..k {
                lhs += (x[j] - x[j - 1])
                    * 0.5
                    * (mc90::compliance(&p, s[k], s[j]) + mc90::compliance(&p, s[k], s[j - 1]));
            }
            let w = 0.5 * (mc90::compliance(&p, s[k], s[k]) + mc90::compliance(&p, s[k], s[k - 1]));
            x.push(x[k - 1] + (target - lhs) / w);
        }
        *x.last().unwrap()
    };
    for name in ["R_P1", "R_A1"] {
        let r1 = at("strike falsework", name);
        let drift: Vec<f64> = (0..days.len())
            .map(|k| at(&format!("creep {k}"), name) - r1)
            .collect();
        assert!(
            drift[2].abs() > 1e-3 * r1.abs(),
            "{name}: drifts {:.1} N from {r1:.1} N: no redistribution to check",
            drift[2]
        );
        for k in 1..days.len() {
            let ratio = drift[k] / drift[0];
            let volterra = exact(days[k]) / exact(days[0]);
            let aaem = xi(days[k]) / xi(days[0]);
            assert!(
                (ratio / volterra - 1.0).abs() <= 0.03,
                "{name}: drift at {} d over that at {} d = {ratio:.4}, creep integral {volterra:.4}",
                days[k],
                days[0]
            );
            assert!(
                (ratio / aaem - 1.0).abs() <= 0.07,
                "{name}: drift at {} d over that at {} d = {ratio:.4}, ageing-coefficient method {aaem:.4}",
                days[k],
                days[0]
            );
        }
    }
}
