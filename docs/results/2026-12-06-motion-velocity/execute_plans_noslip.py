"""execute_plan of cached plans with SimulationConfig(noslip_iterations=5); one line each."""

import sys
import time

from leas_jax.contacts.commands import load_plan_file
from leas_jax.motion.config import SimulationConfig
from leas_jax.motion.execute import execute_plan

for name in sys.argv[1:]:
    plan = load_plan_file(f"runs/motion_plans/{name}.npz")
    t = time.process_time()
    ex = execute_plan(plan, simulation_config=SimulationConfig(noslip_iterations=5))
    print(name, f"{time.process_time() - t:.0f} CPU s", ex.line(), flush=True)
