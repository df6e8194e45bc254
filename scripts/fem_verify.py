#!/usr/bin/env python3
"""Lamé's cylinder and Kirsch's plate with a hole: qdem's static solve and CalculiX's C3D4 and
C3D10 on the same gmsh meshes, against the closed forms (issue 55; docs/verification.md).

Lamé: a quarter of a thick-walled cylinder, bore a = 0.1 m, outside b = 0.2 m, p = 10 MPa in
the bore, E = 200 GPa, ν = 0.3, plane strain (u_z = 0 on both ends), symmetry planes held
normal to themselves: σ_r = A − B/r², σ_θ = A + B/r², A = p a²/(b² − a²), B = p a² b²/(b² − a²),
u_r = (1 + ν)/E·((1 − 2ν) A r + B/r).
Kirsch: a quarter of a square plate of half-width W = 25 a (a = 0.01 m) pulled by σ = 10 MPa
along x, plane strain: on the ligament x = 0, σ_xx(y) = σ/2·(2 + a²/y² + 3a⁴/y⁴), 3σ at the
hole's edge (0, a), σ_yy = −σ at (a, 0), and u_r(a, θ) = σa(1 + κ)/(8μ)·(1 + 2 cos 2θ),
κ = 3 − 4ν (infinite plate; Heywood's finite-width factor for
d/W = 0.04 raises the peak to 3.005σ).

Each mesh comes from `fixtures/fem/generate.py` (the same function that made the committed
ones; `same_as_committed` says whether it reproduced the committed file byte for byte). qdem
runs its fixture scene (`fixtures/fem/{lame,kirsch}.toml`) on it; CalculiX runs C3D4 on the
same linear tetrahedra and C3D10 on the same mesh elevated to second order by gmsh (the
corner nodes the same, the mid-side nodes on the curved surfaces), loads as *DLOAD element-face
pressures. Nodal stresses: qdem's VTU `nodal_stress` where the binary writes it, otherwise the
volume-weighted average of the per-element `stress` over the elements around each node;
CalculiX's from its .frd (*EL FILE S: the integration-point stresses extrapolated to the nodes
and averaged over the elements that share each node). Element stresses for qdem against C3D4
from the .dat (*EL PRINT S, one integration point per C3D4).

    python3 scripts/fem_verify.py QDEM [--sizes coarse,medium] [--problems lame,kirsch]
                                       [--calculix c3d4,c3d10] [--keep DIR] [--reference]

(`--sizes fine --calculix c3d4`: the fine meshes, 114,000-182,000 tetrahedra, without the
C3D10 runs, whose 10-node meshes would take minutes.)

Prints one JSON object per line: per problem, mesh size and solver the mesh size (nodes,
elements), the wall time of the solver's process, and the errors against the closed forms;
then per problem and size qdem against C3D4 on the same mesh. Without `ccx` (Debian's
calculix-ccx) only qdem's rows are printed, and a line on stderr says CalculiX was skipped.
"""

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import gmsh
import meshio
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
FEM = ROOT / "fixtures" / "fem"
sys.path.insert(0, str(FEM))
import generate  # noqa: E402  (fixtures/fem/generate.py: the meshes)

YOUNG, POISSON = 200e9, 0.3
PRESSURE = 10e6  # Lamé's bore pressure, Pa
SIGMA = 10e6  # Kirsch's remote traction, Pa
# The fixes of both scenes: group -> held direction (1-based for CalculiX).
FIXES = {"sym_x": 1, "sym_y": 2, "ends": 3}
# gmsh's 10-node tetrahedron to CalculiX's C3D10 (Abaqus order): the last two edges swap.
GMSH_TO_C3D10 = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]
# The corners of faces 1-4 of C3D4/C3D10 (0-based), CalculiX's *DLOAD labels P1-P4.
FACES = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]


# ---------------------------------------------------------------- closed forms

def lame(r):
    """(σ_r, σ_θ, u_r) of Lamé's cylinder in plane strain at radius r."""
    a, b = generate.LAME["a"], generate.LAME["b"]
    big_a = PRESSURE * a * a / (b * b - a * a)
    big_b = PRESSURE * a * a * b * b / (b * b - a * a)
    return (big_a - big_b / r**2, big_a + big_b / r**2,
            (1 + POISSON) / YOUNG * ((1 - 2 * POISSON) * big_a * r + big_b / r))


