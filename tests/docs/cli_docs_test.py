#!/usr/bin/env python3
"""Every command-line option is documented (issue 22, point 7): each tool's `--help` against its
section of docs/cli.md, in both directions. An option the tool prints and its section (or, for a
run process, the shared "Options of every run process" section) lacks fails; so does an option
the page lists that the tool no longer has. Options are read from the option lines of `--help`
("  -o,--out TEXT ...", "  --no-plots ..."), not from descriptions. The tools are every
feeddrive-* executable in BIN_DIR, so a new tool cannot be left out; each must have its section,
and each "## feeddrive-..." section of the page its executable.

Usage: cli_docs_test.py SRC_DIR BIN_DIR
"""
import os
import re
import subprocess
import sys
from pathlib import Path

RUN_PROCESSES = {"plant", "controller", "trajectory", "monitor", "launch"}
# At least these (the check that the build dir is the right one: a build without them is no
# build of feeddrive); the list checked is every feeddrive-* executable in BIN_DIR.
KNOWN = {"sim", "launch", "plant", "controller", "trajectory", "monitor", "log2csv", "fit", "study", "keys"}
SHARED = "Options of every run process"


def tool_names(bindir):
    """Every feeddrive-* executable in bindir, without the prefix: "sim", "study", ..."""
    return sorted(p.name[len("feeddrive-"):] for p in Path(bindir).glob("feeddrive-*")
                  if p.is_file() and os.access(p, os.X_OK))


def help_options(exe):
    out = subprocess.run([str(exe), "--help"], capture_output=True, text=True, timeout=60)
    if out.returncode != 0:
        sys.exit(f"FAIL: {exe} --help exited {out.returncode}: {out.stderr.strip()}")
    opts = set()
    for line in out.stdout.splitlines():
        m = re.match(r"^\s+(?:-[A-Za-z],)?--([a-z][a-z0-9-]*)", line)
        if m:
            opts.add("--" + m.group(1))
    opts.discard("--help")
    return opts


def doc_sections(page):
    """heading -> the long options in that section's table rows (first cell)."""
    sections, current = {}, None
    for line in page.read_text().splitlines():
        if line.startswith("## "):
            current = line[3:].strip()
            sections[current] = set()
        elif current and line.startswith("| `"):
            first_cell = line.split("|")[1]
            sections[current] |= set(re.findall(r"`(?:-[A-Za-z]`, `)?(--[a-z][a-z0-9-]*)", first_cell))
    return sections


def main():
    src, bindir = Path(sys.argv[1]), Path(sys.argv[2])
    page = src / "docs" / "cli.md"
    sections = doc_sections(page)
    failures = []
    tools = tool_names(bindir)
    for t in sorted(KNOWN - set(tools)):
        failures.append(f"{bindir}/feeddrive-{t} does not exist")
    for heading in sorted(h for h in sections if h.startswith("feeddrive-")):
        if heading[len("feeddrive-"):] not in tools:
            failures.append(f"docs/cli.md '## {heading}': no such executable in {bindir}")
    for tool in tools:
        name = f"feeddrive-{tool}"
        exe = bindir / name
        have = help_options(exe)
        if name not in sections:
            failures.append(f"docs/cli.md has no section '## {name}'")
            continue
        documented = set(sections[name])
        if tool in RUN_PROCESSES:
            documented |= sections.get(SHARED, set())
        for o in sorted(have - documented):
            failures.append(f"{name} {o}: printed by --help, not in docs/cli.md '## {name}'" +
                            (f" or '## {SHARED}'" if tool in RUN_PROCESSES else ""))
        for o in sorted(set(sections[name]) - have):
            failures.append(f"{name} {o}: in docs/cli.md '## {name}', but {name} --help has no such option")
        print(f"{name}: {len(have)} options, all documented" if not (have - documented) else f"{name}: checked")
    shared_used = set().union(*(help_options(bindir / f"feeddrive-{t}") for t in RUN_PROCESSES))
    for o in sorted(sections.get(SHARED, set()) - shared_used):
        failures.append(f"{o}: in docs/cli.md '## {SHARED}', but no run process has it")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
