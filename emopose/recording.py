"""MCAP recording: one JSON channel per kind of message, nanosecond timestamps, readable by Foxglove.

One clock: every message of a recording, and every time field in it (the fields its schema marks as
session time, emopose/recording_schemas.py), lies on the recorder's clock (the session's loop clock),
in seconds since the recorder opened: "session time". The file stores `start_ns` (the wall time at
opening, so Foxglove shows real dates; also in the `emopose` metadata record) plus that offset. Writers
give either stream time t (the control loop's seconds since its stream began; `start_stream` says where
that is on the clock, and a restarted stream moves it on, never back) or nothing (`write_now`: stamped
on arrival, its time fields read from the loop's clock).

Nothing is lost but the last moment: writers only stamp, encode and queue a message; a background thread
puts the queue into zstd chunks and closes, writes and fsyncs one every FLUSH_S, so a killed process
(kill -9, a power cut) loses at most the chunk in progress; `python -m emopose.recover FILE` rewrites such
a torn file into a complete one.
"""

from __future__ import annotations

import functools
import json
import math
import os
import threading
import time
from collections import defaultdict, deque
from pathlib import Path
from typing import Any

from emopose.clock import Clock, MonotonicClock
from emopose.recording_schemas import SCHEMAS, session_time_paths
from emopose.robot.g1_spec import JOINT_NAMES

FLUSH_S = 0.5  # a chunk is closed and on disk at most this long after its first message
GENERIC_SCHEMA = {"type": "object"}
FOXGLOVE_NAMES = {"/joint_states": "sensor_msgs/msg/JointState", "/robot_description": "std_msgs/msg/String"}
METADATA = "emopose"


def joint_state(position, velocity, effort=None) -> dict:
    """A /joint_states message (sensor_msgs/JointState's fields; Recorder.write stamps its `t`): the
    arms by joint name, rad, rad/s and N·m (empty when the backend knows no torque)."""
    return {
        "name": list(JOINT_NAMES),
        "position": [float(v) for v in position],
        "velocity": [float(v) for v in velocity],
        "effort": [] if effort is None else [float(v) for v in effort],
    }


