"""A scripted OpenAI-compatible audio server on 127.0.0.1: /v1/audio/transcriptions and /v1/audio/speech.

Real sockets and real HTTP, so litellm is exercised exactly as against a hosted provider. Each request
(path, headers, body) is recorded; `status` forces an error answer for the next requests.
"""

from __future__ import annotations

import io
import json
import threading
import wave
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer


def wav_bytes(seconds: float, rate: int = 24000) -> bytes:
    buffer = io.BytesIO()
    with wave.open(buffer, "wb") as out:
        out.setnchannels(1)
        out.setsampwidth(2)
        out.setframerate(rate)
        out.writeframes(b"\0\0" * int(seconds * rate))
    return buffer.getvalue()


class FakeAudioServer:
    def __init__(self, transcript: str = "look over there", speech_seconds: float = 1.5) -> None:
        self.transcript, self.speech_seconds = transcript, speech_seconds
        self.status = 200
        self.requests: list[tuple[str, dict, bytes]] = []
        server = self

        class Handler(BaseHTTPRequestHandler):
            def do_POST(self):
                body = self.rfile.read(int(self.headers.get("Content-Length", 0)))
                server.requests.append((self.path, dict(self.headers), body))
                if server.status != 200:
                    self._send(server.status, b'{"error": {"message": "scripted failure"}}',
                               "application/json")
                elif self.path.endswith("/audio/transcriptions"):
                    self._send(200, json.dumps({"text": server.transcript}).encode(), "application/json")
                elif self.path.endswith("/audio/speech"):
                    self._send(200, wav_bytes(server.speech_seconds), "audio/wav")
                else:
                    self._send(404, b'{"error": {"message": "no such path"}}', "application/json")

            def _send(self, status: int, payload: bytes, content_type: str) -> None:
                self.send_response(status)
                self.send_header("Content-Type", content_type)
                self.send_header("Content-Length", str(len(payload)))
                self.end_headers()
                self.wfile.write(payload)

            def log_message(self, *args):
                pass

        self._httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self._httpd.server_port}/v1"

    def __enter__(self) -> FakeAudioServer:
        threading.Thread(target=self._httpd.serve_forever, daemon=True).start()
        return self

    def __exit__(self, *exc) -> None:
        self._httpd.shutdown()
        self._httpd.server_close()
