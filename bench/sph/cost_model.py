#!/usr/bin/env python3
"""Cost model of a large `wading` run of the SPH engine split over MPI ranks (docs/scaling.md).

Predicts the time per step, the wall time and the core-hours of a truck drive through a wading pool
with about 10^8 fluid particles on 16, 64 and 256 nodes, from:

* per-particle costs of one core, measured here on `examples/wading_truck.toml` at three spacings
  (`--measure path/to/spatter` re-measures them; without it the values below, measured 2026-11-26,
  are used): seconds per fluid particle-step and per wall particle-step, fitted by least squares to
  the time per step of one-thread runs;
* the halo of each rank's box: the fluid within two kernel supports of it (the engine's halo width,
  `crates/sph/src/decomp.rs`), counted for the boxes the engine's recursive coordinate bisection cuts
  from the pool's water (a uniform slab), clipped to the water, with the Euclidean distance the engine
  uses;
* the messages of a step on ranks: two neighbour exchanges (migration and halo, one message to each
  peer rank each) and three small all-reductions (the migration check, the time-step maxima and the
  count sums); 56 bytes per halo particle (position, velocity, density);
* an interconnect described by its latency and bandwidth (defaults: an InfiniBand HDR node link,
  200 Gbit/s, shared by the node's ranks; see the option help).

Five ways to run are compared: every wall particle in every rank's wall set (the engine before
2026-11-26); the wall particles within one support of the rank's box (2026-11-26); within one support of
its wall region, the box cut down to the fluid it owns and receives (the engine now), with one rank per
core and with one rank per node and a thread per core (the wall set's per-step rebuild runs on one
thread); and the boundary also stored only where it is needed (not built: today every rank holds the
reference positions of every wall particle). Without `--walls-from` the walls are spread over the ranks
like the water (optimistic: the rank with the most walls sets the pace); with it the largest wall set of
any rank comes from the example's real surfaces (`wall_spread.py`). The scene is the `wading` example's
run as an `sph`-kind scenario without surface tension and adhesion (which do not run on ranks yet).
Only the standard library is used. Every assumption is an option; `--help` lists them.
"""

import argparse
import math
import resource
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import wall_spread

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "wading_truck.toml"

# Measured 2026-11-26 with `bench/sph/cost_model.py --measure target/release/spatter` (one thread,
# release build): seconds of one core per fluid and per wall particle-step on the wading example.
MEASURED_FLUID_S = 4.93e-6
MEASURED_WALL_S = 2.43e-7


