#!/usr/bin/env python3
"""Writes the wading channel of examples/wading_channel_stl.toml as one multi-solid ASCII STL file.

Coordinates in metres: x along the channel (the direction of travel), y across (0 in the middle), z up,
the road at z = 0 outside the pool.
  wading_channel.stl   solids road (approach, entry ramp, pool floor, exit ramp, exit road),
                       wall_left (y = +2), wall_right (y = -2)
The entry ramp (2.5 m) is longer than the exit ramp (1.5 m), unlike a generated channel. The road faces
up, the walls face into the channel. Run: python3 wading_channel_parts.py
"""
# The STL writer of the truck's parts (same folder).
from wading_truck_parts import write

HALF_WIDTH = 2.0   # walls at y = -2 and +2 [m]
WALL_TOP = 1.0     # wall top above the road [m]
# Road profile along the centre line: (x, z) break points [m].
PROFILE = [(0.0, 0.0), (5.0, 0.0), (7.5, -0.5), (12.5, -0.5), (14.0, 0.0), (15.0, 0.0)]


def road():
    tris = []
    for (x0, z0), (x1, z1) in zip(PROFILE, PROFILE[1:]):
        a, b = (x0, -HALF_WIDTH, z0), (x1, -HALF_WIDTH, z1)
        c, d = (x1, HALF_WIDTH, z1), (x0, HALF_WIDTH, z0)
        tris += [(a, b, c), (a, c, d)]
    return tris


def wall(y):
    tris = []
    for (x0, z0), (x1, z1) in zip(PROFILE, PROFILE[1:]):
        a, b = (x0, y, z0), (x1, y, z1)
        c, d = (x1, y, WALL_TOP), (x0, y, WALL_TOP)
        # Normal towards the channel's middle: -y for the wall at +y, +y for the wall at -y.
        tris += [(a, b, c), (a, c, d)] if y > 0 else [(a, c, b), (a, d, c)]
    return tris


write("wading_channel.stl", [("road", road()), ("wall_left", wall(HALF_WIDTH)), ("wall_right", wall(-HALF_WIDTH))])
