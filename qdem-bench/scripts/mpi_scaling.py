#!/usr/bin/env python3
"""Strong and weak scaling of `mpirun -np N qdem run` against one process, side by side.

Usage (from the workspace root; needs Open MPI and a `--features mpi` build):

    python3 qdem-bench/scripts/mpi_scaling.py [--tets 1000000] [--spheres 100000]
        [--tet-steps 200] [--sphere-steps 500] [--pairs 2] [--work out/mpi_scaling]
        [--qdem target/release/qdem] [--json docs/mpi_scaling.json] [--scenes tets,spheres]

Two scenes are written into WORK: a clamped elastic concrete box of about TETS tetrahedra
(a structured mesh, 6 tetrahedra per cell, written as MSH 2.2) under gravity, and a box of
SPHERES single spheres falling onto a floor ([granular], linear law). Each is run by
`qdem run --threads T` on 1 process and by `mpirun -np R qdem run --threads T`, the
configurations (R ranks x T threads) in turn, PAIRS times over, so that the machine's drift
falls on all of them alike; the step time is `wall_seconds / steps` of summary.json (the
stepping loop only: no mesh reading, no scene building). Weak scaling runs the box of 2 x TETS
tetrahedra (the packing of 2 x SPHERES spheres) on 2 ranks against TETS (SPHERES) on 1. Prints one JSON document (and writes it to --json):
per scene and configuration the median step time, and the efficiencies

    strong (R ranks x 1 thread)  = t(1 x 1) / (R t(R x 1))
    weak (2 ranks, twice the work) = rate(2 x 1, 2N) / (2 rate(1 x 1, N))  (element-steps/s)
    ranks x threads              = t(1 x 2) / t(2 x 1)   (2 ranks of 1 thread against 2 threads)

each of the medians, and also pass by pass (the runs of one pass, taken within a minute of
each other, against each other), with the median, min and max of the passes under
"paired": on a machine whose speed drifts by 30% between hours, the paired figures are the
ones to quote.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
           "OMPI_MCA_btl_vader_single_copy_mechanism": "none"}


def log(msg: str) -> None:
    print(f"[mpi_scaling] {msg}", file=sys.stderr, flush=True)


def cells_for(tets: int) -> tuple[int, int, int]:
    """A 2.4 : 1 : 1 box of cells with about `tets` / 6 cells."""
    n = round((tets / 6 / 2.4) ** (1 / 3))
    return (round(2.4 * n), n, n)


def write_box_mesh(path: Path, cells: tuple[int, int, int]) -> None:
    """A structured box (0.1 m cells), 6 Kuhn tetrahedra per cell, and its xmin face as the
    physical surface "clamp" (MSH 2.2, ASCII)."""
    nx, ny, nz = cells
    h = 0.1

    def node(i, j, k):
        return 1 + i + (nx + 1) * (j + (ny + 1) * k)

    kuhn = [(0, 1, 2, True), (1, 2, 0, True), (2, 0, 1, True),
            (0, 2, 1, False), (2, 1, 0, False), (1, 0, 2, False)]
    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", "2",
             '2 1 "clamp"', '3 2 "box"', "$EndPhysicalNames", "$Nodes",
             str((nx + 1) * (ny + 1) * (nz + 1))]
    for k in range(nz + 1):
        for j in range(ny + 1):
            for i in range(nx + 1):
                lines.append(f"{node(i, j, k)} {i * h:.6g} {j * h:.6g} {k * h:.6g}")
    lines.append("$EndNodes")
    elements = []
    for k in range(nz):
        for j in range(ny):
            elements.append(("2", (node(0, j, k), node(0, j, k + 1), node(0, j + 1, k + 1)), 1))
            elements.append(("2", (node(0, j, k), node(0, j + 1, k + 1), node(0, j + 1, k)), 1))
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                for a, b, c, even in kuhn:
                    p = [0, 0, 0]
                    corners = [node(i, j, k)]
                    for axis in (a, b, c):
                        p[axis] += 1
                        corners.append(node(i + p[0], j + p[1], k + p[2]))
                    if not even:
                        corners[1], corners[2] = corners[2], corners[1]
                    elements.append(("4", tuple(corners), 2))
    lines += ["$Elements", str(len(elements))]
    for e, (kind, nodes, tag) in enumerate(elements, start=1):
        lines.append(f"{e} {kind} 2 {tag} {tag} " + " ".join(map(str, nodes)))
    lines.append("$EndElements")
    path.write_text("\n".join(lines) + "\n")


def box_scene(work: Path, tets: int, steps: int) -> Path:
    cells = cells_for(tets)
    name = f"box_{6 * cells[0] * cells[1] * cells[2]}"
    mesh = work / f"{name}.msh"
    if not mesh.exists():
        log(f"writing {mesh} ({cells} cells)")
        write_box_mesh(mesh, cells)
    # The stable step of 0.1 m linear tets of this concrete is about 1.1e-5 s: 1e-5 s steps.
    dt = 1e-5
    scene = work / f"{name}.toml"
    scene.write_text(f"""[run]
