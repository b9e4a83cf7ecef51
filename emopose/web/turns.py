"""What the browser needs from one executed turn: the reply, its cues and their release and stroke times.

Built from `Turn.to_json()`, the serialisation the MCAP recording and results.json use too. Each cue
carries the trigger's character span in the reply (for highlighting) and its release time relative to
speech start (Eq. schedule), so the page can light the trigger up when the gesture is released,
following the audio clock when the reply's WAV plays. In timeline mode a cue also carries its planned
stroke (`stroke_s`, when the arm is planned to arrive at the stroke, on the trigger word) and, once the
sequencer reports it, the executed one (`stroke_executed_s`); both relative to speech start. `intensity`
is the one played, `requested_intensity` the plan's: the schedule softens a gesture that does not fit.

A cue that was not performed carries its `outcome` ({"kind", "reason"}): a gesture dropped by the
timeline (it did not fit; the schedule says so) or refused by the sequencer, whose event of a kind in
NOT_PERFORMED (rejected at its start for self-collision, dropped) names the cue's command. In live mode
the turn is published before its gestures start, so the session adds outcomes that come later
(emopose/web/session.py) through the same `outcome_of`.
"""

from __future__ import annotations

from emopose.contract import EventKind, trigger_position
from emopose.turn.model import Turn

# Sequencer event kinds that mean "this gesture did not run".
NOT_PERFORMED = (EventKind.REJECTED, EventKind.DROPPED)


def outcome_of(event: dict) -> dict | None:
    """{"kind", "reason"} for an event (as Turn.to_json writes it) that says its gesture did not run."""
    if event["kind"] not in NOT_PERFORMED:
        return None
    return {"kind": event["kind"], "reason": event["detail"] or event["kind"]}


def cue_rows(data: dict) -> list[dict]:
    """One row per gesture record of a turn's JSON: what was asked, what runs, when, and if it did not."""
    reply, records = data["plan"]["reply"], data["plan"]["records"]
    releases = data["schedule"]["releases"] if "schedule" in data else [None] * len(records)
    commands = data["submitted"]["commands"] if "submitted" in data else []
    ids = {c["record"]: c["id"] for c in commands}  # record index -> command id (dropped ones have none)
    events = data["dispatched"]["events"] if "dispatched" in data else []
    outcomes = {e["command_id"]: outcome_of(e) for e in events if outcome_of(e) is not None}
    speech_start = data.get("dispatched", {}).get("speech_start")
    strokes = {e["command_id"]: e["t"] - speech_start for e in events
               if e["kind"] == EventKind.STROKE and speech_start is not None}
    rows = []
    for k, (record, resolved, release) in enumerate(zip(records, data["resolved"], releases)):
        command_id = ids.get(k)
        dropped = None if release is None else release["dropped"]
        timing = None if release is None else release.get("timing")  # timeline mode only
        trigger = record["trigger"]
        start = trigger_position(reply, trigger)
        rows.append({
            "k": k, "class": record["class"], "requested": record["variant"],
            "resolved": resolved["resolved"], "resolved_class": resolved["resolved_class"],
            "rule": resolved["rule"], "confidence": record["confidence"],
            # as played (a gesture that did not fit may be softened) and as the plan asked
            "intensity": record["intensity"] if release is None else release["intensity"],
            "requested_intensity": record["intensity"],
            "trigger": trigger, "char_start": start,
            "char_end": None if start is None else start + len(trigger),
            "release_s": None if release is None else release["release_s"],
            "how": None if release is None else release["how"],
            "stroke_s": None if timing is None else timing["arrival_s"],
            "stroke_executed_s": strokes.get(command_id),
            "command_id": command_id,
            "outcome": {"kind": "dropped", "reason": dropped} if dropped else outcomes.get(command_id),
        })
    return rows


def summarize_turn(turn: Turn, turn_id: int, kind: str, audio_url: str | None, library_version: int) -> dict:
    data = turn.to_json()
    plan, speech = data["plan"], data.get("speech")
    output, submitted = data.get("planner_output"), data.get("submitted")
    return {
        "type": "turn", "turn_id": turn_id, "kind": kind,
        "utterance": data["request"]["utterance"], "reply": plan["reply"], "source": plan["source"],
        # narration planners (keyword, local, llm mode=narrate) speak the user's text as the robot's line
        "narrated": kind == "say" and plan["reply"].strip() == data["request"]["utterance"].strip(),
        "notes": plan["notes"], "cues": cue_rows(data),
        "speech": {"duration_s": speech["duration_s"] if speech else 0.0,
                   "estimated": speech["estimated"] if speech else True, "audio": audio_url},
        # when the audio starts (or started) on the server clock: a streamed reply's later sentence
        # waits for the one before it
        "speech_start": data["dispatched"]["speech_start"] if "dispatched" in data
        else submitted["speech_start"] if submitted else None,
        "planner_latency_s": output["latency_s"] if output else 0.0,
        "planner_error": output["error"] if output else None,
        # the dialogue the planner was given, and whether it read it (planners that say so in meta)
        "history_messages": data["request"]["history_messages"],
        "history_used": output["meta"].get("history_used") if output else None,
        "stage_ms": {k: round(v, 2) for k, v in data["stage_ms"].items()},
        "library_version": library_version,
    }
