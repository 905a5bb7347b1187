"""Resume after damage: damaged checkpoints, torn logs, failed starts; a resumed run's logs equal an
uninterrupted run's."""

import json
import shutil

import jax
import numpy as np
import pytest
from training_helpers import gap_field, tiny_config

from leas_jax.cli import main
from leas_jax.errors import LeasError
from leas_jax.terrain import TerrainError
from leas_jax.training import checkpoint, load_policy, records, train
from leas_jax.training.commands import config_from_args


@pytest.fixture(scope="module")
def field():
    return gap_field()


@pytest.fixture(scope="module")
def full_run(tmp_path_factory, field):
    """An uninterrupted run: 3 calls, checkpoints after each (keep 3)."""
    out = tmp_path_factory.mktemp("full") / "run"
    train(tiny_config(), out, progress=False, field=field)
    return out


TIMING = ("wall_s", "sps")  # wall-clock fields: the only ones a resumed run may log differently


def _records(run):
    """metrics.jsonl records without the wall-clock fields."""
    lines = (run / "metrics.jsonl").read_text().splitlines()
    return [{k: v for k, v in json.loads(line).items() if k not in TIMING} for line in lines]


def _scalars(run):
    """Sorted (tag, step, value) of every TensorBoard scalar in the run's event files."""
    from tensorboardX.proto.event_pb2 import Event

    found = []
    for file in sorted((run / "tb").glob("events.out.tfevents.*")):
        for _, _, payload in records._records(file.read_bytes()):
            event = Event()
            event.ParseFromString(payload)
            for value in event.summary.value:
                if value.tag not in TIMING:
                    found.append((value.tag, event.step, value.simple_value))
    return sorted(found)


def test_damaged_newest_checkpoint_and_torn_logs_resume_to_the_uninterrupted_run(tmp_path, field, full_run):
    """The kill came while the newest checkpoint was written (truncated) and while a metrics line and
    a TensorBoard record were written (torn): resume warns, sets the checkpoint aside, trains the
    last call again and ends with the uninterrupted run's policy, metrics and TensorBoard scalars."""
    run = tmp_path / "run"
    shutil.copytree(full_run, run)
    steps = checkpoint.list_checkpoints(run)
    assert len(steps) == 3
    newest = steps[-1][1]
    newest.write_bytes(newest.read_bytes()[: newest.stat().st_size // 2])
    with open(run / "metrics.jsonl", "a") as f:
        f.write('{"iteration": 8, "env_st')
    events = next((run / "tb").glob("events.out.tfevents.*"))
    with open(events, "ab") as f:
        f.write(b"\x20\x00\x00\x00\x00\x00\x00\x00torn")
    with pytest.warns(checkpoint.CheckpointWarning, match="checksum mismatch"):
        resumed = train(tiny_config(), run, progress=False, field=field)
    assert resumed.env_steps == steps[-1][0]
    assert (run / "checkpoints" / (newest.name + ".corrupt")).exists()  # set aside, not deleted
    for x, y in zip(jax.tree.leaves(load_policy(full_run).params), jax.tree.leaves(load_policy(run).params)):
        np.testing.assert_array_equal(x, y)
    assert _records(run) == _records(full_run)
    assert [r["iteration"] for r in _records(run)] == [2, 4, 6]
    assert _scalars(run) == _scalars(full_run)
    assert len(list((run / "tb").glob("events.out.tfevents.*"))) == 2  # the old file, cut back, and the new


def test_every_checkpoint_damaged_is_one_error_and_moves_nothing(tmp_path, full_run):
    run = tmp_path / "run"
    shutil.copytree(full_run, run)
    for _, path in checkpoint.list_checkpoints(run):
        path.write_bytes(path.read_bytes()[:100])
    with pytest.raises(LeasError, match="no intact checkpoint"):
        train(tiny_config(), run, progress=False)
    assert len(checkpoint.list_checkpoints(run)) == 3


def test_forty_random_bit_flips_are_each_detected(full_run):
    path = checkpoint.list_checkpoints(full_run)[-1][1]
    data = path.read_bytes()
    checkpoint.loads_tree(data, "intact")
    rng = np.random.default_rng(0)
    for bit in rng.choice(8 * len(data), size=40, replace=False):
        flipped = bytearray(data)
        flipped[bit // 8] ^= 1 << (bit % 8)
        with pytest.raises(checkpoint.CheckpointError):
            checkpoint.loads_tree(bytes(flipped), f"bit {bit}")


def test_truncated_config_json_and_a_new_checkpoint_interval_still_resume(tmp_path, field, full_run):
    """The checkpoint stores the config it trains: config.json is rewritten from it; checkpoint_every_s
    and keep_checkpoints say how a run is recorded, so changing them on resume is allowed."""
    run = tmp_path / "run"
    shutil.copytree(full_run, run)
    (run / "config.json").write_text('{"num_envs": 6')
    train(tiny_config(checkpoint_every_s=30.0), run, progress=False, field=field)
    assert json.loads((run / "config.json").read_text())["checkpoint_every_s"] == 30.0
    with pytest.raises(LeasError, match="differs in seed"):
        train(tiny_config(seed=4), run, progress=False, field=field)


def test_a_failed_start_leaves_nothing_that_blocks_the_corrected_command(tmp_path, capsys, field):
    out = tmp_path / "run"
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\n')
    small = ["train", "--preset", "smoke", "--no-progress", "--out", str(out)]
    assert main([*small, "--terrain", str(bad)]) == 2
    assert "missing required key" in capsys.readouterr().err
    assert not out.exists()
    with pytest.raises(TerrainError):
        train(tiny_config(terrain=str(bad)), out, progress=False)
    assert not out.exists()
    # a run that wrote its config and a log line but died before its first checkpoint blocks
    # nothing either: the corrected command starts afresh (stopped here before its first iteration)
    out.mkdir()
    (out / "config.json").write_text(tiny_config(seed=9).to_json())
    (out / "metrics.jsonl").write_text('{"iteration": 1, "env_steps": 999, "wall_s": 1.0}\n')
    (out / "checkpoints").mkdir()
    config = tiny_config(terrain="tests/data/slab_with_wall.toml")
    result = train(config, out, progress=False, field=field, stop_after_iterations=0)
    assert result.env_steps == 0 and [s for s, _ in checkpoint.list_checkpoints(out)] == [0]
    assert (out / "metrics.jsonl").read_text() == ""
    assert json.loads((out / "config.json").read_text())["seed"] == config.seed


def test_checkpoint_every_on_the_command_line(capsys):
    from leas_jax.cli import build_parser

    args = build_parser().parse_args(["train", "--out", "x", "--checkpoint-every", "2.5"])
    assert config_from_args(args).checkpoint_every_s == 2.5
    for bad in ("-1", "nan", "inf", "soon"):
        with pytest.raises(SystemExit) as exit_info:
            main(["train", "--out", "x", "--checkpoint-every", bad])
        err = capsys.readouterr().err.strip()
        assert exit_info.value.code == 2 and len(err.splitlines()) == 1 and "seconds" in err
