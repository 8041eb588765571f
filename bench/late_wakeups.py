#!/usr/bin/env python3
"""Who delays the plant: reads `perf sched timehist` output (one CPU) and prints, for the window
from the plant's first to its last switch, each task's share of the CPU and, for every wake-up of
the plant (and of the controller) that waited longer than THRESHOLD_US to run ("sch delay"), the
task that ran just before it. On a kernel without full preemption (preempt=none or voluntary) a lower-priority task
inside a system call keeps the CPU until the call returns, so this list names the tasks whose
kernel work delays a SCHED_FIFO plant. Used by bench/realtime_trace.sh.
  late_wakeups.py TIMEHIST_FILE [THRESHOLD_US] [PLANT_COMM]
"""
import collections
import re
import sys


def rows_of(path):
    pat = re.compile(r"\s*([\d.]+)\s+\[(\d+)\]\s+(.+?)\[([\d/]+)\]\s+([\d.]+)\s+([\d.]+)\s+([\d.]+)")
    out = []
    with open(path) as f:
        for line in f:
            m = pat.match(line)
            if m:  # time [s], task, wait [ms], sch delay [ms], run [ms]
                out.append((float(m[1]), m[3].strip(), float(m[5]), float(m[6]), float(m[7])))
    return out


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: late_wakeups.py TIMEHIST_FILE [THRESHOLD_US] [PLANT_COMM]")
    threshold_ms = (float(sys.argv[2]) if len(sys.argv) > 2 else 20.0) / 1000.0
    plant = sys.argv[3] if len(sys.argv) > 3 else "feeddrive-plant"
    rows = rows_of(sys.argv[1])
    idx = [i for i, r in enumerate(rows) if r[1].startswith(plant)]
    if not idx:
        print(f"error: no switch of {plant} in {sys.argv[1]}: was the run on the traced CPU?", file=sys.stderr)
        sys.exit(2)
    win = rows[idx[0] : idx[-1] + 1]
    span = win[-1][0] - win[0][0]
    share = collections.Counter()
    for r in win:
        share[r[1]] += r[4]
    print(f"window: {span:.2f} s from the plant's first to its last switch")
    for task, ms in share.most_common(8):
        print(f"  {task:<24} {ms:8.0f} ms  {100.0 * ms / 1000.0 / span:5.1f} % of the CPU")
    for who in (plant, "feeddrive-contr"):
        before = collections.Counter()
        late = 0
        for i, r in enumerate(win):
            if i > 0 and r[1].startswith(who) and r[3] > threshold_ms:
                late += 1
                before[win[i - 1][1]] += 1
        print(f"{who} wake-ups that waited > {threshold_ms * 1000:.0f} us to run: {late}; the task that ran before:")
        for task, n in before.most_common(6):
            print(f"  {task:<24} {n}")


if __name__ == "__main__":
    main()
