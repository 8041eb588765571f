#!/usr/bin/env python3
"""One tuning procedure for every controller family (issue 24, item 2; docs/tuning.md).

Usage: python3 scripts/tune.py SPEC.yaml --out DIR [--bin build/bin] [-j N] [--stage all|design|test]

SPEC (studies/tuning.yaml) names the objective, the budget (grid points per family), the design
set (a study's base and families) and the test study, and one grid per controller family (its
scenario file, optional fixed keys `set`, and `grid`: {key: [values]}). The
procedure, the same for every family:
  1. every grid point of every family is a controller of ONE design study (DIR/design.yaml), run
     by feeddrive-study on every design case (DIR/design/results.csv);
  2. each case c gets J_c = e_c/e_lim + sum_k max(0, s_k,c/L_k - 1) (the error against its limit
     plus the hinge penalty of each control-signal figure over its limit), e_c the results column
     objective.error_metric (default position_error_max_abs_m; studies/tuning.yaml: the max |e|
     after the analysis window, position_error_max_abs_settled_m); a candidate's J is the largest
     J_c of its cases (a failed case, or an error without a value: infinity); J <= 1 exactly when
     every design case passes. Each family keeps its candidate of lowest J (ties: lower mean J_c):
     DIR/chosen.yaml, DIR/design.md, DIR/design_cases.csv (every case, for the record);
  3. the test study (the SPEC's test.study with its controllers replaced by the chosen ones,
     DIR/test.yaml) is run once (DIR/test/results.csv, DIR/test_cases.csv); DIR/test.md tables,
     per test family and family, the worst error (objective.error_metric), the worst max |e|
     over the whole run, the cases within the signal limits and the passing ones, and the worst
     of each signal figure.
Every grid must have exactly `budget` points (else exit 2): the same effort for every family.
Bad input: one line on stderr naming the key, exit 2 (a grid that is not a map {key: [values]},
families that are not a list, a limit that is not a number > 0 or names no results column, an
error_metric that is not a results column). A signal figure that is empty or nan scores an
infinite penalty, never 0. A failed feeddrive-study: its exit status.
"""
import argparse
import csv
import itertools
import math
import os
import subprocess
import sys

import yaml


def fail(msg):
    print(f"error: {msg}", file=sys.stderr)
    sys.exit(2)


def load_spec(path):
    try:
        with open(path) as f:
            spec = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as e:
        fail(f"{path}: {e}")
    if not isinstance(spec, dict):
        fail(f"{path}: not a map")
    for key in ("objective", "budget", "design", "test", "families"):
        if key not in spec:
            fail(f"{path}: {key}: missing")
    check_objective(path, spec["objective"])
    if not isinstance(spec["families"], list):
        fail(f"{path}: families = {spec['families']!r}: must be a list of families")
    for i, fam in enumerate(spec["families"]):
        for key in ("name", "scenario", "grid"):
            if not isinstance(fam, dict) or key not in fam:
                fail(f"{path}: families[{i}].{key}: missing")
        check_grid(f"{path}: families.{fam['name']}.grid", fam["grid"])
        n = len(grid_points(fam["grid"]))
        if n != spec["budget"]:
            fail(f"{path}: families.{fam['name']}.grid: {n} points, the budget is {spec['budget']}")
    return spec


def positive_number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and x > 0


FULL_RUN_ERROR = "position_error_max_abs_m"


def error_metric(objective):
    """The results column J's error term reads (objective.error_metric; default the whole run's max |e|)."""
    return objective.get("error_metric", FULL_RUN_ERROR)


def check_objective(path, objective):
    """error_limit_um > 0, error_metric a column name, and signal_limits {column: limit > 0}; the
    columns are checked against the results (read_scores)."""
    if not isinstance(objective, dict):
        fail(f"{path}: objective = {objective!r}: must be a map")
    if not isinstance(error_metric(objective), str) or not error_metric(objective):
        fail(f"{path}: objective.error_metric = {objective.get('error_metric')!r}: must be a results column name")
    if not positive_number(objective.get("error_limit_um")):
        fail(f"{path}: objective.error_limit_um = {objective.get('error_limit_um')!r}: must be a number > 0")
    limits = objective.get("signal_limits")
    if not isinstance(limits, dict):
        fail(f"{path}: objective.signal_limits = {limits!r}: must be a map {{column: limit}}")
    for key, limit in limits.items():
        if not positive_number(limit):
            fail(f"{path}: objective.signal_limits.{key} = {limit!r}: must be a number > 0")


