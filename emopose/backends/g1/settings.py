"""G1Backend settings: defaults, per-joint broadcasting and validation at the edge.

The YAML (conf/backend/g1.yaml) passes plain lists; everything is checked once here with errors
that name the field, so the control loop can trust the arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from emopose.robot import g1_spec
from emopose.robot.g1_spec import NUM_JOINTS


def per_joint(name: str, value: object, n: int = NUM_JOINTS) -> np.ndarray:
    """A scalar (same for every joint) or exactly n finite numbers."""
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise ValueError(
            f"g1 backend: {name} must be a number or a list of {n} numbers, got shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"g1 backend: {name} contains a non-finite value: {arr.tolist()}")
    return arr


def _positive(name: str, value: float, allow_zero: bool = False) -> float:
    value = float(value)
    if not (value > 0 or (allow_zero and value == 0)) or not np.isfinite(value):
        raise ValueError(
            f"g1 backend: {name} must be {'>= 0' if allow_zero else '> 0'}, got {value}"
        )
    return value


@dataclass(frozen=True)
class G1Settings:
    domain_id: int
    network_interface: str | None
    lowstate_timeout_s: float
    lowstate_loss_s: float
    deadman_s: float
    kp: np.ndarray
    kd: np.ndarray
    weight_ramp_up_s: float
    weight_ramp_down_s: float
    release_blend_s: float
    neutral_pose: np.ndarray | None  # None: go back to the pose measured at connect()
    lower: np.ndarray
    upper: np.ndarray
    command_waist: bool
    waist_kp: float
    waist_kd: float
    velocity_feedforward: bool = False  # LowCmd dq: the stream's finite difference (else 0)
    gravity_compensation: bool = False  # LowCmd tau: the model's gravity torque at the target (else 0)

    @classmethod
    def build(cls, **kw: object) -> G1Settings:
        # No limits in the config: the G1's hardware ranges.
        lower = per_joint("lower", g1_spec.LOWER if kw["lower"] is None else kw["lower"])
        upper = per_joint("upper", g1_spec.UPPER if kw["upper"] is None else kw["upper"])
        if np.any(lower >= upper):
            bad = np.flatnonzero(lower >= upper).tolist()
            raise ValueError(
                f"g1 backend: lower must be < upper for every joint; violated at indices {bad}"
            )
        neutral = (
            None if kw["neutral_pose"] is None else per_joint("neutral_pose", kw["neutral_pose"])
        )
        if neutral is not None and np.any((neutral < lower) | (neutral > upper)):
            bad = np.flatnonzero((neutral < lower) | (neutral > upper)).tolist()
            raise ValueError(
                f"g1 backend: neutral_pose lies outside [lower, upper] at indices {bad}"
            )
        domain_id = int(kw["domain_id"])
        if not 0 <= domain_id <= 232:  # Cyclone's default port mapping allows 0..232
            raise ValueError(f"g1 backend: domain_id must be in 0..232, got {domain_id}")
        iface = kw["network_interface"]
        return cls(
            domain_id=domain_id,
            network_interface=str(iface) if iface else None,
            lowstate_timeout_s=_positive("lowstate_timeout_s", kw["lowstate_timeout_s"]),
            lowstate_loss_s=_positive("lowstate_loss_ms", kw["lowstate_loss_ms"]) / 1000.0,
            deadman_s=_positive("deadman_ms", kw["deadman_ms"]) / 1000.0,
            kp=per_joint("kp", kw["kp"]),
            kd=per_joint("kd", kw["kd"]),
            weight_ramp_up_s=_positive("weight_ramp_up_s", kw["weight_ramp_up_s"]),
            weight_ramp_down_s=_positive("weight_ramp_down_s", kw["weight_ramp_down_s"]),
            release_blend_s=_positive("release_blend_s", kw["release_blend_s"], allow_zero=True),
            neutral_pose=neutral,
            lower=lower,
            upper=upper,
            command_waist=bool(kw["command_waist"]),
            waist_kp=_positive("waist_kp", kw["waist_kp"], allow_zero=True),
            waist_kd=_positive("waist_kd", kw["waist_kd"], allow_zero=True),
            velocity_feedforward=bool(kw.get("velocity_feedforward", False)),
            gravity_compensation=bool(kw.get("gravity_compensation", False)),
        )
