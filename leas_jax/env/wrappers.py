"""Batched training wrapper with fresh random resets.

Brax's `AutoResetWrapper` restores the *first* state of each env after an
episode ends, so every env would replay the same start. LeaS needs a fresh
random start per episode (DESIGN.md §5): `FreshResetVmap` draws a new start
with the key carried in the state whenever an episode ends.

The wrapper knows `LeasEnv`'s parts: it selects between the stepped and the
fresh root state first and computes one observation afterwards, which halves
the heightmap lookups of a step that also prepares a reset.
"""

import jax
import jax.numpy as jnp
from brax.envs.base import State, Wrapper


class FreshResetVmap(Wrapper):
    """Vectorises an env over a batch and resets finished envs with a new random draw.

    The returned state of a finished env holds the reward, done flag,
    truncation and metrics of the final transition, and the observation and
    root state of the new episode (Brax's convention for auto-reset).
    """

    def reset(self, rng: jax.Array) -> State:
        """rng: [B, 2] keys -> batched state."""
        return jax.vmap(self.env.reset)(rng)

    def step(self, state: State, action: jax.Array) -> State:
        """state: batched; action: [B, 4]."""
        env = self.env.unwrapped

        def one(s, a):
            root, reward_value, done, metrics, truncation = env.transition(s.pipeline_state, a)
            fresh = env.random_root(root.rng)
            root = jax.tree.map(lambda new, old: jnp.where(done > 0, new, old), fresh, root)
            return s.replace(pipeline_state=root, obs=env.observe(root), reward=reward_value, done=done,
                             metrics=metrics, info={**s.info, "truncation": truncation})
        return jax.vmap(one)(state, action)
