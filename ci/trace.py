#!/usr/bin/env python3
"""Requirement -> test traceability for MINER (REQ-HARNESS-001).

Reads the requirement IDs from the headings of spec/*.md
(`### REQ-<AREA>-NNN: title`), asks every Catch2 test binary which tests carry
which `[REQ-...]` tag, and fails when

  * a requirement is cited by no test (an uncovered requirement), or
  * a test cites an ID that no spec file defines (an unknown ID), or
  * two spec headings define the same ID.

It writes a Markdown matrix requirement -> tests (build/traceability.md).
A hidden Catch2 test (tag `[.]`, which a plain run of its binary skips) never counts.

Evidence mode (issue 19 item 4; ci/test.sh runs it after ctest): with
`--ctest-json F` (the output of `ctest --show-only=json-v1`: each test's name, command
and labels) and `--junit F` (`ctest --output-junit`: what ran and how it ended), a
requirement counts as covered only by a citing test that ran in this ctest run and
passed, and whose labels are none of long, cluster, fuzz (runs CI does not make). The
matrix then gives, per requirement, the passing tests, the kinds of test that hold it
(unit, property, golden, statistical, bench-smoke: the ctest labels) and flags those that
rest on a single test.

Usage: trace.py --spec DIR --out FILE [--extra-citations FILE ...]
                [--ctest-json F --junit F] BINARY...
Non-Catch tests (scripts) cite requirements with a line containing
`cites: REQ-...` and are passed with --extra-citations; in evidence mode they count
through the ctest tests whose command names the script (or a folder holding it).
"""
from __future__ import annotations

import argparse
import json
import pathlib
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from collections import defaultdict

REQ_ID = r"REQ-[A-Z][A-Z0-9]*-\d{3}"
HEADING = re.compile(r"^#{2,4}\s+(" + REQ_ID + r")\b[:\s\u2014-]*(.*)$")
TAG = re.compile(r"\[(" + REQ_ID + r")\]")
ANY_ID = re.compile(REQ_ID)


def parse_spec(files: dict[str, str]) -> tuple[dict[str, tuple[str, str]], list[str]]:
    """{file name: text} -> ({id: (file, title)}, errors)."""
    reqs: dict[str, tuple[str, str]] = {}
    errors = []
    for name, text in sorted(files.items()):
        for line in text.splitlines():
            m = HEADING.match(line)
            if not m:
                continue
            rid, title = m.group(1), m.group(2).strip()
            if rid in reqs:
                errors.append(f"duplicate requirement {rid} in {name} (first in {reqs[rid][0]})")
            else:
                reqs[rid] = (name, title)
    return reqs, errors


def check(reqs: dict[str, tuple[str, str]], citations: dict[str, list[str]]) -> list[str]:
    """citations: {id: [test, ...]} -> errors for uncovered and unknown IDs."""
    errors = []
    for rid in sorted(reqs):
        if not citations.get(rid):
            errors.append(f"uncovered requirement: {rid} ({reqs[rid][0]}: {reqs[rid][1]}) is cited by no test")
    for rid in sorted(citations):
        if rid not in reqs:
            tests = "; ".join(citations[rid][:3])
            errors.append(f"unknown requirement ID: {rid} is cited by {tests} but defined in no spec file")
    return errors


# Labels of runs CI does not make: a test under one of them is no evidence for CI's matrix.
UNCOUNTED_LABELS = {"long", "cluster", "fuzz"}


def read_ctest_json(text: str) -> dict[str, dict]:
    """`ctest --show-only=json-v1` -> {test name: {"command": [...], "labels": [...]}}."""
    tests = {}
    for t in json.loads(text).get("tests", []):
        labels: list[str] = []
        for prop in t.get("properties", []):
            if prop.get("name") == "LABELS":
                labels = list(prop.get("value", []))
        tests[t["name"]] = {"command": list(t.get("command", [])), "labels": labels}
    return tests


def read_junit(text: str) -> dict[str, str]:
    """`ctest --output-junit` -> {test name: "passed" | "failed" | "not run"}."""
    results = {}
    for case in ET.fromstring(text).iter("testcase"):
        status = case.get("status", "")
        failed = case.find("failure") is not None or case.find("error") is not None
        if status == "run" and not failed:
            results[case.get("name", "")] = "passed"
        elif status == "fail" or failed:
            results[case.get("name", "")] = "failed"
        else:
            results[case.get("name", "")] = "not run"
    return results


