#!/usr/bin/env bash
# Prints docs/heuristic.md's leave-one-family-out table (issue 16 item 3): for each map family F,
# the network trained without F (fixtures/sgan/lofo/without-F.bin) and the shipped one (trained
# on all families) on unseen maps of F: grid (REQ-HEUR-004) and strict (REQ-HEUR-011) raw rates,
# and MINER vs RRT* iterations to the target on the same queries.
#   bash docs/figures/lofo.sh [build/release/miner] [samples per family] [weights folder] [grid]
# The weights folder (default fixtures/sgan) holds sgan.bin and lofo/without-F.bin; grid (default
# 32) is the networks' cells per axis (16 for fixtures/sgan/grid16).
# The maps come from dataset seed 1000003 (map seeds splitmix64(1000003 ^ k), k = 1..n), which
# no training sample used (those are splitmix64(11 ^ k) with k < 2048; splitmix64 is a bijection).
set -euo pipefail
miner=${1:-build/release/miner}
n=${2:-20}
root=$(cd "$(dirname "$0")/../.." && pwd)
weights=$(cd "${3:-$root/fixtures/sgan}" && pwd)
grid=${4:-32}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
families=(sim indoor cluttered rooms forest multilevel scan)
for f in "${families[@]}"; do
  "$miner" dataset --preset "$f" --count 1 --test-count "$n" --seed 1000003 --dims "$grid" "$grid" "$grid" --quiet \
    --out "$dir/$f" >/dev/null
  "$miner" bench heuristic --data "$dir/$f" --weights "$weights/lofo/without-$f.bin" --quiet --json \
    >"$dir/$f-lofo.json"
  "$miner" bench heuristic --data "$dir/$f" --weights "$weights/sgan.bin" --quiet --json >"$dir/$f-all.json"
done
python3 - "$dir" "${families[@]}" <<'PY'
import json, sys
d, families = sys.argv[1], sys.argv[2:]
pct = lambda v: f"{100 * v:.0f} %"
num = lambda v: "miss" if v is None else f"{v:.0f}"
def cells(v):
    return (f"{pct(v['connectivity_rate_raw'])} / {pct(v['safety_rate_raw'])} | "
            f"{pct(v['connectivity_rate_strict'])} / {pct(v['safety_rate_strict'])} | "
            f"{num(v['miner']['target_iterations'])} / {num(v['rrtstar']['target_iterations'])} | "
            f"{pct(v['miner']['target_rate'])} / {pct(v['rrtstar']['target_rate'])}")
print("| held-out family F | n | trained without F: grid conn. / safe | strict conn. / safe | MINER / RRT* it. to target | MINER / RRT* reach | "
      "shipped (all families): grid conn. / safe | strict conn. / safe | MINER / RRT* it. to target | MINER / RRT* reach | strict, ground truth T |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for f in families:
    lo, al = (json.load(open(f"{d}/{f}-{k}.json")) for k in ("lofo", "all"))
    print(f"| {f} | {lo['samples']} | {cells(lo)} | {cells(al)} | "
          f"{pct(al['connectivity_rate_strict_truth'])} / {pct(al['safety_rate_strict_truth'])} |")
PY
