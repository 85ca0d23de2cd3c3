#!/usr/bin/env python3
"""Writes the simplified truck of examples/wading_truck.toml as three multi-solid ASCII STL files.

Coordinates in metres: x forward, y across (to the left), z up, the road at z = 0 under the wheels.
  wading_truck_body.stl     solids cab, chassis
  wading_truck_wheels.stl   solids wheel_fl, wheel_fr, wheel_rl, wheel_rr (radius 0.5 m, 24-gon prisms)
  wading_truck_sensors.stl  solids mirror_left, mirror_right, camera_front, camera_side
Every solid is closed and its triangles face outwards. Run: python3 wading_truck_parts.py
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
R, TYRE = 0.5, 0.3          # wheel radius and tyre width [m]
REAR_X, FRONT_X, TRACK = 0.0, 3.8, 2.0  # axle positions and distance between tyre centres [m]


def box(lo, hi):
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (1, 2, 6, 5), (3, 0, 4, 7)]
    tris = []
    for a, b, c, d in quads:
        tris += [(v[a], v[b], v[c]), (v[a], v[c], v[d])]
    return tris


def wheel(cx, cy, cz, n=24):
    """A closed n-gon prism about the y axis: tread and two fan caps."""
    y0, y1 = cy - 0.5 * TYRE, cy + 0.5 * TYRE
    ring = [(cx + R * math.cos(2 * math.pi * k / n), cz + R * math.sin(2 * math.pi * k / n)) for k in range(n)]
    tris = []
    for k in range(n):
        (xa, za), (xb, zb) = ring[k], ring[(k + 1) % n]
        a0, b0, a1, b1 = (xa, y0, za), (xb, y0, zb), (xa, y1, za), (xb, y1, zb)
        tris += [(a0, b1, b0), (a0, a1, b1)]
        tris += [((cx, y0, cz), a0, b0), ((cx, y1, cz), b1, a1)]
    return tris


def write(name, solids):
    path = os.path.join(HERE, name)
    with open(path, "w") as f:
        for solid, tris in solids:
            f.write(f"solid {solid}\n")
            for a, b, c in tris:
                u = [b[i] - a[i] for i in range(3)]
                w = [c[i] - a[i] for i in range(3)]
                n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
                ln = math.sqrt(sum(x * x for x in n)) or 1.0
                f.write("facet normal {:.6g} {:.6g} {:.6g}\n outer loop\n".format(*(x / ln for x in n)))
                for p in (a, b, c):
                    f.write("  vertex {:.6f} {:.6f} {:.6f}\n".format(*p))
                f.write(" endloop\nendfacet\n")
            f.write(f"endsolid {solid}\n")
    print("wrote", path)


if __name__ == "__main__":
    half = 0.5 * TRACK
    write("wading_truck_body.stl", [
        ("cab", box((3.3, -1.25, 1.1), (5.3, 1.25, 3.2))),
        ("chassis", box((-1.2, -0.55, 0.6), (5.3, 0.55, 1.05))),
    ])
    write("wading_truck_wheels.stl", [
        ("wheel_fl", wheel(FRONT_X, half, R)),
        ("wheel_fr", wheel(FRONT_X, -half, R)),
        ("wheel_rl", wheel(REAR_X, half, R)),
        ("wheel_rr", wheel(REAR_X, -half, R)),
    ])
    write("wading_truck_sensors.stl", [
        ("mirror_left", box((4.9, 1.3, 2.2), (5.05, 1.45, 2.5))),
        ("mirror_right", box((4.9, -1.45, 2.2), (5.05, -1.3, 2.5))),
        ("camera_front", box((5.3, -0.1, 0.6), (5.4, 0.1, 0.72))),
        ("camera_side", box((4.3, 1.25, 1.15), (4.45, 1.32, 1.27))),
    ])
