#!/usr/bin/env bash
# The raw region's strict rates (REQ-HEUR-011) per threshold on the validation split of the seven
# family datasets (docs/sgan-training/families.sh data): how the shipped threshold was chosen
# (docs/heuristic.md, "The shipped weights") and how a new network is compared with it.
#   bash docs/figures/threshold_sweep.sh [build/release/miner] WEIGHTS DATA_ROOT [samples per family] [thresholds]
# DATA_ROOT holds fam-sim ... fam-scan; prints per threshold the rates over all families and per family.
# SPLIT=test PREFIX=s16- in the environment: another split and folder prefix (a 16^3 network
# is swept on 16^3 datasets of its own, docs/heuristic.md).
set -euo pipefail
miner=${1:-build/release/miner}
weights=$2
data=$3
n=${4:-30}
thresholds=${5:-"0.05 0.1 0.15 0.2 0.3"}
root=$(cd "$(dirname "$0")/../.." && pwd)
py=/usr/bin/python3; [ -x "$py" ] || py=python3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
families=(sim indoor cluttered rooms forest multilevel scan)
split=${SPLIT:-val}
prefix=${PREFIX:-fam-}
folders=(); for f in "${families[@]}"; do folders+=("$data/$prefix$f"); done
echo "| threshold | n | strict connected | strict safe | per family (connected / safe) |"
echo "|---|---|---|---|---|"
for t in $thresholds; do
  "$py" "$root/src/python/sgan/set_threshold.py" --weights "$weights" --threshold "$t" --reason sweep \
    --out "$dir/w.bin" >/dev/null
  "$miner" bench heuristic --data "${folders[@]}" --split "$split" --samples "$n" --no-planners --quiet --json \
    --weights "$dir/w.bin" >"$dir/r.json"
  "$py" - "$dir/r.json" "$t" <<'PY'
import json, sys
r, t = json.load(open(sys.argv[1])), sys.argv[2]
fams = r["families"]
n = sum(v["samples"] for v in fams.values())
rate = lambda k: sum(v[k] * v["samples"] for v in fams.values()) / n
per = ", ".join(f"{k} {100 * v['connectivity_rate_strict']:.0f} / {100 * v['safety_rate_strict']:.0f}"
                for k, v in fams.items())
print(f"| {t} | {n} | {100 * rate('connectivity_rate_strict'):.1f} % | {100 * rate('safety_rate_strict'):.1f} % | {per} |")
PY
done
