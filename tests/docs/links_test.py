#!/usr/bin/env python3
"""Every relative link of the documentation resolves (issue 22, point 8).

Checks README.md, docs/*.md and every other README.md of the tree (examples/, data/): each
Markdown link or image `[text](target)`, `![alt](target)` and reference definition
`[label]: target` outside code must name a file or folder that exists inside the repository
(a clone stands alone: no link leaves it), and a `#fragment` must name a heading of the target
page (GitHub's anchors: lower case, punctuation dropped, spaces to hyphens, -1, -2 for repeats)
or an explicit `<a id="...">`. External links (http, https, mailto) are not fetched: nothing
leaves this machine.

Usage: links_test.py SRC_DIR
"""
import re
import sys
from pathlib import Path

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
REFDEF = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+.*)?$")
EXTERNAL = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")  # http:, https:, mailto:, ...


def strip_code(text):
    """The page without fenced code blocks and inline code spans (links there are examples)."""
    out, fence = [], None
    for line in text.splitlines():
        m = re.match(r"^\s{0,3}(`{3,}|~{3,})", line)
        if m:
            if fence is None:
                fence = m.group(1)[0] * len(m.group(1))
            elif m.group(1).startswith(fence):
                fence = None
            out.append("")
            continue
        out.append("" if fence else re.sub(r"(`+)(?:(?!\1).)+?\1", "", line))
    return out


def slug(heading):
    """GitHub's anchor of a heading."""
    h = re.sub(r"<[^>]+>", "", heading).strip().lower()
    h = re.sub(r"[^\w\- ]", "", h)
    return h.replace(" ", "-")


def anchors(page, cache={}):
    if page not in cache:
        found, seen, fence = set(), {}, None
        for line in page.read_text(encoding="utf-8").splitlines():
            m = re.match(r"^\s{0,3}(`{3,}|~{3,})", line)
            if m:
                fence = None if fence else m.group(1)[0]
                continue
            if fence:
                continue
            h = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
            if h:
                s = slug(h.group(1))
                n = seen.get(s, 0)
                seen[s] = n + 1
                found.add(s if n == 0 else f"{s}-{n}")
            found |= set(re.findall(r"<a\s+(?:id|name)=\"([^\"]+)\"", line))
        cache[page] = found
    return cache[page]


def pages(src):
    found = [src / "README.md", *sorted((src / "docs").glob("*.md"))]
    for p in sorted(src.rglob("README.md")):
        rel = p.relative_to(src).parts
        if rel[0] in ("build", ".git", "out") or rel[0].startswith("build") or p in found:
            continue
        found.append(p)
    return found


def main():
    src = Path(sys.argv[1]).resolve()
    failures, checked = [], 0
    for page in pages(src):
        for lineno, line in enumerate(strip_code(page.read_text(encoding="utf-8")), 1):
            targets = LINK.findall(line)
            m = REFDEF.match(line)
            if m:
                targets.append(m.group(1))
            for target in targets:
                if EXTERNAL.match(target):
                    continue
                checked += 1
                where = f"{page.relative_to(src)}:{lineno}: {target}"
                path, _, fragment = target.partition("#")
                dest = (page.parent / path).resolve() if path else page
                if src != dest and src not in dest.parents:
                    failures.append(f"{where}: leaves the repository")
                    continue
                if not dest.exists():
                    failures.append(f"{where}: no such file")
                    continue
                if fragment and dest.suffix == ".md" and fragment not in anchors(dest):
                    failures.append(f"{where}: {dest.relative_to(src)} has no heading with anchor #{fragment}")
    for f in failures:
        print("FAIL:", f)
    print(f"{checked} relative links in {len(pages(src))} pages, {len(failures)} broken")
    return 1 if failures or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
