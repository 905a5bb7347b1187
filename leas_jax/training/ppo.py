"""Geometric PPO training, built from Brax's PPO pieces.

Brax's networks, loss (`compute_ppo_loss`), gradient update and running
statistics, in our own loop so that (1) the terrain heightfield is a traced
argument rather than a compiled constant, (2) every episode starts from a
fresh random draw (`FreshResetVmap`), (3) the whole training state (optimizer
moments, normaliser, env states, PRNG key) is checkpointed and a resumed run
continues exactly where it stopped, and (4) the planner-in-the-loop mode can
reuse the same pieces.
"""

from __future__ import annotations

import functools
from typing import Any

import jax
import jax.numpy as jnp
import optax
from brax.training import gradients
from brax.training import networks as brax_networks
from brax.training.acme import running_statistics, specs
from brax.training.agents.ppo import losses as ppo_losses
from brax.training.agents.ppo import networks as ppo_networks
from brax.training.types import Transition
from flax import struct

from leas_jax.env import FreshResetVmap, LeasEnv
from leas_jax.env.field import Heightfield
from leas_jax.training.config import TrainConfig
from leas_jax.training.networks import make_networks


@struct.dataclass
class TrainState:
    """Everything a resumed run needs (batched over envs where it says [B]).

    Attributes:
        params: policy and value network parameters.
        optimizer_state: Adam moments.
        normalizer: observation running statistics.
        env_state: Brax state of the [B] envs.
        episode_return: [B] return of the running episode.
        episode_length: [B] length of the running episode.
        key: PRNG key.
        env_steps: int32[] transitions collected so far.
        iteration: int32[] iterations done so far.
    """

    params: ppo_losses.PPONetworkParams
    optimizer_state: Any
    normalizer: running_statistics.RunningStatisticsState
    env_state: Any
    episode_return: jax.Array
    episode_length: jax.Array
    key: jax.Array
    env_steps: jax.Array
    iteration: jax.Array


def make_optimizer(config: TrainConfig) -> optax.GradientTransformation:
    """Adam with global-norm clipping.

    Geometric mode: with `learning_rate_schedule == "linear"` the rate decays
    linearly to 0 over the run, counted in gradient steps (the number of
    iterations is fixed in advance). Planner mode keeps the rate in the
    optimizer state (`optax.inject_hyperparams`): how many iterations a
    budget of kept env steps takes depends on the contact generator, so the
    update sets the rate from the kept steps instead (`planner_learning_rate`).
    """
    clip = optax.clip_by_global_norm(config.max_grad_norm)
    if config.mode == "planner":
        return optax.chain(clip, optax.inject_hyperparams(optax.adam)(learning_rate=config.learning_rate))
    rate = config.learning_rate
    if config.learning_rate_schedule == "linear":
        updates = config.num_iterations * config.num_epochs * config.num_minibatches
        rate = optax.linear_schedule(config.learning_rate, 0.0, updates)
    return optax.chain(clip, optax.adam(rate))


def planner_learning_rate(config: TrainConfig, env_steps: jax.Array) -> jax.Array:
    """Planner mode: the learning rate after `env_steps` kept steps, float32[].

    "linear" decays from `learning_rate` to 0 at `num_timesteps` kept steps
    (Stable Baselines' PPO1 schedule, the paper's); "constant" keeps it.
    """
    if config.learning_rate_schedule == "constant":
        return jnp.float32(config.learning_rate)
    left = 1.0 - env_steps.astype(jnp.float32) / config.num_timesteps
    return config.learning_rate * jnp.clip(left, 0.0, 1.0)


def with_learning_rate(optimizer_state, rate: jax.Array):
    """The planner-mode optimizer state (see `make_optimizer`) with its learning rate set to `rate`."""
    clip_state, adam_state = optimizer_state
    hyperparams = {**adam_state.hyperparams, "learning_rate": jnp.asarray(rate, jnp.float32)}
    return clip_state, adam_state._replace(hyperparams=hyperparams)


