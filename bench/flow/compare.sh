#!/usr/bin/env bash
# Runs the 3D lid-driven cube cavity in spatter (spatter-cfd) and in OpenFOAM's icoFoam on the same mesh
# with the same time step, one after the other on this machine, and prints cell-steps/s and the ratio.
#
#   bench/flow/compare.sh                 # N = 100: 10^6 cells, 10 timed steps
#   N=40 STEPS=5 bench/flow/compare.sh    # quick case
#   P_SOLVER=PCG bench/flow/compare.sh    # OpenFOAM pressure by DIC-preconditioned CG instead of GAMG
#
# Case: unit cube, N^3 uniform cells, lid y = 1 moving at 1 m/s in +x, nu = 1e-3 m^2/s (Re = 1000),
# dt = 0.5/N (Courant number 0.5 at the lid), started from rest; 2 steps before the clock starts, then
# STEPS timed steps. Both codes use second-order time stepping (spatter: Adams-Bashforth 2; OpenFOAM:
# backward) and van Leer limited convection, and solve the pressure to a residual of 1e-6 (spatter:
# relative 2-norm; OpenFOAM: its normalised residual, relTol 0, PISO with 2 correctors as in icoFoam).
# OpenFOAM runs serial (1 thread) and with 2 MPI ranks (decomposePar, simple 1x1x2); spatter with 1 and
# 2 rayon threads. Needs cargo and the Debian package `openfoam` (icoFoam, blockMesh, decomposePar,
# mpirun). Logs are kept in $CARGO_TARGET_DIR/flow-compare/. Measure on a quiet machine: the load
# average is printed before and after.
set -euo pipefail
export LC_ALL=C
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cd "$root"
n="${N:-100}"
steps="${STEPS:-10}"
psolver="${P_SOLVER:-GAMG}"
target="${CARGO_TARGET_DIR:-target}"
mkdir -p "$target"
target="$(cd "$target" && pwd)"
export CARGO_TARGET_DIR="$target"
logs="$target/flow-compare"
mkdir -p "$logs"
# The Debian package's etc/bashrc cannot be sourced; the solvers only need to find etc/controlDict.
if [ -z "${WM_PROJECT_DIR:-}" ] && [ -f /usr/share/openfoam/etc/controlDict ]; then
    export WM_PROJECT_DIR=/usr/share/openfoam
fi
for tool in icoFoam blockMesh decomposePar mpirun; do
    command -v "$tool" >/dev/null || { echo "compare.sh: $tool not found; install the Debian package openfoam" >&2; exit 1; }
done

echo "load: $(uptime)"
cargo build --quiet --release -p spatter-cfd --example cfd_bench
bin="$target/release/examples/cfd_bench"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

dt="$(awk -v n="$n" 'BEGIN { printf "%.10g", 0.5 / n }')"
t_warm="$(awk -v d="$dt" 'BEGIN { printf "%.10g", 2 * d }')"
t_end="$(awk -v d="$dt" -v s="$steps" 'BEGIN { printf "%.10g", (2 + s) * d }')"
header() {
    printf 'FoamFile\n{\n    version 2.0;\n    format ascii;\n    class %s;\n    object %s;\n}\n' "$1" "$2"
}
case_dir="$work/cavity"
mkdir -p "$case_dir/system" "$case_dir/constant" "$case_dir/0"
{
    header dictionary blockMeshDict
    cat <<EOT
convertToMeters 1;
vertices ( (0 0 0) (1 0 0) (1 1 0) (0 1 0) (0 0 1) (1 0 1) (1 1 1) (0 1 1) );
blocks ( hex (0 1 2 3 4 5 6 7) ($n $n $n) simpleGrading (1 1 1) );
edges ();
boundary
(
    lid { type wall; faces ( (3 7 6 2) ); }
    walls { type wall; faces ( (0 4 7 3) (2 6 5 1) (1 5 4 0) (0 3 2 1) (4 5 6 7) ); }
);
mergePatchPairs ();
EOT
} >"$case_dir/system/blockMeshDict"
{
    header dictionary controlDict
    cat <<EOT
application icoFoam;
startFrom startTime;
startTime 0;
stopAt endTime;
endTime $t_end;
deltaT $dt;
writeControl timeStep;
writeInterval 100000;
purgeWrite 0;
writeFormat binary;
writePrecision 8;
writeCompression off;
timeFormat general;
timePrecision 8;
runTimeModifiable false;
EOT
} >"$case_dir/system/controlDict"
{
    header dictionary fvSchemes
    cat <<EOT
ddtSchemes { default backward; }
gradSchemes { default Gauss linear; }
divSchemes { default none; div(phi,U) Gauss vanLeerV; }
laplacianSchemes { default Gauss linear orthogonal; }
interpolationSchemes { default linear; }
snGradSchemes { default orthogonal; }
EOT
} >"$case_dir/system/fvSchemes"
if [ "$psolver" = "PCG" ]; then
    psettings="solver PCG; preconditioner DIC;"
else
    psettings="solver GAMG; smoother GaussSeidel;"
