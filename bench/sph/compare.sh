#!/usr/bin/env bash
# Runs the SPH benchmark dam break in spatter and in SPlisHSPlasH (WCSPH, PyPI package pysplishsplash)
# on this machine, alternating the two codes, and prints the ratios.
#
#   bench/sph/compare.sh                  # full case: a = 80 spacings (about 10^6 fluid particles)
#   N=46 STEPS=5 bench/sph/compare.sh     # quick case
#
# spatter runs twice: with its default smoothing length (h = 1.5 dp, support 3 dp, about 91 interactions
# per particle) and with h = dp, the support of 2 dp (four particle radii) that SPlisHSPlasH fixes, so that
# the particle-steps/s compare like for like. Needs cargo, python3 with venv and pip; the first run
# installs pysplishsplash into a virtual environment under the target directory. Measure on a quiet
# machine: the load average is printed before and after.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
n="${N:-80}"
steps="${STEPS:-5}"
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}"
venv="${SPL_VENV:-$CARGO_TARGET_DIR/splishsplash-venv}"
version="2.19.0"

echo "load: $(uptime)"
(cd "$root" && cargo build --quiet --release -p spatter-sph --example sph_bench)
bin="$CARGO_TARGET_DIR/release/examples/sph_bench"
if ! "$venv/bin/python" -c "import importlib.metadata as m; assert m.version('pysplishsplash') == '$version'" 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet "pysplishsplash==$version"
fi
# The wheel bundles its own libGLdispatch; when the system's libGLX loads too, importing the module
# crashes inside __glDispatchInit. Loading the system's libGLdispatch first avoids that (no GUI is used).
gld="$(ldconfig -p | awk '/libGLdispatch\.so\.0 .*x86-64/ {print $NF; exit}')"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

spl() {
    OMP_NUM_THREADS="$1" LD_PRELOAD="${gld}" "$venv/bin/python" "$here/splishsplash_dam.py" "$n" "$steps" "$work" \
        >"$work/spl_$1.log" 2>&1 || { tail -20 "$work/spl_$1.log" >&2; exit 1; }
    grep '^RESULT' "$work/spl_$1.log"
}
field() { awk -v k="$1" '{for (i = 1; i < NF; i++) if ($i == k) print $(i + 1)}'; }
# spatter's line: "... N steps: W s/step wall, ... R interactions/s, ... P interactions per particle ..."
sp_rate() { awk '{for (i = 1; i < NF; i++) if ($(i + 1) == "interactions/s,") r = $i; else if ($(i + 1) == "interactions" && $(i + 2) == "per" && $(i + 3) == "particle,") p = $i} END {print r, p}'; }

declare -A ps ir
for t in 1 2; do
    line="$(spl "$t")"
    echo "SPlisHSPlasH $t thread(s): $line"
    ps[spl$t]="$(field particle_steps_per_s <<<"$line")"
    ir[spl$t]="$(field interactions_per_s <<<"$line")"
    for h in 1.0 default; do
        if [ "$h" = default ]; then out="$("$bin" "$n" "$t" "$steps")"; else out="$("$bin" "$n" "$t" "$steps" "$h")"; fi
        out="${out%%$'\n'*}"
        echo "spatter h=$h $t thread(s): $out"
        read -r rate per <<<"$(sp_rate <<<"$out")"
        ir[sp$h$t]="$rate"
        ps[sp$h$t]="$(awk -v r="$rate" -v p="$per" 'BEGIN {print r / p}')"
    done
done
echo "load: $(uptime)"
printf '\n| code | threads | particle-steps/s | interactions/s | interactions per particle |\n|---|---|---|---|---|\n'
for t in 1 2; do
    printf '| SPlisHSPlasH %s WCSPH (support 2 dp) | %s | %.3e | %.3e | %.1f |\n' "$version" "$t" "${ps[spl$t]}" "${ir[spl$t]}" \
        "$(awk -v a="${ir[spl$t]}" -v b="${ps[spl$t]}" 'BEGIN {print a / b}')"
    for h in 1.0 default; do
        printf '| spatter, h = %s | %s | %.3e | %.3e | %.1f |\n' "$([ "$h" = default ] && echo 1.5 || echo 1.0) dp" "$t" \
            "${ps[sp$h$t]}" "${ir[sp$h$t]}" "$(awk -v a="${ir[sp$h$t]}" -v b="${ps[sp$h$t]}" 'BEGIN {print a / b}')"
    done
done
for t in 1 2; do
    printf 'ratio spatter/SPlisHSPlasH, %s thread(s): particle-steps/s %.2f at the same support (h = dp), %.2f with the default h; interactions/s %.2f and %.2f\n' "$t" \
        "$(awk -v a="${ps[sp1.0$t]}" -v b="${ps[spl$t]}" 'BEGIN {print a / b}')" \
        "$(awk -v a="${ps[spdefault$t]}" -v b="${ps[spl$t]}" 'BEGIN {print a / b}')" \
        "$(awk -v a="${ir[sp1.0$t]}" -v b="${ir[spl$t]}" 'BEGIN {print a / b}')" \
        "$(awk -v a="${ir[spdefault$t]}" -v b="${ir[spl$t]}" 'BEGIN {print a / b}')"
done
