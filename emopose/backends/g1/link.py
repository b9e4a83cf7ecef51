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
from emopose.backends.g1.release import FeedLaw
from emopose.backends.g1.settings import G1Settings
from emopose.backends.g1.state_monitor import LowStateMonitor
from emopose.backends.g1.torso import TorsoGravity
from emopose.robot.arm_law import ArmLaw
from emopose.robot.feedforward import Feedforward, GravityModel
from emopose.robot.g1_spec import CONTROL_DT

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
        # dq and tau of every command, as MuJoCo applies them; gravity under the measured torso
        gravity = TorsoGravity(GravityModel(), self.monitor.torso) if law.gravity_compensation else None
        self._feedforward = Feedforward(law, gravity)

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
        return monitor.arm_q()

    def reset_feedforward(self, hold: np.ndarray) -> None:
        """The stream starts holding `hold` (the measured pose, clamped): no velocity reference yet."""
        self._feedforward.reset(hold)

    def feedforward(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(dq*, tau) of the arm law for the next target q."""
        return self._feedforward(q)

    def feed_law(self) -> FeedLaw:
        """What a release plans its feed-forwards with."""
        law = self._feedforward.law
        return FeedLaw(self.settings.kd, law.velocity_feedforward, self._feedforward.gravity
                       if law.gravity_compensation else None, CONTROL_DT)

    def publish(self, q: np.ndarray, weight: float, dq: np.ndarray, tau: np.ndarray) -> int:
        """Build, CRC and write one LowCmd_; returns the CRC. Not thread-safe (backend locks)."""
        cdr, crc = self._builder.build(q, weight, dq, tau)
        self._writer.write(cdr)
        return crc

    def state_age(self) -> float:
        return self.monitor.age()

    def close(self) -> None:
        self.monitor.stop()  # before the participant goes: its thread waits on a reader
        self.session.close()
