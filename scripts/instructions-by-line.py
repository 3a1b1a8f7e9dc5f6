#!/usr/bin/env python3
"""Instructions per ray by source line (or file) of one callgrind part of a
`raypack bench … --instructions` style run: where a ray's instructions go,
with inlined code charged to the raypack line it was inlined from.

    RAYPACK_CALLGRIND_CHILD=1 valgrind --tool=callgrind --dump-instr=yes \\
        --callgrind-out-file=/tmp/cg.out target/profiling/raypack bench traversal \\
        assets/dragon.ply --engine raypack --threads 1 --size 256x256 --random 65536 --rays ao
    scripts/instructions-by-line.py /tmp/cg.out.1 target/profiling/raypack RAYS [--files] [--top N]

Each `cg.out.K` is one counted part (its `Trigger:` line names it: `raypack/ao/single`
…); RAYS is the number of rays that part traced (the instructions per ray that
`--instructions` prints give it: part total ÷ per-ray figure). Build with
`cargo build --profile profiling` (line tables) and name that binary. Only the
instruction-set entry points (`<Task as simd::isa::EntryPoint>::…`), where the queries run, are
counted. Each address is charged to the innermost frame of its inline chain
(`addr2line -i`) that lies in raypack's `src/` outside `src/simd/` (the
intrinsic wrappers), so a vector add is charged to the kernel line that adds.
"""
import argparse
import collections
import re
import subprocess


def exclusive_counts(path, function_part):
    """Instructions executed per address, in functions whose name contains
    `function_part`, leaving out the costs callgrind books to calls."""
    names, counts = {}, collections.Counter()
    function, address, skip_call_cost = "", 0, False
    for line in open(path):
        line = line.rstrip("\n")
        if not line:
            continue
        if line[0] in "0123456789+-*":
            fields = line.split()
            position = fields[0]
            if position.startswith("0x"):
                address = int(position, 16)
            elif position[0] in "+-":
                address += int(position)
            if skip_call_cost:
                skip_call_cost = False
            elif function_part in function and len(fields) >= 3:
                counts[address] += int(fields[2])
            continue
        key, _, value = line.partition("=")
        # Names are compressed: "(id) name" the first time, "(id)" after.
        match = re.match(r"\((\d+)\)(?: (.*))?", value)
        if key in ("fn", "cfn") and match:
            if match.group(2) is not None:
                names[match.group(1)] = match.group(2)
            if key == "fn":
                function = names.get(match.group(1), "")
        elif key == "calls":
            skip_call_cost = True
    return counts


def raypack_lines(binary, addresses):
    """Per address, the innermost raypack source line of its inline chain."""
    query = ["0x%x" % a for a in addresses]
    output = subprocess.run(
        ["addr2line", "-e", binary, "-i", "-a"] + query, capture_output=True, text=True, check=True
    ).stdout.splitlines()
    chains, current = {}, None
    for line in output:
        if line.startswith("0x"):
            current = int(line, 16)
            chains[current] = []
        else:
            chains[current].append(line.split(" (discriminator")[0])
    lines = {}
    for address, chain in chains.items():
        ours = [f for f in chain if "/src/" in f and "/src/simd/" not in f and "/rustc/" not in f and "/.cargo/" not in f]
        lines[address] = ("src/" + ours[0].split("/src/", 1)[1]) if ours else (chain[0] if chain else "?")
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("dump", help="one callgrind part, e.g. /tmp/cg.out.1")
    parser.add_argument("binary", help="the raypack binary that ran (with line tables)")
    parser.add_argument("rays", type=float, help="rays the part traced")
    parser.add_argument("--files", action="store_true", help="sum by file, not by line")
    parser.add_argument("--top", type=int, default=40, help="rows to print")
    args = parser.parse_args()
    counts = exclusive_counts(args.dump, "simd::isa::EntryPoint>::")
    if not counts:
        raise SystemExit(f"{args.dump}: no instructions in an entry point (run with --dump-instr=yes?)")
    lines = raypack_lines(args.binary, sorted(counts))
    total = collections.Counter()
    for address, count in counts.items():
        where = lines.get(address, "?")
        total[where.split(":")[0] if args.files else where] += count
    print("%8.1f  instructions per ray in all" % (sum(counts.values()) / args.rays))
    for where, count in total.most_common(args.top):
        print("%8.1f  %s" % (count / args.rays, where))


if __name__ == "__main__":
    main()
