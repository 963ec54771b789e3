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
    # Sixteenth campaign F4: a region of another map with the same bounds is refused (indoor-1 and
    # indoor-2 share theirs), not sampled as if it were this map's.
    indoor1 = miner.Map.load(SIM1.replace("sim-1.json", "indoor-1.json"))
    other = miner.astar_region(miner.Map.load(SIM1.replace("sim-1.json", "indoor-2.json")), dims=(8, 8, 4))
    with pytest.raises(miner.Error, match="the region was built for another map"):
        miner.plan(indoor1, planner="miner", region=other, iterations=300)


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


# ---- issue 20, ninth campaign: the Python layer checks what the CLI checks (REQ-LIB-002) ----
WALL = json.dumps({"format": "miner-map-v1", "bounds": {"min": [0, 0, 0], "max": [10, 10, 2]}, "resolution": 0.5,
                   "obstacles": [{"type": "box", "min": [4.5, 0, 0], "max": [5.5, 7, 2]},
                                 {"type": "box", "min": [4.5, 9, 0], "max": [5.5, 10, 2]}],
                   "query": {"start": [2, 3, 1], "goal": [8, 3, 1], "robot_radius": 0.1}})
SEALED = json.dumps({"format": "miner-map-v1", "bounds": {"min": [0, 0, 0], "max": [10, 10, 10]}, "resolution": 0.5,
                     "obstacles": [{"type": "box", "min": [7, 7, 7], "max": [10, 10, 7.5]},
                                   {"type": "box", "min": [7, 7, 7.5], "max": [7.5, 10, 10]},
                                   {"type": "box", "min": [7.5, 7, 7.5], "max": [10, 7.5, 10]}],
                     "query": {"start": [1, 1, 1], "goal": [8.75, 8.75, 8.75], "robot_radius": 0.1}})


def test_trajectory_derivative_order_and_time_are_checked():
    t = miner.minco([[0, 0, 0], [1, 0, 0], [2, 1, 0]])
    for k in (-1, -100, -2**31, -10**6):  # read outside the coefficients, or crashed (P1)
        with pytest.raises(miner.Error, match="k: "):
            t.evaluate(1.0, k=k)
        with pytest.raises(miner.Error, match="k: "):
            t.sample(np.linspace(0, 1, 5), k=k)
    with pytest.raises(miner.Error, match="k: "):
        t.evaluate(1.0, k=2**40)
    with pytest.raises(miner.Error, match="t: must be a finite time"):  # NaN answered the start (P12)
        t.evaluate(float("nan"))
    for end in (float("inf"), float("-inf")):  # clamped to an end (sixteenth campaign F8)
        with pytest.raises(miner.Error, match="t: must be a finite time"):
            t.evaluate(end)
    with pytest.raises(miner.Error, match=r"times\[0\]: must be a finite time"):
        t.sample(np.array([float("nan"), 1.0]))
    with pytest.raises(miner.Error, match=r"times\[1\]: must be a finite time"):
        t.sample(np.array([0.5, float("inf")]))
    assert np.allclose(t.evaluate(1e9), t.evaluate(t.total_duration))  # finite times clamp, as documented
    assert np.allclose(t.evaluate(1.0, k=20), 0.0)


def test_region_queries_are_planner_queries():
    m = miner.Map.from_json(WALL)
    for start in ([float("nan"), 3, 1], [5, 3, 1], [-500, 3, 1], [float("inf"), 3, 1]):  # P2 crash, P3
        with pytest.raises(miner.Error, match="start"):
            miner.sgan_region(m, start=start)
    with pytest.raises(miner.Error, match="goal"):
        miner.sgan_region(m, goal=[float("nan"), 3, 1], filter=False)
    with pytest.raises(miner.Error, match="radius"):
        miner.sgan_region(m, radius=5)  # the start is within 5 m of the wall
    with pytest.raises(miner.Error, match="radius"):
        miner.sgan_region(m, radius=1e300)
    for dims, field in (([2**32 + 8, 8, 8], "dims"), ([8.9, 8, 8], "dims"), ([True, 8, 8], "dims"),
                        ([4097, 8, 8], "dims"), ([0, 8, 8], "dims")):  # wrapped, truncated (P4)
        with pytest.raises(miner.Error, match=field):
            miner.astar_region(m, dims=dims)
    assert list(miner.astar_region(m, dims=[8, 8, 4]).dims) == [8, 8, 4]
    with pytest.raises(miner.Error, match="dilation"):
        miner.astar_region(m, dilation=5)


