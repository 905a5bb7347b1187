"""Contact generator (host, Pinocchio Talos): guide path -> quasi-static contact plan.

Host-only (Pinocchio, coal, hpp-centroidal-dynamics), nothing here can be jitted.
docs/design.md §6 fixes the contract; docs/architecture.md the interface:

    from leas_jax.contacts import (ContactGenerator, ContactPlan, GeneratorConfig,
                                   plan_contacts, verify, validate_paths)
    plan = plan_contacts(terrain, guide, timestep)   # guide [T, 4] (x, y, z, yaw)
    report = verify(plan)                            # .ok, .failures

Sub-packages, in the order a guide meets them:
robot (Talos model, IK, collision, equilibrium, sample database), planner (support
surfaces, the generator), validation (worker pool, Ray backend). Beside them: plan
(ContactPlan file format), verify, metrics (a plan's coverage and success on its guide),
viewer, commands (CLI).
Attributes are imported lazily so that `import leas_jax.contacts` stays cheap.
"""

# Eager: the function `verify` must shadow the submodule of the same name, which
# becomes a package attribute as soon as it is imported (verify.py imports only NumPy
# at module level, so this stays cheap).
from leas_jax.contacts.verify import VerificationReport, verify  # noqa: F401 (re-exported in __all__)
from leas_jax.lazy import lazy_getattr

_LAZY = {
    "ContactGenerator": "leas_jax.contacts.planner.generator",
    "GeneratorConfig": "leas_jax.contacts.planner.config",
    "plan_contacts": "leas_jax.contacts.planner.generator",
    "ContactPlan": "leas_jax.contacts.plan",
    "PlanError": "leas_jax.contacts.plan",
    "validate_paths": "leas_jax.contacts.validation.pool",
    "PathResult": "leas_jax.contacts.validation.pool",
    "ValidationPool": "leas_jax.contacts.validation.pool",
    "NOMINAL_ROOT_HEIGHT": "leas_jax.contacts.robot.model",
    "load_talos": "leas_jax.contacts.robot.model",
}

__all__ = sorted([*_LAZY, "VerificationReport", "verify"])


__getattr__ = lazy_getattr(__name__, globals(), _LAZY)
