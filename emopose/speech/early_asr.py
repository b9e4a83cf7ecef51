"""Transcribe the visitor while the hang time runs, so the transcript is ready when the turn ends.

The VAD ends the visitor's turn only after `hang_ms` (600 ms) of silence; whisper needs about as long for
a short sentence on two cores. So when the visitor has paused `after_ms` (96 ms), the utterance so far
(exactly what Utterances would write if the VAD ended it now) is transcribed on a worker thread; if
the turn does end there, the WAV it writes holds the same samples and `transcript(path)` returns that
result (waiting for it if need be) instead of starting over. If the visitor speaks on, that guess is
dropped (a queued one cancelled) and the next pause starts another. Results are keyed by the samples
themselves, so a transcript can never belong to other audio.

    early = EarlyTranscripts(recognizer, folder)
    after each listener feed: early.consider(barge.vad, utterances)    (turn/listening.py does this)
    at the VAD end: text = early.transcript(path)                      (instead of recognizer.utterance)
"""

from __future__ import annotations

import hashlib
import logging
import threading
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

from emopose.speech.audio_in import SAMPLE_RATE, wav_pcm16
from emopose.speech.vad import CHUNK_S, VoiceActivity
from emopose.speech.wav import write_wav

log = logging.getLogger(__name__)


class EarlyTranscripts:
    def __init__(self, recognizer, folder: str | Path, after_ms: float = 96.0) -> None:
        if after_ms < 0:
            raise ValueError(f"asr.listening.early_transcribe_ms must be >= 0 or null, got {after_ms}")
        self.recognizer, self.folder = recognizer, Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.after_s = max(after_ms / 1000, CHUNK_S)
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="early-asr")
        self._guesses: dict[str, Future] = {}
        self._lock = threading.Lock()  # consider() runs on the microphone's thread, transcript() not
        self.started = self.used = 0   # counters: guesses begun, guesses that became the transcript

    def consider(self, vad: VoiceActivity, utterances) -> None:
        """After each feed: a pause of after_ms inside speech starts a transcription of the speech so far."""
        if not (vad.speaking and self.after_s <= vad.pause_s < self.after_s + CHUNK_S):
            return
        pcm = utterances.pending()
        key = samples_key(pcm)
        with self._lock:
            if key in self._guesses:
                return
            for stale in self._guesses.values():
                stale.cancel()   # a queued guess for speech that went on; a running one just finishes
            self.started += 1
            path = self.folder / f"early-{self.started:04d}.wav"
            self._guesses = {key: self._worker.submit(self._transcribe, path, pcm)}

    def transcript(self, path: str | Path) -> str:
        """The utterance's transcript: the early one when it was made from these very samples."""
        key = samples_key(wav_pcm16(path))
        with self._lock:
            guess = self._guesses.pop(key, None)
        if guess is not None and not guess.cancelled():
            self.used += 1
            return guess.result()
        log.debug("no early transcript for %s: transcribing now", path)
        return self.recognizer.utterance(audio=path)

    def _transcribe(self, path: Path, pcm: bytes) -> str:
        """On the worker: a guess's WAV exists only while it is transcribed (a long session keeps none)."""
        write_wav(path, pcm, SAMPLE_RATE)
        try:
            return self.recognizer.utterance(audio=path)
        finally:
            path.unlink(missing_ok=True)

    def close(self) -> None:
        self._worker.shutdown(wait=False, cancel_futures=True)


def samples_key(pcm: bytes) -> str:
    return hashlib.sha1(pcm).hexdigest()
