"""Planner-in-the-loop PPO, the paper's method (docs/design.md §7), jitted parts.

One iteration:
  1. roll out `num_envs` whole episodes (up to `episode_length` steps, fresh
     random starts) with the stochastic policy, in JAX;
  2. on the host, send their guide paths to the contact generator workers;
  3. cut each episode after the generator's `last_valid_index`: the step that
     leaves the last covered pose becomes terminal, later steps are masked out
     of the loss, the advantage and the normaliser update;
  4. run the PPO update (Brax's networks, GAE and distributions; the loss is
     Brax's PPO loss with a per-step mask).
The host loop (`leas_jax.training.loop`) overlaps step 2 of batch k with
step 1 of batch k+1, so batch k+1 is collected with the parameters from
before update k: the data are at most one update stale, which PPO's
importance ratio (clipped at 1 ± epsilon) absorbs.
"""

from __future__ import annotations

import dataclasses
import functools

import jax
import jax.numpy as jnp
import numpy as np
from brax.training import gradients
from brax.training.acme import running_statistics
from brax.training.agents.ppo import losses as ppo_losses
from brax.training.agents.ppo import networks as ppo_networks
from flax import struct

from leas_jax.env import LeasEnv
from leas_jax.env.field import Heightfield
from leas_jax.training.config import TrainConfig
from leas_jax.training.networks import make_networks
from leas_jax.training.ppo import (
    TrainState,
    make_optimizer,
    planner_learning_rate,
    sgd_epochs,
    with_learning_rate,
)


@struct.dataclass
class EpisodeBatch:
    """Whole episodes, padded to T = episode_length steps. Shapes [N, T, ...] unless said.

    Attributes:
        observation: [N, T, 81] observation before each step.
        raw_action: [N, T, 4] pre-tanh action sample (for the log-probability).
        log_prob: [N, T] behaviour log-probability.
        reward: [N, T].
        done: [N, T] 1 where the episode ends at this step.
        truncation: [N, T] 1 where it ends by the time limit.
        alive: [N, T] 1 for steps that belong to the episode.
        poses: [N, T + 1, 4] root poses (x, y, z, yaw), world; frozen after the end.
        guide_length: [N] poses of the guide path: the start and every pose
            after a step, except a final invalid pose.
    """

    observation: jax.Array
    raw_action: jax.Array
    log_prob: jax.Array
    reward: jax.Array
    done: jax.Array
    truncation: jax.Array
    alive: jax.Array
    poses: jax.Array
    guide_length: jax.Array


def rollout_episodes(
    config: TrainConfig, network, state: TrainState, field: Heightfield, key
) -> EpisodeBatch:
    """`config.num_envs` whole episodes from fresh random starts (pure, jittable)."""
    env_config = config.env
    env = LeasEnv(field, env_config)
    policy = ppo_networks.make_inference_fn(network)((state.normalizer, state.params.policy))
    k_reset, k_steps = jax.random.split(key)
    start = jax.vmap(env.reset)(jax.random.split(k_reset, config.num_envs))

    def step(carry, k):
        env_state, alive = carry  # alive: [N] 1 while the episode runs
        actions, extras = policy(env_state.obs, k)
        new = jax.vmap(env.step)(env_state, actions)
        record = dict(
            observation=env_state.obs,
            raw_action=extras["raw_action"],
            log_prob=extras["log_prob"],
            reward=new.reward * alive,
            done=new.done * alive,
            truncation=new.info["truncation"] * alive,
            alive=alive,
            invalid=new.metrics["invalid"] * alive,
        )
        # finished episodes keep their last state (their later steps are padding)
        running = lambda x: (alive > 0).reshape(alive.shape + (1,) * (x.ndim - 1))  # noqa: E731
        env_state = jax.tree.map(lambda a, b: jnp.where(running(a), a, b), new, env_state)
        record["pose"] = env_state.pipeline_state.pose
        return (env_state, alive * (1 - new.done)), record

    _, rec = jax.lax.scan(
        step, (start, jnp.ones(config.num_envs)), jax.random.split(k_steps, env_config.episode_length)
    )
    rec = jax.tree.map(lambda x: jnp.swapaxes(x, 0, 1), rec)  # [N, T, ...]
    poses = jnp.concatenate([start.pipeline_state.pose[:, None], rec["pose"]], axis=1)
    guide_length = 1 + (rec["alive"] - rec["invalid"]).sum(axis=1).astype(jnp.int32)
    return EpisodeBatch(
        observation=rec["observation"],
        raw_action=rec["raw_action"],
        log_prob=rec["log_prob"],
        reward=rec["reward"],
        done=rec["done"],
        truncation=rec["truncation"],
        alive=rec["alive"],
        poses=poses,
        guide_length=guide_length,
    )


