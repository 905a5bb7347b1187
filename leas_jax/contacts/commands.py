"""`leas plan`, `leas verify`, `leas show`: the contact generator on the command line (host-only).

    leas plan --guide GUIDE.npz [--terrain FILE] --out PLAN.npz [--workers N]
    leas verify PLAN.npz                      # exit 0: all checks pass, 1: a check fails
    leas show PLAN.npz --out view.html [--png footsteps.png]

File formats are docs/design.md §6: a guide file is an `.npz` with `guide` [T, 4]
(x, y, z, yaw, world frame), `timestep` (s) and optionally `terrain` (the
terrain file text) and `target` [2]; a plan file is what `ContactPlan.save`
writes. Bad input raises `UsageError` naming the argument, file and key;
`leas_jax.cli.main` prints it on one line and exits with code 2. Each command
function returns the process exit code.
"""

from __future__ import annotations

import argparse
import sys
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

# Keys `ContactPlan.save` writes (docs/design.md §6); checked before loading so a
# truncated or foreign file is named with the missing key.
from leas_jax.contacts.plan import MAX_GUIDE_POSES, PLAN_KEYS
from leas_jax.errors import LeasError, UsageError


@dataclass(frozen=True)
class GuideFile:
    """Contents of a guide file (docs/design.md §6).

    Attributes:
        path: the file.
        guide: [T, 4] (x, y, z, yaw) root poses, world frame, float64.
        timestep: s between poses.
        terrain_text: the terrain file text, or None if the file has none.
        target: [2] goal (x, y), or None.
    """

    path: str
    guide: np.ndarray
    timestep: float
    terrain_text: str | None
    target: np.ndarray | None


def _open_npz(path, argument: str):
    """np.load an .npz, turning every I/O or format problem into a one-line UsageError."""
    file = Path(path)
    if not file.is_file():
        raise UsageError(f"{argument}: {path}: no such file")
    try:
        data = np.load(file, allow_pickle=False)
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
        raise UsageError(
            f"{argument}: {path}: not a readable .npz file ({type(exc).__name__}: {exc})"
        ) from None
    if not isinstance(data, np.lib.npyio.NpzFile):
        raise UsageError(f"{argument}: {path}: a single .npy array, expected an .npz archive")
    return data


def _array(data, path, key: str, argument: str) -> np.ndarray:
    """data[key], with an array np.load refuses (object arrays need pickle) as a one-line UsageError."""
    try:
        return np.asarray(data[key])
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as exc:
        raise UsageError(f"{argument}: {path}: key '{key}' cannot be read ({exc})") from None


def _text(data, path, key: str, argument: str = "--guide") -> str:
    value = _array(data, path, key, argument)
    if value.dtype.kind not in "US" or value.shape != ():
        raise UsageError(f"{path}: key '{key}' must be a text scalar, got {value.dtype} {list(value.shape)}")
    return str(value.item() if value.dtype.kind == "U" else value.item().decode("utf-8"))


def load_guide_file(path, argument: str = "--guide") -> GuideFile:
    """Read and check a guide file (docs/design.md §6).

    Raises:
        UsageError: missing file or key, wrong shape, NaN/inf, non-positive timestep;
            the message names the argument, the file and the key.
    """
    with _open_npz(path, argument) as data:
        for key in ("guide", "timestep"):
            if key not in data.files:
                raise UsageError(
                    f"{argument}: {path}: missing key '{key}' (guide files hold guide [T, 4] "
                    f"and timestep; found {sorted(data.files)})"
                )
        guide = _array(data, path, "guide", argument)
        if guide.ndim != 2 or guide.shape[1] != 4 or guide.shape[0] < 1 or guide.dtype.kind not in "fi":
            raise UsageError(
                f"{argument}: {path}: key 'guide' must be a [T, 4] number array, "
                f"got {guide.dtype} {list(guide.shape)}"
            )
        if guide.shape[0] > MAX_GUIDE_POSES:
            raise UsageError(
                f"{argument}: {path}: key 'guide' holds {guide.shape[0]} poses, more than the "
                f"{MAX_GUIDE_POSES} the contact generator accepts (split the guide)"
            )
        if not np.isfinite(guide).all():
            raise UsageError(f"{argument}: {path}: key 'guide' contains NaN or inf")
        timestep = _array(data, path, "timestep", argument)
        if (
            timestep.size != 1
            or timestep.dtype.kind not in "fi"
            or not np.isfinite(timestep).all()
            or float(timestep.reshape(())) <= 0
        ):
            raise UsageError(
                f"{argument}: {path}: key 'timestep' must be a positive number of seconds, "
                f"got {timestep.tolist()!r}"
            )
        terrain_text = _text(data, path, "terrain", argument) if "terrain" in data.files else None
        target = None
        if "target" in data.files:
            target = _array(data, path, "target", argument)
            if target.shape != (2,) or target.dtype.kind not in "fi" or not np.isfinite(target).all():
                raise UsageError(
                    f"{argument}: {path}: key 'target' must be 2 finite numbers (x, y), "
                    f"got {target.tolist()!r}"
                )
    return GuideFile(
        path=str(path),
        guide=guide.astype(np.float64),
        timestep=float(timestep.reshape(())),
        terrain_text=terrain_text,
        target=target,
    )


