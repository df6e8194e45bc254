#!/usr/bin/env python3
"""A scene's step on 1 and 2 threads and on 2 ranks, from whole-process windows.

    python3 qdem-bench/scripts/step_windows.py fixtures/ballast/paper_load.toml \\
        --steps 100,500 [--rounds 2] [--qdem target/release/qdem] [--configs t1,t2,r2]

Each window is `qdem run SCENE --out TMP --stop-after N --yes` timed as a whole process
(reading the scene and its start_from checkpoint, N steps, the final checkpoint); the step is
the difference of the two windows' wall times over the difference of their step counts, so
the set-up and the checkpoint cancel. `qdem check` times its first 20 steps, which at a
lattice start or a kind change build the contact lists (and on ranks it times steps 21-40):
a window of hundreds of steps is the step a run takes. Configurations: t1 and t2 (one
process, --threads 1 and 2) and r2 (`mpirun -np 2 ... --threads 1`, a binary built with
`--features mpi`). The rounds alternate the configurations so that a drift of the machine
falls on all of them. Prints JSON: each window's seconds, each round's step per
configuration, their medians and the speed-ups over t1.
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time

from mpi_scaling import MPI_ENV, qdem_run_command

# Configurations: (ranks, threads).
CONFIGS = {"t1": (1, 1), "t2": (1, 2), "r2": (2, 1)}


def window(qdem, scene, config, steps):
    """Wall seconds of one `qdem run` stopped after `steps` steps."""
    out = tempfile.mkdtemp(prefix="qdem-window-")
    ranks, threads = CONFIGS[config]
    cmd = qdem_run_command(qdem, scene, ranks, threads, out,
                           ["--stop-after", str(steps), "--yes"])
    start = time.perf_counter()
    done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          env={**os.environ, **MPI_ENV})
    seconds = time.perf_counter() - start
    shutil.rmtree(out, ignore_errors=True)
    # --stop-after ends as Ctrl-C does: exit status 130 with the checkpoint written.
    if done.returncode not in (0, 130):
        raise SystemExit(f"{' '.join(cmd)} failed ({done.returncode}): {done.stderr.decode()[-400:]}")
    return seconds


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scene")
    p.add_argument("--steps", default="100,500", help="the two windows' step counts")
    p.add_argument("--rounds", type=int, default=2)
    p.add_argument("--qdem", default="target/release/qdem")
    p.add_argument("--configs", default="t1,t2,r2")
    a = p.parse_args()
    short, long = (int(n) for n in a.steps.split(","))
    configs = a.configs.split(",")
    rounds = []
    for _ in range(a.rounds):
        row = {}
        for c in configs:
            t_short = window(a.qdem, a.scene, c, short)
            t_long = window(a.qdem, a.scene, c, long)
            row[c] = {"windows_s": [t_short, t_long], "step_s": (t_long - t_short) / (long - short)}
        rounds.append(row)
    median = {c: statistics.median(r[c]["step_s"] for r in rounds) for c in configs}
    out = {"scene": a.scene, "steps": [short, long], "rounds": rounds, "median_step_s": median}
    if "t1" in median:
        out["speed_up_over_t1"] = {c: median["t1"] / median[c] for c in configs}
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
