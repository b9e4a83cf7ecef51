"""ServiceClient: one Unitree RPC service over DDS (rt/api/<service>/request|response).

Each call writes a Request_ whose identity id is unique to this client, then waits for the
Response_ with that id (every client on the domain sees every response). A timeout and a
non-zero status both raise, naming the service, the api id (and the code). The loco client
(loco.py) and the voice client (voice.py) are this class with their APIs on top. cyclonedds is
imported in open(), so constructing a client from config costs nothing.
"""

from __future__ import annotations

import itertools
import json
import os
import threading
import time

from emopose.backends.g1.constants import request_topic, response_topic

RESEND_S = 0.25  # re-send an unanswered idempotent request this often until the call's timeout


class RpcError(RuntimeError):
    """The service answered a request with a non-zero status code."""

    def __init__(self, api_id: int, code: int, message: str) -> None:
        super().__init__(message)
        self.api_id = api_id
        self.code = code


class RpcTimeoutError(TimeoutError):
    """No answer from the service in time."""


class ServiceClient:
    label = "rpc"  # names the service kind in errors ("loco api 7001: ...")
    error_type: type[RuntimeError] = RpcError
    timeout_type: type[TimeoutError] = RpcTimeoutError

    def __init__(self, domain_id: int = 0, network_interface: str | None = None, service: str = "",
                 timeout_s: float = 1.0) -> None:
        self.domain_id, self.network_interface, self.service = domain_id, network_interface, service
        self.timeout_s = timeout_s
        self._session = self._requests = self._responses = None
        self._lock = threading.Lock()  # one call in flight per client: responses are matched by id
        # Unique ids across processes and clients: pid in the high bits, a counter below.
        self._ids = itertools.count(
            ((os.getpid() & 0x7FFF) << 47) | (time.monotonic_ns() & ((1 << 40) - 1))
        )

    def open(self):
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

    def __enter__(self):
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def describe(self) -> str:
        return (f"{self.label} service '{self.service}' on {request_topic(self.service)} "
                f"(domain {self.domain_id}, interface {self.network_interface or 'Cyclone default'})")

    def call(self, api_id: int, parameter: dict, binary: bytes = b"", idempotent: bool = True) -> str:
        """Send one request and return the response's `data` (a JSON string, maybe empty).

        Our writer can match the server's reader before the server's side has matched ours, and a
        request written in that window is lost; so an idempotent request is re-sent (same id) until
        an answer comes or the deadline passes. A non-idempotent one (an audio chunk: a duplicate
        would be heard twice) is written once."""
        from emopose.backends.g1.api_types import Request_, RequestHeader_, RequestIdentity_

        self.open()
        with self._lock:
            deadline = time.monotonic() + self.timeout_s
            # A request written before discovery matched the server would be lost silently.
            for endpoint in (self._requests, self._responses):
                if not endpoint.matched.wait(max(0.0, deadline - time.monotonic())):
                    raise self.timeout_type(
                        f"{self.label} api {api_id}: no {self.describe()} found within {self.timeout_s:g} s")
            request_id = next(self._ids)
            header = RequestHeader_(identity=RequestIdentity_(id=request_id, api_id=api_id))
            request = Request_(header=header, parameter=json.dumps(parameter), binary=list(binary))
            while (remaining := deadline - time.monotonic()) > 0:
                self._requests.write_typed(request)
                answer = self._await(request_id, min(RESEND_S, remaining) if idempotent else remaining)
                if answer is not None:
                    return self._checked(api_id, *answer)
            raise self.timeout_type(
                f"{self.label} api {api_id}: no response from {self.describe()} within {self.timeout_s:g} s")

    def _await(self, request_id: int, window_s: float) -> tuple[int, str] | None:
        """(status code, data) of the response to request_id, or None when none came in window_s."""
        wait_until = time.monotonic() + window_s
        while (window := wait_until - time.monotonic()) > 0:
            for response in self._responses.take_typed(timeout_s=window):
                if response.header.identity.id == request_id:  # else another client's answer
                    return int(response.header.status.code), response.data
        return None

    def _checked(self, api_id: int, code: int, data: str) -> str:
        if code != 0:
            raise self.error_type(
                api_id, code, f"{self.label} api {api_id} failed with status code {code} ({self.describe()})")
        return data
