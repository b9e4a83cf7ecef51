"""The served robot: one Run, a worker thread for turns, and a broadcast log for every page.

Turns (planning, TTS, the pipeline) run through the run's TurnRunner on one worker thread, so the event
loop never blocks and turns never overlap (the runner's dialogue grows in order); the control
loop ticks on its own thread. A streamed reply publishes each sentence as a turn once it is handed over.
Everything a page must hear about (turns, interruptions, saved motions, a failed planner call) goes into
one bounded log with increasing ids; each WebSocket sends what it has not sent yet, so every open page
agrees. A turn is published before its gestures start; what the sequencer later does with its gestures
reaches its cues through emopose/web/cue_outcomes.py. Every published message is also counted (every
turn, however long the session: emopose/web/serve_tally.py), and the runner's dialogue reads the window
serve.history_turns / serve.history_tokens (emopose/turn/dialogue.py).
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
from emopose.contract import GestureRecord, LibraryEntry, Plan
from emopose.resources import Run
from emopose.stages.parse import MAX_SPOKEN_CHARS
from emopose.studio.authoring import PoseStudio
from emopose.turn.dialogue import HistoryWindow
from emopose.turn.model import ResolvedGesture, Turn
from emopose.turn.planning_call import PlanningCancelled
from emopose.turn.runner import StreamedReply
from emopose.web.clients import Clients
from emopose.web.cue_outcomes import CueOutcomes, remember
from emopose.web.planning import PendingPlan, cancelled, narrates
from emopose.web.report import SessionReport
from emopose.web.serve_tally import SOURCE_WORDS, TurnTally, failure_banner
from emopose.web.settings import ServeSettings
from emopose.web.stick_figure import stick_figure
from emopose.web.turns import summarize_turn
from emopose.web.voice_io import VoiceIO

SHARED_STATE_S = 0.04  # pages share a state this fresh (the stick figure's kinematics cost ~3 ms)


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
        self._audio: dict[int, Path] = {}  # the newest turns' WAVs (bounded like the outcome tables)
        self._shared_state: tuple[float, dict] | None = None  # (monotonic time, state without events)
        self.outcomes = CueOutcomes(res.sequencer.events, self.publish)
        self.clients = Clients(settings)
        self.tally = TurnTally(run.session.run_dir / "turns.jsonl")
        self.planner_failure: dict | None = None  # the newest planned turn's failed call, for a banner
        self.pending = PendingPlan(run.runner)  # the line being planned: its time, retries and Cancel
        self.report = SessionReport(run.session.run_dir, run.session.record, res.library.limits)
        run.runner.dialogue.window = HistoryWindow(settings.history_turns, settings.history_tokens)
        self.voice = VoiceIO(self)  # the microphone (VAD, barge-in) and the G1's chest light

    # -- turns (called from the event loop; the work runs on the worker thread) ----------------
    async def say(self, text: str, image: bytes | None = None) -> dict:
        return await self._on_worker(self._say, text, image)

    async def gesture(self, name: str, intensity: int = 3, text: str | None = None) -> dict:
        return await self._on_worker(self._gesture, name, intensity, text)

    async def perform_draft(self, entry: LibraryEntry, intensity: int) -> dict:
        return await self._on_worker(self._perform_draft, entry, intensity)

    @property
    def hears_speech(self) -> bool:
        """True when the configured ASR transcribes audio (asr=whisper or litellm): the page shows a mic."""
        return self.res.asr is not None and self.res.asr.accepts_audio

    async def transcribe(self, audio_path: Path) -> str:
        return await asyncio.get_running_loop().run_in_executor(
            None, lambda: self.res.asr.utterance(audio=audio_path))

    async def _on_worker(self, fn, *args) -> dict:
        return await asyncio.get_running_loop().run_in_executor(self._worker, fn, *args)

    def _say(self, text: str, image: bytes | None, preroll_at_most: float | None = None) -> dict:
        started = self.pending.begin(lambda: self.publish({"type": "turn_started", "utterance": text}))
        published: list[dict] = []

        def on_turn(turn: Turn) -> None:
            published.append(self._publish_turn(turn, "say"))
            self.pending.end(started)

        try:
            reply = self.run.runner.respond(text, image, on_turn, preroll_at_most)
        except PlanningCancelled:
            reply = StreamedReply([], cancelled=True)
        finally:
            self.pending.end(started)
        if reply.cancelled and not published:  # nothing said or done; out of the dialogue; counted
            return self.publish(cancelled(started, next(self._turn_ids), self.res.clock.now()))
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
            remember(self._audio, turn_id, Path(audio))
            url = f"/api/audio/{turn_id}"
        message = self.publish(summarize_turn(turn, turn_id, kind, url, self.res.library.version))
        self.outcomes.track_turn(message)
        if turn.planner_output is not None:  # planned (not scripted): the banner follows the newest call
            failed = turn.planner_output.fallback
            self.planner_failure = failure_banner(turn_id, turn.planner_output.error) if failed else None
            if failed:
                self.publish(self.planner_failure)
        return message

    def hear(self, pcm: bytes) -> bool:
        """The page's microphone (16 kHz mono int16); False when this session does not listen."""
        return self.voice.hear(pcm)

    def say_heard(self, audio_path: Path) -> None:
        """An utterance the microphone's VAD ended: transcribed and said on the turn worker, in order."""
        self._worker.submit(self._say_heard, audio_path)

    def _say_heard(self, audio_path: Path) -> None:
        try:
            text = self.voice.transcript(audio_path)
            if text:
                self._say(text, None, self.voice.reply_preroll_s)
        except Exception as exc:  # noqa: BLE001 - no page waits on this turn: every page hears why
            problem = f"spoken turn failed: {type(exc).__name__}: {exc}"
            self.publish({"type": "error", "message": problem[:300]})

    def interrupt(self) -> dict:
        self.run.runner.silence()
        return self.publish({"type": "interrupted"})

    # -- broadcast log -------------------------------------------------------------------------
    def publish(self, message: dict) -> dict:
        with self._lock:
            message = {**message, "id": self._next_id, "server_now": self.res.clock.now()}
            self._next_id += 1
            self._log.append(message)
            self.tally.observe(message)
        return message

    def log_since(self, last_id: int) -> list[dict]:
        self.outcomes.track()
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

    def status(self, events_from: int = 0, shared: bool = False) -> dict:
        """The live state with the sequencer's events from `events_from` on. `shared` (a page's push): the
        rest as computed for any page at most SHARED_STATE_S ago, so many pages cost what one does."""
        self.outcomes.track()
        events, events_next = self.res.sequencer.events.read(events_from)
        cached = self._shared_state
        if not shared or cached is None or time.monotonic() - cached[0] > SHARED_STATE_S:
            cached = self._shared_state = (time.monotonic(), self._state())
        return {**cached[1], "events_next": events_next,
                "events": [{"t": e.t, "kind": e.kind, "name": e.name, "detail": e.detail} for e in events]}

    def _state(self) -> dict:
        seq, now, session = self.res.sequencer, self.res.clock.now(), self.run.session
        active = seq.active
        return {
            "type": "state", "server_now": now, "state": seq.state.value,
            "active": None if active is None
            else {"name": active.name, "label": active.label, "id": active.id},
            "pending": [{"name": c.name, "label": c.label, "release_in_s": round(c.release_at - now, 3)}
                        for c in seq.pending],
            "loop": None if not session.is_open else {"running": session.loop.running,
                                                      "missed": session.loop.stats.missed_deadlines,
                                                      **session.loop.stats.summary()},
            "library_version": self.res.library.version, "stick": stick_figure(self.pose()[0]),
            "clients": self.clients.counters(), "planner_failure": self.planner_failure,
            "planning": self.pending.state(),  # the line being planned: since when, retries so far
            "voice": self.voice.state(),  # the microphone's VAD (None: this session does not listen)
        }

    def info(self) -> dict:
        channels = self.frames.channels if self.frames is not None else {}
        return {
            "backend": self.res.backend.name, "planner": self.res.planner.name,
            "tts": self.res.synthesizer.name, "library_version": self.res.library.version,
            "asr": self.hears_speech, "channels": {name: c.source for name, c in channels.items()},
            "render": self.renderer is not None and self.renderer.available,
            "render_error": None if self.renderer is None else self.renderer.error,
            "sources": SOURCE_WORDS,  # each plan source in words a visitor reads
            "narrates": narrates(self.res.planner),  # the page's mode hint before the first turn
            "limits": {"utterance_chars": MAX_SPOKEN_CHARS, "max_clients": self.settings.max_clients},
            "history": {"turns": self.settings.history_turns, "tokens": self.settings.history_tokens},
            "report": self.report.info(),  # this session's recording and the command that reports on it
        }

    def close(self) -> None:
        self.voice.close()
        self._worker.shutdown(wait=True, cancel_futures=True)
        if self.frames is not None:
            self.frames.stop()
        if self.webcam is not None:
            self.webcam.close()
        if self.renderer is not None:
            self.renderer.close()

