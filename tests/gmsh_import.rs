//! The same segmental beam built by the generator and read from a Gmsh file gives the same
//! results; Gmsh mapping errors are reported clearly.

use segfem::analysis::steps::{self, Observer, Snapshot};
use segfem::mesh::banded::Band;
use segfem::mesh::segmental::generate_segments;
use segfem::model::ElementKind;
use std::fmt::Write;

/// Write a Gmsh 2.2 ASCII file of the decompression example's mesh: Q8 elements in the
/// physical surface "web", joint faces as 3-node lines in curves "J1a"/"J1b", "J2a"/"J2b".
fn msh_text() -> String {
    msh_text_of(ElementKind::Q8)
}

/// As [`msh_text`] with elements of `kind` (Gmsh types 3, 16, 10; joint faces as 2-node
/// lines, type 1, for Q4 and 3-node lines, type 8, otherwise).
fn msh_text_of(kind: ElementKind) -> String {
    let bands = [Band {
        depth: 0.5,
        rows: 8,
        region: 0,
    }];
    let m = generate_segments(0.0, 0.0, &[2.0, 2.0, 2.0], &[8, 8, 8], &bands, kind);
    let quad_type = kind.info().gmsh_type;
    let line_type = if kind.info().order == 1 { 1 } else { 8 };
    let mut s = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n5\n");
    s.push_str(
        "1 1 \"J1a\"\n1 2 \"J1b\"\n1 3 \"J2a\"\n1 4 \"J2b\"\n2 10 \"web\"\n$EndPhysicalNames\n",
    );
    let _ = writeln!(s, "$Nodes\n{}", m.nodes.len());
    for (i, p) in m.nodes.iter().enumerate() {
        let _ = writeln!(s, "{} {} {} 0", i + 1, p[0], p[1]);
    }
    s.push_str("$EndNodes\n$Elements\n");
    let mut lines = Vec::new();
    for (j, joint) in m.joints.iter().enumerate() {
        for f in &joint.faces {
            lines.push((1 + 2 * j as i32, f.a.clone()));
            lines.push((2 + 2 * j as i32, f.b.clone()));
        }
    }
    let _ = writeln!(s, "{}", lines.len() + m.elements.len());
    let mut tag = 1;
    for (phys, nodes) in &lines {
        let ids: Vec<String> = nodes.iter().map(|n| (n + 1).to_string()).collect();
        let _ = writeln!(s, "{tag} {line_type} 2 {phys} {phys} {}", ids.join(" "));
        tag += 1;
    }
    for (nodes, _, seg) in &m.elements {
        let ids: Vec<String> = nodes.iter().map(|n| (n + 1).to_string()).collect();
        let _ = writeln!(s, "{tag} {quad_type} 2 10 {} {}", seg + 100, ids.join(" "));
        tag += 1;
    }
    s.push_str("$EndElements\n");
    s
}

/// The decompression example with its [mesh] table replaced by `mesh`.
fn model_with_mesh(mesh: &str) -> String {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/segmental-decompression.toml"
    ))
    .unwrap();
    let start = text.find("[mesh]").unwrap();
    let end = text.find("[[supports]]").unwrap();
    format!("{}{}\n{}", &text[..start], mesh, &text[end..])
}

#[derive(Default)]
struct Hist(Vec<Vec<f64>>);

impl Observer for Hist {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        let m = s.system.model;
        let mid = m
            .nodes
            .iter()
            .position(|p| (p[0] - 3.0).abs() < 1e-9 && p[1].abs() < 1e-9)
            .unwrap();
        let open = (0..m.joints.len())
            .map(|j| segfem::results::joints::summarise(s.system, j).max_opening)
            .fold(0.0, f64::max);
        self.0.push(vec![
            s.factors[1],
            s.system.displacements()[2 * mid + 1],
            open,
        ]);
        Ok(())
    }
}

