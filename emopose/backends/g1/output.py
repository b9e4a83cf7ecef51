"""ArmOutput: every LowCmd_ the backend puts on rt/arm_sdk goes through publish(), paced and recorded.

Whoever publishes (the weight ramps, the supervisor's holds, the stream, the release) calls it with
the lifecycle lock held. Each path paces itself on the one deadline policy (emopose/execution/pacing.py);
this is where they meet, so it keeps the last command (where a release starts from: pose, weight and
feed-forwards), never lets two commands of different paths reach the firmware closer than the policy's
minimum gap (a hold just before the stream's first command would otherwise be one), and records each on
/g1/lowcmd at the moment it went out, on the recording's one time base (Recorder.write_now).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from emopose.backends.g1.release import Command
from emopose.clock import Clock
from emopose.execution.pacing import MIN_GAP_PERIODS
from emopose.recording import Recorder
from emopose.robot.g1_spec import CONTROL_DT, NUM_JOINTS

if TYPE_CHECKING:
    from emopose.backends.g1.link import G1Link

MIN_GAP_S = MIN_GAP_PERIODS * CONTROL_DT


class ArmOutput:
    def __init__(
        self, link: G1Link, clock: Clock, recorder: Recorder | None, hold: np.ndarray
    ) -> None:
        self.link = link
        self._clock = clock
        self._recorder = recorder
        self.last = Command(hold.copy(), 0.0, np.zeros(NUM_JOINTS), np.zeros(NUM_JOINTS))
        self._sent_at = -np.inf

    @property
    def weight(self) -> float:
        return self.last.weight

    def publish(self, q: np.ndarray, weight: float, phase: str, feed: tuple | None = None,
                **extra: object) -> int:
        """One LowCmd_ out (caller holds the lifecycle lock); returns its CRC. feed: (dq*, tau) as
        planned (a release), else the arm law's feed-forwards for q."""
        self._clock.sleep_until(self._sent_at + MIN_GAP_S)
        dq, tau = self.link.feedforward(q) if feed is None else feed
        crc = self.link.publish(q, weight, dq, tau)
        self._sent_at = self._clock.now()
        self.last = Command(q, weight, dq, tau)
        if self._recorder is not None:  # the payload costs more than the write: build it only then
            if "t" in extra:  # a streamed command's stream time: on the clock, as write_now's times are
                extra["t"] = self._recorder.stream_clock(float(extra["t"]))
            self._recorder.write_now(
                "/g1/lowcmd",
                {"q": q.tolist(), "weight": weight, "dq": dq.tolist(), "tau": tau.tolist(), "crc": crc,
                 "phase": phase, **extra},
            )
        return crc

    def record(self, topic: str, payload: dict) -> None:
        if self._recorder is not None:
            self._recorder.write_now(topic, payload)
