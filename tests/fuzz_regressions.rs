//! The fuzz corpus and regression inputs, run on CI without the fuzzer (fuzz/README.md).
//! Every file is fed to the reader its fuzz target exercises; each must give Ok or Err,
//! never a panic. Seeds (fuzz/corpus/: the bundled examples and meshes) must be accepted;
//! regression inputs named `err-*` must be refused with an error.

use std::path::{Path, PathBuf};

fn files(dir: &str) -> Vec<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut v: Vec<PathBuf> = std::fs::read_dir(&d)
        .unwrap_or_else(|e| panic!("{}: {e}", d.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    v.sort();
    v
}

/// What the input must give, from its place and name.
fn expect_err(p: &Path) -> Option<bool> {
    let name = p.file_name()?.to_str()?;
    if name.starts_with("err-") {
        Some(true)
    } else if p.to_str()?.contains("/corpus/") {
        Some(false)
    } else {
        None
    }
}

/// The model-file target: text → validated model, as `segfem check`. The label places the
/// model in examples/ (as the fuzz target does) so that `mesh.file` finds the bundled mesh.
#[test]
fn model_file_inputs() {
    let label = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/fuzz.toml");
    let label = label.to_str().unwrap();
    let mut n = 0;
    for dir in ["fuzz/corpus/model_file", "fuzz/regressions/model_file"] {
        for p in files(dir) {
            let bytes = std::fs::read(&p).unwrap();
            let Ok(text) = std::str::from_utf8(&bytes) else {
                continue;
            };
            let r = std::panic::catch_unwind(|| segfem::input::parse(text, label).map(|_| ()));
            let r = r.unwrap_or_else(|_| panic!("{}: panic", p.display()));
            match expect_err(&p) {
                Some(true) => assert!(r.is_err(), "{}: accepted", p.display()),
                Some(false) => assert!(r.is_ok(), "{}: {}", p.display(), r.unwrap_err()),
                None => {}
            }
            n += 1;
        }
    }
    assert!(n >= 15, "{n} inputs");
}

/// The Gmsh target: .msh bytes (ASCII 2.2/4.1, binary 4.1) → mesh.
#[test]
fn gmsh_inputs() {
    let mut n = 0;
    for dir in ["fuzz/corpus/gmsh", "fuzz/regressions/gmsh"] {
        for p in files(dir) {
            let bytes = std::fs::read(&p).unwrap();
            let r = std::panic::catch_unwind(|| {
                segfem::mesh::gmsh::parse_msh(&bytes, "fuzz.msh").map(|_| ())
            });
            let r = r.unwrap_or_else(|_| panic!("{}: panic", p.display()));
            match expect_err(&p) {
                Some(true) => assert!(r.is_err(), "{}: accepted", p.display()),
                Some(false) => assert!(r.is_ok(), "{}: {}", p.display(), r.unwrap_err()),
                None => {}
            }
            n += 1;
        }
    }
    assert!(n >= 8, "{n} inputs");
}
