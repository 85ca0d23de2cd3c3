#!/usr/bin/env bash
# Runs DualSPHysics's 3D dam break (examples/main/01_DamBreak, Symplectic, Wendland) and the same dam break
# in spatter on this machine, alternating the two codes on 1 and 2 threads, and prints particle-steps/s and
# the wall time to simulate the same physical time, with their ratios.
#
#   nice -n 10 bench/sph/dualsphysics.sh                    # about 2*10^5 fluid particles, T = 3 ms
#   N=1000000 T=0.001 nice -n 10 bench/sph/dualsphysics.sh  # the full case (23 steps, about 11 minutes)
#
# Environment:
#   N          fluid particles wanted (default 200000); the spacing is dp = (0.4 * 0.67 * 0.3 m^3 / N)^(1/3),
#              rounded to 4 significant digits, and the case gets about N (both codes print their count)
#   T          simulated time [s] each run reaches (default 0.003: about 40 steps at N = 2*10^5)
#   THREADS    thread counts (default "1 2"); RUNS repetitions of the alternation (default 1)
#   DSPH_REPO  DualSPHysics's repository: a URL (default https://github.com/DualSPHysics/DualSPHysics.git,
#              cloned once, without file contents, into the target directory) or a local git directory
#   DSPH_COMMIT  the commit whose solver is built (default: the repository's HEAD)
#   JOBS       parallel compile jobs for the first build (default 2)
#
# DualSPHysics ships no Linux solver binary: its CPU solver is built from src/source with its own
# Makefile_cpu (g++, -O3 -ffast-math, OpenMP on; Chrono, wave generation and MoorDynPlus left out, they
# need prebuilt libraries and the dam break uses none of them), once per commit, under
# $CARGO_TARGET_DIR/dualsphysics/. Its case generator GenCase is a binary in the repository, missing from
# some copies at recent commits: the newest commit at or before DSPH_COMMIT whose GenCase is present is used.
# The example's XML is changed in these keys only: dp, StepAlgorithm = 2 (Symplectic; the example has 1,
# Verlet), Kernel = 2 (Wendland; the example has 1, cubic spline), TimeMax = TimeOut = T. Its coefh
# (h = coefh * sqrt(3) * dp) sets the support 2h, and spatter runs with the same h/dp and DualSPHysics's
# sound speed (from GenCase's summary); everything else on spatter's side is its default physics. In the
# generated case DtIni (the first step) is set to DualSPHysics's CFL step at rest (see below).
# DualSPHysics runs with -sv:none (no particle files); its time is its own "Simulation Runtime" (the steps,
# after loading and initialising the case), spatter's the wall time of its steps after the set-up.
# Logs: $CARGO_TARGET_DIR/dualsphysics/runs/. Measure on a quiet machine: the load is printed before and after.
set -euo pipefail
export LC_ALL=C
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cd "$root"
nwant="${N:-200000}"
t_end="${T:-0.003}"
threads="${THREADS:-1 2}"
runs="${RUNS:-1}"
repo="${DSPH_REPO:-https://github.com/DualSPHysics/DualSPHysics.git}"
jobs="${JOBS:-2}"
target="${CARGO_TARGET_DIR:-target}"
mkdir -p "$target"
target="$(cd "$target" && pwd)"
export CARGO_TARGET_DIR="$target"
dsph="$target/dualsphysics"
mkdir -p "$dsph/runs"

die() { echo "error: $*" >&2; exit 1; }
num() { awk -v v="$1" 'BEGIN {exit !(v ~ /^[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?$/ && v + 0 > 0)}'; }
num "$nwant" || die "N is '$nwant', expected a positive number of fluid particles"
num "$t_end" || die "T is '$t_end', expected a positive simulated time in seconds"
[[ "$runs" =~ ^[1-9][0-9]*$ ]] || die "RUNS is '$runs', expected a whole number of at least 1"
for t in $threads; do [[ "$t" =~ ^[1-9][0-9]*$ ]] || die "THREADS holds '$t', expected whole numbers of at least 1"; done

echo "load: $(uptime)"
# --- DualSPHysics's repository: a local git directory as it is, a URL cloned once (no file contents until
# they are read: the history holds every binary ever committed).
if [ -d "$repo" ] && gd="$(git -C "$repo" rev-parse --absolute-git-dir 2>/dev/null)"; then
    :