def script_runners(ctest: dict[str, dict], script: str) -> list[str]:
    """The ctest tests whose command names `script` or a folder above it."""
    path = pathlib.Path(script).resolve()
    runners = []
    for name, t in ctest.items():
        for arg in t["command"]:
            try:
                a = pathlib.Path(arg).resolve()
            except (OSError, ValueError):
                continue
            if a == path or (arg.startswith("/") and a in path.parents and a != pathlib.Path("/")):
                runners.append(name)
                break
    return runners


def evidence(citations: dict[str, list[str]], ctest: dict[str, dict], junit: dict[str, str]
             ) -> tuple[dict[str, list[str]], dict[str, str]]:
    """Keeps the citing tests that ran and passed in this run under a counted label.
    citations: {id: [ctest test name]} -> ({id: [passing test]}, {test: why it does not count})."""
    kept: dict[str, list[str]] = defaultdict(list)
    dropped: dict[str, str] = {}
    for rid, tests in citations.items():
        for t in tests:
            # catch_discover_tests registers "binary: name" as "binary:name".
            if t not in ctest and ": " in t and t.replace(": ", ":", 1) in ctest:
                t = t.replace(": ", ":", 1)
            labels = set(ctest.get(t, {}).get("labels", []))
            if t not in ctest:
                dropped[t] = "not registered with ctest"
            elif labels & UNCOUNTED_LABELS:
                dropped[t] = "label " + ", ".join(sorted(labels & UNCOUNTED_LABELS)) + " (not a CI run)"
            elif junit.get(t) != "passed":
                dropped[t] = junit.get(t, "not run") + " in this run"
            else:
                kept[rid].append(t)
    return kept, dropped


def kinds_of(tests: list[str], ctest: dict[str, dict]) -> list[str]:
    return sorted({label for t in tests for label in ctest.get(t, {}).get("labels", [])})


def render_evidence(reqs: dict[str, tuple[str, str]], kept: dict[str, list[str]], ctest: dict[str, dict]) -> str:
    lines = ["# Traceability matrix (evidence)", "",
             "Generated by ci/trace.py after ctest: a requirement counts only tests that cite it, ran in",
             "this ctest run and passed (not hidden, not labelled long, cluster or fuzz).", "",
             "| requirement | spec | title | kinds | n | tests |", "|---|---|---|---|---|---|"]
    single = []
    for rid in sorted(reqs):
        name, title = reqs[rid]
        tests = sorted(set(kept.get(rid, [])))
        if len(tests) == 1:
            single.append(rid)
        kinds = ", ".join(kinds_of(tests, ctest)) or "**none**"
        lines.append(f"| {rid} | {name} | {title} | {kinds} | {len(tests)} | {'<br>'.join(tests) or '**none**'} |")
    covered = sum(1 for r in reqs if kept.get(r))
    lines += ["", f"{covered} of {len(reqs)} requirements held by a passing test in this run; "
              f"{len(single)} rest on a single test: {', '.join(single) or 'none'}."]
    return "\n".join(lines) + "\n"


def render_matrix(reqs: dict[str, tuple[str, str]], citations: dict[str, list[str]]) -> str:
    lines = ["# Traceability matrix", "",
             "Generated by ci/trace.py from spec/*.md and the tests' tags.", "",
             "| requirement | spec | title | tests |", "|---|---|---|---|"]
    for rid in sorted(reqs):
        name, title = reqs[rid]
        tests = "<br>".join(sorted(citations.get(rid, []))) or "**none**"
        lines.append(f"| {rid} | {name} | {title} | {tests} |")
    covered = sum(1 for r in reqs if citations.get(r))
    lines += ["", f"{covered} of {len(reqs)} requirements covered."]
    return "\n".join(lines) + "\n"


def run(args: list[str]) -> str:
    result = subprocess.run(args, capture_output=True, text=True, check=False)
    if result.returncode < 0 or result.returncode > 255:
        raise RuntimeError(f"{' '.join(args)} crashed: {result.stderr}")
    return result.stdout


def parse_list_tests(text: str, exact_names: set[str]) -> dict[str, list[str]] | None:
    """Catch2 v2's `--list-tests` (names at indent 2, wrapped on lines at indent 4, tags at
    indent 6) -> {REQ id: [exact test name]}; None when a wrapped name cannot be matched to
    one of exact_names (whitespace aside), so the caller falls back to a query per tag."""
    if "test case" not in text:  # not Catch2's listing
        return None
    by_words = {" ".join(n.split()): n for n in exact_names}
    entries: list[list[str]] = []  # [name parts, tag text]
    for line in text.splitlines():
        indent = len(line) - len(line.lstrip(" "))
        body = line.strip()
        if not body or indent == 0:
            continue
        if indent >= 6 and body.startswith("[") and entries:
            entries[-1][1] += body
        elif indent >= 4 and entries and not entries[-1][1]:
            entries[-1][0] += " " + body
        elif indent == 2:
            entries.append([body, ""])
        else:
            return None
    if len(entries) != len(exact_names):
        return None
    found: dict[str, list[str]] = defaultdict(list)
    for name, tags in entries:
        exact = by_words.get(" ".join(name.split()))
        if exact is None:
            return None
        for rid in sorted(set(TAG.findall(tags))):
            found[rid].append(exact)
    return found


