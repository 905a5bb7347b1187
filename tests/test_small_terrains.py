"""Terrains with no spawn point (no root pose valid at every yaw): the commands that start from
given poses run on them (navigate, rollout, plan, verify, show), training refuses them in one
line that names the file, and the env's random resets refuse their field."""

from __future__ import annotations

from pathlib import Path

import jax
import pytest

from leas_jax.cli import main
from leas_jax.env import LeasEnv, heightfield_from_terrain
from leas_jax.errors import TerrainError
from leas_jax.terrain import load_terrain
from leas_jax.training import load_policy, preset

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = str(ROOT / "checkpoints" / "leas_talos")
# a 1.6 m x 0.30 m beam over the void: turned across it, a root's feet are over the void
BEAM = """name = "beam"
bounds = [[0.0, 0.0], [1.6, 0.3]]
void_height = -2.0
resolution = 0.02

[[box]]
center = [0.8, 0.15, -0.3]
size = [1.6, 0.3, 0.6]
"""


@pytest.fixture(scope="module")
def beam(tmp_path_factory) -> str:
    path = tmp_path_factory.mktemp("small") / "beam.toml"
    path.write_text(BEAM)
    return str(path)


def _one_line_error(capsys, code: int) -> str:
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    return err


def test_the_beam_has_no_spawn_point_for_the_shipped_policy_nor_the_presets(beam):
    terrain = load_terrain(beam)
    envs = [load_policy(SHIPPED).config.env] + [preset(name).env for name in ("smoke", "quick")]
    for env in envs:
        assert heightfield_from_terrain(terrain, env).spawn_xy.shape == (0, 2)


def test_navigate_then_verify_and_show_its_plan(beam, tmp_path, capsys):
    plan = tmp_path / "plan.npz"
    code = main(
        ["navigate", "--checkpoint", SHIPPED, "--terrain", beam, "--start", "0.3,0.15,0"]
        + ["--goal", "1.3,0.15", "--out", str(plan)]
    )
    out = capsys.readouterr().out
    assert code == 0 and "navigate: reached" in out, out
    assert main(["verify", str(plan)]) == 0
    assert main(["show", str(plan), "--out", str(tmp_path / "view.html"), "--no-robot"]) == 0
    assert (tmp_path / "view.html").stat().st_size > 0


def test_rollout_then_plan_and_verify_its_guide(beam, tmp_path):
    guide, plan = tmp_path / "guide.npz", tmp_path / "plan.npz"
    code = main(
        ["rollout", "--checkpoint", SHIPPED, "--terrain", beam, "--start", "0.3,0.15,0"]
        + ["--target", "1.3,0.15", "--out", str(guide)]
    )
    assert code == 0
    assert main(["plan", "--guide", str(guide), "--out", str(plan)]) == 0
    assert main(["verify", str(plan)]) == 0


def test_training_on_it_is_a_one_line_error_naming_the_file(beam, tmp_path, capsys):
    out = tmp_path / "run"
    code = main(["train", "--preset", "smoke", "--terrain", beam, "--out", str(out), "--no-progress"])
    err = _one_line_error(capsys, code)
    assert f"{beam}: no spawn position" in err and not out.exists()


def test_random_resets_refuse_a_field_without_spawn_points(beam):
    env = LeasEnv(load_terrain(beam))
    with pytest.raises(TerrainError, match="spawn points and it has none"):
        env.reset(jax.random.PRNGKey(0))
