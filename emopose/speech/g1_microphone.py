"""The visitor's voice from the G1's own microphones: UDP multicast 239.168.123.161:5555.

The robot's voice module sends its (noise-suppressed) microphone signal as raw 16 kHz mono 16-bit
little-endian PCM datagrams to that group while its voice mode lets it (README: "The G1's voice,
ears and chest light"). RobotMicrophone hands every datagram to `on_pcm`, the same PCM stream the
host path's detectors take: VoiceActivity.feed, BargeIn.feed (vad.py, barge_in.py). Utterances turns
that stream into WAV files at each end of speech and calls `on_utterance(path)`, e.g. with
`lambda path: recognizer.utterance(audio=path)` (asr=whisper or asr=litellm, unchanged).

The robot's own playback is gated out: while `speaking()` is true (give it the player's
`lambda: player.playing(clock)`) and for `tail_s` after, each datagram is replaced by silence of the
same length, so stream time stays continuous and the VAD hears nothing of the robot (nor the visitor:
barge-in over the robot's voice needs gate off and BargeIn's echo reference instead).
A silent group (no datagram for `silence_warn_s`) gives one warning naming the group, port and the
voice-mode switch, and `silent` is True until datagrams come; nothing raises. group=None listens on
plain UDP (a local port: tests, or a relay).
"""

from __future__ import annotations

import logging
import socket
import struct
import threading
import time
from collections.abc import Callable
from pathlib import Path

from emopose.speech.audio_in import SAMPLE_RATE
from emopose.speech.vad import CHUNK_BYTES, SpeechEvent, VoiceActivity
from emopose.speech.wav import write_wav

log = logging.getLogger(__name__)

MIC_GROUP = "239.168.123.161"
MIC_PORT = 5555
RECEIVE_BYTES = 65536


class RobotMicrophone:
    def __init__(self, on_pcm: Callable[[bytes], object], group: str | None = MIC_GROUP, port: int = MIC_PORT,
                 interface_ip: str = "0.0.0.0", speaking: Callable[[], bool] | None = None,
                 tail_s: float = 0.3, silence_warn_s: float = 3.0) -> None:
        if not 0 < port < 65536 or tail_s < 0 or silence_warn_s <= 0:
            raise ValueError(f"microphone: port must be 1-65535, tail_s >= 0, silence_warn_s > 0; got "
                             f"{port}, {tail_s}, {silence_warn_s}")
        self.on_pcm, self.group, self.port, self.interface_ip = on_pcm, group, port, interface_ip
        self.speaking, self.tail_s, self.silence_warn_s = speaking, tail_s, silence_warn_s
        self.received_bytes = self.muted_bytes = 0
        self.silent = False
        self._gate_until = -float("inf")
        self._socket: socket.socket | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def where(self) -> str:
        group = f"multicast {self.group}" if self.group else "UDP"
        return f"{group} port {self.port} on interface {self.interface_ip}"

    def start(self) -> RobotMicrophone:
        """Join the group and start receiving; an OSError (no such interface) names the address."""
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            sock.bind(("" if self.group else self.interface_ip, self.port))
            if self.group:
                group, interface = socket.inet_aton(self.group), socket.inet_aton(self.interface_ip)
                membership = struct.pack("=4s4s", group, interface)
                sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
            sock.settimeout(0.1)
        except OSError as exc:
            sock.close()
            raise OSError(f"microphone: cannot listen on {self.where()}: {exc}") from exc
        self._socket = sock
        self._stop.clear()
        self._thread = threading.Thread(target=self._receive, name="emopose-g1-mic", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=1.0)
        if self._socket is not None:
            self._socket.close()
        self._thread = self._socket = None

    def _receive(self) -> None:
        last_packet = time.monotonic()
        while not self._stop.is_set():
            try:
                data = self._socket.recv(RECEIVE_BYTES)
            except TimeoutError:
                self._check_silence(time.monotonic() - last_packet)
                continue
            except OSError:
                return  # closed under us by stop()
            last_packet = time.monotonic()
            if self.silent:
                log.info("microphone: datagrams arrive again on %s", self.where())
                self.silent = False
            self._deliver(data[: len(data) - len(data) % 2])

    def _check_silence(self, quiet_s: float) -> None:
        if quiet_s >= self.silence_warn_s and not self.silent:
            self.silent = True
            log.warning("microphone: nothing on %s for %.0f s: is the robot's voice mode on (wake-up mode in "
                        "the Unitree app), and is interface_ip our address on the robot's network? The web "
                        "page's microphone (host audio) still works", self.where(), quiet_s)

    def _deliver(self, pcm: bytes) -> None:
        """Pass the datagram on, or silence of its length while the robot speaks (and tail_s after)."""
        now = time.monotonic()
        speaking = self.speaking is not None and self.speaking()
        if speaking:
            self._gate_until = now + self.tail_s
        self.received_bytes += len(pcm)
        if speaking or now < self._gate_until:
            self.muted_bytes += len(pcm)
            pcm = bytes(len(pcm))
        self.on_pcm(pcm)


class Utterances:
    """A PCM stream -> one WAV per utterance (VAD start to end, with `pad_s` before), on_utterance(path)."""

    def __init__(self, vad: VoiceActivity, folder: str | Path, on_utterance: Callable[[Path], object],
                 pad_s: float = 0.2) -> None:
        self.vad, self.folder, self.on_utterance = vad, Path(folder), on_utterance
        self.folder.mkdir(parents=True, exist_ok=True)
        self.pad_bytes = 2 * round(pad_s * SAMPLE_RATE)
        self._pcm = b""     # everything since the last utterance ended (trimmed while nobody speaks)
        self._offset_s = 0.0  # stream time of self._pcm[0]
        self.count = 0

    def feed(self, pcm: bytes) -> None:
        self.take(pcm, self.vad.feed(pcm))

    def take(self, pcm: bytes, events: list[SpeechEvent]) -> None:
        """PCM and the events its VAD (fed by someone else: a BargeIn) reported for it."""
        self._pcm += pcm
        for event in events:
            if event.kind == "start":
                self._drop(max(0, self._byte_at(event.t_s) - self.pad_bytes))
            else:
                self._emit(self._byte_at(event.t_s))
        # While nobody speaks keep only what a start can still reach back to: its onset is reported
        # min_speech_chunks late, plus the padding and the VAD's partial chunk.
        keep = self.pad_bytes + (self.vad.min_speech_chunks + 1) * CHUNK_BYTES
        if not self.vad.speaking and len(self._pcm) > keep:
            self._drop(len(self._pcm) - keep)

    def pending(self) -> bytes:
        """The utterance so far, as it would be written if the VAD ended it now (early_asr.py)."""
        return self._pcm[:self._byte_at(self.vad.last_speech_end_s)]

    def _byte_at(self, t_s: float) -> int:
        return max(0, 2 * round((t_s - self._offset_s) * SAMPLE_RATE))

    def _drop(self, count: int) -> None:
        self._pcm, self._offset_s = self._pcm[count:], self._offset_s + count / (2 * SAMPLE_RATE)

    def _emit(self, end: int) -> None:
        self.count += 1
        path = write_wav(self.folder / f"utterance-{self.count:04d}.wav", self._pcm[:end], SAMPLE_RATE)
        self._drop(end)
        self.on_utterance(path)
