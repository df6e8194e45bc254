#!/usr/bin/env python3
"""Poured beds side by side: qdem, LIGGGHTS 3.8 and LAMMPS each pour and settle the same
spheres in a box periodic in x and y on a floor, then a timed window runs from the settled
state (issue 57, "Benchmarks of the beds users pour").

Usage (from the workspace root, after `cargo build --release -p qdem-cli --bin qdem`):

    python3 qdem-bench/scripts/poured_compare.py [--spheres 10000,100000] [--steps 2000]
        [--np 1,2] [--repeats 2] [--parts pour,order,second,clumps,tiled] [--work out/poured]
        [--qdem target/release/qdem] [--settle 0.25] [--tile 3] [--wait-idle 0] [--team]

The bed (per sphere count N): monodisperse spheres of r = 5 mm with the material of the
lattice benchmark (`study packing`: rho = 2700 kg/m3, E = 50 MPa, nu = 0.25, mu = 0.5,
restitution 0.5, skin 1 mm), in a square cell of side L = (N v / 0.6)^(1/3) (a bed about as
high as it is wide) periodic in x and y, on a rigid floor at z = 0, under gravity.

Parts:
- `pour`: the script draws the insertion once, by random sequential addition (seeded; the
  spheres in the random order they were drawn, at rest, at least 2.1 r apart across the
  periodic faces, to a volume fraction of 0.2 above the floor), and every code pours and
  settles that insertion itself for the fall time of the highest sphere plus `--settle`
  seconds at the common step, 20% of the Rayleigh time (LIGGGHTS's usual limit): qdem from
  the insertion as a `[granular] sample` (its checkpoint keeps the settled bed),
  LIGGGHTS and LAMMPS from a data file (their restart files keep it). Then each code times
  `--steps` steps from its own settled bed on 1 and 2 threads / MPI ranks, alternating,
  `--repeats` times, the fastest counting: qdem's `summary.json` (`wall_seconds`: the
  initial force evaluation and the step loop), the peers' `Loop time`. Per code:
  particle-steps/s, contacts (sphere-sphere + sphere-floor) and kinetic energy at the end.
  With `--team`, qdem's window runs a second time with `QDEM_TEAM=1` (the step's parallel
  regions on a persistent team of threads), alternated with the default, as code `qdem_team`.
- `order`: qdem's settled positions (its `stones.csv` after the pour, at rest) run by qdem in
  three orders of the rows: `lattice` (sorted by a grid of one diameter, z then y then x),
  `poured` (as the pour left them: the insertion order) and `random` (a seeded shuffle).
- `second`: the time to simulate one second of the poured bed at each code's own accepted
  step: qdem at its default (`dt = "auto"`: its estimate from the contacts present,
  stable_step.rs, times `dt_safety` 0.9) against LIGGGHTS and LAMMPS at 20% of the Rayleigh
  time (the `pour` window's step): seconds per step / dt. qdem's energy and contacts at the
  end of its own-step window are reported beside the peers'.
- `clumps`: clumps of 2-6 spheres (r = 4 mm, arm r: a segment, triangle, tetrahedron,
  bipyramid and octahedron, in equal numbers, about N/4 clumps so about N spheres), in the same
  cell at 20% of the Rayleigh time of their spheres: qdem pours the script's insertion of them
  (random sequential addition of their bounding spheres, turned at random) as rigid stones of a
  `[granular] sample` and times the window from its checkpoint; LIGGGHTS `fix multisphere`
  pours the same templates with its own random insertion (`insert/pack`, equal weights) and
  times `--repeats` consecutive windows in the same deck (multisphere bodies are not restarted).
- `tiled`: a larger poured bed without pouring it: qdem's settled bed of N spheres (its
  `stones.csv` after the pour) copied K x K times across the periodic cell (`--tile`, a cell K
  times as wide, the bed as high; 3 x 3 copies of 10^4 make 90,000 spheres), each copy in its
  poured order. All three codes start from those positions at rest (qdem as a `[granular]
  sample`, the peers from a data file through their pour deck's set-up) and time `--steps`
  steps as in `pour`, with contacts and kinetic energy at the end. Pouring 10^5 spheres costs
  each code about ten times the 10^4 pour; the copies are settled already, and every code runs
  the same positions.

Everything goes to WORK (the decks, data, restarts, qdem's scenes and outputs), the rows to
WORK/poured_compare.json and a markdown table to stdout and WORK/poured_section.md. The Debian
packages `liggghts` and `lammps` are installed if missing.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import liggghts_compare as lc  # noqa: E402
import peers_compare as pc  # noqa: E402

ROOT = lc.ROOT
HERE = Path(__file__).resolve().parent
RADIUS = 0.005
DENSITY = 2700.0
YOUNG = 5.0e7
POISSON = 0.25
FRICTION = 0.5
RESTITUTION = 0.5
SKIN = 0.001
GRAVITY = 9.81
BED_FRACTION = 0.6      # the settled bed's solid fraction, for the cell's size
INSERT_FRACTION = 0.2   # the insertion's, random sequential addition (jams near 0.38)
INSERT_GAP = 2.1        # closest centres at insertion, in radii


def log(msg: str) -> None:
    print(f"[poured_compare] {msg}", file=sys.stderr, flush=True)


def fmt(v: float) -> str:
    return repr(float(v))


def damping_ratio(e: float) -> float:
    return -math.log(e) / math.sqrt(math.log(e) ** 2 + math.pi ** 2)


def rayleigh_time(r: float = RADIUS) -> float:
    """pi r sqrt(rho/G) / (0.1631 nu + 0.8766), as qdem's granular.rs and LIGGGHTS use it."""
    shear = YOUNG / (2.0 * (1.0 + POISSON))
    return math.pi * r * math.sqrt(DENSITY / shear) / (0.1631 * POISSON + 0.8766)


