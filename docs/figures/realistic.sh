#!/usr/bin/env bash
# Tracking MSE of the realistic preset against wind intensity and model mismatch
# (REQ-FLIGHT-019, docs/flight.md). Usage: bash docs/figures/realistic.sh [MINER] [SEEDS]
# Flies fixtures/scenarios/realistic.json with its wind scaled (x0, x0.5, x1, x1.5: mean,
# turbulence sigmas and gust peak together) and its mismatch off / as shipped / doubled
# (each factor's distance from 1 twice), SEEDS seeds each (default 5), and prints a Markdown
# table of the position MSE x / y (median [min, max] over the seeds), goals reached and
# collisions.
set -euo pipefail
MINER=${1:-build/release/miner}
SEEDS=${2:-5}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
python3 - "$MINER" "$SEEDS" "$ROOT" "$WORK" <<'PY'
import copy, json, statistics, subprocess, sys
miner, seeds, root, work = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
base = json.load(open(f"{root}/fixtures/scenarios/realistic.json"))
base["map"] = f"{root}/fixtures/maps/indoor-1.json"
base["vehicle"] = f"{root}/fixtures/vehicles/n3-1500g-aero.json"
def scaled_wind(w, k):
    w = copy.deepcopy(w)
    w["mean_m_s"] = [k * x for x in w["mean_m_s"]]
    w["sigma_horizontal_m_s"] *= k
    w["sigma_vertical_m_s"] *= k
    for g in w["gusts"]:
        g["peak_m_s"] = [k * x for x in g["peak_m_s"]]
    return w
def mismatch(m, k):
    return {key: 1 + k * (v - 1) for key, v in m.items()}
def fmt(xs):
    return f"{statistics.median(xs):.4f} [{min(xs):.4f}, {max(xs):.4f}]"
print(f"| wind (x preset) | mismatch (x preset) | position MSE x (m^2) | position MSE y (m^2) | position MSE z (m^2) | reached | collisions |")
print("|---|---|---|---|---|---|---|")
for wk in (0.0, 0.5, 1.0, 1.5):
    for mk in (0.0, 1.0, 2.0):
        doc = copy.deepcopy(base)
        doc["wind"] = scaled_wind(base["wind"], wk)
        doc["mismatch"] = mismatch(base["mismatch"], mk)
        path = f"{work}/s.json"
        json.dump(doc, open(path, "w"))
        mse, reached, coll = [[], [], []], 0, 0
        for seed in range(1, seeds + 1):
            p = subprocess.run([miner, "fly", "--scenario", path, "--seed", str(seed), "--json", "--quiet",
                                "--out", f"{work}/run"], capture_output=True, text=True)
            if p.returncode not in (0, 3):
                sys.exit(f"miner fly failed ({p.returncode}): {p.stderr}")
            j = json.loads(p.stdout)
            for a in range(3):
                mse[a].append(j["position_mse"][a])
            reached += j["goal_reached"]
            coll += j["collisions"]
        print(f"| {wk:g} | {mk:g} | {fmt(mse[0])} | {fmt(mse[1])} | {fmt(mse[2])} | {reached}/{seeds} | {coll} |")
PY
