"""close() under pressure: called from two threads at once, and hit by Ctrl-C mid-release."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

from emopose.backends.g1 import G1Backend, G1BackendError
from emopose.clock import MonotonicClock

pytestmark = pytest.mark.slow  # two connect/stream/release sessions against one fake robot

FAST = {"lowstate_timeout_s": 10.0, "weight_ramp_up_s": 0.2, "weight_ramp_down_s": 0.4}
BLEND_TICKS, RAMP_TICKS = 10, 20  # release_blend_s 0.2 s, weight_ramp_down_s 0.4 s at 50 Hz
# One session: 10 ramp-up ticks (the last, weight 1 at the held pose, looks like a hold and is
# filtered with them), 5 sends, then the release.
SESSION_TICKS = 10 - 1 + 5 + BLEND_TICKS + RAMP_TICKS


class InterruptOnce(MonotonicClock):
    """A real clock whose next sleep raises KeyboardInterrupt once armed (a Ctrl-C)."""

    armed = False

    def sleep_until(self, deadline: float) -> None:
        if self.armed:
            self.armed = False
            raise KeyboardInterrupt
        super().sleep_until(deadline)


def session(domain_id: int, clock: MonotonicClock | None = None) -> tuple[G1Backend, np.ndarray]:
    backend = G1Backend(
        domain_id=domain_id, release_blend_s=0.2, neutral_pose=[0.0] * 14, clock=clock, **FAST
    )
    q0 = backend.connect(None)
    for i in range(5):
        backend.send(i * 0.02, q0 + 0.01 * (i + 1))
    return backend, q0


def without_holds(rows: list[dict], q0: np.ndarray) -> list[dict]:
    """Drop hold ticks (the supervisor may slip one in before the first send on a busy machine)."""
    hold = np.float32(q0).astype(float)
    return [r for r in rows if not (r["weight"] == 1.0 and np.array_equal(r["q"], hold))]


def release_of(rows: list[dict]) -> np.ndarray:
    """Weights of the release at the end of a session's log rows."""
    return np.array([r["weight"] for r in rows[-(BLEND_TICKS + RAMP_TICKS) :]])


def test_concurrent_close_releases_once_and_ctrl_c_waits_for_the_release(fake_robot, domain_id):
    robot = fake_robot()
    backend, q0 = session(domain_id)
    closers = [threading.Thread(target=backend.close) for _ in range(2)]
    for t in closers:
        t.start()
    for t in closers:
        t.join(timeout=10)
    backend.close()  # and a third time, after the fact
    robot.wait_for("arm", SESSION_TICKS)
    time.sleep(0.1)
    first = robot.entries("arm")
    assert len(without_holds(first, q0)) == SESSION_TICKS  # one release, not two
    weights = release_of(first)
    assert np.all(np.diff(weights) <= 0) and weights[-1] == 0.0
    assert backend.state == "closed"

    clock = InterruptOnce()
    backend, q0 = session(domain_id, clock)
    clock.armed = True  # Ctrl-C lands on the release's first tick
    with pytest.raises(KeyboardInterrupt):
        backend.close()
    robot.wait_for("arm", len(first) + SESSION_TICKS)
    time.sleep(0.1)
    rows = without_holds(robot.entries("arm")[len(first) :], q0)
    assert len(rows) == SESSION_TICKS  # the whole release still went out
    weights = release_of(rows)
    assert np.all(np.diff(weights) <= 0) and weights[-1] == 0.0
    backend.close()  # the app's finally runs close() again: a no-op
    with pytest.raises(G1BackendError):
        backend.send(1.0, np.zeros(14))