class Recorder:
    """Thread-safe MCAP writer. Channels are registered on first use; the robot's description (URDF)
    is the first message, for Foxglove's 3D panel."""

    def __init__(self, path: str | Path, clock: Clock | None = None, describe_robot: bool = True) -> None:
        from mcap.writer import Writer

        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._stream = self.path.open("wb")
        self._writer = Writer(self._stream)
        self._writer.start(profile="", library="emopose")
        self._channels: dict[str, int] = {}
        self._pending: deque[tuple[str, int, bytes]] = deque()  # stamped, encoded, not yet in the file
        self._order = threading.Lock()  # stamps and stream zero; held for microseconds, by any writer
        self._io = threading.Lock()  # the MCAP writer: the flusher thread and close() only
        self._closed = threading.Event()
        self.clock = clock or MonotonicClock()
        self.origin = self.clock.now()  # the recording's zero on its clock
        self._stream_zero = self.origin  # where stream time 0 lies on the clock
        self.start_ns = time.time_ns()
        self._writer.add_metadata(METADATA, {"start_ns": str(self.start_ns)})
        if describe_robot:
            self._describe_robot()
        self._flusher = threading.Thread(target=self._flush_every, name="mcap-flush", daemon=True)
        self._flusher.start()

    def _describe_robot(self) -> None:
        """The URDF first (building it takes a while: a stop signal landing here still leaves a whole,
        readable file behind, not a torn header)."""
        try:
            from emopose.robot.urdf import robot_urdf

            self.write_now("/robot_description", {"data": robot_urdf()})
        except BaseException:
            self._closed.set()
            self._writer.finish()
            self._stream.close()
            raise

    def start_stream(self, zero: float) -> None:
        """Stream time 0 is clock time `zero` from now on (a stream began, or began again)."""
        with self._order:
            if zero < self._stream_zero:
                raise ValueError(
                    f"recorder: a stream cannot restart in the past ({zero} < {self._stream_zero})"
                )
            self._stream_zero = zero

    def session_time(self, clock_time: float) -> float:
        """A time read from the recorder's clock, in seconds since the recording opened."""
        return clock_time - self.origin

    def stream_clock(self, t: float) -> float:
        """Stream time t on the recorder's clock."""
        return self._stream_zero + t

    def write(self, topic: str, t: float, payload: dict[str, Any]) -> None:
        """Record payload at stream time t; it is recorded with `t` = that time on the session clock."""
        with self._order:
            at = self._stream_zero - self.origin + t
        self._queue(topic, at, {**payload, "t": at})

    def write_now(self, topic: str, payload: dict[str, Any]) -> None:
        """Record payload at the clock's current time (stamped on arrival); its session-time fields are
        given on the clock."""
        with self._order:
            at = self.clock.now() - self.origin
        times = _session_time_paths(topic)
        self._queue(topic, at, _shifted(payload, times, -self.origin) if times else payload)

    def _queue(self, topic: str, offset_s: float, payload: dict) -> None:
        """Encode and queue a message; the flusher thread writes it. A writer (the 50 Hz control loop
        among them) never waits for compression or the disk."""
        if self._closed.is_set():
            return
        stamp = self.start_ns + int(round(offset_s * 1e9))
        self._pending.append((topic, stamp, json.dumps(payload, separators=(",", ":")).encode()))

    def flush(self) -> None:
        """Write the queued messages, close the chunk in progress and put it on disk."""
        with self._io:
            self._write_pending()
            self._writer.flush()
            os.fsync(self._stream.fileno())

    def _write_pending(self) -> None:
        while self._pending:
            topic, stamp, data = self._pending.popleft()
            channel = self._channel(topic)
            self._writer.add_message(channel_id=channel, log_time=stamp, publish_time=stamp, data=data)

    def _channel(self, topic: str) -> int:
        if topic not in self._channels:
            schema_id = self._writer.register_schema(
                name=FOXGLOVE_NAMES.get(topic, topic.strip("/").replace("/", ".")),
                encoding="jsonschema",
                data=json.dumps(_schema(topic)).encode(),
            )
            self._channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding="json", schema_id=schema_id
            )
        return self._channels[topic]

    def _flush_every(self) -> None:
        """flush() every FLUSH_S until close()."""
        while not self._closed.wait(FLUSH_S):
            self.flush()

    def close(self) -> None:
        with self._order:
            if self._closed.is_set():
                return
            self._closed.set()  # no more messages; the flusher stops
        self._flusher.join()
        with self._io:
            self._write_pending()
            self._writer.finish()
            self._stream.close()

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _schema(topic: str) -> dict:
    return SCHEMAS.get(topic, GENERIC_SCHEMA)


@functools.cache
def _session_time_paths(topic: str) -> list[tuple[str, ...]]:
    return session_time_paths(_schema(topic))


def _shifted(payload: dict, paths: list[tuple[str, ...]], by: float) -> dict:
    """A copy of payload with the number at each key path ("*": every item) moved by `by`; a non-finite
    one becomes null (JSON has no infinity)."""

    def move(value: Any, path: tuple[str, ...]) -> Any:
        if not path:
            return value + by if isinstance(value, (int, float)) and math.isfinite(value) else None
        if path[0] == "*":
            return [move(item, path[1:]) for item in value] if isinstance(value, list) else value
        if not isinstance(value, dict) or path[0] not in value:
            return value
        return {**value, path[0]: move(value[path[0]], path[1:])}

    for path in paths:
        payload = move(payload, path)
    return payload


def read_recording(path: str | Path) -> dict[str, list[tuple[float, dict]]]:
    """Load an MCAP written by Recorder: topic -> [(session time s, payload)] in log-time order (a file
    without the start record: s from its first message)."""
    from mcap.reader import make_reader

    by_topic: dict[str, list[tuple[int, dict]]] = defaultdict(list)
    with Path(path).open("rb") as f:
        reader = make_reader(f)
        for _schema, channel, message in reader.iter_messages(log_time_order=True):
            by_topic[channel.topic].append((message.log_time, json.loads(message.data)))
        start_ns = recording_start_ns(reader)
    if not by_topic:
        return {}
    start = start_ns if start_ns is not None else min(stamps[0][0] for stamps in by_topic.values())
    return {
        topic: [((stamp - start) / 1e9, payload) for stamp, payload in rows]
        for topic, rows in by_topic.items()
    }


def recording_start_ns(reader) -> int | None:
    """The wall time (ns) a Recorder's file opened: log time of session time 0; None if not recorded."""
    for record in reader.iter_metadata():
        if record.name == METADATA:
            return int(record.metadata["start_ns"])
    return None
