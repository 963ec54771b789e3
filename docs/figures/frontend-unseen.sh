#!/usr/bin/env bash
# Prints docs/heuristic.md's end-to-end table: on unseen maps of the given families (map seed
# 1000003, no training map), `miner bench frontend` with every planner of ours and every OMPL
# planner, interleaved; miner-sgan (region query included) against the fastest other planner,
# the A*-oracle `miner` shown apart (an upper bound, not a competitor).
#   bash docs/figures/frontend-unseen.sh [build/release/miner] [runs] [families...]
# WEIGHTS=fixtures/sgan/grid16/sgan.bin in the environment: miner-sgan with other weights.
set -euo pipefail
miner=${1:-build/release/miner}
runs=${2:-20}
shift 2 || true
families=("$@")
[ ${#families[@]} -gt 0 ] || families=(rooms cluttered)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
for f in "${families[@]}"; do
  "$miner" map gen --preset "$f" --seed 1000003 --quiet --out "$dir/$f.json" >/dev/null
  "$miner" bench frontend --map "$dir/$f.json" --runs "$runs" --time-limit 1 --quiet --json \
    ${WEIGHTS:+--weights "$WEIGHTS"} >"$dir/$f-bench.json"
done
python3 - "$dir" "${families[@]}" <<'PY'
import json, sys
d, families = sys.argv[1], sys.argv[2:]
print("| map | miner-sgan to target | fastest other planner (not the oracle) | ratio | oracle `miner` |")
print("|---|---|---|---|---|")
def ms(v): return f"{v:.2f} ms" if v is not None else "miss"
for f in families:
    b = json.load(open(f"{d}/{f}-bench.json"))
    rows = {p["planner"]: p for p in b["planners"]}
    s = rows["miner-sgan"]
    others = [p for n, p in rows.items() if n not in ("miner-sgan", "miner") and p["target_time_ms"] is not None]
    best = min(others, key=lambda p: p["target_time_ms"])
    ratio = best["target_time_ms"] / s["target_time_ms"] if s["target_time_ms"] else 0.0
    verdict = f"{ratio:.1f}x faster" if ratio >= 1 else f"{1 / ratio:.1f}x slower" if ratio > 0 else "no target"
    print(f"| {f}, seed 1000003, {b['runs']} runs | {ms(s['target_time_ms'])}, {s['target_iterations']:.0f} it., reach "
          f"{s['target_reached']}/{b['runs']} | {best['planner']} {ms(best['target_time_ms'])}, "
          f"{best['target_iterations']:.0f} it., reach {best['target_reached']}/{b['runs']} | "
          f"**{verdict}** | {ms(rows['miner']['target_time_ms'])} |")
PY
