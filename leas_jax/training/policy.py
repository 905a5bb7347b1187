"""A trained LeaS policy as a host object: load it, call it on observations."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import jax
import numpy as np

from leas_jax.env.config import NETWORK_CONDITIONS
from leas_jax.errors import LeasError
from leas_jax.training.config import TrainConfig
from leas_jax.training.networks import deterministic_policy_fn


@dataclass(frozen=True)
class Policy:
    """Deterministic LeaS policy.

    Attributes:
        config: the training configuration (its `env` fixes the MDP).
        normalizer: observation running statistics.
        params: policy network parameters.
        env_steps: training steps behind it.
        source: file it was loaded from.
    """

    config: TrainConfig
    normalizer: Any
    params: Any
    env_steps: int = 0
    source: str = ""

    @cached_property
    def act(self):
        """Pure function obs [..., 81] -> action [..., 4] (closes over the parameters)."""
        return deterministic_policy_fn(self.config, self.normalizer, self.params)

    def __call__(self, obs: jax.Array) -> jax.Array:
        return self.act(obs)

    def __hash__(self):
        return id(self)


def load_policy(path: str | Path | Policy, allow_pickle: bool = False) -> Policy:
    """Load the policy of a run directory (`policy.ckpt`) or a policy file; a `Policy` is returned as is.

    The file's parameters are checked against the networks its config describes
    (same tree, shapes and dtypes) and must be finite, so a damaged or foreign file
    fails here with one line rather than inside a rollout. A policy trained with the
    learned condition refreshed during planner-in-the-loop training (`condition.npz` beside
    its `policy.ckpt`, `training.planner.VerdictData`) gets that condition as its
    `env.learned_weights`: the one its last updates were made with.

    Args:
        path: run directory, policy file, or a loaded `Policy`.
        allow_pickle: also read a legacy `policy.pkl` (warns: unpickling can run code).

    Raises:
        LeasError naming the path when it holds no readable, consistent policy.
    """
    if isinstance(path, Policy):
        return path
    from leas_jax.training.checkpoint import CheckpointError, policy_file, read_policy_payload

    path = Path(path)
    file = policy_file(path)
    if not file.exists():
        raise LeasError(
            f"{path}: no policy.ckpt found (give a run directory from `leas train` or a policy.ckpt file)"
        )
    payload = read_policy_payload(file, allow_pickle)
    try:
        config = TrainConfig.from_dict(payload["config"])
        config.validate()
    except (LeasError, TypeError, ValueError, AttributeError) as exc:
        raise CheckpointError(f"{file}: the policy's config is invalid ({exc})") from None
    try:
        env_steps = int(payload["env_steps"])
    except (TypeError, ValueError):
        raise CheckpointError(f"{file}: env_steps must be an integer, got {payload['env_steps']!r}") from None
    normalizer, params = payload["normalizer"], payload["policy_params"]
    _check_like(file, "policy_params", params, _expected_params(config))
    _check_like(file, "normalizer", normalizer, _expected_normalizer(config))
    refreshed = file.parent / "condition.npz"
    if config.env.condition in NETWORK_CONDITIONS and refreshed.is_file():
        config = dataclasses.replace(
            config, env=dataclasses.replace(config.env, learned_weights=str(refreshed))
        )
    return Policy(config=config, normalizer=normalizer, params=params, env_steps=env_steps, source=str(file))


def _expected_params(config: TrainConfig):
    """Shapes and dtypes (jax.ShapeDtypeStruct tree) of the policy parameters of `config`'s networks."""
    from leas_jax.training.networks import make_networks

    network = make_networks(config)
    return jax.eval_shape(network.policy_network.init, jax.random.PRNGKey(0))


def _expected_normalizer(config: TrainConfig):
    """Shapes and dtypes of the observation running statistics of `config`."""
    import jax.numpy as jnp
    from brax.training.acme import running_statistics, specs

    array = specs.Array((config.env.observation_size,), jnp.float32)
    return jax.eval_shape(lambda: running_statistics.init_state(array))


def _check_like(file: Path, name: str, tree, expected) -> None:
    """CheckpointError unless `tree` has the structure, shapes and dtypes of `expected` and finite leaves."""
    from leas_jax.training.checkpoint import CheckpointError

    got, want = jax.tree.structure(tree), jax.tree.structure(expected)
    if got != want:
        raise CheckpointError(f"{file}: {name} do not fit the config's networks (tree {got} != {want})")
    paths = [jax.tree_util.keystr(p) for p, _ in jax.tree_util.tree_flatten_with_path(expected)[0]]
    for where, leaf, spec in zip(paths, jax.tree.leaves(tree), jax.tree.leaves(expected)):
        array = np.asarray(leaf)
        if array.shape != spec.shape or array.dtype != spec.dtype:
            raise CheckpointError(
                f"{file}: {name}{where} is {array.dtype}{list(array.shape)}, "
                f"the config's networks need {spec.dtype}{list(spec.shape)}"
            )
        if array.dtype.kind in "fc" and not np.all(np.isfinite(array)):
            raise CheckpointError(f"{file}: {name}{where} holds NaN or inf")
