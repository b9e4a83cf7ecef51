"""Dispatch: run the submitted commands on the backend through the 50 Hz control loop.

When the loop already runs on its own thread (web UI, tour, G1), dispatch only waits if asked to;
otherwise it drives the loop on this thread until the sequencer settles (offline rendering with a
fake clock, or real time with the monotonic clock).
"""

from __future__ import annotations

from dataclasses import dataclass

from emopose.sequencer import Event


@dataclass(frozen=True)
class DispatchReport:
    completed: bool
    events: tuple[Event, ...]
    ticks: int


@dataclass
class Dispatch:
    """Stage: submitted -> dispatched. `settle` waits for HOLDING; `rest` also for the neutral recovery."""

    timeout_s: float = 60.0
    until: str = "rest"
    name = "dispatch"
    reads = ("submitted",)
    writes = "dispatched"

    def __post_init__(self) -> None:
        if self.until not in ("settle", "rest", "none"):
            raise ValueError(f"pipeline.dispatch.until must be settle, rest or none, got {self.until!r}")

    def __call__(self, turn, ctx) -> DispatchReport:
        loop, sequencer = ctx.loop, ctx.sequencer
        first_event = len(sequencer.events)
        ticks = loop.stats.ticks
        if self.until == "none":
            done = True
        elif self.until == "settle":
            done = self._wait(ctx, sequencer.settled)
        else:
            done = self._wait(ctx, lambda: sequencer.settled() and sequencer.state.value == "idle")
        return DispatchReport(done, tuple(sequencer.events[first_event:]), loop.stats.ticks - ticks)

    def _wait(self, ctx, done) -> bool:
        if ctx.loop.running:
            return ctx.wait_for(done, self.timeout_s)
        return ctx.loop.run_until(done, self.timeout_s)
