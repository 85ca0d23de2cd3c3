"""How the wall particles of the wading example fall on the ranks of a split (bench/sph/cost_model.py
--walls-from): the largest wall set of any rank, from the example's real surfaces, for the engine's two
rules — every wall particle within one support of the rank's box (before 2026-11-27; the outer boxes reach
to infinity) and within one support of its wall region (the box cut down to the fluid it owns and receives,
widened to a lattice of two supports; `Decomp::wall_region` in crates/sph/src/decomp.rs).

The water is the pool's still water (the road surface of `channel_road.stl`, filled to its lowest point
plus the water depth) on a lattice; the split is the engine's recursive coordinate bisection of it; the
walls are the surfaces of the run's `geometry/*.stl` cut into pieces no wider than a sampling spacing,
each counting its area. Wall particles are taken proportional to area (the run's total over its total
area). Distances are per axis (a box test), which counts a few more pieces near box corners than the
engine's Euclidean test. The fluid a rank receives is taken as its own water's bounds widened by the
halo width; the engine's halo is the fluid within that width of the rank's box, which along a long cut
face can reach farther, so the regions here may be slightly small. Spray is not modelled: a drop thrown
far from the water widens its rank's region.
Only the standard library is used.
"""

import math
from pathlib import Path

INF = math.inf


def read_ascii_stl(path):
    """Triangles of an ASCII STL file, each three (x, y, z) tuples."""
    tris, cur = [], []
    for line in Path(path).read_text().splitlines():
        words = line.split()
        if words and words[0] == "vertex":
            cur.append(tuple(float(v) for v in words[1:4]))
            if len(cur) == 3:
                tris.append(cur)
                cur = []
    return tris


def pieces(tri, spacing):
    """(centre, area) of the n² pieces of `tri` cut by a lattice of n = ⌈longest edge / spacing⌉."""
    a, b, c = tri
    n = max(1, math.ceil(max(math.dist(a, b), math.dist(b, c), math.dist(c, a)) / spacing))
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    cross = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    area = 0.5 * math.sqrt(sum(x * x for x in cross)) / (n * n)
    out = []
    for i in range(n):
        for j in range(n - i):
            # The upright piece (i, j) and, where it exists, the inverted one beside it.
            for s, t in (((i + 1 / 3) / n, (j + 1 / 3) / n), ((i + 2 / 3) / n, (j + 2 / 3) / n)):
                if s + t < 1.0:
                    out.append((tuple(a[k] + s * u[k] + t * v[k] for k in range(3)), area))
    return out


def road_height(road, x, y):
    """Highest road surface under (x, y) [m], or None."""
    best = None
    for a, b, c in road:
        d = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1])
        if d == 0:
            continue
        l1 = ((b[1] - c[1]) * (x - c[0]) + (c[0] - b[0]) * (y - c[1])) / d
        l2 = ((c[1] - a[1]) * (x - c[0]) + (a[0] - c[0]) * (y - c[1])) / d
        l3 = 1 - l1 - l2
        if min(l1, l2, l3) >= -1e-12:
            z = l1 * a[2] + l2 * b[2] + l3 * c[2]
            best = z if best is None else max(best, z)
    return best


def still_water(road, depth, lattice):
    """Lattice points of the still water over the road up to its lowest point + `depth`."""
    xs = [p[0] for t in road for p in t]
    ys = [p[1] for t in road for p in t]
    level = min(p[2] for t in road for p in t) + depth
    pts = []
    for i in range(int((max(xs) - min(xs)) / lattice)):
        x = min(xs) + (i + 0.5) * lattice
        for j in range(int((max(ys) - min(ys)) / lattice)):
            y = min(ys) + (j + 0.5) * lattice
            z0 = road_height(road, x, y)
            if z0 is None:
                continue
            for k in range(int((level - z0) / lattice)):
                pts.append((x, y, z0 + (k + 0.5) * lattice))
    return pts


