"""The reply being planned, as every page sees it: which turn, since when, how many retries; its Cancel;
and whether the planner writes replies at all (`narrates`, the page's mode hint).

A said line is "planning" from its `turn_started` message until its first turn is published (or it
ends otherwise). The state pushed to the pages carries `planning` ({"turn", "since", "retries"}) so a
page shows the elapsed time and, while a model call is being retried, the count. Cancel names the
turn_started message it means, so a Cancel that arrives after that plan came in never cancels the next.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from emopose.planners.base import ModalPlanner, PlannerMode
from emopose.turn.runner import TurnRunner


def retries_so_far(planner) -> int | None:
    """The model-call retries the planner's client has counted so far; None for a planner without a
    model client (the local and keyword planners plan in one step and never retry)."""
    counters = getattr(getattr(planner, "client", None), "counters", None)
    return None if counters is None else counters.retries


def narrates(planner) -> bool:
    """Whether the robot says the visitor's text (narrate) or the planner writes a reply: planners without a
    mode (the local and keyword ones) only choose gestures for the words they are given."""
    return planner.mode is PlannerMode.NARRATE if isinstance(planner, ModalPlanner) else True


class PendingPlan:
    def __init__(self, runner: TurnRunner) -> None:
        self.runner = runner
        self._lock = threading.Lock()
        self._current: dict | None = None  # {"turn", "since", "retries_before"}

    def begin(self, announce: Callable[[], dict]) -> dict:
        """A said line's planning starts: announce() publishes its turn_started message (returned). A Cancel
        naming it is honoured from that moment, before the planner call starts too."""
        with self._lock:  # a Cancel waits for the announcement and the armed call: no gap between them
            started = announce()
            self._current = {"turn": started["id"], "since": started["server_now"],
                             "retries_before": retries_so_far(self.runner.planner)}
            self.runner.planner_call.expect()
        return started

    def end(self, started: dict) -> None:
        """Its first turn is published, or it ended without one."""
        with self._lock:
            if self._current is not None and self._current["turn"] == started["id"]:
                self._current = None
                self.runner.planner_call.settle()

    def state(self) -> dict | None:
        with self._lock:
            current = self._current
        if current is None:
            return None
        before, now = current["retries_before"], retries_so_far(self.runner.planner)
        retries = None if before is None or now is None else max(0, now - before)
        return {"turn": current["turn"], "since": current["since"], "retries": retries}

    def cancel(self, turn: int | None) -> dict:
        """Abandon the pending planner call of `turn` (a turn_started id; None: whichever is pending)."""
        with self._lock:  # held: the line cannot end and the next begin in between
            return self._cancel(turn)

    def _cancel(self, turn: int | None) -> dict:
        current = self._current
        if current is None or turn not in (None, current["turn"]):
            return {"cancelled": False, "reason": "nothing is being planned for that line any more"}
        if self.runner.cancel_planning():
            return {"cancelled": True, "turn": current["turn"]}
        if self.runner.streams:  # a streamed reply before its first sentence: stop the stream
            self.runner.cancel()
            return {"cancelled": True, "turn": current["turn"]}
        return {"cancelled": False, "reason": "the plan has arrived and the reply is starting: use Interrupt"}


def cancelled(started: dict, turn_id: int, now: float) -> dict:
    """The message of a line whose planning was cancelled (`started`: its turn_started message)."""
    return {"type": "turn_cancelled", "turn_id": turn_id, "started": started["id"],
            "utterance": started["utterance"], "planning_s": round(now - started["server_now"], 3)}
