"""Start-up of a contact-generator worker: what a fresh process pays before its first plan.

Every worker of `ValidationPool` (`leas evaluate --workers N`, planner-in-the-loop
training, `leas navigate`) and every command that plans in-process starts by loading the
Talos model and building the generator for its terrain. This script times, in `--runs`
fresh subprocesses each:

  import      `import leas_jax.contacts`;
  talos       `load_talos()` (URDF, meshes, collision geometry);
  generator   `ContactGenerator(terrain)` on the training arena, the model already loaded
              (terrain collision objects, leg databases from the disk cache).

With `--reference DIR` (another checkout of the project, e.g. a `git worktree` of an older
commit) the same subprocesses alternate between this checkout and DIR, so that both are
measured on the same machine in the same minutes, and the ratio of the medians is reported.

    python benchmarks/contact_worker_startup.py [--runs 7] [--reference DIR]
        [--out docs/results/<date-topic>]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import common  # noqa: E402

ARENA = "terrains/training_arena.toml"
STAGES = ("import", "talos", "generator")

_CHILD = """
import json, sys, time
start = time.perf_counter()
import leas_jax.contacts
from leas_jax.contacts import ContactGenerator
from leas_jax.contacts.robot.model import load_talos
from leas_jax.terrain import load_terrain
imported = time.perf_counter()
load_talos()
loaded = time.perf_counter()
ContactGenerator(load_terrain(sys.argv[1]))
built = time.perf_counter()
print(json.dumps({"import": imported - start, "talos": loaded - imported, "generator": built - loaded,
                  "source": leas_jax.contacts.__file__}))
"""


def one_start(checkout: Path) -> dict:
    """Stage times (s) of one fresh process importing leas_jax from `checkout`."""
    env = {**os.environ, "PYTHONPATH": str(checkout)}
    done = subprocess.run(
        [sys.executable, "-c", _CHILD, str(checkout / ARENA)],
        env=env,
        cwd=checkout,
        capture_output=True,
        text=True,
        check=True,
    )
    times = json.loads(done.stdout.strip().splitlines()[-1])
    source = Path(times.pop("source")).resolve()
    if checkout.resolve() not in source.parents:
        raise RuntimeError(f"{checkout}: the subprocess imported leas_jax from {source}")
    return times


def summary(starts: list[dict]) -> dict:
    """Median seconds per stage and of their total, over the starts."""
    medians = {stage: round(statistics.median(s[stage] for s in starts), 3) for stage in STAGES}
    medians["total"] = round(statistics.median(sum(s[stage] for stage in STAGES) for s in starts), 3)
    return medians


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7, help="fresh processes per checkout (default 7)")
    parser.add_argument(
        "--reference", type=Path, default=None, help="another checkout, measured alternately with this one"
    )
    common.add_out_argument(parser)
    args = parser.parse_args(argv)
    if args.runs < 1:
        parser.error("--runs must be >= 1")
    if args.reference is not None and not (args.reference / "leas_jax").is_dir():
        parser.error(f"--reference: {args.reference} is not a checkout of leas-jax (no leas_jax/)")
    checkouts = {"this": common.REPO}
    if args.reference is not None:
        checkouts["reference"] = args.reference
    load = common.load_average()
    starts = {name: [] for name in checkouts}
    begun = time.perf_counter()
    one_start(common.REPO)  # warm the disk caches (leg databases, file pages) for every run alike
    for _ in range(args.runs):
        for name, checkout in checkouts.items():
            starts[name].append(one_start(checkout))
    payload = {
        "runs": args.runs,
        "terrain": ARENA,
        "seconds": {
            name: [{k: round(v, 3) for k, v in s.items()} for s in runs] for name, runs in starts.items()
        },
        "median_s": {name: summary(runs) for name, runs in starts.items()},
        "wall_s": round(time.perf_counter() - begun, 1),
    }
    if args.reference is not None:
        payload["reference"] = {
            "path": str(args.reference),
            "git": common.git_state(args.reference),
        }
        this, ref = payload["median_s"]["this"], payload["median_s"]["reference"]
        payload["ratio_this_to_reference"] = {k: round(this[k] / ref[k], 3) for k in (*STAGES, "total")}
    print(json.dumps(payload["median_s"], indent=2))
    if "ratio_this_to_reference" in payload:
        print("this / reference:", json.dumps(payload["ratio_this_to_reference"]))
    common.save("contact_worker_startup", payload, load, args.out)


if __name__ == "__main__":
    main()
