//! The PLY reader on any bytes: ASCII, binary of either byte order, and gzip
//! (the reader gunzips whatever starts with the gzip magic).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = raypack::scene::ply::parse(Path::new("fuzz.ply"), data);
});
