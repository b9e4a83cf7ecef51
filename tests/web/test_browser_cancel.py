"""Cancel and retries while a reply is planned (issue 31 item 7), in Chromium against the real server.

planner=llm talks to a scripted OpenAI-compatible stub on 127.0.0.1: two HTTP 503s (retried) and then an
answer held back for a minute, so the page sits in "planning…". It must say the model call is being
retried and how often, offer Cancel, and after Cancel say that nothing came of the line; the thinking
gesture stops and the served session's results count the cancelled line. The page's session report:
the command with this session's recording, and the report made on the server and linked.
"""

from __future__ import annotations

import json
import re
import sys

import pytest

from emopose.config import PROJECT_ROOT
from tests.web.browser import SHOTS, get_json, served, watched_page
from tests.web.test_api import wait_for

sys.path.insert(0, str(PROJECT_ROOT / "tests" / "planners"))  # the fake server is a helper, not a test
from fake_answers import http_error, ok  # noqa: E402
from fake_openai import FakeOpenAI  # noqa: E402

pytestmark = pytest.mark.slow
playwright_api = pytest.importorskip("playwright.sync_api")
expect = playwright_api.expect


def thinking_started(base: str) -> bool:
    events = get_json(base + "/api/status")["events"]
    return any(e["kind"] == "started" and e["name"] == "chin_stroke" for e in events)


def test_the_page_shows_retries_and_cancels_the_line_being_planned(browser, tmp_path):
    with FakeOpenAI() as model, served(tmp_path, "planner=llm", "planner.client.model=openai/fake-model",
                                       f"planner.client.api_base={model.url}", "planner.client.cache=false",
                                       "planner.client.backoff_s=0.05", "thinking=chin_stroke",
                                       record=True) as server:
        model.script(http_error(503), http_error(503), ok(delay_s=60))  # after the start-up check's probe
        with watched_page(browser, server["base"]) as page:
            page.goto(server["base"] + "/")
            expect(page.locator("#connection")).to_have_text("live", timeout=15_000)
            page.fill("#say-text", "Where are the toilets?")
            page.click("#send")
            pending = page.locator(".bubble.pending")
            expect(pending.locator(".planning-text")).to_contain_text("planning…")
            expect(pending.locator(".planning-retries")).to_have_text(
                "the model call failed: retrying (2 retries)", timeout=15_000)
            assert wait_for(lambda: thinking_started(server["base"]), timeout_s=15)  # once the arms settle
            SHOTS.mkdir(exist_ok=True)
            page.screenshot(path=str(SHOTS / "chat_planning_retries.png"))
            pending.locator("button.cancel-planning").click()
            expect(pending).to_have_count(0, timeout=10_000)
            expect(page.locator(".cancelled-line")).to_contain_text("nothing was said or done")
            expect(page.locator(".bubble.user").last).to_have_text("Where are the toilets?")
            status = get_json(server["base"] + "/api/status")
            assert status["planning"] is None
            running = [c for c in [status["active"], *status["pending"]] if c is not None]
            assert all(c["label"] != "thinking" for c in running)
            page.screenshot(path=str(SHOTS / "chat_cancelled.png"))
            page.reload()  # a page opened later sees the cancelled line in the conversation
            expect(page.locator(".cancelled-line")).to_have_count(1, timeout=15_000)
            page.locator("#report summary").click()
            recording = re.escape(str((server["run"] / "session.mcap").resolve()))
            expect(page.locator("#report-how code")).to_have_text(
                re.compile(rf"^python -m emopose \+experiment=recording_report recording={recording}$"))
            page.click("#report-make")
            expect(page.locator("#report-result a", has_text="results.md")).to_be_visible(timeout=180_000)
            expect(page.locator("#report-result li", has_text="loop_health.png")).to_have_count(1)
            page.locator("#report").scroll_into_view_if_needed()
            page.screenshot(path=str(SHOTS / "chat_report.png"))
    results = json.loads((server["run"] / "results.json").read_text())
    assert results["cancelled"] == 1 and results["turns"] == 0
