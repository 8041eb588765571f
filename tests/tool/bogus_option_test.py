#!/usr/bin/env python3
"""One error path for every tool (issue 22, point 4): every feeddrive-* executable in BIN_DIR
(the list of tests/docs/cli_docs_test.py, so a new tool cannot be left out) refuses an option it
does not have with the one line "error: --bogus: no such option (see --help)" and exit 2, alone
and after a positional argument; feeddrive-study, -keys and -plant once printed CLI11's own
"The following argument was not expected". fd-drivegen, which parses its own arguments, refuses a
bad number with one line and exit 2.

Usage: bogus_option_test.py SRC_DIR BIN_DIR
"""
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "docs"))
from cli_docs_test import KNOWN, tool_names  # noqa: E402

EXPECTED = "error: --bogus: no such option (see --help)\n"


def run(args):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=60,
                          stdin=subprocess.DEVNULL)


def main():
    bindir = Path(sys.argv[2])
    tools = tool_names(bindir)
    failures = [f"{bindir}/feeddrive-{t} does not exist" for t in sorted(KNOWN - set(tools))]
    for tool in tools:
        exe = bindir / f"feeddrive-{tool}"
        for args in (["--bogus"], ["x.yaml", "--bogus"]):
            r = run([exe] + args)
            if r.returncode != 2 or r.stderr != EXPECTED or r.stdout:
                failures.append(f"feeddrive-{tool} {' '.join(args)}: exit {r.returncode}, stderr {r.stderr!r}, "
                                f"stdout {r.stdout[:200]!r}; expected exit 2 and {EXPECTED!r}")
        print(f"feeddrive-{tool}: checked")
    # A numeric option's bad value: one wording in every tool (tool::within), not CLI11's own.
    for tool, args, line in (
            ("sim", ["x.yaml", "--frequency-response", "-j", "abc"], "error: --jobs: 'abc' is not a finite number"),
            ("sim", ["x.yaml", "--frequency-response", "-j", "0"], "error: --jobs: '0' is outside [1, 256]"),
            ("study", ["x.yaml", "-j", "1.5"], "error: --jobs: '1.5' is not an integer"),
            ("study", ["x.yaml", "-j", "0"], "error: --jobs: '0' is outside [1, 4096]"),
            ("fit", ["--scenario", "x", "--data", "y", "--out", "z", "--max-effects", "abc"],
             "error: --max-effects: 'abc' is not a finite number"),
            ("fit", ["--scenario", "x", "--data", "y", "--out", "z", "--score-threshold", "-1"],
             "error: --score-threshold: '-1' is outside [0, 1e+09]")):
        exe = bindir / f"feeddrive-{tool}"
        if not exe.exists():
            continue
        r = run([exe] + args)
        if r.returncode != 2 or not r.stderr.startswith(line) or r.stderr.count("\n") != 1:
            failures.append(f"feeddrive-{tool} {' '.join(args)}: exit {r.returncode}, stderr {r.stderr!r}; "
                            f"expected exit 2 and {line!r}")
    gen = bindir / "fd-drivegen"
    if gen.exists():
        with tempfile.TemporaryDirectory() as tmp:  # an fd-drivegen that took "1x" would write there
            r = run([gen, "7", Path(tmp) / "rec", "1x"])
        if r.returncode != 2 or not r.stderr.startswith("error: DURATION_S = '1x': not a number") or \
                r.stderr.count("\n") != 1:
            failures.append(f"fd-drivegen 7 DIR 1x: exit {r.returncode}, stderr {r.stderr!r}")
        print("fd-drivegen: checked")
    for f in failures:
        print("FAIL:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
