"""Contact-plan validation on local processes vs a local Ray instance (needs leas-jax[cluster]).

Validates the 5 guides of tests/test_contacts_pool_generator.py 8 times over (40
paths) with `ValidationPool.map`, for 1 and 2 local worker processes and 1 and 2
Ray actors on a local Ray instance (`address="local"`). Each pool is opened and
warmed with one full batch (workers load the Talos model and the sample
database), then timed over `--runs` batches. The results must be identical
across backends. `--backends processes` leaves Ray out (without the extra installed).
Writes <out>/ray_validation.json.

    python benchmarks/ray_validation.py [--runs 3] [--backends processes,ray]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))

from common import add_out_argument, load_average, save  # noqa: E402

BACKENDS = {"processes": "local processes", "ray": "local Ray actors"}
SETTINGS = (
    ("local processes", dict(workers=1)),
    ("local processes", dict(workers=2)),
    ("local Ray actors", dict(address="local", workers=1)),
    ("local Ray actors", dict(address="local", workers=2)),
)


def measure(terrain, guides, timestep: float, runs: int, options: dict) -> tuple[dict, list]:
    """Seconds to open and warm a pool, and per timed batch; the last batch's results."""
    from leas_jax.contacts.validation.pool import ValidationPool

    began = time.perf_counter()
    with ValidationPool(terrain, return_plans=False, **options) as pool:
        pool.map(guides, timestep)
        warm_s = time.perf_counter() - began
        batch_s = []
        for _ in range(runs):
            began = time.perf_counter()
            results = pool.map(guides, timestep)
            batch_s.append(round(time.perf_counter() - began, 3))
    return {"open_and_warm_s": round(warm_s, 2), "batch_s": batch_s}, results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--backends", default="processes,ray", help="comma-separated: processes, ray")
    add_out_argument(parser)
    args = parser.parse_args()
    chosen = [b.strip() for b in args.backends.split(",") if b.strip()]
    unknown = sorted(set(chosen) - set(BACKENDS))
    if unknown or not chosen:
        parser.error(f"--backends: unknown {unknown or chosen}; choose from {sorted(BACKENDS)}")
    if "processes" not in chosen:
        parser.error("--backends: processes are the reference the other backends are checked against")
    load_before = load_average()
    from test_contacts_pool_generator import DT, GUIDES, TERRAIN

    guides = GUIDES * 8
    rows, reference = [], None
    for backend, options in [s for s in SETTINGS if s[0] in {BACKENDS[b] for b in chosen}]:
        figures, results = measure(TERRAIN, guides, DT, args.runs, options)
        if reference is None:
            reference = results
        if results != reference:
            raise SystemExit(f"{backend} {options}: results differ from 1 local process")
        rows.append({"backend": backend, "workers": options["workers"], "paths": len(guides), **figures})
        print(
            f"{backend:17s} x{options['workers']}: open+warm {figures['open_and_warm_s']:.1f} s, "
            f"{len(guides)} paths in {', '.join(f'{s:.2f}' for s in figures['batch_s'])} s",
            flush=True,
        )
    save("ray_validation", {"runs": args.runs, "backends": chosen, "rows": rows}, load_before, args.out)


if __name__ == "__main__":
    main()
