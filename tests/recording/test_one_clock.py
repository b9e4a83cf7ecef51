"""One clock in every recording: every time field of every channel of a real session (the fields each
channel's schema marks as session time) lies within the session's span, and a stream message's `t` is
its own log time."""

from __future__ import annotations

import pytest
from mcap.reader import make_reader

from emopose.recording import recording_start_ns
from emopose.recording_schemas import session_time_paths
from tests.recording.conftest import every_message


def _values(payload, path):
    if not path:
        yield payload
    elif path[0] == "*":
        for item in payload:
            yield from _values(item, path[1:])
    elif isinstance(payload, dict) and path[0] in payload:
        yield from _values(payload[path[0]], path[1:])


def test_every_time_field_lies_on_the_session_clock(session_recording):
    with session_recording.open("rb") as f:
        start_ns = recording_start_ns(make_reader(f))
    messages = every_message(session_recording)
    span = (max(stamp for _, _, stamp, _ in messages) - start_ns) / 1e9
    checked = set()
    for topic, schema, stamp, payload in messages:
        for path in session_time_paths(schema):
            for value in _values(payload, path):
                if value is not None:
                    assert -0.5 <= value <= span + 0.5, (
                        f"{topic} {'.'.join(path)} = {value} (span {span:.2f} s)"
                    )
                    checked.add((topic, path))
        if "t" in payload:  # a message's own time is its log time
            assert payload["t"] == pytest.approx((stamp - start_ns) / 1e9, abs=1e-6), topic
    assert {
        ("/submitted", ("speech_start",)),
        ("/dispatched", ("speech_start",)),
        ("/dispatched", ("events", "*", "t")),
        ("/speech/timeline", ("speech_start",)),
        ("/joints/command", ("t",)),
        ("/sequencer/events", ("t",)),
    } <= checked


def test_the_turn_times_agree_across_channels(session_recording):
    """/dispatched, /speech/timeline and /sequencer/events tell the same times for the same turn."""
    rows = {}
    for topic, _, _, payload in every_message(session_recording):
        rows.setdefault(topic, []).append(payload)
    dispatched, timeline = rows["/dispatched"][0], rows["/speech/timeline"][0]
    assert dispatched["speech_start"] == pytest.approx(timeline["speech_start"])
    assert [e["t"] for e in dispatched["events"]] == pytest.approx(
        [e["t"] for e in rows["/sequencer/events"][: len(dispatched["events"])]]
    )