fi
{
    header dictionary fvSolution
    cat <<EOT
solvers
{
    p { $psettings tolerance 1e-06; relTol 0; }
    pFinal { \$p; }
    U { solver smoothSolver; smoother symGaussSeidel; tolerance 1e-05; relTol 0; }
}
PISO { nCorrectors 2; nNonOrthogonalCorrectors 0; pRefCell 0; pRefValue 0; }
EOT
} >"$case_dir/system/fvSolution"
{
    header dictionary decomposeParDict
    printf 'numberOfSubdomains 2;\nmethod simple;\nsimpleCoeffs { n (1 1 2); delta 0.001; }\n'
} >"$case_dir/system/decomposeParDict"
{
    header dictionary transportProperties
    printf 'nu [0 2 -1 0 0 0 0] 0.001;\n'
} >"$case_dir/constant/transportProperties"
{
    header volVectorField U
    printf 'dimensions [0 1 -1 0 0 0 0];\ninternalField uniform (0 0 0);\nboundaryField\n{\n'
    printf '    lid { type fixedValue; value uniform (1 0 0); }\n    walls { type noSlip; }\n}\n'
} >"$case_dir/0/U"
{
    header volScalarField p
    printf 'dimensions [0 2 -2 0 0 0 0];\ninternalField uniform 0;\nboundaryField\n{\n'
    printf '    lid { type zeroGradient; }\n    walls { type zeroGradient; }\n}\n'
} >"$case_dir/0/p"

(cd "$case_dir" && blockMesh >"$logs/blockMesh_n$n.log" 2>&1) || { tail -20 "$logs/blockMesh_n$n.log" >&2; exit 1; }
(cd "$case_dir" && decomposePar -force >"$logs/decomposePar_n$n.log" 2>&1) || { tail -20 "$logs/decomposePar_n$n.log" >&2; exit 1; }

# Seconds between the end of the warm-up (time t_warm) and the last step, from icoFoam's ExecutionTime
# (CPU seconds of the master process, 0.01 s resolution; field 3) or ClockTime (wall, whole seconds;
# field 7).
foam_seconds() {
    awk -v tw="$t_warm" -v f="$2" '
        /^Time = / { t = $3 }
        /^ExecutionTime = / { e = $f; if (t + 0 <= tw * (1 + 1e-9)) start = e; last = e }
        END { if (start == "" || last == "") exit 1; printf "%.4f", last - start }' "$1"
}
foam() {
    local threads="$1" log="$logs/icoFoam_n${n}_p$1_${psolver}.log"
    if [ "$threads" = 1 ]; then
        (cd "$case_dir" && icoFoam >"$log" 2>&1) || { tail -20 "$log" >&2; exit 1; }
    else
        (cd "$case_dir" && mpirun --allow-run-as-root --oversubscribe -np 2 icoFoam -parallel >"$log" 2>&1) \
            || { tail -20 "$log" >&2; exit 1; }
    fi
    local cpu wall
    cpu="$(foam_seconds "$log" 3)" || { echo "compare.sh: no ExecutionTime in $log" >&2; exit 1; }
    wall="$(foam_seconds "$log" 7)"
    awk -v a="$wall" -v b="$cpu" -v c="$((n * n * n))" -v k="$steps" 'BEGIN { printf "%.6e %.6e", c * k / a, c * k / b }'
}
ours() {
    local log="$logs/spatter_n${n}_t$1.log"
    "$bin" "$n" "$steps" "$1" >"$log" 2>&1 || { tail -20 "$log" >&2; exit 1; }
    sed -n 's/^RESULT .*seconds=\([0-9.]*\) cpu_seconds=\([0-9.]*\) .*/\1 \2/p' "$log" \
        | awk -v c="$((n * n * n))" -v k="$steps" '{ printf "%.6e %.6e", c * k / $1, ($2 > 0 ? c * k / $2 : 0) }'
}

echo "case: ${n}^3 = $((n * n * n)) cells, dt = $dt s, $steps timed steps, OpenFOAM pressure solver $psolver"
echo "wall: cell-steps per wall-clock second (OpenFOAM's ClockTime has 1 s resolution: use N >= 100);"
echo "cpu:  cell-steps per CPU-second (spatter: all threads; OpenFOAM: master rank) - the fair figure for"
echo "      one thread on a loaded machine"
for threads in 1 2; do
    read -r s_wall s_cpu <<<"$(ours "$threads")"
    read -r f_wall f_cpu <<<"$(foam "$threads")"
    [ -n "$s_wall" ] && [ -n "$f_cpu" ] || { echo "compare.sh: a figure is missing (see $logs)" >&2; exit 1; }
    awk -v t="$threads" -v sw="$s_wall" -v sc="$s_cpu" -v fw="$f_wall" -v fc="$f_cpu" 'BEGIN {
        printf "%d thread(s): wall: spatter %.3e, OpenFOAM %.3e, ratio %.2f | cpu: spatter %.3e, OpenFOAM %.3e, ratio %.2f\n",
            t, sw, fw, sw / fw, sc, fc, sc / fc }'
done
echo "load: $(uptime)"
