#!/usr/bin/env bash
# Coverage-guided fuzzing of every reader (issue 21): builds the fuzz/ targets
# with cargo-fuzz (nightly, AddressSanitizer, debug assertions) and runs each
# for SECONDS under `nice -n 19`, one process at a time, then prints per target
# the executions, libFuzzer's final coverage (cov: edges, ft: features) and the
# crashes found. Exits 1 if any target crashed, hung (past the per-input
# limit below) or went over 1 GiB of memory; the inputs are left in
# fuzz/artifacts/TARGET/.
#
#   scripts/fuzz.sh SECONDS [TARGET...]     (default: every target)
#
# FUZZ_TIMEOUT (seconds; default 1, 10 for the dev build below) is
# libFuzzer's per-input limit. It counts wall-clock time, so on a machine busy
# with other work a niced fuzzer can be starved past 1 s on an input that takes
# milliseconds: give it more there, and replay the corpus on a quiet machine
# with the 1 s limit afterwards (scripts/fuzz.sh 0 replays each target's
# corpus once, in the release build, and runs nothing new).
# FUZZ_CODEGEN_UNITS (default 16) is the build's codegen units, see below.
# FUZZ_BUILD (dev or release) is the build: by default `dev` (optimisation
# level 0) for runs of 1 to 60 seconds, such as CI's, and `release` (level 1)
# for longer ones and for replays (fuzz/Cargo.toml). The dev build compiles in
# a quarter of the time and runs each input 10-40 times slower, so its
# default per-input limit is 10 s.
#
# Corpora: fuzz/corpus/TARGET (git-ignored, grows from run to run) on top of
# the seeds: fuzz/seeds/ (committed), scenes/ and tests/data/.
# Reproduce a crash: fuzz/target/x86_64-unknown-linux-gnu/{debug,release}/TARGET FILE
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ $# -lt 1 || ! $1 =~ ^[0-9]+$ ]]; then
    echo "usage: $0 SECONDS [TARGET...]" >&2
    exit 2
fi
seconds=$1
shift
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then
    targets=(nff obj ply toml gltf rays_csv pipeline)
fi

# The longest input tried, per target: room for a small scene with some of
# everything; longer inputs mostly repeat what shorter ones cover, slower.
declare -A max_len=(
    [nff]=16384 [obj]=16384 [ply]=16384 [toml]=16384 [gltf]=16384 [rays_csv]=4096 [pipeline]=8192
)

# The fuzz build has the portable instruction-set level only (`cfg(fuzzing)`,
# src/simd/isa.rs): it targets baseline x86-64, as the main build does.
# cargo-fuzz compiles in one codegen unit unless told otherwise, which leaves
# every core but one idle while LLVM works through the library; 16 units
# build faster, for fuzzers a little slower per input (FUZZ_CODEGEN_UNITS=1
# for long runs where that matters more than the build).
build=${FUZZ_BUILD:-release}
if [[ -z ${FUZZ_BUILD:-} && $seconds -ge 1 && $seconds -le 60 ]]; then
    build=dev
fi
case $build in
    dev) profile=(--dev) out=debug timeout=${FUZZ_TIMEOUT:-10} ;;
    release) profile=(-O) out=release timeout=${FUZZ_TIMEOUT:-1} ;;
    *)
        echo "FUZZ_BUILD must be dev or release, not $build" >&2
        exit 2
        ;;
esac
(cd fuzz && nice -n 19 cargo +nightly fuzz build "${profile[@]}" -a \
    --codegen-units "${FUZZ_CODEGEN_UNITS:-16}" >&2)
bin_dir=fuzz/target/x86_64-unknown-linux-gnu/$out

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# seeds TARGET DIR: copy the files of scenes/ and tests/data/ that suit TARGET into DIR.
seeds() {
    local pattern
    case $1 in
        nff | pipeline) pattern='scenes/*.nff' ;;
        obj) pattern='tests/data/*.obj' ;;
        ply) pattern='tests/data/*.ply tests/data/*.ply.gz' ;;
        toml) pattern='scenes/*.toml' ;;
        *) pattern='' ;;
    esac
    mkdir -p "$2"
    for f in $pattern; do
        # The big SPD scenes would only be cut at max_len.
        if [[ -f $f && $(stat -c %s "$f") -le 65536 ]]; then cp "$f" "$2/"; fi
    done
}

failed=0
printf '%-10s %12s %8s %8s %8s %s\n' target executions cov ft crashes seconds >"$work/table"
for target in "${targets[@]}"; do
    [[ -n ${max_len[$target]:-} ]] || {
        echo "unknown target $target" >&2
        exit 2
    }
    corpus=fuzz/corpus/$target
    artifacts=fuzz/artifacts/$target
    mkdir -p "$corpus" "$artifacts" "$work/$target"
    seed_dirs=("$work/$target/extra")
    seeds "$target" "$work/$target/extra"
    seed_name=$target
    [[ $target == pipeline ]] && seed_name=nff
    [[ -d fuzz/seeds/$seed_name ]] && seed_dirs+=("fuzz/seeds/$seed_name")
    before=$(find "$artifacts" -type f | wc -l)
    bin=$(realpath "$bin_dir/$target")
    # -jobs=1 -workers=1: one fuzzing process, whose output goes to fuzz-0.log.
    # SECONDS 0: -runs=0 executes the corpus once (libFuzzer reads
    # -max_total_time=0 as no limit at all).
    duration=-max_total_time="$seconds"
    [[ $seconds -eq 0 ]] && duration=-runs=0
    (
        cd "$work/$target"
        nice -n 19 "$bin" "$OLDPWD/$corpus" "${seed_dirs[@]/#fuzz/$OLDPWD/fuzz}" \
            "$duration" -max_len="${max_len[$target]}" \
            -rss_limit_mb=1024 -malloc_limit_mb=1024 -timeout="$timeout" \
            -jobs=1 -workers=1 -print_final_stats=1 \
            -artifact_prefix="$OLDPWD/$artifacts/" >/dev/null 2>&1
    ) || true
    log=$work/$target/fuzz-0.log
    cp "$log" "fuzz/artifacts/$target.log" 2>/dev/null || true
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -n 1)
    last=$(grep -E '^#[0-9]+' "$log" | tail -n 1)
    cov=$(grep -o 'cov: [0-9]*' <<<"$last" | grep -o '[0-9]*$' || true)
    ft=$(grep -o 'ft: [0-9]*' <<<"$last" | grep -o '[0-9]*$' || true)
    if [[ -z $execs ]]; then
        # A crash ends the run before the final stats: the last status line counts.
        execs=$(grep -o '^#[0-9]*' <<<"$last" | tr -d '#' || true)
    fi
    crashes=$(($(find "$artifacts" -type f | wc -l) - before))
    if grep -qE '^==[0-9]+==ERROR|deadly signal|ERROR: libFuzzer' "$log" && [[ $crashes -eq 0 ]]; then
        crashes=1
    fi
    if [[ $crashes -gt 0 ]]; then
        failed=1
        echo "== $target: crash; log in fuzz/artifacts/$target.log, inputs in $artifacts/" >&2
        grep -E 'panicked|ERROR|SUMMARY|Test unit written' "$log" | head -n 8 >&2 || true
    fi
    printf '%-10s %12s %8s %8s %8s %s\n' "$target" "${execs:-?}" "${cov:-?}" "${ft:-?}" "$crashes" "$seconds" \
        >>"$work/table"
done
cat "$work/table"
exit "$failed"
