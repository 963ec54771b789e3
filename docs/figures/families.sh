#!/usr/bin/env bash
# Prints docs/heuristic.md's per-family table: the shipped sGAN (trained on `sim` only)
# on unseen maps of every family, grid and strict (REQ-HEUR-011) rates, and MINER vs RRT*
# iterations to the target on the same queries.
#   bash docs/figures/families.sh [build/release/miner] [samples per family]
set -euo pipefail
miner=${1:-build/release/miner}
n=${2:-10}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
families=(sim cluttered rooms forest multilevel)
for f in "${families[@]}"; do
  "$miner" dataset --preset "$f" --count 1 --test-count "$n" --seed 5 --out "$dir/$f" >/dev/null
done
"$miner" bench heuristic --data $(for f in "${families[@]}"; do echo "$dir/$f"; done) --json >"$dir/bench.json"
python3 - "$dir/bench.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
pct = lambda v: f"{100 * v:.0f} %"
num = lambda v: "miss" if v is None else f"{v:.0f}"
print("| family | n | grid connected / safe (raw) | strict connected / safe (raw) | strict, filtered | strict, ground truth T | MINER it. to target | RRT* it. to target | MINER / RRT* reach |")
print("|---|---|---|---|---|---|---|---|---|")
for name, v in list(d["families"].items()) + [("all", d)]:
    print(f"| {name} | {v['samples']} | {pct(v['connectivity_rate_raw'])} / {pct(v['safety_rate_raw'])} | "
          f"{pct(v['connectivity_rate_strict'])} / {pct(v['safety_rate_strict'])} | "
          f"{pct(v['connectivity_rate_strict_filtered'])} / {pct(v['safety_rate_strict_filtered'])} | "
          f"{pct(v['connectivity_rate_strict_truth'])} / {pct(v['safety_rate_strict_truth'])} | "
          f"{num(v['miner']['target_iterations'])} | {num(v['rrtstar']['target_iterations'])} | "
          f"{pct(v['miner']['target_rate'])} / {pct(v['rrtstar']['target_rate'])} |")
print(f"\nmedian inference {d['inference_ms']:.2f} ms, region query {d['region_ms']:.2f} ms over all {d['samples']} queries")
PY