def init_state(config: TrainConfig, field: Heightfield) -> TrainState:
    """Fresh training state for `config` on `field` (jitted inside)."""
    network = make_networks(config)
    optimizer = make_optimizer(config)
    key = jax.random.PRNGKey(config.seed)
    key, k_policy, k_value, k_env = jax.random.split(key, 4)
    params = ppo_losses.PPONetworkParams(
        policy=network.policy_network.init(k_policy), value=network.value_network.init(k_value)
    )
    normalizer = running_statistics.init_state(specs.Array((config.env.observation_size,), jnp.float32))

    @jax.jit
    def reset(field, keys):
        return FreshResetVmap(LeasEnv(field, config.env)).reset(keys)

    env_state = reset(field, jax.random.split(k_env, config.num_envs))
    return TrainState(
        params=params,
        optimizer_state=optimizer.init(params),
        normalizer=normalizer,
        env_state=env_state,
        episode_return=jnp.zeros(config.num_envs),
        episode_length=jnp.zeros(config.num_envs),
        key=key,
        env_steps=jnp.zeros((), jnp.int32),
        iteration=jnp.zeros((), jnp.int32),
    )


def _unroll(config: TrainConfig, network, state: TrainState, field: Heightfield, key):
    """Collect [B, T] transitions with the current stochastic policy; episode statistics.

    Returns (state, data, stats). Every field of `data` is [B, T, ...] except
    `next_observation`, [B, 1, 81]: the observation after the last step only,
    which is all Brax's PPO loss reads of it (the value bootstrap), so the
    other steps' next observations are neither stored nor shuffled.
    """
    env = FreshResetVmap(LeasEnv(field, config.env))
    policy = ppo_networks.make_inference_fn(network)((state.normalizer, state.params.policy))

    def step(carry, k):
        env_state, ep_return, ep_length = carry
        actions, policy_extras = policy(env_state.obs, k)
        nstate = env.step(env_state, actions)
        ep_return = ep_return + nstate.reward
        ep_length = ep_length + 1
        done = nstate.done
        stats = {
            "episodes": done.sum(),
            "episode_return_sum": (done * ep_return).sum(),
            "episode_length_sum": (done * ep_length).sum(),
            "invalid_episodes": (done * nstate.metrics["invalid"]).sum(),
            **{k_: v.mean() for k_, v in nstate.metrics.items() if k_.startswith("reward/")},
            "reward": nstate.reward.mean(),
            "curriculum_level": nstate.pipeline_state.level.mean(),  # 0 without a curriculum
        }
        transition = Transition(
            observation=env_state.obs,
            action=actions,
            reward=nstate.reward,
            discount=1 - done,
            next_observation=(),  # filled after the scan: the final observation only
            extras={
                "policy_extras": policy_extras,
                "state_extras": {"truncation": nstate.info["truncation"]},
            },
        )
        carry = (nstate, ep_return * (1 - done), ep_length * (1 - done))
        return carry, (transition, stats)

    carry = (state.env_state, state.episode_return, state.episode_length)
    (env_state, ep_return, ep_length), (data, stats) = jax.lax.scan(
        step, carry, jax.random.split(key, config.unroll_length)
    )
    data = jax.tree.map(lambda x: jnp.swapaxes(x, 0, 1), data)  # [B, T, ...]
    data = data._replace(next_observation=env_state.obs[:, None])  # [B, 1, 81]
    stats = {
        k: (
            v.sum()
            if k in ("episodes", "episode_return_sum", "episode_length_sum", "invalid_episodes")
            else v.mean()
        )
        for k, v in stats.items()
    }
    return state.replace(env_state=env_state, episode_return=ep_return, episode_length=ep_length), data, stats


def _sgd(config: TrainConfig, network, optimizer, state: TrainState, data: Transition, key):
    """`num_epochs` passes of `num_minibatches` PPO gradient steps over the batch."""
    loss_fn = functools.partial(
        ppo_losses.compute_ppo_loss,
        ppo_network=network,
        entropy_cost=config.entropy_cost,
        discounting=config.discounting,
        reward_scaling=config.reward_scaling,
        gae_lambda=config.gae_lambda,
        clipping_epsilon=config.clipping_epsilon,
        normalize_advantage=True,
        vf_coefficient=config.vf_coefficient,
    )
    update = gradients.gradient_update_fn(loss_fn, optimizer, pmap_axis_name=None, has_aux=True)
    params, opt_state, metrics = sgd_epochs(
        config, update, state.normalizer, state.params, state.optimizer_state, data, key
    )
    return state.replace(params=params, optimizer_state=opt_state), metrics


