#!/usr/bin/env python3
"""One tuning procedure for every controller family (issue 24, item 2; docs/tuning.md).

Usage: python3 scripts/tune.py SPEC.yaml --out DIR [--bin build/bin] [-j N] [--stage all|design|test] [--force]

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
     every design case passes. The signal limits are a HARD constraint: a candidate with any
     design case outside a signal limit (or without a signal figure) is infeasible and ranks after
     every feasible candidate, whatever its J. Each family keeps its best candidate (feasible
     first, then the lowest J, then the lower mean J_c), and the RECOMMENDED controller is chosen
     across families by the same rule on the same design set: the family whose choice ranks first
     (DIR/chosen.yaml `recommended`). DIR/chosen.yaml, DIR/design.md, DIR/design_cases.csv (every
     case, for the record);
  3. the test study (the SPEC's test.study with its controllers replaced by the chosen ones,
     DIR/test.yaml) is run once (DIR/test/results.csv, DIR/test_cases.csv); DIR/test.md tables,
     per test family and family, the worst error (objective.error_metric), the worst max |e|
     over the whole run, the cases within the signal limits and the passing ones, and the worst
     of each signal figure. The test stage runs once: a second run into DIR (DIR/test/ exists)
     is refused (exit 2) unless --force.
Every grid must have exactly `budget` points (else exit 2): the same effort for every family.
Bad input: one line on stderr naming the key and the value, exit 2, before any case runs: the
whole spec is checked up front (name, budget an integer, design a map with base and families,
test a map whose study file exists, each family's name, scenario file, set map and grid map
{key: [values]}; the objective's limits numbers > 0), a probe of one short case
(DIR/probe) checks that error_metric and every signal limit name a results column, and with
--stage test DIR/chosen.yaml must hold every family's point from its grid. A signal figure that
is empty or nan scores an infinite penalty, never 0. A failed feeddrive-study: its exit status.
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


def load_yaml(path, what=""):
    """The YAML document at path, or a one-line error (exit 2): the file, the line and PyYAML's
    problem (its message spans several lines, which the one-line rule does not allow)."""
    try:
        with open(path) as f:
            return yaml.safe_load(f)
    except OSError as e:
        fail(f"{path}: {e.strerror}{what}")
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f" line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(e, "problem", None) or str(e).splitlines()[0]
        fail(f"{path}:{where}: not YAML: {problem}")


def load_spec(path):
    """The spec, checked whole before anything runs (one-line error naming the key, exit 2)."""
    spec = load_yaml(path)
    if not isinstance(spec, dict):
        fail(f"{path}: not a map")
    for key in ("name", "objective", "budget", "design", "test", "families"):
        if key not in spec:
            fail(f"{path}: {key}: missing")
    if not isinstance(spec["name"], str) or not spec["name"]:
        fail(f"{path}: name = {spec['name']!r}: must be a non-empty string")
    check_objective(path, spec["objective"])
    if not isinstance(spec["budget"], int) or isinstance(spec["budget"], bool) or spec["budget"] < 1:
        fail(f"{path}: budget = {spec['budget']!r}: must be an integer >= 1 (grid points per family)")
    check_design(path, spec["design"])
    check_test(path, spec["test"])
    check_families(path, spec)
    return spec


def check_design(path, design):
    """design: a map with base (a scenario file name or a map) and families (a list)."""
    if not isinstance(design, dict):
        fail(f"{path}: design = {design!r}: must be a map with base and families")
    if "base" not in design:
        fail(f"{path}: design.base: missing")
    base = design["base"]
    if isinstance(base, str):
        if not os.path.isfile(relative_to(path, base)):
            fail(f"{path}: design.base = {base!r}: no such file")
    elif not isinstance(base, dict):
        fail(f"{path}: design.base = {base!r}: must be a scenario file name or a map")
    if not isinstance(design.get("families"), list):
        fail(f"{path}: design.families = {design.get('families')!r}: must be a list of families")


def check_test(path, test):
    """test: a map whose study names an existing study file."""
    if not isinstance(test, dict):
        fail(f"{path}: test = {test!r}: must be a map with study")
    study = test.get("study")
    if not isinstance(study, str) or not study:
        fail(f"{path}: test.study = {study!r}: must be a study file name")
    if not os.path.isfile(relative_to(path, study)):
        fail(f"{path}: test.study = {study!r}: no such file")
    body = load_yaml(relative_to(path, study))  # parsed now: a broken test study must not wait for the design stage
    if not isinstance(body, dict):
        fail(f"{relative_to(path, study)}: not a map (test.study of {path})")


def check_families(path, spec):
    """families: a list of {name, scenario (an existing file), set (a map, optional), grid} with
    distinct names, each grid a map of `budget` points."""
    if not isinstance(spec["families"], list):
        fail(f"{path}: families = {spec['families']!r}: must be a list of families")
    names = set()
    for i, fam in enumerate(spec["families"]):
        if not isinstance(fam, dict):
            fail(f"{path}: families[{i}] = {fam!r}: must be a map with name, scenario and grid")
        for key in ("name", "scenario", "grid"):
            if key not in fam:
                fail(f"{path}: families[{i}].{key}: missing")
        name = fam["name"]
        if not isinstance(name, str) or not name or name in names:
            fail(f"{path}: families[{i}].name = {name!r}: must be a non-empty string, unique")
        names.add(name)
        if not isinstance(fam["scenario"], str) or not os.path.isfile(relative_to(path, fam["scenario"])):
            fail(f"{path}: families.{name}.scenario = {fam['scenario']!r}: no such file")
        if not isinstance(fam.get("set", {}), dict):
            fail(f"{path}: families.{name}.set = {fam['set']!r}: must be a map {{key: value}}")
        check_grid(f"{path}: families.{name}.grid", fam["grid"])
        n = len(grid_points(fam["grid"]))
        if n != spec["budget"]:
            fail(f"{path}: families.{name}.grid: {n} points, the budget is {spec['budget']}")


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


def probe_columns(spec, spec_path, args):
    """Before any stage runs: one short case (the first candidate on the first design family,
    0.15 s, past the 0.1 s window) through feeddrive-study into DIR/probe, and its results.csv header checked for
    error_metric and every signal limit (a misspelt column is caught before the design stage)."""
    study = design_study(spec, spec_path)
    study["name"] = spec["name"] + "_probe"
    study["controllers"] = study["controllers"][:1]
    fams = study["families"][:1] or [{"name": "probe"}]
    study["families"] = [{"name": fams[0].get("name", "probe"), "set": {**fams[0].get("set", {}), "duration": 0.15}}]
    study.pop("report")
    path = os.path.join(args.out, "probe.yaml")
    write_yaml(path, study)
    run_study(args.bin, path, os.path.join(args.out, "probe"), 1)
    with open(os.path.join(args.out, "probe", "results.csv"), newline="") as f:
        columns = next(csv.reader(f), [])
    for key in [error_metric(spec["objective"]), *spec["objective"]["signal_limits"]]:
        if key not in columns:
            what = f"error_metric = {key!r}" if key == error_metric(spec["objective"]) else f"signal_limits.{key}"
            fail(f"{spec_path}: objective.{what}: no such results column (probe: {path})")


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
    s["feasible"] = s["signal_ok"] == s["cases"] and math.isfinite(s["J"])
    return s


def rank(summary):
    """The selection rule (docs/tuning.md): the signal limits are a hard constraint, so every
    feasible candidate (within every signal limit in every design case) ranks before every
    infeasible one; then the lower J, then the lower mean J_c."""
    return (not summary["feasible"], summary["J"], summary["mean_J"])


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
        best = min(range(len(rows)), key=lambda k: rank(rows[k][1]))
        table[fam["name"]] = (rows, best)
    return table


def recommend(table):
    """The recommended family: the one whose chosen candidate ranks first by the same rule (rank),
    across families, on the design set; ties keep the spec's order."""
    return min(table, key=lambda name: rank(table[name][0][table[name][1]][1]))


