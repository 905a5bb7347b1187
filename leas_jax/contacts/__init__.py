"""Contact generator (host, Pinocchio Talos): guide path -> quasi-static contact plan.

Host-only (Pinocchio, coal, hpp-centroidal-dynamics), nothing here can be jitted.
DESIGN §6 fixes the contract; docs/architecture.md the interface:

    from leas_jax.contacts import (ContactGenerator, ContactPlan, GeneratorConfig,
                                   plan_contacts, verify, validate_paths)
    plan = plan_contacts(terrain, guide, timestep)   # guide [T, 4] (x, y, z, yaw)
    report = verify(plan)                            # .ok, .failures

Submodules: model (Talos, constants, quaternion conversion), ik (analytic leg IK),
equilibrium (hpp-centroidal-dynamics LP and an independent SciPy LP), database
(per-leg sample database), collision (coal), surfaces (support faces), generator,
plan (ContactPlan file format), verify, pool (worker pool), commands (CLI), viewer.
Attributes are imported lazily so that `import leas_jax.contacts` stays cheap.
"""

import importlib

# Eager: the function `verify` must shadow the submodule of the same name, which
# becomes a package attribute as soon as it is imported (verify.py imports only NumPy
# at module level, so this stays cheap).
from leas_jax.contacts.verify import VerificationReport, verify

_LAZY = {
    "ContactGenerator": "leas_jax.contacts.generator",
    "GeneratorConfig": "leas_jax.contacts.generator",
    "plan_contacts": "leas_jax.contacts.generator",
    "ContactPlan": "leas_jax.contacts.plan",
    "PlanError": "leas_jax.contacts.plan",
    "validate_paths": "leas_jax.contacts.pool",
    "PathResult": "leas_jax.contacts.pool",
    "ValidationPool": "leas_jax.contacts.pool",
    "NOMINAL_ROOT_HEIGHT": "leas_jax.contacts.model",
    "load_talos": "leas_jax.contacts.model",
}

__all__ = sorted([*_LAZY, "VerificationReport", "verify"])


def __getattr__(name):
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'leas_jax.contacts' has no attribute {name!r}")
