//! The OBJ reader on any bytes (gunzipped first when they start with the gzip magic).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = raypack::scene::obj::parse(Path::new("fuzz.obj"), data);
});
