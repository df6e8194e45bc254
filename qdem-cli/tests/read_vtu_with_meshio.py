"""Read a VTU written by `qdem run` with meshio and print, as one JSON object, what
`run_end_to_end.rs` checks.

usage: python3 read_vtu_with_meshio.py FILE.vtu X Y Z

Prints the number of points, the number of tetra cells, the other cell types, the point and
cell data names with their shapes, and the displacement of the point nearest to (X, Y, Z)
(the VTU points are the reference coordinates). Floats are printed with Python's repr, which
round-trips exactly.
"""

import json
import sys

import meshio
import numpy as np


def main():
    path = sys.argv[1]
    target = np.array([float(v) for v in sys.argv[2:5]])
    mesh = meshio.read(path)
    tetra = sum(len(block.data) for block in mesh.cells if block.type == "tetra")
    other = sorted({block.type for block in mesh.cells if block.type != "tetra"})
    distance = np.linalg.norm(mesh.points - target, axis=1)
    nearest = int(np.argmin(distance))
    displacement = mesh.point_data.get("displacement")
    report = {
        "points": int(len(mesh.points)),
        "tetra": int(tetra),
        "other_cell_types": other,
        "point_data": {k: list(np.shape(v)) for k, v in mesh.point_data.items()},
        "cell_data": {
            k: [list(np.shape(block)) for block in v] for k, v in mesh.cell_data.items()
        },
        "cell_data_finite": bool(
            all(np.all(np.isfinite(block)) for v in mesh.cell_data.values() for block in v)
        ),
        "nearest": nearest,
        "nearest_distance": float(distance[nearest]),
        "nearest_displacement": (
            None if displacement is None else [float(x) for x in displacement[nearest]]
        ),
    }
    print(json.dumps(report))


if __name__ == "__main__":
    main()
