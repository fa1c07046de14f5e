//! Fuzzes the glTF 2.0 reader, JSON (`.gltf`, buffers as `data:` URIs) and binary (`.glb`):
//! the first input byte picks the format. No input may panic, hang or exhaust memory.
#![no_main]

use libfuzzer_sys::fuzz_target;
use pleat::mesh::io::MeshFormat;

fuzz_target!(|data: &[u8]| {
    if let Some((&which, rest)) = data.split_first() {
        let format = if which & 1 == 0 {
            MeshFormat::Gltf
        } else {
            MeshFormat::Glb
        };
        pleat_fuzz::read_and_check(rest, format);
    }
});
