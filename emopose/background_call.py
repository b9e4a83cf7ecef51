"""A call on a daemon thread that its caller can stop waiting for: a model call past its deadline, a
planner call a visitor cancelled. Neither can be stopped from outside, so the thread runs on and its
outcome is dropped."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Generic, TypeVar

T = TypeVar("T")


class BackgroundCall(Generic[T]):
    """call() started on a daemon thread; `done` is set when it returns or raises (or by whoever gives up
    waiting), and result() then gives its value or raises its error."""

    def __init__(self, call: Callable[[], T], name: str) -> None:
        self.done = threading.Event()
        self._outcome: dict = {}
        threading.Thread(target=self._run, args=(call,), name=name, daemon=True).start()

    def _run(self, call: Callable[[], T]) -> None:
        try:
            self._outcome["value"] = call()
        except BaseException as exc:  # noqa: BLE001 - handed to the caller by result()
            self._outcome["error"] = exc
        self.done.set()

    def result(self) -> T:
        if "error" in self._outcome:
            raise self._outcome["error"]
        return self._outcome["value"]
