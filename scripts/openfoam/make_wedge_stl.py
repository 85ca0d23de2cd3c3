#!/usr/bin/env python3
"""Writes the wedge reference body as an ASCII STL with outward normals.

A triangular prism: bottom face z = 0 for 0 <= x <= L, a slope rising from the front edge (x = 0, z = 0)
to the top of the vertical rear face (x = L, z = H), width 2W in y. Usage: make_wedge_stl.py out.stl
"""
import sys

L, H, W = 0.30, 0.12, 0.10
a0, b0, c0 = (0.0, -W, 0.0), (L, -W, 0.0), (L, -W, H)
a1, b1, c1 = (0.0, W, 0.0), (L, W, 0.0), (L, W, H)
quads = [
    (a0, a1, b1, b0),  # bottom, normal -z
    (b0, b1, c1, c0),  # rear face, normal +x
    (a0, c0, c1, a1),  # slope, normal (-H, 0, L)
]
tris = [(a0, b0, c0), (a1, c1, b1)]  # sides -y, +y
for q in quads:
    tris += [(q[0], q[1], q[2]), (q[0], q[2], q[3])]


def sub(p, q):
    return tuple(x - y for x, y in zip(p, q))


def cross(u, v):
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


volume = 0.0
out = ["solid wedge"]
for a, b, c in tris:
    n = cross(sub(b, a), sub(c, a))
    m = sum(x * x for x in n) ** 0.5
    volume += sum(x * y for x, y in zip(a, cross(b, c))) / 6.0
    out.append("  facet normal %g %g %g" % tuple(x / m for x in n))
    out.append("    outer loop")
    for p in (a, b, c):
        out.append("      vertex %.6f %.6f %.6f" % p)
    out.append("    endloop")
    out.append("  endfacet")
out.append("endsolid wedge")
expected = 0.5 * L * H * 2 * W
assert abs(volume - expected) < 1e-12, (volume, expected)  # closed and outward
open(sys.argv[1], "w").write("\n".join(out) + "\n")