def common_dt() -> float:
    """The step of every code in the timed windows: 20% of the Rayleigh time."""
    return 0.2 * rayleigh_time()


def cell_side(n: int) -> float:
    """The side of the square cell that a settled bed of n spheres fills about as high as wide."""
    v = 4.0 / 3.0 * math.pi * RADIUS ** 3
    return (n * v / BED_FRACTION) ** (1.0 / 3.0)


# ----------------------------------------------------------------------------- the insertion

def insertion(n: int, seed: int = 57) -> tuple[float, list[tuple[float, float, float]]]:
    """n centres drawn one at a time, uniformly in the cell above the floor, kept where no
    earlier centre is within INSERT_GAP r (minimum image in x and y); the region is as high as
    INSERT_FRACTION needs. Returns the cell side and the centres in the order drawn."""
    side = cell_side(n)
    v = 4.0 / 3.0 * math.pi * RADIUS ** 3
    height = n * v / (INSERT_FRACTION * side * side)
    gap = INSERT_GAP * RADIUS
    cells = max(1, int(side / gap))
    h = side / cells
    grid: dict[tuple[int, int, int], list[int]] = {}
    rng = random.Random(seed)
    pts: list[tuple[float, float, float]] = []
    tries = 0
    while len(pts) < n:
        tries += 1
        if tries > 200 * n:
            sys.exit(f"error: random insertion of {n} spheres stalled at {len(pts)}")
        p = (rng.random() * side, rng.random() * side, RADIUS * 1.05 + rng.random() * height)
        c = (int(p[0] / h) % cells, int(p[1] / h) % cells, int(p[2] / h))
        ok = True
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                for dk in (-1, 0, 1):
                    for q in grid.get(((c[0] + di) % cells, (c[1] + dj) % cells, c[2] + dk), ()):
                        o = pts[q]
                        dx = p[0] - o[0]
                        dx -= side * round(dx / side)
                        dy = p[1] - o[1]
                        dy -= side * round(dy / side)
                        dz = p[2] - o[2]
                        if dx * dx + dy * dy + dz * dz < gap * gap:
                            ok = False
                            break
                    if not ok:
                        break
                if not ok:
                    break
            if not ok:
                break
        if ok:
            grid.setdefault(c, []).append(len(pts))
            pts.append(p)
    return side, pts


def cached_insertion(n: int, d: Path) -> tuple[float, list[tuple[float, float, float]]]:
    """The insertion of `insertion(n)`, kept in d/insert.csv (qdem's sample) so that a second
    run of the script (another part, more repeats) pours nothing again and draws nothing."""
    path = d / "insert.csv"
    if path.exists():
        pts = [(r[1], r[2], r[3]) for r in read_stones(path)]
        if len(pts) == n:
            return cell_side(n), pts
    side, pts = insertion(n)
    write_stones(path, pts)
    return side, pts


def pour_seconds(pts) -> float:
    """The fall time of the highest sphere of the insertion onto the floor."""
    top = max(p[2] for p in pts)
    return math.sqrt(2.0 * top / GRAVITY)


def write_stones(path: Path, centres) -> None:
    """Writes one-sphere stones (qdem's sample format) in the order given."""
    with open(path, "w") as f:
        f.write("stone,x,y,z,radius\n")
        for i, (x, y, z) in enumerate(centres, 1):
            f.write(f"{i},{x:.17e},{y:.17e},{z:.17e},{RADIUS:.17e}\n")


def read_stones(path: Path) -> list[tuple[int, float, float, float, float]]:
    """The rows (stone, x, y, z, radius) of a stones file."""
    rows = []
    with open(path) as f:
        f.readline()
        for line in f:
            if line.strip():
                s, x, y, z, r = line.split(",")
                rows.append((int(s), float(x), float(y), float(z), float(r)))
    return rows


# ----------------------------------------------------------------------------- qdem

def qdem_scene(side: float, dt, t_end: float, out: str, sample: str | None = None,
               start_from: str | None = None, granular_extra: str = "",
               checkpoint: bool = False) -> str:
    """A scene of the poured bed: the cell, the floor, the material and law of the benchmark."""
    dt_line = f'"{dt}"' if isinstance(dt, str) else fmt(dt)
    lines = [
        "# written by qdem-bench/scripts/poured_compare.py",
        "[run]", f"t_end = {fmt(t_end)}", f"dt = {dt_line}",
        f"gravity = [0.0, 0.0, {fmt(-GRAVITY)}]", f"probe_every = {fmt(t_end)}",
    ]
    if start_from:
        lines.append(f'start_from = "{start_from}"')
    lines += [
        "", "[[material]]", 'name = "glass"', f"density = {fmt(DENSITY)}",
        f"young = {fmt(YOUNG)}", f"poisson = {fmt(POISSON)}",
        "", "[contact]", 'law = "hertz-mindlin"', f"friction = {fmt(FRICTION)}",
        f"restitution = {fmt(RESTITUTION)}", f"skin = {fmt(SKIN)}",
        "", "[granular]", 'name = "bed"', 'material = "glass"',
    ]
    if sample:
        lines.append(f'sample = "{sample}"')
    if granular_extra:
        lines.append(granular_extra)
    lines += [
        "", "[periodic]", 'axes = "xy"', f"length = [{fmt(side)}, {fmt(side)}]",
        "origin = [0.0, 0.0, 0.0]",
        "", "[[wall]]", "point = [0.0, 0.0, 0.0]", "normal = [0.0, 0.0, 1.0]",
        "", "[output]", f'dir = "{out}"',
    ]
    if checkpoint:
        lines.append(f"checkpoint_every = {fmt(t_end)}")
    return "\n".join(lines) + "\n"


