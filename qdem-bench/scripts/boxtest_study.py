#!/usr/bin/env python3
"""The box-test study of paper 003: for each of 3 samples (seeds 1, 2, 3), deposit the
sample of the periodic single-sleeper cell (bed, then the sleeper and the crib), then load
it in the three-sleeper box (the cell's sample three times along y), in the single-sleeper
box with fixed walls, and with ordinary and time-delayed periodic boundaries (paper 003's
Eqs. 6-7, and qdem's shared faces); collect the middle sleeper's settlement after every load
cycle. All five cases of a seed load the same middle sample from the same sleeper pose.

    cargo build --release -p qdem-cli
    python3 qdem-bench/scripts/boxtest_study.py [--size study|small] [--seeds 1,2,3]

Writes out/boxtest_study/settlement.csv (case, seed, cycle, settlement), settlement.svg,
runs.json (particles, steps, wall time, sphere-steps/s of every run) and the tables between
<!-- boxtest:begin --> and <!-- boxtest:end --> in docs/boxtest.md, then (study size) runs
boxtest_faces.py: the force through the middle cell's faces over a cycle. Settlement is the
sleeper's downward displacement at the end of each cycle (its load back at the minimum)
relative to the start of the cycles (after the settling time under the minimum load), read
from each run's settlement.csv (qdem's displacement at every cycle's minimum).
"""
import argparse
import csv
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIXTURES = os.path.join(ROOT, "fixtures", "boxtest")
QDEM = os.path.join(ROOT, "target", "release", "qdem")
CASES = ["three_sleeper", "single_fixed", "single_periodic", "single_delayed", "single_shared"]
LABELS = {"three_sleeper": "three-sleeper (middle)", "single_fixed": "single, fixed walls",
          "single_periodic": "single, periodic", "single_delayed": "single, time-delayed",
          "single_shared": "single, time-delayed, shared faces"}
COLOURS = {"three_sleeper": "#000000", "single_fixed": "#1f77b4",
           "single_periodic": "#ff7f0e", "single_delayed": "#2ca02c", "single_shared": "#d62728"}


def svg_frame(w, h, m, xlabel, ylabel):
    """The opening lines of a w x h plot with margin m: white page, x and y axes, labels."""
    return [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12">',
            f'<rect width="{w}" height="{h}" fill="white"/>',
            f'<line x1="{m}" y1="{h - m}" x2="{w - m}" y2="{h - m}" stroke="black"/>',
            f'<line x1="{m}" y1="{m}" x2="{m}" y2="{h - m}" stroke="black"/>',
            f'<text x="{w / 2}" y="{h - 20}" text-anchor="middle">{xlabel}</text>',
            f'<text x="15" y="{h / 2}" transform="rotate(-90 15 {h / 2})" text-anchor="middle">{ylabel}</text>']


def scene_for(size, name, seed, out):
    """The scene text for `seed`, outputs and samples under `out` (absolute paths)."""
    with open(os.path.join(FIXTURES, f"{size}_{name}.toml")) as f:
        text = f.read()
    text = re.sub(r"^seed = \d+", f"seed = {seed}", text, flags=re.M)
    text = text.replace('mesh = "sleeper.msh"', f'mesh = "{FIXTURES}/sleeper.msh"')
    text = re.sub(r'"out/boxtest/[a-z]+/', f'"{out}/', text)
    return text


def run(size, name, seed, out):
    path = os.path.join(out, f"{name}.toml")
    with open(path, "w") as f:
        f.write(scene_for(size, name, seed, out))
    subprocess.run([QDEM, "run", path], check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, name.replace("deposit_", ""), "summary.json")) as f:
        return json.load(f)


def settlement(out, case, settle, cycles):
    """Settlement (m, positive down) of the middle sleeper after each cycle, from the run's
    settlement.csv: its displacement along its (downward) load at the minimum that ends each
    cycle, less the one at the first cycle's start (`settle`, after the settling time). qdem
    takes each minimum at the step nearest it; the last one, at t_end, is the row with no
    maximum."""
    path = os.path.join(out, case, "settlement.csv")
    with open(path) as f:
        rows = sorted((r for r in csv.DictReader(f) if r["body"] == "sleeper2"),
                      key=lambda r: float(r["cycle"]))
    minima = [(float(r["time_min"]), float(r["sleeper2.at_min"])) for r in rows]
    if len(minima) != cycles + 1 or abs(minima[0][0] - settle) > 1e-3:
        sys.exit(f"{path}: {len(minima)} minima of sleeper2's load from t = "
                 f"{minima[0][0] if minima else 'none'}; the study needs {cycles + 1} from "
                 f"{settle} s (a qdem older than settlement.csv's last-minimum row?)")
    return [u - minima[0][1] for _, u in minima[1:]]


