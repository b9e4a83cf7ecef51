"""Long input: an utterance up to the documented limit is spoken whole, a longer one is refused at the API
with a clear error, and a reply is never cut inside a word."""

from __future__ import annotations

import json

from emopose.stages.parse import MAX_SPOKEN_CHARS, cut_at_word, parse_plan

LONG = ("Thank you all for coming today; I will tell you about the arms and the software that moves "
        "them, and when I say on the left, look at the screen on the left. ") * 4  # ~600 characters


def test_a_long_utterance_is_spoken_whole(client):
    turn = client.post("/api/say", json={"text": LONG}).json()
    assert len(LONG) > 500 and turn["reply"] == LONG.strip()  # was cut at 200 characters, mid-word
    assert client.get("/api/info").json()["limits"]["utterance_chars"] == MAX_SPOKEN_CHARS


def test_past_the_limit_the_api_says_what_the_limit_is(client):
    response = client.post("/api/say", json={"text": "a" * (MAX_SPOKEN_CHARS + 1)})
    assert response.status_code == 422
    assert f"at most {MAX_SPOKEN_CHARS} characters" in response.json()["error"]


def test_a_model_reply_past_the_limit_ends_on_a_whole_word():
    words = ("gesture " * 400).strip()  # 3199 characters
    plan = parse_plan(json.dumps({"reply": words, "gestures": [{"class": "pointing", "trigger": words}]}))
    assert len(plan.reply) <= MAX_SPOKEN_CHARS and plan.reply.split() == ["gesture"] * len(plan.reply.split())
    assert plan.records[0].trigger.endswith("gesture") and len(plan.records[0].trigger) <= 200
    assert cut_at_word("the arms and the software", 21) == "the arms and the"
    assert cut_at_word("short enough", 40) == "short enough"
