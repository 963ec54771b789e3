#!/usr/bin/env python3
"""Mutation testing of MINER's numerical core (issue 19 item 1; REQ-HARNESS-008).

A mutant is one textual edit of one source file from the catalogue ci/mutants.json
(operators: arithmetic and comparison swaps, constant and exponent changes, dropped terms,
swapped arguments), with the requirements whose tests should notice it. For each mutant the
runner

  1. applies the edit to a scratch copy of the tree (WORK/tree; the checkout is never
     touched), rebuilds incrementally only the test binaries it will run (WORK/build,
     Release), and
  2. runs the Catch2 tests that cite those requirements: `binary "[REQ-X]~[.]"` for every
     test binary holding such a test, except end-to-end goldens (binaries labelled golden)
     and the long/cluster/fuzz labels. The mutant is killed when one of them fails or times
     out; a mutant that does not compile is "stillborn" and left out of the score.

Before any mutant, each selection of tests runs once on the unmutated tree: a selection that
fails there makes its mutants "unusable" (a broken baseline kills nothing). The score per
capability is killed / (killed + survived). A catalogue entry may carry "excluded": "reason"
(an equivalent mutant, argued): it is listed, not run.

Usage:
  ci/mutation.py [--catalogue ci/mutants.json] [--work build/mutation] [--only ID ...]
                 [--capability CAP ...] [--jobs 2] [--timeout 900] [--min-score 0.95]
                 [--report FILE.md] [--json FILE]
Exit status: 0 when every capability run reaches --min-score, 1 otherwise, 2 on a bad
catalogue or a broken baseline build.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import trace  # noqa: E402  (ci/trace.py: the REQ tags of a Catch2 binary)

ROOT = pathlib.Path(__file__).resolve().parent.parent
OPERATORS = {"arithmetic", "comparison", "constant", "exponent", "drop-term", "swap-args"}
SKIPPED_LABELS = {"golden", "long", "cluster", "fuzz", "mutation"}
KEYS = {"id", "capability", "file", "operator", "find", "replace", "requirements", "why", "excluded"}


class CatalogueError(Exception):
    pass


def load_catalogue(path: pathlib.Path, root: pathlib.Path) -> list[dict]:
    """Reads and checks the catalogue: known keys and operators, unique ids, each `find`
    present exactly once in its file and different from `replace`."""
    doc = json.loads(path.read_text())
    if doc.get("format") != "miner-mutants-v1":
        raise CatalogueError(f"{path}: format must be miner-mutants-v1")
    mutants = doc.get("mutants")
    if not isinstance(mutants, list) or not mutants:
        raise CatalogueError(f"{path}: mutants must be a non-empty list")
    seen = set()
    for i, m in enumerate(mutants):
        where = f"{path}: mutants[{i}]"
        unknown = set(m) - KEYS
        if unknown:
            raise CatalogueError(f"{where}: unknown key(s) {sorted(unknown)}")
        for k in ("id", "capability", "file", "operator", "find", "replace", "requirements", "why"):
            if k not in m:
                raise CatalogueError(f"{where}: missing {k}")
        if m["id"] in seen:
            raise CatalogueError(f"{where}: duplicate id {m['id']}")
        seen.add(m["id"])
        if m["operator"] not in OPERATORS:
            raise CatalogueError(f"{where} ({m['id']}): operator {m['operator']!r} is not one of {sorted(OPERATORS)}")
        if not m["requirements"] or not all(str(r).startswith("REQ-") for r in m["requirements"]):
            raise CatalogueError(f"{where} ({m['id']}): requirements must list REQ- IDs")
        if m["find"] == m["replace"]:
            raise CatalogueError(f"{where} ({m['id']}): replace equals find (no mutation)")
        f = root / m["file"]
        if not f.is_file():
            raise CatalogueError(f"{where} ({m['id']}): no file {m['file']}")
        count = f.read_text().count(m["find"])
        if count != 1:
            raise CatalogueError(f"{where} ({m['id']}): `find` occurs {count} times in {m['file']} (must be once)")
    return mutants


def sync_tree(root: pathlib.Path, tree: pathlib.Path) -> None:
    """Copies the checkout's tracked and untracked-not-ignored files into tree, rewriting only
    files whose bytes differ (so an incremental build rebuilds only what changed)."""
    files = subprocess.run(["git", "-C", str(root), "ls-files", "-co", "--exclude-standard", "-z"],
                           check=True, capture_output=True).stdout.decode().split("\0")
    for rel in filter(None, files):
        src, dst = root / rel, tree / rel
        if not src.is_file():
            continue
        if dst.is_file() and dst.read_bytes() == src.read_bytes():
            continue
        dst.parent.mkdir(parents=True, exist_ok=True)
        # The copy gets the time of now, not the checkout's: with copy2's older time, objects the
        # scratch build made later from other bytes looked up to date to ninja (session 31: a
        # stale grid.cpp.o failed the new tests unmutated, "unusable").
        shutil.copyfile(src, dst)
        shutil.copymode(src, dst)


def sh(cmd: list[str], timeout: float | None = None, cwd: pathlib.Path | None = None,
       env: dict[str, str] | None = None) -> tuple[int, str]:
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=cwd,
                           env=None if env is None else {**os.environ, **env})
        return r.returncode, r.stdout + r.stderr
    except subprocess.TimeoutExpired:
        return -9, f"timed out after {timeout} s"


class Build:
    def __init__(self, work: pathlib.Path, jobs: int):
        self.tree, self.dir, self.jobs = work / "tree", work / "build", jobs
        self.binaries: dict[str, dict] = {}   # target name -> {"path", "labels", "tags": {REQ: [tests]}}

    def configure(self) -> None:
        if not (self.dir / "build.ninja").exists():
            rc, out = sh(["cmake", "-S", str(self.tree), "-B", str(self.dir), "-G", "Ninja",
                          "-DCMAKE_BUILD_TYPE=Release"])
            if rc != 0:
                raise RuntimeError("configure failed:\n" + out[-3000:])

    def build(self, targets: list[str] | None = None) -> tuple[bool, str]:
        cmd = ["cmake", "--build", str(self.dir), "-j", str(self.jobs)]
        for t in targets or []:
            cmd += ["--target", t]
        rc, out = sh(cmd)
        return rc == 0, out

    def discover(self) -> None:
        """The Catch2 test binaries, their ctest labels and REQ tags."""
        rc, out = sh(["ctest", "--show-only=json-v1"], cwd=self.dir)
        if rc != 0:
            raise RuntimeError("ctest --show-only failed:\n" + out[-2000:])
        tests = trace.read_ctest_json(out[out.index("{"):])
        for name, t in tests.items():
            cmd = t["command"]
            if not cmd or ":" not in name:
                continue
            path = pathlib.Path(cmd[0])
            target = path.name
            # Only the tests catch_discover_tests registered ("target:name"); the same binary
            # registered again under another label (e.g. "x (long): ...") is not its label.
            if not str(path).startswith(str(self.dir)) or target in self.binaries or name.split(":", 1)[0] != target:
                continue
            self.binaries[target] = {"path": str(path), "labels": set(t["labels"]), "tags": {}}
        for target, b in self.binaries.items():
            b["tags"] = dict(trace.catch_citations(b["path"]))

    def selection(self, requirements: list[str]) -> list[tuple[str, str]]:
        """(target, Catch2 test spec) pairs that run the requirements' tests, goldens and
        long/cluster/fuzz binaries left out."""
        out = []
        for target, b in sorted(self.binaries.items()):
            if b["labels"] & SKIPPED_LABELS:
                continue
            held = [r for r in requirements if b["tags"].get(r)]
            if held:
                out.append((target, ",".join(f"[{r}]~[.]" for r in held)))
        return out

    def run(self, selection: list[tuple[str, str]], timeout: float) -> tuple[bool, str]:
        """True when every selected test passes; else the first failing (target, spec)."""
        for target, spec in selection:
            # As ctest runs them: MINER_SOURCE_DIR names the (scratch) tree (the session 31 audit:
            # two cli_test cases read fixtures relative to the working folder and failed unmutated).
            rc, out = sh([self.binaries[target]["path"], spec], timeout=timeout, cwd=self.dir,
                         env={"MINER_SOURCE_DIR": str(self.tree)})
            if rc != 0:
                return False, f"{target} {spec}" + (" (timeout)" if rc == -9 else "")
        return True, ""


def render(results: list[dict], scores: dict[str, tuple[int, int]], commit: str) -> str:
    lines = ["# Mutation testing", "",
             f"Generated by `ci/mutation.py` at {commit}: each mutant of ci/mutants.json applied to a scratch",
             "copy, rebuilt, and the tests citing its requirements run (end-to-end goldens excluded).", "",
             "| capability | killed | survived | score | stillborn | unusable | excluded |", "|---|---|---|---|---|---|---|"]
    for cap in sorted({r["capability"] for r in results}):
        rs = [r for r in results if r["capability"] == cap]
        k, s = scores.get(cap, (0, 0))
        count = lambda st: sum(1 for r in rs if r["status"] == st)  # noqa: E731
        score = f"{100.0 * k / (k + s):.1f} %" if k + s else "—"
        lines.append(f"| {cap} | {k} | {s} | {score} | {count('stillborn')} | {count('unusable')} | {count('excluded')} |")
    lines += ["", "| mutant | capability | operator | status | by | why |", "|---|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r['id']} | {r['capability']} | {r['operator']} | {r['status']} | {r.get('by', '')} | {r['why']} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--catalogue", default=str(ROOT / "ci" / "mutants.json"))
    ap.add_argument("--work", default=str(ROOT / "build" / "mutation"))
    ap.add_argument("--only", nargs="*", default=[])
    ap.add_argument("--capability", nargs="*", default=[])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds per test binary run")
    ap.add_argument("--min-score", type=float, default=0.95)
    ap.add_argument("--report")
    ap.add_argument("--json")
    a = ap.parse_args(argv)

    try:
        mutants = load_catalogue(pathlib.Path(a.catalogue), ROOT)
    except (CatalogueError, json.JSONDecodeError) as e:
        print(f"mutation.py: {e}", file=sys.stderr)
        return 2
    if a.only:
        unknown = set(a.only) - {m["id"] for m in mutants}
        if unknown:
            print(f"mutation.py: --only names unknown mutant(s) {sorted(unknown)}", file=sys.stderr)
            return 2
        mutants = [m for m in mutants if m["id"] in a.only]
    if a.capability:
        mutants = [m for m in mutants if m["capability"] in a.capability]

    work = pathlib.Path(a.work).resolve()
    work.mkdir(parents=True, exist_ok=True)
    b = Build(work, a.jobs)
    b.tree.mkdir(exist_ok=True)
    sync_tree(ROOT, b.tree)
    b.configure()
    ok, out = b.build()
    if not ok:
        print("mutation.py: the unmutated tree does not build:\n" + out[-3000:], file=sys.stderr)
        return 2
    b.discover()

    results: list[dict] = []
    # Every selection's baseline on the unmutated build, before any mutant: a restored file is
    # rebuilt only with the next mutant, so a baseline run later would test the last mutant.
    baseline: dict[str, tuple[bool, str]] = {}
    for m in mutants:
        sel = b.selection(m["requirements"])
        if sel and not m.get("excluded") and json.dumps(sel) not in baseline:
            baseline[json.dumps(sel)] = b.run(sel, a.timeout)
    for m in mutants:
        r = {k: m[k] for k in ("id", "capability", "operator", "why")}
        if m.get("excluded"):
            r.update(status="excluded", by=m["excluded"])
            results.append(r)
            continue
        sel = b.selection(m["requirements"])
        key = json.dumps(sel)
        if not sel:
            r.update(status="unusable", by="no non-golden test cites " + ", ".join(m["requirements"]))
            results.append(r)
            continue
        if not baseline[key][0]:
            r.update(status="unusable", by="fails unmutated: " + baseline[key][1])
            results.append(r)
            continue
        path = b.tree / m["file"]
        original = path.read_text()
        start = time.monotonic()
        try:
            path.write_text(original.replace(m["find"], m["replace"], 1))
            built, _ = b.build(sorted({t for t, _ in sel}))
            if not built:
                r.update(status="stillborn")
            else:
                passed, by = b.run(sel, a.timeout)
                r.update(status="survived" if passed else "killed", by=by)
        finally:
            path.write_text(original)
        r["seconds"] = round(time.monotonic() - start, 1)
        results.append(r)
        print(f"mutation.py: {m['id']}: {r['status']} {r.get('by', '')} ({r['seconds']} s)", flush=True)
    b.build()  # leave the scratch build unmutated

    scores: dict[str, tuple[int, int]] = {}
    for r in results:
        k, s = scores.get(r["capability"], (0, 0))
        scores[r["capability"]] = (k + (r["status"] == "killed"), s + (r["status"] == "survived"))
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip() or "?"
    text = render(results, scores, commit)
    if a.report:
        pathlib.Path(a.report).write_text(text)
    if a.json:
        pathlib.Path(a.json).write_text(json.dumps({"commit": commit, "results": results,
                                                    "scores": {c: {"killed": k, "survived": s}
                                                               for c, (k, s) in scores.items()}}, indent=1))
    print(text)
    low = [c for c, (k, s) in scores.items() if k + s and k / (k + s) < a.min_score]
    if low:
        print(f"mutation.py: below {a.min_score:.0%}: {', '.join(sorted(low))}", file=sys.stderr)
    return 1 if low else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
