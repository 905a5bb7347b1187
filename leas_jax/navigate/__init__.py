"""Navigate: a verified whole-body contact plan from a start to a goal on any terrain.

    from leas_jax.navigate import navigate
    result = navigate(policy, terrain, start=(2.0, 4.0, 0.0), goal=(9.5, 5.0))
    result.plan.save("plan.npz")              # passes `leas verify`

Modules: lattice (the root's confident and doubtful poses over positions x headings, with a
step model, jitted), search (A* over the lattice), loop (closed loop with the LeaS policy and the contact generator),
result (NavigationResult), commands (`leas navigate`), report (a navigate query as a
report section). Attributes are imported lazily so
that `import leas_jax.navigate` (and the CLI's parser) loads no JAX.
"""

from leas_jax.lazy import lazy_getattr

_LAZY = {
    "navigate": "leas_jax.navigate.loop",
    "Navigator": "leas_jax.navigate.loop",
    "NavigateConfig": "leas_jax.navigate.loop",
    "Query": "leas_jax.navigate.loop",
    "NavigationResult": "leas_jax.navigate.result",
    "LatticeConfig": "leas_jax.navigate.lattice",
    "SearchConfig": "leas_jax.navigate.search",
}

__all__ = sorted(_LAZY)

__getattr__ = lazy_getattr(__name__, globals(), _LAZY)
