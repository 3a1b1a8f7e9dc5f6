//! The ray CSV reader on any text.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(rays) = raypack::compare::csv::parse_rays("fuzz.csv", text) {
            // What was read is what the format promises: finite origins, unit directions.
            for ray in rays {
                assert!(ray.origin.is_finite(), "{ray:?}");
                assert!((ray.dir.length() - 1.0).abs() < 1e-3, "{ray:?}");
            }
        }
    }
});
