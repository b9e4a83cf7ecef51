"""listen with job.barge_in_at_s: the visitor speaks again while the robot answers, on the run's clock.

The first turn (audio=PATH) is dispatched without waiting; then the microphone is simulated chunk by chunk
(32 ms) in step with the control loop: the robot's own reply as its echo (job.echo_gain, -12 dB by
default, 20 ms late) plus the visitor's second recording (job.barge_in_audio) from barge_in_at_s after
the reply's audio started. It goes through the serve path's Listener (VAD, the echo gate with the
reply as reference, barge-in -> runner.silence()). When the VAD ends the visitor's turn (asr.listening.
hang_ms of silence) the utterance is transcribed and answered as a second turn.
Reported: when the barge-in stopped the robot after the visitor's voice began (its onset in the
recording found by the same VAD on the clean recording), and VAD end -> the robot's first audio: the
measured ASR + planner + synthesis + scheduling time (wall) plus the timeline's pre-roll (run clock).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from emopose.resources import Run
from emopose.speech.audio_in import SAMPLE_RATE, load_audio, wav_pcm16
from emopose.speech.g1_microphone import Utterances
from emopose.speech.listening import ListeningSettings, PlaybackReference
from emopose.speech.vad import CHUNK_BYTES, CHUNK_S, speech_spans
from emopose.turn.listening import Listener
from emopose.turn.runner import TurnRunner

ECHO_DELAY_S = 0.02
TAIL_S = 1.5  # microphone silence after the last sound: the hang time ends the visitor's turn in it


def barge_in_turns(run: Run, asr, first_text: str, second_audio: Path, at_s: float,
                   echo_gain: float) -> dict:
    """The first turn, the visitor's interruption at at_s into its audio, the second turn."""
    res = run.resources
    no_wait = run.runner.pipeline.reconfigured(dispatch=lambda stage: stage.waiting_until("none"))
    live = run.runner.with_pipeline(no_wait)
    first = live.run(first_text)
    visitor = load_audio(second_audio, asr.max_duration_s).pcm16()
    onsets = speech_spans(visitor, **vad_settings(asr))
    if not onsets:
        raise ValueError(f"job.barge_in_audio {second_audio.name}: no speech found in it")
    start = first.dispatched.speech_start
    mic = microphone(wav_pcm16(first.speech.audio_path), visitor, at_s, echo_gain)
    heard: list[Path] = []
    settings = ListeningSettings.from_config(asr.listening)
    barge = settings.detector()
    listener = Listener(barge, res.clock, lambda: res.player.playing(res.clock), live.silence,
                        Utterances(barge.vad, res.run_dir / "heard", heard.append),
                        PlaybackReference(res.player))
    vad_end = feed(run, listener, mic, start, heard)
    voice_at = start + at_s + onsets[0][0]
    result = {"barge_in_at_s": at_s, "visitor_voice_at_s": at_s + onsets[0][0], "reply": first.plan.reply,
              "barge_ins": [{"onset_after_voice_ms": 1000 * (b.onset_s - voice_at),
                             "detected_after_voice_ms": 1000 * (b.detected_s - voice_at),
                             "stopped_after_voice_ms": 1000 * (b.stopped_s - voice_at)}
                            for b in listener.barge_ins],
              "sequencer_pending_after": len(res.sequencer.pending), "player_playing_after": bool(
                  res.player.playing(res.clock))}
    if heard:
        result["second"] = second_turn(run.runner, asr, heard[0], vad_end, res.clock)
    return result


def vad_settings(asr) -> dict:
    s = ListeningSettings.from_config(asr.listening)
    return {"threshold": s.threshold, "min_speech_ms": s.min_speech_ms, "hang_ms": s.hang_ms}


def microphone(reply: bytes, visitor: bytes, at_s: float, echo_gain: float) -> bytes:
    """What the robot's microphone hears from the reply's start: its echo plus the visitor from at_s."""
    echo = np.frombuffer(reply, "<i2").astype(np.float32) * echo_gain
    voice = np.frombuffer(visitor, "<i2").astype(np.float32)
    delay, at = round(ECHO_DELAY_S * SAMPLE_RATE), round(at_s * SAMPLE_RATE)
    out = np.zeros(max(delay + len(echo), at + len(voice)) + round(TAIL_S * SAMPLE_RATE), np.float32)
    out[delay:delay + len(echo)] += echo
    out[at:at + len(voice)] += voice
    return np.clip(out, -32768, 32767).astype("<i2").tobytes()


def feed(run: Run, listener: Listener, mic: bytes, start: float, heard: list) -> float | None:
    """Feed the microphone chunk by chunk as the loop reaches each chunk's end; the clock time the VAD
    ended the visitor's turn (None if it never did)."""
    loop, clock = run.session.loop, run.resources.clock
    for k in range(len(mic) // CHUNK_BYTES):
        end = start + (k + 1) * CHUNK_S
        if clock.now() < end:
            loop.wait_until(lambda end=end: clock.now() >= end - 1e-9, end - clock.now() + 1.0)
        listener.feed(mic[k * CHUNK_BYTES:(k + 1) * CHUNK_BYTES], at=start + k * CHUNK_S)
        if heard:
            return clock.now()
    return None


def second_turn(runner: TurnRunner, asr, path: Path, vad_end: float, clock) -> dict:
    """Transcribe the visitor's utterance and answer it; VAD end -> first audio (see the module doc)."""
    heard = asr.transcribe_detail(path)
    if not heard.text:
        return {"transcript": "", "warnings": heard.warnings}
    turn_start = clock.now()
    turn = runner.run(heard.text)
    compute_s = heard.asr_s + sum(s for name, s in turn.stage_s.items() if name != "dispatch")
    preroll_s = turn.dispatched.speech_start - turn_start
    return {"transcript": heard.text, "reply": turn.plan.reply, "asr_ms": 1000 * heard.asr_s,
            "vad_end_s": vad_end, "vad_end_to_first_audio_ms": 1000 * (compute_s + preroll_s),
            "compute_ms": 1000 * compute_s, "preroll_ms": 1000 * preroll_s}
