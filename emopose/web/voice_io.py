"""serve's ears and chest light: the visitor's microphone into VAD, barge-in and ASR; the light shows state.

Ears (when the recognizer transcribes audio, asr=whisper or litellm; settings asr.listening,
emopose/speech/listening.py): the page's microphone arrives as binary WebSocket messages (16 kHz mono
int16, LiveSession.hear) and, with audio_source=g1, the robot's microphone multicast feeds the same
Listener. While the robot speaks a barge-in interrupts it (LiveSession.interrupt: the reply stops,
the audio stops, the sequencer is interrupted, the arms return to rest); each utterance the VAD ends
(after hang_ms of silence) is transcribed and said on the turn worker (LiveSession.say_heard).
Light (a G1 connected: player=g1, or backend=g1 with the host's audio; player.light=false turns it
off): listening, thinking, speaking, fault (emopose/turn/state_light.py).
"""

from __future__ import annotations

import logging

from emopose.speech.g1_microphone import RobotMicrophone, Utterances
from emopose.speech.listening import ListeningSettings, PlaybackReference
from emopose.turn.listening import Listener
from emopose.turn.state_light import StateLight, session_state

log = logging.getLogger(__name__)


class VoiceIO:
    def __init__(self, session) -> None:
        res = session.res
        self.listener: Listener | None = None
        self.microphone: RobotMicrophone | None = None
        self.light: StateLight | None = chest_light(session)
        if session.hears_speech:
            settings = ListeningSettings.from_config(res.asr.listening)
            self.listener = listener_for(session, settings)
            if settings.audio_source == "g1":
                self.microphone = RobotMicrophone(self.listener.feed, settings.mic_group, settings.mic_port,
                                                  settings.mic_interface_ip).start()

    def hear(self, pcm: bytes) -> bool:
        """The page's microphone; False when this session does not listen."""
        if self.listener is None:
            return False
        self.listener.feed(pcm)
        return True

    def close(self) -> None:
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
    return Listener(barge, res.clock, lambda: res.player.playing(res.clock), silence, utterances, reference)


def chest_light(session) -> StateLight | None:
    """The chest light's follower when a G1 is connected and player.light allows it; else None."""
    res = session.res
    if not res.player.light:
        return None
    voice = getattr(res.player, "voice", None)  # player=g1 shares its voice client
    colours = getattr(res.player, "light_colours", None)
    if voice is None and res.backend.name == "g1":
        from emopose.backends.g1.voice import VoiceClient

        settings = res.backend.settings
        voice = VoiceClient(settings.domain_id, settings.network_interface)
    if voice is None:
        return None
    from emopose.backends.g1.chest_light import ChestLight

    state = session_state(lambda: session.run.runner.planning, res.player, res.clock,
                          lambda: getattr(res.backend, "failure", None))
    return StateLight(ChestLight(voice, colours), state).start()