def prune_after_failure(
    alive: np.ndarray,
    done: np.ndarray,
    truncation: np.ndarray,
    guide_length: np.ndarray,
    last_valid_index: np.ndarray,
):
    """Cut episodes after the contact generator's last valid pose (host, NumPy).

    Step t moves the root from guide pose t to pose t + 1. With l = last valid
    index: steps t < l are kept unchanged; step t = l (leaving the last
    covered pose) becomes terminal (done 1, truncation 0); steps t > l are
    masked. A fully covered guide (l = guide_length - 1) keeps its episode as
    it was; l = -1 (no valid first stance) masks the whole episode.

    Args:
        alive, done, truncation: [N, T] from `EpisodeBatch`.
        guide_length: [N] guide poses per episode.
        last_valid_index: [N] from the contact generator.

    Returns:
        (mask, done, truncation), each [N, T] float32.
    """
    n, t = alive.shape
    steps = np.arange(t)[None, :]
    lvi = np.asarray(last_valid_index)[:, None]
    full = lvi >= (np.asarray(guide_length)[:, None] - 1)
    mask = alive * np.where(full, 1.0, (steps <= lvi))
    failure_step = (~full) & (steps == lvi)
    done = np.where(failure_step, 1.0, done) * mask
    truncation = np.where(failure_step, 0.0, truncation) * mask
    return mask.astype(np.float32), done.astype(np.float32), truncation.astype(np.float32)


def masked_ppo_loss(params, normalizer, batch: dict, rng, network, config: TrainConfig):
    """Brax's PPO loss with a per-step mask. batch: dict of [B, T, ...] arrays.

    Masked steps neither contribute to the means nor carry the advantage
    recursion (they are marked truncated for the GAE, which zeroes their
    temporal differences and cuts the chain).
    """
    dist = network.parametric_action_distribution
    logits = network.policy_network.apply(normalizer, params.policy, batch["observation"])
    values = network.value_network.apply(normalizer, params.value, batch["observation"])
    mask = batch["mask"]
    truncation = jnp.maximum(batch["truncation"], 1.0 - mask)
    termination = batch["done"] * (1.0 - truncation)
    tm = lambda x: jnp.swapaxes(x, 0, 1)  # noqa: E731  [B, T] -> [T, B]
    vs, advantages = ppo_losses.compute_gae(
        truncation=tm(truncation),
        termination=tm(termination),
        rewards=tm(batch["reward"] * config.reward_scaling),
        values=tm(values),
        bootstrap_value=jnp.zeros(values.shape[0]),
        lambda_=config.gae_lambda,
        discount=config.discounting,
    )
    vs, advantages = tm(vs), tm(advantages)
    count = jnp.maximum(mask.sum(), 1.0)
    mean = lambda x: (x * mask).sum() / count  # noqa: E731
    adv_mean = mean(advantages)
    adv_std = jnp.sqrt(mean((advantages - adv_mean) ** 2))
    advantages = (advantages - adv_mean) / (adv_std + 1e-8)
    log_prob = dist.log_prob(logits, batch["raw_action"])
    ratio = jnp.exp(log_prob - batch["log_prob"])
    eps = config.clipping_epsilon
    policy_loss = -mean(jnp.minimum(ratio * advantages, jnp.clip(ratio, 1 - eps, 1 + eps) * advantages))
    value_loss = 0.5 * config.vf_coefficient * mean((jax.lax.stop_gradient(vs) - values) ** 2)
    entropy = mean(dist.entropy(logits, rng))
    total = policy_loss + value_loss - config.entropy_cost * entropy
    return total, {"total_loss": total, "policy_loss": policy_loss, "v_loss": value_loss, "entropy": entropy}


