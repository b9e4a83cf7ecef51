"""timeout_s is a hard deadline per call, body included; the check's first question has a short one; a
reply's control characters never get through (issue 30, items 11-13)."""

from __future__ import annotations

import asyncio

import pytest
from slow_servers import SilentServer, TrickleServer

from emopose.llm.check import check_client
from emopose.llm.client import LLMClient
from emopose.llm.deadline import CallTimeout, clean_text
from emopose.llm.errors import LLMCallError, LLMConfigError

MESSAGES = [{"role": "user", "content": "Hello"}]


def _client(url: str, **settings) -> LLMClient:
    return LLMClient(**{"model": "openai/slow", "api_base": url, "cache": False, "max_retries": 0,
                        "timeout_s": 0.5, **settings})


def test_a_trickling_body_is_cut_at_the_deadline():
    with TrickleServer(pace_s=0.01) as server:  # the whole answer takes about 3 s, each byte 10 ms
        with pytest.raises(LLMCallError) as failure:
            _client(server.url).complete(MESSAGES)
        assert isinstance(failure.value.__cause__, CallTimeout)
        assert server.bytes_sent < server.body_bytes  # given up before the body was complete


def test_a_trickling_body_is_cut_at_the_deadline_in_a_batch_too():
    with TrickleServer(pace_s=0.01) as server:
        with pytest.raises(LLMCallError, match="CallTimeout"):
            asyncio.run(_client(server.url).acomplete(MESSAGES))
        assert server.bytes_sent < server.body_bytes


def test_a_late_answer_is_retried_then_given_up():
    with TrickleServer(pace_s=0.01) as server:
        client = _client(server.url, max_retries=1, backoff_s=0.001, backoff_max_s=0.001)
        with pytest.raises(LLMCallError, match="after 2 attempt"):
            client.complete(MESSAGES)
        assert server.connections >= 1 and client.counters.retries == 1


def test_a_hung_endpoint_fails_the_check_at_the_probe_timeout():
    with SilentServer() as server:
        client = _client(server.url, timeout_s=60.0, probe_timeout_s=0.2)
        with pytest.raises(LLMConfigError, match=r"accepts connections but sent no answer within "
                                                 r"planner.client.probe_timeout_s = 0.2 s"):
            check_client(client, MESSAGES, lambda server: [("none", None)])
        assert server.connections == 1  # one question, not a 60 s probe and its retry


@pytest.mark.parametrize(("raw", "spoken"), [
    ("Hi\x07 there\x1b[0m!", "Hi there!"),
    ("line\x00one\r\ntwo\x85", "lineone \ntwo"),
    ("tab\tkept", "tab\tkept"),
])
def test_control_characters_are_dropped(raw, spoken):
    assert clean_text(raw) == spoken
