"""A planner call its caller can walk away from: a visitor's Cancel while the reply is being planned.

A planner call cannot be stopped from outside (a model server keeps computing, a local forward pass runs
to its end), so the call runs on a daemon thread and the caller waits for either its answer or abandon().
An abandoned call's answer, whenever it comes, is dropped; its error too.

A turn that a page can cancel announces its call with expect() the moment it is announced (turn_started),
so a Cancel that comes before the call starts is honoured too: the call then never starts (run() and
claim() raise PlanningCancelled). settle() ends that window when the turn ends without a call.
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
        self._expected = False  # a turn was announced and its call has not started yet
        self._waiting: threading.Event | None = None  # set by the answer or by abandon()
        self._abandoned = False

    def expect(self) -> None:
        """A turn was announced: its call is coming, and a Cancel from now on is honoured."""
        with self._lock:
            self._expected, self._abandoned = True, False

    def settle(self) -> None:
        """The announced turn ended (with or without a call): a later Cancel finds nothing to cancel."""
        with self._lock:
            if self._waiting is None:
                self._expected, self._abandoned = False, False

    def claim(self) -> None:
        """The call starts now (a streamed reply's, which its own cancel stops from here on):
        PlanningCancelled if the turn was cancelled before."""
        with self._lock:
            self._claim_locked()

    def _claim_locked(self) -> None:
        cancelled = self._expected and self._abandoned
        self._expected = self._abandoned = False
        if cancelled:
            raise PlanningCancelled("the turn was cancelled before its planner call started")

    def run(self, call: Callable[[], T]) -> T:
        """call()'s result, or PlanningCancelled as soon as abandon() is called (the call runs on); a call
        abandoned before it started never starts."""
        with self._lock:  # claimed and started at once: a Cancel lands before or after, never between
            self._claim_locked()
            background = BackgroundCall(call, "emopose-planner-call")
            self._waiting = background.done
        try:
            background.done.wait()
        finally:
            with self._lock:
                abandoned, self._waiting, self._abandoned = self._abandoned, None, False
        if abandoned:
            raise PlanningCancelled("the planner call was cancelled; its answer is dropped")
        return background.result()

    def abandon(self) -> bool:
        """Stop waiting for the call expected or under way (any thread); False when there is none (the plan
        has arrived)."""
        with self._lock:
            if (not self._expected and self._waiting is None) or self._abandoned:
                return False
            self._abandoned = True
            if self._waiting is not None:
                self._waiting.set()
            return True
