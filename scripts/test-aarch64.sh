#!/usr/bin/env bash
# The whole test suite on aarch64 (issue 18: off x86 the hot paths run on the
# portable level, `wide`'s NEON code), cross-compiled and run under qemu-user on
# an x86-64 Debian 12 machine:
#
#   scripts/test-aarch64.sh [CARGO TEST OPTIONS...]     (e.g. --test bvh)
#
# Installs what is missing: the cross linker and libc (gcc-aarch64-linux-gnu,
# libc6-dev-arm64-cross), qemu-user and Rust's aarch64 standard library. The CLI
# tests run the raypack binary as a child process, so the kernel is told to hand
# aarch64 executables to qemu (binfmt_misc, which needs root; the registration
# lasts until reboot). Took 25.5 minutes on 2 cores beside other work
# (2026-11-26: about 12 of building, the rest emulated tests; 385 passed).
set -euo pipefail
cd "$(dirname "$0")/.."

target=aarch64-unknown-linux-gnu
sysroot=/usr/aarch64-linux-gnu

need=()
command -v aarch64-linux-gnu-gcc > /dev/null || need+=(gcc-aarch64-linux-gnu libc6-dev-arm64-cross)
command -v qemu-aarch64 > /dev/null || need+=(qemu-user)
if [[ ${#need[@]} -gt 0 ]]; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}"
fi
rustup target add "$target"

export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_LINKER=aarch64-linux-gnu-gcc
export CARGO_TARGET_AARCH64_UNKNOWN_LINUX_GNU_RUNNER="qemu-aarch64 -L $sysroot"
# For executables started through binfmt_misc (no -L there).
export QEMU_LD_PREFIX=$sysroot

binfmt=/proc/sys/fs/binfmt_misc
if [[ ! -e $binfmt/qemu-aarch64 ]]; then
    mountpoint -q "$binfmt" || mount binfmt_misc -t binfmt_misc "$binfmt"
    # ELF, 64-bit, little-endian, executable or shared object, machine 0xb7 (AArch64);
    # the kernel decodes the \x escapes itself.
    printf '%s' ':qemu-aarch64:M::\x7fELF\x02\x01\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x02\x00\xb7\x00:\xff\xff\xff\xff\xff\xff\xff\x00\xff\xff\xff\xff\xff\xff\xff\xff\xfe\xff\xff\xff:/usr/bin/qemu-aarch64:' \
        > "$binfmt/register"
fi

# The meshes for the tests that load them (as .ci/run does).
scripts/fetch-assets.sh
# Not under an x86 build's target/: nothing to share, and it keeps both.
cargo test --target "$target" --target-dir target/aarch64 "$@" -- --include-ignored
