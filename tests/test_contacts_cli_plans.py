"""`leas plan` -> `leas verify` -> `leas show` on real plans.

`main` below is `leas_jax.cli.main` restricted to this package's commands (the
full CLI imports every sub-package, JAX included); one test goes through the
real `leas_jax.cli.main`.
"""

from __future__ import annotations

import argparse
import re
import sys

import numpy as np
import pytest

from leas_jax.contacts import ContactPlan, commands
from leas_jax.contacts.robot.model import NOMINAL_ROOT_HEIGHT as H
from leas_jax.errors import LeasError

DT = 0.1  # s
TERRAIN = """
name = "cli_plans"
bounds = [[-1.0, -2.0], [4.0, 2.0]]
void_height = -2.0
resolution = 0.02

[[box]]
center = [0.5, 0.0, -0.1]
size = [3.0, 4.0, 0.2]
"""


def _guide(x0: float, x1: float, count: int) -> np.ndarray:
    x = np.linspace(x0, x1, count)
    return np.stack([x, np.zeros(count), np.full(count, H), np.zeros(count)], axis=1)


def main(argv: list[str]) -> int:
    """The documented CLI contract: func's return value is the exit code, LeasError -> 2."""
    parser = argparse.ArgumentParser(prog="leas")
    commands.register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except LeasError as exc:
        print(f"leas {args.command}: error: {exc}", file=sys.stderr)
        return 2


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("cli_plans")
    (folder / "flat.toml").write_text(TERRAIN)
    # 1.2 m at 0.18 m/s on ground; the second guide walks off the edge at x = 2.
    np.savez(
        folder / "walk.npz", guide=_guide(-0.5, 0.7, 68), timestep=DT, terrain=TERRAIN, target=[0.7, 0.0]
    )
    np.savez(folder / "edge.npz", guide=_guide(0.5, 3.0, 140), timestep=DT)
    return folder


def test_plan_verify_show(files, capsys, tmp_path):
    plan_path = tmp_path / "walk.plan.npz"
    assert main(["plan", "--guide", str(files / "walk.npz"), "--out", str(plan_path)]) == 0
    out = capsys.readouterr().out
    match = re.search(
        r"coverage 1\.000, last_valid_index 67/67, footsteps (\d+), postures (\d+), time [\d.]+ s", out
    )
    assert match, out
    plan = ContactPlan.load(plan_path)
    assert plan.coverage == 1.0 and len(plan) == int(match.group(2)) and int(match.group(1)) >= 4

    assert main(["verify", str(plan_path)]) == 0
    assert "OK" in capsys.readouterr().out

    # Lift a foot that stands on the ground by 3 cm in the file: check 1 (on a
    # support surface) and check 2 (FK puts the sole at `feet`) must fail.
    with np.load(plan_path) as data:
        arrays = {key: data[key] for key in data.files}
    standing = np.nonzero(np.isfinite(arrays["feet"][:, 0, 2]))[0][3]
    arrays["feet"][standing, 0, 2] += 0.03
    bad = tmp_path / "bad.plan.npz"
    np.savez(bad, **arrays)
    assert main(["verify", str(bad)]) == 1
    out = capsys.readouterr().out
    assert f"posture {standing}: check 2" in out and "FAILED" in out

    html, png = tmp_path / "view.html", tmp_path / "steps.png"
    assert main(["show", str(plan_path), "--out", str(html), "--png", str(png), "--max-postures", "10"]) == 0
    assert html.stat().st_size > 100_000 and png.read_bytes()[:4] == b"\x89PNG"
    assert "wrote" in capsys.readouterr().out


def test_plan_several_guides_with_terrain_file_and_a_worker(files, capsys, tmp_path):
    out_dir = tmp_path / "plans"
    code = main(
        [
            "plan",
            "--guide",
            str(files / "walk.npz"),
            str(files / "edge.npz"),
            "--terrain",
            str(files / "flat.toml"),
            "--out",
            str(out_dir),
            "--workers",
            "1",
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "2 guides in" in out and "with 1 workers" in out
    walk, edge = ContactPlan.load(out_dir / "walk.plan.npz"), ContactPlan.load(out_dir / "edge.plan.npz")
    assert walk.coverage == 1.0
    # Stops at the edge: every sole on the ground (x <= 2 - half a sole), root not far past.
    assert 0.0 < edge.coverage < 1.0 and edge.guide[edge.last_valid_index, 0] < 2.3
    assert np.nanmax(edge.feet[:, :, 0]) <= 2.0 - 0.1
    # The same plan as in-process with the terrain text from the guide file.
    single = tmp_path / "walk.npz"
    assert main(["plan", "--guide", str(files / "walk.npz"), "--out", str(single)]) == 0
    np.testing.assert_array_equal(ContactPlan.load(single).q, walk.q)


def test_exit_codes_through_the_real_cli(files, capsys, tmp_path):
    from leas_jax.cli import main as leas_main

    broken = tmp_path / "broken.npz"
    np.savez(broken, guide=_guide(0.0, 1.0, 10))
    assert leas_main(["plan", "--guide", str(broken), "--out", str(tmp_path / "p.npz")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "missing key 'timestep'" in err and str(broken) in err