def make_planner_fns(config: TrainConfig):
    """Jitted `(rollout(state, field, key) -> EpisodeBatch, update(state, batch_dict, key) -> (state, metrics))`."""
    network = make_networks(config)
    optimizer = make_optimizer(config)
    loss = functools.partial(masked_ppo_loss, network=network, config=config)
    step = gradients.gradient_update_fn(loss, optimizer, pmap_axis_name=None, has_aux=True)

    def rollout(state: TrainState, field: Heightfield, key) -> EpisodeBatch:
        return rollout_episodes(config, network, state, field, key)

    def update(state: TrainState, batch: dict, key):
        kept = batch["mask"].sum()
        updated = running_statistics.update(state.normalizer, batch["observation"], weights=batch["mask"])
        # a batch with every step pruned carries no statistics (a zero count would divide by zero)
        normalizer = jax.tree.map(lambda new, old: jnp.where(kept > 0, new, old), updated, state.normalizer)

        rate = planner_learning_rate(config, state.env_steps)
        params, opt_state, losses = sgd_epochs(
            config,
            step,
            normalizer,
            state.params,
            with_learning_rate(state.optimizer_state, rate),
            batch,
            key,
        )
        state = state.replace(
            params=params,
            optimizer_state=opt_state,
            normalizer=normalizer,
            env_steps=state.env_steps + kept.astype(jnp.int32),
            iteration=state.iteration + 1,
        )
        return state, {**losses, "learning_rate": rate}

    return jax.jit(rollout), jax.jit(update)


def training_batch(episodes: EpisodeBatch, last_valid_index: np.ndarray) -> tuple[dict, dict]:
    """Host: the masked PPO batch of a validated `EpisodeBatch`, and its statistics.

    Returns:
        batch: dict of [N, T, ...] arrays for `update`.
        stats: rolled_steps, kept_steps, discarded_fraction, episode_return (kept part),
            episode_length, invalid_fraction (episodes ended by an invalid pose).
    """
    host = jax.device_get(episodes)
    mask, done, truncation = prune_after_failure(
        host.alive, host.done, host.truncation, host.guide_length, last_valid_index
    )
    batch = dict(
        observation=host.observation,
        raw_action=host.raw_action,
        log_prob=host.log_prob,
        reward=host.reward,
        done=done,
        truncation=truncation,
        mask=mask,
    )
    alive_steps = float(host.alive.sum())
    returns = (host.reward * mask).sum(axis=1)
    stats = {
        "rolled_steps": alive_steps,
        "kept_steps": float(mask.sum()),
        "discarded_fraction": 1.0 - float(mask.sum()) / max(alive_steps, 1.0),
        "episode_return": float(returns.mean()),
        "episode_length": float(host.alive.sum(axis=1).mean()),
        "invalid_fraction": float((host.done * (1 - host.truncation)).sum() / host.done.shape[0]),
    }
    return batch, stats


def guides_of(episodes: EpisodeBatch) -> list[np.ndarray]:
    """Host: the guide path [L_n, 4] of each episode."""
    poses, lengths = jax.device_get((episodes.poses, episodes.guide_length))
    return [np.asarray(poses[n, : lengths[n]], np.float64) for n in range(len(lengths))]


# The walking truth the learned condition is fitted on (studies/reachability_calibration.py)
# calls a pose feasible when the generator covers the 0.36 m guide from it: 20 steps at the
# target speed and timestep. A covered guide pose is labelled feasible only when the guide
# went on covered for that long after it (or was covered to its end).
VERDICT_HORIZON = 20  # guide poses