def kirsch_ligament(y):
    """Kirsch's σ_xx on the line x = 0 at distance y ≥ a from the hole's centre."""
    a = generate.KIRSCH["a"]
    return SIGMA / 2 * (2 + a * a / y**2 + 3 * a**4 / y**4)


def kirsch_hole_u():
    """U of Kirsch's plane-strain displacement of the hole's edge, u_r(a, θ) = U (1 + 2 cos 2θ):
    U = σ a (1 + κ)/(8 μ), κ = 3 − 4ν; u_y = −U at (0, a), u_x = 3U at (a, 0)."""
    mu = YOUNG / (2 * (1 + POISSON))
    return SIGMA * generate.KIRSCH["a"] * (4 - 4 * POISSON) / (8 * mu)


def heywood_peak():
    """Heywood's peak stress of a hole of diameter d in a strip of width W, gross section:
    σ·(2 + (1 − d/W)³)/(1 − d/W)."""
    ratio = generate.KIRSCH["a"] / generate.KIRSCH["w"]
    return SIGMA * (2 + (1 - ratio) ** 3) / (1 - ratio)


# ---------------------------------------------------------------- meshes

class Mesh:
    """One mesh as CalculiX needs it: nodes by gmsh tag, elements, fixed node sets and the
    faces of the loaded group."""

    def __init__(self, order, load_group):
        tags, coords, _ = gmsh.model.mesh.getNodes()
        self.nodes = {int(t): coords[3 * i:3 * i + 3] for i, t in enumerate(tags)}
        kind, per = (4, 4) if order == 1 else (11, 10)
        elements, connectivity = gmsh.model.mesh.getElementsByType(kind)
        conn = np.asarray(connectivity, dtype=np.int64).reshape(-1, per)
        if order == 2:
            conn = conn[:, GMSH_TO_C3D10]
        self.elements = [int(e) for e in elements]
        self.connectivity = conn
        used = set(conn.ravel().tolist())
        self.nodes = {t: x for t, x in self.nodes.items() if t in used}
        self.sets = {name: sorted(int(n) for n in group_nodes(name)) for name in FIXES}
        self.load_faces = self._faces(load_group)
        if order == 2:
            self._check_midsides()

    def _faces(self, group):
        """(element, face number 1-4) of each triangle of `group`."""
        by_corners = {}
        for e, row in zip(self.elements, self.connectivity):
            for k, face in enumerate(FACES, 1):
                by_corners[frozenset(int(row[i]) for i in face)] = (e, k)
        faces = []
        for dim, tag in physical(2):
            if gmsh.model.getPhysicalName(dim, tag) != group:
                continue
            for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                types, _, conns = gmsh.model.mesh.getElements(dim, entity)
                for kind, conn in zip(types, conns):
                    per = {2: 3, 9: 6}[int(kind)]
                    for tri in np.asarray(conn, dtype=np.int64).reshape(-1, per):
                        faces.append(by_corners[frozenset(int(n) for n in tri[:3])])
        return faces

    def _check_midsides(self):
        """Every mid-side node near its edge's midpoint (the C3D10 order is right)."""
        edges = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
        for row in self.connectivity:
            for k, (i, j) in enumerate(edges, 4):
                p, q, m = (self.nodes[int(row[n])] for n in (i, j, k))
                if np.linalg.norm(m - (p + q) / 2) > 0.25 * np.linalg.norm(p - q):
                    raise RuntimeError("a C3D10 mid-side node is off its edge: wrong node order")


def physical(dim):
    """The (dim, tag) of the model's physical groups of dimension `dim`."""
    return [(d, t) for d, t in gmsh.model.getPhysicalGroups() if d == dim]


def group_nodes(name):
    """The node tags of the physical group called `name`."""
    for dim, tag in gmsh.model.getPhysicalGroups():
        if gmsh.model.getPhysicalName(dim, tag) == name:
            return gmsh.model.mesh.getNodesForPhysicalGroup(dim, tag)[0]
    raise KeyError(name)


