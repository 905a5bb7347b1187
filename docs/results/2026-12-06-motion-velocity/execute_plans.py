"""execute_plan (default settings) of cached plans runs/motion_plans/NAME.npz; one line each."""

import json
import sys
import time

from leas_jax.contacts.commands import load_plan_file
from leas_jax.motion.execute import execute_plan

for name in sys.argv[1:]:
    plan = load_plan_file(f"runs/motion_plans/{name}.npz")
    t = time.process_time()
    ex = execute_plan(plan)
    s = ex.summary()
    print(name, f"{time.process_time() - t:.0f} CPU s", ex.line(), flush=True)
    print(
        "  ",
        json.dumps(
            {
                k: s.get(k)
                for k in (
                    "made",
                    "success",
                    "fallen",
                    "duration_s",
                    "make_cpu_seconds",
                    "simulate_cpu_seconds",
                    "max_landing_position_m",
                    "max_slip_m",
                    "max_torque_ratio",
                )
            }
        ),
        flush=True,
    )
