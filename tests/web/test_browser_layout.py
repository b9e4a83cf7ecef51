"""The chat page and Pose Studio at phone and desktop widths, and what a turn shows, in Chromium.

At 420 px the simulation column must stay on screen (it comes first, in one column), the camera
strip must not cover the live view (the stick figure's side-view label and head), and no page may
scroll sideways. A gesture played softer than asked says so on its cue; a refused gesture shows as
refused, with the reason, on its cue; a narrated turn says so; a named gesture does not speak the motion's
name. Screenshots go to /tmp/web_check/.
"""

from __future__ import annotations

import re

import pytest

from tests.conftest import write_motion
from tests.web.browser import SHOTS, get_json, served, watched_page
from tests.web.test_cue_outcomes import REACH_ACROSS, REACH_IN, REST

pytestmark = pytest.mark.slow
playwright_api = pytest.importorskip("playwright.sync_api")
expect = playwright_api.expect

VIEWPORTS = {"phone": (420, 900), "desktop": (1400, 900)}


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    def add_reaches(library):
        write_motion(library, "reach_in", "comforting", [REST, REACH_IN, REST])  # into the torso at 4-5
        write_motion(library, "reach_across", "comforting", [REST, REACH_ACROSS, REST])

    with served(tmp_path_factory.mktemp("serve_layout"), prepare=add_reaches) as info:
        yield info


def inside(box: dict, width: int, height: int) -> bool:
    return (box["x"] >= 0 and box["y"] >= 0 and box["x"] + box["width"] <= width
            and box["y"] + box["height"] <= height)


def overlap(a: dict, b: dict) -> bool:
    return not (a["x"] + a["width"] <= b["x"] or b["x"] + b["width"] <= a["x"]
                or a["y"] + a["height"] <= b["y"] or b["y"] + b["height"] <= a["y"])


def no_sideways_scroll(page, width: int) -> bool:
    return page.evaluate("document.documentElement.scrollWidth") <= width


@pytest.mark.parametrize("size", VIEWPORTS)
def test_the_live_view_stays_on_screen_and_uncovered(browser, server, size):
    width, height = VIEWPORTS[size]
    camera = "camera" in get_json(server["base"] + "/api/info")["channels"]
    with watched_page(browser, server["base"], width, height) as page:
        page.goto(server["base"] + "/")
        expect(page.locator("#connection")).to_have_text("live", timeout=15_000)
        view = page.locator(".robot-col .view")
        assert inside(view.bounding_box(), width, height), (size, view.bounding_box())
        assert no_sideways_scroll(page, width)
        if camera:
            page.wait_for_function("Number(document.querySelector('#camera').dataset.frames || 0) >= 1",
                                   timeout=30_000)
            assert not overlap(page.locator("#camera-card").bounding_box(), view.bounding_box())
        SHOTS.mkdir(exist_ok=True)
        page.screenshot(path=str(SHOTS / f"chat_{size}.png"))
        page.goto(server["base"] + "/studio")
        expect(page.locator("#verdict")).to_have_text("ready to save", timeout=15_000)
        assert no_sideways_scroll(page, width)
        assert (page.locator("#preview-stick").bounding_box()["x"]
                + page.locator("#preview-stick").bounding_box()["width"] <= width)
        page.screenshot(path=str(SHOTS / f"studio_{size}.png"), full_page=True)


def perform(page, name: str, intensity: int):
    expect(page.locator(f'#gesture-name option[value="{name}"]')).to_have_count(1)
    page.select_option("#gesture-name", name)
    page.select_option("#gesture-intensity", str(intensity))
    page.click("#gesture-go")


def test_softened_and_refused_gestures_are_shown_with_the_reason_and_named_gestures_are_silent(browser,
                                                                                                server):
    with watched_page(browser, server["base"]) as page:
        page.goto(server["base"] + "/")
        expect(page.locator("#connection")).to_have_text("live", timeout=15_000)
        perform(page, "reach_in", 5)  # from rest: every timing at 4 and 5 is refused, softer ones fit
        softened = page.locator(".bubble.robot").last
        expect(softened.locator(".cue .name")).to_have_text("reach_in", timeout=10_000)
        expect(page.locator(".bubble.user").last).to_have_text("▶ perform reach_in (i5)")
        expect(softened.locator(".cue")).to_contain_text(re.compile(r"i[123], softened from i5"))
        expect(softened.locator(".cue.refused")).to_have_count(0)
        page.fill("#say-text", "Welcome to the lab.")
        page.click("#send")
        narrated = page.locator(".bubble.robot").last
        expect(narrated.locator(".narrated")).to_have_text("narration: the robot says your text")
        expect(page.locator("#mode-hint")).to_contain_text("narration: the robot says your text")
        perform(page, "reach_across", 5)
        bubble = page.locator(".bubble.robot").last
        expect(bubble.locator(".cue .name")).to_have_text("reach_across", timeout=10_000)
        expect(bubble.locator(".reply")).to_have_count(0)  # the motion's name is not spoken
        expect(bubble.locator(".cue.refused")).to_have_count(1, timeout=10_000)
        # the schedule refuses it (at every timing and intensity) before the sequencer would
        expect(bubble.locator(".outcome")).to_contain_text("dropped: unsafe: the safety check refuses")
        expect(bubble.locator(".outcome")).to_contain_text("vs torso")
        expect(bubble.locator(".cue.fired")).to_have_count(0)
        SHOTS.mkdir(exist_ok=True)
        page.screenshot(path=str(SHOTS / "chat_refused_cue.png"))
        page.reload()  # a page opened later sees the outcome in the history
        expect(page.locator(".bubble.robot").last.locator(".outcome")).to_contain_text("vs torso",
                                                                                       timeout=10_000)


WIDTHS = (420, 900, 1400)


@pytest.mark.parametrize("width", WIDTHS)
def test_interrupt_stays_put_on_screen_and_nothing_scrolls_sideways(browser, server, width):
    """Issue 31: at 420, 900 and 1400 px (900 px high) the page never scrolls sideways, Interrupt is on
    screen without scrolling and does not move as events come and go, and cue rows fit their bubble."""
    with watched_page(browser, server["base"], width, 900) as page:
        page.goto(server["base"] + "/")
        expect(page.locator("#connection")).to_have_text("live", timeout=15_000)
        button = page.locator("#interrupt")
        before = button.bounding_box()
        assert inside(before, width, 900), (width, before)
        page.fill("#say-text", "Welcome! Look over there on the left, it is really important, I am not sure.")
        page.click("#send")
        bubble = page.locator(".bubble.robot:not(.pending)").last
        expect(bubble.locator(".cue").first).to_be_visible(timeout=10_000)
        expect(page.locator("#events li").nth(2)).to_be_visible(timeout=10_000)
        where = "(() => { const r = document.getElementById('interrupt').getBoundingClientRect();"\
                " return [r.left + scrollX, r.top + scrollY]; })()"  # in the page: scrolling is no move
        placed = [before["x"], before["y"]]
        for _ in range(5):
            assert page.evaluate(where) == pytest.approx(placed), f"Interrupt moved from {placed}"
            page.wait_for_timeout(300)
        assert no_sideways_scroll(page, width)
        frame = bubble.bounding_box()
        for row in bubble.locator(".cue").all():
            box = row.bounding_box()
            assert box["x"] + box["width"] <= frame["x"] + frame["width"] + 0.5, (width, box, frame)
        SHOTS.mkdir(exist_ok=True)
        page.screenshot(path=str(SHOTS / f"chat_{width}.png"))
