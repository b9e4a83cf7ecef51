"""Request guards in front of every route: access token, loopback Host/Origin, body size, JSON only.

One pure-ASGI middleware, so HTTP and WebSocket get the same checks before any route runs:
- token: when serve.token is set, every request needs it (Authorization: Bearer, X-EmoPose-Token,
  the emopose_token cookie, or ?token= once: a valid query token is turned into an HttpOnly cookie
  so the page's scripts, images, audio and WebSocket carry it without putting it in URLs);
- Host: on a loopback bind only loopback Host headers are served, which defeats DNS rebinding;
- Origin: a request that carries an Origin header must come from the server's own origin
  (scheme http/https, host and port equal to the Host header); anything else is refused, including
  the opaque origin "null" that sandboxed iframes, data: URLs and file: pages send. This stops
  cross-site WebSocket hijacking (WebSockets are not covered by CORS) and cross-site posts: browsers
  always send Origin on WebSocket handshakes and POSTs. A request without Origin (curl, scripts, a
  typed-in URL) is not a cross-site browser request and passes (the token, when set, still applies);
- body: JSON only on /api posts (no CSRF "simple requests"), at most serve.max_body_bytes.
"""

from __future__ import annotations

import hmac
from urllib.parse import parse_qs, urlsplit

from starlette.datastructures import Headers
from starlette.responses import JSONResponse
from starlette.types import ASGIApp, Message, Receive, Scope, Send
from starlette.websockets import WebSocketClose

from emopose.web.settings import ServeSettings

TOKEN_COOKIE = "emopose_token"
LOOPBACK_HOSTS = {"localhost", "127.0.0.1", "::1"}
AUDIO_UPLOAD_PATH = "/api/utterance/audio"
BODY_METHODS = {"POST", "PUT", "PATCH", "DELETE"}


def host_name(netloc: str) -> str:
    """'127.0.0.1:8765' -> '127.0.0.1', '[::1]:80' -> '::1'."""
    return (urlsplit(f"//{netloc}").hostname or "").lower()


def same_origin(origin: str, host: str) -> bool:
    """Whether a browser's Origin header names the server reached through `host` (its Host header).

    "null" (a sandboxed iframe, a data: or file: page) is never the server's own origin."""
    parts = urlsplit(origin.strip())
    return (parts.scheme in ("http", "https") and bool(parts.netloc) and not parts.path
            and parts.netloc.lower() == host.strip().lower())


class _Refused(Exception):
    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status, self.message = status, message


class Guard:
    def __init__(self, app: ASGIApp, settings: ServeSettings) -> None:
        self.app, self.settings = app, settings

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] not in ("http", "websocket"):
            return await self.app(scope, receive, send)
        headers = Headers(scope=scope)
        try:
            self._check_host(headers)
            from_query = self._check_token(scope, headers)
            self._check_origin(headers)
            if scope["type"] == "websocket":
                return await self.app(scope, receive, send)
            receive = await self._checked_body(scope, headers, receive)
        except _Refused as refused:
            return await self._refuse(scope, receive, send, refused)
        if from_query:
            send = self._with_cookie(send)
        await self.app(scope, receive, send)

    # -- checks --------------------------------------------------------------------------------
    def _check_host(self, headers: Headers) -> None:
        if self.settings.local_only and host_name(headers.get("host", "")) not in LOOPBACK_HOSTS:
            raise _Refused(421, "this server answers only to localhost / 127.0.0.1 (Host header refused)")

    def _check_token(self, scope: Scope, headers: Headers) -> bool:
        """True when the token came in the query string (so the response sets the cookie)."""
        expected = self.settings.token
        if expected is None:
            return False
        query = parse_qs(scope.get("query_string", b"").decode("latin-1")).get("token", [None])[0]
        auth = headers.get("authorization", "")
        bearer = auth[7:] if auth.lower().startswith("bearer ") else None
        cookie = _cookie(headers.get("cookie", ""), TOKEN_COOKIE)
        for offered in (bearer, headers.get("x-emopose-token"), cookie):
            if offered and hmac.compare_digest(offered.encode(), expected.encode()):
                return False
        if query and hmac.compare_digest(query.encode(), expected.encode()):
            return True
        raise _Refused(401, "access token required: open the page with ?token=..., or send "
                            "'Authorization: Bearer <token>'")

    def _check_origin(self, headers: Headers) -> None:
        origin = headers.get("origin")
        if origin is not None and not same_origin(origin, headers.get("host", "")):
            raise _Refused(403, f"cross-origin request from {origin[:100]!r} refused: only pages served "
                                "by this server may call it")

    async def _checked_body(self, scope: Scope, headers: Headers, receive: Receive) -> Receive:
        if scope["method"] not in BODY_METHODS:
            return receive
        path = scope["path"]
        upload = path == AUDIO_UPLOAD_PATH
        if path.startswith("/api/") and not upload:
            media = headers.get("content-type", "").split(";")[0].strip().lower()
            if media != "application/json":
                raise _Refused(415, "send JSON with 'Content-Type: application/json'")
        limit = self.settings.max_audio_bytes if upload else self.settings.max_body_bytes
        declared = headers.get("content-length")
        if declared is not None and (not declared.isdigit() or int(declared) > limit):
            raise _Refused(413, f"request body larger than {limit} bytes")
        body = bytearray()
        while True:  # also bounds chunked bodies, which declare no length
            message = await receive()
            if message["type"] == "http.disconnect":
                raise _Refused(400, "client disconnected")
            body += message.get("body", b"")
            if len(body) > limit:
                raise _Refused(413, f"request body larger than {limit} bytes")
            if not message.get("more_body", False):
                break
        return _replay(bytes(body), receive)

    # -- responses -----------------------------------------------------------------------------
    async def _refuse(self, scope: Scope, receive: Receive, send: Send, refused: _Refused) -> None:
        if scope["type"] == "websocket":
            await WebSocketClose(code=1008, reason=refused.message[:120])(scope, receive, send)
            return
        await JSONResponse({"error": refused.message}, status_code=refused.status)(scope, receive, send)

    def _with_cookie(self, send: Send) -> Send:
        cookie = f"{TOKEN_COOKIE}={self.settings.token}; Path=/; HttpOnly; SameSite=Strict".encode()

        async def send_with_cookie(message: Message) -> None:
            if message["type"] == "http.response.start":
                message = {**message, "headers": [*message.get("headers", []), (b"set-cookie", cookie)]}
            await send(message)

        return send_with_cookie


def _cookie(header: str, name: str) -> str | None:
    for part in header.split(";"):
        key, _, value = part.strip().partition("=")
        if key == name:
            return value
    return None


def _replay(body: bytes, receive: Receive) -> Receive:
    """A receive() that hands the already-read body to the app once, then defers to the server."""
    pending = [{"type": "http.request", "body": body, "more_body": False}]

    async def replay() -> Message:
        return pending.pop() if pending else await receive()

    return replay