def load_plan_file(path, argument: str = "PLAN"):
    """Load a plan file with `ContactPlan.load`, after checking it is an .npz with every docs/design.md §6 key.

    Raises:
        UsageError: naming the argument, the file and the first missing key.
    """
    with _open_npz(path, argument) as data:
        missing = [key for key in PLAN_KEYS if key not in data.files]
        if not missing:
            poses = _guide_length(data, path, argument)
            if poses > MAX_GUIDE_POSES:
                raise UsageError(
                    f"{argument}: {path}: its guide holds {poses} poses, more than {MAX_GUIDE_POSES} "
                    "(plans of longer guides are not shown or checked)"
                )
    if missing:
        raise UsageError(
            f"{argument}: {path}: missing key '{missing[0]}' (a plan file written by "
            f"ContactPlan.save has {', '.join(PLAN_KEYS)})"
        )
    from leas_jax.contacts import ContactPlan

    try:
        return ContactPlan.load(path)
    except LeasError:
        raise
    except Exception as exc:  # malformed arrays: report on one line, naming the file
        raise UsageError(f"{argument}: {path}: cannot load the plan ({type(exc).__name__}: {exc})") from None


def _guide_length(data, path, argument: str) -> int:
    """Poses of the 'guide' member of an open .npz, from its header alone (nothing loaded)."""
    try:
        with data.zip.open("guide.npy") as member:
            version = np.lib.format.read_magic(member)
            read_header = (
                np.lib.format.read_array_header_1_0
                if version == (1, 0)
                else np.lib.format.read_array_header_2_0
            )
            shape, _, _ = read_header(member)
    except (KeyError, ValueError, OSError, zipfile.BadZipFile) as exc:
        raise UsageError(f"{argument}: {path}: key 'guide' cannot be read ({exc})") from None
    return int(shape[0]) if shape else 1


def _plan_outputs(guide_paths: list[str], out: str) -> list[Path]:
    """One output file per guide: `out` itself for one guide, `out/<stem>.plan.npz` for several."""
    out_path = Path(out)
    if len(guide_paths) == 1:
        if out_path.is_dir():
            return [out_path / (Path(guide_paths[0]).stem + ".plan.npz")]
        if not out_path.parent.is_dir():
            raise UsageError(f"--out: {out}: directory {out_path.parent} does not exist")
        if out_path.suffix != ".npz":
            raise UsageError(f"--out: {out}: plan files end in .npz")
        return [out_path]
    if out_path.exists() and not out_path.is_dir():
        raise UsageError(f"--out: {out}: with {len(guide_paths)} guide files --out must be a directory")
    if not out_path.parent.is_dir():
        raise UsageError(f"--out: {out}: directory {out_path.parent} does not exist")
    stems = [Path(p).stem for p in guide_paths]
    if len(set(stems)) != len(stems):
        raise UsageError(
            f"--guide: several guide files named {sorted(s for s in stems if stems.count(s) > 1)[0]}"
            ".npz would write the same plan file"
        )
    out_path.mkdir(exist_ok=True)
    return [out_path / (stem + ".plan.npz") for stem in stems]


def cmd_plan(args) -> int:
    """`leas plan`: run the contact generator on guide files, save plans, print a summary line each.

    Returns:
        0 when every guide was planned (whatever its coverage), 1 when the
        generator failed on a guide (exception or crashed worker).
    """
    from leas_jax.contacts.validation.pool import ValidationPool
    from leas_jax.contacts.viewer import count_footsteps
    from leas_jax.terrain import load_terrain, loads_terrain

    guides = [load_guide_file(path) for path in args.guide]
    if args.terrain is not None:
        terrain = load_terrain(args.terrain)
    else:
        texts = {g.terrain_text for g in guides}
        if None in texts:
            bare = next(g.path for g in guides if g.terrain_text is None)
            raise UsageError(f"--terrain: required, the guide file {bare} holds no 'terrain' key")
        if len(texts) > 1:
            raise UsageError("--terrain: the guide files hold different terrains; plan them separately")
        terrain = loads_terrain(texts.pop(), source=f"{guides[0].path}:terrain")
    outputs = _plan_outputs(args.guide, args.out)
    # One submit per guide file, so each plan is the one `leas plan` gives for
    # that file alone (the path seed depends on the index within a batch).
    start = time.perf_counter()
    with ValidationPool(terrain, workers=args.workers) as pool:
        futures = [pool.submit([g.guide], g.timestep) for g in guides]
        status = 0
        for guide, future, out in zip(guides, futures, outputs):
            result = future.result()[0]
            if result.error is not None:
                print(f"{guide.path}: contact generator failed: {result.error}", file=sys.stderr)
                status = 1
                continue
            plan = result.plan
            plan.save(out)
            last = guide.guide.shape[0] - 1
            print(
                f"{guide.path}: coverage {result.coverage:.3f}, last_valid_index {result.last_valid_index}/{last}, "
                f"footsteps {count_footsteps(plan)}, postures {np.asarray(plan.q).shape[0]}, "
                f"time {result.seconds:.2f} s -> {out}"
            )
    if len(guides) > 1:
        print(f"{len(guides)} guides in {time.perf_counter() - start:.2f} s with {pool.workers} workers")
    return status


