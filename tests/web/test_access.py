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
                          capture_output=True, text=True, timeout=120, check=False, env={**__import__("os").environ,
                                                                            "EMOPOSE_TOKEN": ""})
    assert done.returncode == 2 and "serve.token" in done.stderr


def test_token_is_checked_on_http_and_websocket(serve_app):
    app, _ = serve_app("serve.host=0.0.0.0", f"serve.token={TOKEN}")
    with TestClient(app, base_url="http://robot.lan:8765") as client:
        assert client.get("/api/info").status_code == 401
        assert client.get("/").status_code == 401
        assert client.get("/api/info", headers={"Authorization": "Bearer wrong-token-0123456789"}).status_code == 401
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
    assert client.post("/api/interrupt", json={}, headers={"Origin": "http://evil.example"}).status_code == 403
    with pytest.raises(WebSocketDisconnect), client.websocket_connect(WS, headers={"Origin": "http://evil.example"}):
        pass
    with client.websocket_connect(WS, headers={"Origin": "http://127.0.0.1"}) as ws:
        assert ws.receive_json()["type"] == "hello"
