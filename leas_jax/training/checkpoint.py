"""Checkpoints and policy files of training runs (host only): data only, checksummed, atomic.

Layout of a run directory:
    config.json                 the TrainConfig (checked on resume)
    checkpoints/step_<N>.ckpt   full TrainState (optimizer, normaliser, env states, key) + config
    policy.ckpt                 what inference needs: normaliser + policy params + config
    metrics.jsonl, tb/          logs

File format (`leas-tree-v1`): the 12 bytes `LEAS-TREE-1\\n`, the SHA-256 digest (32 raw bytes)
of the rest, then an uncompressed `.npz` archive read with `allow_pickle=False`: its
member `tree` is JSON describing the pytree (dicts, lists, tuples, None, JSON scalars, and
the dataclasses and named tuples of `_ALLOWED_TYPES`, by name), the members `leaf_<k>` are
its arrays. Loading such a file runs no code of the file's choosing: no pickle, no
import of a name the file gives, only the constructors of `_ALLOWED_TYPES`. The digest covers
every byte after it, so any bit flip is caught. Files are written atomically
(`leas_jax.files`), so a crash never leaves a truncated checkpoint of its own making.

Runs of earlier versions wrote pickles (`policy.pkl`, `checkpoints/step_<N>.pkl`); unpickling a
file can run arbitrary code, so they are read only with `allow_pickle=True` (`--allow-pickle`),
with a `LegacyPickleWarning`; `leas convert` rewrites them in this format.
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import io
import json
import re
import warnings
from pathlib import Path

import jax
import numpy as np

from leas_jax.errors import LeasError
from leas_jax.files import atomic_write_bytes, atomic_write_text

__all__ = [
    "CheckpointError",
    "PickleRefused",
    "LegacyPickleWarning",
    "CheckpointWarning",
    "atomic_write_bytes",
    "atomic_write_text",
    "dumps_tree",
    "loads_tree",
    "list_checkpoints",
    "save_state",
    "state_path",
    "load_state",
    "read_state",
    "save_policy",
    "read_policy_payload",
    "policy_file",
    "convert_run",
]

MAGIC = b"LEAS-TREE-1\n"
_DIGEST = hashlib.sha256().digest_size
POLICY_NAME = "policy.ckpt"
LEGACY_POLICY_NAME = "policy.pkl"
POLICY_FORMAT = "leas-policy-v2"
STATE_FORMAT = "leas-state-v2"
_STEP_FILE = re.compile(r"^step_(\d+)\.(ckpt|pkl)$")


class CheckpointError(LeasError):
    """A checkpoint or policy file that is damaged, foreign or refused (message names the file)."""


class PickleRefused(CheckpointError):
    """A legacy pickle file met without `allow_pickle=True`."""


class LegacyPickleWarning(UserWarning):
    """A pickle checkpoint was read (allowed by `allow_pickle=True`): it could have run code."""


class CheckpointWarning(UserWarning):
    """A damaged checkpoint was set aside and an older one used."""


def _allowed_types() -> dict:
    """Name -> class of the only types a tree file may construct (dataclasses, named tuples, enums)."""
    import optax
    from brax.envs.base import State
    from brax.training.acme.running_statistics import NormalizationMode, RunningStatisticsState
    from brax.training.agents.ppo.losses import PPONetworkParams
    from brax.training.types import UInt64

    from leas_jax.env.env import RootState
    from leas_jax.training.ppo import TrainState

    classes = (
        TrainState,
        PPONetworkParams,
        RunningStatisticsState,
        NormalizationMode,
        UInt64,
        State,
        RootState,
        optax.EmptyState,
        optax.ScaleByAdamState,
        optax.ScaleByScheduleState,
        optax.InjectStatefulHyperparamsState,
    )
    return {_type_name(c): c for c in classes}


_ALLOWED_TYPES: dict | None = None


def _registry() -> dict:
    global _ALLOWED_TYPES
    if _ALLOWED_TYPES is None:
        _ALLOWED_TYPES = _allowed_types()
    return _ALLOWED_TYPES


def _type_name(cls) -> str:
    return f"{cls.__module__}.{cls.__qualname__}"


def _is_namedtuple(value) -> bool:
    return isinstance(value, tuple) and hasattr(type(value), "_fields")


def _encode(node, leaves: list):
    """JSON description of a pytree node; arrays are appended to `leaves` and referred to by index."""
    if node is None:
        return None
    if isinstance(node, enum.Enum):
        name = _type_name(type(node))
        if name not in _registry():
            raise TypeError(f"cannot save an enum of type {name}")
        return {"enum": name, "member": node.name}
    if isinstance(node, (bool, int, float, str)) and not isinstance(node, np.generic):
        return {"json": node}
    if isinstance(node, (np.ndarray, np.generic, jax.Array)):
        array = np.asarray(jax.device_get(node))
        if array.dtype.kind not in "biufc":
            raise TypeError(f"cannot save an array of dtype {array.dtype}")
        leaves.append(array)
        return {"leaf": len(leaves) - 1, "scalar": isinstance(node, np.generic)}
    if dataclasses.is_dataclass(node) or _is_namedtuple(node):
        name = _type_name(type(node))
        if name not in _registry():
            raise TypeError(f"cannot save an object of type {name} (not in the checkpoint's allowed types)")
        names = node._fields if _is_namedtuple(node) else [f.name for f in dataclasses.fields(node)]
        return {"type": name, "fields": {k: _encode(getattr(node, k), leaves) for k in names}}
    if isinstance(node, dict):
        if not all(isinstance(k, str) for k in node):
            raise TypeError("cannot save a dict with non-string keys")
        return {"dict": {k: _encode(v, leaves) for k, v in node.items()}}
    if isinstance(node, list):
        return {"list": [_encode(v, leaves) for v in node]}
    if isinstance(node, tuple):
        return {"tuple": [_encode(v, leaves) for v in node]}
    raise TypeError(f"cannot save an object of type {type(node).__name__}")


def _decode(spec, leaves):
    """Inverse of `_encode`; every failure is a ValueError/TypeError/KeyError for the caller to name."""
    if spec is None:
        return None
    if not isinstance(spec, dict) or len(spec) not in (1, 2):
        raise ValueError(f"malformed tree node {str(spec)[:60]!r}")
    if "json" in spec:
        value = spec["json"]
        if not isinstance(value, (bool, int, float, str)):
            raise ValueError("a json node holds a container")
        return value
    if "leaf" in spec:
        array = leaves[f"leaf_{int(spec['leaf'])}"]
        return array[()] if spec.get("scalar") else array
    if "enum" in spec:
        return _registry()[spec["enum"]][spec["member"]]
    if "type" in spec:
        cls = _registry()[spec["type"]]
        if isinstance(cls, type) and issubclass(cls, enum.Enum):
            raise ValueError(f"{spec['type']} is an enum")
        fields = {str(k): _decode(v, leaves) for k, v in dict(spec["fields"]).items()}
        return cls(**fields)
    if "dict" in spec:
        return {str(k): _decode(v, leaves) for k, v in dict(spec["dict"]).items()}
    if "list" in spec:
        return [_decode(v, leaves) for v in list(spec["list"])]
    if "tuple" in spec:
        return tuple(_decode(v, leaves) for v in list(spec["tuple"]))
    raise ValueError(f"unknown tree node {sorted(spec)}")


def dumps_tree(tree) -> bytes:
    """Serialise a pytree of arrays, JSON scalars and allowed dataclasses to `leas-tree-v1` bytes."""
    leaves: list = []
    spec = _encode(tree, leaves)
    buffer = io.BytesIO()
    members = {f"leaf_{k}": leaf for k, leaf in enumerate(leaves)}
    np.savez(buffer, tree=np.array(json.dumps(spec)), **members)
    body = buffer.getvalue()
    return MAGIC + hashlib.sha256(body).digest() + body


def loads_tree(data: bytes, source: str):
    """Read `leas-tree-v1` bytes (see the module docstring); runs no code chosen by the file.

    Raises:
        CheckpointError naming `source`: foreign format, checksum mismatch, malformed content.
    """
    if not data.startswith(MAGIC):
        raise CheckpointError(f"{source}: not a leas checkpoint file (no {MAGIC.strip().decode()} header)")
    digest, body = data[len(MAGIC) : len(MAGIC) + _DIGEST], data[len(MAGIC) + _DIGEST :]
    if hashlib.sha256(body).digest() != digest:
        raise CheckpointError(f"{source}: checksum mismatch: the file is truncated or corrupt")
    # The digest matches, so the content is what some writer produced; it may still be hostile
    # (anyone can compute a digest). np.load refuses object arrays, JSON holds data only, and the
    # decoder constructs nothing outside _ALLOWED_TYPES: whatever goes wrong there is reported,
    # never run.
    try:
        with np.load(io.BytesIO(body), allow_pickle=False) as archive:
            leaves = {name: archive[name] for name in archive.files if name != "tree"}
            spec = json.loads(str(archive["tree"]))
        return _decode(spec, leaves)
    except Exception as exc:  # noqa: BLE001 (any parse failure of untrusted bytes -> one named error)
        raise CheckpointError(
            f"{source}: malformed checkpoint content ({type(exc).__name__}: {exc})"
        ) from None


def _read_file(path: Path, allow_pickle: bool, what: str):
    """Content of a tree file, or of a legacy pickle when allowed (with a warning)."""
    path = Path(path)
    if path.suffix == ".pkl":
        if not allow_pickle:
            raise PickleRefused(
                f"{path}: a pickle {what} of an earlier version; unpickling can run code, so it is "
                "refused: if you trust the file, pass --allow-pickle (allow_pickle=True) or rewrite "
                "it with `leas convert --allow-pickle DIR`"
            )
        import pickle

        warnings.warn(
            f"{path}: reading a pickle {what} (allow_pickle=True): this can run code from the file",
            LegacyPickleWarning,
            stacklevel=3,
        )
        try:
            with open(path, "rb") as f:
                return pickle.load(f)
        except Exception as exc:  # noqa: BLE001 (the user opted in; report what broke on one line)
            raise CheckpointError(f"{path}: cannot read {what} ({type(exc).__name__}: {exc})") from None
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise CheckpointError(f"{path}: cannot read {what} ({exc.strerror or exc})") from None
    return loads_tree(data, str(path))


def to_host(tree):
    """Device arrays -> NumPy arrays."""
    return jax.tree.map(np.asarray, jax.device_get(tree))


def like(template, tree):
    """`tree` (loaded from a file, NumPy leaves) in the form of `template` (the same tree
    built fresh): device arrays of the template's types, weakly typed where the template
    holds a Python scalar.

    A file stores every leaf as a plain array, and a plain array is not weakly typed as a
    Python scalar is (`normalizer.std_eps`): without this, a resumed run's jitted iteration
    sees other argument types than an uninterrupted run's and compiles its program again
    instead of loading it from the compilation cache. `tree` has the template's structure
    except where it holds None (a planner run saves no env state): it stays None there.
    """

    def leaf(loaded, fresh):
        if loaded is None:
            return None
        if isinstance(fresh, (bool, int, float)):
            return jax.numpy.asarray(type(fresh)(np.asarray(loaded).item()))  # weakly typed
        return jax.numpy.asarray(loaded, dtype=fresh.dtype)

    return jax.tree.map(leaf, tree, template, is_leaf=lambda node: node is None)


def list_checkpoints(run_dir: Path) -> list[tuple[int, Path]]:
    """[(env_steps, path)] of `checkpoints/step_*.ckpt` (and legacy `.pkl`) sorted by steps.

    Where both formats hold the same step, the `.ckpt` file is listed alone.
    """
    folder = Path(run_dir) / "checkpoints"
    if not folder.is_dir():
        return []
    found: dict[int, Path] = {}
    for p in folder.iterdir():
        if m := _STEP_FILE.match(p.name):
            steps = int(m.group(1))
            if steps not in found or p.suffix == ".ckpt":
                found[steps] = p
    return sorted(found.items())


def state_path(run_dir: Path, env_steps: int) -> Path:
    """checkpoints/step_<env_steps, 12 digits>.ckpt of a run directory."""
    return Path(run_dir) / "checkpoints" / f"step_{env_steps:012d}.ckpt"


def save_state(run_dir: Path, state, env_steps: int, keep: int, config_dict: dict | None = None) -> Path:
    """Write the full training state (and the config it trains) atomically; keep the `keep` newest."""
    payload = {
        "format": STATE_FORMAT,
        "config": config_dict,
        "env_steps": int(env_steps),
        "state": to_host(state),
    }
    path = state_path(run_dir, env_steps)
    atomic_write_bytes(path, dumps_tree(payload))
    for _, old in list_checkpoints(run_dir)[:-keep]:
        old.unlink(missing_ok=True)
    return path


def read_state(path: Path, allow_pickle: bool = False):
    """(TrainState with NumPy leaves, config dict or None) of a checkpoint file.

    Raises:
        CheckpointError naming the file (damaged, foreign, or a refused pickle).
    """
    payload = _read_file(path, allow_pickle, "checkpoint")
    if Path(path).suffix == ".pkl":
        return payload, None
    if not isinstance(payload, dict) or payload.get("format") != STATE_FORMAT:
        raise CheckpointError(f"{path}: not a leas training checkpoint (missing format {STATE_FORMAT!r})")
    from leas_jax.training.ppo import TrainState

    if not isinstance(payload.get("state"), TrainState):
        raise CheckpointError(f"{path}: the checkpoint holds no TrainState")
    config = payload.get("config")
    return payload["state"], config if isinstance(config, dict) else None


def load_state(path: Path, allow_pickle: bool = False):
    """The TrainState (NumPy leaves) of a checkpoint file; see `read_state`."""
    return read_state(path, allow_pickle)[0]


def save_policy(run_dir: Path, normalizer, policy_params, config_dict: dict, env_steps: int) -> Path:
    """Write `policy.ckpt`: everything `load_policy` needs, nothing more."""
    payload = {
        "format": POLICY_FORMAT,
        "config": config_dict,
        "env_steps": int(env_steps),
        "normalizer": to_host(normalizer),
        "policy_params": to_host(policy_params),
    }
    path = Path(run_dir) / POLICY_NAME
    atomic_write_bytes(path, dumps_tree(payload))
    return path


def policy_file(path: Path) -> Path:
    """The policy file of a run directory (`policy.ckpt`, else a legacy `policy.pkl`) or `path` itself."""
    path = Path(path)
    if not path.is_dir():
        return path
    if (path / POLICY_NAME).exists() or not (path / LEGACY_POLICY_NAME).exists():
        return path / POLICY_NAME
    return path / LEGACY_POLICY_NAME


def read_policy_payload(file: Path, allow_pickle: bool = False) -> dict:
    """The dict a policy file holds (format, config, env_steps, normalizer, policy_params).

    Raises:
        CheckpointError naming the file.
    """
    payload = _read_file(file, allow_pickle, "policy")
    legacy = Path(file).suffix == ".pkl"
    expected = "leas-policy-v1" if legacy else POLICY_FORMAT
    if not isinstance(payload, dict) or payload.get("format") != expected:
        raise CheckpointError(f"{file}: not a leas policy file (missing format {expected!r})")
    missing = [k for k in ("config", "env_steps", "normalizer", "policy_params") if k not in payload]
    if missing:
        raise CheckpointError(f"{file}: policy file without {', '.join(missing)}")
    return payload


def convert_run(run_dir: Path) -> list[tuple[Path, Path]]:
    """Rewrite a run directory's legacy pickles (trusted by the caller) in the tree format.

    The policy and each step file get a `.ckpt` twin holding the same arrays bit for
    bit; the state checkpoints store config.json's config. The pickles are kept.

    Returns:
        [(pickle, new file)] converted.
    """
    import warnings

    run_dir = Path(run_dir)
    done = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", LegacyPickleWarning)  # the caller opted in for these files
        legacy = run_dir / LEGACY_POLICY_NAME
        if legacy.exists():
            payload = read_policy_payload(legacy, allow_pickle=True)
            new = save_policy(
                run_dir,
                payload["normalizer"],
                payload["policy_params"],
                payload["config"],
                payload["env_steps"],
            )
            done.append((legacy, new))
        config_file = run_dir / "config.json"
        config = json.loads(config_file.read_text()) if config_file.exists() else None
        folder = run_dir / "checkpoints"
        for old in sorted(folder.glob("step_*.pkl")) if folder.is_dir() else []:
            steps = int(_STEP_FILE.match(old.name).group(1))
            new = state_path(run_dir, steps)
            payload = {"format": STATE_FORMAT, "config": config, "env_steps": steps}
            payload["state"] = to_host(load_state(old, allow_pickle=True))
            atomic_write_bytes(new, dumps_tree(payload))
            done.append((old, new))
    return done
