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

    def test_script_citations_are_read(self):
        found = trace.script_citations(__file__)
        self.assertIn("REQ-HARNESS-001", found)


if __name__ == "__main__":
    unittest.main(verbosity=1)
