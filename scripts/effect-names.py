#!/usr/bin/env python3
"""Every effect name the fit spells as a string is an effect of the plant's list (issue 22).

The fit works on effects by name (plant::NamedEffect); a name renamed in plant::EffectsParams but
left behind in fit/ would never match again and switch a rule off silently. This scan takes the
effect names from the generated key tables (feeddrive-keys: the plant.effects table's map rows,
from the list itself) and fails on any string literal in fit/ that has an effect name's shape
(ends in _friction, _ripple, _force, _error or _delay, or is presliding) and is not one of them or
a parameter of one. Usage: effect-names.py FEEDDRIVE_KEYS_BINARY. ctest lint.effect_names.
"""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def listed(keys_binary):
    out = subprocess.run([keys_binary], check=True, capture_output=True, text=True).stdout
    section = out.split("### plant.effects", 1)[1].split("\n### ", 1)[0]
    effects, params = set(), set()
    for m in re.finditer(r"^\| `([a-z_]+)(?:\.([a-z_]+))?` \| ([^|]*)\|", section, re.M):
        if m.group(2) is None:
            effects.add(m.group(1))
        else:
            params.add(m.group(2))
    return effects, params


def main():
    if len(sys.argv) != 2:
        print("usage: effect-names.py FEEDDRIVE_KEYS_BINARY")
        return 2
    effects, params = listed(sys.argv[1])
    if len(effects) < 5:
        print("effect-names: found %d effects in the plant.effects table; the scan cannot judge" % len(effects))
        return 1
    not_effects = {"effect_force"}  # a column of effectN.csv (docs/fit.md, Outputs), not an effect's name
    shape = re.compile(r'"([a-z]+(?:_[a-z]+)*_(?:friction|ripple|force|error|delay)|presliding)"')
    bad = []
    for dirpath, _, files in os.walk(os.path.join(ROOT, "fit")):
        for f in files:
            if not f.endswith((".cpp", ".hpp")):
                continue
            path = os.path.join(dirpath, f)
            with open(path, encoding="utf-8") as fh:
                for n, line in enumerate(fh, 1):
                    for m in shape.finditer(line):
                        name = m.group(1)
                        if name not in effects and name not in params and name not in not_effects:
                            bad.append("%s:%d: '%s' is no effect (or parameter) of plant.effects' list"
                                       % (os.path.relpath(path, ROOT), n, name))
    for b in bad:
        print(b)
    print("effect-names: %d effects, %d parameters in the list; %d unknown names in fit/" % (len(effects), len(params), len(bad)))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
