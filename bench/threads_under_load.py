#!/usr/bin/env python3
"""Is pneumo ever slower with more threads? `pneumo run` on one scene with --threads 1, with
--threads N (every core) and with neither (each stage on the cores other processes leave free,
core/thread_count.h), first on the machine as it is, then beside processes that each keep one core
busy. Stage by stage from each run's metrics.json: medians with min and max over the repetitions.

    python3 bench/threads_under_load.py [--pneumo build/pneumo] [--scene scenes/totalseg_example.json]
        [--repeats 3] [--busy 1] [--out bench/results/threads.md]

Nothing here is a pass/fail: the figures go to the Markdown file (and stdout).
"""
import argparse
import json
import multiprocessing
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

STAGES = ["roles", "mesh", "solve", "warp", "render", "total"]


def spin():
    while True:
        pass


def one_run(pneumo, scene, threads, out):
    cmd = [pneumo, "-q"] + (["--threads", str(threads)] if threads else []) + ["run", scene, "--force", "--out", out]
    env = dict(os.environ)
    env.pop("OMP_NUM_THREADS", None)   # the default must see no fixed count
    start = time.monotonic()
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
    wall = time.monotonic() - start
    with open(os.path.join(out, "metrics.json")) as f:
        stages = json.load(f)["stage_seconds"]
    return dict(stages, wall=wall)


def summary(values):
    return f"{statistics.median(values):.2f} ({min(values):.2f}–{max(values):.2f})"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pneumo", default="build/pneumo")
    ap.add_argument("--scene", default="scenes/totalseg_example.json")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--busy", type=int, default=1, help="busy processes in the second half")
    ap.add_argument("--out", help="Markdown file to write")
    a = ap.parse_args()
    cores = len(os.sched_getaffinity(0))
    settings = [("--threads 1", 1), (f"--threads {cores}", cores), ("default (fitted to the load)", 0)]
    work = tempfile.mkdtemp(prefix="pneumo_threads_")
    rows = []
    try:
        for busy in (0, a.busy):
            spinners = [multiprocessing.Process(target=spin, daemon=True) for _ in range(busy)]
            for p in spinners:
                p.start()
            time.sleep(1.0)
            load = os.getloadavg()
            # Rounds, each setting once per round, so a drift of the machine spreads over all of them.
            runs = {name: [] for name, _ in settings}
            for r in range(a.repeats + 1):
                for name, threads in settings:
                    result = one_run(a.pneumo, a.scene, threads, os.path.join(work, "run"))
                    if r > 0:   # the first round warms the page cache
                        runs[name].append(result)
            for p in spinners:
                p.terminate()
            for name, _ in settings:
                rows.append((busy, load, name, {s: summary([x[s] for x in runs[name]]) for s in STAGES + ["wall"]}))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    lines = [f"`pneumo run {a.scene}`, {a.repeats} rounds after a warm-up round, {cores} usable cores; "
             "seconds, median (min–max); stages from metrics.json, wall = the whole process.", "",
             "| busy processes | load at start (1 min) | threads | " + " | ".join(STAGES + ["wall"]) + " |",
             "|---|---|---|" + "---|" * (len(STAGES) + 1)]
    for busy, load, name, cells in rows:
        lines.append(f"| {busy} | {load[0]:.2f} | {name} | " + " | ".join(cells[s] for s in STAGES + ["wall"]) + " |")
    text = "\n".join(lines) + "\n"
    sys.stdout.write(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
