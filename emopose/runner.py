"""The turn runner: the one function that runs a turn, for every caller (jobs, web UI, tour, suites).

It owns the planner call (always wrapped in the thinking gesture when one is configured), the stages,
the dialogue history and the recording: a pipeline hook writes every value a stage produces to its
MCAP channel (`/plan`, `/resolved`, ...) as `Turn.field_json` serialises it, the moment it exists.
A scripted Plan (a suite item, a button in the web UI, a robot check) enters at the first stage that
reads a plan, with no planner call and no JSON round trip.
"""

from __future__ import annotations

from contextlib import nullcontext
from dataclasses import dataclass, field, replace
from typing import Any

from emopose.contract import Plan
from emopose.pipeline import Pipeline, PipelineError, Stage
from emopose.planners.base import Planner, PlanRequest
from emopose.session import Session
from emopose.sync_record import TIMELINE, speech_timeline
from emopose.thinking import ThinkingGesture
from emopose.turn import ResolvedGesture, Turn


@dataclass
class TurnRunner:
    planner: Planner
    pipeline: Pipeline
    session: Session
    thinking: ThinkingGesture | None = None
    history: list[dict] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._recorded = self.pipeline.with_hooks(self._recording_hook)

    def with_pipeline(self, pipeline: Pipeline) -> TurnRunner:
        """The same runner (session, planner, history) running other stages: a suite's variant."""
        return replace(self, pipeline=pipeline)

    def run(self, utterance: str, image: str | bytes | None = None, *, use_history: bool = True,
            extra_history: tuple[dict, ...] = (), planner: Planner | None = None, remember: bool = True) -> Turn:
        """Plan and execute one utterance through the whole pipeline; it joins the dialogue history.

        `planner` replaces the configured one for this turn (the tour answers visitors with a sibling);
        `remember=False` leaves the history to the caller (the tour records what was actually said)."""
        self.session.open()
        history = (tuple(self.history) if use_history else ()) + tuple(extra_history)
        turn = Turn(PlanRequest(utterance=utterance, history=history, image=image))
        self._record(turn, "request")
        self.plan(turn, planner or self.planner)
        self._recorded.run(turn)
        if remember:
            self.history.extend([{"role": "user", "content": utterance},
                                 {"role": "assistant", "content": turn.plan.reply}])
        return turn

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
            raise PipelineError(f"a scripted plan has nowhere to enter: no stage of {self.pipeline.names} reads {entry}")
        self._recorded.run(turn, start)
        return turn

    def plan(self, turn: Turn, planner: Planner) -> None:
        """The planner call, wrapped in the thinking gesture that masks its latency."""
        with self.thinking.around_planning() if self.thinking is not None else nullcontext():
            turn.planner_output = planner.plan(turn.request)
        turn.stage_s["planner"] = turn.planner_output.latency_s
        self._record(turn, "planner_output")

    def _recording_hook(self, stage: Stage, turn: Turn) -> None:
        for name in stage.writes:
            self._record(turn, name)
        if "dispatched" in stage.writes and self.session.recording:  # enough to re-measure the sync
            self.session.write(TIMELINE, speech_timeline(turn, self.session.loop))

    def _record(self, turn: Turn, name: str) -> None:
        if not self.session.recording:
            return  # serialising a turn costs more than the stage that made it
        value: Any = turn.field_json(name)
        self.session.write(f"/{name}", value if isinstance(value, dict) else {name: value})