def make_meshes(problem, size, work):
    """The linear .msh for qdem and the C3D4 and C3D10 meshes for CalculiX."""
    params = dict((s, p) for pr, s, p, _ in generate.CASES if pr == problem)[size]
    path = work / generate.mesh_name(problem, size)
    load_group = {"lame": "bore", "kirsch": "right"}[problem]
    with generate.session():
        generate.build(problem, params)
        generate.save(str(path))
        linear = Mesh(1, load_group)
        gmsh.model.mesh.setOrder(2)
        quadratic = Mesh(2, load_group)
    committed = FEM / path.name
    same = committed.read_bytes() == path.read_bytes() if committed.exists() else None
    return path, linear, quadratic, same


# ---------------------------------------------------------------- qdem

def run_qdem(qdem, problem, msh, work):
    """qdem's fixture scene on `msh`: (points, displacement, tets, element stress, nodal
    stress, where the nodal stress comes from, wall seconds)."""
    text = (FEM / f"{problem}.toml").read_text()
    text = re.sub(r'^mesh = ".*"$', f"mesh = {json.dumps(str(msh))}", text, flags=re.M)
    scene = work / f"{msh.stem}.toml"
    scene.write_text(text)
    out = work / f"qdem_{msh.stem}"
    start = time.perf_counter()
    subprocess.run([qdem, "run", str(scene), "--out", str(out)], check=True,
                   capture_output=True)
    wall = time.perf_counter() - start
    vtu = sorted((out / "vtu").glob("state_*.vtu"))[-1]
    m = meshio.read(vtu)
    tets = m.cells_dict["tetra"]
    stress = voigt_qdem(m.cell_data_dict["stress"]["tetra"])
    if "nodal_stress" in m.point_data:
        nodal, source = voigt_qdem(m.point_data["nodal_stress"]), "vtu nodal_stress"
    else:
        nodal, source = volume_average(m.points, tets, stress), "volume-weighted average"
    return m.points, m.point_data["displacement"], tets, stress, nodal, source, wall


def voigt_qdem(s):
    """qdem's six components xx, yy, zz, xy, yz, xz as symmetric 3 × 3 tensors."""
    s = np.asarray(s, dtype=float).reshape(-1, 6)
    t = np.empty((len(s), 3, 3))
    for k, (i, j) in enumerate([(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)]):
        t[:, i, j] = t[:, j, i] = s[:, k]
    return t


def volume_average(points, tets, stress):
    """Each node's stress: Σ V_e σ_e / Σ V_e over the tetrahedra around it."""
    p = points[tets]
    volume = np.abs(np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]),
                              p[:, 3] - p[:, 0])) / 6
    total = np.zeros((len(points), 3, 3))
    weight = np.zeros(len(points))
    for corner in range(4):
        np.add.at(total, tets[:, corner], stress * volume[:, None, None])
        np.add.at(weight, tets[:, corner], volume)
    return total / weight[:, None, None]


# ---------------------------------------------------------------- CalculiX

