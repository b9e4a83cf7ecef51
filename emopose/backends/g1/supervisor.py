"""The backend's watchdog thread: holds the pose until streaming starts, and trips on faults.

Faults: no valid rt/lowstate for longer than lowstate_loss_ms, or (once send() has started) no
send() for longer than deadman_ms: the sequencer stalled. On a fault the supervisor claims the
release from the backend and runs it on this thread, so the hand-back happens even when the
main thread is stuck. It polls with Event.wait (not a spin) so it costs no CPU between checks.
"""

from __future__ import annotations

import logging
import threading
from typing import TYPE_CHECKING

from emopose.backends.g1.constants import TOPIC_LOWSTATE
from emopose.robot.g1_spec import CONTROL_DT

if TYPE_CHECKING:
    from emopose.backends.g1.backend import G1Backend

log = logging.getLogger(__name__)


class Supervisor:
    def __init__(self, backend: G1Backend) -> None:
        self._backend = backend
        s = backend.settings
        # Check at least 4x per deadman period so a stall is seen within ~1.25x the limit.
        self._period = min(0.005, s.deadman_s / 4, s.lowstate_loss_s / 4)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="g1-supervisor", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread.is_alive() and threading.current_thread() is not self._thread:
            self._thread.join(timeout=10.0)

    def _run(self) -> None:
        backend = self._backend
        now = backend._clock.now
        next_hold = now() + CONTROL_DT
        while not self._stop.wait(self._period):
            reason = None
            with backend._lock:
                state = backend.state
                if state not in ("holding", "streaming"):
                    return  # closing or already released: nothing left to watch
                t = now()
                age = backend._link.state_age()
                idle = t - backend._last_send
                if age > backend.settings.lowstate_loss_s:
                    reason = (
                        f"lost {TOPIC_LOWSTATE}: no valid LowState_ for {age * 1e3:.0f} ms (limit "
                        f"{backend.settings.lowstate_loss_s * 1e3:.0f} ms, {backend._link.where()})"
                    )
                elif state == "streaming" and idle > backend.settings.deadman_s:
                    reason = (
                        f"deadman: send() not called for {idle * 1e3:.0f} ms (limit "
                        f"{backend.settings.deadman_s * 1e3:.0f} ms): the sequencer stalled"
                    )
                elif state == "holding" and t >= next_hold:
                    backend._publish(backend._last_q, 1.0, phase="hold")
                    next_hold = max(next_hold + CONTROL_DT, t)  # no burst after a late wake-up
            if reason is not None:
                if backend.fault(reason):
                    try:
                        backend.release(reason)
                    except Exception:
                        log.exception("release after fault failed")
                return
