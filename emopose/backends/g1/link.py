"""G1Link: the DDS side of the backend, one participant with rt/lowstate in and rt/arm_sdk out.

Kept apart from G1Backend so the backend reads as a state machine, and so this module (which
imports cyclonedds) is only imported from connect().
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from emopose.backends.g1.arm_command import ArmCommandBuilder
from emopose.backends.g1.constants import TOPIC_ARM_SDK, TOPIC_LOWSTATE
from emopose.backends.g1.dds import DdsSession
from emopose.backends.g1.errors import G1ConnectionError
from emopose.backends.g1.hg_types import LowCmd_
from emopose.backends.g1.settings import G1Settings
from emopose.backends.g1.state_monitor import LowStateMonitor
from emopose.robot.arm_law import ArmLaw
from emopose.robot.feedforward import Feedforward

log = logging.getLogger(__name__)


class G1Link:
    def __init__(self, settings: G1Settings, now: Callable[[], float]) -> None:
        self.settings = settings
        self.session = DdsSession(settings.domain_id, settings.network_interface)
        try:
            self.monitor = LowStateMonitor(self.session, now)
            self.monitor.start()
            self._writer = self.session.writer(TOPIC_ARM_SDK, LowCmd_)  # discovery runs meanwhile
        except BaseException:
            self.session.close()
            raise
        self._builder: ArmCommandBuilder | None = None
        law = ArmLaw("g1", settings.kp.tolist(), settings.kd.tolist(), settings.velocity_feedforward,
                     settings.gravity_compensation)
        self._feedforward = Feedforward(law)  # dq and tau of every command, as MuJoCo applies them

    def where(self) -> str:
        return self.session.describe()

    def wait_for_robot(self) -> np.ndarray:
        """Block until a valid-CRC lowstate arrives; return the measured arm pose (14,).
        Also prepares the command builder (it needs the measured waist when command_waist)."""
        s, monitor = self.settings, self.monitor
        if not monitor.wait_first(s.lowstate_timeout_s):
            raise G1ConnectionError(
                "refusing to start: no LowState_ with a valid CRC on topic "
                f"'{TOPIC_LOWSTATE}' within {s.lowstate_timeout_s:g} s ({self.where()}); ignored "
                f"{monitor.bad_crc} with a bad CRC and {monitor.undecodable} undecodable. "
                "Is the robot on, and on this network interface and DDS domain?"
            )
        if not self._writer.matched.wait(s.lowstate_timeout_s):
            log.warning(
                "nobody subscribes %s (%s); arm commands may go unheard",
                TOPIC_ARM_SDK,
                self.where(),
            )
        waist = monitor.waist_q() if s.command_waist else None
        self._builder = ArmCommandBuilder(s.kp, s.kd, waist, s.waist_kp, s.waist_kd)
        measured = monitor.arm_q()
        self._feedforward.reset(measured)
        return measured

    def publish(self, q: np.ndarray, weight: float) -> int:
        """Build, CRC and write one LowCmd_; returns the CRC. Not thread-safe (backend locks)."""
        cdr, crc = self._builder.build(q, weight, *self._feedforward(q))
        self._writer.write(cdr)
        return crc

    def state_age(self) -> float:
        return self.monitor.age()

    def close(self) -> None:
        self.monitor.stop()  # before the participant goes: its thread waits on a reader
        self.session.close()
