#!/usr/bin/env python3
"""Issue 26 study of the paper-001 beam's crack phase (docs/bbm.md, "The crack phase"):

1. the solver after breaks: `event_solve = "preconditioned"` (conjugate gradients on the kept
   factor) against the default refactorising solver, at the benchmark settings;
2. speed against error: the implicit 0.025 m beam at dt = 5, 2.5 and 1 ms against the explicit
   0.025 m run (dt = 1.38e-6 s, the paper's explicit step at that size).

Needs the benchmark runs (`qdem run fixtures/bbm/beam_*.toml --threads 1`: out/bbm_*); runs the
variants into out/bbm_study/ (QDEM = the qdem binary, default target/release/qdem), prints one
JSON line per run and writes docs/bbm_speed_error.svg. Usage:

    python3 qdem-bench/scripts/bbm_event_study.py            # run the variants, then report
    python3 qdem-bench/scripts/bbm_event_study.py --report   # report the runs already there
"""
import json
import os
import re
import subprocess
import sys

from doc_section import replace_section

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
OUT = os.path.join(ROOT, "out")
STUDY = os.path.join(OUT, "bbm_study")
QDEM = os.environ.get("QDEM", os.path.join(ROOT, "target", "release", "qdem"))
SVG = os.path.join(ROOT, "docs", "bbm_speed_error.svg")
DOC = os.path.join(ROOT, "docs", "bbm.md")
PX_PER_M = 400.0  # crack.svg draws the 3 m beam 1200 px wide
VARIANTS = [("preconditioned_" + tag, tag, {"event_solve": '"preconditioned"'}, None)
            for tag in ["0.025", "n7676", "n20351"]]
VARIANTS += [(f"implicit_0.025_dt{dt}", "0.025", {}, dt) for dt in ["2.5e-3", "1e-3"]]


def scene(name, tag, bonded, dt):
    text = open(os.path.join(ROOT, "fixtures", "bbm", f"beam_implicit_{tag}.toml")).read()
    text = re.sub(r'dir = ".*"', f'dir = "{os.path.join(STUDY, name)}"', text)
    if dt:
        text = re.sub(r"^dt = .*$", f"dt = {dt}", text, flags=re.M)
    for key, value in bonded.items():
        text = text.replace("[bonded]\n", f"[bonded]\n{key} = {value}\n")
    path = os.path.join(STUDY, f"{name}.toml")
    with open(path, "w") as f:
        f.write(text)
    return path


def breaks(run_dir):
    """Midpoints (m) of the broken bonds drawn in crack.svg."""
    text = open(os.path.join(run_dir, "crack.svg")).read()
    lines = re.findall(r'<line x1="([\d.]+)" y1="([\d.]+)" x2="([\d.]+)" y2="([\d.]+)"', text)
    height = float(re.search(r'<rect x="0" y="0" width="[\d.]+" height="([\d.]+)"', text)[1])
    return [((float(a) + float(c)) / 2 / PX_PER_M, (height - (float(b) + float(d)) / 2) / PX_PER_M)
            for a, b, c, d in lines]


def path_figures(points, reference, spacing):
    """The crack path: centroid x, the highest break, and the share of breaks within half a
    spacing of one of the reference's."""
    if not points:
        return {}
    near = sum(1 for x, y in points
               if any((x - u) ** 2 + (y - v) ** 2 <= (spacing / 2) ** 2 for u, v in reference))
    return {"centroid_x": sum(p[0] for p in points) / len(points),
            "highest_break": max(p[1] for p in points),
            "matched_share": near / len(points)}


def figures(run_dir, reference_dir, spacing):
    s = json.load(open(os.path.join(run_dir, "summary.json")))
    b = s["bonded"]
    out = {"dir": os.path.relpath(run_dir, ROOT), "wall_seconds": s["wall_seconds"],
           "dt": s["dt"], "broken_bonds": b["broken_bonds"],
           "first_break_time": b["first_break_time"],
           "stopped_at": (b["stopped_at_collapse"] or {}).get("time"),
           "factorizations": b["factorizations"], "iterative_solves": b.get("iterative_solves"),
           "crack_phase_per_step": b.get("crack_phase_per_step")}
    out.update(path_figures(breaks(run_dir), breaks(reference_dir), spacing))
    return out


