//! The glTF reader on any bytes, as a `.glb` and as a `.gltf`: a scene or an
//! error naming the file, never a panic. (External buffers are looked for
//! beside `fuzz.gltf`, where there are none.)
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = raypack::scene::gltf::parse(Path::new("fuzz.glb"), data);
});
