"""Policy and value networks (Brax PPO networks, paper §IV sizes) and the deterministic policy."""

from __future__ import annotations

import flax.linen as linen
import jax
from brax.training.acme import running_statistics
from brax.training.agents.ppo import networks as ppo_networks

from leas_jax.training.config import TrainConfig


def make_networks(config: TrainConfig) -> ppo_networks.PPONetworks:
    """2 x 64 tanh policy and value networks with observation normalisation.

    The policy is a tanh-squashed Gaussian, so actions stay in [-1, 1].
    """
    preprocess = running_statistics.normalize if config.normalize_observations else (lambda x, y: x)
    return ppo_networks.make_ppo_networks(
        observation_size=config.env.observation_size,
        action_size=4,
        preprocess_observations_fn=preprocess,
        policy_hidden_layer_sizes=tuple(config.hidden_sizes),
        value_hidden_layer_sizes=tuple(config.hidden_sizes),
        activation=linen.tanh,
    )


def deterministic_policy_fn(config: TrainConfig, normalizer_params, policy_params):
    """obs [..., 81] -> action [..., 4] in [-1, 1], the mode of the policy (pure, jittable)."""
    network = make_networks(config)
    make_policy = ppo_networks.make_inference_fn(network)
    policy = make_policy((normalizer_params, policy_params), deterministic=True)

    def act(obs: jax.Array) -> jax.Array:
        return policy(obs, None)[0]

    return act