def test_map_save_keeps_the_cli_rules(tmp_path):
    m = miner.Map.from_json(WALL)
    with pytest.raises(miner.Error, match="query"):  # a .bt holds no query (P5)
        m.save(str(tmp_path / "q.bt"))
    m.save(str(tmp_path / "q.bt"), drop_query=True)
    assert miner.Map.load(str(tmp_path / "q.bt")).query is None
    for name in ("x.BT", "x.txt"):  # JSON under another suffix (P6)
        with pytest.raises(miner.Error, match=".json or .bt"):
            m.save(str(tmp_path / name))
    with pytest.raises(miner.Error, match="path: empty"):  # "cannot replace file: Success" (P7)
        m.save("")
    m.save(tmp_path / "pathlike.json")  # an os.PathLike is a path
    assert miner.Map.load(tmp_path / "pathlike.json").query is not None
    with pytest.raises(miner.Error, match="name it .json"):
        miner.astar_region(m).save(str(tmp_path / "r.bt"))


def test_collision_queries_refuse_nan_negative_and_non_numbers():
    m = miner.Map.from_json(WALL)
    for radius in (float("nan"), -1.0, float("inf"), 1e300):  # NaN called a wall free (P9)
        with pytest.raises(miner.Error, match="radius"):
            m.is_free([5, 3, 1], radius=radius)
        with pytest.raises(miner.Error, match="radius"):
            m.segment_free([2, 3, 1], [8, 3, 1], radius=radius)
    with pytest.raises(miner.Error, match="p"):
        m.clearance([float("nan")] * 3)
    for p in (["1", "1", "1"], [1 + 1j, 1, 1], [True, True, True], [1, 1], None):
        with pytest.raises(miner.Error, match="p"):
            m.is_free(p)
    assert not m.is_free([5, 3, 1]) and m.is_free([2, 3, 1], radius=0.4)


def test_plan_ranges_and_an_unsolved_run():
    m = miner.Map.from_json(WALL)
    for kwargs, field in (({"iterations": 0}, "iterations"), ({"iterations": True}, "iterations"),
                          ({"iterations": 10**6 + 1}, "iterations"), ({"target_cost": -1.0}, "target_cost"),
                          ({"target_cost": 0.0}, "target_cost"), ({"radius": 10.5}, "radius"),
                          ({"first": 2}, "first"), ({"seed": -1}, "seed"), ({"seed": 2**64}, "seed"),
                          ({"seed": True}, "seed"), ({"planner": 3}, "planner")):  # P11, P15
        with pytest.raises(miner.Error, match=field):
            miner.plan(m, planner=kwargs.pop("planner", "rrtstar"), **kwargs)
    with pytest.raises(miner.Error, match="map"):
        miner.plan("sim-1.json", planner="rrtstar")
    assert miner.plan(m, planner="rrtstar", seed=2**64 - 1, iterations=3000).solved
    sealed = miner.Map.from_json(SEALED)
    with pytest.raises(miner.NoSolution, match="no path"):  # came back with cost 0.0 (P10)
        miner.plan(sealed, planner="rrtstar", iterations=500)


def test_minco_names_what_the_caller_gave():
    with pytest.raises(miner.Error, match=r"points\[0\] and points\[1\]"):  # not durations[0] (P13)
        miner.minco([[0, 0, 0], [1e-300, 0, 0], [1, 0, 0]])
    with pytest.raises(miner.Error, match="v_max: unused"):  # P14
        miner.minco([[0, 0, 0], [1, 0, 0], [2, 1, 0]], durations=[1.0, 1.0], v_max=-5)
    with pytest.raises(miner.Error, match="v_max"):
        miner.minco([[0, 0, 0], [1, 0, 0]], v_max=-5)
    with pytest.raises(miner.Error, match="points"):
        miner.minco(np.array([[0, 0, 0], [1, 0, 0]], dtype=bool))
    with pytest.raises(miner.Error, match="order"):
        miner.minco([[0, 0, 0], [1, 0, 0]], order=5)


