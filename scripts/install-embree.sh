#!/usr/bin/env bash
# Install Embree 4 for raypack's `embree` feature and print the directory that
# holds libembree4.so as the last line of stdout (progress goes to stderr):
#
#   export EMBREE4_LIB_DIR="$(scripts/install-embree.sh | tail -n 1)"
#   cargo test --features embree
#
# Idempotent and cached. In order of preference:
#   1. $EMBREE4_LIB_DIR, if it already holds libembree4.so;
#   2. a system Embree 4 already installed, or the wheel below already cached;
#   3. the distribution's Embree 4 (Debian 13+ packages it as libembree-dev),
#      installed with apt-get when the candidate version is 4.x;
#   4. Embree 4.4.0 built for manylinux (glibc >= 2.27, with its own oneTBB), taken
#      from the PyPI wheel embreex==4.4.0.post1 (Debian 12 packages only Embree
#      3.13.5), unpacked once into ~/.cache/raypack/embree-4.4.0.
#
# The `embree4-sys` crate runs bindgen, which also needs libclang (libclang-dev).
set -euo pipefail

log() { echo "install-embree: $*" >&2; }

has_lib() { [[ -n "$1" && -e "$1/libembree4.so" ]]; }

# 1. An explicit directory.
if has_lib "${EMBREE4_LIB_DIR:-}"; then
    log "using EMBREE4_LIB_DIR"
    echo "$EMBREE4_LIB_DIR"
    exit 0
fi

# 2. An installed system Embree 4 (its linker name comes with the -dev package), or the cache.
system_dir() {
    local dir
    for dir in /usr/lib/x86_64-linux-gnu /usr/lib64 /usr/lib /usr/local/lib; do
        if has_lib "$dir"; then
            echo "$dir"
            return 0
        fi
    done
    return 1
}
if dir="$(system_dir)"; then
    log "using the system's Embree 4 in $dir"
    echo "$dir"
    exit 0
fi
version="4.4.0"
wheel="embreex-4.4.0.post1-cp311-cp311-manylinux_2_27_x86_64.manylinux_2_28_x86_64.whl"
sha256="2cd0f7d5c6342e6247e31f700761689cae7829454d8c6de0c41e62124a023e1f"
cache="${XDG_CACHE_HOME:-$HOME/.cache}/raypack"
dest="$cache/embree-$version"
if has_lib "$dest"; then
    log "using the cached Embree $version in $dest"
    echo "$dest"
    exit 0
fi
if command -v apt-cache > /dev/null; then
    candidate="$(apt-cache policy libembree-dev 2> /dev/null | awk '/Candidate:/ { print $2 }')"
    if [[ "$candidate" == 4.* ]]; then
        log "installing libembree-dev $candidate with apt-get"
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libembree-dev >&2
        if dir="$(system_dir)"; then
            echo "$dir"
            exit 0
        fi
        log "libembree-dev installed but libembree4.so not found; falling back to the wheel"
    else
        log "the distribution packages libembree-dev '${candidate:-none}', not 4.x: using the PyPI wheel"
    fi
fi

# 4. The manylinux build inside the embreex wheel, downloaded once.

mkdir -p "$cache"
work="$(mktemp -d "$cache/.embree-download.XXXXXX")"
trap 'rm -rf "$work"' EXIT
log "downloading $wheel"
python3 -m pip download --quiet --no-deps --only-binary=:all: \
    --platform manylinux_2_28_x86_64 --python-version 3.11 --implementation cp --abi cp311 \
    --dest "$work" "embreex==4.4.0.post1" >&2
echo "$sha256  $work/$wheel" | sha256sum --check --status || {
    log "sha256 mismatch for $wheel: refusing to use it"
    exit 1
}
# Unpack only the shared libraries: libembree4-<hash>.so.4 and its libtbb.
python3 - "$work/$wheel" "$work/lib" << 'EOF'
import pathlib, sys, zipfile
out = pathlib.Path(sys.argv[2])
out.mkdir()
with zipfile.ZipFile(sys.argv[1]) as wheel:
    for name in wheel.namelist():
        if name.startswith("embreex.libs/") and not name.endswith("/"):
            (out / pathlib.Path(name).name).write_bytes(wheel.read(name))
EOF
shopt -s nullglob
libs=("$work"/lib/libembree4-*.so.4)
if [[ ${#libs[@]} -ne 1 ]]; then
    log "expected one libembree4-*.so.4 in the wheel, found ${#libs[@]}"
    exit 1
fi
# The linker looks for libembree4.so; the loader then finds the library's own
# (hashed) soname and its libtbb next to it.
ln -s "$(basename "${libs[0]}")" "$work/lib/libembree4.so"
# Publish atomically, so an interrupted run never leaves a half-filled cache.
rm -rf "$dest"
mv "$work/lib" "$dest"
log "Embree $version unpacked into $dest"
echo "$dest"
