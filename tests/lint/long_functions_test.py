#!/usr/bin/env python3
"""Self-test of scripts/long-functions.py (issue 22, point 3): on tests/lint/long_functions_fixture.cpp
with --limit 10 it must report exactly the fixture's long functions, with their lengths: those
whose signatures hold a brace (a default argument `= {}`, `= T{...}`, a lambda), an operator==,
and the functions after them (a brace in a signature once opened a fake body and hid every later
function of the file); with_reason only with --all; short_one and the declaration never.
Exit 1 with the difference otherwise.
  long_functions_test.py SOURCE_DIR
"""
import os
import re
import subprocess
import sys

src = sys.argv[1]
script = os.path.join(src, "scripts", "long-functions.py")
fixture = os.path.join(src, "tests", "lint", "long_functions_fixture.cpp")
EXPECTED = {  # name: length (signature to closing brace), as the fixture's comments say
    "brace_default": 15,
    "after_brace_default": 15,
    "init_default": 15,
    "lambda_default": 16,
    "operator==": 15,
    "last_one": 15,
}


def run(*extra):
    p = subprocess.run([sys.executable, script, "--limit", "10", *extra, fixture], capture_output=True, text=True)
    rows = {}
    for line in p.stdout.splitlines():
        m = re.match(r"\s*(\d+)\s+\S+:\d+\s+(\S+)", line)
        if m:
            rows[m.group(2)] = int(m.group(1))
    return p.returncode, rows, p.stdout + p.stderr


fail = False
rc, rows, out = run()
if rows != EXPECTED or rc != 1:
    print(f"FAIL: without --all: exit {rc} (want 1), found {rows}\n  want {EXPECTED}\n{out}")
    fail = True
rc, rows, out = run("--all")
if rows != dict(EXPECTED, with_reason=15):
    print(f"FAIL: with --all: found {rows}\n  want {dict(EXPECTED, with_reason=15)}\n{out}")
    fail = True
if not fail:
    print(f"ok: {len(EXPECTED)} long functions found with their lengths, with_reason only with --all")
sys.exit(1 if fail else 0)
