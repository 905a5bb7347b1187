"""Fitting the learned feasibility condition (`leas_jax.env.learned_feasibility`) to labelled poses.

The labels are the contact generator's verdicts (`leas feasibility condition`: the
walking truth; `leas_jax.training.planner.verdict_samples`: the poses of the policy's own
guides during planner-in-the-loop training). Fitting is full-batch Adam on the class-balanced
binary cross-entropy (the data sets hold a few thousand to a few tens of thousands of poses,
so one batch is one jitted call), from random weights or from a previous fit (the refresh of
the DAgger loop). The decision threshold is then set on poses kept aside for a target
sensitivity, the rule the cylinders were calibrated with (95 %).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np
import optax

from leas_jax.env import learned_feasibility as lf
from leas_jax.env.config import ReachabilityConfig
from leas_jax.env.field import Heightfield

TARGET_SENSITIVITY = 0.95  # the cylinders' calibration target (studies/reachability_calibration.py)


@dataclass(frozen=True)
class FitConfig:
    """Settings of one fit. Defaults measured with `leas feasibility condition` (docs/results/2026-12-01-feasibility)."""

    hidden: tuple = (64, 32)  # tanh MLP widths
    # Full-batch Adam steps from random weights, and the decoupled weight decay (AdamW). Trained
    # on 10 800 fresh + 3 000 policy poses, tested on 4 000 fresh and 1 000 policy poses:
    # 1500 steps at 1e-4 gave 94.5 / 88.9 % (fresh) and 95.6 / 74.9 % (policy), 600 at 1e-2
    # 94.3 / 90.7 % and 95.3 / 75.5 % in a third of the time; a 128 x 64 network no better.
    steps: int = 600
    weight_decay: float = 1e-2
    refresh_steps: int = 200  # steps of a DAgger refresh, from the previous weights
    learning_rate: float = 3e-3
    mirror: bool = True  # add every pose's left-right mirror image (Talos and its generator are symmetric)
    aside_fraction: float = 0.15  # share of the poses kept aside to set the threshold
    target_sensitivity: float = TARGET_SENSITIVITY
    seed: int = 0


def features_of(
    params: lf.LearnedParams, field: Heightfield, poses, reach: ReachabilityConfig = ReachabilityConfig()
) -> np.ndarray:
    """Raw features [N, F] of poses [N, 4] on the params' grid (jitted, vmapped); the field must
    carry the rasters of `reach`."""
    return np.asarray(_features(params, field, jnp.asarray(poses, jnp.float32), reach))


@functools.partial(jax.jit, static_argnames=("reach",))
def _features(params, field, poses, reach):
    return jax.vmap(lambda p: lf.features(params, field, p, reach))(poses)


def mirrored(
    x: np.ndarray, grid: np.ndarray, reach: ReachabilityConfig = ReachabilityConfig(), footing=None
) -> np.ndarray:
    """Features [N, F] of the mirrored poses (terrain reflected across the root's x axis);
    `footing`: the features' footing places [K, 2], or None."""
    return x[:, lf.feature_mirror_index(np.asarray(grid), reach, footing)]


def _loss(params, x, y, weight):
    logits = lf.logit_of_features(params, x)
    return jnp.sum(weight * optax.sigmoid_binary_cross_entropy(logits, y)) / jnp.sum(weight)


@functools.partial(jax.jit, static_argnames=("steps", "learning_rate", "weight_decay"))
def _train(params, x, y, weight, steps, learning_rate, weight_decay):
    trainable = {k: params[k] for k in lf.LAYER_KEYS}
    fixed = {k: v for k, v in params.items() if k not in lf.LAYER_KEYS}
    optimizer = optax.adamw(learning_rate, weight_decay=weight_decay)

    def step(carry, _):
        p, state = carry
        loss, grads = jax.value_and_grad(lambda t: _loss({**fixed, **t}, x, y, weight))(p)
        updates, state = optimizer.update(grads, state, p)
        return (optax.apply_updates(p, updates), state), loss

    (trainable, _), losses = jax.lax.scan(step, (trainable, optimizer.init(trainable)), None, length=steps)
    return {**fixed, **trainable}, losses


def balanced_weights(y: np.ndarray) -> np.ndarray:
    """[N] sample weights giving both classes the same total weight (each class half)."""
    y = np.asarray(y, bool)
    n_pos, n_neg = max(int(y.sum()), 1), max(int((~y).sum()), 1)
    return np.where(y, 0.5 / n_pos, 0.5 / n_neg).astype(np.float32) * len(y)


def threshold_for(logits: np.ndarray, y: np.ndarray, target: float) -> float:
    """The largest logit threshold that keeps at least `target` of the feasible poses (y) accepted.

    Raises ValueError when no pose is feasible."""
    feasible = np.sort(np.asarray(logits)[np.asarray(y, bool)])
    if len(feasible) == 0:
        raise ValueError("no feasible pose to set the learned condition's threshold on")
    k = int(np.floor((1.0 - target) * len(feasible)))  # at most k of them rejected
    return float(feasible[min(k, len(feasible) - 1)])


def fit(
    x: np.ndarray,
    y: np.ndarray,
    config: FitConfig = FitConfig(),
    grid: np.ndarray | None = None,
    init: lf.LearnedParams | None = None,
    reach: ReachabilityConfig = ReachabilityConfig(),
    footing: np.ndarray | None = None,
) -> tuple[lf.LearnedParams, dict]:
    """Fit the condition to features x [N, F] (`features_of` with `reach`) and labels y [N] bool.

    Args:
        x, y: the labelled poses' features and verdicts.
        config: the fit's settings.
        grid: [P, 2] the features' patch grid (default `learned_feasibility.patch_grid()`);
            ignored with `init`, whose grid the features must use.
        init: previous parameters to start from (a refresh: `config.refresh_steps` steps,
            standardisation kept); None: random weights, `config.steps` steps.
        footing: [K, 2] the features' footing places (`learned_feasibility.footing_points`), or
            None; ignored with `init`, whose places the features must use.

    Returns:
        (params with the threshold set on the poses kept aside, info: poses, aside,
        final_loss, threshold). Deterministic for a given config.seed and data.
    """
    x, y = np.asarray(x, np.float32), np.asarray(y, bool)
    if len(x) != len(y):
        raise ValueError(f"{len(x)} feature rows but {len(y)} labels")
    rng = np.random.default_rng(config.seed)
    order = rng.permutation(len(x))
    n_aside = int(round(config.aside_fraction * len(x)))
    aside, kept = order[:n_aside], order[n_aside:]
    if init is None:
        params = lf.init_params(
            jax.random.PRNGKey(config.seed), config.hidden, grid, reach=reach, footing=footing
        )
        steps = config.steps
    else:
        params, steps = dict(init), config.refresh_steps
    xt, yt = x[kept], y[kept]
    if config.mirror:
        xt, yt = (
            np.concatenate([xt, mirrored(xt, np.asarray(params["grid"]), reach, params.get("footing"))]),
            np.concatenate([yt, yt]),
        )
    if init is None:  # standardise on the fitting poses (a refresh keeps the input scale it learned on)
        params["mean"] = jnp.asarray(xt.mean(axis=0))
        params["std"] = jnp.asarray(np.maximum(xt.std(axis=0), 1e-3))
    params, losses = _train(
        params,
        jnp.asarray(xt),
        jnp.asarray(yt, jnp.float32),
        jnp.asarray(balanced_weights(yt)),
        steps=steps,
        learning_rate=config.learning_rate,
        weight_decay=config.weight_decay,
    )
    check_x, check_y = (x[aside], y[aside]) if n_aside and y[aside].any() else (xt, yt)
    threshold = threshold_for(
        np.asarray(lf.logit_of_features(params, jnp.asarray(check_x))), check_y, config.target_sensitivity
    )
    params["threshold"] = jnp.asarray(threshold, jnp.float32)
    info = {
        "poses": int(len(x)),
        "aside": int(n_aside),
        "final_loss": float(losses[-1]),
        "threshold": threshold,
    }
    return params, info


def predict(params: lf.LearnedParams, x: np.ndarray) -> np.ndarray:
    """bool [N]: the condition's verdicts on features x [N, F]."""
    return np.asarray(lf.logit_of_features(params, jnp.asarray(x, jnp.float32)) >= params["threshold"])
