"""Pose Studio tells the truth about the draft (issue 31), in Chromium against the real server.

"New" clears the last refusal; the Motion menu shows the draft being edited; typed values outside a
joint's limits are refused, not clamped; refusals cite a time and keyframes; both arms show in the
keyframe list; undo/redo; leaving with unsaved changes asks first.
"""

from __future__ import annotations

import re

import pytest

from tests.conftest import write_motion
from tests.web.browser import SHOTS, served, studio_page
from tests.web.test_cue_outcomes import REACH_IN, REST

pytestmark = pytest.mark.slow
playwright_api = pytest.importorskip("playwright.sync_api")
expect = playwright_api.expect
ELBOW = '#sliders input[type=number][aria-label="right_elbow_joint"]'


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    def add_reach_in(library):  # clean at intensity 1-3, into the torso at 4-5
        write_motion(library, "reach_in", "comforting", [REST, REACH_IN, REST])

    with served(tmp_path_factory.mktemp("serve_studio"), prepare=add_reach_in) as info:
        yield info


@pytest.fixture
def studio(browser, server):
    with studio_page(browser, server["base"]) as page:
        yield page


def type_value(page, selector: str, value: str) -> None:
    page.locator(selector).fill(value)
    page.locator(selector).dispatch_event("change")


def test_a_refusal_cites_time_and_keyframes_and_new_clears_it(studio):
    studio.select_option("#open-name", "reach_in")
    studio.click("#open")
    expect(studio.locator("#name")).to_have_value("reach_in")
    expect(studio.locator("#open-name option:checked")).to_have_text(re.compile("reach_in"))
    studio.select_option("#intensity", "5")
    studio.click("#perform")
    refusal = studio.locator("#perform-result")
    expect(refusal).to_contain_text("draft not performed", timeout=10_000)
    expect(refusal).to_contain_text(re.compile(r"at \d+\.\d\d s \((at|between) K\d"))
    expect(refusal).not_to_contain_text("sample")
    studio.click("#new")
    expect(refusal).to_be_empty()


def test_typed_values_are_refused_visibly_and_edits_undo(studio):
    kept = studio.locator(ELBOW).input_value()
    type_value(studio, ELBOW, "9")
    expect(studio.locator("#joint-note")).to_contain_text("outside its limits")
    expect(studio.locator(ELBOW)).to_have_value(kept)  # not clamped to the limit: not applied at all
    expect(studio.locator("#keyframes li.selected .sum span")).to_have_count(2)  # both arms, each whole
    right = studio.locator("#keyframes li.selected .sum span").nth(1)
    assert right.evaluate("n => n.scrollWidth <= n.clientWidth"), "the right arm's angles are cut off"
    type_value(studio, ELBOW, "0.5")
    expect(right).to_contain_text(re.compile(r"^R( \S+){3} 0\.50 "))  # the right elbow, 4th of the arm
    expect(studio.locator("#open-name option:checked")).to_contain_text("unsaved changes")
    studio.click("#undo")
    expect(studio.locator(ELBOW)).to_have_value(kept)
    studio.click("#redo")
    expect(studio.locator(ELBOW)).to_have_value("0.5")
    SHOTS.mkdir(exist_ok=True)
    studio.screenshot(path=str(SHOTS / "studio_edited.png"))
    dialogs = []
    studio.on("dialog", lambda d: (dialogs.append(d.type), d.dismiss()))
    studio.click("nav a[href='/']")  # leaving with unsaved changes: the browser asks first
    studio.wait_for_timeout(500)
    assert dialogs == ["beforeunload"] and studio.url.endswith("/studio")