def catch_citations(binary: str) -> dict[str, list[str]]:
    """Asks a Catch2 v2 binary for its tests and their REQ tags (one `--list-tests`, checked
    against `--list-test-names-only`; else a query per tag); a hidden test (one a plain run
    skips: absent from the unfiltered list) does not count."""
    found: dict[str, list[str]] = defaultdict(list)
    short = pathlib.Path(binary).name
    visible = {n.strip() for n in run([binary, "--list-test-names-only"]).splitlines() if n.strip()}
    listed = parse_list_tests(run([binary, "--list-tests"]), visible)
    if listed is not None:
        for rid, names in listed.items():
            found[rid].extend(f"{short}: {n}" for n in names)
        return found
    tags = sorted(set(TAG.findall(run([binary, "--list-tags"]))))
    for rid in tags:
        out = run([binary, "--list-test-names-only", f"[{rid}]"])
        for name in out.splitlines():
            if name.strip() and name.strip() in visible:
                found[rid].append(f"{short}: {name.strip()}")
    return found


def script_citations(path: str) -> dict[str, list[str]]:
    found: dict[str, list[str]] = defaultdict(list)
    for line in pathlib.Path(path).read_text().splitlines():
        if "cites:" in line:
            for rid in ANY_ID.findall(line.split("cites:", 1)[1]):
                found[rid].append(pathlib.Path(path).name)
    return found


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spec", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--extra-citations", nargs="*", default=[])
    ap.add_argument("--ctest-json", help="ctest --show-only=json-v1 output (evidence mode, with --junit)")
    ap.add_argument("--junit", help="ctest --output-junit results of this run (evidence mode)")
    ap.add_argument("binaries", nargs="*")
    a = ap.parse_args(argv)
    if bool(a.ctest_json) != bool(a.junit):
        print("trace.py: --ctest-json and --junit go together (evidence mode)", file=sys.stderr)
        return 2

    spec_files = {p.name: p.read_text() for p in sorted(pathlib.Path(a.spec).glob("*.md"))}
    if not spec_files:
        print(f"trace.py: no spec files in {a.spec}", file=sys.stderr)
        return 1
    reqs, errors = parse_spec(spec_files)
    citations: dict[str, list[str]] = defaultdict(list)
    if a.junit:
        ctest = read_ctest_json(pathlib.Path(a.ctest_json).read_text())
        junit = read_junit(pathlib.Path(a.junit).read_text())
        for source in [catch_citations(b) for b in a.binaries]:
            for rid, tests in source.items():
                citations[rid].extend(tests)
        for script in a.extra_citations:
            runners = script_runners(ctest, script)
            for rid in script_citations(script):
                citations[rid].extend(runners)
        errors += [e for e in check(reqs, citations) if e.startswith("unknown")]
        kept, dropped = evidence(citations, ctest, junit)
        for rid in sorted(reqs):
            if not kept.get(rid):
                why = "; ".join(f"{t}: {dropped.get(t, '?')}" for t in sorted(set(citations.get(rid, []))))
                errors.append(f"requirement without evidence: {rid} ({reqs[rid][0]}: {reqs[rid][1]}) has no "
                              f"citing test that ran and passed in this run ({why or 'no citing test'})")
        pathlib.Path(a.out).write_text(render_evidence(reqs, kept, ctest))
        single = sum(1 for r in reqs if len(set(kept.get(r, []))) == 1)
        print(f"trace.py: {len(reqs)} requirements, {sum(1 for r in reqs if kept.get(r))} held by a test that "
              f"passed in this run, {single} by a single test; matrix in {a.out}")
        for e in errors:
            print(f"trace.py: error: {e}", file=sys.stderr)
        return 1 if errors else 0
    for source in [catch_citations(b) for b in a.binaries] + [script_citations(p) for p in a.extra_citations]:
        for rid, tests in source.items():
            citations[rid].extend(tests)
    errors += check(reqs, citations)
    pathlib.Path(a.out).write_text(render_matrix(reqs, citations))
    print(f"trace.py: {len(reqs)} requirements, {sum(1 for r in reqs if citations.get(r))} covered; matrix in {a.out}")
    for e in errors:
        print(f"trace.py: error: {e}", file=sys.stderr)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
