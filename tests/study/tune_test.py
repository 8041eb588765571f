#!/usr/bin/env python3
"""Unit tests of scripts/tune.py's pure logic (docs/tuning.md): the objective of one case, the
grid's order, the choice (the signal limits a hard constraint; the recommendation across
families), and the spec checks' one-line errors (exit 2) before any case runs: the budget, a grid
written as a list, families not a list, a bad or misspelt signal limit (the probe, with the
binaries), name, set, design, test, chosen.yaml, a second test run; nan/empty figures.
Usage: python3 tests/study/tune_test.py SOURCE_DIR [BIN_DIR]"""
import math
import os
import subprocess
import sys
import tempfile
import unittest

SRC = os.path.abspath(sys.argv.pop(1) if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.path.abspath(sys.argv.pop(1) if len(sys.argv) > 1 else os.path.join(SRC, "build", "bin"))
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

    def run_spec(self, families, limits="{}", budget=2, head=None, args=(), files=None):
        """Runs tune.py on a spec (its families, limits and budget, or the whole `head` before
        `families:`) in a fresh folder holding s.yaml and x.yaml (and `files`: {name: text});
        returns (exit status, stderr with the spec's path as SPEC and the folder as DIR)."""
        if head is None:
            head = (f"name: t\nobjective: {{error_limit_um: 0.8, signal_limits: {limits}}}\nbudget: {budget}\n"
                    f"design: {{base: {{}}, families: []}}\ntest: {{study: x.yaml}}\n")
        with tempfile.TemporaryDirectory() as d:
            for name, text in {"s.yaml": "name: s\n", "x.yaml": "name: x\n", **(files or {})}.items():
                os.makedirs(os.path.dirname(os.path.join(d, name)), exist_ok=True)
                with open(os.path.join(d, name), "w") as f:
                    f.write(text)
            path = os.path.join(d, "spec.yaml")
            with open(path, "w") as f:
                f.write(head + f"families: {families}\n")
            out = subprocess.run([sys.executable, os.path.join(SRC, "scripts", "tune.py"), path, "--out",
                                  os.path.join(d, "out"), "--bin", BIN, *args], capture_output=True, text=True)
        return out.returncode, out.stderr.strip().replace(path, "SPEC").replace(d, "DIR")

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


FAM = "[{name: smc, scenario: s.yaml, grid: {controller.lambda: [1, 2]}}]"
HEAD = "objective: {error_limit_um: 0.8, signal_limits: {}}\nbudget: 2\n"


class SpecUpFront(unittest.TestCase):
    """Every malformed spec is one line naming the key and the value, exit 2, before any case runs
    (no Python traceback, no feeddrive-study)."""
    run_spec = Grid.run_spec

    def check(self, head, want, families=FAM, **kw):
        rc, err = self.run_spec(families, head=head, **kw)
        self.assertEqual((rc, err), (2, want))
        self.assertNotIn("Traceback", err)

    def test_no_name(self):
        self.check(HEAD + "design: {base: {}, families: []}\ntest: {study: x.yaml}\n", "error: SPEC: name: missing")

    def test_budget_as_a_string_names_the_type(self):
        # "12" is not 12: the old message said "12 points, the budget is 12".
        self.check("name: t\nobjective: {error_limit_um: 0.8, signal_limits: {}}\nbudget: '2'\n"
                   "design: {base: {}, families: []}\ntest: {study: x.yaml}\n",
                   "error: SPEC: budget = '2': must be an integer >= 1 (grid points per family)")

    def test_design_not_a_map_or_without_base(self):
        self.check("name: t\n" + HEAD + "design: [a]\ntest: {study: x.yaml}\n",
                   "error: SPEC: design = ['a']: must be a map with base and families")
        self.check("name: t\n" + HEAD + "design: {families: []}\ntest: {study: x.yaml}\n",
                   "error: SPEC: design.base: missing")

    def test_test_not_a_map_without_study_or_naming_a_missing_file(self):
        design = "design: {base: {}, families: []}\n"
        self.check("name: t\n" + HEAD + design + "test: x.yaml\n",
                   "error: SPEC: test = 'x.yaml': must be a map with study")
        self.check("name: t\n" + HEAD + design + "test: {}\n", "error: SPEC: test.study = None: must be a study file name")
        self.check("name: t\n" + HEAD + design + "test: {study: nope.yaml}\n",
                   "error: SPEC: test.study = 'nope.yaml': no such file")

    def test_set_given_as_a_list(self):
        self.check("name: t\n" + HEAD + "design: {base: {}, families: []}\ntest: {study: x.yaml}\n",
                   "error: SPEC: families.smc.set = ['controller.k', 1]: must be a map {key: value}",
                   families="[{name: smc, scenario: s.yaml, set: [controller.k, 1], grid: {controller.lambda: [1, 2]}}]")

    def test_a_family_scenario_that_is_no_file(self):
        self.check("name: t\n" + HEAD + "design: {base: {}, families: []}\ntest: {study: x.yaml}\n",
                   "error: SPEC: families.smc.scenario = 'gone.yaml': no such file",
                   families="[{name: smc, scenario: gone.yaml, grid: {controller.lambda: [1, 2]}}]")

    def test_stage_test_with_a_chosen_yaml_lacking_a_family_or_malformed(self):
        head = "name: t\n" + HEAD + "design: {base: {}, families: []}\ntest: {study: x.yaml}\n"
        self.check(head, "error: DIR/out/chosen.yaml: families.smc.point: missing", args=("--stage", "test"),
                   files={"out/chosen.yaml": "recommended: smc\nfamilies: {other: {point: {controller.lambda: 1}}}\n"})
        self.check(head, "error: DIR/out/chosen.yaml: families = None: must be a map {family: {point: ...}}",
                   args=("--stage", "test"), files={"out/chosen.yaml": "smc: {point: {controller.lambda: 1}}\n"})
        self.check(head, "error: DIR/out/chosen.yaml: families.smc.point = {'controller.lambda': 3}: "
                         "not a point of the spec's grid", args=("--stage", "test"),
                   files={"out/chosen.yaml": "recommended: smc\nfamilies: {smc: {point: {controller.lambda: 3}}}\n"})
        self.check(head, "error: DIR/out/chosen.yaml: recommended = 'cascade': must name one of the families ['smc']",
                   args=("--stage", "test"),
                   files={"out/chosen.yaml": "recommended: cascade\nfamilies: {smc: {point: {controller.lambda: 1}}}\n"})

    def test_a_malformed_test_study_is_refused_before_the_design_stage(self):
        # Found in review: a test study that is not YAML passed the up-front check, the whole
        # design stage ran, and --stage test then died with a traceback (exit 1).
        head = "name: t\n" + HEAD + "design: {base: {}, families: []}\ntest: {study: x.yaml}\n"
        rc, err = self.run_spec(FAM, head=head, files={"x.yaml": "name: x\nbase: [1,\n"})
        self.assertEqual(rc, 2)
        self.assertEqual(len(err.splitlines()), 1, err)
        self.assertRegex(err, r"^error: DIR/x\.yaml: line \d+, column \d+: not YAML: ")
        self.check(head, "error: DIR/x.yaml: not a map (test.study of SPEC)", files={"x.yaml": "- a\n"})

    def test_a_spec_that_is_not_yaml_is_one_line(self):
        rc, err = self.run_spec(FAM, head="name: t\nobjective: {error_limit_um: [0.8\n")
        self.assertEqual(rc, 2)
        self.assertEqual(len(err.splitlines()), 1, err)
        self.assertRegex(err, r"^error: SPEC: line \d+, column \d+: not YAML: ")

    def test_a_second_test_run_is_refused_without_force(self):
        head = "name: t\n" + HEAD + "design: {base: {}, families: []}\ntest: {study: x.yaml}\n"
        self.check(head, "error: --stage test: DIR/out/test exists: the test set is run once (--force to run it again)",
                   args=("--stage", "test"),
                   files={"out/chosen.yaml": "recommended: smc\nfamilies: {smc: {point: {controller.lambda: 1}}}\n",
                          "out/test/results.csv": "case\n"})

    @unittest.skipUnless(os.path.exists(os.path.join(BIN, "feeddrive-study")), "needs feeddrive-study (BIN_DIR)")
    def test_a_misspelt_signal_limit_is_caught_before_the_design_stage(self):
        # The probe (one 0.15 s case) reads the real results header; the design study never runs.
        scenario = os.path.join(SRC, "scenarios", "robustness", "robust_smc.yaml")
        head = ("name: t\nobjective: {error_limit_um: 0.8, signal_limits: {control_step_rms: 0.2}}\nbudget: 2\n"
                "design: {base: {duration: 1.0, control_period: 1.0e-4, reference: {type: scurve}}, "
                "families: [{name: f}]}\ntest: {study: x.yaml}\n")
        rc, err = self.run_spec(f"[{{name: smc, scenario: {scenario}, grid: {{controller.k: [10.0, 11.0]}}}}]", head=head)
        self.assertEqual(rc, 2)
        self.assertEqual(err.splitlines()[-1], "error: SPEC: objective.signal_limits.control_step_rms: no such "
                                               "results column (probe: DIR/out/probe.yaml)")
        self.assertNotIn("t_design", err)


class HardConstraint(unittest.TestCase):
    """The signal limits are a hard constraint and the recommendation is chosen across families."""

    def summary(self, j, penalty):
        return tune.summarise([("f", j, 0.8 * j, penalty, {"full_run_um": 0.8 * j})])

    def test_a_feasible_candidate_ranks_before_any_infeasible_one(self):
        # J 4.87 within every limit beats J 3.36 with a signal penalty (the first round's SMC choice).
        feasible, infeasible = self.summary(4.87, 0.0), self.summary(3.36, 0.4)
        self.assertTrue(feasible["feasible"] and not infeasible["feasible"])
        self.assertLess(tune.rank(feasible), tune.rank(infeasible))
        # Among feasible ones the lower J; among infeasible ones too.
        self.assertLess(tune.rank(self.summary(2.0, 0.0)), tune.rank(feasible))
        self.assertLess(tune.rank(self.summary(3.0, 0.1)), tune.rank(self.summary(5.0, 0.1)))
        # A failed case (J infinite) is never feasible.
        self.assertFalse(tune.summarise([("f", math.inf, math.inf, math.inf, {"full_run_um": math.nan})])["feasible"])

    def test_the_recommendation_is_the_best_family_choice_by_the_same_rule(self):
        table = {"a": ([({}, self.summary(3.0, 0.5))], 0), "b": ([({}, self.summary(5.0, 0.0))], 0),
                 "c": ([({}, self.summary(4.0, 0.0))], 0)}
        self.assertEqual(tune.recommend(table), "c")


class RecommendedOneSource(unittest.TestCase):
    """The recommended controller's settings live in scenarios/robustness/recommended.yaml; the
    tuning record (docs/tuning/chosen.yaml: the family and its point) and the family's definition
    (studies/tuning.yaml: its scenario and fixed keys) must say the same, and the studies that
    run it must take that file, not a copy of its keys."""

    def load(self, *parts):
        import yaml
        with open(os.path.join(SRC, *parts)) as f:
            return yaml.safe_load(f)

    def test_the_file_is_the_tuning_choice(self):
        chosen = self.load("docs", "tuning", "chosen.yaml")
        spec = self.load("studies", "tuning.yaml")
        fam = next(f for f in spec["families"] if f["name"] == chosen["recommended"])
        expected = self.load("studies", fam["scenario"])["controller"]
        for key, value in {**fam.get("set", {}), **chosen["families"][fam["name"]]["point"]}.items():
            self.assertTrue(key.startswith("controller."), key)
            expected[key[len("controller."):]] = value
        self.assertEqual(self.load("scenarios", "robustness", "recommended.yaml")["controller"], expected)

    def test_the_studies_take_the_file(self):
        for study in ("robustness_moves.yaml", "reversal_fix.yaml"):
            entries = [c for c in self.load("studies", study)["controllers"] if c["name"] == "recommended"]
            self.assertEqual(len(entries), 1, study)
            self.assertEqual(entries[0]["scenario"], "../scenarios/robustness/recommended.yaml", study)
            self.assertNotIn("set", entries[0], study)


if __name__ == "__main__":
    unittest.main()
