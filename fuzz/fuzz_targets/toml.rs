//! The TOML scene reader with includes, all in memory: the input is
//! `main.toml`, then any number of included files, each after a line
//! `--- NAME` (any format the reader takes by extension: `a.nff`,
//! `sub/b.toml`, `m.ply.gz`…). Nothing touches the disk.
#![no_main]

use libfuzzer_sys::fuzz_target;
use raypack::scene::loader::InMemory;
use raypack::scene::native::load_from;
use std::path::Path;

const MARK: &[u8] = b"\n--- ";

fuzz_target!(|data: &[u8]| {
    let mut files = InMemory::new();
    let mut rest = data;
    let mut name = b"main.toml".as_slice();
    loop {
        let end = rest.windows(MARK.len()).position(|w| w == MARK);
        let (body, next) = match end {
            Some(i) => (&rest[..i], Some(&rest[i + MARK.len()..])),
            None => (rest, None),
        };
        // A later file of the same name replaces an earlier one.
        let path = Path::new("scenes").join(String::from_utf8_lossy(name).trim());
        files.insert(path, body.to_vec());
        let Some(next) = next else { break };
        let (line, after) = match next.iter().position(|&b| b == b'\n') {
            Some(i) => (&next[..i], &next[i + 1..]),
            None => (next, &[][..]),
        };
        name = line;
        rest = after;
    }
    let _ = load_from(Path::new("scenes/main.toml"), &files);
});
