#!/usr/bin/env python3
"""Unit tests of scripts/tune.py's pure logic (docs/tuning.md): the objective of one case, the
grid's order, the choice, and the spec checks' one-line errors (exit 2): the budget, a grid
written as a list, families not a list, a bad or misspelt signal limit; nan/empty figures.
Usage: python3 tests/study/tune_test.py SOURCE_DIR"""
import math
import os
import subprocess
import sys
import tempfile
import unittest

SRC = sys.argv.pop(1) if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
sys.path.insert(0, os.path.join(SRC, "scripts"))
import tune  # noqa: E402

OBJECTIVE = {"error_limit_um": 0.8, "signal_limits": {"control_step_rms_V": 0.2,
                                                      "control_direction_changes_per_s": 2000.0,
                                                      "force_hf_rms_N": 52.0, "control_saturated_fraction": 0.01}}


def row(e_m, step=0.1, changes=1000.0, hf=10.0, sat=0.0, ok="true"):
    return {"ok": ok, "position_error_max_abs_m": repr(e_m), "control_step_rms_V": repr(step),
            "control_direction_changes_per_s": repr(changes), "force_hf_rms_N": repr(hf),
            "control_saturated_fraction": repr(sat)}


class Objective(unittest.TestCase):
    def test_error_alone_within_the_limits(self):
        # 0.4 um against 0.8 um, every signal figure within its limit: J_c = 0.5, no penalty.
        j, e, p = tune.case_score(row(0.4e-6), OBJECTIVE)
        self.assertAlmostEqual(j, 0.5, places=12)
        self.assertAlmostEqual(e, 0.4, places=12)
        self.assertEqual(p, 0.0)

    def test_each_figure_over_its_limit_adds_its_relative_excess(self):
        # 3,000 /s against 2,000: +0.5; 0.3 V against 0.2 V: +0.5; 2 % saturated against 1 %: +1.
        j, _, p = tune.case_score(row(0.4e-6, step=0.3, changes=3000.0, sat=0.02), OBJECTIVE)
        self.assertAlmostEqual(p, 2.0, places=12)
        self.assertAlmostEqual(j, 2.5, places=12)

    def test_a_null_figure_is_not_checked_and_a_failed_case_is_infinite(self):
        r = row(0.4e-6)
        r["force_hf_rms_N"] = "null"
        self.assertAlmostEqual(tune.case_score(r, OBJECTIVE)[0], 0.5, places=12)
        self.assertTrue(math.isinf(tune.case_score(row(0.4e-6, ok="false"), OBJECTIVE)[0]))

    def test_a_nan_or_empty_figure_is_an_infinite_penalty(self):
        # Unknown is never within a limit: a nan or empty figure must not score 0 (a false all-clear).
        for bad in ("nan", "", "inf"):
            r = row(0.4e-6)
            r["control_step_rms_V"] = bad
            j, _, p = tune.case_score(r, OBJECTIVE)
            self.assertTrue(math.isinf(p) and math.isinf(j), bad)
        r = row(0.4e-6)
        r["position_error_max_abs_m"] = "nan"
        self.assertTrue(math.isinf(tune.case_score(r, OBJECTIVE)[0]))

    def test_a_misspelt_limit_is_an_error_not_a_zero_penalty(self):
        objective = {"error_limit_um": 0.8, "signal_limits": {"control_step_rms": 0.2}}
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "results.csv")
            with open(path, "w") as f:
                f.write("controller,family,ok,position_error_max_abs_m,control_step_rms_V\n"
                        "a,f,true,4e-7,0.1\n")
            code = "import sys, tune; tune.read_scores(sys.argv[1], {'error_limit_um': 0.8, " \
                   "'signal_limits': {'control_step_rms': 0.2}})"
            out = subprocess.run([sys.executable, "-c", code, path], capture_output=True, text=True,
                                 env={**os.environ, "PYTHONPATH": os.path.join(SRC, "scripts")})
        self.assertEqual(out.returncode, 2)
        self.assertEqual(out.stderr.strip(),
                         f"error: objective.signal_limits.control_step_rms: no such column in {path}")
        with self.assertRaises(SystemExit):
            tune.case_score(row(0.4e-6), objective)

    def test_pass_means_j_at_most_one_and_no_penalty(self):
        s = tune.summarise([("f", 0.9, 0.72, 0.0, {"full_run_um": 1.5}), ("f", 1.2, 0.4, 0.7, {"full_run_um": 0.5}),
                            ("f", 1.1, 0.88, 0.0, {"full_run_um": 0.9})])
        self.assertEqual((s["pass"], s["signal_ok"], s["cases"]), (1, 2, 3))
        self.assertAlmostEqual(s["J"], 1.2, places=12)
        self.assertEqual(s["worst"], {"full_run_um": 1.5})
        # An unknown figure is never hidden by the max of the others.
        s = tune.summarise([("f", 0.9, 0.72, 0.0, {"full_run_um": math.nan}), ("f", 1.2, 0.4, 0.7, {"full_run_um": 0.5})])
        self.assertTrue(math.isnan(s["worst"]["full_run_um"]))

    def test_the_error_term_reads_the_objectives_error_metric(self):
        # studies/tuning.yaml scores the max |e| after the analysis window: a start transient of
        # 2 um over the whole run and 0.4 um after the window scores J_c = 0.5, not 2.5.
        objective = {**OBJECTIVE, "error_metric": "position_error_max_abs_settled_m"}
        r = {**row(2.0e-6), "position_error_max_abs_settled_m": repr(0.4e-6)}
        self.assertAlmostEqual(tune.case_score(r, objective)[0], 0.5, places=12)
        self.assertAlmostEqual(tune.case_score(r, OBJECTIVE)[0], 2.5, places=12)
        # A window without a value (a run shorter than the window: an empty cell) never passes.
        r["position_error_max_abs_settled_m"] = ""
        self.assertTrue(math.isinf(tune.case_score(r, objective)[0]))


