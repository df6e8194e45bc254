#!/usr/bin/env python3
"""Reads a VTU written by qdem-io's `write_vtu` with meshio and checks its content.

Usage: meshio_check.py FILE NPOINTS NCELLS

Checks (exit status 0 when all hold, 1 with a message otherwise):
- meshio reads the file;
- it has NPOINTS points and NCELLS cells, all of type "tetra";
- every tetrahedron has positive volume (node order as written);
- point_data["displacement"] equals the linear field u(x) = A x + b below, evaluated at the
  points read back, to 1e-12;
- cell_data["cell_index"] holds 0, 1, ..., NCELLS-1 as Float64.

The field must match `displacement_field` in tests/output_meshio.rs.
"""

import sys

import numpy as np

try:
    import meshio
except ImportError:
    sys.exit("meshio is required: pip install meshio")

A = np.array(
    [
        [1.0e-3, 2.0e-3, -5.0e-1],
        [0.0, -3.0e-3, 1.0 / 3.0],
        [7.0, 0.0, 1.0e-6],
    ]
)
B = np.array([0.1, -0.2, 0.25])


def fail(message):
    sys.exit(f"meshio_check: {message}")


def main():
    if len(sys.argv) != 4:
        fail("usage: meshio_check.py FILE NPOINTS NCELLS")
    path, npoints, ncells = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])

    mesh = meshio.read(path)

    if mesh.points.shape != (npoints, 3):
        fail(f"points shape {mesh.points.shape}, expected ({npoints}, 3)")
    types = [block.type for block in mesh.cells]
    if types != ["tetra"]:
        fail(f"cell blocks {types}, expected a single 'tetra' block")
    tets = mesh.cells[0].data
    if tets.shape != (ncells, 4):
        fail(f"tetra block shape {tets.shape}, expected ({ncells}, 4)")

    p = mesh.points[tets]
    vol = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0]) / 6
    if not np.all(vol > 0):
        fail(f"{np.count_nonzero(vol <= 0)} tetrahedra with non-positive volume")

    if "displacement" not in mesh.point_data:
        fail(f"no point_data['displacement'], have {list(mesh.point_data)}")
    u = mesh.point_data["displacement"]
    if u.shape != (npoints, 3):
        fail(f"displacement shape {u.shape}, expected ({npoints}, 3)")
    expected = mesh.points @ A.T + B
    err = np.max(np.abs(u - expected)) if npoints else 0.0
    if not err <= 1e-12:
        fail(f"displacement differs from the linear field by {err}")

    if "cell_index" not in mesh.cell_data:
        fail(f"no cell_data['cell_index'], have {list(mesh.cell_data)}")
    idx = mesh.cell_data["cell_index"][0]
    if idx.dtype != np.float64 or not np.array_equal(idx, np.arange(ncells, dtype=np.float64)):
        fail(f"cell_index is {idx.dtype} {idx[:8]}..., expected 0..{ncells - 1} as float64")

    print(f"meshio_check: OK ({npoints} points, {ncells} tetra, max |u - u_exact| = {err:.3e})")


if __name__ == "__main__":
    main()
