#!/usr/bin/env python3
"""The box-test study of paper 003: for each sample (seeds 1-5 by default), deposit the
sample of the periodic single-sleeper cell (bed, then the sleeper and the crib), then load
it in the three-sleeper box (the cell's sample three times along y), in the single-sleeper
box with fixed walls, and with ordinary and time-delayed periodic boundaries (paper 003's
Eqs. 6-7, and qdem's shared faces); collect the middle sleeper's settlement after every load
cycle. The cases of a seed load the same stones: the periodic boxes and the middle of
the three-sleeper box the cell's sample from the same sleeper pose, the fixed-wall box the
same sample with its stones astride the walls poured back under the sleeper's 3 kN first
(`deposit_fixed_crib`), so that it holds the cell's stone count and mass, and the cropped
fixed-wall box the cell's sample less those stones (paper 003's cut); the last fixed-wall box
deposits the same stones drawn between its own walls (`deposit_walled_bed`, `_crib`).

    cargo build --release -p qdem-cli
    python3 qdem-bench/scripts/boxtest_study.py [--size study|small|paper] [--seeds 1-5]
        [--jobs 2] [--threads 1] [--docs]
    python3 qdem-bench/scripts/boxtest_study.py --variant stiff4 --young 4e9 --cycles 10
    python3 qdem-bench/scripts/boxtest_study.py --seeds 1 --replicas 0.47,0.49,0.51,0.53

The second form loads the samples the first deposited again, here at 4 GPa for 10 cycles
(out/boxtest_study/SIZE_seedN_stiff4/), and prints its errors beside the first study's after
as many cycles: does the stiffness change which boundary comes closest? `--tables-only`
writes the tables and plots again from the last outputs without running anything. The third
form loads sample 1 again with its step a few percent off the study's (0.5 of the contacts'
estimate): how far a run's settlement moves under a perturbation that changes no physics,
beside the scatter between samples. `--resume` reads back the runs that finished from the
same scene (a study stopped part-way, or extended with more seeds).

Runs `--jobs` qdem runs at once (`--threads` each; on a 2-core machine two one-thread runs
beat one two-thread run). Writes out/boxtest_study/settlement.csv (case, seed, cycle,
settlement), settlement.svg, runs.json (particles, steps, wall time, sphere-steps/s of every
run) and prints the tables: settlement per sample, the mean error of each boundary against
the three-sleeper box with its 95% interval over the samples (paired by sample), and which
boundary is closer, pair by pair. With `--docs` the tables go between <!-- boxtest:begin -->
and <!-- boxtest:end --> in docs/boxtest.md with the plot beside, then boxtest_faces.py
writes the force through the middle cell's faces over a cycle. Settlement is the sleeper's
downward displacement at the end of each cycle (its load back at the minimum) relative to
the start of the cycles (after the settling time under the minimum load), read from each
run's settlement.csv (qdem's displacement at every cycle's minimum).
"""
import argparse
import csv
import functools
import json
import math
import os
import re
import subprocess
import sys
import threading
import time
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIXTURES = os.path.join(ROOT, "fixtures", "boxtest")
sys.path.insert(0, FIXTURES)
import grading_table  # noqa: E402  (fixtures/boxtest: a sample's percent passing a sieve)
QDEM = os.path.join(ROOT, "target", "release", "qdem")
CASES = ["three_sleeper", "single_fixed", "single_cropped", "single_walled", "single_periodic",
         "single_delayed", "single_shared"]
DEPOSITS = ["deposit_cell_bed", "deposit_cell_crib", "deposit_fixed_crib", "deposit_walled_bed",
            "deposit_walled_crib"]
# The run each run reads (a loading case not named here reads the cell's crib).
NEEDS = {"deposit_cell_crib": "deposit_cell_bed", "deposit_fixed_crib": "deposit_cell_crib",
         "deposit_walled_crib": "deposit_walled_bed", "single_fixed": "deposit_fixed_crib",
         "single_walled": "deposit_walled_crib"}