def qdem_run(exe: Path, scene: Path, threads: int, team: bool = False) -> dict:
    """Runs `qdem run` on a scene (with a step's parallel regions on a persistent team of
    threads, `QDEM_TEAM=1`, when `team`); returns the figures of its summary.json."""
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads), QDEM_TEAM="1" if team else "0")
    out = subprocess.run([str(exe), "run", str(scene), "--threads", str(threads), "--yes"],
                         cwd=scene.parent, capture_output=True, text=True, env=env)
    (scene.parent / (scene.stem + ".stdout")).write_text(out.stdout + out.stderr)
    if out.returncode != 0:
        sys.exit(f"error: qdem run {scene} failed (exit {out.returncode}):\n"
                 + (out.stdout + out.stderr)[-3000:])
    text = scene.read_text()
    d = re.search(r'^dir = "([^"]+)"', text, re.M).group(1)
    s = json.loads((scene.parent / d / "summary.json").read_text())
    c = s.get("contact", {})
    g = s.get("granular", {})
    return {"wall_s": s["wall_seconds"], "steps": s["steps"], "dt": s["dt"],
            "stable_dt": s.get("stable_dt"), "threads": s["threads"],
            "spheres": c.get("spheres"), "stones": g.get("stones"),
            "contacts": c.get("contacts"), "rebuilds": c.get("rebuilds"),
            "kinetic_energy": s["kinetic_energy"], "out": str(scene.parent / d)}


def qdem_pour(exe: Path, d: Path, side: float, pts, settle: float, threads: int) -> Path:
    """Pours the insertion (d/insert.csv) with qdem; returns the checkpoint of the settled bed."""
    t = pour_seconds(pts) + settle
    scene = d / "qdem_pour.toml"
    scene.write_text(qdem_scene(side, common_dt(), t, "qdem_pour", sample="insert.csv",
                                  checkpoint=True))
    log(f"qdem: pouring {len(pts)} spheres for {t:.3f} s")
    r = qdem_run(exe, scene, threads)
    log(f"qdem pour: {r['steps']} steps in {r['wall_s']:.1f} s, KE {r['kinetic_energy']:.3e} J, "
        f"{r['contacts']} contacts")
    return d / "qdem_pour" / "checkpoint.qdc"


def qdem_window(exe: Path, d: Path, side: float, steps: int, threads: int, dt, name: str,
                sample: str | None = "insert.csv", start_from: str | None = None,
                team: bool = False) -> dict:
    """Times `steps` steps of qdem (dt a number, or "auto" with a t_end of `steps` of the
    common step) from the checkpoint or a sample (on a team of threads when `team`)."""
    t_end = steps * (common_dt() if isinstance(dt, str) else dt)
    scene = d / f"{name}.toml"
    scene.write_text(qdem_scene(side, dt, t_end, name, sample=sample, start_from=start_from))
    return qdem_run(exe, scene, threads, team)


# ----------------------------------------------------------------------------- peers

