"""Visitor questions: scripted ones from the scenario, live ones from anywhere (ASR, web UI).

`poll(where, elapsed_s)` returns the next question due at this point of the tour: a live question
at once, a scripted one when the tour is at its stop (narrating) or on its leg and `after_s` has
passed. Each scripted question fires once. The intent helpers tell an abort ("stop the tour") and a
question about what the camera sees ("what is this?") from other questions.
"""

from __future__ import annotations

import re
import threading
from collections import deque
from dataclasses import dataclass
from typing import Literal

Where = Literal["stop", "leg"]

_ABORT = re.compile(r"\b(stop|end|cancel|abort|finish|quit)\b[\w\s']{0,12}\btour\b|\bthat'?s enough\b",
                    re.IGNORECASE)
_SCENE = re.compile(
    r"\bwhat('?s| is| are)\s+(this|that|these|those|it)\b|\bwhat am i looking at\b|\bwhat do you see\b|"
    r"\bwhat can you see\b|\bwhat('?s| is) (in front of|over) (you|us|there)\b|\bdescribe (what|the scene)\b",
    re.IGNORECASE)


def wants_abort(text: str) -> bool:
    return bool(_ABORT.search(text))


def asks_about_scene(text: str) -> bool:
    return bool(_SCENE.search(text))


@dataclass(frozen=True)
class Question:
    text: str
    answer: str | None = None  # scripted answer for planners that only narrate
    where: str = ""  # "stop:<name>" or "leg:<name>" (or "live")
    scripted: bool = True


class Interruptions:
    """Scripted questions from the scenario plus a thread-safe queue of live ones."""

    def __init__(self, scripted=()) -> None:
        self._pending = [
            (("stop", s.at_stop) if s.at_stop is not None else ("leg", s.during_leg), s.after_s,
             Question(s.text, s.answer, f"{'stop' if s.at_stop else 'leg'}:{s.at_stop or s.during_leg}"))
            for s in scripted
        ]
        self._live: deque[Question] = deque()
        self._lock = threading.Lock()
        self.asked: list[Question] = []

    def ask(self, text: str, answer: str | None = None) -> None:
        """A live question: answered at the next poll, wherever the tour is."""
        with self._lock:
            self._live.append(Question(text, answer, "live", scripted=False))

    def poll(self, where: Where, stop: str, elapsed_s: float) -> Question | None:
        with self._lock:
            if self._live:
                question = self._live.popleft()
            else:
                due = [p for p in self._pending if p[0] == (where, stop) and elapsed_s >= p[1]]
                if not due:
                    return None
                self._pending.remove(due[0])
                question = due[0][2]
            self.asked.append(question)
            return question

    @property
    def unasked(self) -> list[Question]:
        """Scripted questions whose moment never came (the tour was aborted first)."""
        with self._lock:
            return [p[2] for p in self._pending]
