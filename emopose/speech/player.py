"""Speech playback: play(clip, clock) -> the time on the control clock when the audio starts.

player=auto plays the clip's WAV on the default audio device when one exists (sounddevice if it is
importable and lists an output, else `paplay` with a running sound server, else `aplay` with an ALSA
card), otherwise a timed null sink; player=none is always the null sink. play() never blocks and
never raises: gestures are released against the returned start, so a device that cannot be started
(or exits with an error) is logged and replaced by the null sink, and the gesture timeline runs on.
The null sink "plays" for clip.duration_s from the returned start. On a virtual clock (offline
rendering, evaluations) the null sink is used whatever the sink setting: a real device cannot follow
virtual time. The returned start is launch time + latency_s (device output latency, measured per
device; sounddevice reports its own). play(..., follow=True) queues a streamed reply's next sentence:
it starts when the clip playing ends (the device is launched one latency earlier), or at once if
nothing plays; stop() also cancels a clip waiting to follow.
"""

from __future__ import annotations

import logging
import shutil
import subprocess
import threading
from collections.abc import Callable
from pathlib import Path

from emopose.clock import Clock
from emopose.speech.clip import SpeechClip

log = logging.getLogger(__name__)


class Player:
    def __init__(self, sink: str = "auto", latency_s: float = 0.08, command: list[str] | None = None,
                 light: bool = True) -> None:
        """`light`: with a G1 connected (backend=g1 or player=g1) its chest light shows the live session's
        state (emopose/turn/state_light.py); false leaves the light alone."""
        if sink not in ("auto", "none"):
            raise ValueError(f"player.sink must be auto or none, got {sink!r}")
        if latency_s < 0:
            raise ValueError(f"player.latency_s must be >= 0, got {latency_s}")
        self.sink, self.latency_s, self.command = sink, float(latency_s), list(command or [])
        self.light = bool(light)
        self._device: list[str] | object | None | bool = None  # None: not probed yet; False: none/failed
        self._process: subprocess.Popen | None = None
        self._lock = threading.Lock()
        self._generation = 0  # bumped by stop(): a clip scheduled to follow checks it before it starts
        self.started_at: float | None = None
        self.ends_at: float | None = None
        self.clip: SpeechClip | None = None  # the clip started last (the echo gate's reference)
        self.last_sink = "none"
        # on_play(clip, start): told of every clip started (the recording's /speech/said and /speech/audio)
        self.on_play: Callable[[SpeechClip, float], None] | None = None

    # -- public --------------------------------------------------------------------------------
    def play(self, clip: SpeechClip, clock: Clock, follow: bool = False) -> float:
        """`follow` (a streamed reply's next sentence): start when the clip playing ends, not now."""
        if follow and self.playing(clock):
            start = self._follow(clip, clock, self.ends_at)
        else:
            self.stop()  # a new reply cuts the old one off, as the sequencer's interrupt does for gestures
            start = self._start_device(clip, clock)
            if start is None:
                self.last_sink, start = "none", clock.now()
        self.clip, self.started_at, self.ends_at = clip, start, start + clip.duration_s
        if self.on_play is not None:
            self.on_play(clip, start)
        return start

    def expected_latency_s(self, clip: SpeechClip, clock: Clock) -> float:
        """How long after play() the clip will be heard: the sequence stage plans the speech start with it."""
        if self._silent(clip, clock) or not self._probe():
            return 0.0
        return self.latency_s

    def playing(self, clock: Clock) -> bool:
        return self.ends_at is not None and clock.now() < self.ends_at

    def stop(self) -> None:
        with self._lock:
            process, self._process = self._process, None
            self._generation += 1  # clips waiting to follow are not started
        self.ends_at = None
        if process is not None and process.poll() is None:
            process.stopped_by_us = True
            process.terminate()
        if isinstance(self._device, _SoundDevice):
            self._device.stop()

    # -- device --------------------------------------------------------------------------------
    def _silent(self, clip: SpeechClip, clock: Clock) -> bool:
        return self.sink == "none" or not clock.realtime or clip.audio_path is None or clip.duration_s <= 0

    def _follow(self, clip: SpeechClip, clock: Clock, at: float) -> float:
        """Start the clip at `at` (heard then: launched one device latency earlier), unless stop() comes
        first."""
        if self._silent(clip, clock) or not self._probe():
            return at  # the null sink just plays on
        with self._lock:
            generation = self._generation

        def launch() -> None:
            clock.sleep_until(at - self.latency_s)
            with self._lock:
                current = generation == self._generation
            if current:
                self._start_device(clip, clock)

        threading.Thread(target=launch, daemon=True, name="emopose-audio-next").start()
        return at

    def _start_device(self, clip: SpeechClip, clock: Clock) -> float | None:
        if self._silent(clip, clock):
            return None
        device = self._probe()
        if not device:
            return None
        try:
            if isinstance(device, _SoundDevice):
                latency = device.play(Path(clip.audio_path))
                self.last_sink = "sounddevice"
                return clock.now() + (latency if latency is not None else self.latency_s)
            process = subprocess.Popen([*device, str(clip.audio_path)], stdin=subprocess.DEVNULL,
                                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        except Exception as exc:  # a failed device must not stall the gesture timeline
            log.warning("audio device failed to start (%s: %s); using the null sink from now on",
                        type(exc).__name__, exc)
            self._device = False
            return None
        started = clock.now() + self.latency_s
        with self._lock:
            self._process = process
        threading.Thread(target=self._watch, args=(process,), daemon=True, name="emopose-audio").start()
        self.last_sink = Path(device[0]).name
        return started

    def _watch(self, process: subprocess.Popen) -> None:
        _, err = process.communicate()
        if process.returncode != 0 and not getattr(process, "stopped_by_us", False):
            log.warning("audio player %s exited with %s (%s); using the null sink from now on",
                        process.args[0], process.returncode,
                        (err or b"").decode(errors="replace").strip()[:200])
            self._device = False

    def _probe(self):
        if self._device is None:
            self._device = self.command or _find_device() or False
            log.info("speech output: %s", self._device or "null sink (no audio device)")
        return self._device


class _SoundDevice:
    def __init__(self, module) -> None:
        self.sd = module

    def play(self, path: Path) -> float | None:
        import wave

        import numpy as np

        with wave.open(str(path), "rb") as audio:
            rate, frames = audio.getframerate(), audio.readframes(-1)
        self.sd.play(np.frombuffer(frames, dtype=np.int16), rate)
        stream = self.sd.get_stream()
        return getattr(stream, "latency", None)

    def stop(self) -> None:
        self.sd.stop()


def _find_device():
    """The default output, if any: sounddevice, then paplay (sound server running), then aplay (ALSA card)."""
    try:
        import sounddevice

        sounddevice.query_devices(kind="output")
        return _SoundDevice(sounddevice)
    except Exception as exc:  # not installed, no PortAudio, or no output device
        log.debug("sounddevice unavailable: %s", exc)
    paplay, pactl = shutil.which("paplay"), shutil.which("pactl")
    if paplay and pactl and _succeeds([pactl, "info"]):
        return [paplay]
    aplay = shutil.which("aplay")
    cards = Path("/proc/asound/cards")
    if aplay and cards.exists() and "no soundcards" not in cards.read_text():
        return [aplay, "-q"]
    return None


def _succeeds(command: list[str]) -> bool:
    try:
        return subprocess.run(command, capture_output=True, timeout=2, check=False).returncode == 0
    except (OSError, subprocess.SubprocessError):
        return False
