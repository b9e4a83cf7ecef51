"""What the browser needs from one executed turn: the reply, its cues and their release times.

Each cue carries the trigger's character span in the reply (for highlighting) and its release time
relative to speech start (Eq. schedule), so the page can light the trigger up when the gesture is
released, following the audio clock when the reply's WAV plays.
"""

from __future__ import annotations

from emopose.stages.schedule import trigger_position
from emopose.turn import Turn


def cue_rows(turn: Turn) -> list[dict]:
    reply = turn.plan.reply
    schedule = turn.schedule
    releases = schedule.releases if schedule is not None else [None] * len(turn.resolved)
    rows = []
    for k, (resolved, release) in enumerate(zip(turn.resolved, releases)):
        record = resolved.record
        start = trigger_position(reply, record.trigger)
        rows.append({
            "k": k, "class": record.cls, "requested": record.variant, "resolved": resolved.entry.name,
            "resolved_class": resolved.entry.cls, "rule": resolved.rule, "intensity": record.intensity,
            "confidence": record.confidence, "trigger": record.trigger,
            "char_start": start, "char_end": None if start is None else start + len(record.trigger),
            "release_s": None if release is None else release.release_s,
            "how": None if release is None else release.how,
        })
    return rows


def summarize_turn(turn: Turn, turn_id: int, kind: str, audio_url: str | None, library_version: int) -> dict:
    plan = turn.plan
    speech, submitted, output = turn.speech, turn.submitted, turn.planner_output
    return {
        "type": "turn", "turn_id": turn_id, "kind": kind,
        "utterance": turn.request.utterance, "reply": plan.reply, "source": plan.source,
        "notes": list(plan.notes), "cues": cue_rows(turn),
        "speech": {"duration_s": speech.duration_s if speech else 0.0,
                   "estimated": speech.estimated if speech else True, "audio": audio_url},
        "speech_start": submitted.speech_start if submitted else None,
        "planner_latency_s": output.latency_s if output else 0.0,
        "planner_error": output.error if output else None,
        "stage_ms": {k: round(v * 1e3, 2) for k, v in turn.stage_s.items()},
        "library_version": library_version,
    }
