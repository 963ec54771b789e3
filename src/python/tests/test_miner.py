"""pytest of the Python bindings (cites: REQ-LIB-002): `import miner` plans and flies in a few
lines, numpy arrays in and out, errors named, the same seed giving the same answer."""
import json
import os
import pathlib

import numpy as np
import pytest

import miner

SOURCE = pathlib.Path(os.environ.get("MINER_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[3]))
SIM1 = str(SOURCE / "fixtures" / "maps" / "sim-1.json")


def test_map_loads_with_its_query_and_answers_collision_queries():
    m = miner.Map.load(SIM1)
    lo, hi = m.bounds
    assert lo.shape == (3,) and np.all(hi > lo)
    assert m.obstacles.shape[1] == 6 and len(m.obstacles) > 0
    q = m.query
    assert m.is_free(q["start"], q["robot_radius"]) and m.is_free(q["goal"], q["robot_radius"])
    box = m.obstacles[0]
    inside = (box[:3] + box[3:]) / 2
    assert not m.is_free(inside)
    assert m.clearance(inside) == 0.0


def test_bad_input_raises_miner_error_naming_the_field():
    with pytest.raises(miner.Error, match="resolution"):
        miner.Map.from_json(json.dumps({"format": "miner-map-v1", "bounds": {"min": [0, 0, 0], "max": [1, 1, 1]},
                                        "resolution": 1e-300, "obstacles": []}))
    assert issubclass(miner.Error, ValueError)
    with pytest.raises(miner.Error, match="points"):
        miner.minco(np.zeros((4, 2)))
    m = miner.Map.load(SIM1)
    with pytest.raises(miner.Error, match="needs a region"):
        miner.plan(m, planner="miner")


def test_sgan_region_then_miner_rrt_star_then_minco():
    m = miner.Map.load(SIM1)
    region = miner.sgan_region(m, seed=1)
    assert tuple(region.dims) == (32, 32, 32)
    assert region.probabilities.shape == (32, 32, 32)
    assert 0 < region.cell_count < 32 ** 3
    result = miner.plan(m, planner="miner", region=region, seed=1, iterations=3000)
    assert result.solved and result.first_iteration is not None
    path = result.path
    assert path.shape[1] == 3
    assert np.allclose(path[0], m.query["start"]) and np.allclose(path[-1], m.query["goal"])
    r = m.query["robot_radius"]
    assert all(m.segment_free(a, b, r) for a, b in zip(path[:-1], path[1:]))
    assert result.cost == pytest.approx(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())
    # The same seed, the same path; another seed, another tree.
    again = miner.plan(m, planner="miner", region=region, seed=1, iterations=3000)
    assert np.array_equal(again.path, path)
    traj = miner.minco(path, order=4, v_max=2.0, a_max=1.0)
    assert np.allclose(traj.evaluate(0.0), path[0]) and np.allclose(traj.evaluate(traj.total_duration), path[-1])
    assert np.allclose(traj.evaluate(traj.total_duration, 1), 0.0, atol=1e-9)


def test_baselines_and_the_oracle_region():
    m = miner.Map.load(SIM1)
    oracle = miner.astar_region(m)
    assert oracle.source == "astar-dilated"
    for planner in ("rrtstar", "informed", "guided"):
        assert miner.plan(m, planner=planner, seed=2, iterations=3000).solved
    assert miner.plan(m, planner="miner", region=oracle, seed=2, iterations=3000).solved


def test_minco_waypoints_and_durations():
    pts = np.array([[0, 0, 1], [1, 0, 1], [1, 1, 2], [2, 2, 2]], dtype=float)
    traj = miner.minco(pts, durations=[1.0, 1.0, 1.5], order=3)
    assert traj.order == 3 and traj.durations == [1.0, 1.0, 1.5]
    assert traj.coefficients.shape == (2 * 3 * 3, 3)
    times = np.array([0.0, 1.0, 2.0, 3.5])
    assert np.allclose(traj.sample(times), pts, atol=1e-9)
    with pytest.raises(miner.Error, match="durations"):
        miner.minco(pts, durations=[1.0, 0.0, 1.0])


def test_the_default_scenario_flies_to_its_goal():
    s = miner.Scenario.default()
    ref = miner.build_reference(s)
    assert ref.source == "planner" and ref.trajectory.total_duration > 0
    flight = miner.fly(s, ref)
    assert flight.goal_reached and flight.collisions == 0
    assert flight.log.shape == (len(flight.log), len(flight.log_columns))
    assert flight.position_rmse < 0.1
    assert json.loads(flight.summary)["goal_reached"] is True
