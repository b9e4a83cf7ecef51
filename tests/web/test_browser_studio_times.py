"""Pose Studio's keyframe times and copy/paste (issue 31, item 10), in Chromium against the real server.

A keyframe's time is typed or dragged on the curves, undoes and redoes, is saved as `times:`, and a
timing the joint speed bound forbids is refused with the time and the joint. A keyframe is copied and
pasted as it is or mirrored onto the other arm.
"""

from __future__ import annotations

import re

import pytest

from tests.web.browser import SHOTS, get_json, served, studio_page

pytestmark = pytest.mark.slow
playwright_api = pytest.importorskip("playwright.sync_api")
expect = playwright_api.expect
MIRROR = [1, -1, -1, 1, -1, 1, -1]  # q_right = MIRROR * q_left (emopose/robot/kinematics.py)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    with served(tmp_path_factory.mktemp("serve_studio_times")) as info:
        yield info


@pytest.fixture
def studio(browser, server):
    with studio_page(browser, server["base"]) as page:
        yield page


def type_time(page, value: str) -> None:
    page.locator("#kf-time").fill(value)
    page.locator("#kf-time").dispatch_event("change")


def keyframe(page, k: int):
    return page.locator("#keyframes li").nth(k)


def summary(page, k: int):
    return keyframe(page, k).locator(".sum")


def arm(page, k: int, side: int) -> list[float]:
    return [float(v) for v in keyframe(page, k).locator(".sum span").nth(side).inner_text().split()[1:]]


def drag_line(page, t_from: float, t_to: float, span: float) -> None:
    """Drag a keyframe's line in the left-arm column (the plot: 8 px margin, 10 px between the columns)."""
    box = page.locator("#curves").bounding_box()
    width = (box["width"] - 18) / 2
    x = lambda t: box["x"] + 8 + t / span * width  # noqa: E731
    page.mouse.move(x(t_from), box["y"] + 40)
    page.mouse.down()
    page.mouse.move(x(t_to), box["y"] + 40, steps=6)
    page.mouse.up()


def test_keyframe_times_are_typed_dragged_undone_and_saved(studio, server):
    # New: three keyframes over the rule's 1 s, K1 (selected) at 0.5 s
    expect(studio.locator("#kf-time")).to_have_value("0.5")
    expect(studio.locator("#times-mode")).to_contain_text("evenly spaced")
    type_time(studio, "0.7")
    expect(keyframe(studio, 1)).to_contain_text("0.70 s")
    expect(studio.locator("#times-mode")).to_contain_text("set by hand")
    # K1 -> K2 in 0.3 s is under the 0.302 s the speed bound needs: the check's reply (it replaces the
    # evenly spaced draft's "1.00 s") refuses the times, names the time that would do, and previews the
    # motion slowed by 0.8 %, to the next 20 ms tick
    expect(studio.locator("#check-notes")).to_contain_text(
        re.compile(r"K2 at 1\.00 s comes 0\.30 s after K1; right_\w+_joint needs 0\.31 s"))
    expect(studio.locator("#check-speed")).to_contain_text("too fast")
    expect(studio.locator("#traj-meta")).to_contain_text("1.02 s")
    type_time(studio, "1.5")  # past K2: refused and said so, never clamped
    expect(studio.locator("#time-note")).to_contain_text("not applied")
    expect(studio.locator("#kf-time")).to_have_value("0.7")
    drag_line(studio, 0.7, 0.4, span=1.0)
    dragged = float(studio.locator("#kf-time").input_value())
    assert 0.35 <= dragged <= 0.45, dragged
    studio.click("#undo")
    expect(studio.locator("#kf-time")).to_have_value("0.7")
    studio.click("#redo")
    expect(studio.locator("#kf-time")).to_have_value(str(dragged))
    studio.locator("#name").fill("raise_timed")
    studio.locator("#description").fill("right arm raised, quickly up and slowly down")
    expect(studio.locator("#save")).to_be_enabled(timeout=10_000)
    studio.click("#save")
    expect(studio.locator("#save-result")).to_contain_text("saved raise_timed")
    saved = get_json(server["base"] + "/api/library/raise_timed")
    assert saved["times"] == [0.0, dragged, 1.0] and saved["duration"] is None
    SHOTS.mkdir(exist_ok=True)
    studio.screenshot(path=str(SHOTS / "studio_keyframe_times.png"))


def test_a_timing_too_fast_for_the_speed_bound_is_refused_with_time_and_joint(studio):
    type_time(studio, "0.04")
    expect(studio.locator("#verdict")).to_have_text("cannot save", timeout=10_000)
    notes = studio.locator("#check-notes")
    expect(notes).to_contain_text(re.compile(r"K1 at 0\.04 s .* right_\w+_joint needs \d\.\d\d s"))
    expect(studio.locator("#check-speed")).to_contain_text("too fast")
    studio.click("#times-even")
    expect(studio.locator("#verdict")).to_have_text("ready to save", timeout=10_000)
    expect(studio.locator("#kf-time")).to_have_value("0.5")


def test_keyframes_are_copied_and_pasted_as_they_are_or_mirrored(studio):
    raised_left, raised_right = arm(studio, 1, 0), arm(studio, 1, 1)
    studio.click("#kf-copy")
    keyframe(studio, 2).click()
    studio.click("#kf-paste")
    expect(summary(studio, 2)).to_have_text(summary(studio, 1).text_content())
    studio.click("#kf-paste-mirrored")  # the right arm's raise, now on the left arm
    expect(keyframe(studio, 2).locator(".sum span").first).to_have_text(
        "L " + " ".join(f"{m * v + 0.0:.2f}" for m, v in zip(MIRROR, raised_right)))
    assert arm(studio, 2, 1) == pytest.approx([m * v for m, v in zip(MIRROR, raised_left)], abs=0.006)
    studio.click("#undo")
    expect(summary(studio, 2)).to_have_text(summary(studio, 1).text_content())
    keyframe(studio, 0).click()  # Ctrl+C / Ctrl+V on the page: K0 (rest) onto K1
    studio.keyboard.press("Control+c")
    keyframe(studio, 1).click()
    studio.keyboard.press("Control+v")
    expect(summary(studio, 1)).to_have_text(summary(studio, 0).text_content())
