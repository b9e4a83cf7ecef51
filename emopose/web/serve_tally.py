"""What a served session did, every turn counted: results.json's counts and results.md's per-turn table.

The page's log keeps only the newest serve.max_turns_kept messages. The tally sees every message the
session publishes: it counts turns by kind and plan source (fallbacks and failed planner calls apart),
replies stopped early, interrupts, lines cancelled while planned and cues that did not run, and appends
one row per turn (and one per cancelled line, and one per late cue outcome) to turns.jsonl in the run
directory as it happens, so memory stays flat however long the session runs. results.md tables the rows
(the newest MAX_TABLE_ROWS; turns.jsonl has them all).
SOURCE_WORDS says each plan source in words a visitor reads (the page gets it in /api/info).
"""

from __future__ import annotations

import json
import threading
from collections import Counter
from pathlib import Path

from emopose.contract import USABLE_SOURCES
from emopose.results import markdown_table

MAX_TABLE_ROWS = 200
SOURCE_WORDS = {
    "model": "planned by the model",
    "retried": "planned by the model (after a retry)",
    "scripted": "a chosen gesture (no planner)",
    "plain_text": "the model answered in plain text: one calm gesture",
    "empty": "the model answered nothing: one calm gesture",
    "unknown_class": "the model named an unknown gesture: a calm one instead",
    "no_records": "the model chose no gesture: one calm gesture",
    "keyword_fallback": "the model's answer was unusable: gestures chosen by keywords",
    "call_failed": "the planner could not be reached: gestures chosen by keywords",
}


class TurnTally:
    def __init__(self, rows_path: Path | None) -> None:
        self.rows_path = rows_path
        self.kinds: Counter[str] = Counter()
        self.sources: Counter[str] = Counter()
        self.events: Counter[str] = Counter()  # reply_stopped, interrupted, cue outcomes, planner failures
        self._lock = threading.Lock()
        if rows_path is not None:
            rows_path.parent.mkdir(parents=True, exist_ok=True)
            rows_path.write_text("")

    def observe(self, message: dict) -> None:
        """Count one published message (any thread); a turn or a late cue outcome becomes a row."""
        kind = message["type"]
        with self._lock:
            if kind == "turn":
                self.kinds[message["kind"]] += 1
                self.sources[message["source"]] += 1
                self._append(turn_row(message))
            elif kind == "cue_outcome":
                self.events["cues_not_performed"] += 1
                self._append({"turn": message["turn_id"], "late_outcome": message["outcome"]["kind"]})
            elif kind == "turn_cancelled":  # a row, but not a turn: nothing was said or done
                self.events[kind] += 1
                self._append(cancelled_row(message))
            elif kind in ("reply_stopped", "interrupted"):
                self.events[kind] += 1

    def _append(self, row: dict) -> None:
        if self.rows_path is not None:
            with self.rows_path.open("a") as rows:
                rows.write(json.dumps(row) + "\n")

    @property
    def turns(self) -> int:
        return sum(self.kinds.values())

    def results(self) -> dict:
        with self._lock:
            fallbacks = sum(n for source, n in self.sources.items() if source not in USABLE_SOURCES)
            return {"turns": self.turns, "kinds": dict(self.kinds), "sources": dict(self.sources),
                    "fallbacks": fallbacks, "planner_failures": self.sources.get("call_failed", 0),
                    "replies_stopped": self.events["reply_stopped"],
                    "interrupts": self.events["interrupted"], "cancelled": self.events["turn_cancelled"],
                    "cues_not_performed_late": self.events["cues_not_performed"],
                    "turns_file": None if self.rows_path is None else self.rows_path.name}

    def markdown(self) -> str:
        """The per-turn table, with late cue outcomes folded into their turn's row."""
        rows: dict[int, dict] = {}
        if self.rows_path is not None and self.rows_path.is_file():
            for line in self.rows_path.read_text().splitlines():
                row = json.loads(line)
                if "late_outcome" in row:
                    if row["turn"] in rows:
                        rows[row["turn"]]["not run"] += 1
                else:
                    rows[row["turn"]] = row
        kept = list(rows.values())[-MAX_TABLE_ROWS:]
        header = ["turn", "kind", "plan source", "fallback", "cues", "not run", "planner s", "utterance"]
        table = markdown_table(header, [[r[h] for h in header] for r in kept])
        skipped = len(rows) - len(kept)
        return table + (f"\n\n({skipped} earlier turns in {self.rows_path.name})" if skipped else "")


def turn_row(message: dict) -> dict:
    """One published turn as a table row: what kind, where its plan came from, what of its cues ran."""
    cues = message["cues"]
    return {"turn": message["turn_id"], "kind": message["kind"], "plan source": message["source"],
            "fallback": "yes" if message["source"] not in USABLE_SOURCES else "",
            "cues": len(cues), "not run": sum(c["outcome"] is not None for c in cues),
            "planner s": round(message["planner_latency_s"], 2),
            "utterance": _cell(message["utterance"], 48)}


def cancelled_row(message: dict) -> dict:
    """A line cancelled while it was planned, as a table row (its planning time so far)."""
    return {"turn": message["turn_id"], "kind": "say", "plan source": "cancelled while planning",
            "fallback": "", "cues": 0, "not run": 0, "planner s": round(message["planning_s"], 2),
            "utterance": _cell(message["utterance"], 48)}


def _cell(text: str, width: int) -> str:
    """Text for a markdown cell: one line, no pipes, cut at a word with an ellipsis."""
    flat = " ".join(text.split()).replace("|", "/")
    if len(flat) <= width:
        return flat
    cut = flat.rfind(" ", 0, width)
    return flat[:cut if cut > 0 else width] + " ..."


def failure_banner(turn_id: int, error: str | None) -> dict:
    """A failed planner call as the page shows it: a banner with the cause (also in /api/status)."""
    cause = _cell(error or "no cause given", 300)
    return {"type": "planner_failed", "turn_id": turn_id, "error": cause,
            "banner": f"The planner could not be reached, so the robot said your words and chose its "
                      f"gestures by keywords. Cause: {cause}"}
