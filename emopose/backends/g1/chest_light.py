"""ChestLight: the G1's chest light shows the conversation's state (voice service, api 1010 RGB).

    light = ChestLight(player.voice)          # shares player=g1's voice client (or any VoiceClient)
    light.show("listening" | "thinking" | "speaking" | "fault");  light.off();  light.close()

Default colours (RGB 0-255, `colours` overrides any of them): listening green (0, 200, 0),
thinking amber (255, 140, 0), speaking blue (0, 80, 255), fault red (255, 0, 0), off (0, 0, 0).
show() never blocks and never raises on the robot's side: a worker sends the latest state, at least
`min_interval_s` (200 ms, the light's documented minimum) after the previous one, so a burst of
states shows only the last; a failed call is logged once per run of failures and the next show()
tries again. An unknown state name is a ValueError (a wiring mistake, caught in tests).
"""

from __future__ import annotations

import logging
import threading
import time

from emopose.backends.g1.voice import LED_MIN_INTERVAL_S, VoiceClient, checked_rgb
from emopose.execution.worker import Worker

log = logging.getLogger(__name__)

COLOURS: dict[str, tuple[int, int, int]] = {
    "listening": (0, 200, 0),
    "thinking": (255, 140, 0),
    "speaking": (0, 80, 255),
    "fault": (255, 0, 0),
    "off": (0, 0, 0),
}


class ChestLight:
    def __init__(self, voice: VoiceClient, colours: dict[str, tuple[int, int, int]] | None = None,
                 min_interval_s: float = LED_MIN_INTERVAL_S) -> None:
        unknown = set(colours or {}) - set(COLOURS)
        if unknown:
            raise ValueError(f"chest light: unknown state(s) {sorted(unknown)}; states are {sorted(COLOURS)}")
        self.colours = {**COLOURS, **{k: checked_rgb(v) for k, v in (colours or {}).items()}}
        self.voice, self.min_interval_s = voice, min_interval_s
        self._changed = threading.Condition()
        self._pending: str | None = None
        self._last_sent_at = -float("inf")
        self._failing = False
        self.state: str | None = None  # the last state the robot confirmed
        self.sent = 0
        self._worker = Worker("emopose-g1-light", self._run, join_timeout_s=2.0)

    def show(self, state: str) -> None:
        if state not in self.colours:
            raise ValueError(f"chest light: unknown state {state!r}; states are {sorted(self.colours)}")
        with self._changed:
            self._pending = state
            self._changed.notify_all()
        self._worker.start()

    def off(self) -> None:
        self.show("off")

    def settled(self) -> bool:
        """True when no state waits to be sent (tests and close())."""
        with self._changed:
            return self._pending is None

    def close(self, timeout_s: float = 1.0) -> None:
        """Switch the light off (best effort, at most timeout_s) and stop the worker."""
        self.off()
        deadline = time.monotonic() + timeout_s
        while not self.settled() and time.monotonic() < deadline:
            time.sleep(0.01)
        self._worker.stop()

    def _run(self, stopped: threading.Event) -> None:
        while not stopped.is_set():
            with self._changed:
                wait_s = self._last_sent_at + self.min_interval_s - time.monotonic()
                if self._pending is None or wait_s > 0:
                    self._changed.wait(0.1 if self._pending is None else min(wait_s, 0.1))
                    continue
                state, self._pending = self._pending, None
                self._last_sent_at = time.monotonic()
            self._send(state)

    def _send(self, state: str) -> None:
        try:
            self.voice.set_light(self.colours[state])
        except Exception as exc:  # noqa: BLE001 - the light is a courtesy: it never stops a turn
            if not self._failing:
                log.warning("chest light: %s not shown (%s: %s)", state, type(exc).__name__, str(exc)[:200])
            self._failing = True
            return
        self._failing, self.state = False, state
        self.sent += 1
