#!/usr/bin/env bash
# The 16^3 network (fixtures/sgan/grid16, train.py --pool 2) against the shipped 32^3 one on the
# same unseen queries (dataset seed 1000003, as lofo.sh: the 32^3 and 16^3 datasets of a family
# hold the same maps and queries), both trained on all seven families: strict rates of the raw
# region (REQ-HEUR-011), median inference and whole-query times, and MINER (region time
# included) and RRT* to the target on the same random streams. One family at a time, the 32^3
# run then the 16^3 run (sequential: the time columns carry the machine's noise).
#   bash docs/figures/grid16.sh [build/release/miner] [samples per family]
set -euo pipefail
miner=${1:-build/release/miner}
n=${2:-20}
root=$(cd "$(dirname "$0")/../.." && pwd)
py=/usr/bin/python3; [ -x "$py" ] || py=python3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
families=(sim indoor cluttered rooms forest multilevel scan)
for f in "${families[@]}"; do
  for g in 32 16; do
    "$miner" dataset --preset "$f" --count 1 --test-count "$n" --seed 1000003 --dims "$g" "$g" "$g" --quiet \
      --out "$dir/$f-$g" >/dev/null
  done
  "$miner" bench heuristic --data "$dir/$f-32" --weights "$root/fixtures/sgan/sgan.bin" --quiet --json >"$dir/$f-32.json"
  "$miner" bench heuristic --data "$dir/$f-16" --weights "$root/fixtures/sgan/grid16/sgan.bin" --quiet --json \
    >"$dir/$f-16.json"
done
"$py" - "$dir" "${families[@]}" <<'PY'
import json, sys
d, families = sys.argv[1], sys.argv[2:]
pct = lambda v: f"{100 * v:.0f} %"
num = lambda v, p=1: "miss" if v is None else f"{v:.{p}f}"
print("| family | n | grid | strict conn. / safe (raw) | inference ms | region ms | MINER it. to target | MINER ms to target | MINER reach | RRT* ms to target | RRT* reach |")
print("|---|---|---|---|---|---|---|---|---|---|---|")
for f in families:
    for g in ("32", "16"):
        j = json.load(open(f"{d}/{f}-{g}.json"))
        m, r = j["miner"], j["rrtstar"]
        print(f"| {f} | {j['samples']} | {g}^3 | {pct(j['connectivity_rate_strict'])} / {pct(j['safety_rate_strict'])} | "
              f"{j['inference_ms']:.2f} | {j['region_ms']:.2f} | {num(m['target_iterations'], 0)} | {num(m['target_time_ms'])} | "
              f"{pct(m['target_rate'])} | {num(r['target_time_ms'])} | {pct(r['target_rate'])} |")
PY