def verdict_samples(
    guides: list[np.ndarray],
    last_valid_index: np.ndarray,
    rng: np.random.Generator,
    covered_per_guide: int = 4,
    horizon: int = VERDICT_HORIZON,
) -> tuple[np.ndarray, np.ndarray]:
    """Host: the contact generator's verdicts on validated guides as labelled poses (DAgger data).

    For each guide [L_n, 4] with last valid index l (-1: no first stance): when the guide is
    not fully covered (l < L_n - 1), its first uncovered pose l + 1 is labelled infeasible
    (the policy's own failure); up to `covered_per_guide` poses drawn among the covered ones
    that the generator followed for `horizon` more poses (index <= l - horizon, every covered
    pose of a fully covered guide) are labelled feasible.

    Returns:
        (poses [K, 4] (x, y, z, yaw), world; labels [K] bool).
    """
    poses, labels = [], []
    for guide, lvi in zip(guides, np.asarray(last_valid_index), strict=True):
        full = lvi >= len(guide) - 1
        if not full:
            poses.append(guide[lvi + 1][None])
            labels.append(np.zeros(1, bool))
        last_sure = len(guide) - 1 if full else lvi - horizon
        if last_sure >= 0 and covered_per_guide > 0:
            picks = rng.choice(last_sure + 1, size=min(covered_per_guide, last_sure + 1), replace=False)
            poses.append(guide[np.sort(picks)])
            labels.append(np.ones(len(picks), bool))
    if not poses:
        return np.zeros((0, 4)), np.zeros(0, bool)
    return np.concatenate(poses).astype(np.float64), np.concatenate(labels)


def anchor_samples(field: Heightfield, env_config, count: int, rng: np.random.Generator):
    """Host: `count` poses drawn as resets draw them, labelled by the field's current condition.

    Positions: spawn points jittered within the spawn spacing; yaw uniform; z the terrain
    under the point + the nominal root height (`LeasEnv.random_root`, without its validity
    filter). A refit that also fits these keeps the condition's verdicts where the policy's
    guides do not go (see `VerdictData`).

    Returns:
        (poses [count, 4] float64 (x, y, z, yaw), world; labels [count] bool, the condition's).
    """
    from leas_jax.env import condition
    from leas_jax.feasibility.spawns import root_poses

    spawn = np.asarray(field.spawn_xy, dtype=np.float64)
    xy = spawn[rng.integers(0, len(spawn), count)]
    xy = xy + (rng.random((count, 2)) - 0.5) * float(field.spawn_spacing)
    poses = root_poses(field, xy, rng.uniform(-np.pi, np.pi, count), env_config.nominal_root_height)
    valid = jax.jit(jax.vmap(lambda pose: condition.valid(field, pose, env_config)))
    return poses, np.asarray(valid(jnp.asarray(poses, jnp.float32)), bool)


def seed_data(path) -> tuple[np.ndarray, np.ndarray]:
    """Host: the labelled poses of `TrainConfig.condition_seed_data`: (poses [K, 4] float64,
    labels [K] bool). Raises UsageError naming the file and the field when it cannot be used."""
    from leas_jax.errors import UsageError
    from leas_jax.files import resolve_data_path

    where = f"TrainConfig.condition_seed_data: {path}"
    try:
        with np.load(resolve_data_path(path), allow_pickle=False) as data:
            poses, labels = np.asarray(data["poses"], np.float64), np.asarray(data["labels"])
    except (OSError, ValueError, KeyError) as error:
        raise UsageError(f"{where}: not an .npz with 'poses' and 'labels' ({error})") from None
    if poses.ndim != 2 or poses.shape[1] != 4 or labels.shape != (len(poses),) or labels.dtype != bool:
        raise UsageError(
            f"{where}: needs poses [K, 4] and bool labels [K], got {poses.shape} and {labels.shape} {labels.dtype}"
        )
    if not np.isfinite(poses).all():
        raise UsageError(f"{where}: poses hold nan or inf")
    return poses, labels


