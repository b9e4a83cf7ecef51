"""StateLight: the G1's chest light follows the live session's state (serve, the tour; colours:
emopose/backends/g1/chest_light.py).

The state is read, not pushed, every `period_s` (0.1 s): a fault wins (the robot's backend reports a
failure), then speaking (the player's audio is playing), then thinking (`planning`: serve and the tour
pass "from the request until the reply's audio starts", so no green flickers in between), else
listening. Only a change is sent (ChestLight keeps its own 200 ms spacing and sends the newest of a
burst); close() switches the light off. chest_light_for() is the one rule for when there is a light: a
G1 connected (player=g1, whose voice client it shares, or backend=g1 with the host's audio) and
player.light true.
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
    def __init__(self, light, state: Callable[[], str], period_s: float = 0.1,
                 owns_voice: bool = False) -> None:
        if period_s <= 0:
            raise ValueError(f"state light: period_s must be > 0, got {period_s}")
        self.light, self.state, self.period_s = light, state, period_s
        self.owns_voice = owns_voice  # the voice client was opened for the light alone: close() closes it
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
        if self.owns_voice:
            self.light.voice.close()

    def _run(self, stopped: threading.Event) -> None:
        while not stopped.is_set():
            self.step()
            stopped.wait(self.period_s)


def chest_light_for(res, planning: Callable[[], bool]) -> StateLight | None:
    """The started chest light follower of a run's resources (`planning`: a reply is being prepared), or
    None when no G1 is connected or player.light is false."""
    if not res.player.light:
        return None
    voice = getattr(res.player, "voice", None)  # player=g1 shares its voice client
    colours, owns_voice = getattr(res.player, "light_colours", None), voice is None
    if owns_voice and res.backend.name == "g1":
        from emopose.backends.g1.voice import VoiceClient

        settings = res.backend.settings
        voice = VoiceClient(settings.domain_id, settings.network_interface)
    if voice is None:
        return None
    from emopose.backends.g1.chest_light import ChestLight

    state = session_state(planning, res.player, res.clock, lambda: getattr(res.backend, "failure", None))
    return StateLight(ChestLight(voice, colours), state, owns_voice=owns_voice).start()
