"""The live microphone's wiring on virtual time: barge-in -> silence() once, utterances at VAD end, the echo
reference from the player, and the chest light following the session (emopose/turn/listening.py,
state_light.py, speech/listening.py). Scripted detectors: counters and clock times, no audio models."""

from __future__ import annotations

import wave

import pytest

from emopose.clock import FakeClock
from emopose.speech.clip import SpeechClip
from emopose.speech.g1_microphone import Utterances
from emopose.speech.listening import ListeningSettings, PlaybackReference
from emopose.speech.player import Player
from emopose.speech.vad import CHUNK_BYTES, CHUNK_S
from emopose.turn.listening import Listener
from emopose.turn.state_light import StateLight, session_state


def scripted(probabilities: list[float]):
    values = iter(probabilities)
    return lambda chunk: next(values)


def clip(tmp_path, seconds: float = 2.0, level: int = 8000) -> SpeechClip:
    path = tmp_path / "reply.wav"
    with wave.open(str(path), "wb") as out:
        out.setnchannels(1), out.setsampwidth(2), out.setframerate(16000)
        out.writeframes(int(level).to_bytes(2, "little", signed=True) * int(16000 * seconds))
    return SpeechClip(text="reply", audio_path=str(path), duration_s=seconds, words=[])


def listener(probabilities, clock, player, tmp_path, heard, silenced, reference=None):
    settings = ListeningSettings(hang_ms=320)
    barge = settings.detector(scripted(probabilities))
    return Listener(barge, clock, lambda: player.playing(clock), lambda: (silenced.append(clock.now()),
                                                                          player.stop()),
                    Utterances(barge.vad, tmp_path / "heard", heard.append), reference)


def feed_chunks(clock: FakeClock, target: Listener, count: int) -> None:
    for _ in range(count):
        clock.advance(CHUNK_S)
        target.feed(bytes(CHUNK_BYTES))


def test_voice_over_the_robot_silences_it_once_and_the_utterance_follows(tmp_path):
    clock, player, heard, silenced = FakeClock(), Player(sink="none"), [], []
    player.play(clip(tmp_path, seconds=5.0), clock)
    # 10 quiet chunks, the visitor for 20 (0.9 passes the raised 0.8 threshold), then 20 quiet
    target = listener([0.1] * 10 + [0.9] * 20 + [0.1] * 20, clock, player, tmp_path, heard, silenced)
    feed_chunks(clock, target, 50)
    assert len(silenced) == 1 and len(target.barge_ins) == 1  # once, though the voice goes on
    record = target.barge_ins[0]
    assert record.onset_s == pytest.approx(10 * CHUNK_S)
    assert record.detected_s == pytest.approx(15 * CHUNK_S)  # the 160 ms (5 chunk) window while speaking
    assert record.stopped_s == pytest.approx(silenced[0]) and not player.playing(clock)
    assert len(heard) == 1 and heard[0].name == "utterance-0001.wav"  # ended by 320 ms of silence


def test_below_the_raised_threshold_the_robot_is_not_interrupted(tmp_path):
    clock, player, heard, silenced = FakeClock(), Player(sink="none"), [], []
    player.play(clip(tmp_path, seconds=5.0), clock)
    target = listener([0.7] * 40, clock, player, tmp_path, heard, silenced)  # speech at 0.5, not at 0.8
    feed_chunks(clock, target, 40)
    assert silenced == [] and target.barge_ins == [] and heard == []


def test_between_replies_speech_is_a_turn_not_a_barge_in(tmp_path):
    clock, player, heard, silenced = FakeClock(), Player(sink="none"), [], []
    target = listener([0.6] * 10 + [0.1] * 20, clock, player, tmp_path, heard, silenced)
    feed_chunks(clock, target, 30)
    assert silenced == [] and len(heard) == 1


def test_the_echo_reference_is_the_played_clip_at_the_asked_clock_time(tmp_path):
    clock, player = FakeClock(10.0), Player(sink="none")
    player.play(clip(tmp_path, seconds=1.0, level=1234), clock)
    reference = PlaybackReference(player)
    before = reference(9.5, 2 * 16000)  # half a second of nothing, then the clip's first half second
    assert before[:16000] == bytes(16000)
    assert before[16000:16004] == (1234).to_bytes(2, "little", signed=True) * 2
    assert reference(10.9, 6400)[3200:] == bytes(3200)  # past its end: zeros


def test_unknown_listening_settings_are_refused_by_name():
    with pytest.raises(ValueError, match="unknown setting.*hang_time"):
        ListeningSettings.from_config({"hang_time": 500})
    with pytest.raises(ValueError, match="audio_source must be one of"):
        ListeningSettings.from_config({"audio_source": "usb"})


class FakeLight:
    def __init__(self) -> None:
        self.shown: list[str] = []
        self.closed = False

    def show(self, state: str) -> None:
        self.shown.append(state)

    def close(self) -> None:
        self.closed = True


def test_the_chest_light_follows_listening_thinking_speaking_and_fault(tmp_path):
    clock, player, planning, failure = FakeClock(), Player(sink="none"), [False], [None]
    light = StateLight(FakeLight(), session_state(lambda: planning[0], player, clock, lambda: failure[0]))
    light.step()
    planning[0] = True
    light.step(), light.step()  # unchanged: not sent again
    planning[0] = False
    player.play(clip(tmp_path, seconds=1.0), clock)
    light.step()
    clock.advance(1.5)
    light.step()
    failure[0] = "lowstate lost"
    player.play(clip(tmp_path, seconds=1.0), clock)
    light.step()
    light.close()
    assert light.light.shown == ["listening", "thinking", "speaking", "listening", "fault"]
    assert light.light.closed