def svg(path, series, cycles):
    """Settlement against cycle: one polyline per (case, seed)."""
    w, h, m = 640, 420, 60
    top = max(max(v) for _, _, v in series) * 1.1 or 1.0
    x = lambda c: m + (w - 2 * m) * c / cycles
    y = lambda s: h - m - (h - 2 * m) * s / top
    out = svg_frame(w, h, m, "load cycle", "middle-sleeper settlement (mm)")
    for c in range(cycles + 1):
        out.append(f'<text x="{x(c)}" y="{h - m + 16}" text-anchor="middle">{c}</text>')
    for k in range(5):
        s = top * k / 4
        out.append(f'<text x="{m - 6}" y="{y(s) + 4}" text-anchor="end">{1000 * s:.1f}</text>')
    dashes = {1: "", 2: ' stroke-dasharray="6 3"', 3: ' stroke-dasharray="2 3"'}
    for case, seed, values in series:
        pts = " ".join(f"{x(c)},{y(v)}" for c, v in zip(range(cycles + 1), [0.0] + values))
        out.append(f'<polyline points="{pts}" fill="none" stroke="{COLOURS[case]}" stroke-width="1.5"{dashes.get(seed, "")}/>')
    for i, case in enumerate(CASES):
        out.append(f'<line x1="{m + 10}" y1="{m + 10 + 16 * i}" x2="{m + 30}" y2="{m + 10 + 16 * i}" stroke="{COLOURS[case]}" stroke-width="2"/>')
        out.append(f'<text x="{m + 36}" y="{m + 14 + 16 * i}">{LABELS[case]}</text>')
    out.append(f'<text x="{m + 10}" y="{m + 14 + 16 * len(CASES)}">samples 1, 2, 3: solid, dashed, dotted</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", default="study")
    ap.add_argument("--seeds", default="1,2,3")
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    with open(os.path.join(FIXTURES, "generate.py")) as f:
        params = re.search(r'"%s": dict\((.*?)\),\n' % args.size, f.read(), re.S).group(1)
    cycles = int(re.search(r"cycles=(\d+)", params).group(1))
    settle = float(re.search(r"settle=([\d.]+)", params).group(1))
    base = os.path.join(ROOT, "out", "boxtest_study")
    os.makedirs(base, exist_ok=True)
    series, runs = [], []
    for seed in seeds:
        out = os.path.join(base, f"{args.size}_seed{seed}")
        os.makedirs(out, exist_ok=True)
        for name in ["deposit_cell_bed", "deposit_cell_crib"] + CASES:
            s = run(args.size, name, seed, out)
            runs.append(dict(seed=seed, run=name, particles=s["particles"],
                             stones=s["granular"]["stones"], spheres=s["contact"]["spheres"],
                             steps=s["steps"], dt=s["dt"], wall_seconds=s["wall_seconds"],
                             sphere_steps_per_second=s["contact"]["sphere_steps_per_second"],
                             threads=s["threads"]))
            print(f"seed {seed} {name}: {s['wall_seconds']:.1f} s", flush=True)
        for case in CASES:
            series.append((case, seed, settlement(out, case, settle, cycles)))
    with open(os.path.join(base, "settlement.csv"), "w") as f:
        f.write("case,seed,cycle,settlement_m\n")
        for case, seed, values in series:
            for c, v in enumerate(values, 1):
                f.write(f"{case},{seed},{c},{v:.6e}\n")
    with open(os.path.join(base, "runs.json"), "w") as f:
        json.dump(runs, f, indent=1)
    svg(os.path.join(base, "settlement.svg"), series, cycles)
    table = tables(series, runs, seeds)
    print(table)
    if args.size == "study":
        doc = os.path.join(ROOT, "docs", "boxtest.md")
        text = open(doc).read()
        text = re.sub(r"<!-- boxtest:begin -->.*<!-- boxtest:end -->",
                      "<!-- boxtest:begin -->\n" + table + "\n<!-- boxtest:end -->", text, flags=re.S)
        open(doc, "w").write(text)
        os.replace(os.path.join(base, "settlement.svg"), os.path.join(ROOT, "docs", "boxtest_settlement.svg"))
        faces = os.path.join(os.path.dirname(os.path.abspath(__file__)), "boxtest_faces.py")
        subprocess.run([sys.executable, faces, "--seeds", args.seeds], check=True)
    return 0


def tables(series, runs, seeds):
    last = {(c, s): v[-1] for c, s, v in series}
    lines = ["| sample | three-sleeper (mm) | fixed walls (mm) | periodic (mm) | time-delayed (mm) | time-delayed, shared faces (mm) | order fixed < periodic < delayed (paper / shared) | closest to three-sleeper |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for s in seeds:
        ref = last[("three_sleeper", s)]
        vals = [last[(c, s)] for c in CASES[1:]]
        errs = {c: last[(c, s)] - ref for c in CASES[1:]}
        closest = min(errs, key=lambda c: abs(errs[c]))
        order = "/".join("yes" if vals[0] < vals[1] < v else "no" for v in vals[2:])
        cells = " | ".join(f"{1000 * v:.2f} ({1000 * errs[c]:+.2f})" for c, v in zip(CASES[1:], vals))
        lines.append(f"| {s} | {1000 * ref:.2f} | {cells} | {order} | {LABELS[closest]} |")
    lines += ["", "(in brackets: the error against the three-sleeper box's middle sleeper)", "",
              "| sample | run | stones | spheres | steps | dt (s) | wall (s) | sphere-steps/s |",
              "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in runs:
        lines.append(f"| {r['seed']} | {r['run']} | {r['stones']} | {r['spheres']} | {r['steps']} | {r['dt']:.3e} | {r['wall_seconds']:.1f} | {r['sphere_steps_per_second']:.3e} |")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
