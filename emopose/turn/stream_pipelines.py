"""The pipelines a streamed reply runs its sentences through, derived from the configured one.

A streamed reply is spoken sentence by sentence while the model still writes (emopose/turn/runner.py,
TurnRunner.run_streamed). Each sentence runs the configured stages with three changes:
- dispatch never waits between sentences (the runner waits once, after the last, as configured), and
  from the second sentence on its audio follows the clip playing: sentence n+1's speech starts when
  sentence n's ends, or when it is ready if later, and its gestures are moved with it;
- from the second sentence on the sequence stage queues behind the gestures already handed over
  instead of interrupting them (the first does what the configured stage does with a new utterance);
- the first sentence's pre-roll is bounded by the planner's stream_preroll_s: the person has already
  waited for the model.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from emopose.stages.dispatch import Dispatch
from emopose.stages.schedule import ScheduleStage
from emopose.stages.sequence import SequenceStage
from emopose.turn.pipeline import Pipeline, Stage


@dataclass(frozen=True)
class StreamPipelines:
    first: Pipeline   # the first sentence
    rest: Pipeline    # every later sentence
    dispatch: Dispatch | None  # the configured stage: how to wait after the last sentence

    @classmethod
    def derive(cls, pipeline: Pipeline, preroll_s: float) -> StreamPipelines:
        dispatch = next((s for s in pipeline.stages if isinstance(s, Dispatch)), None)
        first = [_sentence_stage(s, first=True, preroll_s=preroll_s) for s in pipeline.stages]
        rest = [_sentence_stage(s, first=False, preroll_s=preroll_s) for s in pipeline.stages]
        return cls(Pipeline(first, pipeline.hooks, pipeline.inputs), Pipeline(rest, pipeline.hooks, pipeline.inputs),
                   dispatch)


def _sentence_stage(stage: Stage, *, first: bool, preroll_s: float) -> Stage:
    if isinstance(stage, Dispatch):
        return replace(stage, until="none", follow=not first)
    if isinstance(stage, SequenceStage) and not first:
        return replace(stage, interrupt=False)
    if isinstance(stage, ScheduleStage) and first and stage.timeline.max_preroll_s > preroll_s:
        return replace(stage, timeline=replace(stage.timeline, max_preroll_s=preroll_s))
    return stage
