"""Does checking the transitions cost navigate its goals on rough ground, and how much time?

The five HPP rough scenes of docs/results/2026-12-06-rough-scenes, their own seeded starts
(`leas evaluate`'s draw, the scenes' [scenario] tables), navigated with the shipped policy,
once with the generator's defaults and once as `leas navigate --motion` plans
(`motion_generator_config`). Success is navigate's (the goal reached with a verified plan).

    python docs/results/2026-12-07-motion-transitions/navigate_success.py OUT.json [--starts 10]

Writes OUT.json: per scene and setting, the successes per start, the rate with its 95 % Wilson
interval and the wall seconds of the scene's navigate queries (one process, in turn).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
SCENES = ("darpa", "rubbles_stairs_2", "rubbles_stairs_3", "rubbles_stairs_bridge_1", "slalom_debris")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out")
    parser.add_argument("--starts", type=int, default=10)
    args = parser.parse_args()

    from leas_jax.contacts.planner.config import motion_generator_config
    from leas_jax.eval.evaluate import policy_for, run_scenario
    from leas_jax.stats import wilson
    from leas_jax.terrain import load_terrain

    policy = policy_for(("navigate",), str(ROOT / "checkpoints/leas_talos"))
    report = {"starts": args.starts, "scenes": {}}
    totals = {"unchecked": [0, 0], "checked": [0, 0]}
    for scene in SCENES:
        terrain = load_terrain(ROOT / f"terrains/hpp/rough/{scene}.toml")
        report["scenes"][scene] = {}
        for setting, generator in (("unchecked", None), ("checked", motion_generator_config())):
            began = time.perf_counter()
            result = run_scenario(
                scene,
                terrain,
                ("navigate",),
                policy,
                args.starts,
                0,
                progress=False,
                generator_config=generator,
            )
            seconds = time.perf_counter() - began
            successes = [bool(t.outcome.success) for t in result.trajectories]
            totals[setting][0] += sum(successes)
            totals[setting][1] += len(successes)
            report["scenes"][scene][setting] = {"successes": successes, "seconds": round(seconds, 1)}
            print(
                f"{scene:26s} {setting:9s} {sum(successes)}/{len(successes)} in {seconds:.0f} s", flush=True
            )
    for setting, (ok, n) in totals.items():
        low, high = wilson(ok, n)
        report[setting] = {"ok": ok, "n": n, "wilson95": [round(low, 3), round(high, 3)]}
        print(f"{setting}: {ok}/{n} [{100 * low:.1f}, {100 * high:.1f}] %")
    Path(args.out).write_text(json.dumps(report, indent=1) + "\n")


if __name__ == "__main__":
    main()
