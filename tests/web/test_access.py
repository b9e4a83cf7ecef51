"""Access control of the web server: the token for network binds, loopback Host, same Origin."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

WS = "ws://127.0.0.1/ws"


# -- access control -------------------------------------------------------------------------------
TOKEN = "test-token-0123456789abcdef"


def test_a_network_bind_needs_a_token(library_copy):
    from emopose.build import ConfigError, build_job
    from emopose.web.settings import ServeSettings
    from tests.web.conftest import compose_serve

    with pytest.raises(ConfigError, match="serve.token"):
        build_job(compose_serve(library_copy, "serve.host=0.0.0.0"))
    with pytest.raises(ValueError, match="URL-safe"):
        ServeSettings(host="0.0.0.0", token="short")
    assert build_job(compose_serve(library_copy, "serve.host=0.0.0.0", f"serve.token={TOKEN}")).settings.token


def test_the_cli_refuses_to_start_on_0000_without_a_token(library_copy, tmp_path):
    import subprocess
    import sys

    from tests.web.conftest import library_overrides

    done = subprocess.run([sys.executable, "-m", "emopose", "+experiment=serve", "serve.host=0.0.0.0",
                           f"hydra.run.dir={tmp_path}/run", *library_overrides(library_copy)],
                          capture_output=True, text=True, timeout=120, check=False,
                          env={**__import__("os").environ, "EMOPOSE_TOKEN": ""})
    assert done.returncode == 2 and "serve.token" in done.stderr
    assert "validation error" not in done.stderr and "pydantic" not in done.stderr  # a sentence, not a dump
    assert "serve.host=0.0.0.0 is reachable from the network" in done.stderr.splitlines()[-1]


def test_token_is_checked_on_http_and_websocket(serve_app):
    app, _ = serve_app("serve.host=0.0.0.0", f"serve.token={TOKEN}")
    with TestClient(app, base_url="http://robot.lan:8765") as client:
        assert client.get("/api/info").status_code == 401
        assert client.get("/").status_code == 401
        assert client.get("/api/info",
                          headers={"Authorization": "Bearer wrong-token-0123456789"}).status_code == 401
        assert client.get("/api/info", headers={"Authorization": f"Bearer {TOKEN}"}).status_code == 200
        with pytest.raises(WebSocketDisconnect) as refused, client.websocket_connect("ws://robot.lan:8765/ws"):
            pass
        assert refused.value.code == 1008
        page = client.get(f"/?token={TOKEN}")  # the page link: the token becomes an HttpOnly cookie
        assert page.status_code == 200 and "HttpOnly" in page.headers["set-cookie"]
        assert client.get("/api/info").status_code == 200  # the cookie now rides along
        with client.websocket_connect("ws://robot.lan:8765/ws") as ws:
            assert ws.receive_json()["type"] == "hello"


def test_local_bind_refuses_foreign_hosts_and_cross_origin(client):
    assert client.get("/api/info", headers={"Host": "evil.example"}).status_code == 421  # DNS rebinding
    assert client.post("/api/interrupt", json={},
                       headers={"Origin": "http://evil.example"}).status_code == 403
    with pytest.raises(WebSocketDisconnect), client.websocket_connect(WS, headers={"Origin": "http://evil.example"}):
        pass
    with client.websocket_connect(WS, headers={"Origin": "http://127.0.0.1"}) as ws:
        assert ws.receive_json()["type"] == "hello"


@pytest.mark.parametrize("origin", ["null", "http://127.0.0.1:9999", "http://127.0.0.1.evil.example",
                                    "file://", "chrome-extension://abc", "http://127.0.0.1/page"])
def test_foreign_and_opaque_origins_are_refused_on_every_route(client, origin):
    """Origin: null is what a sandboxed iframe on any site sends: it must not pass as 'same origin'."""
    headers = {"Origin": origin}
    refused = client.post("/api/interrupt", json={}, headers=headers)
    assert refused.status_code == 403 and "cross-origin" in refused.json()["error"]
    assert client.post("/api/gesture", json={"name": "palm_stop", "intensity": 5},
                       headers=headers).status_code == 403
    assert client.get("/api/turns", headers=headers).status_code == 403
    with pytest.raises(WebSocketDisconnect) as closed, client.websocket_connect(WS, headers=headers):
        pass
    assert closed.value.code == 1008
    assert client.app.state.session.log_since(0) == []  # nothing ran


def test_same_origin_and_origin_less_clients_are_served(client):
    """The page itself (its own origin) and CLI tools such as curl (no Origin header) keep working."""
    assert client.post("/api/interrupt", json={}, headers={"Origin": "http://127.0.0.1"}).status_code == 200
    assert client.post("/api/interrupt", json={}).status_code == 200
    with client.websocket_connect(WS) as ws:
        assert ws.receive_json()["type"] == "hello"