def split(points, ranks):
    """The engine's recursive coordinate bisection (crates/core/src/rcb.rs) with infinite outer faces.
    Returns (tree, boxes, bounds): a tree of (axis, cut, low, high) nodes and rank leaves, every rank's
    box, and the bounding box of its points."""
    boxes, bounds = [], []

    def go(pts, n, box):
        if n == 1:
            boxes.append(box)
            bounds.append(tuple((min(p[a] for p in pts), max(p[a] for p in pts)) for a in range(3)))
            return len(boxes) - 1
        ext = [max(p[a] for p in pts) - min(p[a] for p in pts) for a in range(3)]
        axis = max(range(3), key=lambda a: ext[a])
        pts = sorted(pts, key=lambda p: p[axis])
        left = n // 2
        m = len(pts) * left // n
        at = 0.5 * (pts[m - 1][axis] + pts[m][axis])
        lo = [list(r) for r in box]
        hi = [list(r) for r in box]
        lo[axis][1] = at
        hi[axis][0] = at
        return (axis, at, go(pts[:m], left, tuple(map(tuple, lo))), go(pts[m:], n - left, tuple(map(tuple, hi))))

    tree = go(points, ranks, ((-INF, INF),) * 3)
    return tree, boxes, bounds


def wall_regions(boxes, bounds, support, halo):
    """Each rank's wall region: its box cut to its water's bounds widened by the halo (the fluid it
    receives) and one support, outward to multiples of two supports."""
    step = 2.0 * support
    out = []
    for box, bd in zip(boxes, bounds):
        r = []
        for a in range(3):
            lo = math.floor((bd[a][0] - halo - support) / step) * step
            hi = math.ceil((bd[a][1] + halo + support) / step) * step
            r.append((max(box[a][0], lo), min(box[a][1], hi)))
        out.append(tuple(r))
    return out


def held_area(tree, regions, ranks, samples, reach):
    """Per rank: wall area within `reach` of its box and of its wall region (per axis) [m²]."""
    by_box = [0.0] * ranks
    by_region = [0.0] * ranks
    for p, area in samples:
        stack = [tree]
        while stack:
            node = stack.pop()
            if isinstance(node, int):
                by_box[node] += area
                r = regions[node]
                if all(r[a][0] - reach <= p[a] <= r[a][1] + reach for a in range(3)):
                    by_region[node] += area
                continue
            axis, at, lo, hi = node
            if p[axis] < at + reach:
                stack.append(lo)
            if p[axis] >= at - reach:
                stack.append(hi)
    return by_box, by_region


def largest_wall_sets(geometry, depth, ranks_list, dp, walls_total, shifts, spacing=0.04, lattice=0.025):
    """For each rank count: (largest wall set by box, by wall region, mean by region) over the vehicle
    shifted along x by each of `shifts` [m] (its path through the pool), in wall particles, from the run's
    `geometry` folder (channel parts `channel_*.stl` fixed, the rest the vehicle)."""
    geometry = Path(geometry)
    road = read_ascii_stl(geometry / "channel_road.stl")
    fixed, vehicle = [], []
    for f in sorted(geometry.glob("*.stl")):
        into = fixed if f.name.startswith("channel_") else vehicle
        for t in read_ascii_stl(f):
            into.extend(pieces(t, spacing))
    per_area = walls_total / (sum(a for _, a in fixed) + sum(a for _, a in vehicle))
    water = still_water(road, depth, lattice)
    support = 3.0 * dp
    out = {}
    for ranks in ranks_list:
        tree, boxes, bounds = split(water, ranks)
        regions = wall_regions(boxes, bounds, support, 2.0 * support)
        worst = [0.0, 0.0, 0.0]
        for dx in shifts:
            samples = fixed + [((p[0] + dx, p[1], p[2]), a) for p, a in vehicle]
            by_box, by_region = held_area(tree, regions, ranks, samples, support)
            worst[0] = max(worst[0], max(by_box) * per_area)
            worst[1] = max(worst[1], max(by_region) * per_area)
            worst[2] = max(worst[2], sum(by_region) / ranks * per_area)
        out[ranks] = tuple(worst)
    return out
