//! The NFF reader on any bytes: a scene or a `file:line` error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let _ = raypack::scene::nff::parse(Path::new("fuzz.nff"), data);
});
