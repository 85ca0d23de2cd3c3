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
# installs pysplishsplash into a virtual environment (SPL_VENV, default under the target directory).
# SPlisHSPlasH's logs are kept in $CARGO_TARGET_DIR/sph-compare/. Measure on a quiet machine: the load
# average is printed before and after.
set -euo pipefail
export LC_ALL=C
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cd "$root"
n="${N:-80}"
steps="${STEPS:-5}"
target="${CARGO_TARGET_DIR:-target}"
mkdir -p "$target"
target="$(cd "$target" && pwd)"
export CARGO_TARGET_DIR="$target"
venv="${SPL_VENV:-$target/splishsplash-venv}"
logs="$target/sph-compare"
version="2.19.0"

echo "load: $(uptime)"
cargo build --quiet --release -p spatter-sph --example sph_bench
bin="$target/release/examples/sph_bench"
if ! "$venv/bin/python" -c "import importlib.metadata as m; assert m.version('pysplishsplash') == '$version'" 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet "pysplishsplash==$version"
fi
# The wheel bundles its own libGLdispatch; when the system's libGLX loads too, importing the module
# crashes inside __glDispatchInit. Loading the system's libGLdispatch first avoids that (no GUI is used).
gld="$({ ldconfig -p || /sbin/ldconfig -p; } 2>/dev/null | awk '/libGLdispatch\.so\.0 .*x86-64/ && !f {print $NF; f = 1}' || true)"
preload="${LD_PRELOAD:-}"
if [ -n "$gld" ]; then preload="$gld${preload:+ $preload}"; fi
mkdir -p "$logs"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

spl() {
    local log="$logs/splishsplash_n${n}_t$1.log"
    OMP_NUM_THREADS="$1" LD_PRELOAD="$preload" "$venv/bin/python" "$here/splishsplash_dam.py" "$n" "$steps" "$work" \
        >"$log" 2>&1 || { tail -20 "$log" >&2; exit 1; }
    grep '^RESULT' "$log"
}
field() { awk -v k="$1" '{for (i = 1; i < NF; i++) if ($i == k) print $(i + 1)}'; }
# spatter's line: "... N steps: ... S particle-steps/s, R interactions/s, ..."
sp_rates() { awk '{for (i = 1; i < NF; i++) if ($(i + 1) == "particle-steps/s,") s = $i; else if ($(i + 1) == "interactions/s,") r = $i} END {print s, r}'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN {if (a == "" || b == "" || b == 0) exit 1; print a / b}'; }

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
        read -r "ps[sp$h$t]" "ir[sp$h$t]" <<<"$(sp_rates <<<"$out")"
    done
done
echo "load: $(uptime)"
# Every ratio is computed before printing, so that a missing figure stops the script instead of printing 0.
printf '\n| code | threads | particle-steps/s | interactions/s | interactions per particle |\n|---|---|---|---|---|\n'
for t in 1 2; do
    per="$(ratio "${ir[spl$t]}" "${ps[spl$t]}")"
    printf '| SPlisHSPlasH %s WCSPH (support 2 dp) | %s | %.3e | %.3e | %.1f |\n' "$version" "$t" "${ps[spl$t]}" "${ir[spl$t]}" "$per"
    for h in 1.0 default; do
        per="$(ratio "${ir[sp$h$t]}" "${ps[sp$h$t]}")"
        label="$([ "$h" = default ] && echo 1.5 || echo 1.0) dp"
        printf '| spatter, h = %s | %s | %.3e | %.3e | %.1f |\n' "$label" "$t" "${ps[sp$h$t]}" "${ir[sp$h$t]}" "$per"
    done
done
for t in 1 2; do
    a="$(ratio "${ps[sp1.0$t]}" "${ps[spl$t]}")"
    b="$(ratio "${ps[spdefault$t]}" "${ps[spl$t]}")"
    c="$(ratio "${ir[sp1.0$t]}" "${ir[spl$t]}")"
    d="$(ratio "${ir[spdefault$t]}" "${ir[spl$t]}")"
    printf 'ratio spatter/SPlisHSPlasH, %s thread(s): particle-steps/s %.2f at the same support (h = dp), %.2f with the default h; interactions/s %.2f and %.2f\n' "$t" "$a" "$b" "$c" "$d"
done
