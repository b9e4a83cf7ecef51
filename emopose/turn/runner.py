"""The turn runner: the one function that runs a turn, for every caller (jobs, web UI, tour, suites).

It owns the planner call (always wrapped in the thinking gesture when one is configured), the stages,
the dialogue (emopose/turn/dialogue.py) and the recording: a pipeline hook writes every value a stage
produces to its MCAP channel (`/plan`, `/resolved`, ...) as `Turn.field_json` serialises it, the moment
it exists.
A scripted Plan (a suite item, a button in the web UI, a robot check) enters at the first stage that
reads a plan, with no planner call and no JSON round trip.
A streaming planner's reply (run_streamed) is performed sentence by sentence while the model writes:
each sentence is a Turn of its own, recorded like any other (emopose/turn/stream_pipelines.py).
silence() is the one way to stop talking and clear the gestures (an interrupt, a visitor's question).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager, nullcontext
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

from emopose.contract import Plan
from emopose.execution.posture import THINKING
from emopose.llm.errors import LLMCallError
from emopose.planners.base import Planner, PlanRequest
from emopose.planners.streaming import SentencePlans, StreamingPlanner
from emopose.stages.dispatch import Dispatch
from emopose.sync.recording import TIMELINE, speech_timeline
from emopose.turn.dialogue import Dialogue
from emopose.turn.model import ResolvedGesture, Turn
from emopose.turn.pipeline import Pipeline, PipelineError, Stage
from emopose.turn.planning_call import AbandonableCall
from emopose.turn.session import Session
from emopose.turn.stream_pipelines import StreamPipelines
from emopose.turn.thinking import ThinkingGesture


@dataclass
class TurnRunner:
    planner: Planner
    pipeline: Pipeline
    session: Session
    thinking: ThinkingGesture | None = None
    dialogue: Dialogue = field(default_factory=Dialogue)

    def __post_init__(self) -> None:
        self._recorded = self.pipeline.with_hooks(self._recording_hook)
        self.dialogue.on_message = self.session.write  # each message once, on /dialogue
        self._stream: SentencePlans | None = None  # the reply streaming now, for cancel()
        self._stream_lock = threading.Lock()
        # the planner call under way (or announced: expect()), for cancel_planning()
        self.planner_call = AbandonableCall()
        self._planning = 0  # planner calls under way (the chest light's "thinking")

    def with_pipeline(self, pipeline: Pipeline) -> TurnRunner:
        """The same runner (session, planner, dialogue) running other stages: a suite's variant."""
        return replace(self, pipeline=pipeline)

    def run(self, utterance: str, image: str | bytes | None = None, *, planner: Planner | None = None,
            question: str | None = None, remember: bool = True, preroll_at_most: float | None = None) -> Turn:
        """Plan and execute one utterance through the whole pipeline; it joins the dialogue as an exchange.

        `planner` replaces the configured one for this turn (the tour answers visitors with a sibling);
        `question` and `remember=False` are the tour's, which says prepared lines and adds to the dialogue
        what was actually said (Dialogue.request, Dialogue.said). `preroll_at_most` bounds the timeline's
        pre-roll for a reply the person has already waited for (a spoken one: asr.listening)."""
        self.session.open()
        turn = Turn(self.dialogue.request(utterance, image, question))
        self._record(turn, "request")
        self.plan(turn, planner or self.planner)
        pipeline = self._recorded if preroll_at_most is None else self._recorded.reconfigured(
            schedule=lambda stage: stage.with_preroll_at_most(preroll_at_most))
        pipeline.run(turn)
        if remember:
            self.dialogue.exchange(utterance, turn.plan.reply)
        return turn

    @property
    def planning(self) -> bool:
        """True while a planner call (or a streamed reply's first sentence) is under way. Any thread."""
        return self._planning > 0

    @contextmanager
    def _planning_now(self) -> Iterator[None]:
        self._planning += 1
        try:
            with self.session.loop.sequencer.posture.holding(THINKING):  # the arms between gestures
                yield
        finally:
            self._planning -= 1

    @property
    def streams(self) -> bool:
        """True when the configured planner speaks its replies sentence by sentence (run_streamed)."""
        return isinstance(self.planner, StreamingPlanner) and self.planner.streams

    def respond(self, utterance: str, image: str | bytes | None = None,
                on_turn: Callable[[Turn], None] | None = None,
                preroll_at_most: float | None = None) -> StreamedReply:
        """One reply to a person: sentence by sentence when the planner streams (its first sentence's
        pre-roll bounded by the planner's stream_preroll_s), else one turn (see run())."""
        if self.streams:
            return self.run_streamed(utterance, image, on_turn)
        turn = self.run(utterance, image, preroll_at_most=preroll_at_most)
        if on_turn is not None:
            on_turn(turn)
        return StreamedReply([turn])

    def run_streamed(self, utterance: str, image: str | bytes | None = None,
                     on_turn: Callable[[Turn], None] | None = None) -> StreamedReply:
        """Speak the streaming planner's reply sentence by sentence as it arrives; each sentence is a Turn
        (`on_turn` hears each once handed over). The reply joins the dialogue as far as it was spoken."""
        if not self.streams:
            raise ValueError(f"planner {self.planner.name} does not stream; "
                             "use planner=annotate planner.stream=true")
        self.session.open()
        request = self.dialogue.request(utterance, image)
        with self._stream_lock:  # a Cancel before this is honoured by claim(), one after by cancel()
            self.planner_call.claim()
            plans = self.planner.stream(request)
            self._stream, reply = plans, StreamedReply([])
        try:
            self._perform(request, plans, reply, on_turn or (lambda turn: None))
        except LLMCallError as exc:  # after the first sentence: stop here, what was said stays said
            reply.error = f"the reply stopped after {len(reply.turns)} sentence(s): {exc}"
        finally:
            with self._stream_lock:
                reply.cancelled, self._stream = plans is not self._stream, None
            plans.cancel()  # closes the HTTP stream whatever ended the loop
        if reply.turns and not reply.cancelled and self._streamed.dispatch is not None:
            self._streamed.dispatch.wait()
        self.dialogue.exchange(utterance, reply.text)
        return reply

    def cancel(self) -> None:
        """Stop the reply streaming now: no further sentence is performed. Any thread."""
        with self._stream_lock:
            plans, self._stream = self._stream, None
        if plans is not None:
            plans.cancel()

    def cancel_planning(self) -> bool:
        """Abandon the planner call under way, from any thread: its turn raises PlanningCancelled (the
        thinking gesture stops, nothing joins the dialogue) and the answer is dropped. False: no call was."""
        return self.planner_call.abandon()

    def silence(self) -> None:
        """Stop talking and clear the gestures now, from any thread: a reply still streaming stops first (no
        sentence after this one), the audio stops, and the arms blend from where they are toward neutral."""
        self.cancel()
        loop = self.session.loop
        loop.sequencer.interrupt([], now=loop.clock.now())
        if self._dispatch is not None:  # the stage that started the audio
            self._dispatch.player.stop()

    @cached_property
    def _dispatch(self) -> Dispatch | None:
        return next((s for s in self.pipeline.stages if isinstance(s, Dispatch)), None)

    def _perform(self, request: PlanRequest, plans: SentencePlans, reply: StreamedReply,
                 on_turn: Callable[[Turn], None]) -> None:
        with ExitStack() as thinking:
            thinking.enter_context(self._planning_now())
            if self.thinking is not None:
                thinking.enter_context(self.thinking.around_planning())
            for output in plans:
                thinking.close()  # the first sentence is here: planning is over
                if self._stream is not plans:
                    return  # cancelled while this sentence was being planned
                turn = Turn(request, planner_output=output)
                turn.stage_s["planner"] = output.latency_s
                self._record(turn, "request")
                self._record(turn, "planner_output")
                (self._streamed.rest if reply.turns else self._streamed.first).run(turn)
                if self._stream is not plans:  # the interrupt came while this sentence was handed over
                    self.silence()  # undo it
                    return
                reply.turns.append(turn)
                on_turn(turn)

    @cached_property
    def _streamed(self) -> StreamPipelines:
        return StreamPipelines.derive(self._recorded, self.planner.stream_preroll_s)

    def run_plan(self, plan: Plan, utterance: str | None = None,
                 resolved: list[ResolvedGesture] | None = None) -> Turn:
        """Execute a scripted plan from the first stage that reads it; it stays out of the history.

        With `resolved` (motions in no library: a Pose Studio draft) it enters at the first stage that
        reads those, so everything after resolution (modulation, limits, the sequencer's checks) applies."""
        self.session.open()
        turn = Turn(PlanRequest(utterance=plan.reply if utterance is None else utterance), plan=plan,
                    resolved=resolved)
        entry = "plan" if resolved is None else "resolved"
        for name in ("request", "plan") if resolved is None else ("request", "plan", "resolved"):
            self._record(turn, name)
        start = next((s.name for s in self.pipeline.stages if entry in s.reads), None)
        if start is None:
            raise PipelineError(f"a scripted plan has nowhere to enter: no stage of {self.pipeline.names} "
                                f"reads {entry}")
        self._recorded.run(turn, start)
        return turn

    def plan(self, turn: Turn, planner: Planner) -> None:
        """The planner call, wrapped in the thinking gesture that masks its latency."""
        thinking = self.thinking.around_planning() if self.thinking is not None else nullcontext()
        with self._planning_now(), thinking:
            turn.planner_output = self.planner_call.run(lambda: planner.plan(turn.request))
        turn.stage_s["planner"] = turn.planner_output.latency_s
        self._record(turn, "planner_output")

    def _recording_hook(self, stage: Stage, turn: Turn) -> None:
        for name in stage.writes:
            self._record(turn, name)
        if "dispatched" in stage.writes and self.session.recording:  # enough to re-measure the sync
            self.session.write(TIMELINE, speech_timeline(turn))

    def _record(self, turn: Turn, name: str) -> None:
        if not self.session.recording:
            return  # serialising a turn costs more than the stage that made it
        value: Any = turn.field_json(name)
        self.session.write(f"/{name}", value if isinstance(value, dict) else {name: value})


@dataclass
class StreamedReply:
    """A streamed reply: one Turn per sentence performed, whether an interrupt cancelled it, and the error
    that stopped it early (None when the model finished)."""

    turns: list[Turn]
    cancelled: bool = False
    error: str | None = None

    @property
    def text(self) -> str:
        """What was said."""
        return " ".join(t.plan.reply for t in self.turns if t.plan is not None and t.plan.reply)