def run_ccx(mesh, element, problem, work):
    """CalculiX on `mesh`: (points, displacement from the .dat, nodal stress from the .frd,
    element stress from the .dat (C3D4: its one integration point; None for C3D10), wall
    seconds)."""
    name = f"{problem}_{element.lower()}_{len(mesh.elements)}"
    tags = sorted(mesh.nodes)
    deck = ["*NODE, NSET=NALL"]
    # CalculiX reads a coordinate from at most 20 characters: 13 significant digits.
    deck += [f"{t}, " + ", ".join(f"{c:.13g}" for c in mesh.nodes[t]) for t in tags]
    deck.append(f"*ELEMENT, TYPE={element}, ELSET=EALL")
    for e, row in zip(mesh.elements, mesh.connectivity):
        ids = [str(e)] + [str(int(n)) for n in row]
        deck.append(", ".join(ids[:11]) + ("," if len(ids) > 11 else ""))
        if len(ids) > 11:
            deck.append(", ".join(ids[11:]))
    for group, nodes in mesh.sets.items():
        deck.append(f"*NSET, NSET={group.upper()}")
        deck += [", ".join(map(str, nodes[i:i + 12])) + "," for i in range(0, len(nodes), 12)]
    deck.append("*BOUNDARY")
    deck += [f"{group.upper()}, {dof}, {dof}" for group, dof in FIXES.items()]
    deck += ["*MATERIAL, NAME=STEEL", "*ELASTIC", f"{YOUNG}, {POISSON}",
             "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL",
             "*STEP", "*STATIC", "*DLOAD"]
    # Lamé: p pushes into the bore; Kirsch: −σ on the face x = W pulls it outward.
    value = PRESSURE if problem == "lame" else -SIGMA
    deck += [f"{e}, P{k}, {value}" for e, k in mesh.load_faces]
    deck += ["*NODE FILE", "U", "*EL FILE", "S",
             "*NODE PRINT, NSET=NALL", "U", "*EL PRINT, ELSET=EALL", "S", "*END STEP"]
    (work / f"{name}.inp").write_text("\n".join(deck) + "\n")
    start = time.perf_counter()
    subprocess.run(["ccx", "-i", name], cwd=work, check=True, capture_output=True,
                   env=dict(os.environ, OMP_NUM_THREADS="1"))
    wall = time.perf_counter() - start
    frd = read_frd(work / f"{name}.frd")
    index = {t: i for i, t in enumerate(tags)}
    points = np.array([mesh.nodes[t] for t in tags])
    disp = np.zeros((len(tags), 3))
    nodal = np.zeros((len(tags), 3, 3))
    for t, row in read_dat_displacement(work / f"{name}.dat").items():
        disp[index[t]] = row
    for t, row in frd["STRESS"].items():
        nodal[index[t]] = tensor_ccx(row)
    element_stress = None
    if element == "C3D4":
        element_stress = read_dat_stress(work / f"{name}.dat", mesh.elements)
    return points, disp, nodal, element_stress, wall


def read_frd(path):
    """The result blocks (DISP, STRESS) of an ASCII .frd: {block: {node: values}}."""
    blocks, current = {}, None
    for line in path.read_text().splitlines():
        if line.startswith(" -4"):
            current = line.split()[1]
            blocks[current] = {}
        elif line.startswith(" -1") and current is not None:
            node = int(line[3:13])
            rest = line[13:]
            blocks[current][node] = [float(rest[i:i + 12]) for i in range(0, len(rest), 12)]
        elif line.startswith(" -3"):
            current = None
    return blocks


def tensor_ccx(row):
    """CalculiX's .frd stress SXX SYY SZZ SXY SYZ SZX as a 3 × 3 tensor."""
    xx, yy, zz, xy, yz, zx = row[:6]
    return np.array([[xx, xy, zx], [xy, yy, yz], [zx, yz, zz]])


def read_dat_displacement(path):
    """The .dat's *NODE PRINT U (7 digits, where the .frd has 6): {node: (ux, uy, uz)}."""
    text = path.read_text().split("displacements (vx,vy,vz)")[1].split("stresses")[0]
    out = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[0].isdigit():
            out[int(parts[0])] = [float(v) for v in parts[1:]]
    return out


def read_dat_stress(path, elements):
    """C3D4's stress per element from the .dat's *EL PRINT (elem, ip, sxx syy szz sxy sxz syz)."""
    text = path.read_text().split("stresses (elem, integ.pnt.,sxx,syy,szz,sxy,sxz,syz)")[1]
    out = {}
    for line in text.splitlines():
        parts = line.split()
        if len(parts) == 8 and parts[0].isdigit():
            xx, yy, zz, xy, xz, yz = map(float, parts[2:])
            out[int(parts[0])] = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    return np.array([out[e] for e in elements])


# ---------------------------------------------------------------- errors

