#!/usr/bin/env python3
"""Writes the wedge reference body as an STL with outward normals.

A triangular prism: bottom face z = 0 for 0 <= x <= L, a slope rising from the front edge (x = 0, z = 0)
to the top of the vertical rear face (x = L, z = H), width 2W in y.

    make_wedge_stl.py out.stl               8 triangles, ASCII (the CFD geometry for snappyHexMesh)
    make_wedge_stl.py out.stl --cell 0.01   every face split into triangles of about 1 cm, binary
                                            (the deposition body: deposits are counted per triangle)
"""
import struct
import sys

L, H, W = 0.30, 0.12, 0.10
a0, b0, c0 = (0.0, -W, 0.0), (L, -W, 0.0), (L, -W, H)
a1, b1, c1 = (0.0, W, 0.0), (L, W, 0.0), (L, W, H)
quads = [
    (a0, a1, b1, b0),  # bottom, normal -z
    (b0, b1, c1, c0),  # rear face, normal +x
    (a0, c0, c1, a1),  # slope, normal (-H, 0, L)
]
sides = [(a0, b0, c0), (a1, c1, b1)]  # -y, +y


def sub(p, q):
    return tuple(x - y for x, y in zip(p, q))


def lerp(p, q, t):
    return tuple(x + t * (y - x) for x, y in zip(p, q))


def length(v):
    return sum(x * x for x in v) ** 0.5


def cross(u, v):
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


cell = None
if "--cell" in sys.argv:
    cell = float(sys.argv[sys.argv.index("--cell") + 1])

tris = []
if cell is None:
    tris += sides
    for q in quads:
        tris += [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
else:
    for q in quads:
        nu = max(1, round(length(sub(q[1], q[0])) / cell))
        nv = max(1, round(length(sub(q[3], q[0])) / cell))
        point = lambda i, j: lerp(lerp(q[0], q[1], i / nu), lerp(q[3], q[2], i / nu), j / nv)
        for i in range(nu):
            for j in range(nv):
                p00, p10, p11, p01 = point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)
                tris += [(p00, p10, p11), (p00, p11, p01)]
    for a, b, c in sides:
        n = max(1, round(max(length(sub(b, a)), length(sub(c, b)), length(sub(a, c))) / cell))
        point = lambda i, j: tuple(a[k] + (b[k] - a[k]) * i / n + (c[k] - a[k]) * j / n for k in range(3))
        for i in range(n):
            for j in range(n - i):
                tris.append((point(i, j), point(i + 1, j), point(i, j + 1)))
                if i + j + 1 < n:
                    tris.append((point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)))

volume = sum(sum(x * y for x, y in zip(a, cross(b, c))) / 6.0 for a, b, c in tris)
expected = 0.5 * L * H * 2 * W
assert abs(volume - expected) < 1e-12, (volume, expected)  # closed and outward

if cell is None:
    out = ["solid wedge"]
    for a, b, c in tris:
        n = cross(sub(b, a), sub(c, a))
        m = length(n)
        out.append("  facet normal %g %g %g" % tuple(x / m for x in n))
        out.append("    outer loop")
        for p in (a, b, c):
            out.append("      vertex %.6f %.6f %.6f" % p)
        out.append("    endloop")
        out.append("  endfacet")
    out.append("endsolid wedge")
    open(sys.argv[1], "w").write("\n".join(out) + "\n")
else:
    with open(sys.argv[1], "wb") as f:
        f.write(b"wedge reference body".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for a, b, c in tris:
            n = cross(sub(b, a), sub(c, a))
            m = length(n)
            f.write(struct.pack("<12fH", *(x / m for x in n), *a, *b, *c, 0))