def test_a_reference_flies_only_in_its_own_scenario(tmp_path):
    s = miner.Scenario.default()
    doc = json.loads((SOURCE / "fixtures" / "scenarios" / "default.json").read_text())
    doc["trajectory"]["v_max"], doc["trajectory"]["a_max"] = 0.1, 0.05
    slow = miner.Scenario.from_json(json.dumps(doc), base_dir=str(SOURCE / "fixtures" / "scenarios"))
    ref = miner.build_reference(s)
    with pytest.raises(miner.Error, match="exceed the scenario's trajectory.v_max"):  # P8
        miner.fly(slow, ref)
    # Seventeenth campaign F18: the same ends and limits, another seed or region: another route.
    base = str(SOURCE / "fixtures" / "scenarios")
    other_seed = dict(json.loads((SOURCE / "fixtures" / "scenarios" / "default.json").read_text()), seed=2)
    with pytest.raises(miner.Error, match="seed: the reference was built from a scenario whose seed differs"):
        miner.fly(miner.Scenario.from_json(json.dumps(other_seed), base_dir=base), ref)
    other_region = json.loads((SOURCE / "fixtures" / "scenarios" / "default.json").read_text())
    other_region["planner"] = dict(other_region.get("planner", {}), region="astar")
    with pytest.raises(miner.Error, match=r"planner.region: the reference was built from a scenario whose planner.region "
                                          r"differs from this one's \(\"sgan\" there, \"astar\" here\)"):
        miner.fly(miner.Scenario.from_json(json.dumps(other_region), base_dir=base), ref)
    # The network is compared by its bytes (eighteenth campaign F18): a copy of the shipped weights
    # at another path flies the reference; the same path holding other weights does not.
    weights = tmp_path / "w.bin"
    weights.write_bytes((SOURCE / "fixtures" / "sgan" / "sgan.bin").read_bytes())
    copied = json.loads((SOURCE / "fixtures" / "scenarios" / "default.json").read_text())
    copied["planner"] = dict(copied.get("planner", {}), weights=str(weights))
    assert miner.fly(miner.Scenario.from_json(json.dumps(copied), base_dir=base), ref, log=False).goal_reached
    weights.write_bytes((SOURCE / "fixtures" / "sgan" / "passability" / "lofo" / "without-forest.bin").read_bytes())
    with pytest.raises(miner.Error, match="planner.weights_sha256: the reference was built from a scenario whose"):
        miner.fly(miner.Scenario.from_json(json.dumps(copied), base_dir=base), ref)
    with pytest.raises(miner.Error, match="reference"):
        miner.fly(s, "not a reference")
    for base_dir in (str(tmp_path / "nodir"), str(SOURCE / "README.md")):  # P16
        with pytest.raises(miner.Error, match="base_dir"):
            miner.Scenario.from_json(json.dumps(doc), base_dir=base_dir)


def test_none_for_an_object_and_whole_floats_for_integers():
    m = miner.Map.from_json(WALL)
    with pytest.raises(miner.Error, match="map: expected a miner.Map, got None"):  # recheck of P15
        miner.plan(None, planner="rrtstar")
    with pytest.raises(miner.Error, match="scenario: expected a miner.Scenario, got None"):
        miner.build_reference(None)
    with pytest.raises(miner.Error, match="reference: expected a miner.Reference, got None"):
        miner.fly(miner.Scenario.default(), None)
    # A whole float is that integer (dims from numpy arithmetic); a fractional one is refused.
    assert list(miner.astar_region(m, dims=np.array([8.0, 8.0, 4.0])).dims) == [8, 8, 4]
    with pytest.raises(miner.Error, match=r"dims\[0\]"):
        miner.astar_region(m, dims=[8.5, 8, 4])
    # dims is read once: a tuple, a list, an array and a one-shot iterator give the same region;
    # what is not a sequence of 3 is named.
    assert list(miner.astar_region(m, dims=(8, 8, 4)).dims) == [8, 8, 4]
    assert list(miner.astar_region(m, dims=iter([8, 8, 4])).dims) == [8, 8, 4]
    for bad in (5, [8, 8], "884"):
        with pytest.raises(miner.Error, match="dims"):
            miner.astar_region(m, dims=bad)
    # Seeds follow the same rule (seventeenth campaign F19: seed=1.0 was refused, iterations=300.0
    # accepted): the same path for 7 and 7.0; a fraction, or a float past 2^53, is refused.
    assert np.array_equal(miner.plan(m, planner="rrtstar", seed=7.0, iterations=300).path,
                          miner.plan(m, planner="rrtstar", seed=7, iterations=300).path)
    for bad in (7.5, 2.0 ** 60, -1.0):
        with pytest.raises(miner.Error, match="seed"):
            miner.plan(m, planner="rrtstar", seed=bad, iterations=300)


