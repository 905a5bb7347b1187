"""A contact plan made into a motion and run in MuJoCo, judged in one record (host-only).

`execute_plan(plan)` is what `leas navigate --motion` and `leas evaluate --motion` do with
a reached plan: `make_motion` (a `MotionError` is kept as the reason, naming the phase),
then `simulate` on the plan's own terrain. `Execution.line()` is the one-line verdict and
`Execution.summary()` the figures stored in results files.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

from leas_jax.motion.config import MotionConfig, SimulationConfig


@dataclass(frozen=True)
class Execution:
    """What became of one contact plan.

    Attributes:
        motion: the `Motion` (None when it cannot be made).
        rollout: the `simulate` result (None when there is no motion).
        error: `MotionError`'s message (the phase and why), None when the motion was made.
        make_seconds: wall-clock time of `make_motion`, s.
        make_cpu_seconds: CPU time of this process in `make_motion`, s (NaN: not measured).
    """

    motion: object | None
    rollout: object | None
    error: str | None
    make_seconds: float
    make_cpu_seconds: float = math.nan

    @property
    def success(self) -> bool:
        """The motion was made and its simulation passes every phase (`Rollout.success`)."""
        return self.rollout is not None and bool(self.rollout.success)

    @property
    def fallen(self) -> bool | None:
        """The robot fell in simulation (None: no motion, nothing simulated)."""
        return None if self.rollout is None else bool(self.rollout.fallen)

    def summary(self) -> dict:
        """Figures of the execution, JSON-ready (NaN where undefined; floats rounded).

        Keys: made, error, success, fallen, fall_time_s, phases, phases_reached,
        max_landing_position_m (sole position error at landing, world), max_landing_angle_deg,
        max_slip_m (horizontal, supporting sole), max_torque_ratio (commanded / effort limit),
        torque_ratio_by_group (the same per joint group of `simulate.JOINT_GROUPS`),
        duration_s (motion), make_seconds, make_cpu_seconds, simulate_seconds,
        simulate_cpu_seconds, message.
        """
        out = {
            "made": self.motion is not None,
            "error": self.error,
            "make_seconds": round(self.make_seconds, 3),
            "make_cpu_seconds": _rounded(self.make_cpu_seconds, 3),
        }
        if self.rollout is None:
            return out | {"success": False, "fallen": None}
        figures = self.rollout.summary()
        out |= {
            "success": bool(self.rollout.success),
            "fallen": bool(self.rollout.fallen),
            "fall_time_s": _rounded(self.rollout.fall_time),
            "phases": figures["phases"],
            "phases_reached": figures["phases_reached"],
            "max_landing_position_m": _rounded(figures["max_landing_position_m"]),
            "max_landing_angle_deg": _rounded(figures["max_landing_angle_deg"]),
            "max_slip_m": _rounded(figures["max_slip_m"]),
            "max_torque_ratio": _rounded(figures["max_torque_ratio"]),
            "torque_ratio_by_group": {
                name: round(value, 4) for name, value in self.rollout.group_torque_ratios().items()
            },
            "duration_s": round(self.motion.duration, 3),
            "simulate_seconds": round(self.rollout.seconds, 3),
            "simulate_cpu_seconds": _rounded(self.rollout.cpu_seconds, 3),
            "message": self.rollout.message,
        }
        return out

    def line(self) -> str:
        """One line: why there is no motion, or the simulation's verdict and worst figures."""
        if self.motion is None:
            return f"no motion: {self.error}"
        s = self.summary()
        verdict = "executed" if s["success"] else ("FELL" if s["fallen"] else "FAILED")
        fell = f" at {s['fall_time_s']:.2f} s" if s["fallen"] else ""
        return (
            f"{verdict}{fell}: {s['phases_reached']}/{s['phases']} phases of {s['duration_s']:.1f} s, "
            f"fallen {'yes' if s['fallen'] else 'no'}, max landing error "
            f"{_cm(s['max_landing_position_m'])} / {_deg(s['max_landing_angle_deg'])}, "
            f"max slip {_cm(s['max_slip_m'])}, max torque ratio {s['max_torque_ratio']:.2f} "
            f"(made in {self.make_seconds:.1f} s, simulated in {s['simulate_seconds']:.1f} s)"
            + ("" if s["success"] else f"; {s['message']}")
        )


def _rounded(value: float, digits: int = 6) -> float | None:
    """`value` rounded, None when NaN (JSON has no NaN)."""
    value = float(value)
    return None if math.isnan(value) else round(value, digits)


def _cm(metres: float | None) -> str:
    return "-" if metres is None else f"{metres * 100:.2f} cm"


def _deg(degrees: float | None) -> str:
    return "-" if degrees is None else f"{degrees:.2f} deg"


def execute_plan(
    plan,
    motion_config: MotionConfig = MotionConfig(),
    simulation_config: SimulationConfig = SimulationConfig(),
) -> Execution:
    """Make the whole-body motion of a contact plan and simulate it on the plan's terrain.

    Args:
        plan: a `ContactPlan` (world frame; at least 2 postures).
        motion_config: `make_motion`'s settings.
        simulation_config: `simulate`'s settings.

    Returns:
        Execution: motion and rollout, or the `MotionError` message when no motion can be made.
    """
    from leas_jax.motion.motion import MotionError, make_motion
    from leas_jax.motion.simulate import simulate

    started, cpu_started = time.perf_counter(), time.process_time()
    try:
        motion = make_motion(plan, motion_config)
    except MotionError as exc:
        return Execution(
            None, None, str(exc), time.perf_counter() - started, time.process_time() - cpu_started
        )
    seconds, cpu_seconds = time.perf_counter() - started, time.process_time() - cpu_started
    return Execution(motion, simulate(motion, config=simulation_config), None, seconds, cpu_seconds)
