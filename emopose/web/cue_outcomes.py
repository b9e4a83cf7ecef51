"""Late cue outcomes: what the sequencer says of a published turn's gestures after it was published.

A turn is published before its gestures start; when the sequencer later rejects or drops one, the
turn's cue in the log gets its outcome and a `cue_outcome` message tells the open pages; when a stroke
arrives, the cue gets its executed time and a `cue_stroke` message. A refusal may come before its turn is
published (then track_turn lands it). The tables keep the TRACKED_COMMANDS newest command ids, so a
session of any length holds a bounded amount.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from emopose.contract import EventKind
from emopose.execution.bounded_log import BoundedLog
from emopose.execution.gesture_command import Event
from emopose.web.turns import outcome_of

TRACKED_COMMANDS = 2048  # command ids remembered for late outcomes (far more than the log's turns hold)


class CueOutcomes:
    def __init__(self, events: BoundedLog[Event], publish: Callable[[dict], dict]) -> None:
        self._events, self._publish = events, publish
        self._lock = threading.Lock()
        self._seen = events.total
        self._cue_of: dict[int, tuple[dict, int]] = {}  # command id -> (published turn message, cue index)
        self._refusals: dict[int, dict] = {}  # command id -> outcome (may precede its turn)
        self._strokes: dict[int, float] = {}  # command id -> clock time its stroke arrived

    def track_turn(self, message: dict) -> None:
        """Follow a just-published turn's cues; land what already happened to them."""
        with self._lock:
            ids = [cue["command_id"] for cue in message["cues"]]
            for k, command_id in enumerate(ids):
                if command_id is not None:
                    remember(self._cue_of, command_id, (message, k))
            landed = [self._land(command_id) for command_id in ids if command_id in self._refusals]
            landed += [self._land_stroke(command_id) for command_id in ids if command_id in self._strokes]
        self._publish_all(landed)

    def track(self) -> None:
        """Put the sequencer's new rejections, drops and arrived strokes on their published cues (and
        tell the pages). An event read twice (appended while the cursor moved) lands once."""
        with self._lock:
            cursor, self._seen = self._seen, self._events.total
            landed = []
            for event in self._events.since(cursor):
                if event.kind == EventKind.STROKE and event.command_id is not None:
                    remember(self._strokes, event.command_id, event.t)
                    landed.append(self._land_stroke(event.command_id))
                    continue
                outcome = outcome_of({"kind": event.kind, "detail": event.detail})
                if outcome is not None and event.command_id is not None:
                    remember(self._refusals, event.command_id, outcome)
                    landed.append(self._land(event.command_id))
        self._publish_all(landed)

    def _land(self, command_id: int) -> dict | None:
        """Set a refused command's outcome on its published cue; the page message, or None (caller locks)."""
        message, k = self._cue_of.get(command_id, (None, None))
        if message is None or message["cues"][k]["outcome"] is not None:
            return None
        outcome = message["cues"][k]["outcome"] = self._refusals[command_id]
        return {"type": "cue_outcome", "turn_id": message["turn_id"], "k": k, "outcome": outcome}

    def _land_stroke(self, command_id: int) -> dict | None:
        """Put an arrived stroke's time (from speech start) on its published cue; the page message."""
        message, k = self._cue_of.get(command_id, (None, None))
        cue = None if message is None else message["cues"][k]
        if cue is None or cue["stroke_executed_s"] is not None or message["speech_start"] is None:
            return None
        executed = cue["stroke_executed_s"] = self._strokes[command_id] - message["speech_start"]
        return {"type": "cue_stroke", "turn_id": message["turn_id"], "k": k, "executed_s": executed}

    def _publish_all(self, landed: list[dict | None]) -> None:
        for update in filter(None, landed):
            self._publish(update)


def remember(table: dict, key: int, value: object) -> None:
    """Insert into a dict kept to the TRACKED_COMMANDS newest keys (dicts keep insertion order)."""
    table[key] = value
    while len(table) > TRACKED_COMMANDS:
        del table[next(iter(table))]
