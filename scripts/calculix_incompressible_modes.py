#!/usr/bin/env python3
"""Modes of a nearly incompressible block, qdem against CalculiX hybrid elements (issue 43).

A 1.0 x 0.6 x 0.4 m rubber-like block (E = 5 MPa, nu = 0.4999, rho = 1100 kg/m^3) clamped on
its base z = 0. qdem computes its lowest modes on structured tetrahedral meshes (the same Kuhn
split as qdem_mesh::structured_box, written as gmsh MSH 2.2) with the standard and the
averaged-pressure formulation (`qdem modes`); CalculiX (`ccx`, Debian's calculix-ccx) on
20-node reduced-integration hexahedra C3D20R of the same geometry, at two refinements, is the
reference. CalculiX has no hybrid (displacement-pressure) elements (`C3D20H is an unknown
element type`, `C3D8H` likewise); quadratic reduced-integration hexahedra are its elements for
nearly incompressible solids (no volumetric locking: 8 integration points against 20 nodes).
Prints one JSON object per line.

    python3 scripts/calculix_incompressible_modes.py QDEM [--modes 6] [--keep DIR]

Skips (exit 0, message on stderr) when `ccx` is not installed.
"""

import argparse
import csv
import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

SIZE = (1.0, 0.6, 0.4)
YOUNG, POISSON, DENSITY = 5e6, 0.4999, 1100.0
KUHN = [((0, 1, 2), True), ((1, 2, 0), True), ((2, 0, 1), True),
        ((0, 2, 1), False), ((2, 1, 0), False), ((1, 0, 2), False)]


def write_msh(path, cells):
    """The structured Kuhn tetrahedra of the block, base triangles in physical group `base`."""
    nx, ny, nz = cells
    nid = lambda i, j, k: 1 + i + (nx + 1) * (j + (ny + 1) * k)
    nodes = [(nid(i, j, k), i * SIZE[0] / nx, j * SIZE[1] / ny, k * SIZE[2] / nz)
             for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)]
    tets = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                for perm, even in KUHN:
                    p = [i, j, k]
                    t = [nid(i, j, k)]
                    for axis in perm:
                        p[axis] += 1
                        t.append(nid(*p))
                    if not even:
                        t[2], t[3] = t[3], t[2]
                    tets.append(t)
    tris = []
    for j in range(ny):
        for i in range(nx):
            a, b, c, d = nid(i, j, 0), nid(i + 1, j, 0), nid(i + 1, j + 1, 0), nid(i, j + 1, 0)
            tris += [(a, c, b), (a, d, c)]
    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat",
             "$PhysicalNames", "2", '2 1 "base"', '3 2 "block"', "$EndPhysicalNames",
             "$Nodes", str(len(nodes))]
    lines += [f"{n} {x!r} {y!r} {z!r}" for n, x, y, z in nodes]
    lines += ["$EndNodes", "$Elements", str(len(tris) + len(tets))]
    e = 0
    for t in tris:
        e += 1
        lines.append(f"{e} 2 2 1 1 {t[0]} {t[1]} {t[2]}")
    for t in tets:
        e += 1
        lines.append(f"{e} 4 2 2 2 {t[0]} {t[1]} {t[2]} {t[3]}")
    lines.append("$EndElements")
    Path(path).write_text("\n".join(lines) + "\n")
    return len(tets)


def qdem_modes(qdem, work, cells, formulation, count):
    mesh = work / f"block_{cells[0]}x{cells[1]}x{cells[2]}.msh"
    tets = write_msh(mesh, cells)
    scene = work / f"block_{formulation}_{cells[0]}.toml"
    scene.write_text(
        f'[run]\nt_end = 1.0\ndt = "auto"\n\n[[material]]\nname = "rubber"\ndensity = {DENSITY}\n'
        f'young = {YOUNG}\npoisson = {POISSON}\nformulation = "{formulation}"\n\n'
        f'[[body]]\nname = "block"\nmesh = "{mesh.name}"\nmaterial = "rubber"\n\n'
        f'[[fix]]\nbody = "block"\ngroup = "base"\ndofs = "xyz"\n')
    out = work / f"modes_{formulation}_{cells[0]}"
    subprocess.run([qdem, "modes", str(scene), "--count", str(count), "--out", str(out)],
                   check=True, capture_output=True)
    with open(out / "modes.csv") as f:
        return tets, [float(r["frequency_hz"]) for r in csv.DictReader(f)]