else
    gd="$dsph/repo.git"
    if [ ! -d "$gd" ]; then
        git clone --quiet --bare --filter=blob:none "$repo" "$gd.tmp" || die "cannot clone DSPH_REPO=$repo"
        mv "$gd.tmp" "$gd"
    fi
fi
g() { git --git-dir="$gd" "$@"; }
commit="$(g rev-parse --verify "${DSPH_COMMIT:-HEAD}^{commit}")" || die "no commit ${DSPH_COMMIT:-HEAD} in $repo"
short="${commit:0:7}"

# --- The CPU solver, built once per commit.
solver="$dsph/build-$short/DualSPHysicsCPU"
if [ ! -x "$solver" ]; then
    src="$dsph/build-$short/tree"
    rm -rf "$src"
    mkdir -p "$src"
    # (A snapshot without some large binaries makes git name them on stderr; the sources are complete.)
    g archive "$commit" src/source 2>"$dsph/build-$short/archive.log" | tar -x -C "$src" ||
        { cat "$dsph/build-$short/archive.log" >&2; die "cannot read src/source at $short"; }
    echo "building DualSPHysics's CPU solver ($short) in $dsph/build-$short (log: build.log) ..."
    make -C "$src/src/source" -f Makefile_cpu -j"$jobs" COMPILE_CHRONO=NO COMPILE_WAVEGEN=NO \
        COMPILE_MOORDYNPLUS=NO EXECS_DIRECTORY="$dsph/build-$short" EXECNAME=DualSPHysicsCPU \
        >"$dsph/build-$short/build.log" 2>&1 || { tail -20 "$dsph/build-$short/build.log" >&2; die "build failed"; }
    rm -rf "$src"
fi

# --- GenCase: the newest commit at or before $commit whose binary is present.
gencase=""
for c in $(g log --format=%H "$commit" -- bin/linux/GenCase_linux64); do
    if g cat-file -e "$c:bin/linux/GenCase_linux64" 2>/dev/null; then
        gencase="$dsph/GenCase-${c:0:7}"
        if [ ! -x "$gencase" ]; then
            g show "$c:bin/linux/GenCase_linux64" >"$gencase.tmp" && chmod +x "$gencase.tmp" && mv "$gencase.tmp" "$gencase"
        fi
        break
    fi
done
[ -n "$gencase" ] || die "no commit of $repo up to $short holds bin/linux/GenCase_linux64"

# --- The case: the example's XML with dp for about N fluid particles, Symplectic, Wendland, TimeMax = T.
dp="$(awk -v n="$nwant" 'BEGIN {printf "%.4g", (0.4 * 0.67 * 0.3 / n) ^ (1 / 3)}')"
case_dir="$dsph/runs/case_dp$dp"
rm -rf "$case_dir"
mkdir -p "$case_dir"
xml="examples/main/01_DamBreak/CaseDambreak_Def.xml"
g show "$commit:$xml" >"$case_dir/orig.xml" || die "no $xml at $short"
sed -E -e "s/(<definition dp=\")[^\"]*\"/\1$dp\"/" \
    -e "s/(key=\"StepAlgorithm\" value=\")[^\"]*\"/\12\"/" \
    -e "s/(key=\"Kernel\" value=\")[^\"]*\"/\12\"/" \
    -e "s/(key=\"TimeMax\" value=\")[^\"]*\"/\1$t_end\"/" \
    -e "s/(key=\"TimeOut\" value=\")[^\"]*\"/\1$t_end\"/" \
    "$case_dir/orig.xml" >"$case_dir/Dam_Def.xml"
changed="$(diff "$case_dir/orig.xml" "$case_dir/Dam_Def.xml" | grep -c '^>' || true)"
[ "$changed" -le 5 ] && grep -q "dp=\"$dp\"" "$case_dir/Dam_Def.xml" &&
    grep -q 'key="StepAlgorithm" value="2"' "$case_dir/Dam_Def.xml" &&
    grep -q 'key="Kernel" value="2"' "$case_dir/Dam_Def.xml" ||
    die "$xml at $short does not have the keys dp, StepAlgorithm, Kernel, TimeMax, TimeOut this script sets"