def fmt(x, digits=3):
    return "inf" if math.isinf(x) else "nan" if math.isnan(x) else f"{x:.{digits}g}"


def design_report(spec, table):
    rec = recommend(table)
    lines = [f"# Design stage: {spec['name']} (budget {spec['budget']} candidates per family)", "",
             "Rule: the signal limits are a hard constraint (feasible: within every signal limit in every design "
             "case); each family keeps its feasible candidate of lowest J (ties: lower mean J_c; only if no candidate "
             "is feasible, the infeasible one of lowest J, marked), and the recommended controller is the family "
             "choice that ranks first by the same rule across families.", "",
             f"**Recommended: {rec}** (J {fmt(table[rec][0][table[rec][1]][1]['J'])}, "
             f"{'feasible' if table[rec][0][table[rec][1]][1]['feasible'] else 'INFEASIBLE: no candidate is'}).", ""]
    for fam in spec["families"]:
        rows, best = table[fam["name"]]
        keys = list(fam["grid"])
        lines += [f"## {fam['name']}", "", "| " + " | ".join(k.replace("controller.", "") for k in keys) +
                  " | feasible | J | mean J_c | worst max\\|e\\| [um] | worst penalty | pass |",
                  "|" + "---|" * (len(keys) + 6)]
        for i, (point, s) in enumerate(rows):
            mark = "**" if i == best else ""
            cells = [str(point[k]) for k in keys] + ["yes" if s["feasible"] else "no", fmt(s["J"]), fmt(s["mean_J"]), fmt(s["worst_e_um"]),
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
    chosen = {"recommended": recommend(table), "rule": RULE,
              "families": {name: {"point": rows[best][0], "design": rows[best][1]} for name, (rows, best) in table.items()}}
    write_yaml(os.path.join(args.out, "chosen.yaml"), chosen)
    return chosen


RULE = ("signal limits a hard constraint (feasible: within every signal limit in every design case); per family and "
        "across families the feasible candidate of lowest J = max_c e_c/e_lim, ties the lower mean J_c; infeasible "
        "candidates rank after every feasible one")


def load_chosen(spec, path):
    """DIR/chosen.yaml for --stage test: {recommended, rule, families: {name: {point: {key: value}}}}
    with every family of the spec, each point a point of its grid (one-line error, exit 2)."""
    chosen = load_yaml(path, " (run the design stage first)")
    if not isinstance(chosen, dict) or not isinstance(chosen.get("families"), dict):
        fail(f"{path}: families = {chosen.get('families') if isinstance(chosen, dict) else chosen!r}: "
             "must be a map {family: {point: ...}}")
    for fam in spec["families"]:
        entry = chosen["families"].get(fam["name"])
        point = entry.get("point") if isinstance(entry, dict) else None
        if point is None:
            fail(f"{path}: families.{fam['name']}.point: missing")
        if point not in grid_points(fam["grid"]):
            fail(f"{path}: families.{fam['name']}.point = {point!r}: not a point of the spec's grid")
    names = [fam["name"] for fam in spec["families"]]
    if chosen.get("recommended") not in names:
        fail(f"{path}: recommended = {chosen.get('recommended')!r}: must name one of the families {names}")
    return chosen


def test_study(spec, spec_path, chosen):
    path = relative_to(spec_path, spec["test"]["study"])
    study = load_yaml(path)  # checked by check_test before any case ran
    if isinstance(study.get("base"), str):
        study["base"] = relative_to(path, study["base"])
    study["name"] = spec["name"] + "_test"
    study["controllers"] = [{"name": fam["name"], "scenario": relative_to(spec_path, fam["scenario"]),
                             "set": {**fam.get("set", {}), **chosen["families"][fam["name"]]["point"]}}
                            for fam in spec["families"]]
    return study


def test_report(spec, scores, families, recommended):
    names = [fam["name"] for fam in spec["families"]]
    metric = error_metric(spec["objective"])
    lines = [f"# Test stage: {spec['name']} (run once, the chosen candidate of each family)", "",
             f"Recommended on the design set, before this run: **{recommended}**.", "",
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
        f.write(test_report(spec, scores, [fam["name"] for fam in study["families"]], chosen["recommended"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("spec")
    ap.add_argument("--out", required=True)
    ap.add_argument("--bin", default="build/bin")
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("--stage", choices=["all", "design", "test"], default="all")
    ap.add_argument("--force", action="store_true", help="run the test stage again (it is run once)")
    args = ap.parse_args()
    spec = load_spec(args.spec)
    chosen = None
    if args.stage == "test":
        chosen = load_chosen(spec, os.path.join(args.out, "chosen.yaml"))
    if args.stage in ("all", "test") and os.path.exists(os.path.join(args.out, "test")) and not args.force:
        fail(f"--stage {args.stage}: {os.path.join(args.out, 'test')} exists: the test set is run once "
             "(--force to run it again)")
    os.makedirs(args.out, exist_ok=True)
    probe_columns(spec, args.spec, args)
    if args.stage in ("all", "design"):
        chosen = stage_design(spec, args.spec, args)
    if args.stage in ("all", "test"):
        stage_test(spec, args.spec, args, chosen)


if __name__ == "__main__":
    main()
