"""The served robot: one RunContext, a worker thread for turns, and a broadcast log for every page.

Turns (planning, TTS, the pipeline) run on one worker thread, so the event loop never blocks and
turns never overlap (ctx.history is appended in order); the control loop ticks on its own thread.
Everything a page must hear about (turns, interruptions, saved motions) goes into one bounded log
with increasing ids; each WebSocket sends what it has not sent yet, so every open page agrees.
"""

from __future__ import annotations

import asyncio
import itertools
import json
import threading
import time
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from emopose.contract import GestureRecord
from emopose.planners.base import PlannerOutput
from emopose.studio.authoring import PoseStudio
from emopose.web.settings import ServeSettings
from emopose.web.stick_figure import stick_figure
from emopose.web.turns import summarize_turn


class UnknownMotion(LookupError):
    pass


class LiveSession:
    def __init__(self, ctx, settings: ServeSettings, renderer=None, frames=None, webcam=None) -> None:
        self.ctx, self.settings = ctx, settings
        self.renderer, self.frames, self.webcam = renderer, frames, webcam
        self.studio = PoseStudio.from_context(ctx)
        self.asr = getattr(ctx, "asr", None)  # a Recognizer when the config adds one (mic button)
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="emopose-turn")
        self._lock = threading.Lock()
        self._log: deque[dict] = deque(maxlen=settings.max_turns_kept)
        self._next_id = 1
        self._turn_ids = itertools.count(1)
        self._audio: dict[int, Path] = {}
        self._stick: tuple[float, dict] | None = None

    # -- turns (called from the event loop; the work runs on the worker thread) ----------------
    async def say(self, text: str, image: bytes | None = None) -> dict:
        return await self._on_worker(self._say, text, image)

    async def gesture(self, name: str, intensity: int = 3, text: str | None = None) -> dict:
        return await self._on_worker(self._gesture, name, intensity, text)

    async def transcribe(self, audio_path: Path) -> str:
        return await asyncio.get_running_loop().run_in_executor(
            None, lambda: self.asr.utterance(audio=audio_path))

    async def _on_worker(self, fn, *args) -> dict:
        return await asyncio.get_running_loop().run_in_executor(self._worker, fn, *args)

    def _say(self, text: str, image: bytes | None) -> dict:
        self.publish({"type": "turn_started", "utterance": text})
        return self._publish_turn(self.ctx.run_turn(text, image), "say")

    def _gesture(self, name: str, intensity: int, text: str | None) -> dict:
        """One record naming the variant, through parse..dispatch like any plan (no planner call)."""
        entry = self.ctx.library.get(name)  # the live library: a motion saved a moment ago is here
        if entry is None:
            raise UnknownMotion(f"no motion named {name!r} in the library (version {self.ctx.library.version})")
        record = GestureRecord(cls=entry.cls, variant=name, intensity=intensity, confidence=1.0)
        turn = self.ctx.new_turn(text or name.replace("_", " "), use_history=False)
        raw = json.dumps({"reply": text or "", "gestures": [record.as_json()]})
        turn.planner_output = PlannerOutput(raw=raw, meta={"source": "web gesture"})
        self.ctx.open()
        self.ctx.pipeline.run(turn, self.ctx)
        self.ctx.record_turn(turn)
        return self._publish_turn(turn, "gesture")

    def _publish_turn(self, turn, kind: str) -> dict:
        turn_id = next(self._turn_ids)
        schedule = turn.values.get("schedule")
        audio = schedule.speech.audio_path if schedule is not None else None
        url = None
        if audio is not None and Path(audio).is_file():
            self._audio[turn_id] = Path(audio)
            url = f"/api/audio/{turn_id}"
        return self.publish(summarize_turn(turn, turn_id, kind, url, self.ctx.library.version))

    def interrupt(self) -> dict:
        self.ctx.sequencer.interrupt([], now=self.ctx.clock.now())
        if self.ctx.player is not None:
            self.ctx.player.stop()
        return self.publish({"type": "interrupted"})

    # -- broadcast log -------------------------------------------------------------------------
    def publish(self, message: dict) -> dict:
        with self._lock:
            message = {**message, "id": self._next_id, "server_now": self.ctx.clock.now()}
            self._next_id += 1
            self._log.append(message)
        return message

    def log_since(self, last_id: int) -> list[dict]:
        with self._lock:
            return [m for m in self._log if m["id"] > last_id]

    def audio_path(self, turn_id: int) -> Path | None:
        return self._audio.get(turn_id)

    # -- live state ----------------------------------------------------------------------------
    def pose(self) -> tuple[np.ndarray, np.ndarray | None]:
        """(14 joint angles, the simulator's full qpos or None): what the robot is doing now."""
        data = getattr(self.ctx.backend, "data", None)  # MuJoCo: the simulated state, base included
        qpos = np.array(data.qpos) if data is not None else None
        q = self.ctx.backend.measured()
        return (self.ctx.sequencer.last.copy() if q is None else np.asarray(q, float)), qpos

    def status(self, events_from: int = 0) -> dict:
        seq, clock = self.ctx.sequencer, self.ctx.clock
        now = clock.now()
        active = seq.active
        events = seq.events[events_from:]
        loop = self.ctx.loop
        return {
            "type": "state", "server_now": now, "state": seq.state.value,
            "active": None if active is None else {"name": active.name, "label": active.label, "id": active.id},
            "pending": [{"name": c.name, "label": c.label, "release_in_s": round(c.release_at - now, 3)}
                        for c in seq.pending],
            "events": [{"t": e.t, "kind": e.kind, "name": e.name, "detail": e.detail} for e in events],
            "events_next": events_from + len(events),
            "loop": None if loop is None else {"running": loop.running, "ticks": loop.stats.ticks,
                                               "missed": loop.stats.missed_deadlines},
            "library_version": self.ctx.library.version, "stick": self._stick_now(),
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
            "backend": self.ctx.backend.name, "planner": self.ctx.planner.name,
            "tts": getattr(self.ctx.speech, "name", "?"), "library_version": self.ctx.library.version,
            "asr": self.asr is not None and getattr(self.asr, "name", "none") != "none",
            "channels": {name: c.source for name, c in channels.items()},
            "render": self.renderer is not None and self.renderer.available,
            "render_error": None if self.renderer is None else self.renderer.error,
        }

    def close(self) -> None:
        self._worker.shutdown(wait=True, cancel_futures=True)
        for part in (self.frames, self.webcam):
            if part is not None:
                (part.stop if hasattr(part, "stop") else part.close)()
        if self.renderer is not None:
            self.renderer.close()
