"""VoiceClient: the G1's speaker, volume and chest light through Unitree's `voice` RPC service.

Facts checked against Unitree's public SDK (unitree_sdk2_python: g1/audio/g1_audio_api.py and
g1_audio_client.py; unitree_sdk2 g1_audio_api.hpp): service `voice`, API version 1.0.0.0, the
unitree_api Request_/Response_ envelope on rt/api/voice/request|response; api ids 1001 TTS,
1002 ASR, 1003 start play (parameter {"app_name", "stream_id"}, the PCM bytes in the request's
`binary`), 1004 stop play ({"app_name"}), 1005 get volume ({}), 1006 set volume ({"volume"}),
1010 RGB light ({"R", "G", "B"}). PCM is 16 kHz, mono, 16-bit little-endian (the SDK example
refuses anything else). Reported in public notes on Unitree's VuiClient page, not in the SDK
code: chunks with the same stream_id continue one stream, a new stream_id cuts the old one;
volume 0-100; light calls at least 200 ms apart. The robot reports no playback state.
"""

from __future__ import annotations

import json
import wave
from pathlib import Path

import numpy as np

from emopose.backends.g1.rpc import ServiceClient
from emopose.speech.audio_in import SAMPLE_RATE, resample_pcm16

VOICE_SERVICE = "voice"
VOICE_API_TTS = 1001
VOICE_API_START_PLAY = 1003
VOICE_API_STOP_PLAY = 1004
VOICE_API_GET_VOLUME = 1005
VOICE_API_SET_VOLUME = 1006
VOICE_API_SET_RGB_LED = 1010
PCM_BYTES_PER_SECOND = SAMPLE_RATE * 2  # 16 kHz mono 16-bit
LED_MIN_INTERVAL_S = 0.2


class VoiceClient(ServiceClient):
    label = "voice"

    def __init__(self, domain_id: int = 0, network_interface: str | None = None,
                 service: str = VOICE_SERVICE, timeout_s: float = 1.0) -> None:
        super().__init__(domain_id, network_interface, service, timeout_s)

    def play_chunk(self, app_name: str, stream_id: str, pcm: bytes) -> None:
        """One chunk of a stream (written once: a re-sent chunk would be heard twice)."""
        self.call(VOICE_API_START_PLAY, {"app_name": app_name, "stream_id": stream_id}, pcm,
                  idempotent=False)

    def stop_play(self, app_name: str) -> None:
        self.call(VOICE_API_STOP_PLAY, {"app_name": app_name})

    def get_volume(self) -> int:
        return int(json.loads(self.call(VOICE_API_GET_VOLUME, {}))["volume"])

    def set_volume(self, volume: int) -> None:
        self.call(VOICE_API_SET_VOLUME, {"volume": checked_volume(volume)})

    def set_light(self, rgb: tuple[int, int, int]) -> None:
        self.call(VOICE_API_SET_RGB_LED, dict(zip("RGB", checked_rgb(rgb))))


def checked_volume(volume: int) -> int:
    if isinstance(volume, bool) or not isinstance(volume, int) or not 0 <= volume <= 100:
        raise ValueError(f"player.volume must be an integer 0-100 or null, got {volume!r}")
    return volume


def checked_rgb(rgb) -> tuple[int, int, int]:
    values = tuple(rgb)
    if len(values) != 3 or not all(isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 255
                                   for v in values):
        raise ValueError(f"a light colour is three integers 0-255, got {rgb!r}")
    return values


def robot_pcm(path: str | Path) -> bytes:
    """Any 16-bit PCM WAV (what every synthesizer here writes; stereo is averaged) -> the robot's
    format, 16 kHz mono 16-bit (linear interpolation: emopose.speech.audio_in.resample_pcm16)."""
    with wave.open(str(path), "rb") as audio:
        if audio.getsampwidth() != 2:
            raise ValueError(f"{path}: {8 * audio.getsampwidth()}-bit WAV; the G1 player takes 16-bit PCM")
        channels, rate = audio.getnchannels(), audio.getframerate()
        frames = audio.readframes(audio.getnframes())
    if channels > 1:
        samples = np.frombuffer(frames, dtype="<i2").reshape(-1, channels).astype(np.int32)
        frames = (samples.sum(axis=1) // channels).astype("<i2").tobytes()
    return resample_pcm16(frames, rate)


def chunk_schedule(total_bytes: int, chunk_bytes: int, launch: float, sound_start: float,
                   lead_s: float) -> list[tuple[int, int, float, float]]:
    """(first byte, end byte, send at, play at) of every chunk of one clip.

    Chunk k is heard at sound_start + its offset; it is sent lead_s before that, never before the
    launch. So every chunk reaches the robot between min(lead_s, sound_start - launch) and
    max(lead_s, sound_start - launch) ahead of its play time: the robot's buffer stays that full,
    and a stop empties at most that much."""
    chunks = []
    for first in range(0, total_bytes, chunk_bytes):
        play_at = sound_start + first / PCM_BYTES_PER_SECOND
        chunks.append((first, min(first + chunk_bytes, total_bytes), max(launch, play_at - lead_s), play_at))
    return chunks
