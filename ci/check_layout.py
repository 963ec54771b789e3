#!/usr/bin/env python3
"""The dependency rule of docs/layout.md, checked (cites: REQ-HARNESS-007).

Reads the table under "## Dependency rule" in docs/layout.md (capability | may include) and
fails when a library source of src/miner/<capability>/ (tests excluded) includes a header of
a capability the table does not allow, or when a capability folder has no row. The table is
the rule; this script only reads it, so the document and the check cannot drift.

Usage: check_layout.py REPO_ROOT
"""
from __future__ import annotations

import pathlib
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"miner/([a-z_]+)/')


def read_rule(layout: str) -> dict[str, set[str]]:
    rule: dict[str, set[str]] = {}
    section = layout.split("## Dependency rule", 1)
    if len(section) != 2:
        raise SystemExit("check_layout: docs/layout.md has no '## Dependency rule' section")
    for line in section[1].splitlines():
        if line.startswith("## "):
            break
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 2 or not cells[0].startswith("`"):
            continue
        name = cells[0].strip("`")
        allowed = {c.strip().strip("`") for c in cells[1].split(",") if c.strip() and c.strip() != "nothing"}
        rule[name] = allowed
    return rule


def violations(root: pathlib.Path, rule: dict[str, set[str]]) -> list[str]:
    errors = []
    for folder in sorted(p for p in (root / "src" / "miner").iterdir() if p.is_dir()):
        cap = folder.name
        if cap not in rule:
            errors.append(f"src/miner/{cap}: no row in docs/layout.md's dependency rule")
            continue
        for source in sorted(list(folder.glob("*.hpp")) + list(folder.glob("*.cpp")) + list(folder.glob("*.in"))):
            for number, line in enumerate(source.read_text().splitlines(), 1):
                m = INCLUDE.match(line)
                if m and m.group(1) != cap and m.group(1) not in rule[cap]:
                    errors.append(f"{source.relative_to(root)}:{number}: {cap} includes {m.group(1)}, "
                                  f"which the dependency rule does not allow ({cap} may include: "
                                  f"{', '.join(sorted(rule[cap])) or 'nothing'})")
    return errors


def main() -> int:
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    rule = read_rule((root / "docs" / "layout.md").read_text())
    errors = violations(root, rule)
    for e in errors:
        print(e, file=sys.stderr)
    if not errors:
        print(f"check_layout: {len(rule)} capabilities follow the dependency rule")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
