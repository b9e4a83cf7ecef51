"""The chat page tells the truth (issue 31), in Chromium against the real server (keyword planner).

Trigger marks sit on their words after emoji; a failed planner call is a banner with its cause; sources,
states and events are in words with timestamps; a replaced reply says "cut off"; queued gestures are
not "released" before they start; the bubble keeps its width; the input shows its limit; the page says
whether the dialogue history reached the planner; a disconnected page says so, keeps the typed line and
reconnects; the planning bubble counts the time; the control loop's health is on the page.
"""

from __future__ import annotations

import re

import pytest

from tests.web.browser import SHOTS, get_json, served, watched_page
from tests.web.test_browser_stop import post_json

pytestmark = pytest.mark.slow
playwright_api = pytest.importorskip("playwright.sync_api")
expect = playwright_api.expect
CLOCK = re.compile(r"\d\d:\d\d:\d\d")
# Every text the page shows in these places is kept, so a test can say what never appeared.
WATCH = """(ids) => { window.seen = {}; for (const id of ids) { window.seen[id] = [];
  new MutationObserver(() => window.seen[id].push(document.getElementById(id).textContent))
    .observe(document.getElementById(id), { childList: true, subtree: true, characterData: true }); } }"""


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    with served(tmp_path_factory.mktemp("serve_honest")) as info:
        yield info


@pytest.fixture
def page(browser, server):
    with watched_page(browser, server["base"]) as page:
        page.goto(server["base"] + "/")
        expect(page.locator("#connection")).to_have_text("live", timeout=15_000)
        yield page


def say(page, text: str):
    """Send a line; its reply's bubble, once it is on the page."""
    bubbles = page.locator(".bubble.robot:not(.pending)")
    before = bubbles.count()
    page.fill("#say-text", text)
    page.click("#send")
    expect(bubbles).to_have_count(before + 1, timeout=10_000)
    return page.locator(f'.bubble.robot[data-turn="{bubbles.last.get_attribute("data-turn")}"]')


def test_emoji_do_not_shift_the_trigger_marks(page):
    bubble = say(page, "Wow 🎉🎉 look over there, it is really important.")
    expect(bubble.locator(".reply mark")).to_have_text(["over there", "really"], timeout=10_000)


def test_a_failed_planner_call_is_a_banner_with_its_cause(page, server):
    turn = post_json(server["base"] + "/api/say", {"text": "Where are the toilets?"})
    failed = {**turn, "turn_id": 999, "source": "call_failed", "narrated": True,
              "planner_error": "planner call failed: litellm.APIConnectionError: Connection error."}
    page.evaluate("""async (turn) => { const cues = await import('/static/cues.js');
        document.getElementById('history').append(cues.turnBubble(turn)); }""", failed)
    bubble = page.locator('.bubble.robot[data-turn="999"]')
    expect(bubble.locator(".call-failed")).to_contain_text("Connection error")
    expect(bubble.locator(".narrated")).to_have_count(0)  # not dressed up as a normal narrated turn
    words = get_json(server["base"] + "/api/info")["sources"]["call_failed"]
    expect(bubble.locator(".meta")).to_contain_text(words)
    expect(bubble.locator(".meta")).not_to_contain_text("plan:")


def test_states_events_and_sources_in_words_with_timestamps(page):
    page.evaluate(WATCH, ["seq-queue", "seq-state"])
    first = say(page, "Welcome! Look over there. This is really important, and I am not sure, maybe.")
    width = first.bounding_box()["width"]
    expect(first.locator(".meta")).not_to_contain_text("plan: ")
    expect(first.locator(".meta time")).to_have_text(CLOCK)
    expect(first.locator(".cue .time").first).to_contain_text("executed", timeout=15_000)
    assert first.bounding_box()["width"] == width, "the bubble widened when the executed time arrived"
    second = say(page, "Thank you, that is all.")  # cuts the first reply short
    expect(second.locator(".meta")).to_be_visible(timeout=10_000)
    expect(first.locator(".cut-off")).to_have_text("cut off by the next reply")
    expect(page.locator("#events li").first).to_be_visible(timeout=10_000)
    for item in page.locator("#events li").all():
        expect(item.locator("time")).to_have_text(CLOCK)
    page.wait_for_timeout(1500)
    seen = page.evaluate("window.seen")
    assert not any("released" in text for text in seen["seq-queue"]), seen["seq-queue"]
    assert not any(word in text for text in seen["seq-state"] for word in ("blending", "holding"))
    stopped = page.locator("#events li.bad", has_text="cut short")
    assert stopped.count() == 0, "a normal replacement is shown as a failure"


def test_the_input_shows_its_limit_and_the_history_is_named(page, server):
    limit = get_json(server["base"] + "/api/info")["limits"]["utterance_chars"]
    expect(page.locator("#mode-hint")).not_to_contain_text("writes the reply")  # keyword narrates
    page.fill("#say-text", "x" * (limit + 600))
    allowed = page.evaluate("document.getElementById('say-text').maxLength")
    assert allowed == limit
    assert len(page.input_value("#say-text")) == allowed
    expect(page.locator("#say-count")).to_have_text(f"{allowed} / {allowed}")
    say(page, "Hello there.")
    bubble = say(page, "And the screen is over there.")
    expect(bubble.locator(".meta")).to_contain_text(re.compile(r"\d+ earlier messages? given to the planner"),
                                                    timeout=10_000)
    expect(page.locator("#mode-hint")).to_contain_text("narration: the robot says your text")


def test_planning_counts_time_and_the_loop_health_is_shown(page):
    page.evaluate(WATCH, ["history"])
    say(page, "Welcome to the lab.")
    assert any(re.search(r"planning… \d+\.\d s", t) for t in page.evaluate("window.seen.history"))
    health = re.compile(r"\d+ missed of \d+ ticks .* \d+ stalls?")
    expect(page.locator("#loop-health")).to_contain_text(health)


def test_a_disconnected_page_says_so_keeps_the_line_and_reconnects(browser, server):
    blocked = {"on": False}

    def route(ws):
        if blocked["on"]:
            ws.close()
            return
        server_side = ws.connect_to_server()
        live.append((ws, server_side))

    live: list = []
    with watched_page(browser, server["base"]) as page:
        page.route_web_socket(re.compile(r"/ws$"), route)
        page.goto(server["base"] + "/")
        expect(page.locator("#connection")).to_have_text("live", timeout=15_000)
        blocked["on"] = True
        for ws, _ in live:
            ws.close()
        expect(page.locator("#offline")).to_be_visible()
        expect(page.locator("#connection")).to_contain_text("disconnected")
        expect(page.locator(".view.live .not-live")).to_be_visible()
        page.fill("#say-text", "Are you still there?")
        page.click("#send")
        assert page.input_value("#say-text") == "Are you still there?"
        expect(page.locator("#error")).to_contain_text("not sent")
        page.click("#interrupt")
        expect(page.locator("#interrupt-note")).to_contain_text("not connected")
        SHOTS.mkdir(exist_ok=True)
        page.screenshot(path=str(SHOTS / "chat_disconnected.png"))
        blocked["on"] = False
        expect(page.locator("#connection")).to_have_text("live", timeout=15_000)
        expect(page.locator("#offline")).to_be_hidden()
        assert page.input_value("#say-text") == "Are you still there?"
