#!/usr/bin/env bash
# Latency of the collectives a DEM or SPH step on ranks waits for, on this machine: MPI_Allreduce of two
# doubles (the step's reductions: the largest speed and a rebuild flag, the largest overlap, ...) and a
# ping-pong of a 1 kB message (a small ghost refresh), each timed over ITER calls between two ranks that
# do nothing else (no waiting for a slower rank: the cost of the call itself).
#
#   bench/mpi/latency.sh              # ITER=20000, RANKS=2
#
# Needs mpicc and mpirun (libopenmpi-dev, openmpi-bin). Prints microseconds per call on rank 0.
set -euo pipefail
iter="${ITER:-20000}"
ranks="${RANKS:-2}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cat >"$work/latency.c" <<'C'
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    int rank, size;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    int n = argc > 1 ? atoi(argv[1]) : 20000;
    double in[2] = {1.0 + rank, 2.0}, out[2];
    for (int i = 0; i < n / 10; i++) MPI_Allreduce(in, out, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    double t0 = MPI_Wtime();
    for (int i = 0; i < n; i++) MPI_Allreduce(in, out, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    double t1 = MPI_Wtime();
    char buf[1024] = {0};
    int peer = rank ^ 1;
    double t2 = 0.0, t3 = 0.0;
    if (peer < size) {
        MPI_Barrier(MPI_COMM_WORLD);
        t2 = MPI_Wtime();
        for (int i = 0; i < n; i++) {
            if (rank % 2 == 0) {
                MPI_Send(buf, sizeof buf, MPI_BYTE, peer, 0, MPI_COMM_WORLD);
                MPI_Recv(buf, sizeof buf, MPI_BYTE, peer, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            } else {
                MPI_Recv(buf, sizeof buf, MPI_BYTE, peer, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
                MPI_Send(buf, sizeof buf, MPI_BYTE, peer, 0, MPI_COMM_WORLD);
            }
        }
        t3 = MPI_Wtime();
    }
    if (rank == 0) {
        printf("%d ranks, %d calls: MPI_Allreduce of 2 doubles %.2f us; 1 kB one way (half a ping-pong) %.2f us\n",
               size, n, (t1 - t0) / n * 1e6, (t3 - t2) / n / 2 * 1e6);
    }
    MPI_Finalize();
    return 0;
}
C
mpicc -O2 "$work/latency.c" -o "$work/latency"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
mpirun --oversubscribe -n "$ranks" "$work/latency" "$iter"
