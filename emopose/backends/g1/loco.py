"""LocoClient: walk the G1's base through Unitree's loco RPC (rt/api/sport/request|response).

Each call writes a Request_ whose identity id is unique to this client, then waits for the
Response_ with that id (every client on the domain sees every response). Velocities are clamped
to the configured limits (vx <= 0.3 m/s indoors by default) and the clamp is logged; a timeout
and a non-zero status both raise, naming the api id (and the code). cyclonedds is imported in
open(), so constructing a client from config costs nothing.
"""

from __future__ import annotations

import itertools
import json
import logging
import math
import os
import threading
import time

from emopose.backends.g1.constants import (
    LOCO_API_GET_FSM_ID,
    LOCO_API_SET_FSM_ID,
    LOCO_API_SET_VELOCITY,
    LOCO_SERVICE,
    request_topic,
    response_topic,
)
from emopose.backends.g1.errors import LocoError, LocoTimeoutError

log = logging.getLogger(__name__)


RESEND_S = 0.25  # re-send an unanswered request this often until the call's timeout


def _clamp(name: str, value: float, limit: float) -> float:
    if not math.isfinite(value):
        raise ValueError(f"loco: {name} must be finite, got {value}")
    clamped = min(max(value, -limit), limit)
    if clamped != value:
        log.warning("loco: %s %.3f clamped to %.3f (limit %.3f)", name, value, clamped, limit)
    return clamped


class LocoClient:
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
        self.domain_id, self.network_interface, self.service = domain_id, network_interface, service
        self.timeout_s = timeout_s
        self.max_vx, self.max_vy, self.max_omega, self.max_duration_s = (
            max_vx,
            max_vy,
            max_omega,
            max_duration_s,
        )
        self._session = self._requests = self._responses = None
        self._lock = threading.Lock()  # one call in flight per client: responses are matched by id
        # Unique ids across processes and clients: pid in the high bits, a counter below.
        self._ids = itertools.count(
            ((os.getpid() & 0x7FFF) << 47) | (time.monotonic_ns() & ((1 << 40) - 1))
        )

    def open(self) -> LocoClient:
        from emopose.backends.g1.api_types import Request_, Response_
        from emopose.backends.g1.dds import DdsSession

        if self._session is None:
            self._session = DdsSession(self.domain_id, self.network_interface)
            self._requests = self._session.writer(request_topic(self.service), Request_)
            self._responses = self._session.reader(response_topic(self.service), Response_)
        return self

    def close(self) -> None:
        session, self._session = self._session, None
        if session is not None:
            session.close()

    def __enter__(self) -> LocoClient:  # noqa: PYI034 - open() returns self
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()

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

    # ------------------------------------------------------------------ transport
    def call(self, api_id: int, parameter: dict) -> str:
        """Send one request and return the response's `data` (a JSON string, maybe empty)."""
        from emopose.backends.g1.api_types import Request_, RequestHeader_, RequestIdentity_

        self.open()
        where = (
            f"loco service '{self.service}' on {request_topic(self.service)} "
            f"(domain {self.domain_id}, interface {self.network_interface or 'Cyclone default'})"
        )
        with self._lock:
            deadline = time.monotonic() + self.timeout_s
            # A request written before discovery matched the server would be lost silently.
            for endpoint in (self._requests, self._responses):
                if not endpoint.matched.wait(max(0.0, deadline - time.monotonic())):
                    raise LocoTimeoutError(
                        f"loco api {api_id}: no {where} found within {self.timeout_s:g} s"
                    )
            request_id = next(self._ids)
            header = RequestHeader_(identity=RequestIdentity_(id=request_id, api_id=api_id))
            request = Request_(header=header, parameter=json.dumps(parameter), binary=[])
            # Our writer can match the server's reader before the server's side has matched ours, and
            # a request written in that window is lost; so the same request (same id, and every loco
            # api is idempotent) is re-sent until an answer comes or the deadline passes.
            while (remaining := deadline - time.monotonic()) > 0:
                self._requests.write_typed(request)
                wait_until = time.monotonic() + min(RESEND_S, remaining)
                while (window := wait_until - time.monotonic()) > 0:
                    for response in self._responses.take_typed(timeout_s=window):
                        if response.header.identity.id != request_id:
                            continue  # another client's answer, or a duplicate of an older one
                        code = int(response.header.status.code)
                        if code != 0:
                            raise LocoError(
                                api_id,
                                code,
                                f"loco api {api_id} failed with status code {code} ({where})",
                            )
                        return response.data
            raise LocoTimeoutError(
                f"loco api {api_id}: no response from {where} within {self.timeout_s:g} s"
            )