def peer_meta(side: float, pts) -> dict:
    """The material, step and floor in the form of liggghts_compare.py's packing.json."""
    return {"youngs_modulus": YOUNG, "poisson_ratio": POISSON, "density": DENSITY,
            "friction": FRICTION, "restitution": RESTITUTION,
            "damping_ratio": damping_ratio(RESTITUTION), "gravity": [0.0, 0.0, -GRAVITY],
            "skin": SKIN, "dt": common_dt(),
            "walls": [{"point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}],
            "box_min": [0.0, 0.0, 0.0], "box_max": [side, side, max(p[2] for p in pts)]}


def write_data(path: Path, side: float, pts, title: str) -> None:
    """atom_style granular (LIGGGHTS) = sphere (LAMMPS): id type diameter density x y z."""
    top = max(p[2] for p in pts) + 4 * RADIUS
    with open(path, "w") as f:
        f.write(f"{title}\n\n{len(pts)} atoms\n2 atom types\n\n")
        f.write(f"0.0 {fmt(side)} xlo xhi\n0.0 {fmt(side)} ylo yhi\n")
        f.write(f"{fmt(-4 * RADIUS)} {fmt(top)} zlo zhi\n\nAtoms\n\n")
        for i, (x, y, z) in enumerate(pts, 1):
            f.write(f"{i} 1 {fmt(2 * RADIUS)} {fmt(DENSITY)} {fmt(x % side)} {fmt(y % side)} "
                    f"{fmt(z)}\n")


def fill(template: Path, subs: dict, out: Path) -> Path:
    text = template.read_text()
    for k, v in subs.items():
        text = text.replace(f"@{k}@", str(v))
    left = re.findall(r"@[A-Z_]+@", text)
    if left:
        sys.exit(f"error: unfilled placeholders in {template.name}: {left}")
    out.write_text(text)
    return out


def peer_subs(peer: str, meta: dict, side: float, dt: float) -> dict:
    """The placeholders both of a peer's decks share (the LAMMPS damping's reference overlap
    from a bed as high as the cell is wide)."""
    subs = {"SKIN": fmt(SKIN), "DT": fmt(dt), "G_MAG": fmt(GRAVITY),
            "WALL_OVERLAPS": lc.wall_overlaps(meta)}
    if peer == "liggghts":
        subs.update({"E": fmt(YOUNG), "E_WALL": fmt(YOUNG * lc.E_WALL_FACTOR),
                     "NU": fmt(POISSON), "REST": fmt(lc.restitution(meta)),
                     "MU": fmt(FRICTION)})
    else:
        bed = [(0.0, 0.0, RADIUS, RADIUS), (0.0, 0.0, side - RADIUS, RADIUS)]  # the settled height
        pair = pc.lammps_coefficients(meta, bed, False)
        wall = pc.lammps_coefficients(meta, bed, True)
        subs.update({"KN": fmt(pair["kn"]), "KT": fmt(pair["kt"]), "GN": fmt(pair["gn"]),
                     "GT": fmt(pair["gt"]), "WKN": fmt(wall["kn"]), "WKT": fmt(wall["kt"]),
                     "WGN": fmt(wall["gn"]), "WGT": fmt(wall["gt"]), "MU": fmt(FRICTION),
                     "DELTA_REF": f"{pair['delta_ref']:.4g}"})
    return subs


def run_deck(exe: str, launcher: list[str], deck: Path, n: int) -> dict:
    """Runs a deck; returns the first run's loop time and the thermo of the last `Step` header
    that has the contact sums (the untimed `run 0` at the end)."""
    cmd = [*launcher, exe, "-in", deck.name, "-log", "none", "-nocite"]
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_MCA_btl_vader_single_copy_mechanism="none")
    p = subprocess.run(cmd, cwd=deck.parent, capture_output=True, text=True, env=env)
    (deck.parent / (deck.name + ".stdout")).write_text(p.stdout + p.stderr)
    if p.returncode != 0:
        sys.exit(f"error: {' '.join(cmd)} failed (exit {p.returncode}) in {deck.parent}:\n"
                 + (p.stdout + p.stderr)[-3000:])
    loops = lc.LOOP_RE.findall(p.stdout)
    if not loops:
        sys.exit(f"error: no 'Loop time' line in {deck.parent}/{deck.name}.stdout")
    t, procs, steps, atoms = loops[0]
    final = lc.final_thermo(p.stdout)
    r = {"wall_s": float(t), "procs": int(procs), "steps": int(steps), "atoms": int(atoms)}
    if final is not None:
        left = int(final["Atoms"])
        if left != n:
            sys.exit(f"error: {deck} ends with {left} of {n} spheres")
        if final["zlo"] < -RADIUS:
            sys.exit(f"error: {deck}: a sphere fell through the floor (z = {final['zlo']})")
        r.update({"contacts": int(round(final["csum"] / 2)) + int(round(final["wsum"])),
                  "sphere_sphere_contacts": int(round(final["csum"] / 2)),
                  "sphere_wall_contacts": int(round(final["wsum"])),
                  "kinetic_energy": final["ket"] + final["erot"]})
    return r


def peer_pour(peer: str, exe: str, d: Path, side: float, pts, settle: float, width: int) -> Path:
    """Pours the insertion with a peer; returns its restart file of the settled bed."""
    pd = d / peer
    pd.mkdir(exist_ok=True)
    meta = peer_meta(side, pts)
    write_data(pd / "insert.data", side, pts, f"{peer} poured bed, poured_compare.py")
    steps = math.ceil((pour_seconds(pts) + settle) / common_dt())
    subs = dict(peer_subs(peer, meta, side, common_dt()), DATA="insert.data",
                POUR_STEPS=steps, RESTART="settled.restart", THERMO=max(1000, steps // 10))
    deck = fill(HERE / peer / "pour.in.template", subs, pd / "in.pour")
    log(f"{peer}: pouring {len(pts)} spheres for {steps} steps on {width} ranks")
    r = run_deck(exe, pc_launcher(width), deck, len(pts))
    log(f"{peer} pour: {r['steps']} steps in {r['wall_s']:.1f} s")
    return pd / "settled.restart"


def peer_window(peer: str, exe: str, d: Path, side: float, pts, steps: int, width: int) -> dict:
    """Times `steps` steps of a peer from its settled bed on `width` MPI ranks."""
    pd = d / peer
    meta = peer_meta(side, pts)
    subs = dict(peer_subs(peer, meta, side, common_dt()), RESTART="settled.restart",
                STEPS=steps, THERMO=max(1000, steps // 4))
    deck = fill(HERE / peer / "settled.in.template", subs, pd / "in.settled")
    return run_deck(exe, pc_launcher(width), deck, len(pts))


def pc_launcher(width: int) -> list[str]:
    """The mpirun prefix for `width` ranks (none for one)."""
    return lc.mpi_launcher(width)[0]


def has_style(exe: str, style: str) -> bool:
    """Whether the LIGGGHTS binary lists `style` among its styles."""
    out = subprocess.run([exe, "-log", "none", "-h"], capture_output=True, text=True,
                         timeout=60).stdout
    return re.search(rf"\b{re.escape(style)}\b", out) is not None


# ----------------------------------------------------------------------------- parts

def part_pour(args, n, d, side, pts, qdem, peers, rows) -> None:
    """Each code pours the insertion (unless an earlier run left its settled bed), then the
    timed windows from the settled beds; one row per code and width."""
    if not (d / "qdem_pour" / "checkpoint.qdc").exists():
        qdem_pour(qdem, d, side, pts, args.settle, max(args.np))
    for peer, exe in peers.items():
        if not (d / peer / "settled.restart").exists():
            peer_pour(peer, exe, d, side, pts, args.settle, max(args.np))
    for width in args.np:
        qdem_runs = [(code, lambda team=team: qdem_window(
            qdem, d, side, args.steps, width, common_dt(), "qdem_settled" + "_team" * team,
            sample="insert.csv", start_from="qdem_pour/checkpoint.qdc", team=team))
            for code, team in team_codes(args)]
        peer_runs = [(peer, lambda peer=peer, exe=exe: peer_window(
            peer, exe, d, side, pts, args.steps, width)) for peer, exe in peers.items()]
        runs = timed_windows(args, qdem_runs + peer_runs, f"n={n} width={width}")
        rows += window_rows("pour", n, args.steps, width, runs)


def team_codes(args) -> list[tuple[str, bool]]:
    """qdem's codes and whether each runs on the team: `qdem`, and `qdem_team` with --team."""
    return [("qdem", False), ("qdem_team", True)][:1 + args.team]


def timed_windows(args, windows, label: str) -> dict[str, list]:
    """Runs `--repeats` rounds of the (code, run) windows in turn, each after the machine is
    idle if `--wait-idle`; per code its results with the cores other processes kept busy."""
    runs: dict[str, list] = {}
    for _ in range(args.repeats):
        for code, run in windows:
            if args.wait_idle:
                lc.wait_idle(args.wait_idle)
            with lc.OtherLoad() as ol:
                r = run()
            runs.setdefault(code, []).append((r, ol.cores))
            log(f"{code} {label}: {r['wall_s']:.3f} s")
    return runs


def window_rows(part: str, n: int, steps: int, width: int, runs: dict[str, list]) -> list[dict]:
    """One row per code of `timed_windows`' runs: the fastest, with every run's wall time."""
    rows = []
    for code, rs in runs.items():
        r, _ = min(rs, key=lambda t: t[0]["wall_s"])
        rows.append({"part": part, "code": code, "spheres": n, "width": width,
                     "steps": steps, "dt": common_dt(), "wall_s": r["wall_s"],
                     "particle_steps_per_s": n * steps / r["wall_s"],
                     "contacts": r.get("contacts"), "kinetic_energy": r.get("kinetic_energy"),
                     "all_wall_s": [t[0]["wall_s"] for t in rs],
                     "other_cores_during": [round(t[1], 2) for t in rs]})
    return rows

def orders(rows_in, side: float, seed: int = 7) -> dict[str, list]:
    """The three orders of the settled bed's rows."""
    h = 2 * RADIUS

    def key(r):
        x, y, z = r[1] % side, r[2] % side, r[3]
        return (int(z / h), int(y / h), int(x / h))
    shuffled = list(rows_in)
    random.Random(seed).shuffle(shuffled)
    return {"lattice": sorted(rows_in, key=key), "poured": list(rows_in), "random": shuffled}


def part_order(args, n, d, side, qdem, rows) -> None:
    """qdem on its settled positions in three orders; one row per order and width."""
    stones = d / "qdem_pour" / "stones.csv"
    if not stones.exists():
        sys.exit(f"error: the order part needs {stones} (run the pour part first)")
    settled = read_stones(stones)
    for name, rs in orders(settled, side).items():
        write_stones(d / f"order_{name}.csv", [(r[1], r[2], r[3]) for r in rs])
    for width in args.np:
        runs: dict[str, list] = {}
        for _ in range(args.repeats):
            for name in ("lattice", "poured", "random"):
                q = qdem_window(qdem, d, side, args.steps, width, common_dt(), f"qdem_{name}",
                                sample=f"order_{name}.csv")
                runs.setdefault(name, []).append(q)
                log(f"qdem order {name} n={n} width={width}: {q['wall_s']:.3f} s")
        best = {k: min(v, key=lambda q: q["wall_s"]) for k, v in runs.items()}
        fastest = min(q["wall_s"] for q in best.values())
        for name, q in best.items():
            rows.append({"part": "order", "code": "qdem", "order": name, "spheres": n,
                         "width": width, "steps": args.steps, "dt": q["dt"],
                         "wall_s": q["wall_s"], "particle_steps_per_s": n * args.steps / q["wall_s"],
                         "slower_than_fastest_order": q["wall_s"] / fastest,
                         "contacts": q["contacts"], "kinetic_energy": q["kinetic_energy"],
                         "all_wall_s": [r["wall_s"] for r in runs[name]]})


def part_second(args, n, d, side, qdem, rows) -> None:
    """qdem at its own step; the peers' figure comes from the pour part's rows (their step is
    the common 20% of the Rayleigh time)."""
    for width in args.np:
        runs = []
        for _ in range(args.repeats):
            q = qdem_window(qdem, d, side, args.steps, width, "auto", "qdem_auto",
                            sample="insert.csv", start_from="qdem_pour/checkpoint.qdc")
            runs.append(q)
        q = min(runs, key=lambda r: r["wall_s"] / r["steps"])
        rows.append({"part": "second", "code": "qdem", "spheres": n, "width": width,
                     "steps": q["steps"], "dt": q["dt"], "stable_dt": q["stable_dt"],
                     "wall_s": q["wall_s"], "seconds_per_simulated_second":
                         q["wall_s"] / q["steps"] / q["dt"],
                     "contacts": q["contacts"], "kinetic_energy": q["kinetic_energy"]})
        for r in [r for r in rows if r["part"] == "pour" and r["spheres"] == n
                  and r["width"] == width and not r["code"].startswith("qdem")]:
            rows.append({"part": "second", "code": r["code"], "spheres": n, "width": width,
                         "steps": r["steps"], "dt": r["dt"], "wall_s": r["wall_s"],
                         "seconds_per_simulated_second": r["wall_s"] / r["steps"] / r["dt"],
                         "contacts": r["contacts"], "kinetic_energy": r["kinetic_energy"]})


def tiled_positions(rows, side: float, k: int) -> list[tuple[float, float, float]]:
    """The settled rows copied k x k times across the periodic cell, copy after copy, each in
    its poured order."""
    return [((r[1] % side) + i * side, (r[2] % side) + j * side, r[3])
            for j in range(k) for i in range(k) for r in rows]


def window_deck(peer: str) -> str:
    """A peer's deck that times a window from a data file: the pour deck's set-up with the
    settled deck's thermo, timed run and untimed contact count."""
    pour = (HERE / peer / "pour.in.template").read_text()
    settled = (HERE / peer / "settled.in.template").read_text()
    return pour[:pour.index("thermo_style")] + settled[settled.index("variable zlo"):]


def part_tiled(args, n, d, side, qdem, peers, rows) -> None:
    """All three codes time a window from qdem's settled bed copied `--tile` x `--tile` times;
    one row per code and width."""
    stones = d / "qdem_pour" / "stones.csv"
    if not stones.exists():
        sys.exit(f"error: the tiled part needs {stones} (run the pour part first)")
    k = args.tile
    pts = tiled_positions(read_stones(stones), side, k)
    big = k * side
    td = d.parent / f"n{n}_tiled{k}"
    td.mkdir(parents=True, exist_ok=True)
    write_stones(td / "tiled.csv", pts)
    for peer in peers:
        (td / peer).mkdir(exist_ok=True)
        write_data(td / peer / "tiled.data", big, pts, f"{peer} tiled bed, poured_compare.py")
    log(f"tiled: {len(pts)} spheres ({k} x {k} copies of {n}), cell {big:.4f} m")
    for peer in peers:
        (td / peer / "tiled.in.template").write_text(window_deck(peer))
    # the bed is as high as the copied one (`side`): its height sets LAMMPS's damping
    subs = {peer: dict(peer_subs(peer, peer_meta(big, pts), side, common_dt()),
                       DATA="tiled.data", STEPS=args.steps, THERMO=max(1000, args.steps // 4))
            for peer in peers}
    for width in args.np:
        qdem_runs = [(code, lambda team=team: qdem_window(
            qdem, td, big, args.steps, width, common_dt(), "qdem_tiled" + "_team" * team,
            sample="tiled.csv", team=team)) for code, team in team_codes(args)]
        peer_runs = [(peer, lambda peer=peer, exe=exe: run_deck(
            exe, pc_launcher(width),
            fill(td / peer / "tiled.in.template", subs[peer], td / peer / "in.tiled"), len(pts)))
            for peer, exe in peers.items()]
        runs = timed_windows(args, qdem_runs + peer_runs, f"tiled n={len(pts)} width={width}")
        rows += window_rows("tiled", len(pts), args.steps, width, runs)

CLUMP_RADIUS = 0.004    # the clumps' spheres (m)


def clump_templates() -> dict[int, list[tuple[float, float, float]]]:
    """Sphere centres of the 2- to 6-sphere clumps, arm a = r from the clump's centre (members
    overlap): a segment, triangle, tetrahedron, triangular bipyramid and octahedron; the
    bounding radius of every one is 2 r."""
    a = CLUMP_RADIUS
    s3, t = math.sqrt(3.0) / 2.0, 1.0 / math.sqrt(3.0)
    tri = [(a, 0.0, 0.0), (-a / 2, a * s3, 0.0), (-a / 2, -a * s3, 0.0)]
    return {2: [(a, 0.0, 0.0), (-a, 0.0, 0.0)], 3: tri,
            4: [(a * t, a * t, a * t), (a * t, -a * t, -a * t), (-a * t, a * t, -a * t),
                (-a * t, -a * t, a * t)],
            5: tri + [(0.0, 0.0, a), (0.0, 0.0, -a)],
            6: [(a, 0, 0), (-a, 0, 0), (0, a, 0), (0, -a, 0), (0, 0, a), (0, 0, -a)]}


def rotate(q, v):
    """v turned by the unit quaternion q = (w, x, y, z)."""
    w, x, y, z = q
    tx, ty, tz = 2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0])
    return (v[0] + w * tx + y * tz - z * ty, v[1] + w * ty + z * tx - x * tz,
            v[2] + w * tz + x * ty - y * tx)


def clump_insertion(n_spheres: int, side: float, seed: int = 57):
    """Clumps of 2-6 spheres (the k-th drawn has 2 + k mod 5) turned at random, their bounding
    spheres placed by random sequential addition in the cell (as `insertion`), until the clumps
    hold about n_spheres spheres. Returns the stones (lists of centres) in the order drawn."""
    templates = clump_templates()
    count = max(1, round(n_spheres / 4))
    bound = 2 * CLUMP_RADIUS
    v = 4.0 / 3.0 * math.pi * bound ** 3
    height = count * v / (INSERT_FRACTION * side * side)
    gap = 2.1 * bound
    cells = max(1, int(side / gap))
    h = side / cells
    rng = random.Random(seed)
    grid: dict[tuple[int, int, int], list[int]] = {}
    centres: list[tuple[float, float, float]] = []
    while len(centres) < count:
        p = (rng.random() * side, rng.random() * side, bound * 1.05 + rng.random() * height)
        c = (int(p[0] / h) % cells, int(p[1] / h) % cells, int(p[2] / h))
        near = (centres[k] for di in (-1, 0, 1) for dj in (-1, 0, 1) for dk in (-1, 0, 1)
                for k in grid.get(((c[0] + di) % cells, (c[1] + dj) % cells, c[2] + dk), ()))
        if all(((p[0] - o[0] + side / 2) % side - side / 2) ** 2
               + ((p[1] - o[1] + side / 2) % side - side / 2) ** 2 + (p[2] - o[2]) ** 2
               >= gap * gap for o in near):
            grid.setdefault(c, []).append(len(centres))
            centres.append(p)
    stones = []
    for i, c in enumerate(centres):
        q = [rng.gauss(0, 1) for _ in range(4)]
        norm = math.sqrt(sum(x * x for x in q))
        q = [x / norm for x in q]
        stones.append([tuple(c[k] + d[k] for k in range(3))
                       for d in (rotate(q, m) for m in templates[2 + i % 5])])
    return stones


# LIGGGHTS takes large primes as seeds (15485867 aborts the template without a message)
TEMPLATE_SEEDS = {2: 15485863, 3: 49979687, 4: 67867967, 5: 86028121, 6: 104395301}


def clump_dt() -> float:
    return 0.2 * rayleigh_time(CLUMP_RADIUS)


def write_clump_stones(path: Path, stones) -> None:
    with open(path, "w") as f:
        f.write("stone,x,y,z,radius\n")
        for i, st in enumerate(stones, 1):
            for (x, y, z) in st:
                f.write(f"{i},{x:.17e},{y:.17e},{z:.17e},{CLUMP_RADIUS:.17e}\n")


def liggghts_clumps(exe: str, cd: Path, side: float, stones, settle: float, steps: int,
                    repeats: int, width: int) -> list[dict]:
    """LIGGGHTS's `fix multisphere` pours as many clumps of the same templates (insert/pack,
    its own random insertion, the same weights) in the same cell and times `repeats`
    consecutive windows of `steps` from the settled bed. Returns one record per window."""
    ld = cd / f"liggghts_np{width}"
    ld.mkdir(exist_ok=True)
    top = max(p[2] for st in stones for p in st) + CLUMP_RADIUS
    meta = peer_meta(side, [(0.0, 0.0, top)])
    temps = []
    for k, members in clump_templates().items():
        spheres = " ".join(f"{fmt(x)} {fmt(y)} {fmt(z)} {fmt(CLUMP_RADIUS)}" for x, y, z in members)
        temps.append(f"fix t{k} all particletemplate/multisphere {TEMPLATE_SEEDS[k]} atom_type 1 "
                     f"density constant {fmt(DENSITY)} nspheres {k} ntry 1000000 spheres {spheres} "
                     f"type {k - 1}")  # each template its own body type
    dist = " ".join(f"t{k} 0.2" for k in clump_templates())
    pour_steps = math.ceil((math.sqrt(2.0 * top / GRAVITY) + settle) / clump_dt())
    subs = dict(peer_subs("liggghts", meta, side, clump_dt()), SIDE=fmt(side),
                ZLO=fmt(-4 * CLUMP_RADIUS), ZHI=fmt(top + 4 * CLUMP_RADIUS),
                INS_LO=fmt(CLUMP_RADIUS), INS_HI=fmt(top), TEMPLATES="\n".join(temps),
                DIST=f"fix pdd all particledistribution/discrete/numberbased 32452843 5 {dist}",
                CLUMPS=len(stones), POUR_STEPS=pour_steps, STEPS=steps,
                THERMO=max(1000, pour_steps // 10),
                WINDOWS="\n".join(f"run             {steps}" for _ in range(repeats)))
    deck = fill(HERE / "liggghts" / "clumps.in.template", subs, ld / "in.clumps")
    cmd = [*pc_launcher(width), exe, "-in", deck.name, "-log", "none", "-nocite"]
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_MCA_btl_vader_single_copy_mechanism="none")
    p = subprocess.run(cmd, cwd=ld, capture_output=True, text=True, env=env)
    (ld / "in.clumps.stdout").write_text(p.stdout + p.stderr)
    if p.returncode != 0:
        sys.exit(f"error: LIGGGHTS multisphere failed (exit {p.returncode}) in {ld}:\n"
                 + (p.stdout + p.stderr)[-3000:])
    loops = lc.LOOP_RE.findall(p.stdout)
    windows = [lp for lp in loops if int(lp[2]) == steps][:repeats]
    final = lc.final_thermo(p.stdout)
    if final is None:
        sys.exit(f"error: no final thermo line in {ld}/in.clumps.stdout")
    return [{"wall_s": float(t), "procs": int(pr), "steps": int(st), "atoms": int(at),
             "contacts": int(round(final["csum"] / 2)) + int(round(final["wsum"])),
             "kinetic_energy": final["ket"] + final["erot"]}
            for t, pr, st, at in windows]


def part_clumps(args, n, d, side, qdem, liggghts, rows) -> None:
    """qdem's clump bed beside LIGGGHTS's multisphere one; one row per code and width."""
    cd = d / "clumps"
    cd.mkdir(exist_ok=True)
    stones = clump_insertion(n, side)
    spheres = sum(len(st) for st in stones)
    ckpt = cd / "qdem_pour" / "checkpoint.qdc"
    if not ckpt.exists():
        write_clump_stones(cd / "insert.csv", stones)
        top = max(p[2] for st in stones for p in st)
        t = math.sqrt(2.0 * top / GRAVITY) + args.settle
        scene = cd / "qdem_pour.toml"
        scene.write_text(qdem_scene(side, clump_dt(), t, "qdem_pour", sample="insert.csv",
                                    checkpoint=True))
        log(f"qdem: pouring {len(stones)} clumps ({spheres} spheres) for {t:.3f} s")
        r = qdem_run(qdem, scene, max(args.np))
        log(f"qdem clump pour: {r['steps']} steps, KE {r['kinetic_energy']:.3e} J")
    multisphere = bool(liggghts) and has_style(liggghts, "multisphere")
    for width in args.np:
        runs: dict[str, list] = {"qdem": []}
        for _ in range(args.repeats):
            scene = cd / "qdem_settled.toml"
            scene.write_text(qdem_scene(side, clump_dt(), args.steps * clump_dt(),
                                        "qdem_settled", sample="insert.csv",
                                        start_from="qdem_pour/checkpoint.qdc"))
            runs["qdem"].append(qdem_run(qdem, scene, width))
        if multisphere:
            runs["liggghts"] = liggghts_clumps(liggghts, cd, side, stones, args.settle,
                                               args.steps, args.repeats, width)
        for code, rs in runs.items():
            r = min(rs, key=lambda x: x["wall_s"])
            count = spheres if code == "qdem" else r["atoms"]
            rows.append({"part": "clumps", "code": code, "spheres": count,
                         "clumps": len(stones), "width": width, "steps": args.steps,
                         "dt": clump_dt(), "wall_s": r["wall_s"],
                         "particle_steps_per_s": count * args.steps / r["wall_s"],
                         "clump_steps_per_s": len(stones) * args.steps / r["wall_s"],
                         "contacts": r["contacts"], "kinetic_energy": r["kinetic_energy"],
                         "all_wall_s": [x["wall_s"] for x in rs]})
    if not multisphere:
        rows.append({"part": "clumps", "code": "liggghts", "missing":
                     "the installed LIGGGHTS has no `fix multisphere`: no peer row"})


# ----------------------------------------------------------------------------- report

def markdown(rows: list[dict]) -> str:
    """The tables of the rows, one per part."""
    out = []
    for part in ("pour", "tiled"):
        pour = [r for r in rows if r["part"] == part]
        if not pour:
            continue
        out += [f"{part}:", "", "| spheres | threads / ranks | code | wall (s) | particle-steps/s "
                "| contacts at end | KE at end (J) | qdem / code |",
                "| --- | --- | --- | --- | --- | --- | --- | --- |"]
        for r in pour:
            q = next(x for x in pour if x["code"] == "qdem" and x["spheres"] == r["spheres"]
                     and x["width"] == r["width"])
            out.append(f"| {r['spheres']:,} | {r['width']} | {r['code']} | {r['wall_s']:.3f} | "
                       f"{r['particle_steps_per_s']:.3e} | {r['contacts']} | "
                       f"{r['kinetic_energy']:.4g} | "
                       f"{q['particle_steps_per_s'] / r['particle_steps_per_s']:.2f} |")
        out.append("")
    order = [r for r in rows if r["part"] == "order"]
    if order:
        out += ["| spheres | threads | order | wall (s) | particle-steps/s | / fastest order |",
                "| --- | --- | --- | --- | --- | --- |"]
        for r in order:
            out.append(f"| {r['spheres']:,} | {r['width']} | {r['order']} | {r['wall_s']:.3f} | "
                       f"{r['particle_steps_per_s']:.3e} | {r['slower_than_fastest_order']:.3f} |")
        out.append("")
    second = [r for r in rows if r["part"] == "second"]
    if second:
        out += ["| spheres | threads / ranks | code | dt (s) | wall s per simulated s | "
                "contacts | KE (J) |", "| --- | --- | --- | --- | --- | --- | --- |"]
        for r in second:
            out.append(f"| {r['spheres']:,} | {r['width']} | {r['code']} | {r['dt']:.4g} | "
                       f"{r['seconds_per_simulated_second']:.1f} | {r['contacts']} | "
                       f"{r['kinetic_energy']:.4g} |")
        out.append("")
    clumps = [r for r in rows if r["part"] == "clumps" and "wall_s" in r]
    if clumps:
        out += ["| clumps | spheres | threads / ranks | code | wall (s) | sphere-steps/s | "
                "clump-steps/s | contacts | KE (J) |",
                "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for r in clumps:
            out.append(f"| {r['clumps']:,} | {r['spheres']:,} | {r['width']} | {r['code']} | "
                       f"{r['wall_s']:.3f} | {r['particle_steps_per_s']:.3e} | "
                       f"{r['clump_steps_per_s']:.3e} | {r['contacts']} | "
                       f"{r['kinetic_energy']:.4g} |")
        out.append("")
    return "\n".join(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spheres", default="10000,100000",
                    help="comma-separated sphere counts (1000000 as an option)")
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--np", default="1,2")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--parts", default="pour,order,second,clumps")
    ap.add_argument("--qdem", default=str(ROOT / "target" / "release" / "qdem"))
    ap.add_argument("--work", default="out/poured")
    ap.add_argument("--settle", type=float, default=0.25,
                    help="seconds of settling after the highest sphere's fall")
    ap.add_argument("--peers", default="liggghts,lammps")
    ap.add_argument("--tile", type=int, default=3,
                    help="copies of the settled bed along x and along y (the tiled part)")
    ap.add_argument("--wait-idle", type=float, default=0.0)
    ap.add_argument("--team", action="store_true",
                    help="in the pour and tiled parts, also time qdem with QDEM_TEAM=1 "
                         "(code qdem_team), "
                         "alternated with the default")
    args = ap.parse_args()
    args.np = [int(s) for s in args.np.split(",")]
    parts = set(args.parts.split(","))
    work = Path(args.work) if Path(args.work).is_absolute() else ROOT / args.work
    work.mkdir(parents=True, exist_ok=True)
    qdem = work / "qdem"  # a private copy: a rebuild meanwhile changes nothing
    shutil.copy2(args.qdem, qdem)
    peers = {}
    if "liggghts" in args.peers:
        peers["liggghts"] = lc.ensure_liggghts()
    if "lammps" in args.peers:
        peers["lammps"] = pc.ensure_lammps()
    versions = {"qdem": subprocess.run(["git", "describe", "--always", "--dirty"], cwd=ROOT,
                                       capture_output=True, text=True).stdout.strip()}
    if "liggghts" in peers:
        versions["liggghts"] = lc.liggghts_version(peers["liggghts"])
    if "lammps" in peers:
        versions["lammps"] = pc.lammps_version(peers["lammps"])
    rows: list[dict] = []
    beds = {}
    for n in [int(s) for s in args.spheres.split(",")]:
        d = work / f"n{n}"
        d.mkdir(parents=True, exist_ok=True)
        side, pts = cached_insertion(n, d)
        beds[n] = {"side": side, "insert_top": max(p[2] for p in pts),
                   "pour_seconds": pour_seconds(pts) + args.settle}
        if "pour" in parts or "second" in parts:
            part_pour(args, n, d, side, pts, qdem, peers, rows)
        if "order" in parts:
            part_order(args, n, d, side, qdem, rows)
        if "second" in parts:
            part_second(args, n, d, side, qdem, rows)
        if "tiled" in parts:
            part_tiled(args, n, d, side, qdem, peers, rows)
        if "clumps" in parts:
            part_clumps(args, n, d, side, qdem, peers.get("liggghts"), rows)
    section = markdown(rows)
    doc = {"machine": lc.cpu_model(), "cores": os.cpu_count(), "versions": versions,
           "common_dt": common_dt(), "rayleigh_time": rayleigh_time(), "beds": beds,
           "rows": rows}
    (work / "poured_compare.json").write_text(json.dumps(doc, indent=2) + "\n")
    (work / "poured_section.md").write_text(section)
    print(section)


if __name__ == "__main__":
    main()
