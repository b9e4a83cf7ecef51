"""LocoClient: walk the G1's base through Unitree's loco RPC (rt/api/sport/request|response).

The request/response machinery is rpc.ServiceClient's (shared with the voice client). Velocities
are clamped to the configured limits (vx <= 0.3 m/s indoors by default) and the clamp is logged;
a timeout and a non-zero status both raise, naming the api id (and the code).
"""

from __future__ import annotations

import json
import logging
import math

from emopose.backends.g1.constants import (
    LOCO_API_GET_FSM_ID,
    LOCO_API_SET_FSM_ID,
    LOCO_API_SET_VELOCITY,
    LOCO_SERVICE,
)
from emopose.backends.g1.errors import LocoError, LocoTimeoutError
from emopose.backends.g1.rpc import ServiceClient

log = logging.getLogger(__name__)


def _clamp(name: str, value: float, limit: float) -> float:
    if not math.isfinite(value):
        raise ValueError(f"loco: {name} must be finite, got {value}")
    clamped = min(max(value, -limit), limit)
    if clamped != value:
        log.warning("loco: %s %.3f clamped to %.3f (limit %.3f)", name, value, clamped, limit)
    return clamped


class LocoClient(ServiceClient):
    label, error_type, timeout_type = "loco", LocoError, LocoTimeoutError

    def __init__(
        self,
        domain_id: int = 0,
        network_interface: str | None = None,
        service: str = LOCO_SERVICE,
        timeout_s: float = 1.0,
        max_vx: float = 0.3,
        max_vy: float = 0.2,
        max_omega: float = 0.5,
        max_duration_s: float = 10.0,
    ) -> None:
        super().__init__(domain_id, network_interface, service, timeout_s)
        self.max_vx, self.max_vy, self.max_omega, self.max_duration_s = (
            max_vx,
            max_vy,
            max_omega,
            max_duration_s,
        )

    # ------------------------------------------------------------------ the APIs
    def get_fsm_id(self) -> int:
        return int(json.loads(self.call(LOCO_API_GET_FSM_ID, {}))["data"])

    def set_fsm_id(self, fsm_id: int) -> None:
        self.call(LOCO_API_SET_FSM_ID, {"data": int(fsm_id)})

    def set_velocity(
        self, vx: float, vy: float, omega: float, duration: float = 1.0
    ) -> tuple[float, ...]:
        """Walk at (vx, vy) m/s and omega rad/s for duration s; returns what was actually sent."""
        vx = _clamp("vx", float(vx), self.max_vx)
        vy = _clamp("vy", float(vy), self.max_vy)
        omega = _clamp("omega", float(omega), self.max_omega)
        duration = _clamp("duration", float(duration), self.max_duration_s)
        if duration < 0:
            raise ValueError(f"loco: duration must be >= 0, got {duration}")
        self.call(LOCO_API_SET_VELOCITY, {"velocity": [vx, vy, omega], "duration": duration})
        return vx, vy, omega, duration

    def stop(self) -> None:
        self.set_velocity(0.0, 0.0, 0.0, 0.0)