def plot(points):
    W, H, M = 640, 400, 70
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    xmin, xmax = min(xs) / 1.5, max(xs) * 1.5
    ymax = max(ys) * 1.2
    import math
    px = lambda x: M + (W - 2 * M) * math.log(x / xmin) / math.log(xmax / xmin)
    py = lambda y: H - M - (H - 2 * M) * y / ymax
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}">',
           f'<rect x="{M}" y="{M}" width="{W-2*M}" height="{H-2*M}" fill="none" stroke="black"/>',
           f'<text x="{W/2}" y="30" text-anchor="middle" font-family="sans-serif" font-size="14">'
           'implicit 0.025 m beam: |bonds broken − explicit| / explicit vs wall time</text>',
           f'<text x="{W/2}" y="{H-20}" text-anchor="middle" font-family="sans-serif" '
           'font-size="12">wall time (s, log scale)</text>',
           f'<text x="{M}" y="{H-M+15}" font-family="sans-serif" font-size="11">{xmin:.3g}</text>',
           f'<text x="{W-M}" y="{H-M+15}" font-family="sans-serif" font-size="11" '
           f'text-anchor="end">{xmax:.3g}</text>',
           f'<text x="{M-5}" y="{M+4}" font-family="sans-serif" font-size="11" '
           f'text-anchor="end">{ymax:.2f}</text>',
           f'<text x="{M-5}" y="{H-M}" font-family="sans-serif" font-size="11" '
           'text-anchor="end">0</text>']
    for x, y, label in points:
        out.append(f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="5" fill="#d62728"/>')
        out.append(f'<text x="{px(x)+8:.1f}" y="{py(y)-8:.1f}" font-family="sans-serif" '
                   f'font-size="12">{label}</text>')
    out.append("</svg>")
    with open(SVG, "w") as f:
        f.write("\n".join(out))


def main():
    os.makedirs(STUDY, exist_ok=True)
    if "--report" not in sys.argv:
        for name, tag, bonded, dt in VARIANTS:
            path = scene(name, tag, bonded, dt)
            subprocess.run([QDEM, "run", path, "--threads", "1"], check=True,
                           stdout=subprocess.DEVNULL)
    spacing = {"0.025": 0.025, "n7676": 0.0148, "n20351": 0.0091}
    rows = []
    for name, tag, bonded, dt in VARIANTS:
        base = os.path.join(OUT, f"bbm_implicit_{tag}")
        reference = base if bonded else os.path.join(OUT, "bbm_explicit_0.025")
        row = {"run": name, "against": os.path.relpath(reference, ROOT)}
        row.update(figures(os.path.join(STUDY, name), reference, spacing[tag]))
        rows.append(row)
        print(json.dumps(row))
    explicit = os.path.join(OUT, "bbm_explicit_0.025")
    own = [("implicit_0.025_dt5e-3", os.path.join(OUT, "bbm_implicit_0.025")),
           ("explicit_0.025", explicit)]
    for name, d in own:
        row = {"run": name, "against": os.path.relpath(explicit, ROOT)}
        row.update(figures(d, explicit, 0.025))
        rows.append(row)
        print(json.dumps(row))
    ref = next(r for r in rows if r["run"] == "explicit_0.025")["broken_bonds"]
    points = [(r["wall_seconds"], abs(r["broken_bonds"] - ref) / ref, f"{r['dt'] * 1e3:g} ms")
              for r in rows if r["run"].startswith("implicit_0.025")]
    plot(points)
    write_tables(rows)


def cell(x, spec):
    return "—" if x is None else format(x, spec)


def write_tables(rows):
    """The two tables of docs/bbm.md between <!-- bbm-study:begin --> and <!-- bbm-study:end -->."""
    head = ("| run | against | dt (s) | wall (s) | bonds broken | first break (s) | stopped at (s) "
            "| crack centroid x (m) | highest break (m) | breaks matched | factorisations "
            "| iterative solves |")
    def line(r):
        return (f"| {r['run']} | {r['against']} | {r['dt']:g} | {r['wall_seconds']:.2f} "
                f"| {r['broken_bonds']} | {cell(r['first_break_time'], '.4f')} "
                f"| {cell(r['stopped_at'], '.4f')} | {cell(r.get('centroid_x'), '.3f')} "
                f"| {cell(r.get('highest_break'), '.3f')} | {cell(r.get('matched_share'), '.1%')} "
                f"| {r['factorizations']} | {cell(r['iterative_solves'], 'd')} |")
    parts = ["**Conjugate gradients on the kept factor against refactorising** (benchmark "
             "settings; `against` is the refactorising run):", "", head, "|" + "---|" * 12]
    parts += [line(r) for r in rows if r["run"].startswith("preconditioned")]
    parts += ["", "**Speed against error** (0.025 m, against the explicit run at ∆t = 1.38e-6 s):",
              "", head, "|" + "---|" * 12]
    parts += [line(r) for r in rows if not r["run"].startswith("preconditioned")]
    replace_section(DOC, "<!-- bbm-study:begin -->", "<!-- bbm-study:end -->", parts)


if __name__ == "__main__":
    main()