(cd "$case_dir" && "$gencase" Dam_Def out/Dam -save:all >gencase.log 2>&1) ||
    { tail -20 "$case_dir/gencase.log" >&2; die "GenCase failed"; }
# GenCase's summary (out/Dam.out): "Fluid....: 194400  id:...", "Coefh:1.000000 (hdp:1.732051)",
# "Speed of sound: 33.6066 (automatic)".
summary="$case_dir/out/Dam.out"
nf_dsph="$(awk '$1 == "Fluid....:" {print $2; exit}' "$summary")"
hdp="$(sed -nE 's/.*\(hdp:([0-9.]+)\).*/\1/p' "$summary" | head -1)"
c0="$(awk '/^Speed of sound: .*automatic|^Speed of sound: [0-9.]+ *$/ {print $4; exit}' "$summary")"
[ -n "$nf_dsph" ] && [ -n "$hdp" ] && [ -n "$c0" ] ||
    die "cannot read the fluid count, hdp or speed of sound from GenCase's summary $summary"
support="$(awk -v r="$hdp" 'BEGIN {printf "%.3f", 2 * r}')"
# DualSPHysics's first step takes DtIni, by default h / c0: five times its CFL step at rest, which in a run of
# a few dozen steps would cover a tenth of T. DtIni is set in the generated case to CFL * h / c0, the step it
# takes from then on (the viscous term of its dt2 is zero at rest), so that the steps count the same work.
cfl="$(sed -nE 's/.*<cflnumber value="([0-9.eE+-]+)".*/\1/p' "$case_dir/out/Dam.xml" | tail -1)"
dtini="$(awk -v c="$cfl" -v r="$hdp" -v dp="$dp" -v c0="$c0" 'BEGIN {if (c > 0) printf "%.6e", c * r * dp / c0}')"
[ -n "$dtini" ] && grep -q 'key="DtIni" value="0"' "$case_dir/out/Dam.xml" ||
    die "cannot set DtIni in $case_dir/out/Dam.xml (cflnumber '$cfl', or no DtIni key with the value 0)"
sed -i -E "s/(key=\"DtIni\" value=\")0\"/\1$dtini\"/" "$case_dir/out/Dam.xml"
echo "case: dp = $dp m, h = $hdp dp (support 2h = $support dp), sound speed $c0 m/s, T = $t_end s," \
    "DualSPHysics's DtIni $dtini s;" \
    "DualSPHysics $short, GenCase ${gencase##*-}"

cargo build --quiet --release -p spatter-sph --example sph_dam_time
sp_bin="$target/release/examples/sph_dam_time"

# One DualSPHysics run; prints "steps S time T wall W excluded E cpu C" (C: user + system seconds of the whole
# process, loading the case included, from /usr/bin/time; "nan" without it). Run.out: "Simulation Runtime.....: W sec.",
# "Runtime per physical second......: R sec." (W / simulated time), "Steps of simulation....: 1,234",
# "Excluded particles.....: 0".
dsph_run() {
    local out="$dsph/runs/dsph_dp${dp}_t$1_r$2"
    local timer=()
    rm -rf "$out" "$out.time"
    if [ -x /usr/bin/time ]; then timer=(/usr/bin/time -f "%U %S" -o "$out.time"); fi
    "${timer[@]}" "$solver" "$case_dir/out/Dam" "$out" -sv:none -ompthreads:"$1" >"$out.log" 2>&1 ||
        { tail -20 "$out.log" >&2; die "DualSPHysics failed (log: $out.log)"; }
    local cpu=nan
    if [ -f "$out.time" ]; then cpu="$(awk 'NF == 2 && $1 ~ /^[0-9.]+$/ {c = $1 + $2} END {if (c != "") print c; else print "nan"}' "$out.time")"; fi
    awk -F': *' -v cpu="$cpu" '
        /^Simulation Runtime\.*/ {w = $2 + 0}
        /^Runtime per physical second\.*/ {r = $2 + 0}
        /^Steps of simulation\.*/ {s = $2; gsub(/[^0-9]/, "", s)}
        /^Excluded particles\.*/ {e = $2; gsub(/[^0-9]/, "", e)}
        END {if (!w || !r || !s) exit 1; printf "steps %d time %.6e wall %.4f excluded %d cpu %s\n", s, w / r, w, e, cpu}
    ' "$out/Run.out" || die "cannot read steps and runtimes from $out/Run.out"
}
field() { awk -v k="$1" '{for (i = 1; i < NF; i++) if ($i == k) print $(i + 1)}'; }
calc() { awk "BEGIN {printf \"$1\", $2}"; }