# ---- issue 20, eleventh campaign: Python refuses what the CLI refuses; Ctrl-C stops a long plan ----
def test_plan_refuses_miner_options_for_the_other_planners():
    m = miner.Map.load(SIM1)
    region = miner.astar_region(m)
    for planner in ("rrtstar", "informed", "guided"):  # P2: the region was ignored without a word
        with pytest.raises(miner.Error, match="region: only planner \"miner\""):
            miner.plan(m, planner=planner, region=region, iterations=300)
        with pytest.raises(miner.Error, match="safeguard: only planner \"miner\""):
            miner.plan(m, planner=planner, safeguard=False, iterations=300)
    assert miner.plan(m, planner="miner", region=region, safeguard=False, iterations=2000).cost > 0


def test_ctrl_c_stops_a_long_plan_at_once():
    # P1: a SIGINT during a 10^6-iteration plan waited for the whole budget (43 s), then raised.
    # The planner polls every 1024 iterations: interrupted 50 ms in, the call must cost less CPU
    # than an uninterrupted 20 000-iteration plan of the same map (the budget it would have run is
    # 50 times that); CPU time of this process, compared within the test.
    import resource
    import signal
    import threading

    m = miner.Map.load(SIM1)

    def cpu():
        u = resource.getrusage(resource.RUSAGE_SELF)
        return u.ru_utime + u.ru_stime

    t0 = cpu()
    miner.plan(m, planner="rrtstar", seed=4, iterations=20000)
    uninterrupted = cpu() - t0
    timer = threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = cpu()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        miner.plan(m, planner="rrtstar", seed=4, iterations=1000000)
    interrupted = cpu() - t0
    timer.join()
    assert interrupted < uninterrupted, (interrupted, uninterrupted)
    assert miner.plan(m, planner="rrtstar", seed=4, iterations=300).cost > 0  # the module is usable after it


def test_ctrl_c_stops_a_long_flight():
    # P1 for flights: the flight polls every 4000 N3 ticks (10 s of its ~38 s); interrupted 50 ms
    # in, it costs less CPU than the whole flight.
    import resource
    import signal
    import threading

    def cpu():
        u = resource.getrusage(resource.RUSAGE_SELF)
        return u.ru_utime + u.ru_stime

    s = miner.Scenario.default()
    ref = miner.build_reference(s)
    t0 = cpu()
    miner.fly(s, ref, log=False)
    whole = cpu() - t0
    timer = threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = cpu()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        miner.fly(s, ref, log=False)
    interrupted = cpu() - t0
    timer.join()
    assert interrupted < whole, (interrupted, whole)


def test_generated_maps_saved_regions_target_iterations_and_value_types(tmp_path):
    # Map.generate is seeded: the same preset and seed give the same document, another seed another.
    a = miner.Map.generate("indoor", 3)
    assert a.to_json() == miner.Map.generate("indoor", 3).to_json()
    assert a.to_json() != miner.Map.generate("indoor", 4).to_json()
    with pytest.raises(miner.Error, match="preset"):
        miner.Map.generate("nowhere", 1)
    # A region written as JSON reads back with the same grid and cells.
    m = miner.Map.from_json(WALL)
    r = miner.astar_region(m, dims=[8, 8, 4])
    r.save(tmp_path / "r.json")
    back = miner.Region.load(str(tmp_path / "r.json"))
    assert list(back.dims) == [8, 8, 4] and back.cell_count == r.cell_count and back.source == r.source
    # target_iteration: None without a target; with one any path meets, the first solution's iteration.
    plain = miner.plan(m, planner="rrtstar", iterations=3000, seed=2)
    assert plain.solved and plain.target_iteration is None
    met = miner.plan(m, planner="rrtstar", iterations=3000, seed=2, target_cost=1e6)
    assert met.target_iteration == met.first_iteration == plain.first_iteration
    # What a value must be, named: a number (not a str, not beyond a double), a path, finite points.
    with pytest.raises(miner.Error, match="radius: expected a number, got str"):
        miner.plan(m, planner="rrtstar", radius="0.1")
    with pytest.raises(miner.Error, match="radius: 1" + "0" * 400 + " is beyond the largest double"):
        miner.plan(m, planner="rrtstar", radius=10**400)
    with pytest.raises(miner.Error, match="path: expected a path"):
        miner.Map.load(3)
    with pytest.raises(miner.Error, match=r"points\[1\]: must be finite, got nan"):
        miner.minco([[0, 0, 0], [np.nan, 0, 0], [1, 1, 1]])
    with pytest.raises(miner.Error, match=r"points: expected an array of numbers, got list of dtype <U"):
        miner.minco([["a", "b", "c"], [1, 1, 1]])
    with pytest.raises(miner.Error, match=r"points: expected an array of numbers, got list$"):  # ragged rows
        miner.minco([[0, 0, 0], [1, 1]])
