#!/usr/bin/env bash
# Paired run of two raypack binaries on the triangle matrix: each invocation of
# `bench traversal` runs one binary on one scene; the binaries alternate (A B,
# then B A) for ROUNDS rounds, so the machine's drift falls on both alike.
# OLD and NEW are commands, split at spaces, so one binary can run against
# itself with other options (`"raypack --triangle barycentric"`).
# Prints, per scene, ray kind and path (single rays, 8-ray packets), the median
# of NEW ÷ OLD over the rounds, and the geometric mean of all cells.
#
#   scripts/paired-binaries.sh OLD NEW [ROUNDS] [SCENE...]
#
# Used to check that a build change (profile, crate split) leaves the hot paths
# as fast as they were (issue 52: within 2%).
set -euo pipefail
read -ra old <<< "$1"
read -ra new <<< "$2"
rounds=${3:-5}
shift $(( $# >= 3 ? 3 : $# ))
scenes=("$@")
if [[ ${#scenes[@]} -eq 0 ]]; then
    scenes=(gen:gears gen:tetra gen:teapot gen:mount gen:mesh:10000 gen:mesh:100000 gen:mesh:1000000)
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
echo "CPU: $(grep -m1 "model name" /proc/cpuinfo | cut -d: -f2- | sed "s/^ *//"); kernels: $("${new[@]}" env | sed -n "s/^isa (kernels) *//p")"
for ((r = 0; r < rounds; r++)); do
    for scene in "${scenes[@]}"; do
        if ((r % 2 == 0)); then order=(old new); else order=(new old); fi
        for which in "${order[@]}"; do
            bin=("${old[@]}")
            [[ $which == new ]] && bin=("${new[@]}")
            "${bin[@]}" bench traversal "$scene" --size 512x512 --random 65536 --rounds 3 --json \
                > "$out/$which.$r.${scene//[:\/]/_}.json"
        done
    done
    echo "round $((r + 1)) of $rounds done" >&2
done
python3 - "$out" "$rounds" <<'PY'
import glob, json, math, os, statistics, sys
out, rounds = sys.argv[1], int(sys.argv[2])
cells = {}
for path in glob.glob(os.path.join(out, "*.json")):
    which, r, _ = os.path.basename(path).split(".", 2)
    row = json.load(open(path))["rows"][0]
    for kind in row["kinds"]:
        for p in ("single", "packet"):
            key = (row["scene"], kind["kind"], p)
            cells.setdefault(key, {}).setdefault(int(r), {})[which] = kind[p + "_mrays"]["median"]
ratios = []
print(f"{'scene':<22} {'kind':<8} {'path':<7} new/old (median of {rounds} paired rounds)")
for (scene, kind, p), by_round in sorted(cells.items()):
    rs = [v["new"] / v["old"] for v in by_round.values() if "new" in v and "old" in v]
    m = statistics.median(rs)
    ratios.append(m)
    print(f"{scene:<22} {kind:<8} {p:<7} {m:.3f}")
print(f"geometric mean of {len(ratios)} cells: {math.exp(sum(map(math.log, ratios)) / len(ratios)):.3f}")
PY
