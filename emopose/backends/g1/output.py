"""ArmOutput: every LowCmd_ the backend puts on rt/arm_sdk goes through publish(), paced and recorded.

Whoever publishes (the weight ramps, the supervisor's holds, the stream, the release) calls it with
the lifecycle lock held. It keeps the last command (where a release blends from) and its weight,
never lets two commands reach the firmware closer than half a control period (a hold just before
the stream's first command would otherwise be one), and records each on /g1/lowcmd at the moment
it went out, on the recording's one time base (Recorder.write_now).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from emopose.clock import Clock
from emopose.recording import Recorder
from emopose.robot.g1_spec import CONTROL_DT

if TYPE_CHECKING:
    from emopose.backends.g1.link import G1Link

MIN_GAP_S = CONTROL_DT / 2


class ArmOutput:
    def __init__(
        self, link: G1Link, clock: Clock, recorder: Recorder | None, hold: np.ndarray
    ) -> None:
        self.link = link
        self._clock = clock
        self._recorder = recorder
        self.last_q = hold.copy()
        self.weight = 0.0
        self._sent_at = -np.inf

    def publish(self, q: np.ndarray, weight: float, phase: str, **extra: object) -> int:
        """One LowCmd_ out (caller holds the lifecycle lock); returns its CRC."""
        self._clock.sleep_until(self._sent_at + MIN_GAP_S)
        crc = self.link.publish(q, weight)
        self._sent_at = self._clock.now()
        self.last_q, self.weight = q, weight
        if self._recorder is not None:  # the payload costs more than the write: build it only then
            self._recorder.write_now(
                "/g1/lowcmd",
                {"q": q.tolist(), "weight": weight, "crc": crc, "phase": phase, **extra},
            )
        return crc

    def record(self, topic: str, payload: dict) -> None:
        if self._recorder is not None:
            self._recorder.write_now(topic, payload)