def check_grid(where, grid):
    """A grid is a map {key: [values]} (a list of points, as a study's grid, is not)."""
    if not isinstance(grid, dict):
        fail(f"{where} = {grid!r}: must be a map {{key: [values]}}")
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            fail(f"{where}.{key} = {values!r}: must be a non-empty list of values")


def grid_points(grid):
    """The Cartesian product of the grid's axes (last axis fastest), as {key: value} dicts."""
    keys = list(grid)
    return [dict(zip(keys, values)) for values in itertools.product(*(grid[k] for k in keys))]


def candidate_name(family, i):
    return f"{family}__{i:02d}"


def relative_to(spec_path, name):
    """`name` as written in the file `spec_path`, as an absolute path (the generated studies live elsewhere)."""
    return os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(spec_path)), name))


def write_yaml(path, data):
    with open(path, "w") as f:
        yaml.safe_dump(data, f, default_flow_style=False, sort_keys=False)


def design_study(spec, spec_path):
    controllers = []
    for fam in spec["families"]:
        scenario = relative_to(spec_path, fam["scenario"])
        for i, point in enumerate(grid_points(fam["grid"])):
            controllers.append({"name": candidate_name(fam["name"], i), "scenario": scenario,
                                "set": {**fam.get("set", {}), **point}})
    d = spec["design"]
    return {"name": spec["name"] + "_design", "base": d["base"], "model": d.get("model", "nominal"),
            "controllers": controllers, "families": d["families"],
            "report": {"metric": error_metric(spec["objective"]), "scale": 1.0e6, "unit": "um",
                       "limit": spec["objective"]["error_limit_um"], "require": ["control_signal_within_limits"]}}


def run_study(binary, study_path, out, jobs):
    cmd = [os.path.join(binary, "feeddrive-study"), study_path, "--out", out, "-j", str(jobs), "--no-plots", "-q"]
    print("+ " + " ".join(cmd), file=sys.stderr, flush=True)
    rc = subprocess.call(cmd)
    if rc != 0:
        sys.exit(rc)


def figure(row, key):
    """A results cell as a float: nan when empty or not a number (never 0)."""
    try:
        return float(row[key])
    except (KeyError, ValueError):
        return math.nan


def case_score(row, objective):
    """(J_c, e [um], signal penalty) of one results.csv row, e the objective's error column; J_c =
    inf for a failed case or an error without a finite value (an empty analysis window has none:
    unknown never passes). A figure that is empty or not finite (nan, inf) counts as an infinite
    penalty: unknown is never within the limit. `null` is the summary's "not measurable at this
    period" (force_hf_rms_N when f_c >= 1/(2T), docs/scenario.md) and is not checked. A limit on a
    column the row lacks: exit 2."""
    e_um = figure(row, error_metric(objective)) * 1e6
    if row["ok"] != "true" or not math.isfinite(e_um):
        return math.inf, math.inf, math.inf
    penalty = 0.0
    for key, limit in objective["signal_limits"].items():
        if key not in row:
            fail(f"objective.signal_limits.{key}: no such column in the results")
        if row[key] == "null":
            continue
        x = figure(row, key)
        penalty += max(0.0, x / limit - 1.0) if math.isfinite(x) else math.inf
    return e_um / objective["error_limit_um"] + penalty, e_um, penalty


