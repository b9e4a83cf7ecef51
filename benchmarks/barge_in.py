"""Barge-in and turn-taking in real time: the serve path's Listener on a live Run (monotonic clock).

    python benchmarks/barge_in.py [--trials 20] [--seed 0] [--echo-db -12] [--out barge_in.json]

Each trial: the robot says a line (planner=local, tts=espeak, player=none: the timed sink, so playing()
and stop() behave as on a device); the microphone, fed in real time in 32 ms chunks, hears the reply's
echo while the robot's speaker plays (it stops at a barge-in) through a room (tests/speech/room.py: a
loudspeaker that compresses peaks, 30 ms delay, a 100 ms response of decaying reflections, -12 dB in all
by default, microphone noise at -65 dBFS; --echo-db changes the level) and a visitor's line (another
espeak voice) from a random time in the reply. One echo model (speech/echo.py) serves all trials, as in
a serve session: it learns the room on the first
replies. Measured per trial: visitor voice start -> robot audio stopped and sequencer interrupted (the
clock after runner.silence() returned), and VAD end -> the robot's first audio of the answer, split
into its stages: the transcript (whisper tiny.en, started early in the hang time: speech/early_asr.py;
asr_wait_ms is what is left of it at VAD end), the pipeline's stages (planner, speech, ...) and the
timeline's pre-roll. Then 20 replies with echo only: every barge-in is a self-trigger. Targets (issue
32): p95 barge-in <= 250 ms, 0 self-triggers; VAD end -> first audio median <= 1.0 s, p95 <= 1.5 s.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from emopose.build import build_run  # noqa: E402
from emopose.speech.audio_in import SAMPLE_RATE, wav_pcm16  # noqa: E402
from emopose.speech.early_asr import EarlyTranscripts  # noqa: E402
from emopose.speech.echo import EchoGate  # noqa: E402
from emopose.speech.espeak import EspeakSynthesizer  # noqa: E402
from emopose.speech.g1_microphone import Utterances  # noqa: E402
from emopose.speech.listening import ListeningSettings, PlaybackReference  # noqa: E402
from emopose.speech.vad import CHUNK_S, CHUNK_SAMPLES, speech_spans  # noqa: E402
from emopose.turn.listening import Listener  # noqa: E402
from tests.conftest import compose_config  # noqa: E402
from tests.speech.room import room_echo  # noqa: E402

LINES = ["Welcome to the museum, the paintings are on the left.",
         "This statue was carved from a single block of stone.",
         "Follow me, I will show you the garden and the fountain.",
         "The old maps are kept in the room behind the stairs.",
         "Thank you for visiting, and have a lovely afternoon."]
VISITOR = ["Excuse me, where are the toilets?", "Wait, can you show me the garden?",
           "Sorry, what is that statue made of?", "Could you point to the exit please?"]


def microphone(reply: bytes, visitor: bytes, at_s: float, echo_db: float) -> tuple[np.ndarray, np.ndarray]:
    """(the reply's echo through the room, the visitor from at_s), both padded by 1.5 s of quiet for the
    hang time: the trial adds the echo only while the robot's speaker plays (it stops at a barge-in)."""
    echo = room_echo(reply, echo_db)
    voice = np.frombuffer(visitor, "<i2").astype(np.float64)
    at = round(at_s * SAMPLE_RATE)
    length = max(len(echo), at + len(voice)) + round(1.5 * SAMPLE_RATE)
    echo_track, voice_track = np.zeros(length), np.zeros(length)
    echo_track[:len(echo)] = echo
    voice_track[at:at + len(voice)] = voice
    return echo_track, voice_track


def heard_chunk(echo: np.ndarray, voice: np.ndarray, k: int, playing: bool) -> bytes:
    span = slice(k * CHUNK_SAMPLES, (k + 1) * CHUNK_SAMPLES)
    mixed = voice[span] + (echo[span] if playing else 0.0)
    return np.clip(mixed, -32768, 32767).astype("<i2").tobytes()


def trial(run, settings, echo, reply_text, visitor_pcm, at_s, out_dir, echo_db) -> dict:
    res, heard = run.resources, []
    turn = run.runner.run(reply_text)
    start = turn.dispatched.speech_start
    echo_track, voice_track = microphone(wav_pcm16(turn.speech.audio_path), visitor_pcm or b"", at_s, echo_db)
    barge = settings.detector(echo=echo)  # the room learned so far: one per microphone and loudspeaker
    early = None if settings.early_transcribe_ms is None else EarlyTranscripts(
        res.asr, out_dir / "early", settings.early_transcribe_ms)
    listener = Listener(barge, res.clock, lambda: res.player.playing(res.clock), run.runner.silence,
                        Utterances(barge.vad, out_dir, heard.append), PlaybackReference(res.player), early)
    vad_end = None
    for k in range(len(voice_track) // CHUNK_SAMPLES):
        res.clock.sleep_until(start + (k + 1) * CHUNK_S)  # the chunk has been heard by now
        playing = res.player.playing(res.clock)
        listener.feed(heard_chunk(echo_track, voice_track, k, playing), at=start + k * CHUNK_S)
        if heard:
            vad_end = time.monotonic()
            break
    out = {"barge_ins": len(listener.barge_ins), "reply_s": turn.speech.duration_s,
           "echo_learned": echo.learned, "echo_gain_db": 20 * np.log10(echo.gain)}
    if visitor_pcm and listener.barge_ins:
        voice_at = start + at_s + speech_spans(visitor_pcm)[0][0]
        out["stop_ms"] = 1000 * (listener.barge_ins[0].stopped_s - voice_at)
        out["interrupted"] = not res.sequencer.pending and not res.player.playing(res.clock)
    if heard:
        out.update(answer_after_vad_end(run, early, heard[0], vad_end, settings.reply_preroll_s))
    if early is not None:
        early.close()
    return out


def answer_after_vad_end(run, early, utterance, vad_end, preroll_at_most) -> dict:
    """VAD end -> the answer's first audio, with each stage's share (ms); a spoken reply's pre-roll is
    bounded as the serve bounds it (asr.listening.reply_preroll_s)."""
    text = early.transcript(utterance) if early else run.resources.asr.utterance(audio=utterance)
    transcribed = time.monotonic()
    answer = run.runner.run(text or "Pardon?", preroll_at_most=preroll_at_most)
    run.runner.silence()
    return {"first_audio_ms": 1000 * (answer.dispatched.speech_start - vad_end),
            "asr_wait_ms": 1000 * (transcribed - vad_end), "early_transcript": bool(early and early.used),
            "stage_ms": {k: round(1000 * v, 1) for k, v in answer.stage_s.items()},
            "preroll_ms": 1000 * answer.schedule.preroll_s,
            "outside_stages_ms": 1000 * (answer.dispatched.speech_start - transcribed)
            - sum(1000 * v for v in answer.stage_s.values()),  # the pre-roll is inside dispatch
            "transcript": text}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--echo-db", type=float, default=-12.0, help="the room's echo return loss")
    parser.add_argument("--out", default="barge_in.json")
    args = parser.parse_args()
    rng, work = random.Random(args.seed), Path(tempfile.mkdtemp(prefix="barge-in-"))
    cfg = compose_config(["tts=espeak", "asr=whisper", "player=none", "planner=local", "run.clock=monotonic",
                          "run.record=false", "pipeline.stages.dispatch.until=none"])
    run = build_run(cfg, work)
    run.session.open().start()
    voices = [EspeakSynthesizer(voice="en-us", rate=rate, pitch=pitch, audio_dir=str(work / f"v{rate}"))
              for rate, pitch in ((140, 85), (180, 30), (155, 70))]
    settings = ListeningSettings.from_config(run.resources.asr.listening)
    echo = EchoGate(CHUNK_SAMPLES, settings.echo_return_loss_db, settings.echo_margin_db)
    try:
        rows, self_triggers = [], 0
        for k in range(args.trials):
            visitor = wav_pcm16(voices[k % 3].synthesize(VISITOR[k % 4]).audio_path)
            at_s = rng.uniform(0.3, 2.0)
            rows.append(trial(run, settings, echo, LINES[k % 5], visitor, at_s, work / f"heard{k}",
                              args.echo_db))
            print(k, rows[-1], flush=True)
        for k in range(args.trials):
            self_triggers += trial(run, settings, echo, LINES[k % 5], None, 0.0, work / f"echo{k}",
                                   args.echo_db)["barge_ins"]
    finally:
        run.session.close()
    stops = [r["stop_ms"] for r in rows if "stop_ms" in r]
    first = [r["first_audio_ms"] for r in rows if "first_audio_ms" in r]
    summary = {"trials": args.trials, "detected": len(stops), "interrupted": sum(r.get("interrupted", 0)
                                                                              for r in rows),
               "stop_ms_p50": float(np.percentile(stops, 50)), "stop_ms_p95": float(np.percentile(stops, 95)),
               "stop_ms_max": max(stops), "self_triggers": self_triggers, "self_trigger_replies": args.trials,
               "first_audio_ms_median": float(np.median(first)), "first_audio_ms_p95":
               float(np.percentile(first, 95)), "turns_answered": len(first),
               "asr_wait_ms_median": float(np.median([r["asr_wait_ms"] for r in rows if "asr_wait_ms" in r])),
               "early_transcripts_used": sum(r.get("early_transcript", False) for r in rows),
               "echo_db": args.echo_db, "load_average": os.getloadavg(), "rows": rows}
    Path(args.out).write_text(json.dumps(summary, indent=1))
    print(json.dumps({k: v for k, v in summary.items() if k != "rows"}, indent=1))


if __name__ == "__main__":
    main()
