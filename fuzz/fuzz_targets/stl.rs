//! Fuzzes the STL reader (`read_mesh_bytes` with `MeshFormat::Stl`): no input may panic,
//! hang or exhaust memory; an accepted mesh satisfies the `TriMesh` invariants.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pleat::mesh::io::MeshFormat;

fuzz_target!(|data: &[u8]| {
    pleat_fuzz::read_and_check(data, MeshFormat::Stl);
});
