#!/usr/bin/env python3
"""The force through the middle cell's faces over a load cycle, in the three-sleeper box and
in the single-sleeper periodic boxes: the premise of paper 003's Eqs. 4-7 checked against the
reference it is meant to reproduce.

    python3 qdem-bench/scripts/boxtest_faces.py [--study out/boxtest_study] [--seeds 1,2,3,4,5] [--size study]

Reads each seed's three_sleeper/sections.csv (the average contact force through y = 0.7 and
1.4 m, the middle cell's left and right faces), single_periodic/sections.csv (through the
cell face) and single_delayed/{sections,boundary}.csv (the face force F and the ghost scales:
the middle cell's particles feel s_left F from the left ghosts and s_right F from the right
ones, Eqs. 6-7), and the same of single_shared (one scale s for both sides). Averages each series over the phase of the middle sleeper's load (36 bins,
cycles 2 to the last), and writes faces.csv (phase, seed, series, mean force) into the study
folder, docs/boxtest_faces.svg, and a table of the means at the load's minimum, rising
mid-point, peak and falling mid-point between <!-- faces:begin --> and <!-- faces:end --> in
docs/boxtest.md.
"""
import argparse
import csv
import math
import os
import re

from boxtest_study import ROOT, svg_frame

FREQUENCY, START = 3.0, 0.2  # the study's load: 3 Hz after the settling time (generate.py)
BINS = 36
SERIES = {
    "three_left": "three-sleeper, left face (y = 0.7 m)",
    "three_right": "three-sleeper, right face (y = 1.4 m)",
    "periodic": "periodic, cell face",
    "delayed_left": "time-delayed, left ghosts (s_left F)",
    "delayed_right": "time-delayed, right ghosts (s_right F)",
    "shared": "time-delayed, shared faces (s F)",
}
COLOURS = {"three_left": "#000000", "three_right": "#777777", "periodic": "#ff7f0e",
           "delayed_left": "#2ca02c", "delayed_right": "#98df8a", "shared": "#d62728"}


def table(path):
    with open(path) as f:
        header, *rows = list(csv.reader(f))
    return {name: [float(r[k]) for r in rows] for k, name in enumerate(header)}


def series(run_dir):
    """{series: [(time, force)]} of one seed's three runs."""
    three = table(os.path.join(run_dir, "three_sleeper", "sections.csv"))
    periodic = table(os.path.join(run_dir, "single_periodic", "sections.csv"))
    delayed = table(os.path.join(run_dir, "single_delayed", "boundary.csv"))
    face = table(os.path.join(run_dir, "single_delayed", "sections.csv"))
    shared = table(os.path.join(run_dir, "single_shared", "boundary.csv"))
    shared_face = table(os.path.join(run_dir, "single_shared", "sections.csv"))
    return {
        "three_left": list(zip(three["time"], three["left"])),
        "three_right": list(zip(three["time"], three["right"])),
        "periodic": list(zip(periodic["time"], periodic["face"])),
        "delayed_left": [(t, s * f) for t, s, f in
                         zip(delayed["time"], delayed["left_scale"], face["face"])],
        "delayed_right": [(t, s * f) for t, s, f in
                          zip(delayed["time"], delayed["right_scale"], face["face"])],
        "shared": [(t, s * f) for t, s, f in
                   zip(shared["time"], shared["left_scale"], shared_face["face"])],
    }


def phase_means(points):
    """Mean force per phase bin of the middle sleeper's load, Φ + π/2 in [0, 2π) (0: the
    minimum, π: the peak), over cycles 2 to the last."""
    sums, counts = [0.0] * BINS, [0] * BINS
    for t, f in points:
        cycles = FREQUENCY * (t - START)
        if cycles < 1.0:
            continue
        k = min(int((cycles % 1.0) * BINS), BINS - 1)
        sums[k] += f
        counts[k] += 1
    return [s / c if c else float("nan") for s, c in zip(sums, counts)]


