"""Pipeline: the planner, then the six stages in order, each reading and writing named fields of a Turn.

Stages declare `reads` (field names) and `writes` (one field name). The pipeline checks at build time,
before any model call, that every read is written by an earlier stage (or is an input), so a
mis-ordered or ablated pipeline is refused with a message naming the stage and the missing field.
`step_through()` yields every intermediate value for the web UI, MCAP and tests.
"""

from __future__ import annotations

import time
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

from emopose.planners.base import PlannerOutput, PlanRequest

INPUTS = ("request", "planner_output")


@runtime_checkable
class Stage(Protocol):
    name: str
    reads: tuple[str, ...]
    writes: str

    def __call__(self, turn: Turn, ctx: Any) -> Any: ...


@dataclass
class Turn:
    """Everything one utterance produces on its way to joint commands."""

    request: PlanRequest
    planner_output: PlannerOutput | None = None
    values: dict[str, Any] = field(default_factory=dict)
    stage_s: dict[str, float] = field(default_factory=dict)

    def __getattr__(self, name: str) -> Any:
        values = self.__dict__.get("values", {})
        if name in values:
            return values[name]
        raise AttributeError(f"turn has no field {name!r} (yet); fields so far: {sorted(values)}")


class PipelineError(ValueError):
    pass


class Pipeline:
    def __init__(self, stages: Mapping[str, Stage] | list[Stage]) -> None:
        items = list(stages.values()) if isinstance(stages, Mapping) else list(stages)
        self.stages: list[Stage] = [s for s in items if s is not None]
        self._check_order()

    def _check_order(self) -> None:
        available = set(INPUTS)
        for stage in self.stages:
            if not isinstance(stage, Stage):
                raise PipelineError(f"{stage!r} is not a stage: it needs name, reads, writes and __call__")
            missing = [r for r in stage.reads if r not in available]
            if missing:
                raise PipelineError(
                    f"stage '{stage.name}' reads {missing}, which no earlier stage writes; "
                    f"order is {[s.name for s in self.stages]}, available before it: {sorted(available)}"
                )
            available.add(stage.writes)

    @property
    def names(self) -> list[str]:
        return [s.name for s in self.stages]

    def step_through(self, turn: Turn, ctx: Any, planner: Any | None = None) -> Iterator[tuple[str, Any]]:
        """Run the planner (unless turn already has its output) and each stage, yielding (name, value)."""
        if turn.planner_output is None:
            turn.planner_output = planner.plan(turn.request)
            turn.stage_s["planner"] = turn.planner_output.latency_s
            yield "planner_output", turn.planner_output
        for stage in self.stages:
            started = time.perf_counter()
            value = stage(turn, ctx)
            turn.stage_s[stage.name] = time.perf_counter() - started
            turn.values[stage.writes] = value
            yield stage.writes, value

    def run(self, turn: Turn, ctx: Any, planner: Any | None = None) -> Turn:
        for _ in self.step_through(turn, ctx, planner):
            pass
        return turn
