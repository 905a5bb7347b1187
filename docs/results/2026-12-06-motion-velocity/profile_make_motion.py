"""cProfile of make_motion on a cached plan, stopped after argv[2] s of wall time (SIGALRM)."""

import cProfile
import pstats
import signal
import sys
import time

from leas_jax.contacts.commands import load_plan_file
from leas_jax.motion.motion import make_motion

plan = load_plan_file(f"runs/motion_plans/{sys.argv[1]}.npz")


def stop(*_):
    raise TimeoutError


signal.signal(signal.SIGALRM, stop)
signal.alarm(int(sys.argv[2]))
prof = cProfile.Profile()
t = time.process_time()
prof.enable()
try:
    make_motion(plan)
    print("finished")
except TimeoutError:
    print("stopped after", sys.argv[2], "s wall")
except Exception as e:
    print("error", str(e)[:200])
prof.disable()
print(f"{time.process_time() - t:.0f} CPU s")
st = pstats.Stats(prof)
st.sort_stats("cumulative").print_stats(25)
st.sort_stats("tottime").print_stats(12)