t_end = {steps * dt!r}
dt = {dt!r}
integrator = "verlet"
gravity = [0.0, 0.0, -9.81]
probe_every = {10 * dt!r}

[[material]]
name = "concrete"
density = 2350.0
young = 30e9
poisson = 0.2

[[body]]
name = "box"
mesh = "{mesh.name}"
material = "concrete"

[[fix]]
body = "box"
group = "clamp"
dofs = "xyz"

[[probe]]
name = "end"
body = "box"
point = [{cells[0] * 0.1}, 0.0, 0.0]

[output]
dir = "out"
""")
    return scene


def sphere_scene(work: Path, spheres: int, steps: int) -> Path:
    side = round((spheres / 0.3) ** (1 / 3)) * 0.012
    dt = 2e-5
    scene = work / f"spheres_{spheres}.toml"
    scene.write_text(f"""[run]
t_end = {steps * dt!r}
dt = {dt!r}
gravity = [0.0, 0.0, -9.81]
probe_every = {10 * dt!r}

[[material]]
name = "glass"
density = 2500.0
young = 5e7
poisson = 0.25

[contact]
law = "linear"
normal_stiffness = 1e4
tangential_stiffness = 5e3
friction = 0.5

[granular]
name = "spheres"
material = "glass"
region = [[0.0, 0.0, 0.0], [{side!r}, {side!r}, {2 * side!r}]]
count = {spheres}
grading = [[0.009, 0.0], [0.011, 1.0]]
spheres_per_stone = [1, 1]
seed = 1

