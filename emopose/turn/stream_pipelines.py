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

from dataclasses import dataclass

from emopose.stages.dispatch import Dispatch
from emopose.turn.pipeline import Pipeline


@dataclass(frozen=True)
class StreamPipelines:
    first: Pipeline   # the first sentence
    rest: Pipeline    # every later sentence
    dispatch: Dispatch | None  # the configured stage: how to wait after the last sentence

    @classmethod
    def derive(cls, pipeline: Pipeline, preroll_s: float) -> StreamPipelines:
        first = pipeline.reconfigured(schedule=lambda stage: stage.with_preroll_at_most(preroll_s),
                                      dispatch=lambda stage: stage.streamed(follow=False))
        rest = pipeline.reconfigured(sequence=lambda stage: stage.queueing(),
                                     dispatch=lambda stage: stage.streamed(follow=True))
        return cls(first, rest, pipeline.get("dispatch"))
