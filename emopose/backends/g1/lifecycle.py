"""The G1 backend's state machine: ArmState, and Lifecycle, the one class that makes every transition.

    idle -> ramping (connect) -> holding (weight 1 at the measured pose) -> streaming (first send)
    holding | streaming -> releasing (close() or a fault) -> closed | failed (after a fault)
    ramping -> releasing (connect() aborted with weight given) -> closed;  ramping -> closed

Transitions and the commands published under them share `lock` (re-entrant), so a fault cannot
slip between send()'s state check and its write. Only the backend and its hand-over use the lock;
the supervisor goes through the backend's narrow Supervised interface.
"""

from __future__ import annotations

import threading
from enum import StrEnum

from emopose.backends.g1.errors import G1BackendError


class ArmState(StrEnum):
    IDLE = "idle"
    RAMPING = "ramping"
    HOLDING = "holding"
    STREAMING = "streaming"
    RELEASING = "releasing"
    FAILED = "failed"
    CLOSED = "closed"


ACTIVE = frozenset({ArmState.HOLDING, ArmState.STREAMING})  # under SDK weight, taking commands


class Lifecycle:
    def __init__(self) -> None:
        self.lock = threading.RLock()
        self._state = ArmState.IDLE
        self._failure: str | None = None
        self._released = threading.Event()

    @property
    def state(self) -> ArmState:
        return self._state

    @property
    def failure(self) -> str | None:
        return self._failure

    def start_connect(self) -> None:
        with self.lock:
            if self._state is not ArmState.IDLE:
                raise G1BackendError(
                    f"g1 backend: connect() called twice (backend is {self._state.value})"
                )
            self._state = ArmState.RAMPING

    def connected(self) -> None:
        with self.lock:
            self._expect(ArmState.RAMPING)
            self._state = ArmState.HOLDING

    def stream(self) -> None:
        """A command is about to go out (caller holds the lock): refuse unless active."""
        if self._state not in ACTIVE:
            raise G1BackendError(self.refusal())
        self._state = ArmState.STREAMING

    def claim_release(self, fault: str | None = None, allowed: frozenset = ACTIVE) -> bool:
        """Become releasing if in `allowed` (a fault is remembered); False if someone else has it."""
        with self.lock:
            if self._state not in allowed:
                return False
            self._state = ArmState.RELEASING
            self._failure = fault
            return True

    def released(self) -> None:
        with self.lock:
            self._expect(ArmState.RELEASING)
            self._state = ArmState.FAILED if self._failure is not None else ArmState.CLOSED
        self._released.set()

    def wait_released(self) -> None:
        self._released.wait()

    def closed(self) -> None:
        """Torn down: closed, unless a fault already made it failed."""
        with self.lock:
            if self._state is not ArmState.FAILED:
                self._state = ArmState.CLOSED

    def refusal(self) -> str:
        if self._failure is not None:
            return (
                "g1 backend released the arms after a fault and accepts no more commands: "
                f"{self._failure}"
            )
        if self._state in (ArmState.IDLE, ArmState.RAMPING):
            return "g1 backend: send() before connect() finished"
        return f"g1 backend is {self._state.value}; send() is no longer accepted"

    def _expect(self, state: ArmState) -> None:
        if self._state is not state:
            raise G1BackendError(
                f"g1 backend: internal state error: expected {state.value}, is {self._state.value}"
            )