declare -A R
for ((r = 1; r <= runs; r++)); do
    for t in $threads; do
        line="$(dsph_run "$t" "$r")"
        echo "DualSPHysics $t thread(s), run $r: fluid $nf_dsph $line"
        R[d_steps$t$r]="$(field steps <<<"$line")"
        R[d_time$t$r]="$(field time <<<"$line")"
        R[d_wall$t$r]="$(field wall <<<"$line")"
        R[d_cpu$t$r]="$(field cpu <<<"$line")"
        line="$("$sp_bin" "$dp" "$t" "$t_end" "$hdp" "$c0")" || die "spatter's run failed"
        echo "spatter $t thread(s), run $r: $line"
        for k in fluid steps time_s wall_s cpu_s; do R[s_$k$t$r]="$(field "$k" <<<"$line")"; done
    done
done
echo "load: $(uptime)"

printf '\n| code | threads | run | fluid particles | steps | mean dt [s] | force evaluations per step | wall time [s] | CPU time [s] | particle-steps/s |\n'
printf '|---|---|---|---|---|---|---|---|---|---|\n'
for ((r = 1; r <= runs; r++)); do
    for t in $threads; do
        ds="${R[d_steps$t$r]}" dT="${R[d_time$t$r]}" dw="${R[d_wall$t$r]}"
        ss="${R[s_steps$t$r]}" sT="${R[s_time_s$t$r]}" sw="${R[s_wall_s$t$r]}" sn="${R[s_fluid$t$r]}"
        printf '| DualSPHysics (Symplectic, Wendland) | %s | %s | %s | %s | %.3e | 2 | %.2f | %s | %.3e |\n' \
            "$t" "$r" "$nf_dsph" "$ds" "$(calc %.6e "$dT / $ds")" "$dw" "${R[d_cpu$t$r]}" "$(calc %.6e "$nf_dsph * $ds / $dw")"
        printf '| spatter (velocity Verlet, Wendland) | %s | %s | %s | %s | %.3e | 1 | %.2f | %s | %.3e |\n' \
            "$t" "$r" "$sn" "$ss" "$(calc %.6e "$sT / $ss")" "$sw" "${R[s_cpu_s$t$r]}" "$(calc %.6e "$sn * $ss / $sw")"
    done
done
echo
for ((r = 1; r <= runs; r++)); do
    for t in $threads; do
        ds="${R[d_steps$t$r]}" dT="${R[d_time$t$r]}" dw="${R[d_wall$t$r]}"
        ss="${R[s_steps$t$r]}" sT="${R[s_time_s$t$r]}" sw="${R[s_wall_s$t$r]}" sn="${R[s_fluid$t$r]}"
        # Wall time per simulated second, scaled to the same fluid particle count (the counts differ by the
        # lattice rows each code's walls take; both are printed above).
        a="$(calc %.3f "($sn * $ss / $sw) / ($nf_dsph * $ds / $dw)")"
        b="$(calc %.3f "($dw / $dT / $nf_dsph) / ($sw / $sT / $sn)")"
        c="$(calc %.3f "($dw / $dT) / ($sw / $sT)")"
        echo "ratio spatter/DualSPHysics, $t thread(s), run $r: particle-steps/s $a; wall time to simulate the" \
            "same physical time $b per fluid particle ($c unscaled; support $support dp, $nf_dsph / $sn fluid particles)"
        dc="${R[d_cpu$t$r]}" sc="${R[s_cpu_s$t$r]}"
        if [ "$dc" != nan ] && [ "$sc" != nan ] && [ "$sc" != NaN ]; then
            echo "  particle-steps per CPU-second (the work on a shared machine; DualSPHysics's CPU time includes" \
                "loading its case): $(calc %.3f "($sn * $ss / $sc) / ($nf_dsph * $ds / $dc)")"
        fi
    done
done