def ccx_modes(work, cells, count):
    """Frequencies (Hz) of C3D20R hexahedra of `cells`."""
    nx, ny, nz = (2 * c for c in cells)  # the half-spacing grid of corner and mid-side nodes
    nid = lambda i, j, k: 1 + i + (nx + 1) * (j + (ny + 1) * k)
    nodes = [(nid(i, j, k), i * SIZE[0] / nx, j * SIZE[1] / ny, k * SIZE[2] / nz)
             for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)
             if (i % 2) + (j % 2) + (k % 2) <= 1]
    elements = []
    for k in range(0, nz, 2):
        for j in range(0, ny, 2):
            for i in range(0, nx, 2):
                c = [(i, j, k), (i + 2, j, k), (i + 2, j + 2, k), (i, j + 2, k),
                     (i, j, k + 2), (i + 2, j, k + 2), (i + 2, j + 2, k + 2), (i, j + 2, k + 2)]
                mid = lambda a, b: tuple((x + y) // 2 for x, y in zip(c[a], c[b]))
                edges = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4),
                         (0, 4), (1, 5), (2, 6), (3, 7)]
                elements.append([nid(*p) for p in c] + [nid(*mid(a, b)) for a, b in edges])
    base = [n for n, _, _, z in nodes if z == 0.0]
    deck = ["*NODE, NSET=NALL"] + [f"{n}, {x!r}, {y!r}, {z!r}" for n, x, y, z in nodes]
    deck.append("*ELEMENT, TYPE=C3D20R, ELSET=EALL")
    for e, el in enumerate(elements, 1):
        deck.append(f"{e}, " + ", ".join(map(str, el[:15])) + ",")
        deck.append(", ".join(map(str, el[15:])))
    deck.append("*NSET, NSET=NBASE")
    deck += [", ".join(map(str, base[i:i + 8])) + "," for i in range(0, len(base), 8)]
    deck += ["*BOUNDARY", "NBASE, 1, 3",
             "*MATERIAL, NAME=RUBBER", "*ELASTIC", f"{YOUNG}, {POISSON}",
             "*DENSITY", f"{DENSITY}",
             "*SOLID SECTION, ELSET=EALL, MATERIAL=RUBBER",
             "*STEP", "*FREQUENCY", f"{count}", "*END STEP"]
    name = f"block_c3d20r_{cells[0]}"
    (work / f"{name}.inp").write_text("\n".join(deck) + "\n")
    subprocess.run(["ccx", "-i", name], cwd=work, check=True, capture_output=True)
    text = (work / f"{name}.dat").read_text()
    table = text.split("E I G E N V A L U E   O U T P U T")[1]
    rows = re.findall(r"^\s*(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s*$", table, re.M)
    return len(elements), [float(r[3]) for r in rows[:count]]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("qdem")
    parser.add_argument("--modes", type=int, default=6)
    parser.add_argument("--keep")
    args = parser.parse_args()
    if shutil.which("ccx") is None:
        print("skipped: ccx (CalculiX) is not installed (apt-get install calculix-ccx)",
              file=sys.stderr)
        return 0
    work = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="qdem-ccx-"))
    work.mkdir(parents=True, exist_ok=True)
    reference = {}
    for cells in [(10, 6, 4), (20, 12, 8)]:
        hexes, freq = ccx_modes(work, cells, args.modes)
        reference = freq
        print(json.dumps({"solver": "calculix C3D20R", "cells": cells, "elements": hexes,
                          "frequencies_hz": [round(f, 5) for f in freq]}))
    for cells in [(10, 6, 4), (20, 12, 8)]:
        for formulation in ["standard", "averaged-pressure"]:
            tets, freq = qdem_modes(args.qdem, work, cells, formulation, args.modes)
            print(json.dumps({"solver": f"qdem {formulation}", "cells": cells, "tets": tets,
                              "frequencies_hz": [round(f, 5) for f in freq],
                              "over_calculix": [round(f / r, 4) for f, r in zip(freq, reference)]}))
    if not args.keep:
        shutil.rmtree(work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
