#!/usr/bin/env python3
"""docs/figures/query_rounds.py ROUNDS REPEATS LABEL=BINARY... -- MAP...

Interleaved A/B timing of warm region queries on a busy machine: each round runs every
query_time binary (docs/figures/query_time.cpp linked against one library build; see
query_time.sh's link step) once for REPEATS queries on the maps, in turn; prints per binary
and map the minimum and median over the ROUNDS rounds of each round's medians (the minimum
is the figure least disturbed by other load on the machine), and the cells checksum, which
must agree between builds that answer the same regions.
"""
import collections
import re
import subprocess
import sys


def main(argv):
    if "--" not in argv or len(argv) < 5:
        sys.exit(__doc__)
    cut = argv.index("--")
    rounds, repeats = int(argv[1]), int(argv[2])
    binaries = [a.split("=", 1) for a in argv[3:cut]]
    maps = argv[cut + 1:]
    line = re.compile(r"(\S+): encode (\S+)\s+inference (\S+)\s+filter (\S+)\s+query (\S+) ms.*cells (\d+)")
    runs = collections.defaultdict(list)
    cells = collections.defaultdict(set)
    for _ in range(rounds):
        for label, binary in binaries:
            out = subprocess.run([binary, str(repeats), *maps], check=True, capture_output=True, text=True).stdout
            for m in line.finditer(out):
                runs[(label, m[1])].append(tuple(float(x) for x in m.groups()[1:5]))
                cells[(label, m[1])].add(m[6])
    print(f"{rounds} rounds x {repeats} queries per binary and map; ms, min / median of the rounds' medians")
    print("| build | map | encode | inference | filter | whole query | cells |")
    print("|---|---|---|---|---|---|---|")
    for (label, path), v in sorted(runs.items(), key=lambda kv: (kv[0][1], kv[0][0])):
        cols = []
        for i in range(4):
            xs = sorted(x[i] for x in v)
            cols.append(f"{xs[0]:.3f} / {xs[len(xs) // 2]:.3f}")
        print(f"| {label} | {path} | " + " | ".join(cols) + f" | {','.join(sorted(cells[(label, path)]))} |")


if __name__ == "__main__":
    main(sys.argv)
