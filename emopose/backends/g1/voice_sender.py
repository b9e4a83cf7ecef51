"""VoiceSender: the one thread that talks to the robot's voice service for the G1 player.

Chunks go out at their send times (voice.chunk_schedule), a stop (api 1004) goes out in order with
them: a stop requested before a new reply's chunks were queued reaches the robot before them, so it
can never cut the new reply (1004 names the app, not the stream). play() and stop() only queue and
return. A refused or unanswered chunk drops the rest of its stream with one warning and reports the
failure (the player then falls back); nothing raises into the turn.
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from emopose.backends.g1.voice import VoiceClient
from emopose.clock import Clock
from emopose.execution.worker import Worker

log = logging.getLogger(__name__)
IDLE_WAIT_S = 0.1  # how often an idle sender looks at its stop flag


@dataclass(frozen=True)
class Chunk:
    stream_id: str
    pcm: bytes
    send_at: float
    play_at: float


class VoiceSender:
    def __init__(self, voice: VoiceClient, app_name: str, on_failure: Callable[[Exception], None]) -> None:
        self.voice, self.app_name, self.on_failure = voice, app_name, on_failure
        self._changed = threading.Condition()
        self._chunks: deque[Chunk] = deque()
        self._clock: Clock | None = None
        self._stop_pending = False
        self._sent_since_stop = False
        self.chunks_sent = self.stops_sent = self.failures = 0
        self._worker = Worker("emopose-g1-voice", self._run, join_timeout_s=2.0)

    def queue(self, chunks: list[Chunk], clock: Clock) -> None:
        with self._changed:
            self._clock = clock
            self._chunks.extend(chunks)
            self._changed.notify_all()
        self._worker.start()

    def stop(self) -> None:
        """Drop every chunk not sent yet and stop the robot's playback (at once, in order)."""
        with self._changed:
            self._chunks.clear()
            self._stop_pending = True
            self._changed.notify_all()

    @property
    def idle(self) -> bool:
        with self._changed:
            return not self._chunks and not self._stop_pending

    def close(self) -> None:
        self._worker.stop()

    def _run(self, stopped: threading.Event) -> None:
        while not stopped.is_set():
            job = self._next()
            if job is None:
                continue
            try:
                self._send(job)
            except Exception as exc:  # noqa: BLE001 - the voice link failing must never reach the turn
                self._failed(job, exc)

    def _next(self) -> Chunk | str | None:
        """The next thing to send when it is due ("stop" or a Chunk), or None after a short wait."""
        with self._changed:
            if self._stop_pending:
                self._stop_pending = False
                return "stop" if self._sent_since_stop else None
            if not self._chunks:
                self._changed.wait(IDLE_WAIT_S)
                return None
            wait_s = self._chunks[0].send_at - self._clock.now()
            if wait_s > 0:
                self._changed.wait(min(wait_s, IDLE_WAIT_S))
                return None
            return self._chunks.popleft()

    def _send(self, job: Chunk | str) -> None:
        if job == "stop":
            self.voice.stop_play(self.app_name)
            self.stops_sent += 1
            self._sent_since_stop = False
            return
        self._sent_since_stop = True  # even a chunk that fails may have reached the robot
        self.voice.play_chunk(self.app_name, job.stream_id, job.pcm)
        self.chunks_sent += 1

    def _failed(self, job: Chunk | str, exc: Exception) -> None:
        self.failures += 1
        if job == "stop":
            log.warning("player=g1: stop play was not confirmed (%s); the robot may finish the clip", exc)
            return
        with self._changed:
            dropped = sum(1 for c in self._chunks if c.stream_id == job.stream_id)
            self._chunks = deque(c for c in self._chunks if c.stream_id != job.stream_id)
        # the detail only: on_failure gives the one warning (the player's fallback)
        log.info("player=g1: an audio chunk of stream %s failed (%s: %s); its %d later chunk(s) are "
                 "not sent, the arms keep their timing", job.stream_id, type(exc).__name__, exc, dropped)
        self.on_failure(exc)