def read_scores(results, objective):
    """{controller: [(family, J_c, e_um, penalty, figures), ...]} from a results.csv; figures: the
    whole run's max |e| [um] and each signal figure, for the reports."""
    scores = {}
    with open(results, newline="") as f:
        reader = csv.DictReader(f)
        for key in [error_metric(objective), *objective["signal_limits"]]:
            if key not in (reader.fieldnames or []):
                what = "error_metric" if key == error_metric(objective) else f"signal_limits.{key}"
                fail(f"objective.{what}: no such column in {results}")
        for row in reader:
            j, e, p = case_score(row, objective)
            figures = {key: figure(row, key) for key in objective["signal_limits"]}
            figures["full_run_um"] = figure(row, FULL_RUN_ERROR) * 1e6 if FULL_RUN_ERROR in row else math.nan
            scores.setdefault(row["controller"], []).append((row["family"], j, e, p, figures))
    return scores


def worst(values):
    """The largest value; nan if any is nan (an unknown figure is never hidden by a max)."""
    values = list(values)
    return math.nan if any(math.isnan(v) for v in values) else max(values)


def summarise(cases):
    js = [c[1] for c in cases]
    s = {"J": max(js), "mean_J": sum(js) / len(js), "worst_e_um": max(c[2] for c in cases),
         "worst_penalty": max(c[3] for c in cases), "pass": sum(1 for c in cases if c[1] <= 1.0 and c[3] == 0.0),
         "signal_ok": sum(1 for c in cases if c[3] == 0.0), "cases": len(cases)}
    s["worst"] = {key: worst(c[4][key] for c in cases) for key in cases[0][4]}
    return s


def choose(spec, scores):
    """For each family: the list of (point, summary) and the index of the chosen candidate."""
    table = {}
    for fam in spec["families"]:
        rows = []
        for i, point in enumerate(grid_points(fam["grid"])):
            cases = scores.get(candidate_name(fam["name"], i))
            if not cases:
                fail(f"design results: no cases for {candidate_name(fam['name'], i)}")
            rows.append((point, summarise(cases)))
        best = min(range(len(rows)), key=lambda k: (rows[k][1]["J"], rows[k][1]["mean_J"]))
        table[fam["name"]] = (rows, best)
    return table


def fmt(x, digits=3):
    return "inf" if math.isinf(x) else "nan" if math.isnan(x) else f"{x:.{digits}g}"


def design_report(spec, table):
    lines = [f"# Design stage: {spec['name']} (budget {spec['budget']} candidates per family)", ""]
    for fam in spec["families"]:
        rows, best = table[fam["name"]]
        keys = list(fam["grid"])
        lines += [f"## {fam['name']}", "", "| " + " | ".join(k.replace("controller.", "") for k in keys) +
                  " | J | mean J_c | worst max\\|e\\| [um] | worst penalty | pass |",
                  "|" + "---|" * (len(keys) + 5)]
        for i, (point, s) in enumerate(rows):
            mark = "**" if i == best else ""
            cells = [str(point[k]) for k in keys] + [fmt(s["J"]), fmt(s["mean_J"]), fmt(s["worst_e_um"]),
                                                      fmt(s["worst_penalty"]), f"{s['pass']}/{s['cases']}"]
            lines.append("| " + " | ".join(f"{mark}{c}{mark}" for c in cells) + " |")
        lines.append("")
    return "\n".join(lines)


def write_case_table(results, path, objective):
    """The record of a stage to commit (DIR/design_cases.csv, DIR/test_cases.csv): every case's
    varied keys, the objective's error, the whole run's max |e| and the signal figures, copied
    from feeddrive-study's results.csv (the full table stays there)."""
    fixed = ["ok", error_metric(objective), FULL_RUN_ERROR, *objective["signal_limits"], "control_signal_within_limits"]
    with open(results, newline="") as f:
        reader = csv.DictReader(f)
        varied = [k for k in reader.fieldnames if k.startswith(("plant.", "controller.", "reference."))]
        columns = ["case", "controller", "family", "draw", *varied, *dict.fromkeys(fixed)]
        with open(path, "w", newline="") as out:
            writer = csv.DictWriter(out, fieldnames=columns, extrasaction="ignore", lineterminator="\n")
            writer.writeheader()
            writer.writerows(reader)


