"""Mesh-terrain speed: raster + support surfaces of a 20 x 20 m mesh scene, and
the contact generator on a mesh terrain against the same terrain as boxes.

  scene      terrains/hpp/random_10x10.toml: the HPP group's random_scene_10x10_V3.stl
             (hpp-environments, 7 326 triangles) over 20 x 20 m at 0.02 m (1001 x 1001
             raster points): load the file, ray cast the raster, extract the support
             surfaces, each from a fresh load (no cache). Target <= 10 s.
             Reference in the same run: the same for terrains/training_arena.toml (545
             boxes, 20 x 20 m at 0.02 m).
  generator  the evaluation guides of tests/data (LeaS paths on eval_stairs,
             eval_bridge, eval_circuit): each planned on its terrain as boxes and on
             the terrain's STL export loaded as a `[[mesh]]` terrain; CPU ms per
             footstep (single-support posture) of each. Target: mesh <= 2 x boxes.

  elevation  (--elevation-samples N, off by default) an N x N elevation map of
             0.1 sin(3x) cos(2y) at 0.02 m: load, raster, support surfaces and the
             generator's surface arrays (`surface_arrays`), CPU s each. A curved map
             gives one support polygon per triangle: this shows where that stops scaling.

Times are the process's CPU time (`time.process_time`, wall time saved too); BLAS pools
are limited to one thread; the load average is saved before and after. Writes
<--out>/terrain_raster_speed.json (default benchmarks/results).

    python benchmarks/terrain_raster_speed.py [--runs 3] [--guide-runs 2] [--elevation-samples 150]
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import functools  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import add_out_argument, load_average, save  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
SCENE = REPO / "terrains" / "hpp" / "random_10x10.toml"
BOXES = REPO / "terrains" / "training_arena.toml"
GUIDES = sorted((REPO / "tests" / "data").glob("*_leas_guide.npz"))
SCENE_TARGET_S = 10.0
GENERATOR_TARGET_RATIO = 2.0


def _timed(fn):
    """(cpu s, wall s, result) of fn()."""
    cpu, wall = time.process_time(), time.perf_counter()
    out = fn()
    return time.process_time() - cpu, time.perf_counter() - wall, out


def scene_case(path: Path, runs: int) -> dict:
    """Best and median CPU seconds of load + raster + support surfaces of a terrain file."""
    from leas_jax.terrain import load_terrain

    def once():
        terrain = load_terrain(path)
        heights = terrain.raster()
        surfaces = terrain.support_surfaces()
        return terrain, heights, surfaces

    times = [_timed(once) for _ in range(runs)]
    terrain, heights, surfaces = times[-1][2]
    cpu = sorted(t[0] for t in times)
    return {
        "file": str(path.relative_to(REPO)),
        "raster_shape": list(heights.shape),
        "triangles": int(sum(len(m.faces) for m in terrain.meshes)),
        "boxes": len(terrain.boxes),
        "support_surfaces": len(surfaces),
        "best_cpu_s": cpu[0],
        "median_cpu_s": float(np.median(cpu)),
        "best_wall_s": min(t[1] for t in times),
    }


def elevation_case(samples: int, folder: Path) -> dict:
    """CPU seconds of load, raster, support surfaces and surface arrays of an N x N elevation map."""
    from leas_jax.contacts.planner.surfaces import surface_arrays
    from leas_jax.terrain import load_terrain

    res = 0.02
    x = np.arange(samples) * res
    np.save(folder / "elevation.npy", 0.1 * np.sin(3 * x[:, None]) * np.cos(2 * x[None, :]))
    side = (samples - 1) * res
    (folder / "elevation.toml").write_text(
        f'name = "elevation"\nbounds = [[0.0, 0.0], [{side}, {side}]]\nvoid_height = -2.0\n'
        f'resolution = {res}\n[elevation]\nfile = "elevation.npy"\norigin = [0.0, 0.0, 0.0]\n'
        f"resolution = {res}\n"
    )
    load_s, _, terrain = _timed(lambda: load_terrain(folder / "elevation.toml"))
    raster_s, _, _ = _timed(terrain.raster)
    surfaces_s, _, surfaces = _timed(terrain.support_surfaces)
    arrays_s, _, _ = _timed(lambda: surface_arrays(terrain, 0.5))
    return {
        "samples": samples,
        "triangles": int(len(terrain.meshes[0].faces)),
        "support_surfaces": len(surfaces),
        "load_cpu_s": load_s,
        "raster_cpu_s": raster_s,
        "support_surfaces_cpu_s": surfaces_s,
        "surface_arrays_cpu_s": arrays_s,
    }


def mesh_twin(terrain, folder: Path):
    """The terrain's boxes exported to STL and loaded back as a one-mesh terrain."""
    from leas_jax.terrain import loads_terrain
    from leas_jax.terrain.export import export_terrain

    stl = folder / f"{terrain.name}.stl"
    export_terrain(terrain, stl)
    head = terrain.text.split("[[box]]", 1)[0]
    lines = [line for line in head.splitlines() if not line.startswith("#")]
    text = "\n".join(lines) + f'\n[[mesh]]\nfile = "{stl.name}"\n'
    return loads_terrain(text, source=str(folder / "twin.toml"), path=str(folder / "twin.toml"))


