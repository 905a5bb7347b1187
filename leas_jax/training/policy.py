"""A trained LeaS policy as a host object: load it, call it on observations."""

from __future__ import annotations

import pickle
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import jax

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


def load_policy(path: str | Path) -> Policy:
    """Load `policy.pkl` from a run directory, a checkpoint directory or the file itself.

    Raises:
        LeasError naming the path when it holds no readable policy.
    """
    path = Path(path)
    file = path / "policy.pkl" if path.is_dir() else path
    if not file.exists():
        raise LeasError(
            f"{path}: no policy.pkl found (give a run directory from `leas train` or a policy.pkl file)"
        )
    try:
        with open(file, "rb") as f:
            payload = pickle.load(f)
    except (OSError, pickle.UnpicklingError, EOFError) as exc:
        raise LeasError(f"{file}: cannot read policy ({exc})") from exc
    if not isinstance(payload, dict) or payload.get("format") != "leas-policy-v1":
        raise LeasError(f"{file}: not a leas policy file (missing format 'leas-policy-v1')")
    return Policy(
        config=TrainConfig.from_dict(payload["config"]),
        normalizer=payload["normalizer"],
        params=payload["policy_params"],
        env_steps=payload["env_steps"],
        source=str(file),
    )
