#!/usr/bin/env bash
# Particle-steps per second of the `sph` kind on 1 and 2 MPI ranks (one thread per rank) on this machine:
# the 3D dam break example (16 000 fluid and 53 628 wall particles) run to END seconds of simulated time,
# alternating `mpirun -n 1` and `mpirun -n 2` REPEAT times, each printing the run-cost line.
#
#   bench/sph/ranks.sh                  # END=0.02 s (about 300 steps), REPEAT=2
#   END=0.05 REPEAT=3 bench/sph/ranks.sh
#
# Needs OpenMPI (libopenmpi-dev, openmpi-bin) and libclang-dev; builds `spatter` in release with the `mpi`
# feature, or uses SPATTER=path/to/spatter (built with the feature) as given. Measure on a quiet machine:
# the load average is printed before and after.
set -euo pipefail
export LC_ALL=C
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cd "$root"
end="${END:-0.02}"
repeat="${REPEAT:-2}"
. "$root/bench/mpi_spatter.sh"
# The example with a shorter end time and no particle output beyond the first.
sed -e "s/^end_time_s = .*/end_time_s = $end/" -e "s/^vtu_interval_s = .*/vtu_interval_s = 10.0/" \
    examples/sph_dam_break.toml > "$work/dam.toml"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
for r in $(seq "$repeat"); do
    for n in 1 2; do
        line="$(mpirun --oversubscribe -n "$n" "$exe" run "$work/dam.toml" --threads 1 --quiet \
            --out "$work/run$n" --overwrite >/dev/null 2>&1; grep -h "run cost" "$work/run$n/log.txt" | tail -1)"
        echo "round $r, $n rank(s): ${line#*run cost: }"
    done
done
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
