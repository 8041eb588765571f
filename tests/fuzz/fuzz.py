#!/usr/bin/env python3
"""Seeded fuzzing of feeddrive's inputs (issue 13, point 9). docs/scenario.md, "Fuzzing".

Modes (each a ctest entry, tests/CMakeLists.txt):
  scenario  mutations of scenarios/paper/*.yaml run by feeddrive-sim: one leaf replaced by an
            extreme or ill-typed value, a factor applied, a key deleted or added, the controller,
            reference or open-loop kind switched, a waypoints file with extreme values, a hostile
            name, and raw-text mutations (bit flips, cut lines, truncation, stray quotes).
  csv       mutations of a fit CSV (a short record of the docs/fit.md "real drive") run by
            feeddrive-fit: bit flips, truncation, deleted/duplicated/swapped rows, NaN/inf/1e308
            cells, epoch time stamps, a renamed or dropped column, other separators.
  lcm       mutations of an lcm-logger log of a four-process run (made by the test in a private
            network namespace) run by feeddrive-log2csv and feeddrive-fit: truncation, bit flips
            (anywhere, in event headers, in channel names, in sequence numbers), dropped,
            duplicated and swapped events.
  yaml      YAML constructs in scenarios/paper/*.yaml (issue 19, point 8): a recursive alias (a map
            or list holding its own ancestor, anywhere in the tree), a merge key (<<: a map or a
            list of maps), a shared (non-recursive) alias, each read by every tool that reads YAML:
            feeddrive-sim, feeddrive-study (the scenario as the study's base file, or inline as its
            base map) and feeddrive-fit (the scenario as its model). A recursive alias or a merge
            key must give exit 2 and one line naming the construct ("recursive YAML alias",
            "merge key"); before the fix yaml-cpp's cycle crashed every tool (exit 139).

Every case must end in one of two ways:
  * exit 2, exactly one line on stderr, and no output folder (nor a staging folder);
  * exit 0 with finite results: every number in summary.json / findings.json finite (null only
    where docs/scenario.md allows it), every required column of timeseries.csv finite.
A crash, a hang (timeout), exit 1, several lines, or a non-finite result fails the case; the
report names the seed and shows the mutated input, and `fuzz.py MODE --seed S --cases 1 --keep`
reproduces it.
"""
import argparse
import concurrent.futures
import copy
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile

import yaml

# summary.json keys that may be null (metrics over an empty window, docs/scenario.md).
NULLABLE_SUMMARY = {
    "velocity_error_max_abs_after_first_mps",
    "position_error_max_abs_settled_m",
    "position_error_rms_settled_m",
    "velocity_error_max_abs_settled_mps",
    # move metrics: null for a reference that is no move, a move not finished or not settled
    "move_finished", "move_start_s", "move_end_s", "move_distance_m", "rise_time_s", "overshoot_m", "overshoot_percent",
    "settling_band_m", "settling_time_s", "settle_after_move_s", "position_error_max_abs_during_move_m",
    "position_error_rms_during_move_m", "position_error_max_abs_after_move_m",
    "controller_model",  # open_loop has no model
    # the plant's CVODE counts are null where it ran in another process (a log, the monitor)
    "integrator_steps", "integrator_rhs_evals", "integrator_jac_evals", "integrator_error_test_fails",
    # control-signal quality: no step-to-step change in a run of one step; nothing above 1 kHz
    # is representable at a control period of 0.5 ms or more
    "control_step_rms_V", "force_hf_rms_N",
}
# timeseries.csv columns that must be finite in every row (the diagnostic columns
# u_unsaturated, sliding, z_estimate are NaN where a controller has none).
FINITE_COLUMNS = ["t", "xd", "vd", "ad", "jd", "x", "x_measured", "v", "v_measured", "z", "fg", "i", "u",
                  "f_thrust", "f_friction", "f_ripple", "f_grinding"]

EXTREME = [0, -1, 1, 1e308, -1e308, 1e-308, 5e-324, 1e30, -1e30, 1e-30, 1e6, -1e6, 1e-12,
           float("nan"), float("inf"), float("-inf"), 2**63, -2**63, 2**64, 3, 0.5, "", "abc", "1e", "0x10",
           True, False, None, [], {}, [1, 2], {"a": 1}, "1e308", "-0", "1_000", "\u00e4"]