def svg(path, means, seeds):
    w, h, m = 640, 420, 60
    top = max(v for per in means.values() for vals in per.values() for v in vals
              if not math.isnan(v)) * 1.1
    x = lambda k: m + (w - 2 * m) * (k + 0.5) / BINS
    y = lambda f: h - m - (h - 2 * m) * f / top
    out = svg_frame(w, h, m, "phase of the middle sleeper's load (min, peak at 180°, min)",
                    "mean contact force through the face (N)")
    for deg in range(0, 361, 90):
        px = m + (w - 2 * m) * deg / 360
        out.append(f'<text x="{px}" y="{h - m + 15}" text-anchor="middle">{deg}°</text>')
    for k in range(5):
        f = top * k / 4
        out.append(f'<text x="{m - 5}" y="{y(f) + 4}" text-anchor="end">{f:.0f}</text>')
    line = lambda vals: " ".join(f"{x(k):.1f},{y(v):.1f}" for k, v in enumerate(vals) if not math.isnan(v))
    for seed in seeds:
        for name, vals in means[seed].items():
            out.append(f'<polyline fill="none" stroke="{COLOURS[name]}" stroke-width="0.7" stroke-opacity="0.4" points="{line(vals)}"/>')
    for name, vals in over_samples(means, seeds).items():
        out.append(f'<polyline fill="none" stroke="{COLOURS[name]}" stroke-width="2.5" points="{line(vals)}"/>')
    for i, name in enumerate(SERIES):
        out.append(f'<rect x="{m + 10}" y="{m + 8 + 16 * i}" width="14" height="3" fill="{COLOURS[name]}"/>'
                   f'<text x="{m + 30}" y="{m + 13 + 16 * i}">{SERIES[name]}</text>')
    out.append(f'<text x="{w - m}" y="{m - 10}" text-anchor="end">samples {", ".join(map(str, seeds))} (thick: their mean, thin: each)</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def over_samples(means, seeds):
    """{series: mean over the samples of each phase bin's mean}."""
    return {name: [sum(means[s][name][k] for s in seeds) / len(seeds) for k in range(BINS)]
            for name in SERIES}


def markdown(means, seeds):
    points = [("minimum", 0), ("rising", BINS // 4), ("peak", BINS // 2), ("falling", 3 * BINS // 4)]
    mean = over_samples(means, seeds)
    lines = ["Mean contact force through the face (N) at four phases of the middle sleeper's load "
             "(the bin starting there, 10° wide), averaged over cycles 2 to the last and over "
             f"samples {', '.join(map(str, seeds))} (in brackets: the smallest and largest sample):",
             "", "| series | " + " | ".join(p for p, _ in points) + " |",
             "|---|" + "---|" * len(points)]
    for name, label in SERIES.items():
        vals = " | ".join(
            f"{mean[name][k]:.1f} ({min(means[s][name][k] for s in seeds):.0f}–"
            f"{max(means[s][name][k] for s in seeds):.0f})" for _, k in points)
        lines.append(f"| {label} | {vals} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--study", default=os.path.join(ROOT, "out", "boxtest_study"))
    ap.add_argument("--seeds", default="1,2,3,4,5")
    ap.add_argument("--size", default="study")
    ap.add_argument("--docs", default=os.path.join(ROOT, "docs"))
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    means = {s: {n: phase_means(p) for n, p in
                 series(os.path.join(args.study, f"{args.size}_seed{s}")).items()} for s in seeds}
    with open(os.path.join(args.study, "faces.csv"), "w") as f:
        f.write("phase_deg,seed,series,force\n")
        for s in seeds:
            for name, vals in means[s].items():
                for k, v in enumerate(vals):
                    f.write(f"{(k + 0.5) * 360 / BINS:.1f},{s},{name},{v:.6e}\n")
    svg(os.path.join(args.docs, "boxtest_faces.svg"), means, seeds)
    text = markdown(means, seeds)
    print(text)
    doc = os.path.join(args.docs, "boxtest.md")
    with open(doc) as f:
        body = f.read()
    if "<!-- faces:begin -->" in body:
        body = re.sub(r"<!-- faces:begin -->.*<!-- faces:end -->",
                      f"<!-- faces:begin -->\n{text}\n<!-- faces:end -->", body, flags=re.S)
        with open(doc, "w") as f:
            f.write(body)


if __name__ == "__main__":
    main()
