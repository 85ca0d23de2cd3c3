#!/usr/bin/env bash
# Particle-steps per second of the `dem` kind on 1 and 2 MPI ranks (one thread per rank) on this machine:
# the settling pile of examples/dem_pile.toml enlarged to a 0.24 m × 0.24 m box with its lattice 0.12 m
# high (40 838 grains, about 20 400 per rank on two), run for STEPS steps with no particle output,
# alternating `mpirun -n 1` and `mpirun -n 2` REPEAT times. With WEAK=1 it also measures weak scaling:
# half the box along x (20 048 grains) on one rank against the whole on two, and the machine's ceiling
# for it: two independent one-rank runs of the half box at the same time, one per core, against one
# alone (what sharing the memory system and the clock with a second busy core costs without any
# communication; no split over ranks can do better).
#
#   bench/dem/ranks.sh                     # STEPS=1000, REPEAT=2
#   STEPS=2000 REPEAT=3 WEAK=1 bench/dem/ranks.sh
#
# particle-steps/s = grains × steps / wall time of the run as its log reports it ("completed in … s":
# set-up, the lattice fill and the first output included; the start of mpirun not). The 2-rank
# efficiency is (2-rank rate) / (2 × 1-rank rate), from the best of the rounds of each.
#
# Needs OpenMPI (libopenmpi-dev, openmpi-bin) and libclang-dev; builds `spatter` in release with the `mpi`
# feature, or uses SPATTER=path/to/spatter (built with the feature) as given. Measure on a quiet machine:
# the load average is printed before and after.
set -euo pipefail
export LC_ALL=C
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cd "$root"
steps="${STEPS:-1000}"
repeat="${REPEAT:-2}"
. "$root/bench/mpi_spatter.sh"
dt="$(awk -F' = ' '/^dt_s/ {print $2}' examples/dem_pile.toml)"
duration="$(awk -v n="$steps" -v dt="$dt" 'BEGIN {printf "%.10g", n * dt}')"
# The example in a box of lx × 0.24 m with the lattice 0.12 m high, one output at
# the start and one at the end.
scene() {
    sed -e "s/^duration_s = .*/duration_s = $duration/" \
        -e "s/^output_interval_s = .*/output_interval_s = $duration/" \
        -e "s/point_m = \[0.06, 0, 0\]/point_m = [$1, 0, 0]/" \
        -e "s/point_m = \[0, 0.06, 0\]/point_m = [0, 0.24, 0]/" \
        -e "s/max_m = \[0.06, 0.06, 0.03\]/max_m = [$1, 0.24, 0.12]/" \
        examples/dem_pile.toml
    printf '\n[output]\nparticles_vtu = false\n'
}
scene 0.24 > "$work/pile.toml"
scene 0.12 > "$work/half.toml"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
# Runs scene $1 on $2 ranks; prints "grains steps seconds particle-steps/s".
measure() {
    local out="$work/run_$2_$(basename "$1" .toml)${3:-}"
    mpirun --oversubscribe -n "$2" "$exe" run "$1" --threads 1 --quiet --out "$out" --overwrite \
        >/dev/null 2>"$work/stderr" || { cat "$work/stderr" >&2; exit 1; }
    local last secs
    last="$(tail -1 "$out/energy.csv")"
    secs="$(grep -ho 'completed in [0-9.]* s' "$out/log.txt" | tail -1 | awk '{print $3}')"
    awk -F, -v s="$secs" -v row="$last" 'BEGIN {split(row, c, ","); printf "%d %d %.3f %.4e\n", c[3], c[2], s, c[3] * c[2] / s}'
}
# Two one-rank runs of the half box at once; prints their summed particle-steps/s.
measure_pair() {
    measure "$work/half.toml" 1 _a >"$work/pair_a" &
    measure "$work/half.toml" 1 _b >"$work/pair_b"
    wait
    cat "$work/pair_a" "$work/pair_b" | awk '{s += $4} END {printf "%.4e\n", s}'
}
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
best1=0; best2=0; bestw=0; bestp=0
for r in $(seq "$repeat"); do
    for n in 1 2; do
        read -r grains done secs rate <<<"$(measure "$work/pile.toml" "$n")"
        echo "round $r, $n rank(s): $grains grains, $done steps, $secs s, $rate particle-steps/s"
        if [ "$n" = 1 ]; then best1="$(awk -v a="$best1" -v b="$rate" 'BEGIN {print (b > a ? b : a)}')"; fi
        if [ "$n" = 2 ]; then best2="$(awk -v a="$best2" -v b="$rate" 'BEGIN {print (b > a ? b : a)}')"; fi
    done
    if [ -n "${WEAK:-}" ]; then
        read -r grains done secs rate <<<"$(measure "$work/half.toml" 1)"
        echo "round $r, 1 rank, half the box: $grains grains, $done steps, $secs s, $rate particle-steps/s"
        bestw="$(awk -v a="$bestw" -v b="$rate" 'BEGIN {print (b > a ? b : a)}')"
        rate="$(measure_pair)"
        echo "round $r, two 1-rank runs of the half box at once: $rate particle-steps/s together"
        bestp="$(awk -v a="$bestp" -v b="$rate" 'BEGIN {print (b > a ? b : a)}')"
    fi
done
awk -v a="$best1" -v b="$best2" 'BEGIN {printf "strong scaling (whole box): 2-rank efficiency %.0f %% (best rates %.4e and %.4e)\n", 50 * b / a, a, b}'
if [ -n "${WEAK:-}" ]; then
    awk -v a="$bestw" -v b="$best2" 'BEGIN {printf "weak scaling (half the box per rank): 2-rank efficiency %.0f %% (best rates %.4e and %.4e)\n", 50 * b / a, a, b}'
    awk -v a="$bestw" -v b="$bestp" 'BEGIN {printf "ceiling (two independent half boxes at once): %.0f %% of twice one alone (best rates %.4e and %.4e)\n", 50 * b / a, a, b}'
fi
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
