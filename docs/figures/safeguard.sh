#!/usr/bin/env bash
# Prints docs/plan.md's safeguard table: MINER with the sGAN region (miner-sgan) and with
# the A*-dilated oracle region (miner), with the safeguard (REQ-PLAN-020) and with the
# paper's fixed mu, beside our other planners, on four maps of families the network never
# trained on. Iterations are exact (same bytes on every run); times depend on the machine.
#   bash docs/figures/safeguard.sh [build/release/miner] [runs]
set -euo pipefail
miner=${1:-build/release/miner}
runs=${2:-20}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$miner" map gen --preset cluttered --size 40 40 20 --obstacles 80 --seed 11 --out "$dir/cluttered.json" >/dev/null
"$miner" map gen --preset sim --obstacles 300 --seed 12 --out "$dir/sim-300.json" >/dev/null
"$miner" map gen --preset rooms --size 50 30 4 --resolution 0.2 --seed 13 --out "$dir/rooms.json" >/dev/null
"$miner" map gen --preset forest --size 60 60 15 --obstacles 260 --seed 14 --out "$dir/forest.json" >/dev/null
for m in cluttered sim-300 rooms forest; do
  "$miner" bench frontend --map "$dir/$m.json" --runs "$runs" --planners rrtstar,informed,guided,miner,miner-sgan \
    --throughput-iterations 0 --quiet --json >"$dir/$m.on.json"
  "$miner" bench frontend --map "$dir/$m.json" --runs "$runs" --planners miner,miner-sgan --no-safeguard \
    --throughput-iterations 0 --quiet --json >"$dir/$m.off.json"
done
python3 - "$dir" <<'PY'
import json, sys
d = sys.argv[1]
def cell(s):
    it = s["target_iterations"]
    q1, q3 = s["target_iterations_q1"], s["target_iterations_q3"]
    f = lambda v: "miss" if v is None else f"{v:.0f}"
    return f"{f(it)} [{f(q1)}, {f(q3)}] ({s['target_reached']}/{s['runs']})"
print("| map | rrtstar | informed | guided | miner-sgan, safeguard | miner-sgan, paper's mu | miner (oracle, upper bound), safeguard | miner (oracle), paper's mu |")
print("|---|---|---|---|---|---|---|---|")
for m in ["cluttered", "sim-300", "rooms", "forest"]:
    on = {s["planner"]: s for s in json.load(open(f"{d}/{m}.on.json"))["planners"]}
    off = {s["planner"]: s for s in json.load(open(f"{d}/{m}.off.json"))["planners"]}
    row = [cell(on[p]) for p in ["rrtstar", "informed", "guided"]]
    row += [cell(on["miner-sgan"]), cell(off["miner-sgan"]), cell(on["miner"]), cell(off["miner"])]
    print(f"| {m} | " + " | ".join(row) + " |")
PY
