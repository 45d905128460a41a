#!/usr/bin/env python3
"""The command table of docs/guide/command-line.md against the CLI itself: every command the
table names exists, and the flags its row shows are flags of `riner COMMAND --help`, in the
help's order (the guide reads as the help does). Exit 1 with one line per mismatch.

  check_cli_guide.py RINER_BINARY

Python's standard library only."""
import os
import re
import subprocess
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(__file__), ".."))
ROW = re.compile(r"^\| `riner (\w+)([^`]*)` \|", re.M)
HELP_FLAG = re.compile(r"^  (--[a-z0-9-]+)", re.M)


def main():
    if len(sys.argv) != 2:
        raise SystemExit("usage: check_cli_guide.py RINER_BINARY")
    riner = sys.argv[1]
    with open(os.path.join(ROOT, "docs", "guide", "command-line.md"), encoding="utf-8") as f:
        guide = f.read()
    rows = ROW.findall(guide)
    problems = []
    if not rows:
        problems.append("command-line.md: no command table rows found")
    for command, row in rows:
        run = subprocess.run([riner, command, "--help"], capture_output=True, text=True)
        if run.returncode != 0:
            problems.append(f"riner {command} --help: exit {run.returncode}")
            continue
        help_flags = HELP_FLAG.findall(run.stdout)
        latest = None  # the flag of the row so far that comes last in the help
        for flag in re.findall(r"--[a-z0-9-]+", row):
            if flag not in help_flags:
                problems.append(f"riner {command}: the guide shows {flag}, the help has none")
                continue
            at = help_flags.index(flag)
            if latest is not None and at < help_flags.index(latest):
                problems.append(f"riner {command}: the guide shows {flag} after {latest}, the "
                                "help before it")
            elif latest is None or at > help_flags.index(latest):
                latest = flag
    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
