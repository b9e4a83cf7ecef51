"""What a job runs with: the immutable resources built once, the session and the turn runner.

`Resources` is frozen: nothing writes a slot into it after build.py made it. The `Session` owns
everything with a lifecycle (recorder, backend connection, control loop); the `TurnRunner` runs turns.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from emopose.backends.base import Backend
from emopose.clock import Clock
from emopose.execution.sequencer import Sequencer
from emopose.library import MotionLibrary
from emopose.planners.base import Planner
from emopose.scene.view import SceneSlot
from emopose.speech.asr import Recognizer
from emopose.speech.clip import Synthesizer
from emopose.speech.player import Player
from emopose.turn.pipeline import Pipeline
from emopose.turn.runner import TurnRunner
from emopose.turn.session import Session


@dataclass(frozen=True)
class Resources:
    library: MotionLibrary
    planner: Planner
    pipeline: Pipeline
    backend: Backend
    sequencer: Sequencer
    clock: Clock
    synthesizer: Synthesizer
    player: Player
    asr: Recognizer | None
    scene: SceneSlot
    run_dir: Path


@dataclass(frozen=True)
class Run:
    """A job's whole world; `with run:` releases the robot and closes the recording on the way out."""

    resources: Resources
    session: Session
    runner: TurnRunner

    def __enter__(self) -> Run:
        return self

    def __exit__(self, *exc: object) -> None:
        self.session.close()
