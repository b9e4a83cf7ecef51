"""The fake robot's locomotion service: answers Unitree RPCs on rt/api/<service>/request.

Implements the three APIs the tour uses: 7001 get FSM id, 7101 set FSM id, 7105 set velocity
({"velocity": [vx, vy, omega], "duration": s}), and integrates base odometry (x, y, yaw in the
odometry frame) from the commanded velocity for the commanded duration. Unknown APIs answer
3203 (not implemented), malformed parameters 3204, as Unitree's server does.
"""

from __future__ import annotations

import json
import math
import threading
from collections.abc import Callable

from emopose.backends.g1.api_types import Request_, Response_, ResponseHeader_, ResponseStatus_
from emopose.backends.g1.constants import (
    LOCO_API_GET_FSM_ID,
    LOCO_API_SET_FSM_ID,
    LOCO_API_SET_VELOCITY,
    RPC_ERR_SERVER_API_NOT_IMPL,
    RPC_ERR_SERVER_API_PARAMETER,
    RPC_OK,
    request_topic,
    response_topic,
)
from emopose.backends.g1.dds import DdsSession
from emopose.execution.worker import Worker


class FakeLoco:
    def __init__(
        self,
        session: DdsSession,
        service: str,
        log: Callable[[dict], None],
        forced_codes: dict[int, int] | None = None,
    ) -> None:
        self._requests = session.reader(request_topic(service), Request_)
        self._responses = session.writer(response_topic(service), Response_)
        self._log = log
        self._forced = dict(forced_codes or {})
        self._lock = threading.Lock()
        self.fsm_id = 801  # what a standing G1 in its walking controller reports (any int will do)
        self.odom = [0.0, 0.0, 0.0]
        self._velocity = (0.0, 0.0, 0.0)
        self._remaining_s = 0.0
        self._worker = Worker("fake-loco", self._serve, join_timeout_s=1.0)

    def start(self) -> None:
        self._worker.start()

    def stop(self) -> None:
        self._worker.stop()

    def step(self, dt: float) -> None:
        """Integrate odometry over dt (called from the robot's state loop)."""
        with self._lock:
            if self._remaining_s <= 0:
                return
            dt = min(dt, self._remaining_s)
            self._remaining_s -= dt
            vx, vy, omega = self._velocity
            x, y, yaw = self.odom
            self.odom = [
                x + (vx * math.cos(yaw) - vy * math.sin(yaw)) * dt,
                y + (vx * math.sin(yaw) + vy * math.cos(yaw)) * dt,
                yaw + omega * dt,
            ]

    def _serve(self, stop: threading.Event) -> None:
        answer_requests(self._requests, stop, self._answer)

    def _answer(self, request: Request_) -> None:
        identity = request.header.identity
        code, data = self._handle(int(identity.api_id), request.parameter)
        with self._lock:
            odom = list(self.odom)
        self._log(
            {
                "kind": "loco",
                "api_id": int(identity.api_id),
                "parameter": request.parameter,
                "code": code,
                "fsm_id": self.fsm_id,
                "odom": odom,
            }
        )
        if request.header.policy.noreply:
            return
        header = ResponseHeader_(identity=identity, status=ResponseStatus_(code=code))
        self._responses.write_typed(Response_(header=header, data=data, binary=[]))

    def _handle(self, api_id: int, parameter: str) -> tuple[int, str]:
        if api_id in self._forced:
            return self._forced[api_id], ""
        try:
            p = json.loads(parameter) if parameter else {}
            if api_id == LOCO_API_GET_FSM_ID:
                return RPC_OK, json.dumps({"data": self.fsm_id})
            if api_id == LOCO_API_SET_FSM_ID:
                self.fsm_id = int(p["data"])
                return RPC_OK, ""
            if api_id == LOCO_API_SET_VELOCITY:
                vx, vy, omega = (float(v) for v in p["velocity"])
                duration = float(p.get("duration", 1.0))
                if not all(map(math.isfinite, (vx, vy, omega, duration))) or duration < 0:
                    raise ValueError("non-finite velocity or negative duration")
                with self._lock:
                    self._velocity, self._remaining_s = (vx, vy, omega), duration
                return RPC_OK, ""
        except (KeyError, TypeError, ValueError):
            return RPC_ERR_SERVER_API_PARAMETER, ""
        return RPC_ERR_SERVER_API_NOT_IMPL, ""


def answer_requests(requests, stop: threading.Event, answer: Callable[[Request_], None]) -> None:
    """A fake service's loop: answer each request read from `requests` until stop (or its session closes)."""
    while not stop.is_set():
        try:
            batch = requests.take_typed(timeout_s=0.05)
        except Exception:  # noqa: BLE001 - the session was closed under us: just stop
            return
        for request in batch:
            answer(request)
