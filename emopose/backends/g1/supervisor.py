"""The backend's watchdog thread: holds the pose until streaming starts, and trips on faults.

Faults: no valid rt/lowstate for longer than lowstate_loss_ms, or (once send() has started) no
send() for longer than deadman_ms: the sequencer stalled. On a fault the supervisor hands the
release to the backend on this thread, so the hand-back happens even when the main thread is stuck.
It sees the backend only through the narrow Supervised interface (a snapshot, a hold, a fault),
never its lock or internals. It polls with Event.wait (not a spin): no CPU between checks.
"""

from __future__ import annotations

import logging
import threading
from dataclasses import dataclass
from typing import Protocol

from emopose.backends.g1.constants import TOPIC_LOWSTATE
from emopose.backends.g1.lifecycle import ACTIVE, ArmState
from emopose.clock import Clock
from emopose.execution.pacing import DeadlineGrid
from emopose.execution.worker import Worker
from emopose.robot.g1_spec import CONTROL_DT

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Vitals:
    state: ArmState
    lowstate_age_s: float  # since the newest valid rt/lowstate
    idle_s: float  # since the last send() (inf before the first)
    where: str  # the DDS domain and interface, for messages


class Supervised(Protocol):
    def vitals(self) -> Vitals: ...

    def hold(self) -> None:
        """Publish one tick at the held pose, if still holding."""

    def fail(self, reason: str) -> None:
        """Claim the release for a fault and run it on the calling thread (if nobody else has)."""


def fault_reason(v: Vitals, lowstate_loss_s: float, deadman_s: float) -> str | None:
    if v.lowstate_age_s > lowstate_loss_s:
        return (
            f"lost {TOPIC_LOWSTATE}: no valid LowState_ for {v.lowstate_age_s * 1e3:.0f} ms (limit "
            f"{lowstate_loss_s * 1e3:.0f} ms, {v.where})"
        )
    if v.state is ArmState.STREAMING and v.idle_s > deadman_s:
        return (
            f"deadman: send() not called for {v.idle_s * 1e3:.0f} ms (limit "
            f"{deadman_s * 1e3:.0f} ms): the sequencer stalled"
        )
    return None


class Supervisor:
    def __init__(
        self,
        target: Supervised,
        clock: Clock,
        lowstate_loss_s: float,
        deadman_s: float,
    ) -> None:
        self._target, self._clock = target, clock
        self._loss_s, self._deadman_s = lowstate_loss_s, deadman_s
        # Check at least 4x per deadman period so a stall is seen within ~1.25x the limit.
        self._period = min(0.005, deadman_s / 4, lowstate_loss_s / 4)
        self._worker = Worker("g1-supervisor", self._run, join_timeout_s=10.0)

    def start(self) -> None:
        self._worker.start()

    def stop(self) -> None:
        """Also called from the supervisor's own thread (a fault tears the backend down)."""
        self._worker.stop()

    def _run(self, stop: threading.Event) -> None:
        holds = DeadlineGrid(self._clock, CONTROL_DT)  # the holds keep the one deadline policy
        while not stop.wait(self._period):
            vitals = self._target.vitals()
            if vitals.state not in ACTIVE:
                return  # closing or already released: nothing left to watch
            reason = fault_reason(vitals, self._loss_s, self._deadman_s)
            if reason is not None:
                self._target.fail(reason)
                return
            holds.skip_missed()  # a late wake-up re-anchors on the grid: no burst
            if vitals.state is ArmState.HOLDING and holds.due():
                holds.take()
                self._target.hold()
                holds.sent()
