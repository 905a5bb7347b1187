"""`leas plan` / `leas verify` / `leas show`: argument and file errors, exit codes.

`run_leas` follows the documented CLI contract (docs/architecture.md): parse
with the parsers `register` adds, run `func`, turn a LeasError into one line
on stderr and exit code 2, else exit with `func`'s return value.
"""

from __future__ import annotations

import argparse

import numpy as np
import pytest

from leas_jax.contacts import commands
from leas_jax.errors import LeasError

TERRAIN = """
name = "cli_flat"
bounds = [[-1.0, -1.0], [3.0, 1.0]]
void_height = -2.0
resolution = 0.02

[[box]]
center = [1.0, 0.0, -0.1]
size = [4.0, 2.0, 0.2]
"""


def run_leas(argv: list[str], capsys) -> tuple[int, str, str]:
    parser = argparse.ArgumentParser(prog="leas")
    commands.register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    try:
        code = args.func(args)
    except LeasError as exc:
        print(f"leas {args.command}: error: {exc}", file=__import__("sys").stderr)
        code = 2
    out = capsys.readouterr()
    return code, out.out, out.err


def _guide(length: int = 20) -> np.ndarray:
    guide = np.zeros((length, 4))
    guide[:, 0] = np.linspace(0.0, 0.5, length)
    guide[:, 2] = 1.02
    return guide


def _one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_plan_missing_guide_file(tmp_path, capsys):
    code, _, err = run_leas(
        ["plan", "--guide", str(tmp_path / "nope.npz"), "--out", str(tmp_path / "p.npz")], capsys
    )
    assert code == 2
    line = _one_error_line(err)
    assert "--guide" in line and "nope.npz" in line and "no such file" in line


@pytest.mark.parametrize(
    "contents, key",
    [
        (dict(guide=_guide()), "timestep"),
        (dict(timestep=0.1, terrain=TERRAIN), "guide"),
    ],
)
def test_plan_guide_missing_key(tmp_path, capsys, contents, key):
    path = tmp_path / "g.npz"
    np.savez(path, **contents)
    code, _, err = run_leas(["plan", "--guide", str(path), "--out", str(tmp_path / "p.npz")], capsys)
    assert code == 2
    line = _one_error_line(err)
    assert str(path) in line and f"missing key '{key}'" in line


@pytest.mark.parametrize(
    "contents, message",
    [
        (dict(guide=np.zeros((5, 3)), timestep=0.1), "key 'guide' must be a [T, 4]"),
        (dict(guide=np.full((5, 4), np.nan), timestep=0.1), "key 'guide' contains NaN"),
        (dict(guide=_guide(), timestep=-0.1), "key 'timestep' must be a positive"),
        (
            dict(guide=_guide(), timestep=0.1, terrain=TERRAIN, target=[1.0, 2.0, 3.0]),
            "key 'target' must be 2",
        ),
        (dict(guide=_guide(), timestep=0.1, terrain=np.zeros(3)), "key 'terrain' must be a text scalar"),
        (dict(guide=_guide(), timestep=0.1), "--terrain: required"),
    ],
)
def test_plan_bad_guide_contents(tmp_path, capsys, contents, message):
    path = tmp_path / "g.npz"
    np.savez(path, **contents)
    code, _, err = run_leas(["plan", "--guide", str(path), "--out", str(tmp_path / "p.npz")], capsys)
    assert code == 2
    assert message in _one_error_line(err)


def test_plan_bad_terrain_file_and_out_dir(tmp_path, capsys):
    guide = tmp_path / "g.npz"
    np.savez(guide, guide=_guide(), timestep=0.1)
    bad = tmp_path / "bad.toml"
    bad.write_text(TERRAIN.replace("resolution = 0.02", "resolution = -0.02"))
    code, _, err = run_leas(
        ["plan", "--guide", str(guide), "--terrain", str(bad), "--out", str(tmp_path / "p.npz")], capsys
    )
    assert code == 2 and "resolution" in _one_error_line(err)
    good = tmp_path / "t.toml"
    good.write_text(TERRAIN)
    code, _, err = run_leas(
        ["plan", "--guide", str(guide), "--terrain", str(good), "--out", str(tmp_path / "missing" / "p.npz")],
        capsys,
    )
    assert code == 2 and "--out" in _one_error_line(err) and "does not exist" in err


def test_plan_guides_with_different_terrains_are_refused(tmp_path, capsys):
    a, b = tmp_path / "a.npz", tmp_path / "b.npz"
    np.savez(a, guide=_guide(), timestep=0.1, terrain=TERRAIN)
    np.savez(b, guide=_guide(), timestep=0.1, terrain=TERRAIN.replace("cli_flat", "other"))
    code, _, err = run_leas(["plan", "--guide", str(a), str(b), "--out", str(tmp_path / "plans")], capsys)
    assert code == 2 and "different terrains" in _one_error_line(err)


def test_workers_must_be_non_negative(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        run_leas(["plan", "--guide", "g.npz", "--out", "p.npz", "--workers", "-1"], capsys)
    assert exit_info.value.code == 2


def test_verify_and_show_file_errors(tmp_path, capsys):
    code, _, err = run_leas(["verify", str(tmp_path / "nope.npz")], capsys)
    assert code == 2 and "PLAN" in err and "no such file" in _one_error_line(err)
    text = tmp_path / "plan.npz"
    text.write_text("not a zip archive")
    code, _, err = run_leas(["verify", str(text)], capsys)
    assert code == 2 and "not a readable .npz" in _one_error_line(err)
    partial = tmp_path / "partial.npz"
    np.savez(
        partial,
        q=np.zeros((1, 39)),
        guide_index=np.zeros(1, int),
        last_valid_index=0,
        coverage=0.0,
        terrain=TERRAIN,
        guide=_guide(),
    )
    for argv in (["verify", str(partial)], ["show", str(partial), "--out", str(tmp_path / "v.html")]):
        code, _, err = run_leas(argv, capsys)
        assert code == 2 and "missing key 'feet'" in _one_error_line(err) and str(partial) in err
    code, _, err = run_leas(["show", str(partial), "--out", str(tmp_path / "no" / "v.html")], capsys)
    assert code == 2 and "--out" in _one_error_line(err)


def test_load_guide_file_returns_contents(tmp_path):
    path = tmp_path / "g.npz"
    np.savez(
        path,
        guide=_guide(7).astype(np.float32),
        timestep=np.float64(0.05),
        terrain=TERRAIN,
        target=[2.0, 0.5],
    )
    loaded = commands.load_guide_file(path)
    assert loaded.guide.shape == (7, 4) and loaded.guide.dtype == np.float64
    assert loaded.timestep == 0.05 and loaded.terrain_text == TERRAIN
    assert loaded.target.tolist() == [2.0, 0.5]