fn tmp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("segfem-gmsh-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The decompression beam with Q4, Q8 and Q9 elements, written as a Gmsh file and read
/// back, solved through the opening of its joints: every history value equal to the
/// generator's run of the same element kind (1e-9 relative: the same mesh, numbering and
/// equations; only the text coordinates' round-off differs).
#[test]
fn generated_and_gmsh_meshes_give_the_same_results() {
    for kind in [ElementKind::Q4, ElementKind::Q8, ElementKind::Q9] {
        same_results(kind);
    }
}

fn same_results(kind: ElementKind) {
    let name = format!("{kind:?}");
    let dir = tmp_dir(&format!("same-{name}"));
    std::fs::write(dir.join("beam.msh"), msh_text_of(kind)).unwrap();
    let gmsh_mesh = "[mesh]\ntype = \"gmsh\"\nfile = \"beam.msh\"\njoint_material = \"dry\"\njoints = [{ a = \"J1a\", b = \"J1b\" }, { a = \"J2a\", b = \"J2b\" }]\n";
    let model_path = dir.join("beam.toml");
    std::fs::write(&model_path, model_with_mesh(gmsh_mesh)).unwrap();
    let from_gmsh = segfem::input::load(&model_path).unwrap().model;
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/segmental-decompression.toml"
    ))
    .unwrap();
    let text = if kind == ElementKind::Q8 {
        text
    } else {
        let t = text.replace("element = \"Q8\"", &format!("element = \"{name}\""));
        assert_ne!(t, text);
        t
    };
    let generated = segfem::input::parse(&text, "segmental-decompression.toml")
        .unwrap()
        .model;
    assert_eq!(from_gmsh.interfaces.len(), generated.interfaces.len());
    assert_eq!(from_gmsh.nodes.len(), generated.nodes.len(), "{name}");
    let (mut a, mut b) = (Hist::default(), Hist::default());
    steps::run(&from_gmsh, &mut a).unwrap();
    steps::run(&generated, &mut b).unwrap();
    assert_eq!(a.0.len(), b.0.len());
    assert!(b.0.last().unwrap()[2] > 0.0, "the joints open in this run");
    for (ra, rb) in a.0.iter().zip(&b.0) {
        for k in 0..3 {
            // Same mesh, same numbering up to round-off of the text coordinates.
            assert!(
                (ra[k] - rb[k]).abs() <= 1e-9 * rb[k].abs().max(1e-6),
                "{name}: {ra:?} vs {rb:?}"
            );
        }
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// A Gmsh 2.2 file mixing Q9 (type 10) and T6 (type 9) elements: a 2 m × 1 m block of 2 × 2
/// cells, the left column Q9, each cell of the right column split along its diagonal into
/// two T6 (the cell's centre node their shared mid-side node), every interior node moved.
/// Boundary nodes carry a linear displacement field (point supports): the free interior
/// nodes, on the conforming Q9–T6 interface too, and every Gauss-point stress reproduce it
/// (patch test; tolerances as in tests/verification.rs: 1e-12 m on 1e-3 m, 1e-9 of E ε).
#[test]
fn gmsh_mixed_q9_and_t6_mesh_passes_the_patch_test() {
    let (nx, ny, lx, ly) = (2usize, 2usize, 2.0, 1.0);
    let (gx, gy) = (2 * nx + 1, 2 * ny + 1);
    let id = |i: usize, j: usize| j * gx + i;
    let on_boundary = |i: usize, j: usize| i == 0 || j == 0 || i == gx - 1 || j == gy - 1;
    let mut nodes = Vec::new();
    for j in 0..gy {
        for i in 0..gx {
            let mut p = [
                lx * i as f64 / (gx - 1) as f64,
                ly * j as f64 / (gy - 1) as f64,
            ];
            if !on_boundary(i, j) {
                let k = id(i, j) as f64;
                p[0] += 0.04 * (1.7 * k).sin();
                p[1] += 0.03 * (2.3 * k).cos();
            }
            nodes.push(p);
        }
    }
    let mut elements: Vec<(i64, Vec<usize>)> = Vec::new();
    for r in 0..ny {
        for c in 0..nx {
            let (i, j) = (2 * c, 2 * r);
            let q = [
                id(i, j),
                id(i + 2, j),
                id(i + 2, j + 2),
                id(i, j + 2),
                id(i + 1, j),
                id(i + 2, j + 1),
                id(i + 1, j + 2),
                id(i, j + 1),
                id(i + 1, j + 1),
            ];
            if c == 0 {
                elements.push((ElementKind::Q9.info().gmsh_type, q.to_vec()));
            } else {
                let t6 = ElementKind::T6.info().gmsh_type;
                elements.push((t6, vec![q[0], q[1], q[2], q[4], q[5], q[8]]));
                elements.push((t6, vec![q[0], q[2], q[3], q[8], q[6], q[7]]));
            }
        }
    }
    let mut msh = String::from(
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 10 \"web\"\n$EndPhysicalNames\n",
    );
    let _ = writeln!(msh, "$Nodes\n{}", nodes.len());
    for (k, p) in nodes.iter().enumerate() {
        let _ = writeln!(msh, "{} {:.17e} {:.17e} 0", k + 1, p[0], p[1]);
    }
    let _ = writeln!(msh, "$EndNodes\n$Elements\n{}", elements.len());
    for (k, (t, ns)) in elements.iter().enumerate() {
        let ids: Vec<String> = ns.iter().map(|n| (n + 1).to_string()).collect();
        let _ = writeln!(msh, "{} {t} 2 10 1 {}", k + 1, ids.join(" "));
    }
    msh.push_str("$EndElements\n");
    let field = |p: [f64; 2]| {
        [
            1e-3 + 2e-3 * p[0] - 1e-3 * p[1],
            -5e-4 + 0.5e-3 * p[0] + 1.5e-3 * p[1],
        ]
    };
    let (e, nu) = (30e9, 0.2);
    let mut text = format!(
        "[[materials]]\nname = \"c\"\nkind = \"elastic\"\nE = {e}\nnu = {nu}\n\n[[regions]]\nname = \"web\"\nmaterial = \"c\"\nthickness = 0.3\n\n[mesh]\ntype = \"gmsh\"\nfile = \"mixed.msh\"\n\n"
    );
    for j in 0..gy {
        for i in 0..gx {
            if on_boundary(i, j) {
                let p = nodes[id(i, j)];
                let u = field(p);
                let _ = writeln!(
                    text,
                    "[[supports]]\nname = \"b{i}_{j}\"\npoint = [{:.17e}, {:.17e}]\nux = {:.17e}\nuy = {:.17e}\n",
                    p[0], p[1], u[0], u[1]
                );
            }
        }
    }
    text.push_str("[[load_cases]]\nname = \"none\"\n\n[[steps]]\nname = \"s\"\nkind = \"linear\"\nloads = { none = 1.0 }\n");
    let dir = tmp_dir("mixed-t6");
    std::fs::write(dir.join("mixed.msh"), msh).unwrap();
    let path = dir.join("mixed.toml");
    std::fs::write(&path, text).unwrap();
    let model = segfem::input::load(&path)
        .unwrap_or_else(|e| panic!("{e}"))
        .model;
    let kinds: Vec<ElementKind> = model.elements.iter().map(|e| e.kind).collect();
    assert_eq!(kinds.iter().filter(|k| **k == ElementKind::Q9).count(), 2);
    assert_eq!(kinds.iter().filter(|k| **k == ElementKind::T6).count(), 4);
    let mut last = Last::default();
    steps::run(&model, &mut last).unwrap();
    for (k, p) in model.nodes.iter().enumerate() {
        let u = field(*p);
        assert!(
            (last.u[2 * k] - u[0]).abs() < 1e-12 && (last.u[2 * k + 1] - u[1]).abs() < 1e-12,
            "node {k} at {p:?}: {:?} vs {u:?}",
            &last.u[2 * k..2 * k + 2]
        );
    }
    let eps = [2e-3, 1.5e-3, -1e-3 + 0.5e-3];
    let c = e / (1.0 - nu * nu);
    let sig = [
        c * (eps[0] + nu * eps[1]),
        c * (eps[1] + nu * eps[0]),
        c * (1.0 - nu) / 2.0 * eps[2],
    ];
    assert_eq!(last.stress.len(), 2 * 9 + 4 * 3);
    for s in &last.stress {
        for k in 0..3 {
            assert!((s[k] - sig[k]).abs() < 1e-9 * c * 2e-3, "{s:?} vs {sig:?}");
        }
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// Last converged displacements and Gauss-point stresses.
#[derive(Default)]
struct Last {
    u: Vec<f64>,
    stress: Vec<[f64; 3]>,
}

impl Observer for Last {
    fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
        self.u = s.system.displacements().to_vec();
        let g = &s.system.families.continuum.gauss.committed;
        self.stress = g.iter().map(|p| p.stress).collect();
        Ok(())
    }
}

#[test]
fn unmapped_groups_and_bad_joints_are_clear_errors() {
    let dir = tmp_dir("errors");
    std::fs::write(
        dir.join("beam.msh"),
        msh_text().replace("\"web\"", "\"deck\""),
    )
    .unwrap();
    let mesh = "[mesh]\ntype = \"gmsh\"\nfile = \"beam.msh\"\njoint_material = \"dry\"\njoints = [{ a = \"J1a\", b = \"J1b\" }]\n";
    let p = dir.join("m.toml");
    std::fs::write(&p, model_with_mesh(mesh)).unwrap();
    let e = segfem::input::load(&p)
        .err()
        .expect("unmapped surface")
        .to_string();
    assert!(
        e.contains("mesh.file") && e.contains("'deck' is not mapped"),
        "{e}"
    );
    // Faces that do not face each other: J1a paired with J2b.
    std::fs::write(dir.join("beam.msh"), msh_text()).unwrap();
    let mesh = "[mesh]\ntype = \"gmsh\"\nfile = \"beam.msh\"\njoint_material = \"dry\"\njoints = [{ a = \"J1a\", b = \"J2b\" }]\n";
    std::fs::write(&p, model_with_mesh(mesh)).unwrap();
    let e = segfem::input::load(&p)
        .err()
        .expect("faces apart")
        .to_string();
    assert!(e.contains("mesh.joints[0].b") && e.contains("faces"), "{e}");
    // A group that does not exist.
    let mesh = "[mesh]\ntype = \"gmsh\"\nfile = \"beam.msh\"\njoint_material = \"dry\"\njoints = [{ a = \"J9a\", b = \"J1b\" }]\n";
    std::fs::write(&p, model_with_mesh(mesh)).unwrap();
    let e = segfem::input::load(&p)
        .err()
        .expect("unknown group")
        .to_string();
    assert!(e.contains("mesh.joints[0].a") && e.contains("J9a"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}

/// The Gmsh-made example (prismatic + tapered segment, cantilever): the joint opens at the
/// top when the cantilever moment w·1²/2 cancels the prestress there. Beam theory at the
/// joint (A = 0.15 m², I = 3.125e-3 m⁴, P = 400 kN acting 0.05 m above the joint's centroid):
/// w = (P/A + P e c/I) / (c/(2I)) = 106.7 kN/m; the run uses steps of 10 kN/m.
#[test]
fn gmsh_example_joint_opens_where_beam_theory_says() {
    let path = std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/gmsh-tapered.toml"
    ));
    let model = segfem::input::load(path).unwrap().model;
    #[derive(Default)]
    struct First(Option<f64>, f64);
    impl Observer for First {
        fn increment(&mut self, s: &Snapshot) -> std::io::Result<()> {
            let open = segfem::results::joints::summarise(s.system, 0).max_opening;
            if open > 0.0 && self.0.is_none() {
                self.0 = Some(s.factors[1]);
            }
            if open == 0.0 {
                self.1 = s.factors[1];
            }
            Ok(())
        }
    }
    let mut f = First::default();
    steps::run(&model, &mut f).unwrap();
    let w_open = f.0.expect("the joint opens");
    let w_dec = (400e3 / 0.15 + 400e3 * 0.05 * 0.25 / 3.125e-3) / (0.25 / (2.0 * 3.125e-3)) / 1e3;
    assert!(
        f.1 <= w_dec && w_dec <= w_open,
        "closed at {} kN/m, open at {w_open} kN/m, beam theory {w_dec:.1}",
        f.1
    );
}
