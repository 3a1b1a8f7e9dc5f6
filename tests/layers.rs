//! The module layers of ARCHITECTURE.md, enforced: a module of `src/` uses
//! only modules of lower layers (`crate::NAME` paths in its code, its doc
//! comments and its `#[cfg(test)]` module excepted), a subcommand of
//! `src/cli/` uses only `cli::args`, `cli::stdout` and `cli::error`,
//! never another subcommand, and no two files use each other at any depth
//! (`crate::`, `super::`, `self::` and child-module paths alike; a parent and
//! its child count like any two files). A `super::` path inside an inline
//! module is read from the file's module: write `crate::` paths there.

use std::path::{Path, PathBuf};

/// The layers, bottom first. Keep in step with ARCHITECTURE.md.
const LAYERS: &[&[&str]] = &[
    &[
        "simd",
        "rng",
        "bounds",
        "huge_pages",
        "embree_settings",
        "atomic_file",
        "plural",
        "statistics",
    ],
    &["ray", "environment"],
    &["packet"],
    &["geometry"],
    &["camera"],
    &["scene"],
    &["accel"],
    &["embree"],
    &["engines"],
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
                    // Inside cli, a subcommand uses args, stdout and the error types only.
                    if module == "cli" && rel.parent() == Some(Path::new("cli")) {
                        let sub = after.trim_start_matches("::");
                        let name = &sub[..sub
                            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                            .unwrap_or(sub.len())];
                        let allowed = ["args", "stdout", "error", ""];
                        let is_mod = rel.file_name().is_some_and(|f| {
                            f == "mod.rs" || f == "args.rs" || f == "stdout.rs" || f == "error.rs"
                        });
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

/// The module path of a source file: `src/accel/bvh/leaf.rs` → `accel::bvh::leaf`,
/// `src/accel/mod.rs` → `accel`.
fn module_path(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .filter(|p| p != "mod")
        .collect();
    parts.join("::")
}

/// The text of a file's code without its re-exports (`pub use …;`, any
/// visibility): a parent naming its children's items for its users is no use
/// of them, and a child may use its parent's own items only where the parent
/// uses nothing of the child.
fn without_reexports(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(at) = rest.find("pub") {
        let after = rest[at + 3..].trim_start();
        let after = if after.starts_with('(') {
            after
                .find(')')
                .map_or(after, |close| after[close + 1..].trim_start())
        } else {
            after
        };
        let is_reexport = after.starts_with("use ") && (at == 0 || rest[..at].ends_with(char::is_whitespace));
        out.push_str(&rest[..at]);
        if is_reexport {
            let end = rest[at..].find(';').map_or(rest.len(), |e| at + e + 1);
            rest = &rest[end..];
        } else {
            out.push_str("pub");
            rest = &rest[at + 3..];
        }
    }
    out.push_str(rest);
    out
}

/// Every full path a file's code names, made absolute from the crate root
/// (without `crate::`): `crate::…`, `super::…` and `self::…` paths, and paths
/// through the file's own child modules (`mod leaf;` then `leaf::LeafRef`),
/// with `{…}` groups (nested, across lines) expanded: `crate::a::{b, c::D}` →
/// `a::b`, `a::c::D`. `module` is the file's module path.
fn used_paths(text: &str, module: &str) -> Vec<String> {
    fn group(prefix: &str, rest: &str, out: &mut Vec<String>) -> usize {
        // `rest` starts just after a `{`; returns the bytes read through its `}`.
        let (mut depth, mut start) = (0, 0);
        for (i, c) in rest.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth > 0 => depth -= 1,
                ',' | '}' if depth == 0 => {
                    let item = rest[start..i].trim();
                    if let Some(open) = item.find('{') {
                        let inner = format!("{prefix}{}", item[..open].trim());
                        group(&inner, &item[open + 1..], out);
                    } else if !item.is_empty() {
                        out.push(format!("{prefix}{item}"));
                    }
                    start = i + 1;
                    if c == '}' {
                        return i + 1;
                    }
                }
                _ => {}
            }
        }
        rest.len()
    }
    let is_ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let children: Vec<&str> = text
        .lines()
        .filter_map(|l| {
            let l = l.trim();
            let l = l.strip_prefix("pub ").unwrap_or(l);
            l.strip_prefix("mod ")?.strip_suffix(';')
        })
        .collect();
    let parent = |m: &str| m.rsplit_once("::").map_or(String::new(), |(p, _)| p.to_string());
    let join = |base: &str, rest: &str| {
        if base.is_empty() {
            rest.to_string()
        } else {
            format!("{base}::{rest}")
        }
    };
    let mut out = Vec::new();
    for (i, c) in text.char_indices() {
        // A path starts at an identifier not preceded by `::` or another identifier character.
        if !is_ident(c) || text[..i].ends_with(is_ident) || text[..i].ends_with("::") {
            continue;
        }
        let rest = &text[i..];
        let end = rest
            .find(|c: char| !(is_ident(c) || c == ':'))
            .unwrap_or(rest.len());
        let mut path = &rest[..end];
        if !path.contains("::") {
            continue;
        }
        // Resolve the path's start to a module path from the crate root.
        let mut base = module.to_string();
        let absolute = if let Some(p) = path.strip_prefix("crate::") {
            base.clear();
            p
        } else if path.starts_with("super::") {
            while let Some(p) = path.strip_prefix("super::") {
                base = parent(&base);
                path = p;
            }
            path
        } else if let Some(p) = path.strip_prefix("self::") {
            p
        } else if children
            .iter()
            .any(|child| path.split("::").next() == Some(child))
        {
            path
        } else {
            continue;
        };
        let full = join(&base, absolute);
        if full.ends_with("::") && rest[end..].starts_with('{') {
            group(&full, &rest[end + 1..], &mut out);
        } else {
            out.push(full);
        }
    }
    out
}