class Grid(unittest.TestCase):
    def test_cartesian_product_last_axis_fastest(self):
        pts = tune.grid_points({"a": [1, 2], "b": ["x", "y", "z"]})
        self.assertEqual(len(pts), 6)
        self.assertEqual(pts[0], {"a": 1, "b": "x"})
        self.assertEqual(pts[1], {"a": 1, "b": "y"})
        self.assertEqual(pts[3], {"a": 2, "b": "x"})

    def test_the_budget_is_checked_with_a_one_line_error(self):
        code, err = self.run_spec("\n  - {name: smc, scenario: s.yaml, grid: {controller.lambda: [1, 2, 3]}}", budget=4)
        self.assertEqual(code, 2)
        self.assertEqual(err, "error: SPEC: families.smc.grid: 3 points, the budget is 4")

    def run_spec(self, families, limits="{}", budget=2):
        spec = (f"name: t\nobjective: {{error_limit_um: 0.8, signal_limits: {limits}}}\nbudget: {budget}\n"
                f"design: {{base: {{}}, families: []}}\ntest: {{study: x.yaml}}\nfamilies: {families}\n")
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "spec.yaml")
            with open(path, "w") as f:
                f.write(spec)
            out = subprocess.run([sys.executable, os.path.join(SRC, "scripts", "tune.py"), path, "--out",
                                  os.path.join(d, "out")], capture_output=True, text=True)
        return out.returncode, out.stderr.strip().replace(path, "SPEC")

    def test_a_grid_written_as_a_list_is_a_one_line_error(self):
        # Study files write grids as lists of points; tune.py's grid is a map {key: [values]}.
        rc, err = self.run_spec("[{name: smc, scenario: s.yaml, "
                                "grid: [{controller.lambda: 1}, {controller.lambda: 2}]}]")
        self.assertEqual(rc, 2)
        self.assertEqual(err, "error: SPEC: families.smc.grid = [{'controller.lambda': 1}, {'controller.lambda': 2}]: "
                              "must be a map {key: [values]}")
        rc, err = self.run_spec("[{name: smc, scenario: s.yaml, grid: {controller.lambda: 3}}]")
        self.assertEqual((rc, err), (2, "error: SPEC: families.smc.grid.controller.lambda = 3: "
                                        "must be a non-empty list of values"))

    def test_families_not_a_list_and_bad_limits_are_one_line_errors(self):
        self.assertEqual(self.run_spec("3"), (2, "error: SPEC: families = 3: must be a list of families"))
        fam = "[{name: smc, scenario: s.yaml, grid: {controller.lambda: [1, 2]}}]"
        self.assertEqual(self.run_spec(fam, "{control_step_rms_V: -1}"),
                         (2, "error: SPEC: objective.signal_limits.control_step_rms_V = -1: must be a number > 0"))

    def test_an_error_metric_that_is_no_column_is_an_error(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "results.csv")
            with open(path, "w") as f:
                f.write("controller,family,ok,position_error_max_abs_m\na,f,true,4e-7\n")
            code = "import sys, tune; tune.read_scores(sys.argv[1], {'error_limit_um': 0.8, " \
                   "'error_metric': 'position_error_max_abs_settled', 'signal_limits': {}})"
            out = subprocess.run([sys.executable, "-c", code, path], capture_output=True, text=True,
                                 env={**os.environ, "PYTHONPATH": os.path.join(SRC, "scripts")})
        self.assertEqual((out.returncode, out.stderr.strip()),
                         (2, f"error: objective.error_metric: no such column in {path}"))

    def test_the_projects_specs_have_equal_budgets(self):
        for name in ("tuning.yaml", "tuning_long.yaml"):
            spec = tune.load_spec(os.path.join(SRC, "studies", name))
            self.assertTrue(all(len(tune.grid_points(f["grid"])) == spec["budget"] for f in spec["families"]))


if __name__ == "__main__":
    unittest.main()
