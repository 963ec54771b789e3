#!/usr/bin/env bash
# Prints docs/traj.md's allocation table (REQ-TRAJ-011): on MINER's path (sGAN region, seed 1,
# 20000 iterations) of every fixture map, rest to rest, jerk and snap, the trapezoidal
# allocation against `miner traj solve --allocate optimise` (default rho = 1, the paper
# bench's limits v_max 2 m/s, a_max 1 m/s^2): F = J + rho T, J, total time, solve time, and
# the peaks re-sampled here at 2000 instants per segment from the printed coefficients.
#   bash docs/figures/allocation.sh [build/release/miner] [rho]
set -euo pipefail
miner=${1:-build/release/miner}
rho=${2:-1}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
for m in sim-1 sim-2 sim-3 indoor-1 indoor-2; do
  "$miner" plan --map "fixtures/maps/$m.json" --json >"$dir/$m.plan.json"
done
python3 - "$miner" "$rho" "$dir" <<'PY'
import json, subprocess, sys, math, re
miner, rho, d = sys.argv[1], float(sys.argv[2]), sys.argv[3]
vmax, amax = 2.0, 1.0
def peaks(a):
    s = a["order"]; v = acc = 0.0
    for T, c in zip(a["durations"], a["coefficients"]):
        for k in range(2001):
            t = T * k / 2000
            vel = [sum(j * c[j][ax] * t ** (j - 1) for j in range(1, 2 * s)) for ax in range(3)]
            ac = [sum(j * (j - 1) * c[j][ax] * t ** (j - 2) for j in range(2, 2 * s)) for ax in range(3)]
            v = max(v, math.sqrt(sum(x * x for x in vel))); acc = max(acc, math.sqrt(sum(x * x for x in ac)))
    return v, acc
print(f"| map | s | segments | trapezoid: F / J / T (s) | trapezoid peaks v / a | optimised: F / J / T (s) | F lowered by | optimised peaks v / a (2000 samples/segment) | Ceres iterations + search evaluations | solve (ms) |")
print("|---|---|---|---|---|---|---|---|---|---|")
for m in ("sim-1", "sim-2", "sim-3", "indoor-1", "indoor-2"):
    plan = json.load(open(f"{d}/{m}.plan.json"))
    pts = plan["path"]
    for s in (3, 4):
        base = {"order": s, "points": pts, "head": [pts[0]] + [[0, 0, 0]] * (s - 1),
                "tail": [pts[-1]] + [[0, 0, 0]] * (s - 1), "limits": {"v_max": vmax, "a_max": amax}}
        json.dump(base, open(f"{d}/trap.json", "w"))
        trap = json.loads(subprocess.run([miner, "traj", "solve", "--problem", f"{d}/trap.json"], check=True,
                                         capture_output=True, text=True).stdout)
        json.dump(dict(base, allocation="optimise", rho=rho), open(f"{d}/opt.json", "w"))
        said = subprocess.run([miner, "traj", "solve", "--problem", f"{d}/opt.json", "--out", f"{d}/opt-answer.json"],
                              check=True, capture_output=True, text=True)
        opt = json.load(open(f"{d}/opt-answer.json"))
        # The solve time is said on the terminal, never written to the answer (same bytes every run).
        solve_ms = float(re.search(r"allocation solved in ([0-9.e+-]+) ms", said.stdout + said.stderr).group(1))
        tT = sum(trap["durations"]); tF = trap["cost"] + rho * tT
        al = opt["allocation"]
        tv, ta = peaks(trap); ov, oa = peaks(opt)
        print(f"| {m} | {s} | {len(pts) - 1} | {tF:.4g} / {trap['cost']:.4g} / {tT:.1f} | {tv:.3f} / {ta:.3f} "
              f"| {al['objective']:.4g} / {al['cost']:.4g} / {al['total_time']:.1f} | {100 * (1 - al['objective'] / tF):.1f} % "
              f"| {ov:.3f} / {oa:.3f} | {al['iterations']} + {al['polish_evaluations']} | {solve_ms:.1f} |")
print(f"\nrho = {rho}; limits v_max {vmax} m/s, a_max {amax} m/s^2. The trapezoid's own MINCO curve may exceed the limits "
      "(its peaks are shown); the optimiser starts from it stretched to meet them (answer field trapezoid_stretch).")
PY
