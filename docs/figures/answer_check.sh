#!/usr/bin/env bash
# Prints docs/traj.md's answer-check table (REQ-TRAJ-010): random trajectory problems whose
# durations spread over 1x .. 1e6x, solved by `miner traj solve`; per spread how many
# answers come back and how many are refused, by cause. Every answer that comes back is
# re-evaluated here in exact rational arithmetic from its printed coefficients: the largest
# waypoint miss relative to L (the problem's position scale) must stay <= 1e-9.
#   bash docs/figures/answer_check.sh [build/release/miner] [problems per spread]
set -euo pipefail
miner=${1:-build/release/miner}
count=${2:-200}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
python3 - "$miner" "$count" "$dir" <<'PY'
import json, random, subprocess, sys
from fractions import Fraction
miner, count, d = sys.argv[1], int(sys.argv[2]), sys.argv[3]
print("| durations spread | problems | answered | refused: waypoints missed | refused: optimality | refused: constraint / not finite | largest waypoint miss of an answer (exact, / L) |")
print("|---|---|---|---|---|---|---|")
for spread in (1.0, 10.0, 1e2, 1e3, 1e4, 1e6):
    rng = random.Random(int(spread))
    answered = missed = optimality = other = 0
    worst = 0.0
    for k in range(count):
        s = rng.choice((3, 4))
        M = rng.randint(1, 12)
        pts = [[rng.uniform(-10, 10), rng.uniform(-10, 10), rng.uniform(0, 5)] for _ in range(M + 1)]
        T0 = 10 ** rng.uniform(-1, 1)
        T = [T0 * spread ** rng.random() for _ in range(M)]
        if M >= 2:
            T[0], T[-1] = T0, T0 * spread
        head = [pts[0]] + [[rng.gauss(0, 1) for _ in range(3)] for _ in range(s - 1)]
        tail = [pts[-1]] + [[rng.gauss(0, 1) for _ in range(3)] for _ in range(s - 1)]
        path = f"{d}/p.json"
        json.dump({"order": s, "points": pts, "durations": T, "head": head, "tail": tail}, open(path, "w"))
        r = subprocess.run([miner, "traj", "solve", "--problem", path], capture_output=True, text=True)
        if r.returncode != 0:
            e = r.stderr
            if "meets its waypoints only" in e: missed += 1
            elif "optimality conditions" in e: optimality += 1
            else: other += 1
            continue
        answered += 1
        a = json.loads(r.stdout)
        L = max(max(abs(c) for p in pts for c in p), max(max(p[i] for p in pts) - min(p[i] for p in pts) for i in range(3)))
        for i, (Ti, c) in enumerate(zip(a["durations"], a["coefficients"])):
            t = Fraction(Ti)
            for tau, target in ((Fraction(0), pts[i]), (t, pts[i + 1])):
                for ax in range(3):
                    v = sum(Fraction(c[j][ax]) * tau ** j for j in range(len(c)))
                    worst = max(worst, float(abs(v - Fraction(target[ax]))) / L)
    print(f"| {spread:g} | {count} | {answered} | {missed} | {optimality} | {other} | {worst:.1e} |")
PY