def guide_terrain(guide_file: Path) -> Path:
    """The terrain of a tests/data guide: eval_<scenario>_<what>_leas_guide.npz -> terrains/eval_<scenario>.toml."""
    return REPO / "terrains" / ("_".join(guide_file.stem.split("_")[:2]) + ".toml")


def footsteps(plan) -> int:
    """Single-support postures of a plan (one per footstep)."""
    return int(np.isnan(plan.feet[:, :, 0]).any(axis=1).sum())


def generator_case(guide_file: Path, runs: int, folder: Path) -> dict:
    """CPU ms per footstep of the generator on a guide, boxes against their mesh twin."""
    from leas_jax.contacts import ContactGenerator, GeneratorConfig
    from leas_jax.terrain import load_terrain

    with np.load(guide_file) as data:
        guide, dt = data["guide"], float(data["timestep"])
    boxes = load_terrain(guide_terrain(guide_file))
    out = {"guide": guide_file.name, "poses": len(guide)}
    for label, terrain in (("boxes", boxes), ("mesh", mesh_twin(boxes, folder))):
        generator = ContactGenerator(terrain, GeneratorConfig())
        plan = generator.plan(guide, dt)  # warm-up: caches (surfaces, collision objects)
        cpu = sorted(_timed(functools.partial(generator.plan, guide, dt))[0] for _ in range(runs))
        steps = max(footsteps(plan), 1)
        out[label] = {
            "coverage": float(plan.coverage),
            "footsteps": footsteps(plan),
            "best_ms_per_footstep": 1000 * cpu[0] / steps,
            "median_ms_per_footstep": 1000 * float(np.median(cpu)) / steps,
        }
    out["ratio_mesh_over_boxes"] = out["mesh"]["best_ms_per_footstep"] / out["boxes"]["best_ms_per_footstep"]
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="timed repeats of the scene case")
    parser.add_argument("--guide-runs", type=int, default=2, help="timed repeats of each guide")
    add_out_argument(parser)
    parser.add_argument(
        "--elevation-samples", type=int, default=0, help="N of an N x N elevation case (0: skip)"
    )
    args = parser.parse_args(argv)
    load_before = load_average()
    scene = scene_case(SCENE, args.runs)
    reference = scene_case(BOXES, args.runs)
    print(f"scene {scene['best_cpu_s']:.2f} s (boxes reference {reference['best_cpu_s']:.2f} s)")
    with tempfile.TemporaryDirectory() as folder:
        guides = [generator_case(g, args.guide_runs, Path(folder)) for g in GUIDES]
        elevation = elevation_case(args.elevation_samples, Path(folder)) if args.elevation_samples else None
    if elevation:
        print(f"elevation {elevation}")
    for g in guides:
        print(
            f"{g['guide']}: {g['boxes']['best_ms_per_footstep']:.2f} ms/step boxes, "
            f"{g['mesh']['best_ms_per_footstep']:.2f} mesh (x{g['ratio_mesh_over_boxes']:.2f}); "
            f"coverage {g['boxes']['coverage']:.3f} / {g['mesh']['coverage']:.3f}"
        )
    worst = max(g["ratio_mesh_over_boxes"] for g in guides)
    save(
        "terrain_raster_speed",
        {
            "scene": scene,
            "boxes_reference": reference,
            "scene_over_reference": scene["best_cpu_s"] / reference["best_cpu_s"],
            "scene_target_s": SCENE_TARGET_S,
            "scene_within_target": scene["best_cpu_s"] <= SCENE_TARGET_S,
            "generator": guides,
            "generator_worst_ratio": worst,
            "generator_target_ratio": GENERATOR_TARGET_RATIO,
            "generator_within_target": worst <= GENERATOR_TARGET_RATIO,
            "elevation": elevation,
        },
        load_before,
        out=args.out,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
