"""What a recording needs so its speech-gesture sync can be measured again from session.mcap alone.

Two channels, on the recording's session clock like every time in it (the `t` of /joints/command):
  /sequencer/events  every sequencer event as it happens: {t, kind, name, command_id, detail}
  /speech/timeline   per dispatched turn, the planned and executed timeline: the speech start and
                     duration, each word's onset and text span, and per planned gesture its command,
                     stroke-start keyframe, trigger onset, planned and executed stroke arrival (s from
                     speech start) and drop reason.
`read_stroke_sync(path)` rebuilds the streams and runs the same measurement as sync_eval.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from emopose import STROKE_TOLERANCE
from emopose.contract import EventKind, trigger_position
from emopose.recording import read_recording
from emopose.sync.strokes import PlannedStroke, Streams, StrokeSync, measure_strokes, planned_strokes

EVENTS, TIMELINE = "/sequencer/events", "/speech/timeline"


def event_message(event, stream_t: float) -> dict:
    """A sequencer event as recorded on /sequencer/events, at its stream time (Recorder.write puts `t` on
    the session clock)."""
    return {"t": stream_t, "kind": event.kind, "name": event.name, "command_id": event.command_id,
            "detail": event.detail}


def speech_timeline(turn) -> dict:
    """A dispatched turn's /speech/timeline message, its times read from the loop's clock (as
    Recorder.write_now takes them)."""
    speech, plan, speech_start = turn.speech, turn.plan, turn.dispatched.speech_start
    strokes = {e.command_id: e.t - speech_start for e in turn.dispatched.events if e.kind == EventKind.STROKE}
    gestures = []
    for stroke, record in zip(planned_strokes(turn), (m.resolved.record for m in turn.schedule.gestures)):
        position = trigger_position(plan.reply, record.trigger)
        gestures.append({"k": stroke.k, "motion": stroke.motion, "command_id": stroke.command_id,
                         "keyframe": stroke.keyframe.tolist(), "planned_s": stroke.planned_s,
                         "executed_s": strokes.get(stroke.command_id), "dropped": stroke.dropped,
                         "trigger": record.trigger,
                         "onset_s": None if position is None else speech.onset_at_char(position)})
    return {"speech_start": speech_start, "duration_s": speech.duration_s,
            "text": speech.text, "preroll_s": turn.schedule.preroll_s,
            "words": [{"text": w.text, "char_start": w.char_start, "char_end": w.char_end,
                       "start_s": w.start_s} for w in speech.words],
            "gestures": gestures}


def read_stroke_sync(path: str | Path, tolerance: float = STROKE_TOLERANCE) -> list[StrokeSync]:
    """Every recorded turn's strokes against their words' onsets, from the MCAP alone."""
    topics = read_recording(path)
    if TIMELINE not in topics:
        raise ValueError(f"{path}: no {TIMELINE} channel (recorded before stroke-sync recording existed?)")
    commands = topics.get("/joints/command", [])
    times = np.array([m["t"] for _, m in commands])
    q = np.array([m["q"] for _, m in commands])
    sim = topics.get("/joints/sim")
    events = [(m["t"], m["kind"], m["command_id"]) for _, m in topics.get(EVENTS, [])]
    rows = []
    for number, (_, turn) in enumerate(topics[TIMELINE]):
        planned = [PlannedStroke(g["k"], g["motion"], g["command_id"], np.asarray(g["keyframe"]),
                                 g["planned_s"], g["dropped"]) for g in turn["gestures"]]
        streams = Streams(events, turn["speech_start"], times, q,
                          None if sim is None else np.array([m["t"] for _, m in sim]),
                          None if sim is None else np.array([m["q"] for _, m in sim]))
        rows += measure_strokes(f"turn-{number}", planned, [g["onset_s"] for g in turn["gestures"]], streams,
                                turn["preroll_s"], tolerance)
    return rows
