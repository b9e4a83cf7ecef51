"""The run context: shared resources built once by build.py and handed to stages and jobs.

Execution resources (backend connection, control loop) open lazily in `open()`, so jobs that only
plan (the benchmarks) never touch a simulator or a robot.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from contextlib import nullcontext
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from emopose.backends.base import Backend
from emopose.clock import Clock
from emopose.control_loop import ControlLoop
from emopose.library import MotionLibrary
from emopose.pipeline import Pipeline, Turn
from emopose.planners.base import Planner, PlanRequest
from emopose.recording import Recorder
from emopose.sequencer import Sequencer
from emopose.speech.clip import SpeechClip, Synthesizer

log = logging.getLogger(__name__)


@dataclass
class RunContext:
    library: MotionLibrary
    planner: Planner
    pipeline: Pipeline
    backend: Backend
    sequencer: Sequencer
    clock: Clock
    speech: Synthesizer
    run_dir: Path
    record: bool = True
    player: object | None = None
    thinking: object | None = None  # emopose.thinking.ThinkingGesture: masks planner latency
    scene: object | None = None  # emopose.tour.scene_view.SceneView: what pointing can aim at (tour)
    recorder: Recorder | None = None
    loop: ControlLoop | None = None
    history: list[dict] = field(default_factory=list)

    # -- execution -----------------------------------------------------------------------------
    def open(self) -> ControlLoop:
        """Connect the backend and start the 50 Hz stream at the measured pose (idempotent)."""
        if self.loop is not None:
            return self.loop
        if self.record and self.recorder is None:
            self.recorder = Recorder(self.run_dir / "session.mcap")
        measured = self.backend.connect(self.recorder)
        q0 = self.library.neutral_entry.q[0] if measured is None else np.asarray(measured, dtype=float)
        self.loop = ControlLoop(self.sequencer, self.backend, self.clock, self.recorder)
        self.loop.begin(q0)
        return self.loop

    def close(self) -> None:
        try:
            if self.loop is not None:
                self.loop.stop()
            self.backend.close()
        finally:
            if self.recorder is not None:
                self.recorder.close()

    def __enter__(self) -> RunContext:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def start_speech(self, clip: SpeechClip) -> float:
        """Start playback (or the timed null sink) and return its start on the control clock."""
        if self.player is not None:
            return self.player.play(clip, self.clock)
        return self.clock.now()

    def wait_for(self, done: Callable[[], bool], timeout_s: float) -> bool:
        end = time.monotonic() + timeout_s
        while time.monotonic() < end:
            if done():
                return True
            if self.loop is not None and self.loop.error is not None:
                raise RuntimeError("control loop failed") from self.loop.error
            time.sleep(0.01)
        return False

    # -- one utterance -------------------------------------------------------------------------
    def new_turn(self, utterance: str, image: str | bytes | None = None, use_history: bool = True) -> Turn:
        history = tuple(self.history) if use_history else ()
        return Turn(PlanRequest(utterance=utterance, history=history, image=image))

    def run_turn(self, utterance: str, image: str | bytes | None = None) -> Turn:
        """Plan and execute one utterance through the whole pipeline, and log it to history and MCAP."""
        self.open()
        turn = self.new_turn(utterance, image)
        self.plan_turn(turn)
        self.pipeline.run(turn, self, self.planner)
        self.history.extend([{"role": "user", "content": utterance},
                             {"role": "assistant", "content": turn.plan.reply}])
        self.record_turn(turn)
        return turn

    def plan_turn(self, turn: Turn) -> None:
        """The planner call, wrapped in the optional thinking gesture that masks its latency."""
        masking = self.thinking.around_planning(self) if self.thinking is not None else nullcontext()
        with masking:
            turn.planner_output = self.planner.plan(turn.request)
        turn.stage_s["planner"] = turn.planner_output.latency_s

    def record_turn(self, turn: Turn) -> None:
        if self.recorder is None or self.loop is None:
            return
        t = self.loop.stream_time
        self.recorder.write("/plan", t, {"utterance": turn.request.utterance, "reply": turn.plan.reply,
                                         "source": turn.plan.source,
                                         "records": [r.as_json() for r in turn.plan.records]})
        if "resolved" in turn.values:
            self.recorder.write("/resolved", t, {"gestures": [r.audit() for r in turn.resolved]})
        if "schedule" in turn.values:
            s = turn.schedule
            self.recorder.write("/schedule", t, {
                "speech_duration_s": s.speech.duration_s,
                "releases": [{"name": g.name, "release_s": r.release_s, "how": r.how,
                              "trigger_found": r.trigger_found} for g, r in zip(s.gestures, s.releases)]})
