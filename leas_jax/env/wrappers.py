"""Batched training wrapper with fresh random resets.

Brax's `AutoResetWrapper` restores the *first* state of each env after an
episode ends, so every env would replay the same start. LeaS needs a fresh
random start per episode (docs/design.md §5): `FreshResetVmap` draws a new start
with the key carried in the state whenever an episode ends.

The wrapper knows `LeasEnv`'s parts: it selects between the stepped and the
fresh root state first and computes one observation afterwards, which halves
the heightmap lookups of a step that also prepares a reset.

Only the envs whose episode ended draw a start. A vmapped `random_root` of
every env followed by a select (the plain way) made the draws a third of an
unroll's time although a few percent of the envs end per step; instead the
finished envs are gathered into a short batch (`reset_capacities`), drawn,
and spread back, with a `lax.switch` picking the smallest capacity that holds
this step's count (the whole batch when many end at once). Each draw uses the
same key as the plain way, so the starts are bit for bit the same.
"""

import jax
import jax.numpy as jnp
from brax.envs.base import State, Wrapper


def reset_capacities(batch: int) -> tuple:
    """Sizes of the gathered reset batches tried in turn for `batch` envs, the last = `batch`."""
    return tuple(k for k in (batch // 64, batch // 16, batch // 4) if 0 < k < batch) + (batch,)


def fresh_roots(env, root, done: jax.Array):
    """`root` with every finished env's root replaced by a fresh random start.

    Args:
        env: the unwrapped `LeasEnv`.
        root: batched `RootState`, [B] leading axis.
        done: bool[B], True where the episode ended.

    Returns:
        Batched `RootState` [B]: where done, `env.next_root(root)` (`random_root` with its
        key, advanced for the next reset, on a curriculum arena at its next row); elsewhere
        `root` unchanged.
    """
    batch = done.shape[0]
    count = done.sum()

    def select(fresh):
        return jax.tree.map(
            lambda new, old: jnp.where(done.reshape(done.shape + (1,) * (old.ndim - 1)), new, old),
            fresh,
            root,
        )

    def gathered(capacity):
        def branch(root):
            if capacity == batch:
                return select(jax.vmap(env.next_root)(root))
            idx = jnp.nonzero(done, size=capacity, fill_value=0)[0]  # [capacity] finished envs first
            drawn = jax.vmap(env.next_root)(jax.tree.map(lambda x: x[idx], root))  # [capacity]
            slot = jnp.clip(jnp.cumsum(done) - 1, 0, capacity - 1)  # [B] rank of each finished env
            return select(jax.tree.map(lambda x: x[slot], drawn))

        return branch

    capacities = reset_capacities(batch)
    if len(capacities) == 1:
        return gathered(batch)(root)
    which = sum((count > k).astype(jnp.int32) for k in capacities[:-1])  # the first capacity >= count
    return jax.lax.switch(which, [gathered(k) for k in capacities], root)


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
        """state: batched [B]; action: [B, 4]."""
        env = self.env.unwrapped
        root, reward_value, done, metrics, truncation = jax.vmap(env.transition)(state.pipeline_state, action)
        root = fresh_roots(env, root, done > 0)
        return state.replace(
            pipeline_state=root,
            obs=jax.vmap(env.observe)(root),
            reward=reward_value,
            done=done,
            metrics=metrics,
            info={**state.info, "truncation": truncation},
        )
