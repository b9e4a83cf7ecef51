"""HTTP API of the live robot: info, status, turns (typed or spoken), named gestures, interrupt, cancel a
line being planned, audio, and the session's recording report (made in a child process).

The WebSocket carries the same actions for the page; these routes serve scripts and tests.
"""

from __future__ import annotations

import asyncio
import tempfile
from pathlib import Path

from fastapi import APIRouter, HTTPException, Request
from fastapi.responses import FileResponse

from emopose.contract import GestureRecord
from emopose.speech.asr import ASRError
from emopose.stages.parse import MAX_SPOKEN_CHARS
from emopose.stages.resolve import resolve_record
from emopose.web.report import ReportFailed, ReportUnavailable
from emopose.web.schemas import CancelRequest, GestureRequest, ResolveRequest, SayRequest
from emopose.web.session import LiveSession, UnknownMotion

router = APIRouter(prefix="/api")

# What MediaRecorder produces in Chromium / Firefox, mapped to the suffix the ASR expects.
AUDIO_TYPES = {"audio/webm": ".webm", "audio/ogg": ".ogg", "audio/wav": ".wav", "audio/x-wav": ".wav",
               "audio/mpeg": ".mp3", "audio/mp4": ".m4a"}


def session_of(request: Request) -> LiveSession:
    return request.app.state.session


@router.get("/health")
def health() -> dict:
    return {"ok": True}


@router.get("/info")
def info(request: Request) -> dict:
    return session_of(request).info()


@router.get("/status")
def status(request: Request) -> dict:
    """The live state, with the control loop's whole account: missed deadlines, stalls, lateness."""
    session = session_of(request)
    return session.status(events_from=max(0, session.res.sequencer.events.total - 20))


@router.get("/turns")
def turns(request: Request) -> dict:
    return {"log": session_of(request).log_since(0)}


@router.post("/say")
async def say(body: SayRequest, request: Request) -> dict:
    session = session_of(request)
    return await session.say(body.text, camera_image(session) if body.attach_camera else None)


@router.post("/gesture")
async def gesture(body: GestureRequest, request: Request) -> dict:
    try:
        return await session_of(request).gesture(body.name, body.intensity, body.text)
    except UnknownMotion as exc:
        raise HTTPException(404, str(exc)) from exc


@router.post("/resolve")
def resolve(body: ResolveRequest, request: Request) -> dict:
    """The resolver on the live library, without executing: which entry a record would run."""
    library = session_of(request).res.library
    resolved = resolve_record(GestureRecord(cls=body.cls, variant=body.variant), library)
    return {**resolved.as_json(), "library_version": library.version}


@router.post("/interrupt")
def interrupt(request: Request) -> dict:
    return session_of(request).interrupt()


@router.post("/cancel")
def cancel(body: CancelRequest, request: Request) -> dict:
    """Abandon the planner call of the line being planned: the turn ends as turn_cancelled."""
    return session_of(request).pending.cancel(body.turn)


@router.get("/report")
def report_info(request: Request) -> dict:
    return session_of(request).report.info()


@router.post("/report")
async def make_report(request: Request) -> dict:
    """The recording report on this session's recording as it is now (seconds to minutes)."""
    try:
        return await asyncio.to_thread(session_of(request).report.make)
    except ReportUnavailable as exc:
        raise HTTPException(409, str(exc)) from exc
    except ReportFailed as exc:
        raise HTTPException(500, str(exc)) from exc


@router.get("/report/{name}")
def report_file(name: str, request: Request) -> FileResponse:
    path = session_of(request).report.file(name)  # only the newest report's files, never a client path
    if path is None or not path.is_file():
        raise HTTPException(404, f"no report file {name!r}: make the report first (POST /api/report)")
    return FileResponse(path)


@router.get("/audio/{turn_id}")
def audio(turn_id: int, request: Request) -> FileResponse:
    path = session_of(request).audio_path(turn_id)  # only files the session registered, never a client path
    if path is None or not path.is_file():
        raise HTTPException(404, f"turn {turn_id} has no audio (tts=none, or the turn is unknown)")
    return FileResponse(path, media_type="audio/wav")


@router.post("/utterance/audio")
async def utterance_audio(request: Request) -> dict:
    """Microphone input: transcribe with the configured ASR, then run the turn."""
    session = session_of(request)
    if not session.hears_speech:
        raise HTTPException(409, "no speech recognition configured; "
                                 "type the utterance (or run with asr=whisper, local, or asr=litellm)")
    media = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if media not in AUDIO_TYPES:
        raise HTTPException(415, f"audio type {media!r} not accepted; use one of {sorted(AUDIO_TYPES)}")
    body = await request.body()  # already bounded by serve.max_audio_bytes
    if not body:
        raise HTTPException(400, "empty audio")
    with tempfile.TemporaryDirectory(prefix="emopose-mic-") as folder:
        path = Path(folder) / f"utterance{AUDIO_TYPES[media]}"
        path.write_bytes(body)
        try:
            text = await session.transcribe(path)
        except ASRError as exc:
            raise HTTPException(422, str(exc)) from exc
    if not text.strip():
        raise HTTPException(422, "the recording contained no recognisable speech")
    if len(text) > MAX_SPOKEN_CHARS:
        raise HTTPException(422, f"the transcript has {len(text)} characters; the input limit is "
                                 f"{MAX_SPOKEN_CHARS}: speak a shorter utterance")
    return await session.say(text)


def camera_image(session: LiveSession) -> bytes | None:
    """The camera feed's latest JPEG, for a planner that accepts an image with the utterance."""
    if session.frames is None or "camera" not in session.frames.channels:
        return None
    return session.frames.latest("camera")[1]
