"""The served robot: one Run, a worker thread for turns, and a broadcast log for every page.

Turns (planning, TTS, the pipeline) run through the run's TurnRunner on one worker thread, so the event
loop never blocks and turns never overlap (the runner's dialogue grows in order); the control
loop ticks on its own thread. A streamed reply publishes each sentence as a turn once it is handed over.
Everything a page must hear about (turns, interruptions, saved motions) goes into one bounded log
with increasing ids; each WebSocket sends what it has not sent yet, so every open page agrees.
A turn is published before its gestures start; when the sequencer later rejects or drops one, the
turn's cue in the log gets its outcome and a `cue_outcome` message tells the open pages.
"""

from __future__ import annotations

import asyncio
import itertools
import threading
import time
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from emopose.backends.capabilities import SimulatedState
from emopose.contract import EventKind, GestureRecord, LibraryEntry, Plan
from emopose.resources import Run
from emopose.studio.authoring import PoseStudio
from emopose.turn.model import ResolvedGesture, Turn
from emopose.web.settings import ServeSettings
from emopose.web.stick_figure import stick_figure
from emopose.web.turns import outcome_of, summarize_turn

TRACKED_COMMANDS = 2048  # command ids remembered for late outcomes (far more than the log's turns hold)


class UnknownMotion(LookupError):
    pass


