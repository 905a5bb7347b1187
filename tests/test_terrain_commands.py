"""`leas terrain generate|show|export` sub-commands, driven through their argparse parsers."""

import argparse
from pathlib import Path

import mujoco
import pytest
import trimesh

from leas_jax.errors import UsageError
from leas_jax.terrain import TerrainError
from leas_jax.terrain.commands import register
from leas_jax.terrain.generate import generate_eval_terrains, generate_training_arena

TERRAINS = Path(__file__).resolve().parents[1] / "terrains"


def run(*argv):
    parser = argparse.ArgumentParser(prog="leas")
    register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["terrain", *argv])
    args.func(args)


def test_generate_to_stdout(capsys):
    run("generate", "--seed", "3")
    assert capsys.readouterr().out == generate_training_arena(3)


def test_generate_to_file(tmp_path):
    out = tmp_path / "arena.toml"
    run("generate", "--seed", "0", "--out", str(out))
    assert out.read_text() == (TERRAINS / "training_arena.toml").read_text()


def test_generate_eval_dir(tmp_path):
    run("generate", "--eval-dir", str(tmp_path))
    texts = generate_eval_terrains()
    assert sorted(p.stem for p in tmp_path.iterdir()) == sorted(texts)
    for name, text in texts.items():
        assert (tmp_path / f"{name}.toml").read_text() == text


@pytest.mark.parametrize(
    "argv, message",
    [
        (["generate", "--seed", "-1"], "--seed -1: must be >= 0"),
        (["generate", "--eval-dir", "/nonexistent/dir"], "--eval-dir /nonexistent/dir: not a directory"),
        (["generate", "--eval-dir", ".", "--out", "x.toml"], "either --out or --eval-dir"),
        (["show", "terrains/eval_ground.toml", "--out", "x.jpg"], "must be a .png file"),
        (["export", "terrains/eval_ground.toml", "--out", "x.ply"], "unknown format '.ply'"),
    ],
)
def test_bad_arguments_are_usage_errors(argv, message):
    with pytest.raises(UsageError) as info:
        run(*argv)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_show_writes_a_png(tmp_path):
    out = tmp_path / "hole.png"
    run("show", str(TERRAINS / "eval_circuit.toml"), "--out", str(out))
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert out.stat().st_size > 10_000


def test_show_and_export_report_bad_terrain_files(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\n')
    with pytest.raises(TerrainError, match=r"bad\.toml: bounds: missing required key"):
        run("show", str(bad), "--out", str(tmp_path / "x.png"))
    with pytest.raises(TerrainError, match=r"missing\.toml: cannot read terrain file"):
        run("export", str(tmp_path / "missing.toml"), "--out", str(tmp_path / "x.xml"))


@pytest.mark.parametrize("suffix", [".xml", ".glb", ".obj", ".stl"])
def test_export(tmp_path, suffix):
    out = tmp_path / f"bridge{suffix}"
    run("export", str(TERRAINS / "eval_bridge.toml"), "--out", str(out))
    if suffix == ".xml":
        assert mujoco.MjModel.from_xml_path(str(out)).ngeom == 9
    else:
        assert len(trimesh.load(str(out), force="mesh").faces) == 9 * 12
