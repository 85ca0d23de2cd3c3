"""The dam break of `spatter bench sph` in SPlisHSPlasH (WCSPH), timed step by step.

    python splishsplash_dam.py N STEPS WORKDIR

Column a × 2a × a (a = N spacings of 5 mm, 2a high) in a box 4a long, a wide and 2.5a high (closed; the
lid stays clear of the water, as the benchmark's open top does), y up (SPlisHSPlasH's convention),
particle radius 2.5 mm (spacing 5 mm), WCSPH (Becker & Teschner 2007: Tait law, exponent 7, stiffness
50 000), Wendland C2 kernel with SPlisHSPlasH's fixed support of four radii (2 spacings), walls of one
layer of boundary particles (Akinci et al. 2012), standard viscosity 1e-6 m²/s, fixed time step 1e-4 s.
Two warm-up steps, then STEPS timed steps (wall and CPU time between the end-of-step callbacks); threads
from OMP_NUM_THREADS. Prints one line starting with RESULT; neighbours are counted at the end.
"""
import json
import os
import sys
import time

import pysplishsplash as sph

n, steps, work = int(sys.argv[1]), int(sys.argv[2]), os.path.abspath(sys.argv[3])
dp = 0.005
a = n * dp
dt = 1e-4
os.makedirs(work, exist_ok=True)

# A unit cube centred at the origin, scaled and placed below.
box = os.path.join(work, "box.obj")
with open(box, "w") as f:
    for x in (-0.5, 0.5):
        for y in (-0.5, 0.5):
            for z in (-0.5, 0.5):
                f.write(f"v {x} {y} {z}\n")
    # Vertices numbered 1 + 4 i_x + 2 i_y + i_z; two triangles per face, outward normals.
    for t in ((1, 2, 4), (1, 4, 3), (5, 7, 8), (5, 8, 6), (1, 5, 6), (1, 6, 2),
              (3, 4, 8), (3, 8, 7), (1, 3, 7), (1, 7, 5), (2, 6, 8), (2, 8, 4)):
        f.write("f {} {} {}\n".format(*t))

scene = {
    "Configuration": {
        "particleRadius": dp / 2, "simulationMethod": 0, "gravitation": [0, -9.81, 0],
        "timeStepSize": dt, "cflMethod": 0, "kernel": 1, "gradKernel": 1,
        "boundaryHandlingMethod": 0, "enableZSort": True, "stiffness": 50000, "exponent": 7,
    },
    # Version 2.19.0 reads the coefficient from the method's block (checked: a top-level "viscosity" key
    # leaves the default 0.01 in place).
    "Materials": [{"id": "Fluid", "density0": 1000, "viscosityMethod": 1,
                   "Standard viscosity": {"viscosity": 1e-6}}],
    "RigidBodies": [{
        "geometryFile": box, "translation": [2 * a, 1.25 * a, a / 2], "rotationAxis": [1, 0, 0],
        "rotationAngle": 0, "scale": [4 * a, 2.5 * a, a], "isDynamic": False, "isWall": True}],
    "FluidBlocks": [{"denseMode": 0, "start": [0, 0, 0], "end": [a, 2 * a, a]}],
}
scene_file = os.path.join(work, f"dam_{n}.json")
with open(scene_file, "w") as f:
    json.dump(scene, f, indent=1)

base = sph.Exec.SimulatorBase()
# The simulator stops once its time exceeds stopAt: 2 + STEPS steps.
base.init(["splishsplash_dam", "--no-gui", "--no-initial-pause", "--stopAt", str((steps + 1.5) * dt),
           "--output-dir", os.path.join(work, "out"), scene_file], "SPlisHSPlasH")
state = {"k": 0}


def after_step():
    state["k"] += 1
    if state["k"] == 2:
        state["t0"], state["c0"] = time.perf_counter(), time.process_time()
    if state["k"] == steps + 2:
        state["wall"] = time.perf_counter() - state["t0"]
        state["cpu"] = time.process_time() - state["c0"]
        sim = sph.Simulation.getCurrent()
        nf = sim.getFluidModel(0).numActiveParticles()
        state["nf"] = nf
        state["ff"] = sum(sim.numberOfNeighbors(0, 0, i) for i in range(nf))
        state["fb"] = sum(sim.numberOfNeighbors(0, 1, i) for i in range(nf)) if sim.numberOfPointSets() > 1 else 0


base.setTimeStepCB(after_step)
base.run()
if "wall" not in state:
    sys.exit(f"SPlisHSPlasH ran {state['k']} steps, fewer than the {steps + 2} asked for")
print(f"steps run: {state['k']}")
nf, wall, cpu, inter = state["nf"], state["wall"], state["cpu"], state["ff"] + state["fb"]
print(f"RESULT fluid {nf} threads {os.environ.get('OMP_NUM_THREADS', '?')} steps {steps} "
      f"s_per_step {wall / steps:.4f} cpu_s_per_step {cpu / steps:.4f} "
      f"particle_steps_per_s {nf * steps / wall:.4e} interactions_per_particle {inter / nf:.2f} "
      f"interactions_per_s {inter * steps / wall:.4e}")
