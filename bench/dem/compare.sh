#!/usr/bin/env bash
# Runs the DEM benchmark box in spatter and in LAMMPS on this machine and prints the ratio.
#
#   bench/dem/compare.sh            # full case: 102,400 spheres, 1000 timed steps
#   QUICK=1 STEPS=200 bench/dem/compare.sh
#   METHOD=chunks QUICK=1 bench/dem/compare.sh   # busy machine: fastest of 400 single steps each
#
# Needs `lmp` (Debian package `lammps`, GRANULAR package included) and cargo; with `mpirun` (OpenMPI)
# LAMMPS also runs on two ranks, against spatter's two threads. Measure on a quiet machine: the load
# average is printed first.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
steps="${STEPS:-1000}"
quick="${QUICK:+--quick}"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"

echo "load: $(uptime)"
command -v lmp >/dev/null || { echo "lmp not found: apt-get install -y lammps" >&2; exit 1; }
(cd "$root" && cargo build --quiet --release -p spatter-dem --example dem_bench)

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

if [ "${METHOD:-}" = "chunks" ]; then
    # On a busy machine whole runs are time-sliced; the fastest single step of many approximates the
    # speed on an idle core for both codes alike (same case, same state, 1 thread).
    chunks="${CHUNKS:-400}"
    bin="$CARGO_TARGET_DIR/release/examples/dem_bench"
    out="$("$bin" $quick --lammps-data "$work/box.data" --chunks "$chunks" --chunk-steps 1)"
    echo "$out"
    lx="$(awk '/^box_x/ {print $2}' <<<"$out")"
    ly="$(awk '/^box_y/ {print $2}' <<<"$out")"
    n="$(awk '/^particles/ {print $2}' <<<"$out")"
    spatter1="$(awk '/best_chunk/ {print $2}' <<<"$out")"
    # The same with per-contact energy bookkeeping, and without any (LAMMPS books none).
    outp="$("$bin" $quick --lammps-data "$work/boxp.data" --chunks "$chunks" --chunk-steps 1 --per-contact)"
    spatterp="$(awk '/best_chunk/ {print $2}' <<<"$outp")"
    out0="$("$bin" $quick --lammps-data "$work/box0.data" --chunks "$chunks" --chunk-steps 1 --no-energy)"
    spatter0="$(awk '/best_chunk/ {print $2}' <<<"$out0")"
    (cd "$work" && lmp -in "$here/in.box_chunks" -var data "$work/box.data" -var lx "$lx" -var ly "$ly" \
        -var chunk 1 -var chunks "$chunks" -log "$work/log.lammps" -screen none)
    lammps="$(grep '^Loop time' "$work/log.lammps" | awk -v n="$n" '{print n * $9 / $4}' | sort -g | tail -1)"
    printf 'LAMMPS   1 thread, fastest step: %.4e particle-steps/s\n' "$lammps"
    printf 'spatter  1 thread, fastest step: %.4e particle-steps/s (energy budget, residual method: the default)\n' "$spatter1"
    printf 'spatter  1 thread, fastest step: %.4e particle-steps/s (engine.energy_method = "per_contact")\n' "$spatterp"
    printf 'spatter  1 thread, fastest step: %.4e particle-steps/s (engine.track_energy = false)\n' "$spatter0"
    printf 'ratio spatter/LAMMPS (1 thread): %.2f with the energy budget (default), %.2f per contact, %.2f without\n' \
        "$(awk -v a="$spatter1" -v b="$lammps" 'BEGIN {print a / b}')" \
        "$(awk -v a="$spatterp" -v b="$lammps" 'BEGIN {print a / b}')" \
        "$(awk -v a="$spatter0" -v b="$lammps" 'BEGIN {print a / b}')"
    exit 0
fi
out="$("$CARGO_TARGET_DIR/release/examples/dem_bench" $quick --lammps-data "$work/box.data" --steps "$steps")"
echo "$out"
lx="$(awk '/^box_x/ {print $2}' <<<"$out")"
ly="$(awk '/^box_y/ {print $2}' <<<"$out")"
spatter1="$(awk '/^spatter_threads_1/ {print $2}' <<<"$out")"
spatter2="$(awk '/^spatter_threads_2/ {print $2}' <<<"$out")"
outp="$("$CARGO_TARGET_DIR/release/examples/dem_bench" $quick --lammps-data "$work/boxp.data" --steps "$steps" \
    --threads-only 1 --per-contact)"
spatterp="$(awk '/^spatter_threads_1/ {print $2}' <<<"$outp")"
out0="$("$CARGO_TARGET_DIR/release/examples/dem_bench" $quick --lammps-data "$work/box0.data" --steps "$steps" \
    --threads-only 1 --no-energy)"
spatter0="$(awk '/^spatter_threads_1/ {print $2}' <<<"$out0")"

(cd "$work" && lmp -in "$here/in.box" -var data "$work/box.data" -var lx "$lx" -var ly "$ly" \
    -var steps "$steps" -log "$work/log.lammps" -screen none)
loop="$(grep '^Loop time' "$work/log.lammps" | tail -1)"
echo "LAMMPS: $loop"
# "Loop time of T on P procs for N steps with M atoms"
lammps="$(awk '{print $12 * $9 / $4}' <<<"$loop")"
# LAMMPS on two MPI ranks (the same data file), when mpirun is there.
lammps2=""
if command -v mpirun >/dev/null; then
    root_flag=""
    [ "$(id -u)" = 0 ] && root_flag="--allow-run-as-root"
    (cd "$work" && mpirun $root_flag --oversubscribe -n 2 lmp -in "$here/in.box" -var data "$work/box.data" \
        -var lx "$lx" -var ly "$ly" -var steps "$steps" -log "$work/log2.lammps" -screen none)
    loop2="$(grep '^Loop time' "$work/log2.lammps" | tail -1)"
    echo "LAMMPS, 2 ranks: $loop2"
    lammps2="$(awk '{print $12 * $9 / $4}' <<<"$loop2")"
fi
printf 'LAMMPS   1 thread : %.4e particle-steps/s\n' "$lammps"
[ -n "$lammps2" ] && printf 'LAMMPS   2 ranks  : %.4e particle-steps/s\n' "$lammps2"
printf 'spatter  1 thread : %.4e particle-steps/s\n' "$spatter1"
printf 'spatter  2 threads: %.4e particle-steps/s (parallel efficiency %.0f %%)\n' "$spatter2" \
    "$(awk -v a="$spatter1" -v b="$spatter2" 'BEGIN {print 50 * b / a}')"
[ -n "$lammps2" ] && printf 'ratio spatter 2 threads / LAMMPS 2 ranks: %.2f\n' \
    "$(awk -v a="$spatter2" -v b="$lammps2" 'BEGIN {print a / b}')"
printf 'spatter  1 thread : %.4e particle-steps/s with per-contact energy bookkeeping\n' "$spatterp"
printf 'spatter  1 thread : %.4e particle-steps/s without energy bookkeeping\n' "$spatter0"
printf 'ratio spatter/LAMMPS (1 thread): %.2f with the energy budget (residual, default), %.2f per contact, %.2f without\n' \
    "$(awk -v a="$spatter1" -v b="$lammps" 'BEGIN {print a / b}')" \
    "$(awk -v a="$spatterp" -v b="$lammps" 'BEGIN {print a / b}')" \
    "$(awk -v a="$spatter0" -v b="$lammps" 'BEGIN {print a / b}')"
