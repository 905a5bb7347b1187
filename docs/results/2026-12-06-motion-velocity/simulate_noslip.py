"""simulate a saved motion with MuJoCo's noslip_iterations = argv[2]."""

import sys
import time

import leas_jax.motion.robot as R
from leas_jax.motion.motion import Motion
from leas_jax.motion.simulate import simulate

orig = R.terrain_scene
n = int(sys.argv[2])


def patched(terrain, timestep):
    mj = orig(terrain, timestep)
    mj.model.opt.noslip_iterations = n
    return mj


R.terrain_scene = patched
m = Motion.load(sys.argv[1])
t = time.process_time()
r = simulate(m)
s = r.summary()
print(
    sys.argv[1],
    "noslip",
    n,
    f"{time.process_time() - t:.0f} CPU s",
    r.message,
    "fall",
    r.fall_time,
    "max slip",
    s["max_slip_m"],
    "max landing",
    s["max_landing_position_m"],
    flush=True,
)
