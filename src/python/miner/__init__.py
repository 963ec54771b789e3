"""MINER: MINER-RRT* planning and flight from Python (REQ-LIB-002).

    import miner
    m = miner.Map.load("fixtures/maps/sim-1.json")
    region = miner.sgan_region(m)                  # the sGAN's heuristic region (map's query)
    result = miner.plan(m, planner="miner", region=region, seed=1)
    traj = miner.minco(result.path, v_max=2.0, a_max=1.0)
    s = miner.Scenario.default()
    flight = miner.fly(s, miner.build_reference(s))

Arrays are numpy arrays (points as (n, 3)); bad input raises miner.Error (a ValueError)
naming the field, an unsolvable query miner.NoSolution.
"""
from ._miner import (Error, Flight, Map, NoSolution, PlanResult, Reference, Region, Scenario, Trajectory,
                     astar_region, build_reference, fly, minco, plan, sgan_region)

__all__ = ["Error", "Flight", "Map", "NoSolution", "PlanResult", "Reference", "Region", "Scenario", "Trajectory",
           "astar_region", "build_reference", "fly", "minco", "plan", "sgan_region"]
