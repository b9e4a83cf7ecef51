"""/sequencer/events: every event is stamped once, so the recorded times are the events' own and monotone."""

from __future__ import annotations

from emopose.clock import FakeClock
from emopose.recording import read_recording
from emopose.sync.recording import EVENTS
from tests.wiring import wire


class CreepingClock(FakeClock):
    """Virtual time that moves a microsecond on every read, as a real clock does between two reads."""

    def now(self) -> float:
        with self._lock:
            self._t += 1e-6
            return self._t


def test_recorded_event_times_are_the_events_own_and_never_decrease(library, tmp_path):
    wired = wire(library, tmp_path)
    clock = CreepingClock()
    wired.loop.clock = wired.stages[4].clock = clock
    wired.sequencer.on_event = wired.session.record_event
    with wired.session:
        for utterance in ("Welcome to the lab!", "Look over there, yes!", "No, I doubt that. Welcome!"):
            wired.runner.run(utterance)
        recorder = wired.session.recorder  # recordings are on session time (since the file opened)
        expected = [recorder.session_time(event.t) for event in wired.sequencer.events]
    recorded = read_recording(tmp_path / "session.mcap")[EVENTS]
    payload_times = [payload["t"] for _, payload in recorded]
    assert len(expected) >= 6 and {"stroke", "completed"} <= {p["kind"] for _, p in recorded}
    assert payload_times == sorted(payload_times)
    assert payload_times == sorted(expected)
    # the log time is the same single read: it sits a constant offset from the payload time
    offsets = [logged - payload["t"] for logged, payload in recorded]
    assert max(offsets) - min(offsets) < 1e-8
