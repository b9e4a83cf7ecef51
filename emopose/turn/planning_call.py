"""A planner call its caller can walk away from: a visitor's Cancel while the reply is being planned.

A planner call cannot be stopped from outside (a model server keeps computing, a local forward pass runs
to its end), so the call runs on a daemon thread and the caller waits for either its answer or abandon().
An abandoned call's answer, whenever it comes, is dropped; its error too.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TypeVar

from emopose.background_call import BackgroundCall

T = TypeVar("T")


class PlanningCancelled(Exception):
    """The planner call was abandoned (a visitor cancelled the turn): there is no plan to perform."""


class AbandonableCall:
    """One call at a time (a TurnRunner plans its turns one after another)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._waiting: threading.Event | None = None  # set by the answer or by abandon()
        self._abandoned = False

    @property
    def pending(self) -> bool:
        """True while a call is under way and not abandoned. Any thread."""
        with self._lock:
            return self._waiting is not None and not self._abandoned

    def run(self, call: Callable[[], T]) -> T:
        """call()'s result, or PlanningCancelled as soon as abandon() is called (the call runs on)."""
        background = BackgroundCall(call, "emopose-planner-call")
        with self._lock:
            self._waiting, self._abandoned = background.done, False
        try:
            background.done.wait()
        finally:
            with self._lock:
                abandoned, self._waiting = self._abandoned, None
        if abandoned:
            raise PlanningCancelled("the planner call was cancelled; its answer is dropped")
        return background.result()

    def abandon(self) -> bool:
        """Stop waiting for the call under way (any thread); False when none was (the plan had arrived)."""
        with self._lock:
            if self._waiting is None or self._abandoned:
                return False
            self._abandoned = True
            self._waiting.set()
            return True