[[wall]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[output]
dir = "out"
""")
    return scene


def qdem_run_command(qdem: str, scene, ranks: int, threads: int, out, extra=()) -> list[str]:
    """`qdem run SCENE --out OUT --threads T` and `extra`, under `mpirun -np R` for R > 1
    ranks (run it with MPI_ENV)."""
    cmd = [qdem, "run", str(scene), "--out", str(out), "--threads", str(threads), *extra]
    if ranks > 1:
        cmd = ["mpirun", "--oversubscribe", "--bind-to", "none", "-np", str(ranks)] + cmd
    return cmd


def run(qdem: str, scene: Path, ranks: int, threads: int, out: Path) -> tuple[float, int]:
    """Seconds per step of one run (the stepping loop's wall time over its steps), and the
    elements it steps (tetrahedra, or particles for a scene without)."""
    cmd = qdem_run_command(qdem, scene, ranks, threads, out)
    p = subprocess.run(cmd, capture_output=True, text=True, env={**os.environ, **MPI_ENV})
    if p.returncode != 0:
        sys.exit(f"error: {' '.join(cmd)} failed:\n{p.stderr}")
    summary = json.loads((out / "summary.json").read_text())
    return summary["wall_seconds"] / summary["steps"], summary["tets"] or summary["particles"]


def cpu_model() -> str:
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return platform.processor()


def measure(qdem: str, work: Path, label: str, runs: list[tuple[str, Path, int, int]],
            pairs: int) -> dict:
    times: dict[str, list[float]] = {key: [] for key, *_ in runs}
    size: dict[str, int] = {}
    for rep in range(pairs):
        for key, scene, ranks, threads in runs:
            t, size[key] = run(qdem, scene, ranks, threads, work / f"out_{label}_{key}")
            times[key].append(t)
            log(f"{label} {key} pass {rep + 1}: {t:.4e} s/step")
    return {key: {"seconds_per_step": statistics.median(v), "all": v, "elements": size[key],
                  "element_steps_per_second": size[key] / statistics.median(v)}
            for key, v in times.items()}


def paired(m: dict) -> dict:
    """The efficiencies of each pass (its runs against each other): median, min, max."""
    passes = range(len(m["1x1"]["all"]))
    t = {k: v["all"] for k, v in m.items()}
    size = {k: v["elements"] for k, v in m.items()}
    figures = {"strong_efficiency_2x1": [t["1x1"][i] / (2 * t["2x1"][i]) for i in passes],
               "ranks_over_threads": [t["1x2"][i] / t["2x1"][i] for i in passes]}
    if "2x1_double" in t:
        figures["weak_efficiency_2x1"] = [
            size["2x1_double"] * t["1x1"][i] / (2 * size["1x1"] * t["2x1_double"][i])
            for i in passes]
    return {k: {"median": statistics.median(v), "min": min(v), "max": max(v), "all": v}
            for k, v in figures.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--tets", type=int, default=1_000_000)
    ap.add_argument("--spheres", type=int, default=100_000)
    ap.add_argument("--tet-steps", type=int, default=200)
    ap.add_argument("--sphere-steps", type=int, default=500)
    ap.add_argument("--pairs", type=int, default=2)
    ap.add_argument("--work", type=Path, default=ROOT / "out/mpi_scaling")
    ap.add_argument("--qdem", default=str(ROOT / "target/release/qdem"))
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--scenes", default="tets,spheres",
                    help="which scenes to run, comma-separated: tets, spheres")
    args = ap.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    wanted = args.scenes.split(",")
    scenes = []
    if "tets" in wanted:
        box = box_scene(args.work, args.tets, args.tet_steps)
        box2 = box_scene(args.work, 2 * args.tets, args.tet_steps)
        scenes.append(("tets", box, [("2x1_double", box2, 2, 1)]))
    if "spheres" in wanted:
        packing = sphere_scene(args.work, args.spheres, args.sphere_steps)
        packing2 = sphere_scene(args.work, 2 * args.spheres, args.sphere_steps)
        scenes.append(("spheres", packing, [("2x1_double", packing2, 2, 1)]))
    configs = [("1x1", 1, 1), ("2x1", 2, 1), ("1x2", 1, 2)]
    result = {"machine": f"{cpu_model()}, {os.cpu_count()} cores",
              "mpirun": subprocess.run(["mpirun", "--version"], capture_output=True,
                                       text=True).stdout.splitlines()[0],
              "command": " ".join(sys.argv)}
    for label, scene, extra in scenes:
        runs = [(key, scene, r, t) for key, r, t in configs] + extra
        m = measure(args.qdem, args.work, label, runs, args.pairs)
        t = {k: v["seconds_per_step"] for k, v in m.items()}
        rate = {k: v["element_steps_per_second"] for k, v in m.items()}
        row = {"scene": scene.name, "runs": m,
               "strong_efficiency_2x1": t["1x1"] / (2 * t["2x1"]),
               "ranks_over_threads": t["1x2"] / t["2x1"]}
        if "2x1_double" in t:
            row["weak_efficiency_2x1"] = rate["2x1_double"] / (2 * rate["1x1"])
        row["paired"] = paired(m)
        result[label] = row
    text = json.dumps(result, indent=2)
    print(text)
    if args.json:
        args.json.write_text(text + "\n")


if __name__ == "__main__":
    main()