def lame_errors(points, disp, nodal):
    """u_r and σ_θ at the bore (mean and largest relative error) and the RMS of the nodal
    σ_r, σ_θ errors over the whole wall, over p."""
    x, y = points[:, 0], points[:, 1]
    r = np.hypot(x, y)
    c, s = x / r, y / r
    u_r = disp[:, 0] * c + disp[:, 1] * s
    s_r = np.einsum("i,i,i->i", c, c, nodal[:, 0, 0]) + 2 * c * s * nodal[:, 0, 1] \
        + s * s * nodal[:, 1, 1]
    s_t = s * s * nodal[:, 0, 0] - 2 * c * s * nodal[:, 0, 1] + c * c * nodal[:, 1, 1]
    exact_r, exact_t, exact_u = lame(r)
    bore = np.abs(r - generate.LAME["a"]) < 1e-6
    u_err = u_r[bore] / exact_u[bore] - 1
    t_err = s_t[bore] / exact_t[bore] - 1
    return {
        "bore_nodes": int(bore.sum()),
        "u_r_bore_mean_error": u_err.mean(),
        "u_r_bore_max_error": u_err[np.argmax(np.abs(u_err))],
        "sigma_theta_bore_exact_mpa": exact_t[bore][0] / 1e6,
        "sigma_theta_bore_mean_error": t_err.mean(),
        "sigma_theta_bore_max_error": t_err[np.argmax(np.abs(t_err))],
        "sigma_r_bore_mean_over_p": (s_r[bore].mean() - exact_r[bore][0]) / PRESSURE,
        "sigma_theta_rms_over_p": math.sqrt(np.mean(((s_t - exact_t) / PRESSURE) ** 2)),
        "sigma_r_rms_over_p": math.sqrt(np.mean(((s_r - exact_r) / PRESSURE) ** 2)),
    }


def kirsch_errors(points, disp, nodal):
    """σ_xx at the hole's edge (0, a) and σ_yy at (a, 0) over σ, the largest and RMS error of
    σ_xx along the ligament x = 0, a ≤ y ≤ 3a, against Kirsch, over σ; the displacement of
    those two points against Kirsch's."""
    a = generate.KIRSCH["a"]
    x, y = points[:, 0], points[:, 1]
    on_axis = np.abs(x) < 1e-9
    edge = on_axis & (np.abs(y - a) < 1e-9)
    side = (np.abs(y) < 1e-9) & (np.abs(x - a) < 1e-9)
    ligament = on_axis & (y <= 3 * a + 1e-9)
    lig_err = (nodal[ligament, 0, 0] - kirsch_ligament(y[ligament])) / SIGMA
    peak = nodal[edge, 0, 0].mean() / SIGMA
    return {
        "edge_nodes": int(edge.sum()),
        "ligament_nodes": int(ligament.sum()),
        "sigma_xx_edge_over_sigma": peak,
        "edge_error_vs_kirsch": peak / 3 - 1,
        "edge_error_vs_heywood": peak * SIGMA / heywood_peak() - 1,
        "sigma_yy_side_over_sigma": nodal[side, 1, 1].mean() / SIGMA,
        "ligament_max_error_over_sigma": lig_err[np.argmax(np.abs(lig_err))],
        "ligament_rms_error_over_sigma": math.sqrt(np.mean(lig_err**2)),
        "u_y_edge_error": disp[edge, 1].mean() / -kirsch_hole_u() - 1,
        "u_x_side_error": disp[side, 0].mean() / (3 * kirsch_hole_u()) - 1,
    }


def errors(problem, points, disp, nodal):
    """The error row of `problem` for one solver's nodal results."""
    if problem == "lame":
        return lame_errors(points, disp, nodal)
    return kirsch_errors(points, disp, nodal)


def by_coordinates(points_a, points_b):
    """The index into points_b of each point of points_a (the same mesh, any node order)."""
    key = lambda p: tuple(np.round(p, 9))
    index = {key(p): i for i, p in enumerate(points_b)}
    return np.array([index[key(p)] for p in points_a])


def rounded(row):
    """`row` with its floats to four significant digits, for the JSON line."""
    return {k: (float(f"{v:.4g}") if isinstance(v, (float, np.floating)) else v)
            for k, v in row.items()}


# ---------------------------------------------------------------- main

