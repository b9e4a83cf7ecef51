"""ctypes binding to libespeak-ng: text -> 16-bit mono PCM plus the engine's own word events.

libespeak-ng keeps process-wide state and is not reentrant. Worse, a render leaves state behind that
the next one inherits (seen: the sample count drifts, a clause pause grows, a stray word event comes
before the text): inside one process the same text gave different audio, and onsets up to 128 ms apart,
depending on what was rendered before; espeak_Terminate + espeak_Initialize does not clear it. So the
library lives in a small renderer process per voice that initialises it and sets the voice once and
never renders itself: each request is rendered by a fork of that pristine state, which then exits.
Every render of a text is thus the one a fresh process would make (same samples, same word events).
AUDIO_OUTPUT_SYNCHRONOUS makes espeak_Synth return only when the whole text is rendered; the callback
receives the samples plus espeakEVENT_WORD events (audio_position in ms, text_position, length).

Verified on espeak-ng 1.51: text_position is 1-based and counts characters (Unicode code points, as
Python str indices), not UTF-8 bytes, for espeakCHARS_UTF8 input ("café naïve", emoji, CJK).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import logging
import os
import pickle
import threading
from dataclasses import dataclass

from emopose.child_process import ChildProcess, ChildProcessGone, answer_channel, send_answer

log = logging.getLogger(__name__)

AUDIO_OUTPUT_SYNCHRONOUS = 2
INITIALIZE_DONT_EXIT = 0x8000  # without it, a missing espeak-ng-data calls exit() inside the library
POS_CHARACTER = 1
CHARS_UTF8 = 1
EVENT_LIST_TERMINATED, EVENT_WORD = 0, 1
PARAM_RATE, PARAM_PITCH = 1, 3
EE_OK, EE_NOT_FOUND = 0, 2
LIBRARY_NAMES = ("libespeak-ng.so.1", "libespeak-ng.so")

INSTALL_HINT = ("install the espeak-ng package (Debian/Ubuntu: apt-get install espeak-ng libespeak-ng1), "
                "or run with tts=none")


class EspeakUnavailable(RuntimeError):
    """libespeak-ng cannot be loaded or initialised."""


class _Event(ctypes.Structure):
    """espeak_EVENT from speak_lib.h (the trailing union is 8 bytes: a pointer or char[8])."""

    _fields_ = [("type", ctypes.c_int), ("unique_identifier", ctypes.c_uint),
                ("text_position", ctypes.c_int), ("length", ctypes.c_int),
                ("audio_position", ctypes.c_int), ("sample", ctypes.c_int),
                ("user_data", ctypes.c_void_p), ("id", ctypes.c_void_p)]


_Callback = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(ctypes.c_short), ctypes.c_int,
                             ctypes.POINTER(_Event))


@dataclass(frozen=True)
class WordEvent:
    """One espeakEVENT_WORD: char_index is text_position - 1 (0-based, in characters)."""

    char_index: int
    length: int
    audio_s: float


@dataclass(frozen=True)
class Rendering:
    pcm: bytes  # mono int16, native byte order
    sample_rate: int
    events: tuple[WordEvent, ...]

    @property
    def num_samples(self) -> int:
        return len(self.pcm) // 2

    @property
    def duration_s(self) -> float:
        return self.num_samples / self.sample_rate


def _load(library_path: str | None) -> ctypes.CDLL:
    candidates = [library_path] if library_path else [*LIBRARY_NAMES, ctypes.util.find_library("espeak-ng")]
    errors = []
    for name in filter(None, candidates):
        try:
            return ctypes.CDLL(name)
        except OSError as exc:
            errors.append(f"{name}: {exc}")
    raise EspeakUnavailable(f"libespeak-ng could not be loaded ({'; '.join(errors) or 'not found'}): "
                            f"{INSTALL_HINT}")


class _Engine:
    """The initialised libespeak-ng of the renderer process (serve_renders); never used by its callers."""

    def __init__(self, library_path: str | None) -> None:
        lib = self.lib = _load(library_path)
        lib.espeak_Initialize.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_char_p, ctypes.c_int]
        lib.espeak_SetVoiceByName.argtypes = [ctypes.c_char_p]
        lib.espeak_SetParameter.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_int]
        lib.espeak_Synth.argtypes = [ctypes.c_char_p, ctypes.c_size_t, ctypes.c_uint, ctypes.c_int,
                                     ctypes.c_uint, ctypes.c_uint, ctypes.c_void_p, ctypes.c_void_p]
        lib.espeak_Info.argtypes, lib.espeak_Info.restype = [ctypes.c_void_p], ctypes.c_char_p
        self.sample_rate = lib.espeak_Initialize(AUDIO_OUTPUT_SYNCHRONOUS, 0, None, INITIALIZE_DONT_EXIT)
        if self.sample_rate <= 0:
            raise EspeakUnavailable(f"espeak_Initialize failed (espeak-ng-data missing?): {INSTALL_HINT}")
        self.version = lib.espeak_Info(None).decode(errors="replace")
        self._callback = _Callback(self._on_audio)  # keep a reference: the library only holds the pointer
        lib.espeak_SetSynthCallback(self._callback)
        self._pcm = bytearray()
        self._events: list[WordEvent] = []
        self._voice: str | None = None

    def _on_audio(self, wav, count, events) -> int:
        if wav and count > 0:
            self._pcm += ctypes.string_at(wav, 2 * count)
        i = 0
        while events[i].type != EVENT_LIST_TERMINATED:
            event = events[i]
            if event.type == EVENT_WORD:
                self._events.append(WordEvent(event.text_position - 1, event.length,
                                              event.audio_position / 1e3))
            i += 1
        return 0  # continue synthesis

    def set_voice(self, voice: str) -> None:
        if voice == self._voice:
            return
        rc = self.lib.espeak_SetVoiceByName(voice.encode())
        if rc != EE_OK:
            raise ValueError(f"tts.voice {voice!r} is not an espeak-ng voice (error {rc}); "
                             "list the installed ones with `espeak-ng --voices`")
        self._voice = voice

    def render(self, text: str, voice: str, rate: int, pitch: int) -> Rendering:
        self.set_voice(voice)
        self.lib.espeak_SetParameter(PARAM_RATE, rate, 0)
        self.lib.espeak_SetParameter(PARAM_PITCH, pitch, 0)
        self._pcm, self._events = bytearray(), []
        # A NUL would end the C string early; a lone surrogate cannot be encoded. Both become one
        # character, so espeak's character positions still index the caller's text.
        data = text.replace("\0", " ").encode("utf-8", errors="replace")
        rc = self.lib.espeak_Synth(data, len(data) + 1, 0, POS_CHARACTER, 0, CHARS_UTF8, None, None)
        if rc != EE_OK:
            raise RuntimeError(f"espeak_Synth failed with error {rc} for a {len(text)}-character text")
        return Rendering(bytes(self._pcm), self.sample_rate, tuple(self._events))


def serve_renders(library_path: str | None, voice: str) -> None:
    """The renderer process: initialise and set the voice once, then answer each request from a fork."""
    requests, answers = answer_channel()
    try:
        engine = _Engine(library_path)
        engine.set_voice(voice)
    except (EspeakUnavailable, ValueError) as exc:
        return send_answer(answers, exc)
    send_answer(answers, (engine.sample_rate, engine.version))
    while True:
        try:
            text, rate, pitch = pickle.load(requests)
        except EOFError:
            return
        child = os.fork()
        if child == 0:
            try:
                send_answer(answers, engine.render(text, voice, rate, pitch))
            except Exception as exc:  # noqa: BLE001 - handed to the caller, who raises it
                send_answer(answers, exc)
            os._exit(0)
        _, status = os.waitpid(child, 0)
        if status != 0:
            send_answer(answers, RuntimeError(f"espeak render process died (wait status {status})"))


class _Renderer:
    """The parent's handle on one voice's renderer process. Use only under _LOCK."""

    def __init__(self, library_path: str | None, voice: str) -> None:
        self.child = ChildProcess("emopose.speech.espeak_lib", "serve_renders", library_path, voice,
                                  name="espeak renderer")
        self.sample_rate, self.version = self._receive(self.child.receive)

    def render(self, text: str, rate: int, pitch: int) -> Rendering:
        return self._receive(lambda: self.child.request((text, rate, pitch)))

    @staticmethod
    def _receive(answer):
        try:
            return answer()
        except ChildProcessGone as exc:
            raise EspeakUnavailable(str(exc)) from exc


_LOCK = threading.Lock()
_renderers: dict[str, _Renderer] = {}


def engine_identity(voice: str, library_path: str | None = None) -> tuple[int, str]:
    """(sample rate, library version) of voice's renderer, started once (raises EspeakUnavailable with
    the install hint, or ValueError for a voice espeak-ng does not have)."""
    with _LOCK:
        renderer = _get_renderer(voice, library_path)
        return renderer.sample_rate, renderer.version


def render(text: str, voice: str = "en-us", rate: int = 165, pitch: int = 50,
           library_path: str | None = None) -> Rendering:
    """Synthesize text from the library's freshly initialised state; thread-safe (one request at a time)."""
    with _LOCK:
        return _get_renderer(voice, library_path).render(text, rate, pitch)


def _get_renderer(voice: str, library_path: str | None) -> _Renderer:
    renderer = _renderers.get(voice)
    if renderer is None or not renderer.child.alive:
        renderer = _renderers[voice] = _Renderer(library_path, voice)
    elif library_path:
        log.debug("espeak renderer for %s already running; ignoring library_path=%s", voice, library_path)
    return renderer
