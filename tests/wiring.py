"""A hand-wired run without Hydra (tests that need no config): the six stages with their dependencies,
a session and a runner."""

from __future__ import annotations

from dataclasses import dataclass

from emopose.backends.dry_run import DryRunBackend
from emopose.clock import FakeClock
from emopose.execution.control_loop import ControlLoop
from emopose.execution.sequencer import Sequencer
from emopose.execution.trajectory import TrajectoryBuilder
from emopose.planners.baselines.keyword import KeywordPlanner
from emopose.speech.clip import EstimatedSpeech
from emopose.speech.player import Player
from emopose.stages.dispatch import Dispatch
from emopose.stages.modulate import Modulate
from emopose.stages.parse import Parse
from emopose.stages.resolve import Resolve
from emopose.stages.schedule import ScheduleStage
from emopose.stages.sequence import SequenceStage
from emopose.turn.pipeline import Pipeline
from emopose.turn.runner import TurnRunner
from emopose.turn.session import Session


@dataclass
class Wired:
    sequencer: Sequencer
    loop: ControlLoop
    player: Player
    stages: list
    session: Session
    runner: TurnRunner


def wire(library, run_dir, *, planner=None, synthesizer=None, backend=None, mode: str = "anchor",
         until: str = "rest", record: bool = True) -> Wired:
    clock = FakeClock()
    sequencer = Sequencer(TrajectoryBuilder(library.limits), library.neutral_entry.q[0])
    loop, player = ControlLoop(sequencer, backend or DryRunBackend(), clock), Player(sink="none")
    stages = [Parse(), Resolve(library), Modulate(library.limits),
              ScheduleStage(synthesizer or EstimatedSpeech(), library.limits, sequencer=sequencer, mode=mode),
              SequenceStage(sequencer, clock, player), Dispatch(loop, player, until=until)]
    session = Session(loop.backend, loop, library.neutral_entry.q[0], run_dir, record=record)
    runner = TurnRunner(planner or KeywordPlanner(), Pipeline(stages), session)
    return Wired(sequencer, loop, player, stages, session, runner)
