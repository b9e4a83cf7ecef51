"""A page on another origin cannot drive the robot: Chromium, a second HTTP origin, a sandboxed iframe.

The attacker's page (served on another port) holds a sandboxed iframe, whose origin is "null", and
both try the server's WebSocket: read the conversation, make the robot perform palm_stop at
intensity 5. The server's own page on the same socket keeps working.
"""

from __future__ import annotations

import functools
import http.server
import threading

import pytest

from tests.web.browser import get_json, served
from tests.web.conftest import free_port

pytestmark = pytest.mark.slow
playwright_api = pytest.importorskip("playwright.sync_api")

# Opens the robot's socket, tries to make it act, and reports what it saw to the top page.
PROBE = """
const report = (r) => parent === window ? (window.__probe = r) : parent.postMessage(r, "*");
const seen = {origin: self.origin, opened: false, messages: [], close: null};
const ws = new WebSocket("ws://127.0.0.1:%(port)d/ws");
ws.onopen = () => { seen.opened = true; \
ws.send(JSON.stringify({type: "gesture", name: "palm_stop", intensity: 5})); };
ws.onmessage = (e) => { \
seen.messages.push(typeof e.data === "string" ? JSON.parse(e.data).type : "binary"); };
ws.onclose = (e) => { seen.close = e.code; report(seen); };
setTimeout(() => report(seen), 4000);
"""


def attacker_page(port: int) -> str:
    probe = PROBE % {"port": port}
    frame = f"<script>{probe}</script>".replace("&", "&amp;").replace('"', "&quot;")
    return (f"<!doctype html><html><body><h1>another site</h1>"
            f"<script>window.addEventListener('message', (e) => {{ window.__framed = e.data; }});</script>"
            f'<iframe sandbox="allow-scripts" srcdoc="{frame}"></iframe>'
            f"<script>{probe}</script></body></html>")


@pytest.fixture
def other_origin(tmp_path):
    """A second origin: a plain HTTP server on another port of 127.0.0.1 serving the attacker's page."""
    port = free_port()
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(tmp_path))
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", port), handler)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    yield tmp_path, f"http://127.0.0.1:{port}"
    httpd.shutdown()
    httpd.server_close()


def test_a_sandboxed_cross_origin_frame_cannot_use_the_robot_socket(browser, tmp_path, other_origin):
    folder, origin = other_origin
    with served(tmp_path / "server") as server:
        port = int(server["base"].rsplit(":", 1)[1])
        (folder / "attack.html").write_text(attacker_page(port))
        context = browser.new_context()
        try:
            page = context.new_page()
            page.goto(f"{origin}/attack.html")
            page.wait_for_function("window.__framed !== undefined && window.__probe !== undefined",
                                   timeout=15_000)
            framed, top = page.evaluate("window.__framed"), page.evaluate("window.__probe")
            own = context.new_page()
            own.goto(server["base"] + "/")
            own.wait_for_function("document.querySelector('#connection').textContent === 'live'",
                                  timeout=15_000)
        finally:
            context.close()
        assert framed["origin"] == "null"  # the sandboxed frame really has the opaque origin
        for seen in (framed, top):
            # refused at the handshake: nothing read
            assert not seen["opened"] and seen["messages"] == [], seen
        assert get_json(server["base"] + "/api/turns")["log"] == []  # and nothing performed
