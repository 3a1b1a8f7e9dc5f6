//! The built binary's instruction-set entry points are compiled whole (#18).
//!
//! An entry point (`<Task as raypack::simd::isa::EntryPoint>::<level>`,
//! `#[target_feature]`)
//! runs the traversal and kernels on its level's lane types. Everything under
//! it must be inlined into it: a closure or function that is not
//! `#[inline(always)]` becomes a function of its own, compiled without the
//! level's features, where LLVM cannot inline the level's SIMD intrinsics, so
//! each one costs a call. The check reads the binary's disassembly
//! (`objdump`), at any optimisation level from 1:
//!
//! - At level 1 (the test profile's), LLVM inlines the `#[inline(always)]`
//!   code but leaves every intrinsic out of line, so the calls show what was
//!   compiled where: no function other than the entry points may call an
//!   intrinsic beyond baseline x86-64 (SSE, SSE2), and each entry point calls
//!   only its own level's.
//! - At levels 2 and 3 the intrinsics are inlined wherever they can be, so no
//!   function may call one out of line.
//!
//! Either way `nested_transform_packet`, the deliberate break of the packet
//! kernels' recursion, is the one exception, and the check requires it to be
//! seen breaking the rule: that proves it reads this build's calls correctly.

use std::collections::{BTreeMap, BTreeSet, HashMap};

/// The deliberate break of the packet kernels' recursion (`#[inline(never)]`).
const BREAK: &str = "nested_transform_packet";

/// Functions of std allowed to call intrinsics out of line: its CPU feature
/// detection, its builtins, and the intrinsics themselves.
const ALLOWED: [&str; 3] = ["std_detect::", "compiler_builtins::", "core_arch::"];

/// `core::arch`'s x86 modules that baseline x86-64 has (what code outside
/// the entry points may use).
const BASELINE: [&str; 2] = ["sse", "sse2"];

/// The `core::arch` modules an entry point may not call into, by level:
/// those of higher levels than its own.
fn forbidden_in(level: &str) -> &'static [&'static str] {
    match level {
        "avx2" => &["avx512"],
        _ => &[],
    }
}

/// The intrinsics a function calls out of line, as `core::arch` module
/// (`avx2`, `sse41`, …) and name.
type Calls = BTreeSet<(String, String)>;

/// Every function of `binary` that calls an x86 intrinsic, with its calls.
fn intrinsic_calls(binary: &str) -> BTreeMap<String, Calls> {
    let text = objdump(&["-d", "--no-show-raw-insn", "-C", binary]);
    // Calls into another codegen unit go through the global offset table
    // (`call *0x…(%rip)  # 1234 <_DYNAMIC+0x…>`): a slot holds its function's
    // address as a relative relocation's addend.
    let slots: HashMap<u64, u64> = objdump(&["-R", binary])
        .lines()
        .filter_map(|line| {
            let mut fields = line.split_whitespace();
            let slot = u64::from_str_radix(fields.next()?, 16).ok()?;
            (fields.next()? == "R_X86_64_RELATIVE").then_some(())?;
            let target = fields.next()?.strip_prefix("*ABS*+0x")?;
            Some((slot, u64::from_str_radix(target, 16).ok()?))
        })
        .collect();
    let functions: HashMap<u64, &str> = text
        .lines()
        .filter_map(|line| {
            let (address, name) = line.strip_suffix(">:")?.split_once(" <")?;
            Some((u64::from_str_radix(address, 16).ok()?, name))
        })
        .collect();
    let mut calls = BTreeMap::<String, Calls>::new();
    let mut function = "";
    for line in text.lines() {
        if line.ends_with(">:") {
            function = line;
            continue;
        }
        if !line.contains("\tcall") {
            continue;
        }
        let callee = match line.split_once("# ") {
            Some((_, slot)) => slot
                .split_whitespace()
                .next()
                .and_then(|a| u64::from_str_radix(a, 16).ok())
                .and_then(|a| slots.get(&a))
                .and_then(|target| functions.get(target))
                .copied()
                .unwrap_or(""),
            None => line
                .split_once('<')
                .map_or("", |(_, name)| name.trim_end_matches('>')),
        };
        // `core::core_arch::x86[_64]::<module>::<intrinsic>`
        let Some(at) = callee.find("core_arch::x86") else {
            continue;
        };
        let mut path = callee[at..].split("::").skip(2);
        if let (Some(module), Some(name)) = (path.next(), path.next()) {
            calls
                .entry(function.to_string())
                .or_default()
                .insert((module.to_string(), name.to_string()));
        }
    }
    calls
}