class LiveSession:
    def __init__(self, run: Run, settings: ServeSettings, renderer=None, frames=None, webcam=None) -> None:
        self.run, self.res, self.settings = run, run.resources, settings
        self.renderer, self.frames, self.webcam = renderer, frames, webcam
        res = self.res
        self.studio = PoseStudio(res.library, res.pipeline.get("modulate"), res.sequencer.safety)
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="emopose-turn")
        self._lock = threading.Lock()
        self._log: deque[dict] = deque(maxlen=settings.max_turns_kept)
        self._next_id = 1
        self._turn_ids = itertools.count(1)
        self._audio: dict[int, Path] = {}
        self._stick: tuple[float, dict] | None = None
        self._outcome_lock = threading.Lock()
        self._events_seen = res.sequencer.events.total
        self._cue_of: dict[int, tuple[dict, int]] = {}  # command id -> (published turn message, cue index)
        self._refusals: dict[int, dict] = {}  # command id -> outcome (may precede its turn)
        self._strokes: dict[int, float] = {}  # command id -> clock time its stroke arrived

    # -- turns (called from the event loop; the work runs on the worker thread) ----------------
    async def say(self, text: str, image: bytes | None = None) -> dict:
        return await self._on_worker(self._say, text, image)

    async def gesture(self, name: str, intensity: int = 3, text: str | None = None) -> dict:
        return await self._on_worker(self._gesture, name, intensity, text)

    async def perform_draft(self, entry: LibraryEntry, intensity: int) -> dict:
        return await self._on_worker(self._perform_draft, entry, intensity)

    @property
    def hears_speech(self) -> bool:
        """True when the configured ASR transcribes audio (asr=litellm): the page shows its microphone."""
        return self.res.asr is not None and self.res.asr.accepts_audio

    async def transcribe(self, audio_path: Path) -> str:
        return await asyncio.get_running_loop().run_in_executor(
            None, lambda: self.res.asr.utterance(audio=audio_path))

    async def _on_worker(self, fn, *args) -> dict:
        return await asyncio.get_running_loop().run_in_executor(self._worker, fn, *args)

    def _say(self, text: str, image: bytes | None) -> dict:
        self.publish({"type": "turn_started", "utterance": text})
        published: list[dict] = []
        reply = self.run.runner.respond(text, image, lambda t: published.append(self._publish_turn(t, "say")))
        whole = published and reply.error is None and not reply.cancelled
        stopped = {"type": "reply_stopped", "error": reply.error, "cancelled": reply.cancelled}
        return published[-1] if whole else self.publish({**stopped, "sentences": len(published)})

    def _gesture(self, name: str, intensity: int, text: str | None) -> dict:
        """One record naming the variant, from resolve to dispatch like any plan (no planner call)."""
        library = self.res.library  # the live library: a motion saved a moment ago is here
        entry = library.get(name)
        if entry is None:
            raise UnknownMotion(f"no motion named {name!r} in the library (version {library.version})")
        record = GestureRecord(cls=entry.cls, variant=name, intensity=intensity, confidence=1.0)
        turn = self.run.runner.run_plan(Plan.scripted(text or "", record))  # silent unless given words
        return self._publish_turn(turn, "gesture")

    def _perform_draft(self, entry: LibraryEntry, intensity: int) -> dict:
        """A Pose Studio draft, in no library: from modulation to dispatch like a resolved record, so the
        joint limits and the sequencer's self-collision check judge it as they judge any gesture."""
        record = GestureRecord(cls=entry.cls, intensity=intensity, confidence=1.0)
        resolved = [ResolvedGesture(record, entry, "exact")]
        turn = self.run.runner.run_plan(Plan.scripted("", record), resolved=resolved)
        return self._publish_turn(turn, "draft")

    def _publish_turn(self, turn: Turn, kind: str) -> dict:
        turn_id = next(self._turn_ids)
        audio = turn.speech.audio_path if turn.speech is not None else None
        url = None
        if audio is not None and Path(audio).is_file():
            self._audio[turn_id] = Path(audio)
            url = f"/api/audio/{turn_id}"
        message = self.publish(summarize_turn(turn, turn_id, kind, url, self.res.library.version))
        with self._outcome_lock:
            ids = [cue["command_id"] for cue in message["cues"]]
            for k, command_id in enumerate(ids):
                if command_id is not None:
                    _remember(self._cue_of, command_id, (message, k))
            landed = [self._land(command_id) for command_id in ids if command_id in self._refusals]
            landed += [self._land_stroke(command_id) for command_id in ids if command_id in self._strokes]
        self._publish_outcomes(landed)
        return message

    def _track_outcomes(self) -> None:
        """Put the sequencer's new rejections, drops and arrived strokes on their published cues (and
        tell the pages).

        A refusal may come before its turn is published (then _publish_turn lands it); an event read
        twice (appended while the cursor moved) lands once."""
        events = self.res.sequencer.events
        with self._outcome_lock:
            cursor, self._events_seen = self._events_seen, events.total
            landed = []
            for event in events.since(cursor):
                if event.kind == EventKind.STROKE and event.command_id is not None:
                    _remember(self._strokes, event.command_id, event.t)
                    landed.append(self._land_stroke(event.command_id))
                    continue
                outcome = outcome_of({"kind": event.kind, "detail": event.detail})
                if outcome is not None and event.command_id is not None:
                    _remember(self._refusals, event.command_id, outcome)
                    landed.append(self._land(event.command_id))
        self._publish_outcomes(landed)

    def _land(self, command_id: int) -> dict | None:
        """Set a refused command's outcome on its published cue; the page message, or None (caller locks)."""
        message, k = self._cue_of.get(command_id, (None, None))
        if message is None or message["cues"][k]["outcome"] is not None:
            return None
        outcome = message["cues"][k]["outcome"] = self._refusals[command_id]
        return {"type": "cue_outcome", "turn_id": message["turn_id"], "k": k, "outcome": outcome}

    def _land_stroke(self, command_id: int) -> dict | None:
        """Put an arrived stroke's time (from speech start) on its published cue; the page message."""
        message, k = self._cue_of.get(command_id, (None, None))
        cue = None if message is None else message["cues"][k]
        if cue is None or cue["stroke_executed_s"] is not None or message["speech_start"] is None:
            return None
        executed = cue["stroke_executed_s"] = self._strokes[command_id] - message["speech_start"]
        return {"type": "cue_stroke", "turn_id": message["turn_id"], "k": k, "executed_s": executed}

    def _publish_outcomes(self, landed: list[dict | None]) -> None:
        for update in filter(None, landed):
            self.publish(update)

    def interrupt(self) -> dict:
        self.run.runner.silence()
        return self.publish({"type": "interrupted"})

    # -- broadcast log -------------------------------------------------------------------------
    def publish(self, message: dict) -> dict:
        with self._lock:
            message = {**message, "id": self._next_id, "server_now": self.res.clock.now()}
            self._next_id += 1
            self._log.append(message)
        return message

    def log_since(self, last_id: int) -> list[dict]:
        self._track_outcomes()
        with self._lock:
            return [m for m in self._log if m["id"] > last_id]

    def audio_path(self, turn_id: int) -> Path | None:
        return self._audio.get(turn_id)

    # -- live state ----------------------------------------------------------------------------
    def pose(self) -> tuple[np.ndarray, np.ndarray | None]:
        """(14 joint angles, the simulator's full qpos or None): what the robot is doing now."""
        backend = self.res.backend
        data = backend.data if isinstance(backend, SimulatedState) else None  # the full state, base included
        qpos = np.array(data.qpos) if data is not None else None
        q = self.res.backend.measured()
        return (self.res.sequencer.last.copy() if q is None else np.asarray(q, float)), qpos

    def status(self, events_from: int = 0) -> dict:
        seq, clock = self.res.sequencer, self.res.clock
        self._track_outcomes()
        now, active = clock.now(), seq.active
        events, events_next = seq.events.read(events_from)
        session = self.run.session
        return {
            "type": "state", "server_now": now, "state": seq.state.value,
            "active": None if active is None
            else {"name": active.name, "label": active.label, "id": active.id},
            "pending": [{"name": c.name, "label": c.label, "release_in_s": round(c.release_at - now, 3)}
                        for c in seq.pending],
            "events": [{"t": e.t, "kind": e.kind, "name": e.name, "detail": e.detail} for e in events],
            "events_next": events_next,
            "loop": None if not session.is_open else {"running": session.loop.running,
                                                      "missed": session.loop.stats.missed_deadlines,
                                                      **session.loop.stats.summary()},
            "library_version": self.res.library.version, "stick": self._stick_now(),
        }

    def _stick_now(self) -> dict:
        """Forward kinematics once per 40 ms however many pages ask (it costs ~3 ms)."""
        cached = self._stick
        if cached is None or time.monotonic() - cached[0] > 0.04:
            cached = (time.monotonic(), stick_figure(self.pose()[0]))
            self._stick = cached
        return cached[1]

    def info(self) -> dict:
        channels = self.frames.channels if self.frames is not None else {}
        return {
            "backend": self.res.backend.name, "planner": self.res.planner.name,
            "tts": self.res.synthesizer.name, "library_version": self.res.library.version,
            "asr": self.hears_speech, "channels": {name: c.source for name, c in channels.items()},
            "render": self.renderer is not None and self.renderer.available,
            "render_error": None if self.renderer is None else self.renderer.error,
        }

    def close(self) -> None:
        self._worker.shutdown(wait=True, cancel_futures=True)
        if self.frames is not None:
            self.frames.stop()
        if self.webcam is not None:
            self.webcam.close()
        if self.renderer is not None:
            self.renderer.close()


def _remember(table: dict, key: int, value: object) -> None:
    """Insert into a dict kept to the TRACKED_COMMANDS newest keys (dicts keep insertion order)."""
    table[key] = value
    while len(table) > TRACKED_COMMANDS:
        del table[next(iter(table))]