def stage_design(spec, spec_path, args):
    study = os.path.join(args.out, "design.yaml")
    write_yaml(study, design_study(spec, spec_path))
    run_study(args.bin, study, os.path.join(args.out, "design"), args.jobs)
    results = os.path.join(args.out, "design", "results.csv")
    table = choose(spec, read_scores(results, spec["objective"]))
    write_case_table(results, os.path.join(args.out, "design_cases.csv"), spec["objective"])
    with open(os.path.join(args.out, "design.md"), "w") as f:
        f.write(design_report(spec, table))
    chosen = {name: {"point": rows[best][0], "design": rows[best][1]} for name, (rows, best) in table.items()}
    write_yaml(os.path.join(args.out, "chosen.yaml"), chosen)
    return chosen


def test_study(spec, spec_path, chosen):
    path = relative_to(spec_path, spec["test"]["study"])
    with open(path) as f:
        study = yaml.safe_load(f)
    if isinstance(study.get("base"), str):
        study["base"] = relative_to(path, study["base"])
    study["name"] = spec["name"] + "_test"
    study["controllers"] = [{"name": fam["name"], "scenario": relative_to(spec_path, fam["scenario"]),
                             "set": {**fam.get("set", {}), **chosen[fam["name"]]["point"]}}
                            for fam in spec["families"]]
    return study


def test_report(spec, scores, families):
    names = [fam["name"] for fam in spec["families"]]
    metric = error_metric(spec["objective"])
    lines = [f"# Test stage: {spec['name']} (run once, the chosen candidate of each family)", "",
             f"Each cell: worst `{metric}` [um] (the objective's error); worst max|e| over the whole run [um]; "
             "worst J_c; cases whose command is within every signal limit; cases that pass (error <= limit as "
             "well).", "", "| test family | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    summaries = {}
    for tf in families:
        cells = []
        for name in names:
            cases = [c for c in scores.get(name, []) if c[0] == tf]
            s = summaries[tf, name] = summarise(cases) if cases else None
            cells.append("–" if s is None else f"{fmt(s['worst_e_um'])}; full run {fmt(s['worst']['full_run_um'])}; "
                         f"J {fmt(s['J'])}; signal ok {s['signal_ok']}/{s['cases']}; pass {s['pass']}/{s['cases']}")
        lines.append(f"| {tf} | " + " | ".join(cells) + " |")
    limits = spec["objective"]["signal_limits"]
    lines += ["", "The worst of each control-signal figure (limit in the header).", "",
              "| test family | family | " + " | ".join(f"{k} ({fmt(v, 4)})" for k, v in limits.items()) + " |",
              "|---|---|" + "---|" * len(limits)]
    for tf in families:
        for name in names:
            s = summaries[tf, name]
            if s is not None:
                lines.append(f"| {tf} | {name} | " + " | ".join(fmt(s["worst"][k], 4) for k in limits) + " |")
    return "\n".join(lines) + "\n"


def stage_test(spec, spec_path, args, chosen):
    study = test_study(spec, spec_path, chosen)
    path = os.path.join(args.out, "test.yaml")
    write_yaml(path, study)
    run_study(args.bin, path, os.path.join(args.out, "test"), args.jobs)
    results = os.path.join(args.out, "test", "results.csv")
    scores = read_scores(results, spec["objective"])
    write_case_table(results, os.path.join(args.out, "test_cases.csv"), spec["objective"])
    with open(os.path.join(args.out, "test.md"), "w") as f:
        f.write(test_report(spec, scores, [fam["name"] for fam in study["families"]]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("spec")
    ap.add_argument("--out", required=True)
    ap.add_argument("--bin", default="build/bin")
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("--stage", choices=["all", "design", "test"], default="all")
    args = ap.parse_args()
    spec = load_spec(args.spec)
    os.makedirs(args.out, exist_ok=True)
    if args.stage in ("all", "design"):
        chosen = stage_design(spec, args.spec, args)
    else:
        try:
            with open(os.path.join(args.out, "chosen.yaml")) as f:
                chosen = yaml.safe_load(f)
        except OSError as e:
            fail(f"--stage test: {e} (run the design stage first)")
    if args.stage in ("all", "test"):
        stage_test(spec, args.spec, args, chosen)


if __name__ == "__main__":
    main()
