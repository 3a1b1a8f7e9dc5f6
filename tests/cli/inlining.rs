//! The built binary's instruction-set entry points are compiled whole (#18).
//!
//! The check reads the optimised code, so it runs where the test profile
//! optimises at level 2 or more: `CARGO_PROFILE_TEST_OPT_LEVEL=3 cargo test
//! --test cli inlining`, as CI's Embree stage runs it. At the test profile's
//! own level 1, LLVM leaves even `_mm256_mul_ps` out of line everywhere, so
//! there is nothing to check; the test says so, and fails instead where
//! `RAYPACK_REQUIRE_INLINING_CHECK` is set (CI), so that a build at the wrong
//! level cannot pass it unchecked.

/// No function of raypack calls an x86 intrinsic out of line (which a closure
/// or a function not `#[inline(always)]` under an entry point would cause, at
/// many times the cost) except `nested_transform_packet`, the deliberate break
/// of the packet kernels' recursion (and std's CPU feature detection). Reads
/// the binary's disassembly (`objdump`).
#[cfg(target_arch = "x86_64")]
#[test]
fn entry_points_call_no_intrinsic_out_of_line() {
    let opt_level = env!("RAYPACK_BUILD_OPT_LEVEL");
    if !matches!(opt_level, "2" | "3") {
        assert!(
            std::env::var_os("RAYPACK_REQUIRE_INLINING_CHECK").is_none(),
            "RAYPACK_REQUIRE_INLINING_CHECK is set, but the binary was built at \
             opt-level {opt_level}: build the tests with CARGO_PROFILE_TEST_OPT_LEVEL=3"
        );
        eprintln!(
            "not checked: the binary was built at opt-level {opt_level}, where intrinsics \
             stay out of line anyway (CARGO_PROFILE_TEST_OPT_LEVEL=3 checks it)"
        );
        return;
    }
    let out = std::process::Command::new("objdump")
        .args(["-d", "--no-show-raw-insn", "-C", env!("CARGO_BIN_EXE_raypack")])
        .output()
        .expect("objdump (binutils) is needed to read the binary");
    assert!(out.status.success(), "objdump failed");
    let text = String::from_utf8_lossy(&out.stdout);
    // Allowed: the break above, and std's CPU feature detection.
    let allowed = ["nested_transform_packet", "std_detect::", "compiler_builtins::"];
    let mut function = "";
    let mut offenders = std::collections::BTreeSet::new();
    for line in text.lines() {
        if line.ends_with(">:") {
            function = line;
        } else if line.contains("call")
            && line.contains("core_arch::x86")
            && !allowed.iter().any(|a| function.contains(a))
        {
            offenders.insert(function.to_string());
        }
    }
    assert!(
        offenders.is_empty(),
        "intrinsics called out of line in: {offenders:#?}"
    );
}
