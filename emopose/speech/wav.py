"""WAV files for speech clips: 16-bit mono PCM in, duration out (T_a comes from the sample count)."""

from __future__ import annotations

import hashlib
import io
import os
import tempfile
import wave
from pathlib import Path

DEFAULT_CACHE = Path(tempfile.gettempdir()) / "emopose-tts"


def cache_dir(configured: str | Path | None, key: str) -> Path:
    """The configured audio directory (created), or a per-machine temp cache; `key` names it in errors."""
    path = Path(configured).expanduser() if configured else DEFAULT_CACHE
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(
            f"{key} = {str(path)!r} cannot be created ({exc}); point it at a writable folder"
        ) from exc
    return path


def clip_key(*parts: object) -> str:
    """A stable file stem for one (engine settings, text) combination."""
    return hashlib.sha1("\x1f".join(map(str, parts)).encode("utf-8", errors="replace")).hexdigest()[:20]


def write_wav(path: Path, pcm: bytes, sample_rate: int) -> Path:
    """Write atomically, so a concurrent reader of the cache never sees half a file."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".tmp")
    with os.fdopen(fd, "wb") as raw, wave.open(raw, "wb") as out:
        out.setnchannels(1)
        out.setsampwidth(2)
        out.setframerate(sample_rate)
        out.writeframes(pcm)
    os.replace(tmp, path)
    return path


def read_pcm(path: Path) -> bytes:
    """The samples of a WAV file, as written by write_wav."""
    with wave.open(str(path), "rb") as audio:
        return audio.readframes(audio.getnframes())


def wav_duration(source: Path | bytes) -> float:
    """Duration in seconds of a WAV file or WAV bytes (raises wave.Error / EOFError if not a WAV)."""
    with wave.open(io.BytesIO(source) if isinstance(source, bytes) else str(source), "rb") as audio:
        rate = audio.getframerate()
        frames = audio.getnframes()
        if frames >= 0x7FFF0000:  # streamed WAVs leave the size field at its maximum: count the data
            frames = len(audio.readframes(-1)) // (audio.getsampwidth() * audio.getnchannels())
        return frames / rate