class VerdictData:
    """Host: the DAgger loop of the learned condition during planner-in-the-loop training.

    Every validated batch adds its verdicts (`verdict_samples`); every
    `config.condition_refresh_every` iterations, once `config.condition_refresh_min_poses`
    poses are in, the condition is refitted from its current weights on all of them
    (`leas_jax.feasibility.fit` with `init`) and the field carries the new weights: the next
    rollouts terminate where the refreshed condition says so, while the PPO update keeps the
    generator's pruning. Only with `config.env.condition == "learned"` and a refresh period > 0.
    Every refit also fits `config.condition_anchor_poses` poses drawn as resets are and
    labelled by the condition the run started with (`anchor_samples`), so that it keeps its
    verdicts where the policy's guides do not go, and the labelled poses of
    `config.condition_seed_data` (`seed_data`).
    """

    def __init__(self, config: TrainConfig, seed: int = 0):
        self.config = config
        self.rng = np.random.default_rng(seed)
        self.poses = np.zeros((0, 4))
        self.labels = np.zeros(0, bool)
        self.iterations = 0
        self.refreshes = 0
        self.anchor_poses = np.zeros((0, 4))
        self.anchor_labels = np.zeros(0, bool)
        self.seed_poses, self.seed_labels = (
            seed_data(config.condition_seed_data)
            if config.condition_seed_data
            else (np.zeros((0, 4)), np.zeros(0, bool))
        )

    @property
    def enabled(self) -> bool:
        return self.config.env.condition == "learned" and self.config.condition_refresh_every > 0

    def add(self, guides: list[np.ndarray], last_valid_index: np.ndarray) -> int:
        """Add one batch's verdicts; the number of poses added."""
        poses, labels = verdict_samples(guides, last_valid_index, self.rng)
        self.poses = np.concatenate([self.poses, poses])
        self.labels = np.concatenate([self.labels, labels])
        self.iterations += 1
        return len(poses)

    def due(self) -> bool:
        """Whether this iteration refreshes the condition."""
        return (
            self.enabled
            and self.iterations % self.config.condition_refresh_every == 0
            and len(self.labels) >= self.config.condition_refresh_min_poses
            and self.labels.any()
            and not self.labels.all()
        )

    def refresh(self, field: Heightfield) -> tuple[Heightfield, dict]:
        """The field with the condition refitted on every verdict so far, and the fit's info."""
        from leas_jax.feasibility.fit import FitConfig, features_of, fit

        reach = self.config.env.reachability
        if self.refreshes == 0 and self.config.condition_anchor_poses > 0:
            self.anchor_poses, self.anchor_labels = anchor_samples(
                field, self.config.env, self.config.condition_anchor_poses, self.rng
            )
        poses = np.concatenate([self.anchor_poses, self.seed_poses, self.poses])
        labels = np.concatenate([self.anchor_labels, self.seed_labels, self.labels])
        x = features_of(field.condition, field, poses, reach)
        fit_config = FitConfig(seed=self.refreshes)
        if self.config.condition_refresh_sensitivity is not None:
            fit_config = dataclasses.replace(
                fit_config, target_sensitivity=self.config.condition_refresh_sensitivity
            )
        params, info = fit(x, labels, fit_config, init=field.condition, reach=reach)
        self.refreshes += 1
        return field.replace(condition=params), info

    def save(self, run_dir, field: Heightfield) -> None:
        """run_dir/condition.npz (the current weights) and condition_data.npz (the verdicts), atomically."""
        import os
        from pathlib import Path

        from leas_jax.env.learned_weights import save_params

        run_dir = Path(run_dir)
        save_params(run_dir / "condition.npz", field.condition, refreshes=self.refreshes)
        tmp = run_dir / f"condition_data.tmp{os.getpid()}.npz"
        np.savez(
            tmp,
            poses=self.poses,
            labels=self.labels,
            anchor_poses=self.anchor_poses,
            anchor_labels=self.anchor_labels,
        )
        os.replace(tmp, run_dir / "condition_data.npz")
