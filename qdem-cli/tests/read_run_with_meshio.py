"""Read every VTU file of a `qdem run` output directory with meshio and print, as one JSON
object, what `paraview_output.rs` checks.

usage: python3 read_run_with_meshio.py OUT_DIR

For every DataSet of OUT_DIR/results.pvd (time, part, file): the number of points, the cells
of each type, and the shape of every point and cell array. For every time with spheres and
contacts: the largest difference, over the spheres, between the sum of the contact lines'
forces on a sphere (normal_force + tangential_force on `first`, times `scale_first` where
written; minus the same times `scale_second` on `second`) and the sphere's `contact_force`,
and the largest contact force, so that the caller can judge the difference against round-off.

meshio 5.3 cannot read an UnstructuredGrid without cells (it indexes the empty cell types):
a file whose Piece has NumberOfCells="0" (a contacts file at a time nothing touches, the body
file of a run without tetrahedra) is reported from its header, with "empty": true, the point
count and the names of its point arrays.
"""

import json
import os
import sys
import xml.etree.ElementTree as ET

import meshio
import numpy as np


def describe(mesh):
    return {
        "points": int(len(mesh.points)),
        "cells": {block.type: int(len(block.data)) for block in mesh.cells},
        "point_data": {k: list(np.shape(v)) for k, v in mesh.point_data.items()},
        "cell_data": {k: [list(np.shape(b)) for b in v] for k, v in mesh.cell_data.items()},
        "finite": bool(
            all(np.all(np.isfinite(v)) for v in mesh.point_data.values())
            and all(np.all(np.isfinite(b)) for v in mesh.cell_data.values() for b in v)
        ),
    }


def empty(path):
    """The report of a file without cells, from its XML, or None if it has cells."""
    root = ET.parse(path).getroot()
    piece = root.find("UnstructuredGrid/Piece")
    if int(piece.get("NumberOfCells")) != 0:
        return None
    points = int(piece.get("NumberOfPoints"))
    arrays = piece.find("PointData").findall("DataArray")
    return {
        "points": points,
        "cells": {},
        "point_data": {a.get("Name"): [points] for a in arrays},
        "cell_data": {},
        "finite": True,
        "empty": True,
    }


def force_sums(spheres, contacts):
    """(largest |Σ line forces − contact_force| over the spheres, largest |contact_force|);
    `contacts` is None for a time without any contact."""
    applied = spheres.point_data["contact_force"]
    total = np.zeros_like(applied)
    if contacts is not None:
        data = {k: v[0] for k, v in contacts.cell_data.items()}
        force = data["normal_force"] + data["tangential_force"]
        first, second = data["first"].astype(int), data["second"].astype(int)
        scale_first = data.get("scale_first", np.ones(len(first)))[:, None]
        scale_second = data.get("scale_second", np.ones(len(first)))[:, None]
        np.add.at(total, first, scale_first * force)
        pair = second >= 0
        np.add.at(total, second[pair], -(scale_second * force)[pair])
    largest = float(np.abs(applied).max()) if len(applied) else 0.0
    return float(np.abs(total - applied).max()) if len(applied) else 0.0, largest


def main():
    out = sys.argv[1]
    root = ET.parse(os.path.join(out, "results.pvd")).getroot()
    files, by_time = {}, {}
    for entry in root.iter("DataSet"):
        name = entry.get("file")
        path = os.path.join(out, name)
        report = empty(path)
        if report is None:
            mesh = meshio.read(path)
            report = describe(mesh)
            kind = os.path.basename(name).split("_")[0]
            by_time.setdefault(entry.get("timestep"), {})[kind] = mesh
        files[name] = dict(report, part=int(entry.get("part")))
    times = len({entry.get("timestep") for entry in root.iter("DataSet")})
    sums = []
    for time, meshes in by_time.items():
        if "spheres" in meshes:
            error, largest = force_sums(meshes["spheres"], meshes.get("contacts"))
            sums.append({"time": float(time), "error": error, "largest": largest})
    print(json.dumps({"files": files, "force_sums": sums, "times": times}))


if __name__ == "__main__":
    main()