def run_cpu(exe, spacing, end, work):
    """One-thread run of the wading example at `spacing` [m] to `end` [s]; returns (fluid, walls,
    steps, CPU seconds of the run)."""
    text = EXAMPLE.read_text()
    text = re.sub(r"(?m)^spacing_m = .*$", f"spacing_m = {spacing}", text)
    text = re.sub(r"(?m)^\[output\]$", f"[output]\nend_time_s = {end}", text)
    scen = work / f"truck_{spacing}_{end}.toml"
    scen.write_text(text)
    for stl in EXAMPLE.parent.glob("wading_truck_*.stl"):
        target = work / stl.name
        if not target.exists():
            target.write_bytes(stl.read_bytes())
    out = work / f"out_{spacing}_{end}"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([exe, "run", str(scen), "--threads", "1", "--quiet", "--overwrite", "--out", str(out)],
                   check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    cost = next(l for l in (out / "log.txt").read_text().splitlines() if "run cost:" in l)
    fluid, walls, steps = (int(x) for x in re.search(r"(\d+) fluid \+ (\d+) wall particles, (\d+) steps", cost).groups())
    return fluid, walls, steps, cpu


def cpu_per_step(exe, spacing, work):
    """CPU seconds per step of the wading example at `spacing` on one thread: the difference of a run
    to 0.15 s and one to 0.05 s over the difference of their steps, so that set-up and outputs cancel
    and other work on the machine does not count."""
    f, w, n1, c1 = run_cpu(exe, spacing, 0.05, work)
    _, _, n2, c2 = run_cpu(exe, spacing, 0.15, work)
    return f, w, (c2 - c1) / (n2 - n1)


def fit_costs(rows):
    """Least squares t = a·fluid + b·walls (no constant) over the rows; returns (a, b)."""
    sff = sum(f * f for f, _, _ in rows)
    sww = sum(w * w for _, w, _ in rows)
    sfw = sum(f * w for f, w, _ in rows)
    sft = sum(f * t for f, _, t in rows)
    swt = sum(w * t for _, w, t in rows)
    det = sff * sww - sfw * sfw
    return (sft * sww - swt * sfw) / det, (swt * sff - sft * sfw) / det


def rcb_boxes(lo, hi, parts):
    """Boxes of recursive coordinate bisection of a uniformly filled box into `parts` pieces: each cut
    across the longest side, at the fraction that gives each side its share of the ranks."""
    if parts == 1:
        return [(lo, hi)]
    axis = max(range(3), key=lambda a: hi[a] - lo[a])
    left = parts // 2
    cut = lo[axis] + (hi[axis] - lo[axis]) * left / parts
    hi_l, lo_r = list(hi), list(lo)
    hi_l[axis] = cut
    lo_r[axis] = cut
    return rcb_boxes(lo, tuple(hi_l), left) + rcb_boxes(tuple(lo_r), hi, parts - left)


def clipped_ball_part(w, ext, n=120):
    """Volume (len(ext) = 3), area (2) or length (1) of {g in [0, ext_i]: |g| <= w}, the part of the
    region beyond a box corner, edge or face that lies within `w` of it and inside the water (midpoint
    rule, n points per axis)."""
    if len(ext) == 1:
        return min(ext[0], w)
    e0 = min(ext[0], w)
    h = e0 / n
    total = 0.0
    for i in range(n):
        g = (i + 0.5) * h
        rest = math.sqrt(max(w * w - g * g, 0.0))
        if len(ext) == 2:
            total += min(ext[1], rest) * h
        else:
            total += clipped_ball_part(rest, ext[1:], n) * h
    return total


def halo_volume(box, water, w):
    """Volume of water within Euclidean distance `w` of `box` but outside it [m^3]."""
    lo, hi = box
    side = [hi[a] - lo[a] for a in range(3)]
    below = [min(w, lo[a] - water[0][a]) for a in range(3)]
    above = [min(w, water[1][a] - hi[a]) for a in range(3)]
    total = 0.0
    # Every combination of (inside, below, above) per axis, except all inside.
    for code in range(27):
        c = [(code // 3**a) % 3 for a in range(3)]
        if c == [0, 0, 0]:
            continue
        inside = math.prod(side[a] for a in range(3) if c[a] == 0)
        ext = [below[a] if c[a] == 1 else above[a] for a in range(3) if c[a] != 0]
        if min(ext) <= 0.0:
            continue
        total += inside * clipped_ball_part(w, ext)
    return total


def box_gap(a, b):
    d2 = 0.0
    for k in range(3):
        g = max(a[0][k] - b[1][k], b[0][k] - a[1][k], 0.0)
        d2 += g * g
    return math.sqrt(d2)


def decomposition(ranks, water, w, dp):
    """(largest halo in particles, mean peers, largest peer count) of `ranks` RCB boxes of the water."""
    boxes = rcb_boxes(water[0], water[1], ranks)
    cache = {}
    halo = 0.0
    for b in boxes:
        key = tuple(round(x, 9) for x in (*[b[1][a] - b[0][a] for a in range(3)],
                                          *[min(w, b[0][a] - water[0][a]) for a in range(3)],
                                          *[min(w, water[1][a] - b[1][a]) for a in range(3)]))
        if key not in cache:
            cache[key] = halo_volume(b, water, w)
        halo = max(halo, cache[key])
    stride = max(1, len(boxes) // 128)
    sample = boxes[::stride]
    peers = [sum(1 for o in boxes if o is not b and box_gap(b, o) <= w) for b in sample]
    return halo / dp**3, sum(peers) / len(peers), max(peers)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--measure", metavar="SPATTER", help="re-measure the per-particle costs with this binary")
    ap.add_argument("--particles", type=float, default=1e8, help="fluid particles of the large case")
    ap.add_argument("--nodes", default="16,64,256", help="node counts to predict")
    ap.add_argument("--cores-per-node", type=int, default=64, help="cores (one rank or thread each) per node")
    ap.add_argument("--latency-us", type=float, default=1.5,
                    help="one point-to-point message, and one stage of a tree all-reduction [us]")
    ap.add_argument("--link-gb-s", type=float, default=25.0,
                    help="node link bandwidth [GB/s], shared by the node's ranks (HDR InfiniBand: 25)")
    ap.add_argument("--halo-cost", type=float, default=1e-7,
                    help="seconds of one core per halo particle and step (binning, state from density)")
    ap.add_argument("--thread-efficiency", type=float, default=0.8,
                    help="parallel efficiency of a node's threads for one rank per node")
    ap.add_argument("--wall-bytes", type=float, default=75.0,
                    help="bytes of the boundary's own arrays per wall particle (reference position and "
                         "normal, volume, area, part, wet flag and time), held by every rank")
    ap.add_argument("--wall-set-bytes", type=float, default=120.0,
                    help="bytes per entry of a rank's wall set (position, velocity, state, grid)")
    ap.add_argument("--chunk-test-s", type=float, default=2e-8,
                    help="seconds to place and test one chunk of 256 wall particles against the rank's box")
    ap.add_argument("--fluid-bytes", type=float, default=412.0,
                    help="bytes held per fluid or halo particle (`spatter bench sph`)")
    ap.add_argument("--walls-from", metavar="RUN",
                    help="take the largest wall set of any rank from the real surfaces of this run of the "
                         "example (its geometry/ folder, e.g. `spatter run examples/wading_truck.toml "
                         "--smoke --out RUN`) instead of spreading the walls like the water")
    args = ap.parse_args()

    # The example's geometry (examples/wading_truck.toml): channel 4 m wide, water 0.3 m deep; the
    # run drives the front axle from x = 3.1 m to the pool's end at 11 m at 3 m/s.
    width, depth, speed, drive = 4.0, 0.3, 3.0, 11.0 - 3.1
    # At spacing 0.1 m the example holds 5 358 fluid and 41 931 wall particles and steps
    # 4.45e-4 s (0.15 s in 337 steps); fluid scales as 1/dp^3, walls (surfaces sampled at the fluid
    # spacing) as 1/dp^2, the acoustic time step as dp.
    ref_dp, ref_fluid, ref_walls, ref_dt = 0.1, 5358, 41931, 0.15 / 337
    cf, cw = MEASURED_FLUID_S, MEASURED_WALL_S
    if args.measure:
        with tempfile.TemporaryDirectory() as tmp:
            rows = [cpu_per_step(args.measure, s, Path(tmp)) for s in (0.15, 0.1, 0.07)]
        for f, wl, t in rows:
            print(f"measured: {f} fluid + {wl} wall particles: {t * 1e3:.2f} ms of CPU per step (1 thread)")
        cf, cw = fit_costs(rows)
        for f, wl, t in rows:
            print(f"  fit {cf * f + cw * wl:.4f} s against {t:.4f} s per step")
    print(f"per core: {cf:.3g} s per fluid particle-step, {cw:.3g} s per wall particle-step")

    dp = ref_dp * (ref_fluid / args.particles) ** (1 / 3)
    walls = ref_walls * (ref_dp / dp) ** 2
    dt = ref_dt * dp / ref_dp
    steps = drive / speed / dt
    length = ref_fluid * ref_dp**3 / (width * depth)  # the pool's water as a full-depth slab
    water = ((0.0, 0.0, 0.0), (length, width, depth))
    support = 3.0 * dp  # h = 1.5 dp, Wendland support 2h (the wading default)
    halo_w = 2.0 * support
    print(f"case: {args.particles:.3g} fluid particles, dp = {dp * 1e3:.2f} mm, {walls:.3g} wall particles, "
          f"water {length:.2f} x {width:.1f} x {depth:.1f} m, dt = {dt:.3g} s, {steps:.3g} steps for "
          f"{drive / speed:.2f} s, halo {halo_w * 1e3:.1f} mm")
    print()
    node_counts = [int(n) for n in args.nodes.split(",")]
    largest = None
    if args.walls_from:
        # The front axle's path through the pool: 3.1 m to 11 m.
        shifts = [0.0, 0.33 * drive, 0.67 * drive, drive]
        rank_counts = sorted({n * c for n in node_counts for c in (1, args.cores_per_node)})
        largest = wall_spread.largest_wall_sets(Path(args.walls_from) / "geometry", depth, rank_counts, dp,
                                                walls, shifts)
        print("largest wall set of any rank from the example's surfaces (the truck at four places on its "
              "path; spread like the water: walls / ranks):")
        print()
        print("| ranks | spread like the water | within a support of the box | within a support of the "
              "wall region (largest) | wall region (mean) |")
        print("|---|---|---|---|---|")
        for r in rank_counts:
            by_box, by_region, mean = largest[r]
            print(f"| {r} | {walls / r:.3g} | {by_box:.3g} | {by_region:.3g} | {mean:.3g} |")
        print()
    print("| layout | nodes | ranks | fluid per rank | halo / fluid | peers (mean, max) | fluid + halo [ms] "
          "| walls [ms] | messages [ms] | step [ms] | wall time [h] | core-hours | memory per node [GB] |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    cores = args.cores_per_node
    lat = args.latency_us * 1e-6
    layouts = [
        # (name, one rank per node, which walls a rank's wall set holds, boundary stored split)
        ("every wall in every rank's wall set (before 2026-11-26), rank per core", False, "all", False),
        ("walls near the box (2026-11-26), rank per core", False, "box", False),
        ("walls near the fluid, rank per core", False, "region", False),
        ("walls near the fluid, rank per node", True, "region", False),
        ("walls near the fluid and stored only there (not built), rank per core", False, "region", True),
    ]
    if largest is None:
        # Spread like the water, both rules alike: keep one of the two rows.
        layouts = [l for l in layouts if l[2] != "box"]
    for nodes in node_counts:
        for name, per_node, held_rule, stored in layouts:
            local = held_rule != "all"
            ranks = nodes if per_node else nodes * cores
            speedup = cores * args.thread_efficiency if per_node else 1.0
            n_rank = args.particles / ranks
            halo, peers_mean, peers_max = decomposition(ranks, water, halo_w, dp)
            # The walls within one support of a box: its share, plus the band one support wide around
            # it (counted like the fluid's halo at that width: an upper bound for surfaces).
            band = decomposition(ranks, water, support, dp)[0] / n_rank
            if not local:
                w_set = walls
            elif largest is None:
                w_set = walls / ranks * (1.0 + band)
            else:
                # The rank with the most walls sets the pace (it owns as much fluid as the others).
                w_set = largest[ranks][0 if held_rule == "box" else 1]
            compute = (cf * n_rank + args.halo_cost * halo) / speedup
            # The per-step rebuild of the wall set (`build_wall_set`) is a serial loop, so the walls of
            # a rank of many threads are charged to one thread; the chunk tests run on all of them.
            wall_t = cw * w_set + (args.chunk_test_s * walls / 256 / speedup if local else 0.0)
            ranks_per_node = 1 if per_node else cores
            bw = args.link_gb_s * 1e9 / ranks_per_node
            reduce_t = 3 * lat * math.ceil(math.log2(ranks)) if ranks > 1 else 0.0
            comm = 2 * lat * peers_max + 56 * halo / bw + reduce_t
            step = compute + wall_t + comm
            hours = steps * step / 3600
            held = w_set if stored else walls
            mem = ranks_per_node * ((n_rank + halo) * args.fluid_bytes + held * args.wall_bytes
                                    + w_set * args.wall_set_bytes) / 1e9
            print(f"| {name} | {nodes} | {ranks} | {n_rank:.3g} | {halo / n_rank:.2f} | "
                  f"{peers_mean:.1f}, {peers_max} | {compute * 1e3:.1f} | {wall_t * 1e3:.1f} | "
                  f"{comm * 1e3:.2f} | {step * 1e3:.1f} | {hours:.3g} | {hours * nodes * cores:.3g} | "
                  f"{mem:.3g} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
