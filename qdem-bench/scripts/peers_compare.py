#!/usr/bin/env python3
"""Side-by-side DEM throughput on one settled packing: qdem (this build and, optionally, an
older `study` binary) against LIGGGHTS 3.8 and LAMMPS, alternating in one run.

Usage (from the workspace root, after `cargo build --release -p qdem-bench --bin study`):

    python3 qdem-bench/scripts/peers_compare.py [--spheres 10000] [--steps 2000]
        [--np 1,2] [--repeats 2] [--old OLD/study] [--work out/peers] [--wait-idle 0]

For each sphere count N the packing WORK/nN (made by `study packing` if missing) is timed by
every code on 1 and 2 threads / MPI ranks, the codes alternating `--repeats` times; the
fastest run of each counts. LIGGGHTS runs the deck of liggghts_compare.py; LAMMPS the deck
qdem-bench/scripts/lammps/bench.in.template: `pair_style gran/hertz/history` with
kn = 4/3 E*, kt = 8 G*, `newton off`, the walls as `fix wall/gran` planes (rigid: E* = E/(1-nu^2)).
LAMMPS's damping grows as sqrt(delta) where qdem's and LIGGGHTS's grow as delta^(1/4), so its
gamma_n, gamma_t give qdem's damping at a reference overlap (the Hertz overlap under the weight
of half the bed's height of spheres). Both peers' time is their `Loop time`; qdem's the
`wall_s` of `dem-throughput`. The rows go to WORK/peers_compare.json and a markdown table to
stdout and WORK/peers_section.md.

The Debian packages `liggghts` and `lammps` are installed if missing.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import liggghts_compare as lc  # noqa: E402

ROOT = lc.ROOT
LAMMPS_TEMPLATE = Path(__file__).resolve().parent / "lammps" / "bench.in.template"
DAMPING_PREFACTOR = 2.0 * math.sqrt(5.0 / 6.0)


def log(msg: str) -> None:
    print(f"[peers_compare] {msg}", file=sys.stderr, flush=True)


def ensure_lammps() -> str:
    exe = shutil.which("lmp") or shutil.which("lmp_serial")
    if exe is None:
        log("LAMMPS not found: installing the Debian package 'lammps'")
        pre = [] if os.geteuid() == 0 else ["sudo"]
        env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
        lc.sh(pre + ["apt-get", "install", "-y", "-qq", "--no-install-recommends", "lammps"], env=env)
        exe = shutil.which("lmp")
    if exe is None:
        sys.exit("error: no LAMMPS binary (lmp) after installing the 'lammps' package")
    return exe


def lammps_version(exe: str) -> str:
    out = subprocess.run([exe, "-h"], capture_output=True, text=True, timeout=60).stdout
    m = re.search(r"Simulator - ([^\n]+)", out)
    pkg = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "lammps"],
                         capture_output=True, text=True).stdout.strip()
    v = m.group(1).strip() if m else "unknown"
    return f"{v} (Debian package lammps {pkg})" if pkg else v


def stars(e: float, nu: float, wall: bool) -> tuple[float, float]:
    """E* and G* of two spheres of (E, nu), or of a sphere on a rigid wall (qdem's
    PairElasticity: 1/E* = sum (1 - nu^2)/E, 1/G* = sum 2 (2 - nu)(1 + nu)/E)."""
    sides = 1 if wall else 2
    return e / (sides * (1 - nu * nu)), e / (sides * 2 * (2 - nu) * (1 + nu))


def lammps_coefficients(meta: dict, spheres, wall: bool) -> dict:
    e, nu, rho = meta["youngs_modulus"], meta["poisson_ratio"], meta["density"]
    r = max(s[3] for s in spheres)
    m = rho * 4.0 / 3.0 * math.pi * r ** 3
    e_star, g_star = stars(e, nu, wall)
    r_star, m_star = (r, m) if wall else (r / 2, m / 2)
    g = math.sqrt(sum(c * c for c in meta["gravity"]))
    height = max(s[2] for s in spheres) - min(s[2] for s in spheres) + 2 * r
    load = m * max(g, 1e-12) * max(1.0, 0.5 * height / (2 * r))
    delta = (3 * load / (4 * e_star * math.sqrt(r_star))) ** (2 / 3)
    zeta = meta.get("damping_ratio", 0.0)
    root = math.sqrt(r_star * delta)
    gamma = [DAMPING_PREFACTOR * zeta * math.sqrt(k * root * m_star) / (m_star * root)
             for k in (2 * e_star, 8 * g_star)]
    return {"kn": 4 / 3 * e_star, "kt": 8 * g_star, "gn": gamma[0], "gt": gamma[1],
            "delta_ref": delta}


def write_lammps_inputs(meta: dict, spheres, steps: int, d: Path) -> Path:
    lc.write_liggghts_inputs(meta, spheres, steps, d)  # the data file (atom_style granular = sphere)
    data = d / "lammps.data"
    data.write_text((d / "liggghts.data").read_text())
    pair, wall = lammps_coefficients(meta, spheres, False), lammps_coefficients(meta, spheres, True)
    fmt = lc.fmt
    walls = []
    for i, w in enumerate(meta["walls"]):
        a = next(k for k in range(3) if abs(w["normal"][k]) > 1e-12)
        p = fmt(w["point"][a])
        lo_hi = f"{p} NULL" if w["normal"][a] > 0 else f"NULL {p}"
        walls.append(f"fix wall{i} all wall/gran hertz/history {fmt(wall['kn'])} {fmt(wall['kt'])} "
                     f"{fmt(wall['gn'])} {fmt(wall['gt'])} {fmt(meta['friction'])} 1 "
                     f"{'xyz'[a]}plane {lo_hi}")
    g = meta["gravity"]
    gmag = math.sqrt(sum(c * c for c in g))
    grid = ["*", "*", "*"]
    if gmag > 0:
        grid[max(range(3), key=lambda k: abs(g[k]))] = "1"
    subs = {
        "PROCS": " ".join(grid), "DATA": data.name, "SKIN": fmt(meta["skin"]),
        "KN": fmt(pair["kn"]), "KT": fmt(pair["kt"]), "GN": fmt(pair["gn"]),
        "GT": fmt(pair["gt"]), "MU": fmt(meta["friction"]), "DT": fmt(meta["dt"]),
        "G_MAG": fmt(gmag),
        "G_DIR": " ".join(fmt(c / gmag) for c in g) if gmag > 0 else "0.0 0.0 -1.0",
        "WALLS": "\n".join(walls), "WALL_OVERLAPS": lc.wall_overlaps(meta),
        "THERMO": str(max(1000, steps // 4)), "STEPS": str(steps),
        "DELTA_REF": f"{pair['delta_ref']:.4g}",
    }
    text = LAMMPS_TEMPLATE.read_text()
    for k, v in subs.items():
        text = text.replace(f"@{k}@", v)
    left = re.findall(r"@[A-Z_]+@", text)
    if left:
        sys.exit(f"error: unfilled placeholders in the LAMMPS deck: {left}")
    deck = d / "in.lammps"
    deck.write_text(text)
    return deck


def run_peer(exe: str, launcher: list[str], deck: Path, meta: dict, spheres, name: str) -> dict:
    """Runs LIGGGHTS or LAMMPS on `deck` (both print the same "Loop time" and thermo lines)."""
    out = deck.parent / name
    out.mkdir(exist_ok=True)
    for f in deck.parent.glob("*.data"):
        shutil.copy2(f, out / f.name)
    local = out / "in.bench"
    shutil.copy2(deck, local)
    return lc.run_liggghts(exe, launcher, local, meta, spheres)


def qdem_throughput(exe: Path, d: Path, steps: int, threads: int) -> dict:
    out = lc.sh([str(exe), "dem-throughput", "--packing", str(d), "--steps", str(steps)],
                cwd=ROOT, capture_output=True,
                env=dict(os.environ, RAYON_NUM_THREADS=str(threads))).stdout
    for line in reversed(out.strip().splitlines()):
        if line.strip().startswith("{"):
            return json.loads(line)
    sys.exit(f"error: no JSON object on {exe} dem-throughput's stdout")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spheres", default="10000")
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--np", default="1,2")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--new", default=str(ROOT / "target" / "release" / "study"))
    ap.add_argument("--old", default=None, help="an older study binary, timed beside this one")
    ap.add_argument("--work", default="out/peers")
    ap.add_argument("--wait-idle", type=float, default=0.0)
    args = ap.parse_args()
    work = Path(args.work) if Path(args.work).is_absolute() else ROOT / args.work
    work.mkdir(parents=True, exist_ok=True)
    qdems = {"qdem": Path(args.new)}
    if args.old:
        qdems["qdem (old)"] = Path(args.old)
    for name, exe in list(qdems.items()):  # private copies: a rebuild meanwhile changes nothing
        copy = work / ("study-" + ("old" if "old" in name else "new"))
        shutil.copy2(exe, copy)
        qdems[name] = copy
    liggghts, lammps = lc.ensure_liggghts(), ensure_lammps()
    versions = {"liggghts": lc.liggghts_version(liggghts), "lammps": lammps_version(lammps)}
    machine = lc.cpu_model()
    rows = []
    for n in [int(s) for s in args.spheres.split(",")]:
        d = work / f"n{n}"
        if not (d / "packing.json").exists():
            d.mkdir(parents=True, exist_ok=True)
            lc.sh([str(qdems["qdem"]), "packing", "--spheres", str(n), "--out", str(d)], cwd=ROOT)
        meta, spheres = lc.read_packing(d)
        q0 = qdem_throughput(qdems["qdem"], d, 10, 1)
        meta = dict(meta, dt=q0["dt"])  # the peers run the step qdem runs
        decks = {"liggghts": lc.write_liggghts_inputs(meta, spheres, args.steps, d),
                 "lammps": write_lammps_inputs(meta, spheres, args.steps, d)}
        for width in [int(s) for s in args.np.split(",")]:
            launcher = lc.mpi_launcher(width)[0]
            runs: dict[str, list] = {}
            for rep in range(args.repeats):
                for name, exe in qdems.items():
                    busy = lc.wait_idle(args.wait_idle) if args.wait_idle else None
                    with lc.OtherLoad() as ol:
                        q = qdem_throughput(exe, d, args.steps, width)
                    runs.setdefault(name, []).append((q["wall_s"], q, busy, ol.cores))
                    log(f"{name} n={n} width={width}: {q['wall_s']:.3f} s")
                for peer, exe in (("liggghts", liggghts), ("lammps", lammps)):
                    busy = lc.wait_idle(args.wait_idle) if args.wait_idle else None
                    with lc.OtherLoad() as ol:
                        p = run_peer(exe, launcher, decks[peer], meta, spheres, peer)
                    runs.setdefault(peer, []).append((p["wall_s"], p, busy, ol.cores))
                    log(f"{peer} n={n} width={width}: {p['wall_s']:.3f} s")
            for name, rs in runs.items():
                wall, r, busy, other = min(rs, key=lambda t: t[0])
                rows.append({
                    "code": name, "spheres": n, "steps": args.steps, "dt": meta["dt"],
                    "width": width, "wall_s": wall, "particle_steps_per_s": n * args.steps / wall,
                    "contacts": r.get("contacts"), "kinetic_energy": r.get("kinetic_energy"),
                    "bytes_per_particle_step": r.get("bytes_per_particle_step"),
                    "all_wall_s": [t[0] for t in rs], "other_cores_during": [round(t[3], 2) for t in rs],
                    "version": versions.get(name, name), "machine": machine})
    lines = ["| spheres | threads / ranks | code | wall (s) | particle-steps/s | contacts at end "
             "| KE at end (J) | qdem / code |", "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        new = next(x for x in rows if x["code"] == "qdem" and x["spheres"] == r["spheres"]
                   and x["width"] == r["width"])
        ratio = new["particle_steps_per_s"] / r["particle_steps_per_s"]
        lines.append(f"| {r['spheres']:,} | {r['width']} | {r['code']} | {r['wall_s']:.3f} | "
                     f"{r['particle_steps_per_s']:.3e} | {r['contacts']:,} | "
                     f"{r['kinetic_energy']:.4g} | {ratio:.2f} |")
    section = "\n".join(lines) + "\n"
    (work / "peers_compare.json").write_text(json.dumps({"versions": versions, "rows": rows},
                                                        indent=2) + "\n")
    (work / "peers_section.md").write_text(section)
    print(section)


if __name__ == "__main__":
    main()
