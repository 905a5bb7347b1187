"""The environment's termination condition, selected by `EnvConfig.condition`. Pure, jittable.

"cylinders": the paper's reachability condition (`reachability.valid` with
`EnvConfig.reachability`); "learned": the network of `learned_feasibility`, trained on the
contact generator's walking verdicts, whose parameters the heightfield carries
(`Heightfield.condition`, loaded by `heightfield_from_terrain` from `EnvConfig.learned_weights`);
"walkability": the walkability model of rough ground (`leas feasibility walkability`, fitted on
procedural terrain families): the plausible cylinders (`reachability.relaxed_reachability`:
trunk, leg reach, hands, solid ground) and the model's network, as navigate's lattice judges
its confident poses with the model.
"""

import jax

from leas_jax.env import learned_feasibility, reachability
from leas_jax.env.config import CLEARANCE_CONDITIONS, EnvConfig
from leas_jax.env.field import Heightfield

CONDITIONS = ("cylinders", "learned", "walkability")


def valid(field: Heightfield, pose: jax.Array, config: EnvConfig) -> jax.Array:
    """True when the pose passes the selected condition. pose: [4] (x, y, z, yaw), world -> bool[]."""
    if config.condition in ("learned", "walkability"):
        if not field.condition:
            raise ValueError(
                f"EnvConfig.condition is {config.condition!r} but the heightfield has no learned condition: "
                "build it with the same EnvConfig"
            )
        accepted = learned_feasibility.valid(field.condition, field, pose, config.reachability)
        if config.condition == "learned":
            return accepted
        return accepted & reachability.valid(
            field, pose, reachability.relaxed_reachability(config.reachability)
        )
    if config.condition != "cylinders":
        raise ValueError(
            f"EnvConfig.condition must be one of {', '.join(CONDITIONS)}, got {config.condition!r}"
        )
    return reachability.valid(field, pose, config.reachability)


def clearance_shortfall(field: Heightfield, pose: jax.Array, margin: float, config: EnvConfig) -> jax.Array:
    """`reachability.clearance_shortfall` under `config.clearance_condition`: the fraction of the
    six poses shifted by `margin` (m) along the root frame's axes that fail the selected
    condition ("condition": the env's own, "cylinders": its cylinders). pose: [4] -> float[]."""
    if config.clearance_condition == "cylinders":
        return reachability.clearance_shortfall(field, pose, margin, config.reachability)
    if config.clearance_condition != "condition":
        raise ValueError(
            f"EnvConfig.clearance_condition must be one of {', '.join(CLEARANCE_CONDITIONS)}, "
            f"got {config.clearance_condition!r}"
        )
    probes = reachability.shifted_poses(pose, margin)
    return 1.0 - jax.vmap(lambda probe: valid(field, probe, config))(probes).mean()
