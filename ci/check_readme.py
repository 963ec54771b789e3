#!/usr/bin/env python3
"""The README quick start is what CI runs (REQ-HARNESS-004).

cites: REQ-HARNESS-004

Checks that README.md has a "Quick start" section whose first fenced block is a clone
line followed by exactly two commands, that each command's script exists, and that
.ci/run runs the second (test) command verbatim.
"""
import pathlib
import re
import sys


def quick_start_commands(readme: str) -> list[str]:
    section = re.search(r"^## Quick start\s*$(.*?)(?=^## |\Z)", readme, re.M | re.S)
    if not section:
        raise ValueError("README.md has no '## Quick start' section")
    block = re.search(r"^```[a-z]*\n(.*?)^```", section.group(1), re.M | re.S)
    if not block:
        raise ValueError("the Quick start section has no fenced code block")
    lines = [l.strip() for l in block.group(1).splitlines() if l.strip() and not l.strip().startswith("#")]
    if not lines or not lines[0].startswith("git clone"):
        raise ValueError("the Quick start block must start with the git clone line")
    return lines[1:]


def main(root: pathlib.Path) -> int:
    errors = []
    try:
        commands = quick_start_commands((root / "README.md").read_text())
    except (OSError, ValueError) as e:
        print(f"check_readme.py: {e}", file=sys.stderr)
        return 1
    if len(commands) != 2:
        errors.append(f"the Quick start block has {len(commands)} commands after the clone, expected 2: {commands}")
    for c in commands:
        for script in re.findall(r"\b(ci/[\w.-]+\.sh)\b", c):
            if not (root / script).is_file():
                errors.append(f"'{c}' names {script}, which does not exist")
    ci_run = (root / ".ci/run").read_text().splitlines()
    if len(commands) == 2 and commands[1] not in [l.strip() for l in ci_run]:
        errors.append(f".ci/run does not run the README test command '{commands[1]}'")
    for e in errors:
        print(f"check_readme.py: {e}", file=sys.stderr)
    if not errors:
        print(f"check_readme.py: quick start = {commands}; .ci/run runs '{commands[1]}'")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")))
