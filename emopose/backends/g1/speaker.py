"""player=g1: the reply's audio from the robot's own speaker, streamed over DDS (voice service).

play() resamples the clip's WAV (any synthesizer's: espeak, piper, hosted) to 16 kHz mono 16-bit,
cuts it into `chunk_s` chunks and queues them on the VoiceSender, which sends each `lead_s` before
its play time (voice.chunk_schedule); it returns launch + `latency_s`, the launch-to-sound latency
measured on the robot (README: "The G1's voice"), so the timeline plans strokes against the sound as
heard from the robot. A new reply is a new stream id (the robot cuts the old one); a streamed reply's
next sentence (follow=True) continues the same stream. stop() (interrupt, barge-in, silence()) drops
what is not sent and sends stop play (1004), before any chunk of a later reply.

Faults never raise into the turn: the voice service not answering when first used (or when retried,
every `retry_s`), a refused request or a chunk not answered mid-stream give one warning, and until the
next retry the replies play through `fallback` (auto: the host's audio device, exactly as player=auto;
none: the timed null sink). A clip whose chunks stopped mid-stream is not retimed: the arms keep the
timeline they were given. Virtual-time runs use the fallback's null sink, as player=auto does.
"""

from __future__ import annotations

import itertools
import logging
import time
import wave

from emopose.backends.g1.voice import (
    PCM_BYTES_PER_SECOND,
    VOICE_SERVICE,
    VoiceClient,
    checked_volume,
    chunk_schedule,
    robot_pcm,
)
from emopose.backends.g1.voice_sender import Chunk, VoiceSender
from emopose.clock import Clock
from emopose.speech.clip import SpeechClip
from emopose.speech.player import Player

log = logging.getLogger(__name__)
FALLBACKS = ("auto", "none")


class G1Player(Player):
    def __init__(self, latency_s: float = 0.25, lead_s: float = 0.3, chunk_s: float = 0.1,
                 app_name: str = "emopose", volume: int | None = None, fallback: str = "auto",
                 retry_s: float = 10.0, domain_id: int = 0, network_interface: str | None = None,
                 service: str = VOICE_SERVICE, timeout_s: float = 1.0, light: bool = True,
                 light_colours: dict | None = None) -> None:
        super().__init__(sink="auto", latency_s=latency_s, light=light)
        self.light_colours = {k: tuple(v) for k, v in (light_colours or {}).items()}  # chest_light.COLOURS
        if fallback not in FALLBACKS:
            raise ValueError(f"player.fallback must be one of {FALLBACKS}, got {fallback!r}")
        if not 0.02 <= chunk_s <= 1.0 or lead_s <= 0 or retry_s < 0:
            raise ValueError(f"player.chunk_s must be in [0.02, 1] s, lead_s > 0 and retry_s >= 0; got "
                             f"{chunk_s}, {lead_s}, {retry_s}")
        if not app_name:
            raise ValueError("player.app_name is empty: the robot's stop play names the app")
        self.volume = None if volume is None else checked_volume(volume)
        self.lead_s, self.retry_s, self.app_name = float(lead_s), float(retry_s), app_name
        self.chunk_bytes = 2 * max(1, round(chunk_s * PCM_BYTES_PER_SECOND / 2))
        self.voice = VoiceClient(domain_id, network_interface, service, timeout_s)
        self.fallback = Player(sink=fallback)
        self.sender = VoiceSender(self.voice, app_name, self._link_failed)
        self._link: bool | None = None  # None: not tried; a failure sets False until _retry_at
        self._retry_at = 0.0
        self._stream_id: str | None = None
        self._stream_ids = itertools.count(time.time_ns() // 1_000_000)  # ms, as Unitree's example
        self.clips: list[tuple[str, int, float, float]] = []  # (stream id, bytes, launch, sound start)

    # -- the Player interface --------------------------------------------------------------------
    def play(self, clip: SpeechClip, clock: Clock, follow: bool = False) -> float:
        if self._silent(clip, clock) or not self._connected():
            self._stream_id = None
            start = self.fallback.play(clip, clock, follow)
            host = self.fallback
            self.last_sink, self.started_at, self.ends_at = host.last_sink, host.started_at, host.ends_at
            self.clip = clip
            return start
        return super().play(clip, clock, follow)

    def expected_latency_s(self, clip: SpeechClip, clock: Clock) -> float:
        if self._silent(clip, clock) or not self._connected():
            return self.fallback.expected_latency_s(clip, clock)
        return self.latency_s

    def stop(self) -> None:
        with self._lock:
            self._generation += 1  # a sentence waiting to follow is not started
            streaming, self._stream_id = self._stream_id, None
        self.ends_at = None
        if streaming is not None:
            self.sender.stop()
        self.fallback.stop()

    def close(self) -> None:
        """Stop the sound, send the pending stop, and leave the DDS domain."""
        self.stop()
        deadline = time.monotonic() + self.voice.timeout_s
        while not self.sender.idle and time.monotonic() < deadline:
            time.sleep(0.01)
        self.sender.close()
        self.voice.close()

    # -- the device (called by Player.play and its follow thread) --------------------------------
    def _probe(self) -> bool:
        return bool(self._link)

    def _start_device(self, clip: SpeechClip, clock: Clock) -> float | None:
        try:
            pcm = robot_pcm(clip.audio_path)
        except (OSError, ValueError, EOFError, wave.Error) as exc:
            log.warning("player=g1: cannot read %s (%s); this clip is silent", clip.audio_path, exc)
            return None
        with self._lock:
            if self._stream_id is None:  # a new reply; a following sentence continues the stream
                self._stream_id = str(next(self._stream_ids))
            stream_id = self._stream_id
        launch = clock.now()
        sound_start = launch + self.latency_s
        schedule = chunk_schedule(len(pcm), self.chunk_bytes, launch, sound_start, self.lead_s)
        self.sender.queue([Chunk(stream_id, pcm[a:b], send, play) for a, b, send, play in schedule], clock)
        self.clips.append((stream_id, len(pcm), launch, sound_start))
        self.last_sink = "g1"
        return sound_start

    # -- the link ------------------------------------------------------------------------------
    def _connected(self) -> bool:
        """Whether the voice service answers; tried on first use, then again every retry_s."""
        if self._link or time.monotonic() < self._retry_at:
            return bool(self._link)
        try:
            if self.volume is not None:
                self.voice.set_volume(self.volume)
            else:
                self.voice.get_volume()  # proves requests and responses both get through
            self._link = True
        except Exception as exc:  # noqa: BLE001 - no cyclonedds, no robot, a refusal: all fall back
            self._link_failed(exc)
        return bool(self._link)

    def _link_failed(self, exc: Exception) -> None:
        self._link, self._retry_at = False, time.monotonic() + self.retry_s
        log.warning("player=g1: the robot's voice service failed (%s: %s); replies play through "
                    "player.fallback=%s, the robot is tried again in %g s", type(exc).__name__,
                    str(exc)[:200], self.fallback.sink, self.retry_s)
