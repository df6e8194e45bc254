#!/usr/bin/env python3
"""What the VTU output of one time costs a granular run of 10^5 spheres (docs/paraview.md).

usage: python3 scripts/vtk_cost.py [--work out/vtk_cost] [--spheres 100000] [--steps 400]
                                   [--repeats 2]

1. `study packing --spheres N --settle 0.1` settles a packing of spheres in a box of walls
   (the packing of docs/BENCHMARKS.md's granular throughput, settled for 0.1 s);
2. the packing becomes a `[granular]` sample of one-sphere stones in a scene with the same
   material, law and walls;
3. that scene is run STEPS steps without VTU output and with a VTU time every STEPS/4 steps
   (five times: t = 0 and four more), REPEATS times each, on 2 threads;
4. prints the wall seconds of each run (`summary.json`'s `wall_seconds`, the stepping loop
   with its outputs), the seconds one VTU time adds, and the bytes of each file of a time.

Needs `cargo build --release -p qdem-cli -p qdem-bench` first (target/release/qdem, study).
"""

import argparse
import json
import os
import shutil
import subprocess
import sys


def scene(meta, steps, vtu_every, out):
    lo, hi = meta["box_min"], meta["box_max"]
    walls = "".join(
        "[[wall]]\npoint = %s\nnormal = %s\n\n" % (list(w["point"]), list(w["normal"]))
        for w in meta["walls"]
    )
    vtu = "vtu_every = %r\n" % vtu_every if vtu_every else ""
    return f"""# {meta['spheres']} settled spheres as one-sphere stones, {steps} steps (scripts/vtk_cost.py).
[run]
t_end = {steps * meta['dt']!r}
dt = "auto"
gravity = {list(meta['gravity'])}
probe_every = 1.0

[[material]]
name = "grains"
density = {meta['density']!r}
young = {meta['youngs_modulus']!r}
poisson = {meta['poisson_ratio']!r}

[contact]
law = "hertz-mindlin"
friction = {meta['friction']!r}
damping_ratio = {meta['damping_ratio']!r}

[granular]
name = "packing"
material = "grains"
sample = "stones.csv"

{walls}[output]
dir = "{out}"
{vtu}"""


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--work", default="out/vtk_cost")
    p.add_argument("--spheres", type=int, default=100000)
    p.add_argument("--steps", type=int, default=400)
    p.add_argument("--repeats", type=int, default=2)
    args = p.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(root, "target"))
    qdem, study = (os.path.join(target, "release", exe) for exe in ("qdem", "study"))
    os.makedirs(args.work, exist_ok=True)
    packing = os.path.join(args.work, "packing")
    if not os.path.exists(os.path.join(packing, "packing.json")):
        subprocess.run([study, "packing", "--spheres", str(args.spheres), "--settle", "0.1",
                        "--out", packing], check=True)
    meta = json.load(open(os.path.join(packing, "packing.json")))
    with open(os.path.join(packing, "packing.csv")) as f, \
            open(os.path.join(args.work, "stones.csv"), "w") as out:
        out.write("stone,x,y,z,radius\n")
        for k, line in enumerate(l for l in f.read().splitlines()[1:] if l.strip()):
            out.write("%d,%s\n" % (k + 1, line))
    runs = {"without": None, "with": args.steps / 4 * meta["dt"]}
    seconds = {name: [] for name in runs}
    for _ in range(args.repeats):
        for name, every in runs.items():
            path = os.path.join(args.work, name + ".toml")
            with open(path, "w") as f:
                f.write(scene(meta, args.steps, every, "out/" + name))
            shutil.rmtree(os.path.join(args.work, "out", name), ignore_errors=True)
            subprocess.run([qdem, "run", path, "--threads", "2"], check=True,
                           env=dict(os.environ, CI="1"), stdout=subprocess.DEVNULL)
            summary = json.load(open(os.path.join(args.work, "out", name, "summary.json")))
            seconds[name].append(summary["wall_seconds"])
            print("%s VTU: %.3f s for %d steps" % (name, summary["wall_seconds"], summary["steps"]))
    added = [(w - wo) / 5 for w, wo in zip(seconds["with"], seconds["without"])]
    print("one VTU time adds %s s" % ", ".join("%.3f" % a for a in added))
    vtu = os.path.join(args.work, "out", "with", "vtu")
    for name in sorted(os.listdir(vtu)):
        if name.endswith("00004.vtu") or name == "walls.vtu":
            print("%s: %d bytes" % (name, os.path.getsize(os.path.join(vtu, name))))


if __name__ == "__main__":
    sys.exit(main())
