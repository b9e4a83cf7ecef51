"""What a recording needs so its speech-gesture sync can be measured again from session.mcap alone.

Two channels, on the recording's session clock like every time in it (the `t` of /joints/command):
  /sequencer/events  every sequencer event as it happens: {t, kind, name, command_id, detail}
  /speech/timeline   per dispatched turn, the planned and executed timeline: the speech start and
                     duration, each word's onset and text span, and per planned gesture its command,
                     stroke-start keyframe, trigger onset, planned and executed stroke arrival (s from
                     speech start) and drop reason.
`read_stroke_sync(recording)` rebuilds the streams and runs the same measurement as sync_eval;
`read_gold_anchor_sync(recording, items)` measures the same executed strokes against annotated anchors of
the texts that were spoken (sync_eval's stroke-vs-gold-anchor, for a served session driven with suite
texts). A recording is the MCAP's path or what read_recording gave for it (a long session's file takes
minutes to decode: read it once).
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from emopose import STROKE_TOLERANCE
from emopose.contract import EventKind, trigger_position
from emopose.recording import read_recording
from emopose.speech.espeak_lib import WordEvent
from emopose.sync.affiliate import gold_anchor_strokes
from emopose.sync.strokes import PlannedStroke, Streams, StrokeSync, measure_strokes, planned_strokes
from emopose.sync.words import annotated_spans

Recording = str | Path | dict  # an MCAP path, or the topics read_recording gave for it

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


def read_stroke_sync(recording: Recording, tolerance: float = STROKE_TOLERANCE) -> list[StrokeSync]:
    """Every recorded turn's strokes against their words' onsets, from the MCAP alone."""
    return [row for _, _, rows in recorded_turns(recording, tolerance) for row in rows]


def read_gold_anchor_sync(recording: Recording, items: Sequence[tuple[str, Sequence[str]]],
                          tolerance: float = STROKE_TOLERANCE) -> tuple[list[StrokeSync], int]:
    """The recorded strokes against the annotated anchors of the texts spoken, in the order they were
    spoken (items: (text, anchors)); a turn is one item's whole text or one sentence of it. Returns the
    per-anchor rows (as sync_eval's stroke-vs-gold-anchor: an anchor without a gesture counts as not
    arrived; one that is not in its own text is left out) and how many anchors were not in any recorded
    turn (a text not spoken, or spoken changed)."""
    rows, unspoken, queue = [], 0, iter(items)
    current = None  # (text, anchor spans not yet assigned, search cursor)
    for name, turn, strokes in recorded_turns(recording, tolerance):
        said = turn["text"]
        start = -1 if current is None else current[0].find(said, current[2])
        while start < 0:  # the turn starts the next item: the anchors left of the last one were not said
            unspoken += 0 if current is None else sum(span is not None for span in current[1])
            text, anchors = next(queue, (None, ()))
            if text is None:
                raise ValueError(f"a recorded turn matches no item left: {said[:60]!r}")
            current = (text, annotated_spans(text, tuple(anchors)), 0)
            start = text.find(said)
        text, spans, _ = current
        end = start + len(said)
        inside = [(a - start, b - start) for a, b in (s for s in spans if s is not None) if start <= a < end]
        current = (text, [s for s in spans if s is None or not start <= s[0] < end], end)
        events = [WordEvent(w["char_start"], w["char_end"] - w["char_start"], w["start_s"])
                  for w in turn["words"]]
        rows += gold_anchor_strokes(name, said, inside,
                                    [g["trigger"] for g in turn["gestures"]], strokes, events)
    if current is not None:
        unspoken += sum(span is not None for span in current[1])
    return rows, unspoken + sum(len(anchors) for _, anchors in queue)


def recorded_turns(recording: Recording,
                   tolerance: float = STROKE_TOLERANCE) -> Iterator[tuple[str, dict, list[StrokeSync]]]:
    """Each recorded /speech/timeline turn: its name ("turn-N"), message and gestures' measured strokes."""
    topics = recording if isinstance(recording, dict) else read_recording(recording)
    if TIMELINE not in topics:
        source = "the recording" if isinstance(recording, dict) else recording
        raise ValueError(f"{source}: no {TIMELINE} channel (recorded before stroke-sync recording existed?)")
    commands = topics.get("/joints/command", [])
    times = np.array([m["t"] for _, m in commands])
    q = np.array([m["q"] for _, m in commands])
    sim = topics.get("/joints/sim")
    sim_times = None if sim is None else np.array([m["t"] for _, m in sim])  # once, not per turn
    sim_q = None if sim is None else np.array([m["q"] for _, m in sim])
    events = [(m["t"], m["kind"], m["command_id"]) for _, m in topics.get(EVENTS, [])]
    for number, (_, turn) in enumerate(topics[TIMELINE]):
        planned = [PlannedStroke(g["k"], g["motion"], g["command_id"], np.asarray(g["keyframe"]),
                                 g["planned_s"], g["dropped"]) for g in turn["gestures"]]
        streams = Streams(events, turn["speech_start"], times, q, sim_times, sim_q)
        name = f"turn-{number}"
        yield name, turn, measure_strokes(name, planned, [g["onset_s"] for g in turn["gestures"]], streams,
                                          turn["preroll_s"], tolerance)