def verify(qdem, problem, size, work, elements, reference):
    """Print the rows of `problem` at `size`: qdem, each CalculiX element of `elements`, and
    qdem against C3D4; with `reference`, write the coarse C3D4 reference CSV."""
    msh, linear, quadratic, same = make_meshes(problem, size, work)
    points, disp, tets, stress, nodal, source, wall = run_qdem(qdem, problem, msh, work)
    base = {"problem": problem, "mesh": size}
    print(json.dumps(rounded({**base, "solver": "qdem", "nodes": len(points),
                              "elements": len(tets), "wall_s": wall, "nodal_stress": source,
                              "same_as_committed": same,
                              **errors(problem, points, disp, nodal)})), flush=True)
    c3d4 = None
    for element, mesh in [("C3D4", linear), ("C3D10", quadratic)]:
        if element not in elements:
            continue
        c_points, c_disp, c_nodal, c_stress, c_wall = run_ccx(mesh, element, problem, work)
        print(json.dumps(rounded({**base, "solver": f"calculix {element}",
                                  "nodes": len(c_points), "elements": len(mesh.elements),
                                  "wall_s": c_wall, "nodal_stress": "frd (extrapolated, averaged)",
                                  **errors(problem, c_points, c_disp, c_nodal)})), flush=True)
        if element == "C3D4":
            c3d4 = (c_points, c_disp, c_stress, mesh)
    if c3d4 is None:
        return
    c_points, c_disp, c_stress, mesh = c3d4
    c_tets = by_tag_rows(mesh)
    c_nodal = volume_average(c_points, c_tets, c_stress)
    node_map = by_coordinates(points, c_points)
    element_map = by_coordinates(points[tets].mean(axis=1), c_points[c_tets].mean(axis=1))
    scale = {"lame": PRESSURE, "kirsch": SIGMA}[problem]
    print(json.dumps(rounded({
        **base, "compare": "qdem vs calculix C3D4, same mesh",
        "max_element_stress_diff_over_load": np.abs(stress - c_stress[element_map]).max() / scale,
        "max_displacement_diff_over_max": np.abs(disp - c_disp[node_map]).max()
        / np.abs(c_disp).max(),
        "max_nodal_stress_diff_over_load": np.abs(nodal - c_nodal[node_map]).max() / scale,
    })), flush=True)
    if reference and size == "coarse":
        write_reference(FEM / f"{problem}_coarse_c3d4.csv", c_points, c_disp, c_nodal)


def write_reference(path, points, disp, nodal):
    """C3D4's displacement and volume-weighted nodal stress (qdem's order xx, yy, zz, xy, yz,
    xz) at the nodes on the hole (r = a), the reference of qdem-io/tests/fem_verification.rs."""
    r = np.hypot(points[:, 0], points[:, 1])
    on_hole = np.abs(r - min(r)) < 1e-6
    lines = ["x,y,z,ux,uy,uz,sxx,syy,szz,sxy,syz,sxz"]
    for i in np.flatnonzero(on_hole):
        s = nodal[i]
        values = list(points[i]) + list(disp[i]) + [s[0, 0], s[1, 1], s[2, 2], s[0, 1],
                                                    s[1, 2], s[0, 2]]
        lines.append(",".join(f"{v:.7g}" if k >= 3 else f"{v:.13g}"
                              for k, v in enumerate(values)))
    path.write_text("\n".join(lines) + "\n")


def by_tag_rows(mesh):
    """The C3D4 connectivity as rows into the point array of the sorted node tags."""
    index = {t: i for i, t in enumerate(sorted(mesh.nodes))}
    return np.vectorize(index.get)(mesh.connectivity)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("qdem")
    parser.add_argument("--sizes", default="coarse,medium")
    parser.add_argument("--problems", default="lame,kirsch")
    parser.add_argument("--calculix", default="c3d4,c3d10",
                        help="the CalculiX elements to run (empty: none)")
    parser.add_argument("--keep")
    parser.add_argument("--reference", action="store_true",
                        help="write fixtures/fem/*_coarse_c3d4.csv from the coarse C3D4 runs")
    args = parser.parse_args()
    elements = [e.upper() for e in args.calculix.split(",") if e]
    if elements and shutil.which("ccx") is None:
        print("CalculiX skipped: ccx is not installed (apt-get install calculix-ccx); "
              "qdem's rows only", file=sys.stderr)
        elements = []
    work = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="qdem-fem-"))
    work.mkdir(parents=True, exist_ok=True)
    qdem = str(Path(args.qdem).resolve())
    for problem in args.problems.split(","):
        for size in args.sizes.split(","):
            verify(qdem, problem, size, work.resolve(), elements, args.reference)
    if not args.keep:
        shutil.rmtree(work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
