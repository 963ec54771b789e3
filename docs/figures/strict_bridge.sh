#!/usr/bin/env bash
# Filter step 5 (the strict bridge, REQ-HEUR-014) on and off, on the same queries (the test
# split of the seven family datasets, docs/sgan-training/families.sh data), one family after the
# other, off then on (sequential runs of one binary: the time columns carry the machine's noise;
# iterations, rates and cells are deterministic).
#   bash docs/figures/strict_bridge.sh [build/release/miner] DATA_ROOT [samples per family] [weights]
set -euo pipefail
miner=${1:-build/release/miner}
data=$2
n=${3:-20}
weights=${4:-}
py=/usr/bin/python3; [ -x "$py" ] || py=python3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
echo "| family | n | strict connected (filtered) off -> on | witness | queries bridged | filter ms median (max) off -> on | MINER iterations to target off -> on | MINER ms to target off -> on | RRT* ms to target |"
echo "|---|---|---|---|---|---|---|---|---|"
for f in sim indoor cluttered rooms forest multilevel scan; do
  for mode in off on; do
    extra=(); [ "$mode" = on ] && extra+=(--strict-bridge)
    [ -n "$weights" ] && extra+=(--weights "$weights")
    "$miner" bench heuristic --data "$data/fam-$f" --split test --samples "$n" --quiet --json "${extra[@]}" >"$dir/$mode.json"
  done
  "$py" - "$dir/off.json" "$dir/on.json" "$f" <<'PY'
import json, sys
a, b, f = json.load(open(sys.argv[1])), json.load(open(sys.argv[2])), sys.argv[3]
p = lambda v: f"{100 * v:.0f} %"
g = lambda v: "-" if v is None else f"{v:.1f}"
print(f"| {f} | {a['samples']} | {p(a['connectivity_rate_strict_filtered'])} -> {p(b['connectivity_rate_strict_filtered'])} "
      f"| {p(b['strict_witness_rate'])} | {p(b['strict_bridged_rate'])} "
      f"| {a['filter_ms']:.2f} ({a['filter_ms_max']:.1f}) -> {b['filter_ms']:.2f} ({b['filter_ms_max']:.1f}) "
      f"| {g(a['miner']['target_iterations'])} -> {g(b['miner']['target_iterations'])} "
      f"| {g(a['miner']['target_time_ms'])} -> {g(b['miner']['target_time_ms'])} | {g(b['rrtstar']['target_time_ms'])} |")
PY
done
