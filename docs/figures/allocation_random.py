#!/usr/bin/env python3
"""Writes two seeded random rest-to-rest allocation problems, off the fixture maps, for timing
`miner traj solve --allocate optimise` (docs/traj.md): a 40-segment minimum-snap zig-zag with
legs of 0.5-20 m and a 12-segment minimum-jerk path with legs of 0.05-50 m, v_max 3 m/s,
a_max 2 m/s^2, rho 2.
    python3 docs/figures/allocation_random.py OUT_DIR
"""
import json
import math
import random
import sys

out = sys.argv[1]
random.seed(34)
for name, order, segments, lo, hi in [("zigzag40_s4", 4, 40, 0.5, 20.0), ("rand12_s3", 3, 12, 0.05, 50.0)]:
    points = [[0.0, 0.0, 1.0]]
    for _ in range(segments):
        length = random.uniform(lo, hi)
        heading, pitch = random.uniform(0, 2 * math.pi), random.uniform(-0.5, 0.5)
        q = points[-1]
        points.append([q[0] + length * math.cos(heading) * math.cos(pitch),
                       q[1] + length * math.sin(heading) * math.cos(pitch), q[2] + length * math.sin(pitch)])
    rest = [[0, 0, 0]] * (order - 1)
    problem = {"order": order, "points": points, "head": [points[0]] + rest, "tail": [points[-1]] + rest,
               "limits": {"v_max": 3.0, "a_max": 2.0}, "allocation": "optimise", "rho": 2.0}
    with open(f"{out}/{name}.json", "w") as f:
        json.dump(problem, f)
