"""What the browser needs from one executed turn: the reply, its cues and their release times.

Built from `Turn.to_json()`, the serialisation the MCAP recording and results.json use too. Each cue
carries the trigger's character span in the reply (for highlighting) and its release time relative to
speech start (Eq. schedule), so the page can light the trigger up when the gesture is released,
following the audio clock when the reply's WAV plays.
"""

from __future__ import annotations

from emopose.stages.schedule import trigger_position
from emopose.turn import Turn


def cue_rows(data: dict) -> list[dict]:
    """One row per gesture record of a turn's JSON: what was asked, what runs, and when."""
    reply, records = data["plan"]["reply"], data["plan"]["records"]
    releases = data["schedule"]["releases"] if "schedule" in data else [None] * len(records)
    rows = []
    for k, (record, resolved, release) in enumerate(zip(records, data["resolved"], releases)):
        trigger = record["trigger"]
        start = trigger_position(reply, trigger)
        rows.append({
            "k": k, "class": record["class"], "requested": record["variant"], "resolved": resolved["resolved"],
            "resolved_class": resolved["resolved_class"], "rule": resolved["rule"], "intensity": record["intensity"],
            "confidence": record["confidence"], "trigger": trigger,
            "char_start": start, "char_end": None if start is None else start + len(trigger),
            "release_s": None if release is None else release["release_s"],
            "how": None if release is None else release["how"],
        })
    return rows


def summarize_turn(turn: Turn, turn_id: int, kind: str, audio_url: str | None, library_version: int) -> dict:
    data = turn.to_json()
    plan, speech = data["plan"], data.get("speech")
    output, submitted = data.get("planner_output"), data.get("submitted")
    return {
        "type": "turn", "turn_id": turn_id, "kind": kind,
        "utterance": data["request"]["utterance"], "reply": plan["reply"], "source": plan["source"],
        "notes": plan["notes"], "cues": cue_rows(data),
        "speech": {"duration_s": speech["duration_s"] if speech else 0.0,
                   "estimated": speech["estimated"] if speech else True, "audio": audio_url},
        "speech_start": submitted["speech_start"] if submitted else None,
        "planner_latency_s": output["latency_s"] if output else 0.0,
        "planner_error": output["error"] if output else None,
        "stage_ms": {k: round(v, 2) for k, v in data["stage_ms"].items()},
        "library_version": library_version,
    }
