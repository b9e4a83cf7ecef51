"""Pipeline: the stages in order, each reading and writing named fields of a Turn (emopose/turn/model.py).

Stages declare `reads` and `writes` (Turn field names) and receive everything else they need in their
constructors, so `__call__(turn)` takes the turn alone. The pipeline checks at build time, before any
model call, that every read is written by an earlier stage (or is an input), so a mis-ordered or
ablated pipeline is refused with a message naming the stage and the missing field. A run may enter
later than the first stage (a scripted Plan enters at `resolve`). Hooks run after every stage with the
stage and the turn (timing is the pipeline's own; the turn runner adds recording), and
`step_through()` yields every intermediate value for the web UI, MCAP and tests.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any, Protocol, runtime_checkable

from emopose.turn.model import Turn

PLANNED = ("request", "planner_output")  # what the turn runner fills in before the first stage


@runtime_checkable
class Stage(Protocol):
    name: str
    reads: tuple[str, ...]
    writes: tuple[str, ...]

    def __call__(self, turn: Turn) -> Any: ...


Hook = Callable[[Stage, Turn], None]


class PipelineError(ValueError):
    pass


class Pipeline:
    def __init__(self, stages: Mapping[str, Stage] | Sequence[Stage], hooks: Sequence[Hook] = (),
                 inputs: Sequence[str] = PLANNED) -> None:
        """`inputs`: the Turn fields filled in before the first stage (a pipeline from resolve on
        takes a plan)."""
        items = list(stages.values()) if isinstance(stages, Mapping) else list(stages)
        self.stages: list[Stage] = [s for s in items if s is not None]
        self.hooks, self.inputs = tuple(hooks), tuple(inputs)
        self._check_order(0, self.inputs)

    def with_hooks(self, *hooks: Hook) -> Pipeline:
        return Pipeline(self.stages, (*self.hooks, *hooks), self.inputs)

    def reconfigured(self, **changes: Callable[[Any], Stage]) -> Pipeline:
        """A copy in which the stage called `name` is replaced by changes[name](stage), for each name it
        has (an ablated stage stays ablated); hooks and inputs are kept. The stages' own methods make
        the re-configured copies (e.g. ScheduleStage.in_mode)."""
        return Pipeline([changes[s.name](s) if s.name in changes else s for s in self.stages],
                        self.hooks, self.inputs)

    def _check_order(self, first: int, inputs: Sequence[str]) -> None:
        known, available = set(Turn.field_names()), set(inputs)
        for stage in self.stages[first:]:
            if not isinstance(stage, Stage):
                raise PipelineError(f"{stage!r} is not a stage: it needs name, reads, writes and __call__")
            unknown = [f for f in (*stage.reads, *stage.writes) if f not in known]
            if unknown:
                raise PipelineError(f"stage '{stage.name}' names {unknown}, "
                                    f"which are not Turn fields {sorted(known)}")
            missing = [r for r in stage.reads if r not in available]
            if missing:
                raise PipelineError(
                    f"stage '{stage.name}' reads {missing}, which no earlier stage writes; "
                    f"order is {self.names}, available before it: {sorted(available)}"
                )
            available.update(stage.writes)

    @property
    def names(self) -> list[str]:
        return [s.name for s in self.stages]

    def get(self, name: str) -> Stage | None:
        """The stage called `name`, or None when this pipeline has none."""
        return next((s for s in self.stages if s.name == name), None)

    def _first(self, turn: Turn, start: str | None) -> int:
        """The index of the first stage to run, checked against what the turn already holds."""
        if start is not None and start not in self.names:
            raise PipelineError(f"cannot start at '{start}': the pipeline is {self.names}")
        first = 0 if start is None else self.names.index(start)
        self._check_order(first, [f for f in Turn.field_names() if getattr(turn, f) is not None])
        return first

    def step_through(self, turn: Turn, start: str | None = None) -> Iterator[tuple[str, Any]]:
        """Run each stage from `start` (default: the first), yielding (field, value) for what it writes."""
        for stage in self.stages[self._first(turn, start):]:
            began = time.perf_counter()
            value = stage(turn)
            turn.stage_s[stage.name] = time.perf_counter() - began
            outputs = value if len(stage.writes) > 1 else (value,)
            for name, output in zip(stage.writes, outputs, strict=True):
                setattr(turn, name, output)
            for hook in self.hooks:
                hook(stage, turn)
            for name, output in zip(stage.writes, outputs):
                yield name, output

    def run(self, turn: Turn, start: str | None = None) -> Turn:
        for _ in self.step_through(turn, start):
            pass
        return turn
