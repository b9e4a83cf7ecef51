"""serve's ears and chest light: the visitor's microphone into VAD, barge-in and ASR; the light shows state.

Ears (when the recognizer transcribes audio, asr=whisper or litellm; settings asr.listening,
emopose/speech/listening.py): the page's microphone (static/mic.js) arrives as binary WebSocket messages
(16 kHz mono int16, LiveSession.hear; state() tells the page what the VAD hears) and, with
audio_source=g1, the robot's microphone multicast feeds the same Listener. The visitor's voice holds the
listening posture. While the robot speaks a barge-in interrupts it (LiveSession.interrupt: the reply stops,
the audio stops, the sequencer is interrupted, the arms return to rest); each utterance the VAD ends
(after hang_ms of silence) is transcribed and said on the turn worker (LiveSession.say_heard).
Light (a G1 connected: player=g1, or backend=g1 with the host's audio; player.light=false turns it
off): listening, thinking (from the request until the reply plays), speaking, fault
(emopose/turn/state_light.py).
"""

from __future__ import annotations

import logging

from emopose.execution.posture import LISTENING, REST
from emopose.speech.early_asr import EarlyTranscripts
from emopose.speech.g1_microphone import RobotMicrophone, Utterances
from emopose.speech.listening import ListeningSettings, PlaybackReference
from emopose.turn.listening import Listener
from emopose.turn.state_light import StateLight, chest_light_for

log = logging.getLogger(__name__)


class VoiceIO:
    def __init__(self, session) -> None:
        res = session.res
        self.listener: Listener | None = None
        self.microphone: RobotMicrophone | None = None
        self.light: StateLight | None = chest_light(session)
        self.posture = res.sequencer.posture
        self.asr = res.asr
        self.reply_preroll_s: float | None = None  # a spoken reply's pre-roll bound (asr.listening)
        if session.hears_speech:
            settings = ListeningSettings.from_config(res.asr.listening)
            self.reply_preroll_s = settings.reply_preroll_s
            self.listener = listener_for(session, settings)
            if settings.audio_source == "g1":
                self.microphone = RobotMicrophone(self.hear, settings.mic_group, settings.mic_port,
                                                  settings.mic_interface_ip).start()

    def hear(self, pcm: bytes) -> bool:
        """The page's (or the robot's) microphone; False when this session does not listen. The visitor's
        voice holds the listening posture; its end gives it up (the reply's planning then holds thinking)."""
        if self.listener is None:
            return False
        for event in self.listener.feed(pcm):
            self.posture.request(LISTENING if event.kind == "start" else REST)
        return True

    def transcript(self, audio_path) -> str:
        """An utterance the VAD ended, transcribed (mostly during the hang time already: early_asr.py)."""
        early = self.listener.early if self.listener is not None else None
        return early.transcript(audio_path) if early else self.asr.utterance(audio=audio_path)

    def state(self) -> dict | None:
        """For the page (state.voice): whether the VAD hears the visitor now, and how many utterances it
        has ended (each is transcribed, then said: its turn_started message carries the transcript)."""
        if self.listener is None:
            return None
        ended = self.listener.utterances.count if self.listener.utterances is not None else 0
        return {"speaking": self.listener.visitor_speaking, "utterances": ended}

    def close(self) -> None:
        if self.listener is not None and self.listener.early is not None:
            self.listener.early.close()
        if self.microphone is not None:
            self.microphone.stop()
        if self.light is not None:
            self.light.close()


def listener_for(session, settings: ListeningSettings) -> Listener:
    """The session's Listener: barge-in interrupts it, utterances go to say_heard; the robot's own
    playback is the echo reference only for its own microphone (the page's browser cancels echo)."""
    res = session.res
    barge = settings.detector()
    utterances = Utterances(barge.vad, session.run.session.run_dir / "heard", session.say_heard)
    reference = PlaybackReference(res.player) if settings.audio_source == "g1" else None
    silence = session.interrupt if settings.barge_in else (lambda: None)
    early = None if settings.early_transcribe_ms is None else EarlyTranscripts(
        res.asr, session.run.session.run_dir / "heard" / "early", settings.early_transcribe_ms)
    return Listener(barge, res.clock, lambda: res.player.playing(res.clock), silence, utterances, reference,
                    early)


def chest_light(session) -> StateLight | None:
    """The chest light's follower when a G1 is connected and player.light allows it; else None."""
    def thinking() -> bool:  # from the request (PendingPlan) until its first sentence is handed over
        return session.run.runner.planning or session.pending.state() is not None

    return chest_light_for(session.res, thinking)
