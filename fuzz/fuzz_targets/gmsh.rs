//! Gmsh `.msh` bytes (ASCII 2.2 / 4.1 and binary 4.1) -> mesh. Any input must give Ok or Err,
//! never a panic, hang or out-of-memory.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = segfem::mesh::gmsh::parse_msh(data, "fuzz.msh");
});
