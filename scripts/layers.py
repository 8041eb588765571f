#!/usr/bin/env python3
"""The include graph's layers (issue 22, "Measure it"): which component includes which.

A component is a top-level folder with an include/feeddrive/ tree (common, plant, controller,
trajectory, sim, record, service, monitor, fit, study, analysis); its files are every .cpp/.hpp/.h
under the folder outside tests/, but an executable's (a file with main(): it wires the libraries). An include "feeddrive/<x>/..." is an edge to the folder that holds
include/feeddrive/<x>. Prints each component's layer (0: includes no other component; otherwise one
more than the highest layer it includes) and what it includes, and exits 1 if the graph has a
cycle or an offline tool's library reaches the bus: fit, record or analysis above service (the
rule "an offline tool never links the bus", docs/contributing.md). ctest lint.layers runs it.
"""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OFFLINE = ["fit", "record", "analysis"]
BUS = "service"


def components():
    """include prefix -> component folder, e.g. csv -> common."""
    owner = {}
    for comp in sorted(os.listdir(ROOT)):
        inc = os.path.join(ROOT, comp, "include", "feeddrive")
        if comp in ("build", "tests") or not os.path.isdir(inc):
            continue
        for dirpath, dirnames, _ in os.walk(os.path.join(ROOT, comp)):
            if os.path.basename(dirpath) == "feeddrive" and os.path.basename(os.path.dirname(dirpath)) == "include":
                for d in dirnames:
                    owner[d] = comp
    return owner


def graph(owner):
    edges = {c: set() for c in set(owner.values())}
    pat = re.compile(r'#include\s+"feeddrive/([a-z_]+)/')
    for comp in edges:
        for dirpath, _, files in os.walk(os.path.join(ROOT, comp)):
            if "/tests" in dirpath or "/build" in dirpath:
                continue
            for f in files:
                if not f.endswith((".cpp", ".hpp", ".h")):
                    continue
                with open(os.path.join(dirpath, f), encoding="utf-8", errors="replace") as fh:
                    text = fh.read()
                if re.search(r"^int main\(", text, re.M):
                    continue  # an executable wires the libraries; it is no layer of them
                for m in pat.finditer(text):
                        dep = owner.get(m.group(1))
                        if dep and dep != comp:
                            edges[comp].add(dep)
    return edges


def layers(edges):
    layer, state = {}, {}

    def visit(c, path):
        if state.get(c) == "open":
            raise ValueError("cycle: " + " -> ".join(path + [c]))
        if c in layer:
            return layer[c]
        state[c] = "open"
        layer[c] = 1 + max((visit(d, path + [c]) for d in edges[c]), default=-1)
        state[c] = "done"
        return layer[c]

    for c in sorted(edges):
        visit(c, [])
    return layer


def reaches(edges, a, b):
    seen, todo = set(), [a]
    while todo:
        c = todo.pop()
        if c == b:
            return True
        if c not in seen:
            seen.add(c)
            todo.extend(edges[c])
    return False


def main():
    edges = graph(components())
    try:
        layer = layers(edges)
    except ValueError as e:
        print("layers: " + str(e))
        return 1
    print("| layer | component | includes |\n|---|---|---|")
    for c in sorted(layer, key=lambda c: (layer[c], c)):
        print(f"| {layer[c]} | {c} | {', '.join(sorted(edges[c])) or '–'} |")
    bad = [c for c in OFFLINE if c in edges and reaches(edges, c, BUS)]
    if bad:
        print("layers: " + ", ".join(bad) + " reach " + BUS + " (an offline tool never links the bus)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
