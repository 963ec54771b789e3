#!/usr/bin/env python3
"""Tests of the traceability checker: it must catch planted gaps.

cites: REQ-HARNESS-001
"""
import os
import pathlib
import stat
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import trace  # noqa: E402  (ci/trace.py)

SPEC = {
    "world.md": "# World\n\n### REQ-WORLD-001: Map format\nText.\n\n### REQ-WORLD-002: Validation\nText.\n",
    "core.md": "## REQ-CORE-001 — RNG\n",
}


class TraceCheckerTest(unittest.TestCase):
    def test_parses_headings_with_titles(self):
        reqs, errors = trace.parse_spec(SPEC)
        self.assertEqual(errors, [])
        self.assertEqual(set(reqs), {"REQ-WORLD-001", "REQ-WORLD-002", "REQ-CORE-001"})
        self.assertEqual(reqs["REQ-WORLD-002"], ("world.md", "Validation"))

    def test_clean_when_every_requirement_is_cited(self):
        reqs, _ = trace.parse_spec(SPEC)
        cites = {r: ["t"] for r in reqs}
        self.assertEqual(trace.check(reqs, cites), [])

    def test_planted_uncovered_requirement_is_caught(self):
        reqs, _ = trace.parse_spec(SPEC)
        cites = {"REQ-WORLD-001": ["t1"], "REQ-CORE-001": ["t2"]}
        errors = trace.check(reqs, cites)
        self.assertEqual(len(errors), 1)
        self.assertIn("uncovered requirement: REQ-WORLD-002", errors[0])

    def test_planted_unknown_id_is_caught(self):
        reqs, _ = trace.parse_spec(SPEC)
        cites = {r: ["t"] for r in reqs}
        cites["REQ-WORLD-099"] = ["world_test: bogus"]
        errors = trace.check(reqs, cites)
        self.assertEqual(len(errors), 1)
        self.assertIn("unknown requirement ID: REQ-WORLD-099", errors[0])
        self.assertIn("world_test: bogus", errors[0])

    def test_duplicate_ids_are_caught(self):
        _, errors = trace.parse_spec({"a.md": "### REQ-A-001: x\n", "b.md": "### REQ-A-001: y\n"})
        self.assertEqual(len(errors), 1)
        self.assertIn("duplicate requirement REQ-A-001", errors[0])

    def test_matrix_lists_tests_and_marks_gaps(self):
        reqs, _ = trace.parse_spec(SPEC)
        text = trace.render_matrix(reqs, {"REQ-WORLD-001": ["bin: test one"]})
        self.assertIn("| REQ-WORLD-001 | world.md | Map format | bin: test one |", text)
        self.assertIn("| REQ-CORE-001 | core.md | RNG | **none** |", text)
        self.assertIn("1 of 3 requirements covered.", text)

    def test_end_to_end_with_a_fake_catch_binary_fails_on_a_gap(self):
        with tempfile.TemporaryDirectory() as d:
            spec = pathlib.Path(d, "spec")
            spec.mkdir()
            for name, text in SPEC.items():
                (spec / name).write_text(text)
            fake = pathlib.Path(d, "fake_test")
            # Answers --list-tags and --list-test-names-only like Catch2 v2 does.
            fake.write_text(
                "#!/bin/sh\n"
                'if [ "$1" = "--list-tags" ]; then\n'
                '  printf "All available tags:\\n   1  [REQ-WORLD-001]\\n   1  [REQ-CORE-001]\\n   1  [unit]\\n3 tags\\n"\n'
                'elif [ "$#" = "1" ]; then printf "Map loads\\nRNG repeats\\n"\n'
                'elif [ "$2" = "[REQ-WORLD-001]" ]; then echo "Map loads"\n'
                'elif [ "$2" = "[REQ-CORE-001]" ]; then echo "RNG repeats"\n'
                "fi\n")
            fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
            out = pathlib.Path(d, "matrix.md")
            cmd = [sys.executable, trace.__file__, "--spec", str(spec), "--out", str(out), str(fake)]
            r = subprocess.run(cmd, capture_output=True, text=True)
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertIn("uncovered requirement: REQ-WORLD-002", r.stderr)
            self.assertIn("fake_test: Map loads", out.read_text())
            (spec / "world.md").write_text("### REQ-WORLD-001: Map format\n")
            r = subprocess.run(cmd, capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)

    # Evidence mode (issue 19 item 4): only tests that ran and passed in this run count.
    CTEST = {"tests": [
        {"name": "world_test: Map loads", "command": ["/b/world_test", "Map loads"],
         "properties": [{"name": "LABELS", "value": ["unit"]}]},
        {"name": "world_test: Map saves", "command": ["/b/world_test", "Map saves"],
         "properties": [{"name": "LABELS", "value": ["property"]}]},
        {"name": "slow_test: Sweep", "command": ["/b/slow_test", "Sweep"],
         "properties": [{"name": "LABELS", "value": ["long"]}]},
        {"name": "pytests", "command": ["/usr/bin/python3", "-m", "pytest", "/src/python/tests"],
         "properties": [{"name": "LABELS", "value": ["unit"]}]},
    ]}

    def junit(self, cases):
        body = "".join(f'<testcase name="{n}" status="{s}">' + ("<failure message='x'/>" if s == "fail" else "")
                       + "</testcase>" for n, s in cases.items())
        return f'<?xml version="1.0"?><testsuite tests="{len(cases)}">{body}</testsuite>'

    def test_evidence_counts_only_tests_that_ran_and_passed(self):
        import json
        ctest = trace.read_ctest_json(json.dumps(self.CTEST))
        junit = trace.read_junit(self.junit({"world_test: Map loads": "run", "world_test: Map saves": "fail",
                                             "slow_test: Sweep": "run"}))
        self.assertEqual(junit["world_test: Map saves"], "failed")
        cites = {"REQ-A-001": ["world_test: Map loads", "world_test: Map saves"],
                 "REQ-A-002": ["world_test: Map saves"],          # only a failing test
                 "REQ-A-003": ["slow_test: Sweep"],               # only a long test
                 "REQ-A-004": ["pytests"],                        # registered, not run
                 "REQ-A-005": ["hidden_test: never registered"]}
        kept, dropped = trace.evidence(cites, ctest, junit)
        self.assertEqual(kept["REQ-A-001"], ["world_test: Map loads"])
        for rid in ("REQ-A-002", "REQ-A-003", "REQ-A-004", "REQ-A-005"):
            self.assertNotIn(rid, kept)
        self.assertIn("failed", dropped["world_test: Map saves"])
        self.assertIn("long", dropped["slow_test: Sweep"])
        self.assertIn("not run", dropped["pytests"])
        self.assertIn("not registered", dropped["hidden_test: never registered"])

    def test_evidence_matrix_gives_kinds_and_flags_single_tests(self):
        import json
        ctest = trace.read_ctest_json(json.dumps(self.CTEST))
        reqs = {"REQ-A-001": ("a.md", "One"), "REQ-A-002": ("a.md", "Two")}
        text = trace.render_evidence(reqs, {"REQ-A-001": ["world_test: Map loads", "world_test: Map saves"],
                                            "REQ-A-002": ["world_test: Map loads"]}, ctest)
        self.assertIn("| REQ-A-001 | a.md | One | property, unit | 2 |", text)
        self.assertIn("1 rest on a single test: REQ-A-002", text)

    def test_scripts_count_through_the_tests_that_run_them(self):
        import json
        ctest = trace.read_ctest_json(json.dumps(self.CTEST))
        self.assertEqual(trace.script_runners(ctest, "/src/python/tests/test_miner.py"), ["pytests"])
        self.assertEqual(trace.script_runners(ctest, "/src/other/check.py"), [])

    def test_end_to_end_evidence_mode_fails_when_the_only_citing_test_failed(self):
        import json
        with tempfile.TemporaryDirectory() as d:
            spec = pathlib.Path(d, "spec")
            spec.mkdir()
            (spec / "world.md").write_text("### REQ-WORLD-001: Map format\n### REQ-WORLD-002: Hidden\n")
            fake = pathlib.Path(d, "world_test")
            # Like Catch2 v2: a hidden test appears under its tag but not in the plain list.
            fake.write_text(
                "#!/bin/sh\n"
                'if [ "$1" = "--list-tags" ]; then printf "   1  [REQ-WORLD-001]\\n   1  [REQ-WORLD-002]\\n"\n'
                'elif [ "$#" = "1" ]; then echo "Map loads"\n'
                'elif [ "$2" = "[REQ-WORLD-001]" ]; then echo "Map loads"\n'
                'elif [ "$2" = "[REQ-WORLD-002]" ]; then echo "Hidden check"\n'
                "fi\n")
            fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
            cj, ju, out = (pathlib.Path(d, n) for n in ("ctest.json", "junit.xml", "m.md"))
            cj.write_text(json.dumps(self.CTEST))
            cmd = [sys.executable, trace.__file__, "--spec", str(spec), "--out", str(out),
                   "--ctest-json", str(cj), "--junit", str(ju), str(fake)]
            ju.write_text(self.junit({"world_test: Map loads": "run"}))
            r = subprocess.run(cmd, capture_output=True, text=True)
            self.assertEqual(r.returncode, 1, r.stderr)  # REQ-WORLD-002 rests on a hidden test only
            self.assertIn("requirement without evidence: REQ-WORLD-002", r.stderr)
            self.assertNotIn("REQ-WORLD-001 (", r.stderr)
            (spec / "world.md").write_text("### REQ-WORLD-001: Map format\n")
            r = subprocess.run(cmd, capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            ju.write_text(self.junit({"world_test: Map loads": "fail"}))
            r = subprocess.run(cmd, capture_output=True, text=True)
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertIn("world_test: Map loads: failed in this run", r.stderr)

    def test_list_tests_output_is_parsed_with_wrapped_names_and_tags(self):
        text = ("All available test cases:\n"
                "  Short test\n      [REQ-A-001][unit]\n"
                "  A long name that Catch2 wraps at eighty columns when it lists the tests of\n"
                "    a binary\n      [REQ-A-002][REQ-A-001]\n      [REQ-B-003]\n"
                "3 test cases\n")
        exact = {"Short test", "A long name that Catch2 wraps at eighty columns when it lists the tests of a binary"}
        got = trace.parse_list_tests(text, exact)
        self.assertEqual(sorted(got["REQ-A-001"]), sorted(exact))
        self.assertEqual(got["REQ-B-003"], [sorted(exact)[0]])
        # A wrapped name that matches no exact name (a split word): no guess, fall back.
        self.assertIsNone(trace.parse_list_tests(text, {"Short test", "something else"}))

    def test_script_citations_are_read(self):
        found = trace.script_citations(__file__)
        self.assertIn("REQ-HARNESS-001", found)


if __name__ == "__main__":
    unittest.main(verbosity=1)
