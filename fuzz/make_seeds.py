#!/usr/bin/env python3
"""Writes the small hand-made MSH seeds of fuzz/seeds/ (the fixture copies are made by cp).

One tiny mesh (5 nodes, 2 tetrahedra, a triangle in the surface group "left", a point in
"origin") in the variants the gmsh fixtures do not cover: MSH 4.1 binary with a 4-byte size_t,
big-endian binary of both versions, parametric nodes, and the smallest ASCII files.

    python3 fuzz/make_seeds.py
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
NODES = [(1, (0.0, 0.0, 0.0)), (2, (1.0, 0.0, 0.0)), (3, (0.0, 1.0, 0.0)),
         (4, (0.0, 0.0, 1.0)), (5, (1.0, 1.0, 1.0))]
TETS = [(1, (1, 2, 3, 4)), (2, (2, 3, 4, 5))]
NAMES = b'$PhysicalNames\n3\n0 4 "origin"\n2 2 "left"\n3 1 "body"\n$EndPhysicalNames\n'


def msh22_ascii():
    out = b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n" + NAMES
    out += b"$Nodes\n%d\n" % len(NODES)
    for i, (x, y, z) in NODES:
        out += b"%d %r %r %r\n" % (i, x, y, z)
    out += b"$EndNodes\n$Elements\n4\n"
    out += b"10 15 2 4 1 1\n"
    out += b"11 2 2 2 1 1 2 3\n"
    for i, n in TETS:
        out += b"%d 4 2 1 1 %d %d %d %d\n" % ((i,) + n)
    return out + b"$EndElements\n"


def msh22_binary(endian):
    i32 = lambda *v: struct.pack(endian + "%di" % len(v), *v)
    out = b"$MeshFormat\n2.2 1 8\n" + i32(1) + b"\n$EndMeshFormat\n" + NAMES
    out += b"$Nodes\n%d\n" % len(NODES)
    for i, p in NODES:
        out += i32(i) + struct.pack(endian + "3d", *p)
    out += b"\n$EndNodes\n$Elements\n4\n"
    out += i32(15, 1, 2) + i32(10, 4, 1, 1)
    out += i32(2, 1, 2) + i32(11, 2, 1, 1, 2, 3)
    out += i32(4, 2, 2)
    for i, n in TETS:
        out += i32(i, 1, 1, *n)
    return out + b"\n$EndElements\n"


def msh41(binary, endian="<", size_t=8, parametric=False):
    st = "Q" if size_t == 8 else "I"
    if binary:
        i32 = lambda *v: struct.pack(endian + "%di" % len(v), *v)
        sz = lambda *v: struct.pack(endian + "%d%s" % (len(v), st), *v)
        dbl = lambda *v: struct.pack(endian + "%dd" % len(v), *v)
        nl = b""  # binary sections are one block of data, then "\n$End..."
    else:
        def words(vals, fmt):
            return b"".join((fmt % v).encode() + b" " for v in vals)
        i32 = lambda *v: words(v, "%d")
        sz = lambda *v: words(v, "%d")
        dbl = lambda *v: words(v, "%r")
        nl = b"\n"
    head = b"4.1 %d %d\n" % (1 if binary else 0, size_t)
    out = b"$MeshFormat\n" + head
    if binary:
        out += struct.pack(endian + "i", 1) + b"\n"
    out += b"$EndMeshFormat\n" + NAMES
    # Entities: one point (phys 4), one surface (phys 2), one volume (phys 1).
    out += b"$Entities\n" + sz(1, 0, 1, 1) + nl
    out += i32(1) + dbl(0, 0, 0) + sz(1) + i32(4) + nl
    out += i32(1) + dbl(0, 0, 0, 1, 1, 0) + sz(1) + i32(2) + sz(0) + nl
    out += i32(1) + dbl(0, 0, 0, 1, 1, 1) + sz(1) + i32(1) + sz(1) + i32(1) + nl
    out += (b"\n" if binary else b"") + b"$EndEntities\n"
    # Nodes: the point's node, then the rest in the volume (parametric in the surface).
    out += b"$Nodes\n" + sz(2, len(NODES), 1, len(NODES)) + nl
    out += i32(0, 1, 0) + sz(1) + nl + sz(1) + nl + dbl(*NODES[0][1]) + nl
    rest = NODES[1:]
    if parametric:
        out += i32(2, 1, 1) + sz(len(rest)) + nl
        out += sz(*[i for i, _ in rest]) + nl
        for _, p in rest:
            out += dbl(*p) + dbl(0.5, 0.5) + nl
    else:
        out += i32(3, 1, 0) + sz(len(rest)) + nl
        out += sz(*[i for i, _ in rest]) + nl
        for _, p in rest:
            out += dbl(*p) + nl
    out += (b"\n" if binary else b"") + b"$EndNodes\n"
    out += b"$Elements\n" + sz(3, 4, 1, 13) + nl
    out += i32(0, 1, 15) + sz(1) + nl + sz(10, 1) + nl
    out += i32(2, 1, 2) + sz(1) + nl + sz(11, 1, 2, 3) + nl
    out += i32(3, 1, 4) + sz(len(TETS)) + nl
    for i, n in TETS:
        out += sz(i, *n) + nl
    return out + (b"\n" if binary else b"") + b"$EndElements\n"


SEEDS = {
    "msh_ascii/tiny_22_ascii.msh": msh22_ascii(),
    "msh_ascii/tiny_41_ascii.msh": msh41(False),
    "msh_ascii/tiny_41_ascii_parametric.msh": msh41(False, parametric=True),
    "msh_binary/tiny_22_binary_le.msh": msh22_binary("<"),
    "msh_binary/tiny_22_binary_be.msh": msh22_binary(">"),
    "msh_binary/tiny_41_binary_le_size8.msh": msh41(True, "<", 8),
    "msh_binary/tiny_41_binary_le_size4.msh": msh41(True, "<", 4),
    "msh_binary/tiny_41_binary_be_size8.msh": msh41(True, ">", 8, parametric=True),
}

for name, data in SEEDS.items():
    path = os.path.join(HERE, "seeds", name)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data)
    print(path, len(data))
