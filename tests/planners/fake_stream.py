"""Streamed answers for the fake OpenAI server: server-sent events, one chunk per token, at a set pace.

A request with "stream": true gets its answer as OpenAI's chat.completion.chunk events (chunked
transfer encoding, as a real server sends them), ending with a finish_reason and `data: [DONE]`.
`first_token_s` and `tokens_per_s` pace the tokens; `hold` (an Event) stops the stream after
`hold_after` tokens until it is set (a test's way to prove something happened before the model
finished); `die_after` drops the connection after that many tokens, as a killed server does. An unstreamed
request for a paced answer gets it whole once all of it would have been written (generation_s).
"""

from __future__ import annotations

import contextlib
import json
import re
import socket
import threading
import time
from dataclasses import dataclass
from http.server import BaseHTTPRequestHandler

from fake_answers import Answer


@dataclass
class StreamAnswer(Answer):
    first_token_s: float = 0.0
    tokens_per_s: float = 0.0  # 0: as fast as the socket takes them
    die_after: int | None = None
    hold: threading.Event | None = None
    hold_after: int = 0


def streamed(text: str, first_token_s: float = 0.0, tokens_per_s: float = 0.0, die_after: int | None = None,
             hold: threading.Event | None = None, hold_after: int = 0) -> StreamAnswer:
    return StreamAnswer(content=text, kind="stream", first_token_s=first_token_s, tokens_per_s=tokens_per_s,
                        die_after=die_after, hold=hold, hold_after=hold_after)


def runaway(sentences: int = 60, tokens_per_s: float = 200.0) -> StreamAnswer:
    """A model that will not stop talking: `sentences` sentences (about 3 s of speech each), paced so a
    client that closes early is seen doing it (streams_dropped) before the server has sent it all."""
    text = " ".join(f"This is sentence number {k} of a reply that goes on and on." for k in range(sentences))
    return streamed(text, tokens_per_s=tokens_per_s)


def generation_s(answer: Answer) -> float:
    """How long the whole answer takes to write: what an unstreamed request waits before its reply."""
    if not isinstance(answer, StreamAnswer) or not answer.tokens_per_s:
        return 0.0
    return answer.first_token_s + len(tokens(answer.content or "")) / answer.tokens_per_s


def tokens(text: str) -> list[str]:
    """Word-sized tokens, each with its leading space, as BPE vocabularies mostly cut English."""
    return re.findall(r"\s*\S+", text)


def chunk_event(model: str, content: str | None, finish_reason: str | None = None) -> bytes:
    delta = {} if content is None else {"role": "assistant", "content": content}
    payload = {"id": "chatcmpl-fake", "object": "chat.completion.chunk", "created": int(time.time()),
               "model": model, "choices": [{"index": 0, "delta": delta, "finish_reason": finish_reason}]}
    return f"data: {json.dumps(payload)}\n\n".encode()


def events(answer: Answer, model: str, stopping: threading.Event):
    """(bytes, is_token) in order, paced; stops early when the answer dies or the server stops."""
    parts = tokens(answer.content or "") if isinstance(answer, StreamAnswer) else [answer.content or ""]
    first = answer.first_token_s if isinstance(answer, StreamAnswer) else 0.0
    pace = 1.0 / answer.tokens_per_s if isinstance(answer, StreamAnswer) and answer.tokens_per_s else 0.0
    started = time.perf_counter()
    for k, part in enumerate(parts):
        if isinstance(answer, StreamAnswer):
            if answer.die_after is not None and k >= answer.die_after:
                return
            if answer.hold is not None and k == answer.hold_after:
                while not answer.hold.wait(0.02):
                    if stopping.is_set():
                        return
                started = time.perf_counter() - first - k * pace  # the pace resumes from here
        if stopping.wait(max(0.0, started + first + k * pace - time.perf_counter())):
            return
        yield chunk_event(model, part), True
    yield chunk_event(model, None, answer.finish_reason), False
    yield b"data: [DONE]\n\n", False


def send_stream(handler: BaseHTTPRequestHandler, answer: Answer, model: str, server) -> bool:
    """Write the events in HTTP chunks, counting tokens and early client closes on `server` (a FakeOpenAI);
    a dying answer drops the connection without the terminating chunk. True when all of it went out."""
    handler.send_response(200)
    handler.send_header("Content-Type", "text/event-stream")
    handler.send_header("Transfer-Encoding", "chunked")
    handler.end_headers()
    finished = False
    try:
        for data, is_token in events(answer, model, server._stopping):
            handler.wfile.write(b"%x\r\n%s\r\n" % (len(data), data))
            handler.wfile.flush()
            with server._lock:
                server.tokens_sent += is_token
            finished = not is_token
    except (BrokenPipeError, ConnectionResetError):
        with server._lock:
            server.streams_dropped += 1
        return False
    if not finished:
        with contextlib.suppress(OSError):
            handler.connection.shutdown(socket.SHUT_RDWR)
        handler.close_connection = True
        return False
    handler.wfile.write(b"0\r\n\r\n")
    return True
