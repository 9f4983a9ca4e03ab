//! Any bytes either read to a mesh that validates or yield an error; nothing panics, hangs or
//! allocates by a count read from the file. The format (MSH 2.2/4.1, ASCII/binary) is in the
//! header, so the seed corpus (`run.sh` copies `../shared/meshes/*.msh` and the test meshes)
//! covers every reader path.
#![no_main]

use libfuzzer_sys::fuzz_target;
use signorini_runtime::fem::mesh::gmsh;

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = gmsh::parse(data, "fuzz.msh") {
        mesh.validate().expect("a mesh the reader returns validates");
        for r in &mesh.regions {
            let _ = mesh.region(&r.name);
        }
    }
});