LABELS = {"three_sleeper": "three-sleeper (middle)", "single_fixed": "single, fixed walls",
          "single_cropped": "single, fixed walls, cropped",
          "single_walled": "single, fixed walls, own deposit", "single_periodic": "single, periodic",
          "single_delayed": "single, time-delayed",
          "single_shared": "single, time-delayed, shared faces"}
COLOURS = {"three_sleeper": "#000000", "single_fixed": "#1f77b4", "single_cropped": "#9467bd",
           "single_walled": "#8c564b",
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


def run(size, name, seed, out, qdem, threads, variant=None, resume=False):
    """One run of `seed` with its samples under `out`; a `variant` (dict of `name`, `young`,
    `t_end`) loads those samples at another stiffness or for fewer cycles and writes its runs
    under `out`_NAME. With `resume`, a run that finished from the same scene text (its
    summary.json newer than its scene file) is read back instead of run again."""
    text = scene_for(size, name, seed, out)
    if variant:
        text = re.sub(r'^dir = "(.*)/([a-z_]+)"$', rf'dir = "\1_{variant["name"]}/\2"', text,
                      flags=re.M)
        if variant["young"]:
            text = re.sub(r"^young = .*$", f"young = {variant['young']}", text, flags=re.M)
        if variant["t_end"]:
            text = re.sub(r"^t_end = .*$", f"t_end = {variant['t_end']}", text, flags=re.M)
        if variant.get("dt_safety"):
            text = re.sub(r"^dt_safety = .*$", f"dt_safety = {variant['dt_safety']}", text,
                          flags=re.M)
        out = f"{out}_{variant['name']}"
        os.makedirs(out, exist_ok=True)
    path = os.path.join(out, f"{name}.toml")
    summary = os.path.join(out, name.replace("deposit_", ""), "summary.json")
    if resume and os.path.exists(summary) and os.path.exists(path) \
            and open(path).read() == text and os.path.getmtime(summary) > os.path.getmtime(path):
        with open(summary) as f:
            return json.load(f)
    with open(path, "w") as f:
        f.write(text)
    subprocess.run([qdem, "run", path, "--threads", str(threads)], check=True,
                   stdout=subprocess.DEVNULL, env=dict(os.environ, CI="true"))
    with open(summary) as f:
        return json.load(f)


def run_all(size, seeds, base, qdem, jobs, threads, variant=None, resume=False):
    """Every run of every seed, `jobs` at a time on `threads` threads each, each once the run
    it reads has finished (`NEEDS`): a seed's bed, then its crib, then its loading cases (the
    three-sleeper box first, the longest), the poured-back fixed-wall box's after the pour of
    its stones astride the walls (`deposit_fixed_crib`), the walled box's after its own bed
    and crib; with a `variant`, only the loading cases, on the samples already deposited. Returns the
    runs' summaries in a fixed order (seed, then run), whatever order they finished in. Seeds
    are taken in order (a seed's runs before the next seed's), so a study stopped early has
    its first samples whole."""
    deposits = [] if variant else DEPOSITS
    order = lambda name: 1 + CASES.index(name) if name in CASES else 0
    needs = lambda name: NEEDS.get(name, "deposit_cell_crib" if name in CASES else None)
    ready = [(seed, order(name), name) for seed in seeds for name in deposits + CASES
             if not deposits or needs(name) is None]
    done, failed = {}, []
    lock = threading.Condition()
    running = [0]

    def worker():
        while True:
            with lock:
                while not ready and running[0] and not failed:
                    lock.wait()
                if not ready or failed:
                    lock.notify_all()
                    return
                seed, rank, name = min(ready, key=lambda t: (t[0], t[1]))
                ready.remove((seed, rank, name))
                running[0] += 1
            out = os.path.join(base, f"{size}_seed{seed}")
            os.makedirs(out, exist_ok=True)
            try:
                s = run(size, name, seed, out, qdem, threads, variant, resume)
            except Exception as e:  # a failed run stops the study after the running ones
                with lock:
                    failed.append(f"seed {seed} {name}: {e}")
                    running[0] -= 1
                    lock.notify_all()
                return
            print(f"seed {seed} {name}: {s['wall_seconds']:.1f} s", flush=True)
            with lock:
                done[(seed, name)] = s
                running[0] -= 1
                ready.extend((seed, order(after), after) for after in deposits + CASES
                             if deposits and needs(after) == name)
                lock.notify_all()

    pool = [threading.Thread(target=worker) for _ in range(jobs)]
    for t in pool:
        t.start()
    for t in pool:
        t.join()
    if failed:
        sys.exit("; ".join(failed))
    runs = []
    for seed in seeds:
        for name in deposits + CASES:
            s = done[(seed, name)]
            runs.append(dict(seed=seed, run=name, particles=s["particles"],
                             stones=s["granular"]["stones"], spheres=s["contact"]["spheres"],
                             steps=s["steps"], dt=s["dt"], wall_seconds=s["wall_seconds"],
                             sphere_steps_per_second=s["contact"]["sphere_steps_per_second"],
                             threads=s["threads"]))
    return runs


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


def svg(path, series, cycles, seeds):
    """Settlement against cycle: each case's mean over the samples (thick) over its samples
    (thin)."""
    w, h, m = 680, 440, 60
    top = max(max(v) for _, _, v in series) * 1.1 or 1.0
    x = lambda c: m + (w - 2 * m) * c / cycles
    y = lambda s: h - m - (h - 2 * m) * s / top
    out = svg_frame(w, h, m, "load cycle", "middle-sleeper settlement (mm)")
    for c in range(0, cycles + 1, 5 if cycles > 10 else 1):
        out.append(f'<text x="{x(c)}" y="{h - m + 16}" text-anchor="middle">{c}</text>')
    for k in range(5):
        s = top * k / 4
        out.append(f'<text x="{m - 6}" y="{y(s) + 4}" text-anchor="end">{1000 * s:.1f}</text>')
    line = lambda values: " ".join(f"{x(c):.1f},{y(v):.1f}" for c, v in enumerate([0.0] + values))
    for case, _, values in series:
        out.append(f'<polyline points="{line(values)}" fill="none" stroke="{COLOURS[case]}" stroke-width="0.7" stroke-opacity="0.45"/>')
    for case in CASES:
        runs = [v for c, _, v in series if c == case]
        mean = [sum(col) / len(col) for col in zip(*runs)]
        out.append(f'<polyline points="{line(mean)}" fill="none" stroke="{COLOURS[case]}" stroke-width="2.5"/>')
    for i, case in enumerate(CASES):
        out.append(f'<line x1="{m + 10}" y1="{m + 10 + 16 * i}" x2="{m + 30}" y2="{m + 10 + 16 * i}" stroke="{COLOURS[case]}" stroke-width="2.5"/>')
        out.append(f'<text x="{m + 36}" y="{m + 14 + 16 * i}">{LABELS[case]}</text>')
    out.append(f'<text x="{m + 10}" y="{m + 14 + 16 * len(CASES)}">thick: mean of samples {", ".join(map(str, seeds))}; thin: each sample</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out))


def parse_seeds(text):
    """"1-5" or "1,2,3"."""
    if "-" in text:
        lo, hi = text.split("-")
        return list(range(int(lo), int(hi) + 1))
    return [int(s) for s in text.split(",")]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", default="study")
    ap.add_argument("--seeds", default="1-5")
    ap.add_argument("--jobs", type=int, default=2, help="runs at once (default 2)")
    ap.add_argument("--threads", type=int, default=1, help="threads per run (default 1)")
    ap.add_argument("--qdem", default=QDEM)
    ap.add_argument("--variant", help="load the samples already deposited again, as NAME: "
                    "with --young and/or --cycles; runs under out/boxtest_study/SIZE_seedN_NAME")
    ap.add_argument("--young", type=float, help="the variant's Young's modulus (Pa)")
    ap.add_argument("--cycles", type=int, help="the variant's load cycles")
    ap.add_argument("--replicas", help="load the samples already deposited again at these "
                    "dt_safety values (e.g. 0.47,0.49,0.51,0.53) and print how far one run's "
                    "settlement moves with its step: the scatter of a run beside a sample's")
    ap.add_argument("--resume", action="store_true",
                    help="read back the runs that finished from the same scene instead of "
                         "running them again (a study stopped part-way, the same qdem)")
    ap.add_argument("--tables-only", action="store_true",
                    help="no runs: the tables and plots again from the outputs of the last study")
    ap.add_argument("--docs", action="store_true",
                    help="write the tables and plots into docs/ (the study size)")
    args = ap.parse_args()
    seeds = parse_seeds(args.seeds)
    with open(os.path.join(FIXTURES, "generate.py")) as f:
        params = re.search(r'"%s": dict\((.*?)\),\n' % args.size, f.read(), re.S).group(1)
    cycles = int(re.search(r"cycles=(\d+)", params).group(1))
    settle = float(re.search(r"settle=([\d.]+)", params).group(1))
    variant, suffix = None, ""
    if args.replicas:
        return replicas(args, seeds, cycles, settle)
    if args.variant:
        cycles = args.cycles or cycles
        variant = dict(name=args.variant, young=args.young, t_end=settle + cycles / 3.0)
        suffix = f"_{args.variant}"
    base = os.path.join(ROOT, "out", "boxtest_study")
    os.makedirs(base, exist_ok=True)
    record = os.path.join(base, args.variant or "", "runs.json")
    if args.tables_only:
        with open(record) as f:
            saved = json.load(f)
        runs, wall = saved["runs"], saved["wall_seconds"]
        args.jobs, args.threads = saved["jobs"], saved["threads"]
    else:
        started = time.time()
        runs = run_all(args.size, seeds, base, args.qdem, args.jobs, args.threads, variant,
                       args.resume)
        wall = time.time() - started
    series = [(case, seed, settlement(os.path.join(base, f"{args.size}_seed{seed}{suffix}"),
                                      case, settle, cycles))
              for seed in seeds for case in CASES]
    base = os.path.join(base, args.variant) if args.variant else base
    os.makedirs(base, exist_ok=True)
    with open(os.path.join(base, "settlement.csv"), "w") as f:
        f.write("case,seed,cycle,settlement_m\n")
        for case, seed, values in series:
            for c, v in enumerate(values, 1):
                f.write(f"{case},{seed},{c},{v:.6e}\n")
    with open(os.path.join(base, "runs.json"), "w") as f:
        json.dump(dict(size=args.size, seeds=seeds, jobs=args.jobs, threads=args.threads,
                       wall_seconds=wall, runs=runs), f, indent=1)
    svg(os.path.join(base, "settlement.svg"), series, cycles, seeds)
    table = tables(series, runs, seeds, cycles, wall, args)
    if args.variant:
        table += "\n\n" + beside_base(series, seeds, cycles, os.path.dirname(base), args.variant)
    with open(os.path.join(base, "tables.md"), "w") as f:
        f.write(table + "\n")
    print(table)
    if args.docs:
        doc = os.path.join(ROOT, "docs", "boxtest.md")
        text = open(doc).read()
        text = re.sub(r"<!-- boxtest:begin -->.*<!-- boxtest:end -->",
                      "<!-- boxtest:begin -->\n" + table + "\n<!-- boxtest:end -->", text, flags=re.S)
        open(doc, "w").write(text)
        os.replace(os.path.join(base, "settlement.svg"), os.path.join(ROOT, "docs", "boxtest_settlement.svg"))
        faces = os.path.join(os.path.dirname(os.path.abspath(__file__)), "boxtest_faces.py")
        subprocess.run([sys.executable, faces, "--seeds", ",".join(map(str, seeds)),
                        "--size", args.size], check=True)
    return 0


def t95(df):
    """The two-sided 95% quantile of Student's t with `df` degrees of freedom."""
    return t_quantile(df, 0.475)


def std_dev(values):
    """The sample standard deviation (n − 1 in the denominator)."""
    mean = sum(values) / len(values)
    return math.sqrt(sum((v - mean) ** 2 for v in values) / (len(values) - 1))


def mean_ci(values):
    """Mean and the half-width of its 95% interval (Student t over the samples)."""
    n = len(values)
    mean = sum(values) / n
    if n < 2:
        return mean, float("nan")
    return mean, t95(n - 1) * std_dev(values) / math.sqrt(n)


def error(values, case, seed):
    """`case`'s settlement less its sample's three-sleeper box's, from {(case, seed): value}."""
    return values[(case, seed)] - values[("three_sleeper", seed)]


def closest(values, seed):
    """The single-sleeper box whose settlement is nearest the three-sleeper box's on `seed`."""
    return min(CASES[1:], key=lambda c: abs(error(values, c, seed)))


def replicas(args, seeds, cycles, settle):
    """Each seed's loading cases again at each of `args.replicas`' steps (the base runs step
    at 0.5 of the estimate): a perturbation far below any physical change, which a granular
    packing under cycles amplifies. Prints each case's settlement per step with its standard
    deviation (a run's own scatter) beside the base study's scatter between samples, and
    writes replicas.md."""
    base = os.path.join(ROOT, "out", "boxtest_study")
    values = [float(v) for v in args.replicas.split(",")]
    series = {}
    for v in values:
        name = f"dt{round(1000 * v):03d}"
        variant = dict(name=name, young=None, t_end=None, dt_safety=v)
        run_all(args.size, seeds, base, args.qdem, args.jobs, args.threads, variant, args.resume)
        for seed in seeds:
            for case in CASES:
                out = os.path.join(base, f"{args.size}_seed{seed}_{name}")
                series[(case, seed, v)] = settlement(out, case, settle, cycles)[-1]
    between = {}
    path = os.path.join(base, "settlement.csv")
    if os.path.exists(path):
        with open(path) as f:
            for r in csv.DictReader(f):
                if int(r["cycle"]) == cycles:
                    series.setdefault((r["case"], int(r["seed"]), 0.5), float(r["settlement_m"]))
                    between.setdefault(r["case"], []).append(float(r["settlement_m"]))
    steps = sorted({v for _, _, v in series})
    lines = [f"Settlement after {cycles} cycles (mm) of sample(s) {', '.join(map(str, seeds))} "
             "loaded at steps of 0.47-0.53 of the contacts' estimate (0.5: the study's run), "
             "the standard deviation over these runs beside the study's over its samples:", "",
             "| sample | case | " + " | ".join(f"dt_safety {v}" for v in steps) +
             " | s over the steps | s over the study's samples |",
             "| --- | --- |" + " --- |" * (len(steps) + 2)]
    for seed in seeds:
        for case in CASES:
            xs = [series[(case, seed, v)] for v in steps if (case, seed, v) in series]
            cells = " | ".join(f"{1000 * series[(case, seed, v)]:.2f}"
                               if (case, seed, v) in series else "" for v in steps)
            spread = between.get(case, [])
            lines.append(f"| {seed} | {LABELS[case]} | {cells} | {1000 * std_dev(xs):.2f} | "
                         + (f"{1000 * std_dev(spread):.2f} ({len(spread)} samples)" if len(spread) > 1
                            else "") + " |")
    table = "\n".join(lines)
    with open(os.path.join(base, "replicas.md"), "w") as f:
        f.write(table + "\n")
    print(table)
    return 0


def beside_base(series, seeds, cycles, base, name):
    """The variant's errors against the three-sleeper box beside the base study's after the
    same number of cycles (read from the base study's settlement.csv), per boundary: does the
    variant change which boundary is closest?"""
    path = os.path.join(base, "settlement.csv")
    if not os.path.exists(path):
        return f"(no {path}: run the base study first to compare)"
    with open(path) as f:
        at = {(r["case"], int(r["seed"])): float(r["settlement_m"]) for r in csv.DictReader(f)
              if int(r["cycle"]) == cycles}
    mine = {(c, s): v[cycles - 1] for c, s, v in series}
    lines = [f"Error against the three-sleeper box after {cycles} cycles, mean ± 95% interval "
             f"over samples {', '.join(map(str, seeds))} (mm), the base study beside `{name}`:", "",
             f"| case | base | {name} | closest on (base / {name}) |", "| --- | --- | --- | --- |"]
    for c in CASES[1:]:
        cells = []
        for d in (at, mine):
            e, h = mean_ci([error(d, c, s) for s in seeds])
            cells.append(f"{1000 * e:+.2f} ± {1000 * h:.2f}")
        wins = [sum(closest(d, s) == c for s in seeds) for d in (at, mine)]
        lines.append(f"| {LABELS[c]} | {cells[0]} | {cells[1]} | {wins[0]} / {wins[1]} |")
    return "\n".join(lines)


def t_power(df):
    """The one-sided 80% quantile of Student's t with `df` degrees of freedom."""
    return t_quantile(df, 0.3)


# The normal quantiles for the t expansion: 97.5% and 80% one-sided.
NORMAL = {0.475: 1.959963985, 0.3: 0.841621234}


@functools.lru_cache(maxsize=None)
def t_quantile(df, above_zero):
    """The x where Student's t density with `df` degrees of freedom, integrated from 0,
    reaches `above_zero`: by bisection on Simpson's rule (2,000 panels) below 10 degrees of
    freedom; from 10 on, the Cornish-Fisher expansion in 1/df about the normal quantile (to
    its 1/df^3 term: within 1e-4 of the exact value there)."""
    if df >= 10:
        z = NORMAL[above_zero]
        return (z + (z ** 3 + z) / (4 * df) + (5 * z ** 5 + 16 * z ** 3 + 3 * z) / (96 * df ** 2)
                + (3 * z ** 7 + 19 * z ** 5 + 17 * z ** 3 - 15 * z) / (384 * df ** 3))
    density = lambda t: math.exp(math.lgamma((df + 1) / 2) - math.lgamma(df / 2)
                                 - 0.5 * math.log(df * math.pi)
                                 - (df + 1) / 2 * math.log1p(t * t / df))

    def cdf0(x):
        n = 2000
        h = x / n
        inner = sum((4 if k % 2 else 2) * density(k * h) for k in range(1, n))
        return h / 3 * (density(0) + inner + density(x))
    lo, hi = 0.0, 20.0
    for _ in range(60):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if cdf0(mid) < above_zero else (lo, mid)
    return (lo + hi) / 2


def samples_needed(sd, delta, power):
    """The fewest paired samples n whose 95% interval on a mean difference is at most
    ±`delta` (`power` False), or which detect a true difference `delta` at 5% with 80% power
    (`power` True), for paired differences of standard deviation `sd`; Student t."""
    for n in range(2, 10_001):
        need = t95(n - 1) + (t_power(n - 1) if power else 0.0)
        if need * sd / math.sqrt(n) <= delta:
            return f"{n:,}"
    return "> 10,000"


PAIRS = [("single_delayed", "single_periodic"), ("single_shared", "single_periodic"),
         ("single_periodic", "single_fixed"), ("single_delayed", "single_fixed"),
         ("single_shared", "single_fixed"), ("single_shared", "single_delayed"),
         ("single_cropped", "single_fixed"), ("single_periodic", "single_cropped"),
         ("single_delayed", "single_cropped"), ("single_shared", "single_cropped"),
         ("single_walled", "single_cropped"), ("single_periodic", "single_walled")]


def power_table(last, seeds):
    """The paired scatter of each error and each difference between boundaries, the
    difference this study resolves (the half-width of its 95% interval), and the samples that
    ±2 mm at 95% and 2 mm at 80% power would need at that scatter."""
    n = len(seeds)
    rows = [(f"{LABELS[c]} against the three-sleeper box", [error(last, c, s) for s in seeds])
            for c in CASES[1:]]
    rows += [(f"{LABELS[a]} − {LABELS[b]}",
              [error(last, a, s) - error(last, b, s) for s in seeds]) for a, b in PAIRS]
    lines = [f"How finely {n} paired samples resolve (s: the paired standard deviation over the "
             "samples; the resolved difference: the half-width of the 95% interval, t·s/√n; "
             "the samples that s would need):", "",
             "| compared | s (mm) | resolved at 95% (mm) | n: ±2 mm at 95% | n: 2 mm, 80% power |",
             "| --- | --- | --- | --- | --- |"]
    for name, d in rows:
        sd = std_dev(d)
        lines.append(f"| {name} | {1000 * sd:.2f} | ±{1000 * t95(n - 1) * sd / math.sqrt(n):.2f} | "
                     f"{samples_needed(sd, 2e-3, False)} | {samples_needed(sd, 2e-3, True)} |")
    return "\n".join(lines)


def grading_rows(path):
    """The rows of a run's grading.csv as numbers (sorted by sieve size, as qdem writes them)."""
    with open(path, newline="") as f:
        return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]


def sample_table(size, seeds, base):
    """Per sample, the stones and rock mass every case loads (from each run's grading.csv, at
    its start) and the largest deviation of the loaded sample's grading (the periodic cell's,
    the single boxes' sample) from the asked curve, in points passing on the asked basis."""
    with open(os.path.join(FIXTURES, f"{size}_deposit_cell_bed.toml"), "rb") as f:
        asked = tomllib.load(f)["granular"]
    curve, basis = asked["grading"], asked.get("grading_basis", "number")
    lines = ["The stones each case loads (count, rock mass at 2,600 kg/m³ from each run's "
             "grading.csv at its start) and the loaded sample's grading against the asked curve "
             f"(the largest deviation over its sieves, in points passing by {basis}; the "
             "three-sleeper box holds the cell's sample three times, less the stones astride its "
             "two end walls; its middle third is the cell's sample):", "",
             "| sample | " + " | ".join(LABELS[c] for c in CASES) + " | grading: largest deviation |",
             "| --- |" + " --- |" * (len(CASES) + 1)]
    column = "mass_passing" if basis == "mass" else "number_passing"
    worst = 0.0
    for seed in seeds:
        rows = {c: grading_rows(os.path.join(base, f"{size}_seed{seed}", c, "grading.csv"))
                for c in CASES}
        cells = [f"{len(rows[c])}, {sum(r['mass'] for r in rows[c]):.2f} kg" for c in CASES]
        dev = max(abs(grading_table.passing(rows["single_periodic"], a, column) - 100 * want)
                  for a, want in curve)
        worst = max(worst, dev)
        lines.append(f"| {seed} | " + " | ".join(cells) + f" | {dev:.1f} points |")
    lines += ["", f"Largest deviation of any sample's grading from the asked curve: {worst:.1f} "
              "points passing."]
    return "\n".join(lines)


def tables(series, runs, seeds, cycles, wall, args):
    last = {(c, s): v[-1] for c, s, v in series}
    # Settlement per cycle over the last five cycles: has the rate settled?
    rate = {(c, s): (v[-1] - v[-6]) / 5 for c, s, v in series if len(v) >= 6}
    singles = CASES[1:]
    mm = lambda v: f"{1000 * v:.2f}"
    lines = [f"Settlement of the middle sleeper after {cycles} cycles (mm; in brackets the error "
             "against the same sample's three-sleeper box):", "",
             "| sample | three-sleeper | " + " | ".join(LABELS[c].removeprefix("single, ")
                                                      for c in CASES[1:]) + " | closest |",
             "| --- |" + " --- |" * (len(CASES) + 1)]
    for s in seeds:
        cells = " | ".join(f"{mm(last[(c, s)])} ({1000 * error(last, c, s):+.2f})" for c in singles)
        lines.append(f"| {s} | {mm(last[('three_sleeper', s)])} | {cells} | {LABELS[closest(last, s)]} |")
    lines += ["", f"Over the {len(seeds)} samples (mean ± half-width of the 95% interval, "
              "Student t; the error is paired by sample):", "",
              "| case | settlement (mm) | error (mm) | abs. error (mm) | closest on | rate, last 5 cycles (mm/cycle) |",
              "| --- | --- | --- | --- | --- | --- |"]
    nearest = [closest(last, s) for s in seeds]
    for c in CASES:
        m, h = mean_ci([last[(c, s)] for s in seeds])
        r, rh = mean_ci([rate[(c, s)] for s in seeds]) if rate else (float("nan"),) * 2
        row = f"| {LABELS[c]} | {mm(m)} ± {mm(h)} |"
        if c == "three_sleeper":
            row += " | | |"
        else:
            e, eh = mean_ci([error(last, c, s) for s in seeds])
            a, ah = mean_ci([abs(error(last, c, s)) for s in seeds])
            row += f" {1000 * e:+.2f} ± {mm(eh)} | {mm(a)} ± {mm(ah)} | {nearest.count(c)} of {len(seeds)} |"
        lines.append(row + f" {1000 * r:.3f} ± {1000 * rh:.3f} |")
    lines += ["", "Which boundary is closer, paired by sample: the difference of the absolute "
              "errors, |e_A| − |e_B| (negative: A closer):", "",
              "| A | B | mean (mm) | 95% interval (mm) | A closer on |", "| --- | --- | --- | --- | --- |"]
    for a, b in PAIRS:
        d = [abs(error(last, a, s)) - abs(error(last, b, s)) for s in seeds]
        m, h = mean_ci(d)
        lines.append(f"| {LABELS[a]} | {LABELS[b]} | {1000 * m:+.2f} | [{1000 * (m - h):+.2f}, "
                     f"{1000 * (m + h):+.2f}] | {sum(v < 0 for v in d)} of {len(seeds)} |")
    lines += ["", power_table(last, seeds)]
    lines += ["", sample_table(args.size, seeds, os.path.join(ROOT, "out", "boxtest_study"))]
    lines += ["", runs_table(runs, args.jobs, args.threads, wall)]
    return "\n".join(lines)


def runs_table(runs, jobs, threads, wall):
    """Each run of the study over its samples: the range of its stones, spheres and step, its
    median steps, wall time and speed (every run is in runs.json)."""
    total = sum(r["wall_seconds"] for r in runs)
    lines = [f"The runs over the samples ({jobs} at a time, {threads} thread(s) each, range and "
             f"median; {total:,.0f} s of run time in all, {wall:,.0f} s of wall time in this "
             "call (runs read back with `--resume` take none); every run in "
             "`out/boxtest_study/runs.json`):", "",
             "| run | stones | spheres | dt (s) | steps (median) | wall (s): median, range | "
             "sphere-steps/s (median) |", "| --- | --- | --- | --- | --- | --- | --- |"]
    median = lambda xs: sorted(xs)[len(xs) // 2]
    for name in dict.fromkeys(r["run"] for r in runs):
        rs = [r for r in runs if r["run"] == name]
        col = lambda key: [r[key] for r in rs]
        span = lambda key, f="{}": f"{f.format(min(col(key)))}–{f.format(max(col(key)))}"
        lines.append(f"| {name} | {span('stones')} | {span('spheres')} | "
                     f"{span('dt', '{:.2e}')} | {median(col('steps'))} | "
                     f"{median(col('wall_seconds')):.1f} ({span('wall_seconds', '{:.1f}')}) | "
                     f"{median(col('sphere_steps_per_second')):.2e} |")
    wall_of = {(r["seed"], r["run"]): r["wall_seconds"] for r in runs}
    seeds = sorted({r["seed"] for r in runs})
    for case in ("single_delayed", "single_shared"):
        ratio = sorted(wall_of[(s, case)] / wall_of[(s, "single_periodic")] for s in seeds)
        lines.append(f"\n{LABELS[case]} over the same sample's ordinary periodic box, wall "
                     f"time: median {median(ratio):.2f}, range {ratio[0]:.2f}–{ratio[-1]:.2f} "
                     "(two runs at a time: each beside another one).")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(main())