FACTORS = [1e-12, 1e-6, 1e-3, 0.1, -1, 10, 1e3, 1e6, 1e12]
NAMES = ["x'; system 'touch MARK'; print '", "`touch MARK`", "a" * 300, "a\tb", "\u00e4\u00f6\u00fc \u2014 ok",
         "@x $y {z}", "line\nbreak", "\\", "\"", "'"]


def fail_report(mode, seed, what, data, rc, out, err):
    text = data if isinstance(data, str) else repr(data[:3000])
    return (f"FAIL {mode} seed {seed}: {what}\n  exit {rc}\n  stderr: {err[:1500]!r}\n  stdout: {out[-500:]!r}\n"
            f"  input:\n{text[:4000]}\n  reproduce: tests/fuzz/fuzz.py {mode} --seed {seed} --cases 1 --keep ...")


def leaves(node, path=()):
    if isinstance(node, dict):
        if not node:
            yield path
        for k, v in node.items():
            yield from leaves(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from leaves(v, path + (i,))
    else:
        yield path


def get(node, path):
    for p in path:
        node = node[p]
    return node


def put(node, path, value):
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value


def dump(doc):
    return yaml.safe_dump(doc, sort_keys=False, allow_unicode=True, width=10**9)


# ---------------------------------------------------------------- scenario mutations
def mutate_scenario(rng, text, case_dir):
    """Returns (mutated text, True if the mutation chose duration/control_period itself)."""
    doc = yaml.safe_load(text)
    op = rng.choice(["leaf"] * 6 + ["factor"] * 4 + ["delete", "add", "switch", "switch", "waypoints", "name",
                     "effect", "text", "text", "text"])
    timing = False
    if op in ("leaf", "factor", "delete"):
        paths = [p for p in leaves(doc) if p]
        path = rng.choice(paths)
        timing = path[0] in ("duration", "control_period")
        if op == "leaf":
            put(doc, path, copy.deepcopy(rng.choice(EXTREME)))
        elif op == "factor":
            v = get(doc, path)
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                put(doc, path, v * rng.choice(FACTORS))
            else:
                put(doc, path, copy.deepcopy(rng.choice(EXTREME)))
        else:
            parent = get(doc, path[:-1])
            del parent[path[-1]]
    elif op == "add":
        target = doc
        for k in rng.choice([(), ("plant",), ("controller",), ("reference",), ("plant", "friction"), ("analysis",)]):
            target = target.setdefault(k, {}) if isinstance(target, dict) else target
        if isinstance(target, dict):
            target[rng.choice(["extra", "mas", "duration", "eta", "settled_after", "type"])] = rng.choice(EXTREME)
    elif op == "switch":
        which = rng.choice(["controller", "reference", "kind"])
        if which == "controller":
            doc["controller"] = {"type": rng.choice(["sliding_mode", "cascade", "open_loop", "pid"])}
        elif which == "reference":
            doc["reference"] = {"type": rng.choice(["none", "sine", "step", "accel_limited", "scurve", "ramp"])}
            if rng.random() < 0.5:
                key = rng.choice(["amplitude", "frequency", "distance", "max_velocity", "max_acceleration", "max_jerk",
                                  "velocity", "start_time", "step_time"])
                doc["reference"][key] = rng.choice(EXTREME)
        else:
            doc["controller"] = {"type": "open_loop", "kind": rng.choice(["sine", "step", "ramp", "constant", "file"]),
                                 rng.choice(["amplitude", "frequency", "rate", "offset", "start_time", "phase"]):
                                     rng.choice(EXTREME + [1e308, 1e308])}
    elif op == "waypoints":
        n = rng.randint(0, 6)
        t = sorted(rng.uniform(0, 0.1) for _ in range(n))
        rows = ["t,x"] + [f"{ti!r},{rng.choice([0.0, 0.01, 1e308, -1e308, 1e-300, 5.0, float('nan')])!r}" for ti in t]
        if rng.random() < 0.3 and rows[1:]:
            rows[rng.randrange(1, len(rows))] = rng.choice(["", "x,y", "1;2", "0.1", "\xff\xfe"])
        with open(os.path.join(case_dir, "wp.csv"), "w", encoding="utf-8", errors="surrogateescape") as f:
            f.write("\n".join(rows) + "\n")
        doc["reference"] = {"type": "waypoints", "file": "wp.csv"}
    elif op == "name":
        doc["name"] = rng.choice(NAMES)
    elif op == "effect":
        from_effects = {"constant_force": {"force": 1.0}, "coulomb_friction": {"coulomb_force": 5.0},
                        "viscous_friction": {"viscous": 10.0}, "presliding": {"bristle_stiffness": 1e6},
                        "cogging_ripple": {"pitch": 0.024, "cogging_amplitude": 2.0}, "spring_force": {"stiffness": 100.0},
                        "mass_error": {"mass": 90.0}, "input_delay": {"delay": 2e-4},
                        "grinding_force": {"damping": 100.0, "stiffness": 1e5}}
        name = rng.choice(sorted(from_effects))
        params = dict(from_effects[name])
        key = rng.choice(sorted(params))
        if rng.random() < 0.7:
            params[key] = rng.choice(EXTREME)
        doc.setdefault("plant", {}).setdefault("effects", {})[name] = params
    if op == "text":
        out = text
    else:
        out = dump(doc)
    # Raw-text damage on top (always for "text", sometimes for the others).
    if op == "text" or rng.random() < 0.1:
        data = bytearray(out.encode("utf-8"))
        for _ in range(rng.randint(1, 3)):
            kind = rng.choice(["flip", "cut", "dupline", "delline", "insert", "truncate"])
            if not data:
                break
            i = rng.randrange(len(data))
            if kind == "flip":
                data[i] ^= 1 << rng.randrange(8)
            elif kind == "cut":
                del data[i:i + rng.randint(1, 20)]
            elif kind == "insert":
                data[i:i] = rng.choice([b'"', b"'", b":", b"\t", b"{", b"[", b"- ", b"\n", b"&a ", b"*a", b"\x00", b"#"])
            elif kind == "truncate":
                del data[i:]
            else:
                lines = data.split(b"\n")
                j = rng.randrange(len(lines))
                if kind == "dupline":
                    lines.insert(j, lines[j])
                else:
                    del lines[j]
                data = bytearray(b"\n".join(lines))
        out = bytes(data).decode("utf-8", errors="surrogateescape")
        timing = True  # the text may now say anything about duration
    return out, timing


def cap_duration(text, timing):
    """Keeps a case short: duration <= 0.05 s and <= 2000 control periods, where the mutation
    left duration and control_period as numbers and did not aim at them."""
    try:
        doc = yaml.safe_load(text)
    except Exception:
        return text
    if not isinstance(doc, dict):
        return text
    def number(v):  # PyYAML (YAML 1.1) reads 1e-4 as a string; feeddrive reads it as a number
        if isinstance(v, bool):
            return None
        try:
            f = float(v)
        except (TypeError, ValueError):
            return None
        return f if math.isfinite(f) else None
    d, cp = number(doc.get("duration")), number(doc.get("control_period"))
    if d is None or cp is None or cp <= 0 or d <= 0:
        return text
    cap = min(0.05, 2000 * cp)
    if timing:
        # The mutation chose the timing: keep it, unless it asks for a run of more than 2e4
        # steps (a case must stay short; the run-size limit has its own tests).
        if d / cp <= 2e4:
            return text
        cap = 2e4 * cp
    if d <= cap:
        return text
    doc["duration"] = cap
    return dump(doc)


# ---------------------------------------------------------------- result checks
def check_json_finite(path, nullable=()):
    with open(path, encoding="utf-8") as f:
        j = json.load(f)
    bad = []

    def walk(v, key):
        if isinstance(v, dict):
            for k, x in v.items():
                walk(x, k)
        elif isinstance(v, list):
            for x in v:
                walk(x, key)
        elif v is None:
            if key not in nullable:
                bad.append(f"{key} is null")
        elif isinstance(v, float) and not math.isfinite(v):
            bad.append(f"{key} = {v}")
    walk(j, "")
    return j, bad


def check_timeseries(path):
    with open(path, encoding="utf-8") as f:
        header = f.readline().strip().split(",")
        cols = [header.index(c) for c in FINITE_COLUMNS if c in header]
        for n, line in enumerate(f, start=2):
            cells = line.rstrip("\n").split(",")
            for c in cols:
                v = float(cells[c])
                if not math.isfinite(v):
                    return f"timeseries.csv line {n}: {header[c]} = {cells[c]}"
    return None


def judge(case_dir, out_dir, rc, err, results):
    """None if the case passed, else why it failed."""
    lines = err.splitlines()
    partial = [p for p in os.listdir(case_dir) if ".partial-" in p]
    if partial:
        return f"a staging folder remains: {partial}"
    if rc == 2:
        if len(lines) != 1:
            return f"exit 2 with {len(lines)} lines on stderr (expected 1)"
        if os.path.exists(out_dir):
            return "exit 2 but an output folder was created"
        return None
    if rc not in (0, 3):  # 3: feeddrive-fit's "unexplained discrepancy" verdict (docs/fit.md)
        return f"exit {rc} (expected 0, 2 or 3)"
    return results()


def run(cmd, cwd, timeout):
    try:
        p = subprocess.run(cmd, cwd=cwd, capture_output=True, timeout=timeout)
        return p.returncode, p.stdout.decode("utf-8", "replace"), p.stderr.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        return None, "", "(timeout)"


# ---------------------------------------------------------------- modes
def case_scenario(args, seed, base):
    rng = random.Random(seed)
    name = rng.choice(sorted(base))
    case_dir = tempfile.mkdtemp(prefix=f"fuzz-{seed}-", dir=args.work)
    text, timing = mutate_scenario(rng, base[name], case_dir)
    text = cap_duration(text, timing)
    path = os.path.join(case_dir, "s.yaml")
    with open(path, "w", encoding="utf-8", errors="surrogateescape") as f:
        f.write(text)
    out_dir = os.path.join(case_dir, "out")
    plots = rng.random() < 0.05
    cmd = [os.path.join(args.bin, "feeddrive-sim"), path, "--out", out_dir, "-q"] + ([] if plots else ["--no-plots"])
    rc, out, err = run(cmd, case_dir, args.timeout)

    def results():
        summary, bad = check_json_finite(os.path.join(out_dir, "summary.json"), NULLABLE_SUMMARY)
        if summary.get("steps", 0) > 0 and summary.get("position_error_max_abs_m") is None:
            bad.append("position_error_max_abs_m is null with steps > 0")
        ts = check_timeseries(os.path.join(out_dir, "timeseries.csv"))
        if ts:
            bad.append(ts)
        if os.path.exists(os.path.join(case_dir, "MARK")):
            bad.append("a name ran as a command")
        return "; ".join(bad) if bad else None

    why = "timeout (hang)" if rc is None else judge(case_dir, out_dir, rc, err, results)
    if why is None and not args.keep:
        shutil.rmtree(case_dir, ignore_errors=True)
    return None if why is None else fail_report("scenario", seed, why, f"(from {name})\n" + text, rc, out, err)


def mutate_bytes(rng, data, ops, structured=None):
    data = bytearray(data)
    for _ in range(rng.randint(1, 3)):
        op = rng.choice(ops)
        if structured and op in structured:
            data = structured[op](rng, data)
            continue
        if not data:
            break
        i = rng.randrange(len(data))
        if op == "flip":
            data[i] ^= 1 << rng.randrange(8)
        elif op == "truncate":
            del data[i:]
    return bytes(data)


def csv_ops():
    def lines_op(f):
        def g(rng, data):
            lines = bytes(data).split(b"\n")
            return bytearray(b"\n".join(f(rng, lines)))
        return g

    def delete_rows(rng, lines):
        i = rng.randrange(1, max(2, len(lines) - 1))
        del lines[i:i + rng.choice([1, 1, 5, 100])]
        return lines

    def dup_row(rng, lines):
        i = rng.randrange(1, max(2, len(lines) - 1))
        lines.insert(i, lines[i])
        return lines

    def swap_rows(rng, lines):
        i = rng.randrange(1, max(2, len(lines) - 2))
        lines[i], lines[i + 1] = lines[i + 1], lines[i]
        return lines

    def bad_cell(rng, lines):
        i = rng.randrange(1, max(2, len(lines) - 1))
        cells = lines[i].split(b",")
        if cells and cells != [b""]:
            cells[rng.randrange(len(cells))] = rng.choice([b"nan", b"inf", b"-inf", b"1e308", b"-1e308", b"", b"x",
                                                           b"1e-320", b"0x1p3", b"1,5"])
        lines[i] = b",".join(cells)
        return lines

    def epoch(rng, lines):
        off = rng.choice([1.7e9, 1e9, 1e6, -1e9, 1e15])
        out = [lines[0]]
        for l in lines[1:]:
            cells = l.split(b",")
            if len(cells) > 1:
                try:
                    cells[0] = repr(float(cells[0]) + off).encode()
                except ValueError:
                    pass
            out.append(b",".join(cells))
        return out

    def scale_time(rng, lines):
        k = rng.choice([1e-6, 1e-3, 1e3, 1e6, -1])
        out = [lines[0]]
        for l in lines[1:]:
            cells = l.split(b",")
            if len(cells) > 1:
                cells[0] = repr(float(cells[0]) * k).encode()
            out.append(b",".join(cells))
        return out

    def header(rng, lines):
        lines[0] = rng.choice([b"t,x", b"t,x,x", b"t;x;u", b"time,x,u", b"t,x,force_N", b"\xef\xbb\xbft,x,u",
                               b"t,x,u,xd", b"t,u,x", b"t,,u", b""])
        return lines

    def constant(rng, lines):
        col = rng.choice([1, 2])
        out = [lines[0]]
        for l in lines[1:]:
            cells = l.split(b",")
            if len(cells) > col:
                cells[col] = b"0"
            out.append(b",".join(cells))
        return out

    def crlf(rng, lines):
        return [l + b"\r" for l in lines]

    def short(rng, lines):
        return lines[:rng.choice([2, 10, 49, 51, 60])]

    structured = {n: lines_op(f) for n, f in [("delete_rows", delete_rows), ("dup_row", dup_row), ("swap_rows", swap_rows),
                                              ("bad_cell", bad_cell), ("epoch", epoch), ("scale_time", scale_time),
                                              ("header", header), ("constant", constant), ("crlf", crlf), ("short", short)]}
    ops = ["flip", "truncate"] + list(structured) + ["epoch", "delete_rows", "bad_cell"]
    return ops, structured


def fit_results(case_dir, out_dir):
    def results():
        # A candidate the fit could not score (not eligible, not fitted) has "score": null in its
        # ranking (fit/src/report.cpp); every other number is finite.
        _, bad = check_json_finite(os.path.join(out_dir, "findings.json"), {"score"})
        return "; ".join(bad[:5]) if bad else None
    return results


def case_csv(args, seed, base):
    rng = random.Random(seed)
    ops, structured = csv_ops()
    data = mutate_bytes(rng, base["csv"], ops, structured)
    case_dir = tempfile.mkdtemp(prefix=f"fuzz-{seed}-", dir=args.work)
    path = os.path.join(case_dir, "d.csv")
    with open(path, "wb") as f:
        f.write(data)
    out_dir = os.path.join(case_dir, "out")
    cmd = [os.path.join(args.bin, "feeddrive-fit"), "-s", base["model"], "-d", path, "--out", out_dir, "-q", "--no-plots",
           "--max-effects", "1"]
    rc, out, err = run(cmd, case_dir, args.timeout)
    why = "timeout (hang)" if rc is None else judge(case_dir, out_dir, rc, err, fit_results(case_dir, out_dir))
    if why is None and not args.keep:
        shutil.rmtree(case_dir, ignore_errors=True)
    shown = data.decode("utf-8", "replace")
    if len(shown) > 3000:
        shown = shown[:1500] + "\n...\n" + shown[-1500:]
    return None if why is None else fail_report("csv", seed, why, shown, rc, out, err)


def lcm_events(data):
    """(offset, header+channel length, total length) of each event of an LCM log."""
    ev, i = [], 0
    while i + 28 <= len(data):
        clen = int.from_bytes(data[i + 20:i + 24], "big")
        dlen = int.from_bytes(data[i + 24:i + 28], "big")
        ev.append((i, 28 + clen, 28 + clen + dlen))
        i += 28 + clen + dlen
    return ev


def lcm_ops(events):
    def pick(rng):
        return events[rng.randrange(len(events))]

    def flip_header(rng, data):
        off, _, _ = pick(rng)
        if off + 28 <= len(data):
            data[off + rng.randrange(28)] ^= 1 << rng.randrange(8)
        return data

    def flip_channel(rng, data):
        off, hc, _ = pick(rng)
        if off + hc <= len(data):
            data[off + 28 + rng.randrange(hc - 28)] ^= 1 << rng.randrange(8)
        return data

    def flip_seq(rng, data):
        # Every message of ours starts with the 8-byte fingerprint, the int64 run_id, the int64 seq.
        off, hc, tot = pick(rng)
        if off + hc + 24 <= len(data):
            data[off + hc + 16 + rng.randrange(8)] ^= 1 << rng.randrange(8)
        return data

    def flip_payload(rng, data):
        off, hc, tot = pick(rng)
        if off + tot <= len(data) and tot > hc:
            data[off + hc + rng.randrange(tot - hc)] ^= 1 << rng.randrange(8)
        return data

    def drop_event(rng, data):
        off, _, tot = pick(rng)
        del data[off:off + tot]
        return data

    def dup_event(rng, data):
        off, _, tot = pick(rng)
        data[off:off] = data[off:off + tot]
        return data

    def truncate_boundary(rng, data):
        off, _, _ = pick(rng)
        del data[off:]
        return data

    structured = {"flip_header": flip_header, "flip_channel": flip_channel, "flip_seq": flip_seq,
                  "flip_payload": flip_payload, "drop_event": drop_event, "dup_event": dup_event,
                  "truncate_boundary": truncate_boundary}
    ops = ["flip", "truncate"] + list(structured) + ["drop_event", "flip_channel", "flip_seq"]
    return ops, structured


def case_lcm(args, seed, base):
    rng = random.Random(seed)
    ops, structured = lcm_ops(base["events"])
    data = bytes(base["log"])
    # Structured mutations use the original event offsets: apply them first, then raw ones.
    mutated = bytearray(data)
    chosen = [rng.choice(ops) for _ in range(rng.randint(1, 2))]
    for op in sorted(chosen, key=lambda o: o in ("flip", "truncate", "drop_event", "dup_event", "truncate_boundary")):
        if op in structured:
            mutated = structured[op](rng, mutated)
        elif mutated:
            i = rng.randrange(len(mutated))
            if op == "flip":
                mutated[i] ^= 1 << rng.randrange(8)
            else:
                del mutated[i:]
    case_dir = tempfile.mkdtemp(prefix=f"fuzz-{seed}-", dir=args.work)
    path = os.path.join(case_dir, "run.lcmlog")
    with open(path, "wb") as f:
        f.write(mutated)
    fails = []
    tool = rng.choice(["log2csv", "fit"])
    out_dir = os.path.join(case_dir, "out")
    if tool == "log2csv":
        cmd = [os.path.join(args.bin, "feeddrive-log2csv"), path, "--scenario", base["scenario"], "--out", out_dir, "-q"]

        def results():
            _, bad = check_json_finite(os.path.join(out_dir, "summary.json"), NULLABLE_SUMMARY)
            ts = check_timeseries(os.path.join(out_dir, "timeseries.csv"))
            return "; ".join(bad + ([ts] if ts else [])) or None
    else:
        cmd = [os.path.join(args.bin, "feeddrive-fit"), "-s", base["scenario"], "-d", path, "--out", out_dir, "-q",
               "--no-plots", "--max-effects", "1"]
        results = fit_results(case_dir, out_dir)
    rc, out, err = run(cmd, case_dir, args.timeout)
    why = "timeout (hang)" if rc is None else judge(case_dir, out_dir, rc, err, results)
    if why is None and not args.keep:
        shutil.rmtree(case_dir, ignore_errors=True)
    desc = f"{tool}: ops {chosen}; {len(mutated)} of {len(data)} bytes; first difference at byte " + str(
        next((i for i in range(min(len(data), len(mutated))) if data[i] != mutated[i]), min(len(data), len(mutated))))
    return None if why is None else fail_report("lcm", seed, why, desc, rc, out, err)


# ---------------------------------------------------------------- YAML constructs (issue 19, point 8)
def containers(node, path=()):
    """(path, node) of every map and list of the tree, the root first."""
    if isinstance(node, (dict, list)):
        yield path, node
        items = node.items() if isinstance(node, dict) else enumerate(node)
        for k, v in items:
            yield from containers(v, path + (k,))


def mutate_yaml(rng, text):
    """Returns (mutated text, the construct the tools must name, or None if none is refused)."""
    doc = yaml.safe_load(text)
    kind = rng.choice(["recursive", "recursive", "merge", "merge", "shared"])
    spots = list(containers(doc))
    path, node = rng.choice(spots)
    if kind == "recursive":
        # The node itself or one of its ancestors, held inside it: PyYAML writes &id001 ... *id001.
        ancestor = get(doc, path[:rng.randint(0, len(path))])
        if isinstance(node, dict):
            node[rng.choice(["inner", "extra", "model"])] = ancestor
        else:
            node.insert(rng.randint(0, len(node)), ancestor)
        want = "recursive YAML alias"
    elif kind == "merge":
        maps = [n for _, n in spots if isinstance(n, dict)]
        target = rng.choice(maps)
        source = copy.deepcopy(rng.choice(maps))
        value = source if rng.random() < 0.7 else [source, {"extra": 1}]
        target[MERGE] = value
        want = "merge key"
    else:
        other_path, other = rng.choice(spots)
        if rng.random() < 0.2:
            other, other_path = copy.deepcopy(other), None  # a copy: no alias at all
        if isinstance(node, dict):
            node[rng.choice(["extra", "shared"])] = other
        else:
            node.append(other)
        # `other` may be an ancestor of `node`: then the alias is recursive after all.
        want = "recursive YAML alias" if other_path is not None and other_path == path[:len(other_path)] else None
    out = yaml.dump(doc, Dumper=MergeDumper, sort_keys=False, allow_unicode=True, width=10**9)
    return out, want


class MergeKey(str):
    """A key written as a plain << (PyYAML quotes a str '<<', which is an ordinary key)."""


MERGE = MergeKey("<<")


class MergeDumper(yaml.SafeDumper):
    pass


MergeDumper.add_representer(MergeKey, lambda d, v: yaml.ScalarNode("tag:yaml.org,2002:merge", "<<", style=None))
MergeDumper.add_implicit_resolver("tag:yaml.org,2002:merge", __import__("re").compile(r"^(?:<<)$"), ["<"])


def case_yaml(args, seed, base):
    rng = random.Random(seed)
    name = rng.choice(sorted(base["scenarios"]))
    case_dir = tempfile.mkdtemp(prefix=f"fuzz-{seed}-", dir=args.work)
    text, want = mutate_yaml(rng, base["scenarios"][name])
    path = os.path.join(case_dir, "s.yaml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
    tools = ["sim", "study_file", "study_inline"] + (["fit"] if want else [])  # the fit runs only to refuse
    why = None
    for tool in tools:
        out_dir = os.path.join(case_dir, "out-" + tool)
        if tool == "sim":
            cmd = [os.path.join(args.bin, "feeddrive-sim"), path, "--out", out_dir, "-q", "--no-plots"]
        elif tool == "fit":
            cmd = [os.path.join(args.bin, "feeddrive-fit"), "-s", path, "-d", base["csv"], "--out", out_dir, "-q",
                   "--no-plots", "--max-effects", "1"]
        else:
            study = os.path.join(case_dir, tool + ".yaml")
            with open(study, "w", encoding="utf-8") as f:
                if tool == "study_file":
                    f.write("name: fuzz\nbase: s.yaml\nset: {duration: 0.01}\n")
                else:  # the scenario text indented under base: (its anchors and aliases inside the study)
                    f.write("name: fuzz\nset: {duration: 0.01}\nbase:\n" + "".join("  " + l + "\n" for l in text.splitlines()))
            cmd = [os.path.join(args.bin, "feeddrive-study"), study, "--out", out_dir, "-q", "--no-plots", "-j", "1"]
        rc, out, err = run(cmd, case_dir, args.timeout)
        if rc is None:
            why = f"{tool}: timeout (hang)"
        elif want:
            if rc != 2 or len(err.splitlines()) != 1 or want not in err:
                why = f"{tool}: expected exit 2 and one line naming the {want!r}"
            elif os.path.exists(out_dir):
                why = f"{tool}: exit 2 but an output folder was created"
        else:
            why = judge(case_dir, out_dir, rc, err, lambda: None)
            why = why and f"{tool}: {why}"
        if why:
            why += f"\n  command: {' '.join(cmd)}"
            break
    if why is None and not args.keep:
        shutil.rmtree(case_dir, ignore_errors=True)
    return None if why is None else fail_report("yaml", seed, why, f"(from {name}, expected: {want})\n" + text, rc, out, err)


def make_fit_base(args):
    """A short record of the docs/fit.md "real drive" (truth_cogging.yaml, 1.5 s) as CSV t,x,u."""
    d = tempfile.mkdtemp(prefix="fuzz-base-", dir=args.work)
    shutil.copy(os.path.join(args.src, "scenarios/fit/rich_reference.csv"), d)
    with open(os.path.join(args.src, "scenarios/fit/truth_cogging.yaml"), encoding="utf-8") as f:
        doc = yaml.safe_load(f)
    doc["duration"] = 1.5
    with open(os.path.join(d, "truth.yaml"), "w", encoding="utf-8") as f:
        f.write(dump(doc))
    subprocess.run([os.path.join(args.bin, "feeddrive-sim"), "truth.yaml", "--out", "rec", "--no-plots", "-q"], cwd=d, check=True)
    rows = []
    with open(os.path.join(d, "rec/timeseries.csv"), encoding="utf-8") as f:
        h = f.readline().strip().split(",")
        it, ix, iu = h.index("t"), h.index("x_measured"), h.index("u")
        for line in f:
            c = line.strip().split(",")
            rows.append(f"{c[it]},{c[ix]},{c[iu]}")
    model = os.path.join(d, "model.yaml")
    with open(os.path.join(args.src, "scenarios/fit/model.yaml"), encoding="utf-8") as f:
        m = yaml.safe_load(f)
    m["reference"]["file"] = os.path.join(d, "rich_reference.csv")
    with open(model, "w", encoding="utf-8") as f:
        f.write(dump(m))
    return {"csv": ("t,x,u\n" + "\n".join(rows) + "\n").encode(), "model": model}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mode", choices=["scenario", "csv", "lcm", "yaml"])
    ap.add_argument("--src", required=True, help="source folder")
    ap.add_argument("--bin", required=True, help="folder of the feeddrive executables")
    ap.add_argument("--seed", type=int, default=1, help="first seed")
    ap.add_argument("--cases", type=int, default=100)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per case before it counts as a hang")
    ap.add_argument("--log", help="lcm mode: the lcm-logger log to mutate")
    ap.add_argument("--scenario", help="lcm mode: the scenario of the logged run (also the fit's model)")
    ap.add_argument("--keep", action="store_true", help="keep every case's folder")
    ap.add_argument("--work", default=None, help="scratch folder (default: a new temporary one)")
    args = ap.parse_args()
    own_work = args.work is None
    args.work = args.work or tempfile.mkdtemp(prefix="feeddrive-fuzz-")
    os.makedirs(args.work, exist_ok=True)
    if args.mode == "scenario":
        folder = os.path.join(args.src, "scenarios/paper")
        base = {n: open(os.path.join(folder, n), encoding="utf-8").read() for n in os.listdir(folder) if n.endswith(".yaml")}
        fn = case_scenario
    elif args.mode == "csv":
        base = make_fit_base(args)
        fn = case_csv
    elif args.mode == "yaml":
        folder = os.path.join(args.src, "scenarios/paper")
        scenarios = {n: open(os.path.join(folder, n), encoding="utf-8").read() for n in os.listdir(folder) if n.endswith(".yaml")}
        csv = os.path.join(args.work, "d.csv")  # read only if the fit got past the scenario (it must not)
        with open(csv, "w", encoding="utf-8") as f:
            f.write("t,x,u\n" + "".join(f"{i * 1e-3!r},0.0,0.0\n" for i in range(100)))
        base = {"scenarios": scenarios, "csv": csv}
        fn = case_yaml
    else:
        data = open(args.log, "rb").read()
        base = {"log": data, "events": lcm_events(data), "scenario": args.scenario}
        fn = case_lcm
    seeds = range(args.seed, args.seed + args.cases)
    failures = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for r in pool.map(lambda s: fn(args, s, base), seeds):
            if r:
                failures.append(r)
                print(r, flush=True)
    print(f"{args.mode}: {len(seeds) - len(failures)} of {len(seeds)} cases passed (seeds {args.seed}..{args.seed + args.cases - 1})")
    if own_work and not args.keep and not failures:
        shutil.rmtree(args.work, ignore_errors=True)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
