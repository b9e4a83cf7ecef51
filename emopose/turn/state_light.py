"""StateLight: the G1's chest light follows the live session's state (serve; colours: chest_light.py).

The state is read, not pushed, every `period_s` (0.1 s): a fault wins (the robot's backend reports a
failure), then speaking (the player's audio is playing), then thinking (a planner call is under way,
TurnRunner.planning), else listening. Only a change is sent (ChestLight keeps its own 200 ms spacing
and sends the newest of a burst); close() switches the light off.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from emopose.clock import Clock
from emopose.execution.worker import Worker


def session_state(planning: Callable[[], bool], player, clock: Clock,
                  failure: Callable[[], object]) -> Callable[[], str]:
    """The state a session is in now, by the precedence above."""
    def state() -> str:
        if failure():
            return "fault"
        if player.playing(clock):
            return "speaking"
        return "thinking" if planning() else "listening"

    return state


class StateLight:
    def __init__(self, light, state: Callable[[], str], period_s: float = 0.1) -> None:
        if period_s <= 0:
            raise ValueError(f"state light: period_s must be > 0, got {period_s}")
        self.light, self.state, self.period_s = light, state, period_s
        self.shown: str | None = None
        self._worker = Worker("emopose-state-light", self._run, join_timeout_s=1.0)

    def start(self) -> StateLight:
        self._worker.start()
        return self

    def step(self) -> str:
        """Show the state if it changed; returns it (the worker calls this every period_s)."""
        state = self.state()
        if state != self.shown:
            self.light.show(state)
            self.shown = state
        return state

    def close(self) -> None:
        self._worker.stop()
        self.light.close()

    def _run(self, stopped: threading.Event) -> None:
        while not stopped.is_set():
            self.step()
            stopped.wait(self.period_s)