def sgd_epochs(config: TrainConfig, update, normalizer, params, optimizer_state, data, key):
    """`num_epochs` passes of `num_minibatches` gradient steps over one batch (geometric and
    planner PPO alike).

    Each epoch shuffles the batch's leading axis (`num_envs` episodes) and splits it into
    `num_minibatches` equal parts, one gradient step each.

    Args:
        config: num_envs, num_epochs, num_minibatches.
        update: a Brax `gradients.gradient_update_fn` of the loss, called as
            `update(params, normalizer, minibatch, key, optimizer_state=...)`.
        normalizer: observation statistics the loss normalises with (fixed here).
        params, optimizer_state: the network's, before the epochs.
        data: pytree of [num_envs, T, ...] arrays.
        key: PRNG key.

    Returns:
        (params, optimizer_state, {"loss/<name>": mean over every step}).
    """

    def minibatch(carry, inputs):
        params, opt_state = carry
        part, k = inputs
        (_, metrics), params, opt_state = update(params, normalizer, part, k, optimizer_state=opt_state)
        return (params, opt_state), metrics

    def epoch(carry, k):
        k_perm, k_mb = jax.random.split(k)
        perm = jax.random.permutation(k_perm, config.num_envs)
        parts = jax.tree.map(lambda x: x[perm].reshape((config.num_minibatches, -1) + x.shape[1:]), data)
        return jax.lax.scan(minibatch, carry, (parts, jax.random.split(k_mb, config.num_minibatches)))

    (params, optimizer_state), metrics = jax.lax.scan(
        epoch, (params, optimizer_state), jax.random.split(key, config.num_epochs)
    )
    return params, optimizer_state, {f"loss/{k}": v.mean() for k, v in metrics.items()}


def flat_batch_networks(network: ppo_networks.PPONetworks) -> ppo_networks.PPONetworks:
    """`network` with its policy and value applied to a 2-D batch.

    Brax's PPO loss applies the networks to [T, B, 81] observations. The
    weight gradients of a 3-D input reach XLA:CPU as products with a
    transposed [64, T*B] copy, about three times slower than the [T*B, 64]
    products of a 2-D input; the loss's gradient took 40 % less time with the
    batch flattened. Same parameters and results (up to float rounding).
    """

    def flat(ffn: brax_networks.FeedForwardNetwork) -> brax_networks.FeedForwardNetwork:
        def apply(normalizer, params, obs):
            """obs: [..., 81] -> [..., outputs], through a [prod(...), 81] batch."""
            out = ffn.apply(normalizer, params, obs.reshape((-1, obs.shape[-1])))
            return out.reshape(obs.shape[:-1] + out.shape[1:])

        return brax_networks.FeedForwardNetwork(init=ffn.init, apply=apply)

    return network.replace(
        policy_network=flat(network.policy_network), value_network=flat(network.value_network)
    )


def make_train_call(config: TrainConfig):
    """Jitted `(state, field) -> (state, metrics)` running `iterations_per_call` PPO iterations.

    Metrics: per-call means of the per-iteration statistics, plus sums of the
    episode counters (episodes, episode_return_sum, ...).
    """
    network = flat_batch_networks(make_networks(config))
    optimizer = make_optimizer(config)

    def iteration(state: TrainState, field: Heightfield):
        key, k_unroll, k_sgd = jax.random.split(state.key, 3)
        state, data, stats = _unroll(config, network, state, field, k_unroll)
        state = state.replace(normalizer=running_statistics.update(state.normalizer, data.observation))
        state, losses = _sgd(config, network, optimizer, state, data, k_sgd)
        state = state.replace(
            key=key, env_steps=state.env_steps + config.batch_size, iteration=state.iteration + 1
        )
        return state, {**stats, **losses}

    def call(state: TrainState, field: Heightfield):
        state, metrics = jax.lax.scan(
            lambda s, _: iteration(s, field), state, None, length=config.iterations_per_call
        )
        summed = ("episodes", "episode_return_sum", "episode_length_sum", "invalid_episodes")
        return state, {k: (v.sum() if k in summed else v.mean()) for k, v in metrics.items()}

    return jax.jit(call, donate_argnums=(0,))
