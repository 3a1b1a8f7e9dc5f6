#!/usr/bin/env bash
# docs/report.html, the page of raypack's measured figures, and its screenshot
# docs/report.png, from the bench results committed in docs/results/*.json.
#
#   scripts/report.sh            regenerate the page and the screenshot
#   scripts/report.sh --measure  measure the results anew first (minutes), then regenerate
#
# The results are `raypack bench … --json` (each with the machine and build it
# ran on). Measuring uses the build with every engine (or the Embree build)
# when there is one, so that the ratios between engines are in the page;
# RAYPACK=path/to/raypack and ENGINES=raypack,embree override the choice. The screenshot needs Debian's
# `chromium` (apt-get install chromium). Every output is written to a temporary
# name and renamed when complete. `cargo build --release --all-features
# --target-dir target/all` builds the binary with every engine.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ -z "${RAYPACK:-}" ]; then
    if [ -x target/all/release/raypack ]; then
        RAYPACK=target/all/release/raypack
    elif [ -x target/embree/release/raypack ]; then
        RAYPACK=target/embree/release/raypack
    else
        cargo build --release --quiet
        RAYPACK=target/release/raypack
    fi
fi
if [ -z "${ENGINES:-}" ]; then
    # Every engine the binary links (`raypack env` lists them).
    ENGINES="$("$RAYPACK" env | sed -n 's/^engines *//p' | tr ' ' ',')"
fi

# into FILE COMMAND...: COMMAND's stdout into FILE, renamed into place when complete.
into() {
    local file=$1
    shift
    "$@" > "$file.tmp"
    mv "$file.tmp" "$file"
}

if [ "${1:-}" = --measure ]; then
    mkdir -p docs/results
    echo "measuring with $RAYPACK, engines $ENGINES" >&2
    into docs/results/kernels.json "$RAYPACK" bench kernels --json
    into docs/results/scene-spd_balls.json "$RAYPACK" bench scene scenes/spd_balls.nff \
        --size 256x256 --threads 1,2 --engine "$ENGINES" --json
    into docs/results/traversal.json "$RAYPACK" bench traversal --sizes 1000,10000,100000 \
        --size 1024x1024 --random 262144 --threads 1,2 --engine "$ENGINES" --json
    # Every ray kind on the SPD balls, a 10^3- and a 10^6-triangle mesh and (once
    # scripts/fetch-assets.sh has run) the dragon, secondary rays from 1024x1024
    # primary hits (256k-ray sets: smaller ones read slowly on some VMs, docs/measurements.md).
    into docs/results/traversal-spd_balls.json "$RAYPACK" bench traversal scenes/spd_balls.nff \
        --size 1024x1024 --random 262144 --threads 1,2 --rounds 6 --engine "$ENGINES" --json
    into docs/results/traversal-mesh.json "$RAYPACK" bench traversal --sizes 1000,1000000 \
        --size 1024x1024 --random 262144 --threads 1,2 --rounds 6 --engine "$ENGINES" --json
    if [ -f assets/dragon.ply ]; then
        into docs/results/traversal-dragon.json "$RAYPACK" bench traversal assets/dragon.ply \
            --size 1024x1024 --random 262144 --threads 1,2 --rounds 6 --engine "$ENGINES" --json
    fi
    # Issue 54's matrix against Embree (tens of minutes); it needs the embree feature.
    case ",$ENGINES," in
    *,embree,*) "$RAYPACK" bench matrix --json docs/results/matrix.json ;;
    *) echo "no docs/results/matrix.json: $RAYPACK has no Embree" >&2 ;;
    esac
elif [ -n "${1:-}" ]; then
    echo "usage: scripts/report.sh [--measure]" >&2
    exit 2
fi

# The timing-annotated renders and cost heat maps the README shows go on the page too.
"$RAYPACK" report docs/results/*.json -o docs/report.html \
    --image docs/render-lecture.png --image docs/render-spd-balls-small-cost.png \
    --image docs/render-dragon-cost.png
echo "wrote docs/report.html" >&2
# Chromium writes PNG only to a name ending in .png.
chromium --headless --disable-gpu --no-sandbox --hide-scrollbars --window-size=1200,2400 \
    --screenshot="$PWD/docs/report.tmp.png" "file://$PWD/docs/report.html" 2> /dev/null
mv docs/report.tmp.png docs/report.png
echo "wrote docs/report.png" >&2