/// `objdump`'s output for `args`.
fn objdump(args: &[&str]) -> String {
    let out = std::process::Command::new("objdump")
        .args(args)
        .output()
        .expect("objdump (binutils) is needed to read the binary");
    assert!(out.status.success(), "objdump {args:?} failed");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The x86 level of an entry point's name (`…simd::isa::EntryPoint>::avx2>:`),
/// if it is one. The portable level's entry point is checked as every other
/// function is: baseline intrinsics only.
fn entry_level(function: &str) -> Option<&str> {
    const ENTRY: &str = "simd::isa::EntryPoint>::";
    let rest = &function[function.find(ENTRY)? + ENTRY.len()..];
    let level = rest.split(|c: char| !c.is_ascii_alphanumeric()).next()?;
    (level != "portable").then_some(level)
}

#[cfg(target_arch = "x86_64")]
#[test]
fn entry_points_call_no_intrinsic_out_of_line() {
    let opt_level = env!("RAYPACK_BUILD_OPT_LEVEL");
    if !matches!(opt_level, "1" | "2" | "3") {
        assert!(
            std::env::var_os("RAYPACK_REQUIRE_INLINING_CHECK").is_none(),
            "RAYPACK_REQUIRE_INLINING_CHECK is set, but the binary was built at \
             opt-level {opt_level}, where LLVM inlines nothing to check"
        );
        eprintln!("not checked: the binary was built at opt-level {opt_level}");
        return;
    }
    let optimised = opt_level != "1";
    let calls = intrinsic_calls(env!("CARGO_BIN_EXE_raypack"));
    let mut offenders = Vec::new();
    let mut break_seen = false;
    let mut entries = BTreeSet::new();
    for (function, called) in &calls {
        if function.contains(BREAK) {
            break_seen |= called
                .iter()
                .any(|(module, _)| !BASELINE.contains(&module.as_str()));
            continue;
        }
        if ALLOWED.iter().any(|a| function.contains(a)) {
            continue;
        }
        // The calls that break the rule: at levels 2 and 3 any call; at
        // level 1 an entry point's into a higher level, and any other
        // function's beyond baseline.
        let breaking: Vec<_> = match entry_level(function) {
            Some(level) => {
                entries.insert(level.to_string());
                let forbidden = forbidden_in(level);
                called
                    .iter()
                    .filter(|(module, _)| optimised || forbidden.iter().any(|f| module.starts_with(f)))
                    .collect()
            }
            None => called
                .iter()
                .filter(|(module, _)| optimised || !BASELINE.contains(&module.as_str()))
                .collect(),
        };
        if !breaking.is_empty() {
            offenders.push(format!("{function} calls {breaking:?}"));
        }
    }
    assert!(
        offenders.is_empty(),
        "intrinsics called out of line (opt-level {opt_level}):\n{}",
        offenders.join("\n")
    );
    assert!(
        break_seen,
        "{BREAK} was not seen calling SIMD intrinsics out of line: the check no \
         longer reads this build's calls ({} functions seen calling intrinsics)",
        calls.len()
    );
    if !optimised {
        // At level 1 some entry points call intrinsics of their own level out
        // of line (the AVX2 level's, today), so the check is seen to read
        // entry points; which level's do depends on what LLVM leaves unmerged.
        assert!(
            entries
                .iter()
                .all(|level| ["avx2", "avx512"].contains(&level.as_str()))
                && !entries.is_empty(),
            "entry points seen: {entries:?}"
        );
    }
}
