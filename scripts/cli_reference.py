#!/usr/bin/env python3
"""docs/guide/cli-reference.md from the CLI's own help: every command of `riner --help`, its
usage, description, arguments and flags, as `riner COMMAND --help` prints them, in the help's
order. With --check, exit 1 if the page differs from what it would write (a ctest runs that).

  cli_reference.py RINER_BINARY [--check]

Python's standard library only."""
import os
import re
import subprocess
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(__file__), ".."))
PAGE = os.path.join(ROOT, "docs", "guide", "cli-reference.md")


def help_text(riner, *words):
    run = subprocess.run([riner, *words, "--help"], capture_output=True, text=True)
    if run.returncode != 0:
        raise SystemExit(f"riner {' '.join(words)} --help: exit {run.returncode}")
    return run.stdout


def commands(riner):
    text = help_text(riner)
    block = text.split("commands:", 1)[1].split("\n\n", 1)[0]
    return re.findall(r"^  (\w+)  ", block, re.M)


def cell(text):
    return " ".join(text.split()).replace("|", "\\|")


def entries(block):
    """[(name, help)] of an 'arguments:' or 'options:' block."""
    found = []
    for line in block.splitlines():
        if line.startswith("      "):
            name, words = found[-1]
            found[-1] = (name, (words + " " + line.strip()).strip())
        elif line.startswith("  "):
            found.append((line.strip(), ""))
    return found


def section(riner, command):
    text = help_text(riner, command)
    usage, rest = text.split("\n", 1)
    parts = re.split(r"^(arguments|options):\n", rest, flags=re.M)
    lines = [f"## `riner {command}`", "", f"`{usage.removeprefix('usage: ').strip()}`", ""]
    description = parts[0].strip()
    if description:
        lines += [" ".join(p.split()) + "\n" for p in description.split("\n\n")]
    for kind, block in zip(parts[1::2], parts[2::2]):
        header = "argument" if kind == "arguments" else "flag"
        lines += [f"| {header} | meaning |", "|---|---|"]
        lines += [f"| `{cell(name)}` | {cell(words)} |" for name, words in entries(block)]
        lines.append("")
    return "\n".join(lines)


def render(riner):
    names = commands(riner)
    head = [
        "# Every command and flag",
        "",
        "Generated from the CLI's own help (`riner COMMAND --help`) by "
        "`scripts/cli_reference.py`; a test regenerates it and fails on any difference. The "
        "overview, with examples: [command-line.md](command-line.md); the settings "
        "`--config` and `--set` change: [../settings.md](../settings.md).",
        "",
        " · ".join(f"[{n}](#riner-{n})" for n in names),
        "",
    ]
    return "\n".join(head + [section(riner, n) for n in names]).rstrip() + "\n"


def main():
    args = [a for a in sys.argv[1:] if a != "--check"]
    if len(args) != 1:
        raise SystemExit("usage: cli_reference.py RINER_BINARY [--check]")
    page = render(args[0])
    if "--check" in sys.argv:
        with open(PAGE, encoding="utf-8") as f:
            if f.read() != page:
                raise SystemExit(f"{PAGE} is out of date: scripts/cli_reference.py "
                                 f"{args[0]} (it writes the page)")
        return
    tmp = PAGE + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(page)
    os.replace(tmp, PAGE)
    print(f"wrote {os.path.relpath(PAGE, ROOT)}")


if __name__ == "__main__":
    main()
