"""CPU time (`time.process_time`) of `make_motion` on cached plans, and how it ends.

    PYTHONPATH=$PWD python docs/results/2026-12-06-motion-reach/time_make_motion.py NAME...

NAME: a plan of runs/motion_plans/ without .npz (the studies' cache, not committed).
"""

import sys
import time

from leas_jax.contacts.commands import load_plan_file
from leas_jax.motion.motion import MotionError, make_motion


def main() -> None:
    for name in sys.argv[1:]:
        plan = load_plan_file(f"runs/motion_plans/{name}.npz")
        began = time.process_time()
        try:
            ends = f"made {make_motion(plan).duration:.1f} s"
        except MotionError as error:
            ends = f"MotionError: {str(error)[:160]}"
        print(name, f"{time.process_time() - began:.1f} CPU s", ends, flush=True)


if __name__ == "__main__":
    main()