def cmd_verify(args) -> int:
    """`leas verify`: re-run the docs/design.md §6 checks from the plan file alone.

    Prints one line per failing (posture, check) and a summary.

    Returns:
        0 when every posture passes every check, 1 otherwise.
    """
    plan = load_plan_file(args.plan)
    from leas_jax.contacts import verify

    report = verify(plan)
    count = np.asarray(plan.q).shape[0]
    for posture, check, message in report.failures:
        print(f"posture {posture}: check {check}: {message}")
    if report.ok:
        print(
            f"{args.plan}: OK, {count} postures pass all checks "
            f"(coverage {float(plan.coverage):.3f}, last_valid_index {int(plan.last_valid_index)})"
        )
        return 0
    postures = len({failure[0] for failure in report.failures})
    print(f"{args.plan}: FAILED, {len(report.failures)} failed checks in {postures} of {count} postures")
    return 1


def cmd_show(args) -> int:
    """`leas show`: write the 3D HTML view (and optionally the top-down PNG) of a plan file."""
    from leas_jax.contacts.viewer import write_footsteps_png, write_html

    out = Path(args.out) if args.out is not None else Path(args.plan).with_suffix(".html")
    for argument, path in (("--out", out), ("--png", args.png)):
        if path is not None and not Path(path).parent.is_dir():
            raise UsageError(f"{argument}: {path}: directory {Path(path).parent} does not exist")
    if args.png is not None and Path(args.png).suffix.lower() != ".png":
        raise UsageError(f"--png: {args.png}: the footsteps image is a PNG file (name it *.png)")
    if out.suffix.lower() not in (".html", ".htm"):
        raise UsageError(f"--out: {out}: the view is an HTML file (name it *.html)")
    if args.max_postures < 1:
        raise UsageError(f"--max-postures: expected an integer >= 1, got {args.max_postures}")
    plan = load_plan_file(args.plan)
    write_html(plan, out, max_postures=args.max_postures, robot=not args.no_robot)
    print(f"wrote {out} ({out.stat().st_size / 1e6:.2f} MB)")
    if args.png is not None:
        write_footsteps_png(plan, args.png)
        print(f"wrote {args.png}")
    return 0


def _workers(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected an integer >= 0, got {text!r}")
    return value


def register(subparsers) -> None:
    """Add `plan`, `verify` and `show` to the `leas` parser; each sets `func` (args -> exit code)."""
    plan = subparsers.add_parser(
        "plan",
        help="contact plan along guide paths",
        description="Run the Talos contact generator along guide paths (docs/design.md §6 guide files) "
        "and save the contact plans.",
    )
    plan.add_argument(
        "--guide",
        nargs="+",
        required=True,
        metavar="GUIDE.npz",
        help="guide file(s): guide [T, 4], timestep, optional terrain text and target",
    )
    plan.add_argument(
        "--terrain", metavar="FILE", help="terrain file (default: the text inside the guide file)"
    )
    plan.add_argument(
        "--out",
        required=True,
        metavar="PLAN.npz",
        help="plan file; a directory when several guides are given",
    )
    plan.add_argument(
        "--workers", type=_workers, default=0, help="worker processes (default 0: plan in this process)"
    )
    plan.set_defaults(func=cmd_plan)

    verify = subparsers.add_parser(
        "verify",
        help="re-check a contact plan file",
        description="Re-run every contact-plan check (sole on a support surface, forward kinematics, "
        "joint limits, collisions, static equilibrium, one foot moves at a time) from the "
        "file alone. Exit code 0: all pass; 1: a check fails.",
    )
    verify.add_argument("plan", metavar="PLAN.npz")
    verify.set_defaults(func=cmd_verify)

    show = subparsers.add_parser(
        "show",
        help="3D HTML view of a contact plan",
        description="Write a self-contained 3D HTML view of a contact plan (terrain, guide, footprints, "
        "Talos at key postures) and optionally a top-down PNG of the footsteps.",
    )
    show.add_argument("plan", metavar="PLAN.npz")
    show.add_argument("--out", metavar="VIEW.html", help="HTML file (default: PLAN.html)")
    show.add_argument("--png", metavar="FILE", help="also write a top-down footsteps PNG")
    show.add_argument("--max-postures", type=int, default=60, help="robot postures stored in the page")
    show.add_argument("--no-robot", action="store_true", help="omit the robot meshes (smaller file)")
    show.set_defaults(func=cmd_show)
