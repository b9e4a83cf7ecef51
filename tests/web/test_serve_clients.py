"""How many pages may watch, and how fast each is pushed: a cap refused with a clear close reason, a push
budget shared among the open pages, and a per-page backoff while its cycles come back late (counters, no
wall clock; the 200-page latency is measured in benchmarks/serve_clients.py)."""

from __future__ import annotations

import pytest
from fastapi.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from emopose.web.clients import REFUSED_CODE, Clients, Pacer
from emopose.web.settings import ServeSettings
from tests.web.conftest import LOCAL

WS = "ws://127.0.0.1/ws"


def test_a_page_over_the_cap_is_closed_with_the_reason_and_counted(serve_app):
    app, session = serve_app("serve.max_clients=2")
    with TestClient(app, base_url=LOCAL) as client:
        with client.websocket_connect(WS) as first, client.websocket_connect(WS) as second:
            assert first.receive_json()["type"] == second.receive_json()["type"] == "hello"
            with client.websocket_connect(WS) as third, pytest.raises(WebSocketDisconnect) as refused:
                third.receive_json()
            assert refused.value.code == REFUSED_CODE and "serve.max_clients" in refused.value.reason
            counters = client.get("/api/status").json()["clients"]
            assert counters["open"] == 2 and counters["refused"] == 1 and counters["max_clients"] == 2
        with client.websocket_connect(WS) as again:  # room again once a page closed
            assert again.receive_json()["type"] == "hello"
    assert session.clients.accepted == 3 and session.clients.open == 0


def test_the_push_budget_is_shared_among_open_pages():
    settings = ServeSettings(max_clients=2000, push_budget_hz=400, state_hz=20, sim_fps=15, min_push_hz=1)
    clients = Clients(settings)
    for _ in range(10):
        clients.admit()
    assert clients.share_hz() == 20  # 10 pages: each at the full state rate
    for _ in range(190):
        clients.admit()
    assert clients.share_hz() == 2  # 200 pages: 400 pushes a second among them
    for _ in range(800):
        clients.admit()
    assert clients.share_hz() == 1  # never below the floor


def test_a_late_page_halves_its_rate_down_to_the_floor_and_regains_it_when_on_time():
    clients = Clients(ServeSettings(push_budget_hz=400, state_hz=20, min_push_hz=1))
    clients.admit()
    pacer = Pacer(clients)
    assert pacer.next_period(late_s=0.0) == pytest.approx(0.05)
    periods = [pacer.next_period(late_s=1.0) for _ in range(8)]  # every cycle a second late
    assert periods[:4] == pytest.approx([0.1, 0.2, 0.4, 0.8]) and periods[-1] == pytest.approx(1.0)
    assert clients.slowed == 5  # 0.05 -> 1.0 s: five slowdowns, then held at the floor uncounted
    recovered = [pacer.next_period(late_s=0.0) for _ in range(40)]
    assert recovered[0] == pytest.approx(0.8) and recovered[-1] == pytest.approx(0.05)
    assert clients.slowed == 5
