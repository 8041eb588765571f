#!/usr/bin/env python3
"""Lists the functions longer than a limit (default 80 lines) in the C++ sources.

Usage: python3 scripts/long-functions.py [--limit N] [--all] [paths...]
  paths   files or folders to scan (default: the repository, without tests/, build*/, examples/)
  --all   list every function at or over the limit, also those with a stated reason
A function's length is counted from the first line of its signature to its closing brace. A
function that is long on purpose carries a comment line "long-function: <reason>" just above it;
it is listed with the reason and does not count as a finding. Exit status: 1 when a function
without a reason is over the limit, else 0 (issue 22, item 3: no function over ~80 lines
without a reason stated above it).

The scan is a brace-counting heuristic, not a parser: comments, string and character literals and
preprocessor lines are blanked first; a brace at namespace or class scope whose header holds a
parameter list opens a function body. A brace inside a parameter list (a default argument `= {}`,
`= T{...}`, a lambda) belongs to the header. Lambdas are counted as part of the function around
them. tests/lint/long_functions_test.py checks it on tests/lint/long_functions_fixture.cpp.
"""
import argparse
import os
import re
import sys

EXTS = (".cpp", ".hpp", ".cc", ".h", ".c")
SKIP_DIRS = {"tests", "examples", ".git", "third_party"}
SCOPE_RE = re.compile(r"(inline\s+)?(namespace|class|struct|union|enum)\b|extern\s*\"")
QUALIFIERS = {"const", "override", "final", "noexcept", "mutable", "volatile", "try"}


def blank(text):
    """Comments, literals and preprocessor lines replaced by spaces; newlines kept."""
    out = []
    i, n = 0, len(text)
    at_line_start = True
    while i < n:
        c = text[i]
        if at_line_start and c == "#":  # preprocessor line, with continuations
            while i < n and text[i] != "\n":
                if text[i] == "\\" and i + 1 < n and text[i + 1] == "\n":
                    out.append(" \n")
                    i += 2
                    continue
                out.append(" ")
                i += 1
            continue
        if c in " \t":
            out.append(c)
            i += 1
            continue
        at_line_start = c == "\n"
        if text.startswith("//", i):
            while i < n and text[i] != "\n":
                out.append(" ")
                i += 1
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            k = text.find("(", i)
            delim = ")" + text[i + 2:k] + '"'
            j = text.find(delim, k)
            j = n if j < 0 else j + len(delim)
            out.append('""' + re.sub(r"[^\n]", " ", text[i + 2:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator 1'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (j - i - 1) + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """(name, first line, length) of each function body in the file."""
    with open(path, encoding="utf-8", errors="replace") as f:
        raw = f.read()
    text = blank(raw)
    stack = []  # kinds: scope, func, block, init
    header_start = 0
    found = []
    for i, c in enumerate(text):
        if c == "{":
            top = stack[-1] if stack else "scope"
            if top != "scope":
                stack.append(("block", None))
                continue
            header = text[header_start:i]
            h = header.strip()
            if header.count("(") > header.count(")"):
                # Inside a parameter list: a default argument `= {}`, `= T{...}` or `= [] {...}`,
                # not a body; the header goes on after it.
                stack.append(("nested", None))
                continue
            if SCOPE_RE.match(re.sub(r"^template\s*<.*?>\s*", "", h, flags=re.S)):
                stack.append("scope")
                header_start = i + 1
            elif "(" in h and "=" not in _before_params(h) and not _brace_init_in_ctor(h):
                name = re.findall(r"([~\w:]*operator\s*(?:\(\)|[^\s\w(]+)|[~\w:]+)\s*\(", h)
                first = header_start + (len(header) - len(header.lstrip()))
                stack.append(("func", (name[0] if name else "?", raw.count("\n", 0, first) + 1)))
            else:
                stack.append(("init", None))
        elif c == "}":
            if not stack:
                continue
            top = stack.pop()
            if top == "scope":
                header_start = i + 1
            elif top[0] == "func":
                name, line = top[1]
                end = raw.count("\n", 0, i) + 1
                found.append((name, line, end - line + 1))
                header_start = i + 1
            elif top[0] == "init" and (not stack or stack[-1] == "scope"):
                pass  # the header goes on to the ';'
        elif c == ";" and (not stack or stack[-1] == "scope"):
            header_start = i + 1
    return found


def _before_params(h):
    """The header before its first '(', with an operator's name (operator==, operator=) removed: an
    '=' there is an initialization (int x = f(...) {...}), not a function."""
    return re.sub(r"operator\s*[^\s(]+", "operator", h.replace("operator()", "operator")).split("(")[0]


def _brace_init_in_ctor(h):
    """True when the header is a constructor's initializer list and this brace is a member's {...}."""
    if not re.search(r"\)\s*(noexcept\s*)?:[^:]", h):
        return False
    m = re.search(r"(\w+|>)\s*$", h)
    return bool(m) and m.group(1) not in QUALIFIERS


def reason_above(lines, line):
    """The "long-function: ..." reason in the comment lines just above the signature, if any."""
    i = line - 2
    while i >= 0 and (lines[i].strip().startswith("//") or lines[i].strip().startswith("template")):
        m = re.search(r"long-function:\s*(.*)", lines[i])
        if m:
            return m.group(1).strip()
        i -= 1
    return None


def sources(paths):
    for p in paths:
        if os.path.isfile(p):
            yield p
            continue
        for root, dirs, files in os.walk(p):
            dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS and not d.startswith("build"))
            for f in sorted(files):
                if f.endswith(EXTS):
                    yield os.path.join(root, f)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=int, default=80)
    ap.add_argument("--all", action="store_true")
    ap.add_argument("paths", nargs="*")
    a = ap.parse_args()
    root = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    paths = a.paths or [root]
    rows = []
    for path in sources(paths):
        lines = open(path, encoding="utf-8", errors="replace").read().split("\n")
        for name, line, length in functions(path):
            if length > a.limit:
                rows.append((length, os.path.relpath(path, root), line, name, reason_above(lines, line)))
    rows.sort(key=lambda r: (-r[0], r[1], r[2]))
    bad = 0
    for length, path, line, name, reason in rows:
        if reason is None:
            bad += 1
        elif not a.all:
            continue
        print(f"{length:5d}  {path}:{line}  {name}" + (f"  [reason: {reason}]" if reason else ""))
    print(f"{bad} function(s) over {a.limit} lines without a stated reason", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
