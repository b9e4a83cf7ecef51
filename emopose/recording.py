"""MCAP recording: one JSON channel per kind of message, nanosecond timestamps, readable by Foxglove.

Every message of a recording lies on one monotonic time base: the recorder's clock (the session's
loop clock), in seconds since the recorder opened; the file stores `start_ns` (the wall time at
opening, so Foxglove shows real dates) plus that offset. Writers give either stream time t (the
control loop's seconds since its stream began; `start_stream` says where that is on the clock, and
a restarted stream moves it on, never back) or nothing (`write_now`: stamped on arrival, for
messages with no tick of their own such as the G1's hand-over phases or the turn's plan).
"""

from __future__ import annotations

import json
import threading
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

from emopose.clock import Clock, MonotonicClock

JOINT_STREAM_SCHEMA = {
    "type": "object",
    "properties": {
        "t": {"type": "number", "description": "stream time, s"},
        "q": {"type": "array", "items": {"type": "number"}, "description": "14 joint positions, rad"},
    },
}
GENERIC_SCHEMA = {"type": "object"}


class Recorder:
    """Thread-safe MCAP writer. Channels are registered on first use."""

    def __init__(self, path: str | Path, schemas: dict[str, dict] | None = None,
                 clock: Clock | None = None) -> None:
        from mcap.writer import Writer

        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._stream = self.path.open("wb")
        self._writer = Writer(self._stream)
        self._writer.start(profile="", library="emopose")
        self._schemas = dict(schemas or {})
        self._channels: dict[str, int] = {}
        self._lock = threading.Lock()
        self._closed = False
        self.clock = clock or MonotonicClock()
        self.origin = self.clock.now()  # the recording's zero on its clock
        self._stream_zero = self.origin  # where stream time 0 lies on the clock
        self.start_ns = time.time_ns()

    def start_stream(self, zero: float) -> None:
        """Stream time 0 is clock time `zero` from now on (a stream began, or began again)."""
        with self._lock:
            if zero < self._stream_zero:
                raise ValueError(
                    f"recorder: a stream cannot restart in the past ({zero} < {self._stream_zero})"
                )
            self._stream_zero = zero

    def _channel(self, topic: str) -> int:
        if topic not in self._channels:
            schema = self._schemas.get(
                topic, JOINT_STREAM_SCHEMA if topic.startswith("/joints") else GENERIC_SCHEMA
            )
            schema_id = self._writer.register_schema(
                name=topic.strip("/").replace("/", "."), encoding="jsonschema",
                data=json.dumps(schema).encode()
            )
            self._channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding="json", schema_id=schema_id
            )
        return self._channels[topic]

    def write(self, topic: str, t: float, payload: dict[str, Any]) -> None:
        """Record payload at stream time t."""
        data = json.dumps(payload, separators=(",", ":")).encode()
        with self._lock:
            self._add(topic, self._stream_zero - self.origin + t, data)

    def write_now(self, topic: str, payload: dict[str, Any]) -> None:
        """Record payload at the clock's current time (stamped under the lock: in arrival order)."""
        data = json.dumps(payload, separators=(",", ":")).encode()
        with self._lock:
            self._add(topic, self.clock.now() - self.origin, data)

    def _add(self, topic: str, offset_s: float, data: bytes) -> None:
        if self._closed:
            return
        stamp = self.start_ns + int(round(offset_s * 1e9))
        self._writer.add_message(channel_id=self._channel(topic), log_time=stamp, publish_time=stamp,
                                 data=data)

    def close(self) -> None:
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._writer.finish()
            self._stream.close()

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_recording(path: str | Path) -> dict[str, list[tuple[float, dict]]]:
    """Load an MCAP written by Recorder: topic -> [(stream time s, payload)] in log-time order."""
    from mcap.reader import make_reader

    by_topic: dict[str, list[tuple[int, dict]]] = defaultdict(list)
    with Path(path).open("rb") as f:
        reader = make_reader(f)
        for _schema, channel, message in reader.iter_messages(log_time_order=True):
            by_topic[channel.topic].append((message.log_time, json.loads(message.data)))
    if not by_topic:
        return {}
    start = min(stamps[0][0] for stamps in by_topic.values())
    return {
        topic: [((stamp - start) / 1e9, payload) for stamp, payload in rows]
        for topic, rows in by_topic.items()
    }
