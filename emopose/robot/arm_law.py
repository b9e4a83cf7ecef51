"""The arm motors' control law: one definition for what the G1 is sent and what MuJoCo applies.

The G1's motors run tau = kp (q* - q) + kd (dq* - dq) + tau_ff; EmoPose's G1 backend sends kp, kd, the
position q* and, as the law says, dq* (the stream's velocity) and tau_ff (the model's gravity torque).
`robot` (conf/arm_law/robot.yaml, the default) sends both, so the arm neither sags nor trails;
`robot_plain` is Unitree's arm example (dq* = tau_ff = 0) and `robot_gravity` the gravity torque alone.
MuJoCo applies the configured law, so the simulator tracks like the robot. `mjcf` keeps the model's own
stiffer servos with gravity compensation and a velocity feed-forward, as the simulator ran before; it is
optimistic and kept for comparison.
`tracking_lag_s` is how long the joints trail the command stream under this law (measured with
sync_eval on MuJoCo); the timeline plans that much ahead on backends with actuators.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from emopose.robot.g1_spec import NUM_JOINTS


@dataclass(frozen=True)
class ArmLaw:
    name: str
    kp: float | list[float] | None  # None: the MJCF's own servo gains (simulator only)
    kd: float | list[float] | None
    velocity_feedforward: bool = False  # dq* = the stream's finite difference (else 0)
    gravity_compensation: bool = False  # tau_ff = the model's gravity torque (else 0)
    tracking_lag_s: float = 0.0

    def __post_init__(self) -> None:
        if (self.kp is None) != (self.kd is None):
            raise ValueError(f"arm_law {self.name}: give both kp and kd, or neither (the MJCF's servos)")
        for label, gains in (("kp", self.kp), ("kd", self.kd)):
            if gains is not None and (np.any(self.gains(gains) < 0)
                                      or self.gains(gains).shape != (NUM_JOINTS,)):
                raise ValueError(f"arm_law {self.name}: {label} must be >= 0, "
                                 f"a scalar or {NUM_JOINTS} values")
        if not 0.0 <= self.tracking_lag_s < 0.5:
            raise ValueError(f"arm_law {self.name}: tracking_lag_s must be in [0, 0.5) s, "
                             f"got {self.tracking_lag_s}")

    @staticmethod
    def gains(values: float | list[float]) -> np.ndarray:
        return np.broadcast_to(np.asarray(values, dtype=float), (NUM_JOINTS,)).copy()

    @property
    def model_servos(self) -> bool:
        return self.kp is None
