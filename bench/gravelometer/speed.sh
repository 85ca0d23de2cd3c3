#!/usr/bin/env bash
# Wall time of the DIN 55996-1 gravelometer preset at its published size with coupled air (k–ε):
# builds the release binary, runs bench/gravelometer/din_full_coupled.toml and prints
#   * the run's set-up (grid, DEM and fluid steps, DEM steps per fluid step);
#   * per output interval: simulated time, stones and member spheres in the domain, wall time of the
#     interval and wall seconds per simulated second (from the times the fluid fields were written);
#   * the split of a coupling step between fluid, void fraction, forces and DEM (over the whole run,
#     from the run's summary; "DEM" is everything between two fluid steps: the DEM steps, injection,
#     events, wear and the scene's outputs).
#
#   bench/gravelometer/speed.sh                         # 2 threads, duration_s of the scenario file
#   THREADS=1 DURATION=0.05 bench/gravelometer/speed.sh # another thread count, a shorter window
#   OUT=runs/din_speed bench/gravelometer/speed.sh      # keep the run folder elsewhere
#
# Measure on a quiet machine: the load average is printed before and after. Needs cargo and python3.
set -euo pipefail
export LC_ALL=C
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
cd "$root"
threads="${THREADS:-2}"
target="${CARGO_TARGET_DIR:-target}"
out="${OUT:-$target/gravelometer-speed/din_full_coupled}"
scenario="$here/din_full_coupled.toml"
if [ -n "${DURATION:-}" ]; then
    mkdir -p "$(dirname "$out")"
    scenario="$(dirname "$out")/din_full_coupled_${DURATION}.toml"
    sed "s/^duration_s = .*/duration_s = ${DURATION}/" "$here/din_full_coupled.toml" > "$scenario"
fi
cargo build --release -p spatter-cli --locked
bin="$target/release/spatter"
rm -rf "$out"
echo "load before: $(uptime)"
start=$(date +%s.%N)
"$bin" run "$scenario" --out "$out" --threads "$threads" --quiet
end=$(date +%s.%N)
echo "load after:  $(uptime)"
python3 - "$out" "$start" "$end" "$threads" <<'PY'
import csv, json, os, re, sys
out, start, end, threads = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
summary = json.load(open(os.path.join(out, "summary.json")))
sc = dict((k, v) for k, v in summary["scalars"])
log = open(os.path.join(out, "log.txt")).read()
grid = re.search(r"grid (\d+) × (\d+) × (\d+) cells of (\S+) m", log)
sub = re.search(r"(\d+) DEM steps per fluid step \(Δt_f = (\S+) s\)", log)
fewest = re.search(r"at fewest (\d+)", " ".join(summary["headline"])).group(1)
cells = int(grid.group(1)) * int(grid.group(2)) * int(grid.group(3))
print(f"threads {threads}; grid {grid.group(1)} x {grid.group(2)} x {grid.group(3)} = {cells} cells of "
      f"{grid.group(4)} m; DEM step {sc['dt_s']:.4g} s; fluid step {sub.group(2)} s "
      f"({sub.group(1)} DEM steps at most, {fewest} at fewest)")
# Particles at every output (energy.csv) and stones (bodies.csv rows per time).
particles = {}
with open(os.path.join(out, "energy.csv")) as f:
    for row in csv.DictReader(f):
        particles[round(float(row["t_s"]), 6)] = int(float(row["particles"]))
stones = {}
with open(os.path.join(out, "bodies.csv")) as f:
    for row in csv.DictReader(f):
        t = round(float(row["t_s"]), 6)
        stones[t] = stones.get(t, 0) + 1
pvd = open(os.path.join(out, "fields.pvd")).read()
outputs = [(float(t), os.path.getmtime(os.path.join(out, p)))
           for t, p in re.findall(r'timestep="([^"]+)"[^>]*file="([^"]+)"', pvd)]
print(f"{'t_end_s':>8} {'stones':>6} {'spheres':>8} {'wall_s':>8} {'wall_s_per_sim_s':>16}")
for (t0, w0), (t1, w1) in zip(outputs, outputs[1:]):
    k = round(t1, 6)
    print(f"{t1:8.4f} {stones.get(k, 0):6d} {particles.get(k, 0):8d} {w1 - w0:8.1f} {(w1 - w0) / (t1 - t0):16.0f}")
n = len(outputs) - 1
if n >= 2:
    # The last fifth of the run (at least its last interval): stones in the pipe, in flight, on the panel.
    m = max(1, n // 5)
    (t0, w0), (t1, w1) = outputs[-1 - m], outputs[-1]
    print(f"last {m} interval(s), t = {t0:.4f}..{t1:.4f} s: {(w1 - w0) / (t1 - t0):.0f} wall s per simulated s")
steps = sc["coupling_steps"]
parts = [("fluid", sc["time_fluid_s_per_step"]), ("void fraction", sc["time_void_fraction_s_per_step"]),
         ("forces", sc["time_forces_s_per_step"]), ("DEM", sc["time_dem_s_per_step"])]
total = sum(v for _, v in parts)
print(f"coupling steps {int(steps)}; per step [ms]: "
      + ", ".join(f"{name} {1e3 * v:.1f} ({100 * v / total:.0f} %)" for name, v in parts)
      + f"; total {1e3 * total:.1f}")
print(f"stones injected {int(sc['stones_injected'])}, spheres at the end {int(sc['particles'])}; "
      f"wall time {end - start:.0f} s for {outputs[-1][0]:.4f} s simulated: {(end - start) / outputs[-1][0]:.0f} wall s per simulated s")
PY
