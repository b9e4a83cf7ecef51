"""The page's WebSocket: actions in (say, gesture, interrupt, cancel), live state and frames out.

A binary message from the page is its microphone, 16 kHz mono int16 PCM (any length): it goes to the
session's Listener (emopose/web/voice_io.py: VAD, barge-in, an utterance per VAD end).

Receiving and sending run side by side: a turn is started as a task, so an interrupt sent while the
planner works is handled at once. The sender pushes, each cycle, every new broadcast-log message (turns,
interruptions, saves), the sequencer state with new events and the stick figure (at most at
serve.state_hz), and the newest frame of each image channel as a binary message: one tag byte ('s' sim,
'c' camera) + JPEG. How many pages may watch and how fast each is pushed: emopose/web/clients.py.
"""

from __future__ import annotations

import asyncio
import json
import logging

from fastapi import APIRouter, WebSocket, WebSocketDisconnect
from pydantic import TypeAdapter, ValidationError

from emopose.execution.posture import LISTENING, REST
from emopose.web.api import camera_image
from emopose.web.clients import REFUSED_CODE, Pacer
from emopose.web.schemas import (
    CancelMessage,
    ClientMessage,
    GestureMessage,
    InterruptMessage,
    ListeningMessage,
    SayMessage,
)
from emopose.web.session import LiveSession, UnknownMotion

log = logging.getLogger(__name__)
router = APIRouter()
_messages = TypeAdapter(ClientMessage)
_NOT_LISTENING = {"type": "error", "message": "binary messages are microphone audio, and this server does "
                  "not listen: run with asr=whisper (or asr=litellm)"}


@router.websocket("/ws")
async def websocket_endpoint(websocket: WebSocket) -> None:
    session: LiveSession = websocket.app.state.session
    await websocket.accept()
    if not session.clients.admit():
        await websocket.close(code=REFUSED_CODE, reason=session.clients.refusal())
        return
    try:
        await _serve_page(websocket, session)
    finally:
        session.clients.leave()


async def _serve_page(websocket: WebSocket, session: LiveSession) -> None:
    await websocket.send_json({"type": "hello", **session.info(), "log": session.log_since(0)})
    watching = session.frames.watching() if session.frames is not None else None
    if watching is not None:
        watching.__enter__()
    sender = asyncio.create_task(_send_loop(websocket, session))
    tasks: set[asyncio.Task] = set()
    try:
        while True:
            message = await websocket.receive()
            if message["type"] == "websocket.disconnect":
                break
            if message.get("bytes") is not None:  # the page's microphone: 16 kHz mono int16 PCM
                reply = None if session.hear(message["bytes"]) else _NOT_LISTENING
            else:
                reply = await _handle(session, message.get("text"), tasks, websocket)
            if reply is not None:
                await websocket.send_json(reply)
    except WebSocketDisconnect:
        pass
    finally:
        sender.cancel()
        if watching is not None:
            watching.__exit__(None, None, None)


async def _handle(session: LiveSession, text: str | None, tasks: set, websocket: WebSocket) -> dict | None:
    if text is None:
        return {"type": "error", "message": "send JSON text messages, not binary"}
    if len(text) > session.settings.max_ws_message_bytes:
        return {"type": "error",
                "message": f"message larger than {session.settings.max_ws_message_bytes} bytes"}
    try:
        message = _messages.validate_json(text)
    except ValidationError as exc:
        problems = "; ".join(f"{'.'.join(map(str, e['loc']))}: {e['msg']}" for e in exc.errors()[:5])
        return {"type": "error", "message": f"invalid message: {problems}"}
    if isinstance(message, InterruptMessage):
        session.interrupt()
        return None
    if isinstance(message, ListeningMessage):  # the visitor types: the listening posture (posture.py)
        session.res.sequencer.posture.request(LISTENING if message.active else REST)
        return None
    if isinstance(message, CancelMessage):  # a cancelled line reaches every page as turn_cancelled
        answer = session.pending.cancel(message.turn)
        return None if answer["cancelled"] else {"type": "cancel_refused", "message": answer["reason"]}
    if isinstance(message, SayMessage):
        image = camera_image(session) if message.attach_camera else None
        action = session.say(message.text, image)
    elif isinstance(message, GestureMessage):
        action = session.gesture(message.name, message.intensity, message.text)
    else:
        return {"type": "pong"}
    task = asyncio.create_task(_report_failure(action, websocket))
    tasks.add(task)
    task.add_done_callback(tasks.discard)
    return None


async def _report_failure(action, websocket: WebSocket) -> None:
    """Results reach every page through the broadcast log; failures go back to the asking page."""
    try:
        await action
    except UnknownMotion as exc:
        await _send_quietly(websocket, {"type": "error", "message": str(exc)})
    except Exception as exc:  # a failed turn is reported, the session goes on
        log.exception("turn failed")
        await _send_quietly(websocket, {"type": "error",
                                        "message": f"turn failed: {type(exc).__name__}: {exc}"[:300]})


async def _send_quietly(websocket: WebSocket, message: dict) -> None:
    try:
        await websocket.send_json(message)
    except Exception:  # noqa: BLE001 -- the page may have gone away meanwhile
        log.debug("could not deliver %s to a closed page", message.get("type"))


async def _send_loop(websocket: WebSocket, session: LiveSession) -> None:
    settings, pacer, clock = session.settings, Pacer(session.clients), asyncio.get_running_loop()
    last_id = max((m["id"] for m in session.log_since(0)), default=0)
    events_from = session.res.sequencer.events.total
    frames_seen: dict[str, int] = {}
    state_due, late = 0.0, 0.0
    try:
        while True:
            started = clock.time()
            for message in session.log_since(last_id):
                last_id = message["id"]
                await websocket.send_text(json.dumps({**message, "now": session.res.clock.now()}))
            if started >= state_due:
                state = session.status(events_from, shared=True)
                events_from = state.pop("events_next")
                await websocket.send_text(json.dumps(state))
                state_due = started + 1.0 / settings.state_hz
            if session.frames is not None:
                for name in session.frames.channels:
                    seq, jpeg = session.frames.latest(name)
                    if jpeg is not None and frames_seen.get(name) != seq:
                        frames_seen[name] = seq
                        await websocket.send_bytes(name[0].encode() + jpeg)
            period = pacer.next_period(late)
            await asyncio.sleep(max(0.0, period - (clock.time() - started)))
            late = clock.time() - started - period  # sends that blocked, or a loop too busy to wake us
    except (WebSocketDisconnect, RuntimeError, asyncio.CancelledError):
        return
