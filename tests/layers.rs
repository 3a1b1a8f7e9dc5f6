//! The module layers of ARCHITECTURE.md, enforced: a module of `src/` uses
//! only modules of lower layers (`crate::NAME` paths in its code, its doc
//! comments and its `#[cfg(test)]` module excepted), and a subcommand of
//! `src/cli/` uses only `cli::args` and `cli`'s error types, never another
//! subcommand.

use std::path::{Path, PathBuf};

/// The layers, bottom first. Keep in step with ARCHITECTURE.md.
const LAYERS: &[&[&str]] = &[
    &[
        "simd",
        "rng",
        "bounds",
        "huge_pages",
        "engine",
        "atomic_file",
        "plural",
        "statistics",
        "environment",
    ],
    &["ray"],
    &["packet"],
    &["geometry"],
    &["camera"],
    &["scene"],
    &["accel"],
    &["embree"],
    &["render"],
    &["picture"],
    &["compare"],
    &["bench"],
    &["report"],
    &["cli"],
];

fn layer(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code lines of a source file: up to its `#[cfg(test)]` module, without
/// comment lines.
fn code_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .take_while(|(_, l)| l.trim() != "#[cfg(test)]")
        .filter(|(_, l)| !l.trim_start().starts_with("//"))
        .map(|(i, l)| (i + 1, l))
}

/// The names after each `crate::` on a line.
fn crate_paths(line: &str) -> impl Iterator<Item = (&str, &str)> {
    line.match_indices("crate::").map(move |(i, _)| {
        let rest = &line[i + "crate::".len()..];
        let end = rest
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        (&rest[..end], &rest[end..])
    })
}

#[test]
fn no_module_uses_a_module_above_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let mut violations = Vec::new();
    for file in &files {
        let rel = file.strip_prefix(&src).unwrap();
        let top = rel.components().next().unwrap().as_os_str().to_string_lossy();
        let module = top.trim_end_matches(".rs");
        if module == "lib" || module == "main" {
            continue;
        }
        let own = layer(module).unwrap_or_else(|| panic!("src/{top} is in no layer: add it to LAYERS"));
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in code_lines(&text) {
            for (used, after) in crate_paths(line) {
                if used == module {
                    // Inside cli, a subcommand uses args and the error types only.
                    if module == "cli" && rel.parent() == Some(Path::new("cli")) {
                        let sub = after.trim_start_matches("::");
                        let name = &sub[..sub
                            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                            .unwrap_or(sub.len())];
                        let allowed = ["args", "CliError", "CliResult", ""];
                        let is_mod = rel.file_name().is_some_and(|f| f == "mod.rs" || f == "args.rs");
                        if !is_mod
                            && !allowed.contains(&name)
                            && name != rel.file_stem().unwrap().to_string_lossy()
                        {
                            violations.push(format!(
                                "src/{}:{n}: a subcommand uses cli::{name}",
                                rel.display()
                            ));
                        }
                    }
                    continue;
                }
                match layer(used) {
                    Some(l) if l < own => {}
                    Some(_) => violations.push(format!(
                        "src/{}:{n}: {module} uses {used}, not below it",
                        rel.display()
                    )),
                    None => {
                        violations.push(format!("src/{}:{n}: crate::{used} is in no layer", rel.display()))
                    }
                }
            }
        }
    }
    assert!(
        violations.is_empty(),
        "layer violations:\n{}",
        violations.join("\n")
    );
}

#[test]
fn the_check_catches_an_upward_use() {
    // The parsing itself: an upward path is seen, comments and tests are not.
    let text = "use crate::render::x;\n// use crate::cli::y;\n#[cfg(test)]\nuse crate::cli::z;\n";
    let seen: Vec<_> = code_lines(text)
        .flat_map(|(_, l)| crate_paths(l).map(|(m, _)| m))
        .collect();
    assert_eq!(seen, ["render"]);
    assert!(layer("render") > layer("scene"));
}
