"""The web UI in a real headless Chromium (Debian's), driven by Playwright, against the real server.

The server is the real CLI on a free port (tests/web/browser.py); backend dry_run always, and mujoco
when offscreen EGL rendering works here. Screenshots go to /tmp/web_check/ for a human look.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from tests.web.browser import SHOTS, get_json, served, watched_page

pytestmark = pytest.mark.slow
playwright_api = pytest.importorskip("playwright.sync_api")
expect = playwright_api.expect


def egl_works() -> bool:
    probe = "import mujoco; mujoco.Renderer(mujoco.MjModel.from_xml_string('<mujoco/>'), 8, 8)"
    env = {**os.environ, "MUJOCO_GL": "egl"}
    return subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, timeout=120,
                          check=False).returncode == 0


def backends() -> list:
    mujoco = pytest.param("mujoco", marks=pytest.mark.skipif(not egl_works(), reason="no offscreen EGL here"))
    return ["dry_run", mujoco]


@pytest.fixture(scope="module", params=backends())
def server(request, tmp_path_factory):
    with served(tmp_path_factory.mktemp(f"serve_{request.param}"), f"backend={request.param}") as info:
        yield {**info, "backend": request.param}


@pytest.fixture
def page(browser, server):
    with watched_page(browser, server["base"]) as page:
        yield page


def live_view(page, server):
    return page.locator("#sim" if server["backend"] == "mujoco" else "#stick")


def test_chat_reply_cues_and_a_moving_simulation_view(page, server):
    page.goto(server["base"] + "/")
    expect(page.locator("#badges")).to_contain_text(server["backend"])
    expect(page.locator("#badges")).to_contain_text("keyword")
    if server["backend"] == "mujoco":
        page.wait_for_function("Number(document.querySelector('#sim').dataset.frames || 0) >= 3",
                               timeout=30_000)
    page.fill("#say-text", "Welcome to the lab! The robot arm is over there, it is really important.")
    page.click("#send")
    bubble = page.locator(".bubble.robot").last
    expect(bubble).to_contain_text("The robot arm is over there")
    expect(bubble.locator(".cue")).to_have_count(3)
    expect(bubble.locator(".cue.fired").first).to_be_visible(timeout=10_000)  # highlighted at its release
    expect(bubble.locator("mark.fired").first).to_be_visible()
    expect(page.locator("#seq-state")).not_to_have_text("idle", timeout=10_000)
    view = live_view(page, server)
    first = view.screenshot()
    page.wait_for_timeout(700)
    assert view.screenshot() != first, "the simulation view did not change while a gesture ran"
    expect(bubble.locator(".cue.fired")).to_have_count(3, timeout=15_000)
    # each cue shows where its stroke was planned on the word, then where the robot actually put it
    expect(bubble.locator(".cue .time").first).to_contain_text("stroke")
    expect(bubble.locator(".cue .time").first).to_contain_text("executed", timeout=15_000)
    SHOTS.mkdir(exist_ok=True)
    page.screenshot(path=str(SHOTS / f"chat_{server['backend']}.png"))


def test_interrupt_clears_the_queue(page, server):
    page.goto(server["base"] + "/")
    expect(page.locator("#connection")).to_have_text("live")
    page.fill("#say-text", "Welcome! Look over there. This is really important. I am not sure, maybe.")
    page.click("#send")
    expect(page.locator("#seq-queue li").first).not_to_have_text("empty", timeout=10_000)
    # the turn's cues are on the page (the message follows the hand-off to the sequencer) before the click
    expect(page.locator(".bubble.robot").last.locator(".cue").first).to_be_visible(timeout=10_000)
    page.click("#interrupt")
    expect(page.locator("#seq-queue li")).to_have_text(["empty"], timeout=5_000)
    expect(page.locator(".bubble.robot").last.locator(".cue.cancelled").first).to_be_visible()
    status = get_json(server["base"] + "/api/status")
    assert status["pending"] == []


def test_studio_variant_is_saved_and_the_next_message_resolves_to_it(page, server):
    name = f"wave_{server['backend']}_variant"
    page.goto(server["base"] + "/studio")
    expect(page.locator("#verdict")).to_have_text("ready to save", timeout=15_000)
    rendering = get_json(server["base"] + "/api/info")["render"]
    expect(page.locator("#preview-caption")).to_contain_text("MuJoCo" if rendering else "stick",
                                                             timeout=60_000)
    page.fill("#name", name)
    page.select_option("#class", "welcoming")
    page.fill("#description", "a wide raised wave made in the browser test")
    elbow = page.locator('#sliders input[type=number][aria-label="right_elbow_joint"]')
    elbow.fill("0.5")
    elbow.dispatch_event("change")
    expect(page.locator("#keyframes li.selected")).to_contain_text("0.50")
    expect(page.locator("#verdict")).to_have_text("ready to save", timeout=10_000)
    page.click("#save")
    expect(page.locator("#save-result")).to_contain_text(f"saved {name}", timeout=10_000)
    assert (server["library"] / f"{name}.yaml").is_file()
    page.click("#perform")  # the draft on screen, which is now also the saved motion
    expect(page.locator("#perform-result")).to_contain_text("performing the draft on screen", timeout=10_000)
    # saving again needs the box
    expect(page.locator("#name-hint")).to_contain_text("replace the existing motion")
    expect(page.locator("#save")).to_be_disabled()
    page.check("#overwrite")
    expect(page.locator("#save")).to_be_enabled()
    SHOTS.mkdir(exist_ok=True)
    page.screenshot(path=str(SHOTS / f"studio_{server['backend']}.png"), full_page=True)

    page.goto(server["base"] + "/")  # the chat page: ask for the new variant by name
    expect(page.locator(f'#gesture-name option[value="{name}"]')).to_have_count(1, timeout=10_000)
    page.select_option("#gesture-name", name)
    page.click("#gesture-go")
    cue = page.locator(".bubble.robot").last.locator(".cue")
    expect(cue.locator(".name")).to_have_text(name, timeout=10_000)
    expect(cue).to_contain_text("exact")
