#!/usr/bin/env python3
"""Tests of the mutation runner's own logic: the catalogue checks, the choice of tests and the
score (the campaign itself is the ctest test `mutation`).

cites: REQ-HARNESS-008
"""
import json
import os
import pathlib
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mutation  # noqa: E402  (ci/mutation.py)


def mutant(**over):
    m = {"id": "traj-001", "capability": "traj", "file": "src/a.cpp", "operator": "arithmetic",
         "find": "a + b", "replace": "a - b", "requirements": ["REQ-TRAJ-001"], "why": "sum becomes difference"}
    m.update(over)
    return m


class CatalogueTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.root = pathlib.Path(self.dir.name)
        (self.root / "src").mkdir()
        (self.root / "src" / "a.cpp").write_text("int f(int a, int b) { return a + b; }\nint g() { return 1 < 2; }\n")

    def tearDown(self):
        self.dir.cleanup()

    def load(self, mutants, fmt="miner-mutants-v1"):
        path = self.root / "mutants.json"
        path.write_text(json.dumps({"format": fmt, "mutants": mutants}))
        return mutation.load_catalogue(path, self.root)

    def refused(self, mutants, text, fmt="miner-mutants-v1"):
        with self.assertRaises(mutation.CatalogueError) as cm:
            self.load(mutants, fmt)
        self.assertIn(text, str(cm.exception))

    def test_a_good_catalogue_loads(self):
        got = self.load([mutant(), mutant(id="traj-002", operator="comparison", find="1 < 2", replace="1 <= 2")])
        self.assertEqual([m["id"] for m in got], ["traj-001", "traj-002"])

    def test_the_repository_catalogue_applies_to_this_tree(self):
        # Every mutant's `find` still occurs exactly once in its file and every requirement it
        # names exists in spec/: a refactoring that moves the mutated line must move the mutant.
        root = pathlib.Path(__file__).resolve().parent.parent
        got = mutation.load_catalogue(root / "ci" / "mutants.json", root)
        self.assertGreaterEqual(len(got), 50)
        spec = "".join(p.read_text() for p in (root / "spec").glob("*.md"))
        for m in got:
            for req in m["requirements"]:
                self.assertIn("### " + req + ":", spec, m["id"])

    def test_bad_catalogues_are_refused_naming_the_fault(self):
        self.refused([mutant()], "format must be", fmt="other")
        self.refused([], "non-empty")
        self.refused([mutant(colour="red")], "unknown key")
        self.refused([mutant(operator="rename")], "operator 'rename'")
        self.refused([mutant(), mutant()], "duplicate id traj-001")
        self.refused([mutant(find="a * b")], "occurs 0 times")
        self.refused([mutant(find="int")], "occurs 4 times")
        self.refused([mutant(replace="a + b")], "replace equals find")
        self.refused([mutant(requirements=[])], "requirements")
        self.refused([mutant(file="src/none.cpp")], "no file")
        m = mutant()
        del m["why"]
        self.refused([m], "missing why")


class SelectionTest(unittest.TestCase):
    def test_goldens_and_long_binaries_never_judge_a_mutant(self):
        b = mutation.Build(pathlib.Path("/nonexistent"), 1)
        b.binaries = {
            "traj_test": {"path": "/b/traj_test", "labels": {"unit"}, "tags": {"REQ-TRAJ-001": ["x"], "REQ-TRAJ-002": ["y"]}},
            "traj_golden": {"path": "/b/traj_golden", "labels": {"golden"}, "tags": {"REQ-TRAJ-001": ["g"]}},
            "traj_long": {"path": "/b/traj_long", "labels": {"long"}, "tags": {"REQ-TRAJ-001": ["l"]}},
            "plan_test": {"path": "/b/plan_test", "labels": {"statistical"}, "tags": {"REQ-PLAN-001": ["p"]}},
        }
        self.assertEqual(b.selection(["REQ-TRAJ-001", "REQ-TRAJ-002"]),
                         [("traj_test", "[REQ-TRAJ-001]~[.],[REQ-TRAJ-002]~[.]")])
        self.assertEqual(b.selection(["REQ-PLAN-001", "REQ-TRAJ-009"]), [("plan_test", "[REQ-PLAN-001]~[.]")])
        self.assertEqual(b.selection(["REQ-WORLD-001"]), [])


class ReportTest(unittest.TestCase):
    def test_score_counts_killed_over_killed_and_survived(self):
        results = [dict(id="a", capability="traj", operator="arithmetic", why="", status="killed", by="t"),
                   dict(id="b", capability="traj", operator="constant", why="", status="survived"),
                   dict(id="c", capability="traj", operator="constant", why="", status="stillborn"),
                   dict(id="d", capability="plan", operator="constant", why="", status="excluded", by="equivalent")]
        text = mutation.render(results, {"traj": (1, 1), "plan": (0, 0)}, "abc123")
        self.assertIn("| traj | 1 | 1 | 50.0 % | 1 | 0 | 0 |", text)
        self.assertIn("| plan | 0 | 0 | — | 0 | 0 | 1 |", text)
        self.assertIn("| b | traj | constant | survived |", text)


if __name__ == "__main__":
    unittest.main(verbosity=1)
