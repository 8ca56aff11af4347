//! Model-file text -> validated model, through the same call as `segfem check`.
//! Any input must give Ok or Err, never a panic, hang or out-of-memory.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        // The label places the model in examples/ so that `mesh.file = "gmsh-tapered.msh"`
        // (from the seed corpus) resolves to the bundled mesh.
        let label = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/fuzz.toml");
        let _ = segfem::input::parse(text, label);
    }
});