/// Files of `src/` that use each other, directly or round a longer loop: the
/// strongly connected components of the file-level graph of the paths their
/// code names ([`used_paths`]; a parent's re-exports are no use), with more
/// than one file. A child and its parent count like any two files: a parent
/// that uses its children and a child that uses its parent are a loop.
fn file_cycles(modules: &[(String, String)]) -> Vec<Vec<String>> {
    let names: Vec<&str> = modules.iter().map(|(m, _)| m.as_str()).collect();
    let index = |path: &str| {
        // The longest prefix of `path` that is a file of its own.
        let parts: Vec<&str> = path.split("::").collect();
        (1..=parts.len())
            .rev()
            .find_map(|k| names.iter().position(|n| *n == parts[..k].join("::")))
    };
    let edges: Vec<Vec<usize>> = modules
        .iter()
        .enumerate()
        .map(|(from, (module, text))| {
            let mut to: Vec<usize> = used_paths(&without_reexports(text), module)
                .iter()
                .filter_map(|p| index(p))
                .filter(|&t| t != from)
                .collect();
            to.sort();
            to.dedup();
            to
        })
        .collect();
    // Tarjan's strongly connected components.
    struct State<'a> {
        edges: &'a [Vec<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        stack: Vec<usize>,
        on_stack: Vec<bool>,
        next: usize,
        found: Vec<Vec<usize>>,
    }
    fn visit(s: &mut State, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        for &w in &s.edges[v] {
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on_stack[w] => s.low[v] = s.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut component = Vec::new();
            loop {
                let w = s.stack.pop().unwrap();
                s.on_stack[w] = false;
                component.push(w);
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                s.found.push(component);
            }
        }
    }
    let n = modules.len();
    let mut s = State {
        edges: &edges,
        index: vec![None; n],
        low: vec![0; n],
        stack: Vec::new(),
        on_stack: vec![false; n],
        next: 0,
        found: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.found
        .into_iter()
        .map(|c| {
            let mut c: Vec<String> = c.into_iter().map(|i| names[i].to_string()).collect();
            c.sort();
            c
        })
        .collect()
}

#[test]
fn no_two_files_use_each_other() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let modules: Vec<(String, String)> = files
        .iter()
        .map(|f| {
            let text = std::fs::read_to_string(f).unwrap();
            let code: Vec<&str> = code_lines(&text).map(|(_, l)| l).collect();
            (module_path(&src, f), code.join("\n"))
        })
        .filter(|(m, _)| m != "lib" && m != "main")
        .collect();
    let cycles = file_cycles(&modules);
    assert!(
        cycles.is_empty(),
        "files that use each other (move what they share below them):\n{}",
        cycles
            .iter()
            .map(|c| c.join(" ↔ "))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

#[test]
fn the_cycle_check_sees_a_loop_through_a_group() {
    let module = |name: &str, text: &str| (name.to_string(), text.to_string());
    let looped = [
        module("a::x", "use crate::a::{\n    y::{Y, Z},\n    w,\n};"),
        module("a::y", "use crate::a::z::Z;"),
        module("a::z", "use crate::a::x::X;"),
        module("a::w", "use crate::a::w2::W;"),
        module("a", "pub use w::V;\nmod w;"),
    ];
    assert_eq!(file_cycles(&looped), [["a::x", "a::y", "a::z"]]);
    assert!(
        file_cycles(&looped[1..]).is_empty(),
        "a parent's re-export of a child's item is no use of it"
    );
}

#[test]
fn the_cycle_check_sees_relative_paths_and_parents() {
    let module = |name: &str, text: &str| (name.to_string(), text.to_string());
    // A parent that calls into its child, and the child that uses the parent's type.
    let hub = [
        module("a", "mod b;\npub struct T;\nfn f() { b::g(); }"),
        module("a::b", "use super::T;\npub fn g() {}"),
    ];
    assert_eq!(file_cycles(&hub), [["a", "a::b"]]);
    let through_self = [
        module("a", "mod b;\nfn f() { self::b::g(); }"),
        module("a::b", "fn g() { crate::a::h(); }"),
    ];
    assert_eq!(file_cycles(&through_self), [["a", "a::b"]]);
    let staircase = [
        module("a", "mod b;\nmod c;\npub use b::T;\nfn f() { c::g(); }"),
        module("a::b", "pub struct T;"),
        module("a::c", "use super::b::T;\npub fn g() {}"),
    ];
    assert!(file_cycles(&staircase).is_empty());
}
