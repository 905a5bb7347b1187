"""Policies and checkpoints are data: a crafted file cannot run code through any loader or command."""

import json
import pickle
import warnings

import numpy as np
import pytest

from leas_jax.cli import main
from leas_jax.errors import LeasError
from leas_jax.training import checkpoint, load_policy
from leas_jax.training.config import preset


class _WritesMarker:
    """Unpickling this runs `exec`, which writes the marker file."""

    def __init__(self, marker):
        self.marker = str(marker)

    def __reduce__(self):
        return (exec, (f"open({self.marker!r}, 'w').write('code ran')",))


@pytest.fixture
def hostile(tmp_path):
    """A run directory whose policy and checkpoint are pickles that write `marker` when loaded."""
    marker = tmp_path / "marker"
    run = tmp_path / "hostile_run"
    (run / "checkpoints").mkdir(parents=True)
    evil = pickle.dumps({"format": "leas-policy-v1", "config": _WritesMarker(marker)})
    (run / "policy.pkl").write_bytes(evil)
    (run / "checkpoints" / "step_000000000064.pkl").write_bytes(pickle.dumps(_WritesMarker(marker)))
    (run / "config.json").write_text(preset("smoke").to_json())
    return run, marker


def test_the_crafted_pickle_does_run_code_when_explicitly_allowed(hostile):
    """Control: the file is effective, so the refusals below are what keeps the marker away."""
    run, marker = hostile
    with pytest.warns(checkpoint.LegacyPickleWarning), pytest.raises(LeasError):
        load_policy(run, allow_pickle=True)
    assert marker.read_text() == "code ran"


def test_load_policy_and_load_state_refuse_pickles(hostile):
    run, marker = hostile
    for call in (
        lambda: load_policy(run),
        lambda: load_policy(run / "policy.pkl"),
        lambda: checkpoint.load_state(run / "checkpoints" / "step_000000000064.pkl"),
    ):
        with pytest.raises(checkpoint.PickleRefused, match="--allow-pickle"):
            call()
    assert not marker.exists()


def test_a_pickle_renamed_to_ckpt_is_not_unpickled(hostile):
    run, marker = hostile
    (run / "policy.ckpt").write_bytes((run / "policy.pkl").read_bytes())
    with pytest.raises(checkpoint.CheckpointError, match="not a leas checkpoint file"):
        load_policy(run)
    assert not marker.exists()


def test_a_tree_file_with_a_valid_checksum_constructs_only_allowed_types(tmp_path):
    """Anyone can compute the digest: a file naming os.system, or eval, builds nothing."""
    import hashlib
    import io

    def forge(spec, **leaves) -> bytes:
        text = spec if isinstance(spec, str) else json.dumps(spec)
        buffer = io.BytesIO()
        np.savez(buffer, tree=np.array(text), **leaves)
        body = buffer.getvalue()
        return checkpoint.MAGIC + hashlib.sha256(body).digest() + body

    marker = tmp_path / "marker"
    command = {"json": f"touch {marker}"}
    for spec in (
        {"type": "posix.system", "fields": {"command": command}},
        {"type": "builtins.eval", "fields": {"source": command}},
        {"enum": "os.system", "member": "x"},
        {"dict": {"a": {"leaf": 0}}},  # a leaf that is not there
        {"list": [{"list": [None]}] * 3, "extra": 1, "more": 2},
        '{"list": ' * 50_000 + "null" + "}" * 50_000,  # nested past the recursion limit
    ):
        with pytest.raises(checkpoint.CheckpointError, match="malformed checkpoint content"):
            checkpoint.loads_tree(forge(spec), "forged")
    assert not marker.exists()
    # an object array in the archive is refused by np.load(allow_pickle=False)
    objects = np.array([_WritesMarker(marker)], dtype=object)
    with pytest.raises(checkpoint.CheckpointError):
        checkpoint.loads_tree(forge({"leaf": 0}, leaf_0=objects), "forged")
    assert not marker.exists()


def _fails_in_one_line(capsys, argv) -> str:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning would mean a pickle was read
        code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "Traceback" not in err, err
    return err


@pytest.mark.parametrize(
    "command",
    [
        ["rollout", "--terrain", "terrains/eval_ground.toml", "--start", "4,4,0", "--target", "8,4"],
        ["evaluate", "--scenario", "ground", "--methods", "leas", "--n-starts", "1", "--workers", "0"],
        ["hole-sweep", "--widths", "1", "--methods", "leas", "--n-starts", "1", "--workers", "0"],
        ["arena-check", "--episodes", "4", "--seeds", "0"],
        ["navigate", "--terrain", "terrains/eval_ground.toml", "--start", "4,4,0", "--goal", "8,4"],
    ],
    ids=["rollout", "evaluate", "hole-sweep", "arena-check", "navigate"],
)
def test_policy_commands_refuse_the_hostile_policy(capsys, tmp_path, hostile, command):
    run, marker = hostile
    out = ["--out", str(tmp_path / ("g.npz" if command[0] in ("rollout", "navigate") else "out"))]
    err = _fails_in_one_line(capsys, [*command, "--checkpoint", str(run), *out])
    assert "--allow-pickle" in err and not marker.exists()


def test_train_init_and_resume_refuse_the_hostile_checkpoint(capsys, tmp_path, hostile):
    run, marker = hostile
    small = ["--preset", "smoke", "--no-progress", "--terrain", "tests/data/slab_with_wall.toml"]
    fine_tune = ["train", *small, "--mode", "planner", "--init", str(run), "--out", str(tmp_path / "ft")]
    assert "--allow-pickle" in _fails_in_one_line(capsys, fine_tune)
    assert "--allow-pickle" in _fails_in_one_line(capsys, ["train", *small, "--out", str(run)])
    assert not marker.exists()


def test_convert_rewrites_a_trusted_pickle_run_bit_for_bit(capsys, tmp_path, run_dir):
    """`leas convert --allow-pickle` turns an earlier version's pickles into .ckpt files holding the
    same arrays; without --allow-pickle it refuses."""
    import jax

    payload = checkpoint.read_policy_payload(run_dir / "policy.ckpt")
    state = checkpoint.load_state(checkpoint.list_checkpoints(run_dir)[-1][1])
    old = tmp_path / "old_run"
    (old / "checkpoints").mkdir(parents=True)
    (old / "config.json").write_text((run_dir / "config.json").read_text())
    (old / "policy.pkl").write_bytes(pickle.dumps({**payload, "format": "leas-policy-v1"}))
    (old / "checkpoints" / "step_000000001024.pkl").write_bytes(pickle.dumps(state))
    assert "--allow-pickle" in _fails_in_one_line(capsys, ["convert", str(old)])
    assert not (old / "policy.ckpt").exists()
    assert main(["convert", "--allow-pickle", str(old)]) == 0
    converted = load_policy(old)
    assert converted.source.endswith("policy.ckpt")
    original = load_policy(run_dir)
    for a, b in zip(
        jax.tree.leaves((original.normalizer, original.params)),
        jax.tree.leaves((converted.normalizer, converted.params)),
    ):
        assert np.asarray(a).dtype == np.asarray(b).dtype
        np.testing.assert_array_equal(a, b)
    new_state, config = checkpoint.read_state(old / "checkpoints" / "step_000000001024.ckpt")
    assert config == json.loads((run_dir / "config.json").read_text())
    for a, b in zip(jax.tree.leaves(state), jax.tree.leaves(new_state)):
        np.testing.assert_array_equal(a, b)
