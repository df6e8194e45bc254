#!/usr/bin/env python3
"""Side-by-side DEM throughput: qdem against LIGGGHTS 3.8 on the same settled packing.

Usage (from the workspace root):

    python3 qdem-bench/scripts/liggghts_compare.py [--spheres 10000,100000] [--steps 2000]
        [--work out/liggghts] [--docs docs] [--np 2] [--fake-packing] [--regen-packing]
        [--skip-qdem] [--no-build] [--repeats 3] [--wait-idle 300]

For each sphere count N:
  1. qdem makes a settled packing
     (`study packing --spheres N --out WORK/nN`: packing.csv + packing.json) and times itself
     on it (`study dem-throughput --packing WORK/nN --steps S`, one JSON object on stdout);
  2. the same spheres are written as a LIGGGHTS data file (atom_style granular) and the deck
     qdem-bench/scripts/liggghts/bench.in.template is filled in with the packing's material,
     time step, skin, gravity and walls, and run with `mpirun -np NP liggghts`;
  3. LIGGGHTS's "Loop time of T on P procs for S steps with N atoms" gives its wall time.
Particle-steps/s = N*S/T for both codes; the rows go to DOCS/liggghts_compare.json and a table
to the section of DOCS/BENCHMARKS.md between <!-- liggghts:begin --> and <!-- liggghts:end -->
(appended at the end of the file if absent; the rest of the file is never touched).

--fake-packing tests the LIGGGHTS half alone: the script writes its own packing.csv/json
(a loose cubic lattice, r = 0.005 m, rho 2700, E 5e7 Pa, nu 0.25, mu 0.5, e 0.5, dt 1e-5,
skin 0.001 m, a floor and four side walls) instead of calling qdem, runs only LIGGGHTS, checks
that no sphere left the box, and writes its JSON into WORK (DOCS only if --docs is given).

--skip-qdem times LIGGGHTS alone on packings already in WORK/nN (e.g. a qdem packing made
earlier, or any packing.csv/json pair). Before each timed run the script waits up to
--wait-idle seconds for the CPUs to be idle and records how busy they were (cpu_busy_before).

LIGGGHTS is installed from Debian (package `liggghts`, 3.8.0 in bookworm) if missing.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TEMPLATE = Path(__file__).resolve().parent / "liggghts" / "bench.in.template"
BEGIN = "<!-- liggghts:begin -->"
END = "<!-- liggghts:end -->"
E_WALL_FACTOR = 1.0e6  # wall type's Young's modulus / sphere's: sphere-wall E* -> E/(1-nu^2)


def log(msg: str) -> None:
    print(f"[liggghts_compare] {msg}", file=sys.stderr, flush=True)


# ----------------------------------------------------------------------------- installation

def sh(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, check=True, text=True, **kw)


def ensure_liggghts() -> str:
    exe = shutil.which("liggghts")
    if exe is None:
        log("LIGGGHTS not found: installing the Debian package 'liggghts'")
        pre = [] if os.geteuid() == 0 else ["sudo"]
        env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
        sh(pre + ["apt-get", "update", "-qq"], env=env)
        # --no-install-recommends: the package recommends paraview, which the benchmark does not need
        sh(pre + ["apt-get", "install", "-y", "-qq", "--no-install-recommends", "liggghts"], env=env)
        files = sh(["dpkg", "-L", "liggghts"], capture_output=True).stdout.split()
        bins = [f for f in files if f.startswith("/usr/bin/")]
        log(f"package 'liggghts' installs {bins}")
        exe = shutil.which("liggghts") or (bins[0] if bins else None)
    if exe is None:
        sys.exit("error: no LIGGGHTS binary after installing the 'liggghts' package")
    return exe


def liggghts_version(exe: str) -> str:
    # `-log none`: otherwise LIGGGHTS leaves a log.liggghts in the current folder
    out = subprocess.run([exe, "-log", "none", "-h"], capture_output=True, text=True,
                         timeout=60).stdout
    m = re.search(r"LIGGGHTS \(Version ([^,)]+)", out)
    pkg = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "liggghts"],
                         capture_output=True, text=True).stdout.strip()
    v = m.group(1) if m else "unknown"
    return f"{v} (Debian package liggghts {pkg})" if pkg else v


def mpi_launcher(np_: int) -> tuple[list[str], str]:
    """The command prefix that runs LIGGGHTS on np_ MPI ranks, and a description of it."""
    mpirun = shutil.which("mpirun")
    if np_ <= 1 or mpirun is None:
        if np_ > 1:
            log("mpirun not found: running LIGGGHTS serially (1 process)")
        return [], "serial, 1 process"
    ver = subprocess.run([mpirun, "--version"], capture_output=True, text=True).stdout.splitlines()
    flags = ["--oversubscribe"]
    if os.geteuid() == 0:
        flags.insert(0, "--allow-run-as-root")
    desc = f"{ver[0].strip() if ver else 'mpirun'}, mpirun -np {np_} (pure MPI, 1 thread/rank)"
    return [mpirun, *flags, "-np", str(np_)], desc


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


def cpu_busy(seconds: float = 2.0) -> float:
    """Fraction of all CPUs busy over `seconds` (from /proc/stat)."""
    import time

    def sample():
        v = [int(x) for x in Path("/proc/stat").read_text().splitlines()[0].split()[1:]]
        idle = v[3] + (v[4] if len(v) > 4 else 0)
        return sum(v), idle
    t0, i0 = sample()
    time.sleep(seconds)
    t1, i1 = sample()
    return 1.0 - (i1 - i0) / max(1, t1 - t0)


class OtherLoad:
    """Measures how many cores other processes kept busy while a timed child ran: CPU time of the
    whole machine (/proc/stat) less this script's waited-for descendants' (getrusage)."""

    @staticmethod
    def _busy_s() -> float:
        v = [int(x) for x in Path("/proc/stat").read_text().splitlines()[0].split()[1:]]
        idle = v[3] + (v[4] if len(v) > 4 else 0)
        return (sum(v[:8]) - idle) / os.sysconf("SC_CLK_TCK")

    @staticmethod
    def _own_s() -> float:
        import resource
        r = resource.getrusage(resource.RUSAGE_CHILDREN)
        return r.ru_utime + r.ru_stime

    def __enter__(self):
        import time
        self.t, self.b, self.o = time.monotonic(), self._busy_s(), self._own_s()
        return self

    def __exit__(self, *exc):
        import time
        wall = max(1e-9, time.monotonic() - self.t)
        other = (self._busy_s() - self.b) - (self._own_s() - self.o)
        self.cores = max(0.0, other / wall)
        if self.cores > 0.2:
            log(f"WARNING: other processes kept {self.cores:.2f} cores busy during the timed run")
        return False


def wait_idle(limit_s: float, threshold: float = 0.15) -> float:
    """Waits up to limit_s for the machine to be idle (another build or benchmark would skew the
    timing); returns the last busy fraction measured."""
    import time
    start = time.monotonic()
    busy = cpu_busy()
    warned = False
    while busy > threshold and time.monotonic() - start < limit_s:
        if not warned:
            log(f"machine {busy:.0%} busy: waiting up to {limit_s:.0f} s for it to be idle")
            warned = True
        time.sleep(5)
        busy = cpu_busy()
    if busy > threshold:
        log(f"WARNING: timing on a machine {busy:.0%} busy; the figures will be low")
    return busy


# ----------------------------------------------------------------------------- packings

def read_packing(d: Path) -> tuple[dict, list[tuple[float, float, float, float]]]:
    meta = json.loads((d / "packing.json").read_text())
    spheres = []
    with open(d / "packing.csv") as f:
        header = f.readline().strip().split(",")
        ix = [header.index(k) for k in ("x", "y", "z", "radius")]
        for line in f:
            if line.strip():
                v = line.split(",")
                spheres.append(tuple(float(v[i]) for i in ix))
    if meta.get("spheres", len(spheres)) != len(spheres):
        sys.exit(f"error: {d}/packing.json says {meta['spheres']} spheres, packing.csv has {len(spheres)}")
    return meta, spheres


def fake_packing(n: int, d: Path) -> None:
    """A loose simple-cubic lattice of n spheres (r = 5 mm, centres 12 mm apart) in a box, each
    centre jittered by up to 0.9 mm in x and y (seeded; no overlaps) so that the columns topple
    as they settle and spheres reach the side walls."""
    import random
    rng = random.Random(1)
    r, pitch, jit = 0.005, 0.012, 0.0009
    nx = max(1, round(n ** (1.0 / 3.0)))
    ny = nx
    nz = math.ceil(n / (nx * ny))
    margin = 0.002
    spheres = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                if len(spheres) == n:
                    break
                jx = jit * (2 * rng.random() - 1) if 0 < i < nx - 1 else 0.0
                jy = jit * (2 * rng.random() - 1) if 0 < j < ny - 1 else 0.0
                spheres.append((margin + r + i * pitch + jx, margin + r + j * pitch + jy,
                                margin + r + k * pitch, r))
    box_max = [2 * margin + 2 * r + (nx - 1) * pitch, 2 * margin + 2 * r + (ny - 1) * pitch,
               2 * margin + 2 * r + (nz - 1) * pitch]
    rho, e = 2700.0, 0.5
    meta = {
        "spheres": n, "box_min": [0.0, 0.0, 0.0], "box_max": box_max,
        "density": rho, "youngs_modulus": 5.0e7, "poisson_ratio": 0.25, "friction": 0.5,
        "restitution": e,
        "damping_ratio": -math.log(e) / math.sqrt(math.log(e) ** 2 + math.pi ** 2),
        "gravity": [0.0, 0.0, -9.81], "dt": 1.0e-5, "skin": 0.001,
        "walls": [
            {"point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]},
            {"point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0]},
            {"point": box_max, "normal": [-1.0, 0.0, 0.0]},
            {"point": [0.0, 0.0, 0.0], "normal": [0.0, 1.0, 0.0]},
            {"point": box_max, "normal": [0.0, -1.0, 0.0]},
        ],
        "fake": True,
    }
    d.mkdir(parents=True, exist_ok=True)
    (d / "packing.json").write_text(json.dumps(meta, indent=2) + "\n")
    with open(d / "packing.csv", "w") as f:
        f.write("x,y,z,radius\n")
        for s in spheres:
            f.write(",".join(repr(v) for v in s) + "\n")


# ----------------------------------------------------------------------------- qdem side

class Qdem:
    def __init__(self, work: Path, build: bool = True) -> None:
        if build:
            log("building qdem-bench's study binary "
                "(cargo build --release -p qdem-bench --bin study)")
            sh(["cargo", "build", "--release", "-p", "qdem-bench", "--bin", "study"], cwd=ROOT)
        target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
        if not target.is_absolute():
            target = ROOT / target
        self.exe = target / "release" / "study"
        if not self.exe.exists():
            sys.exit(f"error: no {self.exe}; run without --no-build")
        # a private copy, so that a rebuild of the workspace during the study changes nothing
        work.mkdir(parents=True, exist_ok=True)
        copy = work / "study"
        shutil.copy2(self.exe, copy)
        self.exe = copy
        rev = subprocess.run(["git", "describe", "--always", "--dirty"], cwd=ROOT,
                             capture_output=True, text=True).stdout.strip()
        self.version = f"qdem {rev or 'unknown'}" + ("" if build else " (prebuilt binary)")

    def packing(self, n: int, d: Path) -> None:
        log(f"qdem: settling a packing of {n} spheres into {d}")
        sh([str(self.exe), "packing", "--spheres", str(n), "--out", str(d)], cwd=ROOT)

    def throughput(self, d: Path, steps: int, threads: int) -> dict:
        log(f"qdem: timing {steps} steps on {d} on {threads} threads")
        out = sh([str(self.exe), "dem-throughput", "--packing", str(d), "--steps", str(steps)],
                 cwd=ROOT, capture_output=True,
                 env=dict(os.environ, RAYON_NUM_THREADS=str(threads))).stdout
        # the last line that parses as a JSON object
        for line in reversed(out.strip().splitlines()):
            line = line.strip()
            if line.startswith("{"):
                return json.loads(line)
        sys.exit(f"error: no JSON object on dem-throughput's stdout:\n{out}")


# ----------------------------------------------------------------------------- LIGGGHTS side

def fmt(v: float) -> str:
    return repr(float(v))


def wall_commands(meta: dict) -> str:
    lines = []
    for i, w in enumerate(meta["walls"]):
        p, nrm = w["point"], w["normal"]
        axis = [k for k in range(3) if abs(nrm[k]) > 1e-12]
        if len(axis) != 1:
            sys.exit(f"error: wall {w} is not axis-aligned; this deck supports only x/y/z planes")
        a = axis[0]
        lines.append(f"fix wall{i} all wall/gran model hertz tangential history primitive type 2 "
                     f"{'xyz'[a]}plane {fmt(p[a])}")
    return "\n".join(lines)


def wall_overlaps(meta: dict) -> str:
    """An atom-style expression: how many of the walls a sphere overlaps (centre closer than its
    radius c_rad to the plane, on either side)."""
    terms = []
    for w in meta["walls"]:
        a = next(k for k in range(3) if abs(w["normal"][k]) > 1e-12)
        terms.append(f"(abs({'xyz'[a]}-({fmt(w['point'][a])}))<c_rad)")
    return "+".join(terms) if terms else "0"


def restitution(meta: dict) -> float:
    """The restitution for LIGGGHTS: packing.json's e, checked against qdem's damping ratio
    (LIGGGHTS's beta = ln e / sqrt(ln^2 e + pi^2) = -zeta); if the two disagree, the e that
    reproduces qdem's zeta, so that both codes damp alike."""
    e = meta["restitution"]
    zeta = meta.get("damping_ratio")
    if zeta is None:
        return e
    e_zeta = math.exp(-math.pi * zeta / math.sqrt(1.0 - zeta * zeta)) if zeta < 1 else 0.0
    if abs(e_zeta - e) > 1e-6 * max(e, 1e-12):
        log(f"WARNING: packing.json's restitution {e} and damping_ratio {zeta} (e = {e_zeta:.9g}) "
            "disagree; LIGGGHTS gets the e of qdem's damping ratio")
        return e_zeta
    return e


def write_liggghts_inputs(meta: dict, spheres, steps: int, d: Path) -> Path:
    rmax = max(s[3] for s in spheres)
    lo = [min(meta["box_min"][k], min(s[k] - s[3] for s in spheres)) for k in range(3)]
    hi = [max(meta["box_max"][k], max(s[k] + s[3] for s in spheres)) for k in range(3)]
    pad = 2.0 * rmax  # "slightly larger than the box": walls and spheres strictly inside the domain
    data = d / "liggghts.data"
    rho = meta["density"]
    with open(data, "w") as f:
        f.write("LIGGGHTS data file written by qdem-bench/scripts/liggghts_compare.py\n\n")
        f.write(f"{len(spheres)} atoms\n2 atom types\n\n")
        for k, ax in enumerate("xyz"):
            f.write(f"{fmt(lo[k] - pad)} {fmt(hi[k] + pad)} {ax}lo {ax}hi\n")
        f.write("\nAtoms\n\n")
        # atom_style granular: atom-ID atom-type diameter density x y z
        for i, (x, y, z, r) in enumerate(spheres, 1):
            f.write(f"{i} 1 {fmt(2 * r)} {fmt(rho)} {fmt(x)} {fmt(y)} {fmt(z)}\n")
    g = meta["gravity"]
    gmag = math.sqrt(sum(c * c for c in g))
    gdir = " ".join(fmt(c / gmag) for c in g) if gmag > 0 else "0.0 0.0 -1.0"
    e = meta["youngs_modulus"]
    rest = restitution(meta)
    grid = ["*", "*", "*"]
    if gmag > 0:
        grid[max(range(3), key=lambda k: abs(g[k]))] = "1"
    subs = {
        "PROCS": " ".join(grid),
        "DATA": data.name, "SKIN": fmt(meta["skin"]), "E": fmt(e),
        "E_WALL": fmt(e * E_WALL_FACTOR), "E_WALL_FACTOR": f"{E_WALL_FACTOR:g}",
        "NU": fmt(meta["poisson_ratio"]), "REST": fmt(rest),
        "MU": fmt(meta["friction"]), "DT": fmt(meta["dt"]), "G_MAG": fmt(gmag), "G_DIR": gdir,
        "WALLS": wall_commands(meta), "WALL_OVERLAPS": wall_overlaps(meta), "THERMO": str(max(1000, steps // 4)), "STEPS": str(steps),
    }
    text = TEMPLATE.read_text()
    for k, v in subs.items():
        text = text.replace(f"@{k}@", v)
    left = re.findall(r"@[A-Z_]+@", text)
    if left:
        sys.exit(f"error: unfilled placeholders in the deck: {left}")
    deck = d / "in.bench"
    deck.write_text(text)
    return deck


LOOP_RE = re.compile(r"Loop time of ([0-9.eE+-]+) on (\d+) procs for (\d+) steps with (\d+) atoms")


def final_thermo(stdout: str) -> dict | None:
    """The thermo row under the last `Step` header that has the contact sums, by column name
    with the c_/v_ prefixes dropped (LIGGGHTS prints c_csum as "csum", LAMMPS keeps
    "c_csum"); None if no such header."""
    final = None
    lines = stdout.splitlines()
    for i, line in enumerate(lines):
        cols = line.split()
        if cols[:1] == ["Step"] and ("csum" in cols or "c_csum" in cols) and i + 1 < len(lines):
            names = [c.split("_", 1)[1] if c[:2] in ("c_", "v_") else c for c in cols]
            final = dict(zip(names, (float(v) for v in lines[i + 1].split())))
    return final


def run_liggghts(exe: str, launcher: list[str], deck: Path, meta: dict, spheres) -> dict:
    cmd = [*launcher, exe, "-in", deck.name, "-log", "log.liggghts", "-nocite"]
    log(f"LIGGGHTS: {' '.join(cmd)} (in {deck.parent})")
    env = dict(os.environ, OMP_NUM_THREADS="1", OMPI_MCA_btl_vader_single_copy_mechanism="none")
    p = subprocess.run(cmd, cwd=deck.parent, capture_output=True, text=True, env=env)
    (deck.parent / "liggghts.stdout").write_text(p.stdout + p.stderr)
    if p.returncode != 0:
        sys.exit(f"error: LIGGGHTS failed (exit {p.returncode}); see {deck.parent}/liggghts.stdout:\n"
                 + (p.stdout + p.stderr)[-3000:])
    loops = LOOP_RE.findall(p.stdout)
    if not loops:
        sys.exit(f"error: no 'Loop time' line in {deck.parent}/liggghts.stdout")
    t, procs, steps, atoms = loops[0]  # the first run is the timed one; the second is `run 0`
    final = final_thermo(p.stdout)  # the final `run 0`
    if final is None:
        sys.exit(f"error: no final thermo line in {deck.parent}/liggghts.stdout")
    pair_contacts = int(round(final["csum"] / 2))
    wall_contacts = int(round(final["wsum"]))
    contacts = pair_contacts + wall_contacts
    atoms_left, ke = final["Atoms"], final["ket"] + final["erot"]
    xl, xh, yl, yh, zl, zh = (final[k] for k in ("xlo", "xhi", "ylo", "yhi", "zlo", "zhi"))
    bmin, bmax = meta["box_min"], meta["box_max"]
    rmax = max(s[3] for s in spheres)
    tol = 0.5 * rmax
    inside = (xl > bmin[0] - tol and xh < bmax[0] + tol and yl > bmin[1] - tol
              and yh < bmax[1] + tol and zl > bmin[2] - tol)
    log(f"LIGGGHTS final state: {int(atoms_left)} atoms, KE {ke:.4g} J, centres in "
        f"x [{xl:.4g}, {xh:.4g}] y [{yl:.4g}, {yh:.4g}] z [{zl:.4g}, {zh:.4g}]; "
        f"{pair_contacts} sphere-sphere + {wall_contacts} sphere-wall contacts; "
        f"{'inside' if inside else 'OUTSIDE'} the walls")
    if not inside or int(atoms_left) != len(spheres):
        sys.exit("error: spheres left the box in the LIGGGHTS run")
    builds = re.search(r"Neighbor list builds = (\d+)", p.stdout)
    return {"wall_s": float(t), "procs": int(procs), "steps": int(steps), "atoms": int(atoms),
            "contacts": contacts, "sphere_sphere_contacts": pair_contacts,
            "sphere_wall_contacts": wall_contacts, "kinetic_energy": ke,
            "neighbor_builds": int(builds.group(1)) if builds else None}


# ----------------------------------------------------------------------------- report

def row(code, n, steps, dt, wall_s, parallel, contacts, machine, **extra):
    r = {"code": code, "spheres": n, "steps": steps, "dt": dt, "wall_s": wall_s,
         "particle_steps_per_s": n * steps / wall_s if wall_s > 0 else None,
         "threads_or_procs": parallel, "contacts": contacts, "machine": machine}
    r.update(extra)
    return r


def traffic(r: dict) -> str:
    """qdem's modelled bytes per particle-step and the share of the triad bandwidth (measured in
    the same process, on as many threads) the run moved."""
    b, t = r.get("bytes_per_particle_step"), r.get("triad_bytes_per_s")
    if not b or not t or not r["particle_steps_per_s"]:
        return ""
    return f"{b:,.0f} ({100 * b * r['particle_steps_per_s'] / t:.0f}% of {t / 1e9:.1f} GB/s)"


def sci(v) -> str:
    return "—" if v is None else f"{v:.3e}"


def markdown(rows: list[dict], args, version: str, mpi_desc: str, machine: str,
             liggghts_only: bool) -> str:
    cmd = (f"python3 qdem-bench/scripts/liggghts_compare.py --spheres "
           f"{','.join(map(str, args.spheres))} --steps {args.steps}"
           + (f" --np {','.join(map(str, args.np))}" if args.np != [2, 1] else "")
           + (f" --repeats {args.repeats}" if args.repeats != 3 else "")
           + (" --fake-packing" if args.fake_packing else "")
           + (" --skip-qdem" if args.skip_qdem else ""))
    qv = next((r["version"] for r in rows if r["code"] == "qdem"), None)
    out = [BEGIN, "", "## DEM throughput against LIGGGHTS", ""]
    out.append(f"**Machine:** {machine}, {os.cpu_count()} cores. "
               f"Measured {_dt.date.today().isoformat()}"
               + (f" ({qv})" if qv else "") + ".")
    out.append("")
    out.append(f"**LIGGGHTS:** {version}; {mpi_desc}; no MPI cut along gravity "
               "(`processors * * 1`). Deck: `qdem-bench/scripts/liggghts/bench.in.template` "
               "(filled in per run; the filled deck `in.bench`, data file and output are left in "
               "`out/liggghts/nN/`). **qdem:** `study dem-throughput`, rayon threads.")
    out.append("")
    out.append("**Same problem on both sides:** the same settled packing (`study packing`: a "
               "lattice poured into a box of a floor and four side walls), started at rest; the "
               "same time step (the one qdem ran), steps and neighbour skin (`neighbor SKIN bin`, "
               "`neigh_modify delay 0`); rigid spheres with rotation, Hertz normal + Mindlin "
               "tangential with history, Coulomb limit, no rolling friction or cohesion, gravity, "
               "the packing's ρ, E, ν, μ and restitution e (LIGGGHTS β = ln e/√(ln²e+π²) = −ζ). "
               "Walls are rigid planes in qdem and LIGGGHTS `wall/gran` primitives of a wall atom "
               f"type with E × {E_WALL_FACTOR:g} (so sphere–wall E* → E/(1−ν²), R* = r; checked: "
               "a sphere resting on the floor settles at the rigid-wall Hertz overlap to 8 digits).")
    out.append("")
    out.append(f"**Timing:** the two codes alternate, {args.repeats} runs each, the fastest counts "
               "(all are in `docs/liggghts_compare.json`, with how busy the other processes kept "
               "the machine). LIGGGHTS's time is its `Loop time` (the run loop; set-up and the "
               "first neighbour build excluded); qdem's the `wall_s` of `dem-throughput` (the "
               "step loop after the initial force evaluation). Particle-steps/s = spheres × "
               "steps / wall time.")
    out.append("")
    out.append("| spheres | steps | dt (s) | code | run as | wall (s) | particle-steps/s | "
               "contacts at end | KE at end (J) | bytes/particle-step (of triad) | "
               "qdem / LIGGGHTS |")
    out.append("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for n, width in sorted({(r["spheres"], r["threads_or_procs"]) for r in rows},
                           key=lambda t: (t[0], -t[1])):
        rs = [r for r in rows if (r["spheres"], r["threads_or_procs"]) == (n, width)]
        lig = next((r for r in rs if r["code"] == "liggghts"), None)
        for r in rs:
            ratio = ""
            if r["code"] == "qdem" and lig and r["particle_steps_per_s"] and lig["particle_steps_per_s"]:
                ratio = f"**{r['particle_steps_per_s'] / lig['particle_steps_per_s']:.2f}**"
            run_as = (f"{r['threads_or_procs']} threads" if r["code"] == "qdem"
                      else f"{r['threads_or_procs']} MPI procs")
            out.append(f"| {n:,} | {r['steps']} | {r['dt']:.4g} | {r['code']} | {run_as} | "
                       f"{r['wall_s']:.2f} | {sci(r['particle_steps_per_s'])} | "
                       f"{'—' if r['contacts'] is None else format(r['contacts'], ',')} | "
                       f"{'—' if r.get('kinetic_energy') is None else format(r['kinetic_energy'], '.3g')} | "
                       f"{traffic(r)} | {ratio} |")
    out.append("")
    out.append("Contacts at the end of the run, sphere–sphere plus sphere–wall: qdem's as "
               "`dem-throughput` reports them (pairs with a non-zero force); LIGGGHTS's from "
               "`compute contact/atom` (summed, halved) plus the spheres closer to a wall than "
               "their radius, counted after the timed run. KE: translational + rotational "
               "(LIGGGHTS `compute ke` + `erotate/sphere`). The two runs start from the same "
               "state and integrate the same law, so both agree closely; a KE far from 0 means "
               "the packing was still moving (not fully settled), the same for both codes.")
    if liggghts_only:
        out.append("")
        out.append("**LIGGGHTS only** (`--fake-packing` or `--skip-qdem`): "
                   + ("a loose lattice written by the script; " if args.fake_packing else "")
                   + "not a comparison.")
    out.append("")
    out.append("Reproduce (installs the Debian package `liggghts` if it is missing; about "
               "15 minutes for 10⁴ and 10⁵ spheres, most of it qdem settling the 10⁵ packing):")
    out.append("")
    out.append("```sh")
    out.append(cmd)
    out.append("```")
    out.append("")
    out.append(END)
    return "\n".join(out) + "\n"


def update_benchmarks_md(path: Path, section: str) -> None:
    text = path.read_text() if path.exists() else "# Benchmarks\n"
    b, e = text.find(BEGIN), text.find(END)
    if b >= 0 and e > b:
        text = text[:b] + section.rstrip("\n") + text[e + len(END):]
    else:
        text = text.rstrip("\n") + "\n\n" + section
    path.write_text(text)


# ----------------------------------------------------------------------------- main

def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spheres", default="10000,100000",
                    help="comma-separated sphere counts (default 10000,100000)")
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--work", default="out/liggghts")
    ap.add_argument("--docs", default=None, help="where liggghts_compare.json and BENCHMARKS.md "
                    "are (default docs; with --fake-packing, only if given)")
    ap.add_argument("--np", default="2,1",
                    help="comma-separated widths: LIGGGHTS on that many MPI processes against "
                    "qdem on as many threads (default 2,1)")
    ap.add_argument("--fake-packing", action="store_true",
                    help="test the LIGGGHTS half alone on a lattice the script writes")
    ap.add_argument("--regen-packing", action="store_true",
                    help="remake qdem's packing even if WORK/nN/packing.json exists")
    ap.add_argument("--skip-qdem", action="store_true",
                    help="time LIGGGHTS only, on the packings already in WORK/nN")
    ap.add_argument("--no-build", action="store_true",
                    help="use target/release/study as it is, without cargo build")
    ap.add_argument("--repeats", type=int, default=3,
                    help="timed runs of each code per sphere count, alternating; the fastest "
                    "counts (default 3)")
    ap.add_argument("--wait-idle", type=float, default=300.0,
                    help="seconds to wait, before each timed run, for the CPUs to be idle "
                    "(default 300; a warning, not an error, if they are not)")
    args = ap.parse_args()
    args.spheres = [int(s) for s in args.spheres.split(",") if s.strip()]
    args.np = [int(s) for s in args.np.split(",") if s.strip()]

    work = (ROOT / args.work) if not Path(args.work).is_absolute() else Path(args.work)
    docs = None
    if args.docs is not None:
        docs = Path(args.docs) if Path(args.docs).is_absolute() else ROOT / args.docs
    elif not (args.fake_packing or args.skip_qdem):
        docs = ROOT / "docs"

    exe = ensure_liggghts()
    version = liggghts_version(exe)
    launchers = {w: mpi_launcher(w) for w in args.np}
    mpi_desc = "; ".join(desc for _, desc in launchers.values())
    machine = cpu_model()
    log(f"LIGGGHTS {version} at {exe}; {mpi_desc}; CPU {machine}")
    liggghts_only = args.fake_packing or args.skip_qdem
    qdem = None if liggghts_only else Qdem(work, build=not args.no_build)

    rows, metas = [], {}
    for n in args.spheres:
        d = work / f"n{n}"
        if args.fake_packing:
            fake_packing(n, d)
        elif args.skip_qdem:
            if not (d / "packing.json").exists():
                sys.exit(f"error: --skip-qdem needs {d}/packing.json and packing.csv")
        elif args.regen_packing or not (d / "packing.json").exists():
            d.mkdir(parents=True, exist_ok=True)
            qdem.packing(n, d)
        meta, spheres = read_packing(d)
        metas[n] = meta
        n_real = len(spheres)
        deck = write_liggghts_inputs(meta, spheres, args.steps, d)
        for width in args.np:
            launcher = launchers[width][0]
            # the two codes alternate, `--repeats` times; each keeps its fastest run (least disturbed)
            q_runs, l_runs = [], []
            for rep in range(args.repeats):
                if qdem is not None:
                    busy = wait_idle(args.wait_idle)
                    with OtherLoad() as ol:
                        q = qdem.throughput(d, args.steps, width)
                    if q.get("spheres", n_real) != n_real or q["steps"] != args.steps:
                        sys.exit(f"error: qdem timed {q.get('spheres')} spheres for {q['steps']} "
                                 f"steps; expected {n_real} for {args.steps}")
                    if rep == 0 and q["dt"] != meta["dt"]:
                        # qdem picks its step from its own stability bound too; LIGGGHTS must use
                        # the step qdem actually ran
                        log(f"qdem ran dt = {q['dt']!r}, packing.json says {meta['dt']!r}: "
                            "LIGGGHTS gets qdem's")
                        meta = dict(meta, dt=q["dt"], dt_packing_json=meta["dt"])
                        metas[n] = meta
                        deck = write_liggghts_inputs(meta, spheres, args.steps, d)
                    elif q["dt"] != meta["dt"]:
                        sys.exit(f"error: qdem's dt changed between runs ({meta['dt']!r} then "
                                 f"{q['dt']!r}): was the study binary rebuilt meanwhile?")
                    q_runs.append((q, busy, ol.cores))
                    log(f"qdem run {rep + 1}/{args.repeats}: {q}")
                busy = wait_idle(args.wait_idle)
                with OtherLoad() as ol:
                    lg = run_liggghts(exe, launcher, deck, meta, spheres)
                if lg["atoms"] != n_real or lg["steps"] != args.steps:
                    sys.exit(f"error: LIGGGHTS ran {lg['steps']} steps with {lg['atoms']} atoms, "
                             f"expected {args.steps} with {n_real}")
                l_runs.append((lg, busy, ol.cores))
                log(f"LIGGGHTS run {rep + 1}/{args.repeats}: {n_real} spheres, {lg['steps']} steps in "
                    f"{lg['wall_s']:.3f} s on {lg['procs']} procs = "
                    f"{n_real * lg['steps'] / lg['wall_s']:.4g} particle-steps/s")
            if q_runs:
                q, busy, other = min(q_runs, key=lambda t: t[0]["wall_s"])
                rows.append(row("qdem", n_real, q["steps"], q["dt"], q["wall_s"],
                                q.get("threads"), q.get("contacts"), machine,
                                reported_particle_steps_per_s=q.get("particle_steps_per_s"),
                                version=qdem.version,
                                **{k: q[k] for k in ("stable_bound", "rebuilds", "kinetic_energy",
                                                     "candidates_per_sphere",
                                                     "bytes_per_particle_step", "triad_bytes_per_s")
                                   if k in q},
                                all_wall_s=[t[0]["wall_s"] for t in q_runs],
                                cpu_busy_before=round(busy, 3), other_cores_during=round(other, 3)))
            lg, busy, other = min(l_runs, key=lambda t: t[0]["wall_s"])
            rows.append(row("liggghts", n_real, lg["steps"], meta["dt"], lg["wall_s"], lg["procs"],
                            lg["contacts"], machine, version=version, launcher=launchers[width][1],
                            neighbor_builds=lg["neighbor_builds"],
                            sphere_sphere_contacts=lg["sphere_sphere_contacts"],
                            sphere_wall_contacts=lg["sphere_wall_contacts"],
                            kinetic_energy=lg["kinetic_energy"],
                            all_wall_s=[t[0]["wall_s"] for t in l_runs],
                            cpu_busy_before=round(busy, 3), other_cores_during=round(other, 3),
                            deck=str(deck.relative_to(ROOT) if deck.is_relative_to(ROOT) else deck)))
            if q_runs:
                log(f"{n_real} spheres, width {width}: qdem / LIGGGHTS = "
                    f"{rows[-2]['particle_steps_per_s'] / rows[-1]['particle_steps_per_s']:.3f}")

    for n, width in sorted({(r["spheres"], r["threads_or_procs"]) for r in rows}):
        q = [r for r in rows if (r["spheres"], r["threads_or_procs"]) == (n, width)]
        qd = next((r for r in q if r["code"] == "qdem"), None)
        lg = next((r for r in q if r["code"] == "liggghts"), None)
        if qd and lg:
            qd["ratio_qdem_over_liggghts"] = qd["particle_steps_per_s"] / lg["particle_steps_per_s"]

    section = markdown(rows, args, version, mpi_desc, machine, liggghts_only)
    out_json = json.dumps(rows, indent=2) + "\n"
    (work).mkdir(parents=True, exist_ok=True)
    (work / "liggghts_compare.json").write_text(out_json)
    (work / "liggghts_section.md").write_text(section)
    if docs is not None:
        docs.mkdir(parents=True, exist_ok=True)
        (docs / "liggghts_compare.json").write_text(out_json)
        update_benchmarks_md(docs / "BENCHMARKS.md", section)
        log(f"wrote {docs / 'liggghts_compare.json'} and the liggghts section of "
            f"{docs / 'BENCHMARKS.md'}")
    print(section)


if __name__ == "__main__":
    main()
