"""The real server and Debian's Chromium for the browser tests (test_browser*.py).

The server is the real CLI (python -m emopose +experiment=serve) in a subprocess on a free port, with
the keyword planner and a temporary copy of library/g1; Chromium gets a fake microphone (a tone) and
auto-accepts its permission prompt, so the page can record speech headless.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
import urllib.request
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from tests.web.conftest import copy_library, free_port, library_overrides

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--use-fake-ui-for-media-stream", "--use-fake-device-for-media-stream"]
SHOTS = Path("/tmp/web_check")


def get_json(url: str) -> dict:
    with urllib.request.urlopen(url, timeout=5) as response:
        return json.load(response)


@contextlib.contextmanager
def served(root: Path, *overrides: str, stop: signal.Signals = signal.SIGINT, record: bool = False,
           prepare: Callable[[Path], object] | None = None) -> Iterator[dict]:
    """The CLI serving in root (its log in root/server.log); a graceful stop (`stop`: Ctrl-C's SIGINT, or
    SIGTERM as systemd and docker send it) must write results.json. `prepare(library folder)` runs before
    the server starts (extra motion files). The yielded dict's "process" is the server's Popen."""
    library = copy_library(root)
    if prepare is not None:
        prepare(library)
    port = free_port()
    base = f"http://127.0.0.1:{port}"
    # No provider key: every endpoint a test names is a local stub, which must work keyless.
    env = ({k: v for k, v in os.environ.items() if k != "OPENAI_API_KEY"}
           | {"MUJOCO_GL": "egl", "EMOPOSE_TOKEN": ""})
    with open(root / "server.log", "w") as log:
        process = subprocess.Popen(
            [sys.executable, "-m", "emopose", "+experiment=serve", "planner=keyword", f"serve.port={port}",
             f"run.record={str(record).lower()}", f"hydra.run.dir={root}/run", *library_overrides(library),
             *overrides],
            stdout=log, stderr=subprocess.STDOUT, env=env)
        try:
            _wait_until_up(process, base, root)
            yield {"base": base, "library": library, "root": root, "run": root / "run", "process": process}
        finally:
            process.send_signal(stop)  # a graceful stop: the job writes results.json
            try:
                process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                process.kill()
    assert (root / "run" / "results.json").is_file()


def _wait_until_up(process: subprocess.Popen, base: str, root: Path) -> None:
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline:
        if process.poll() is not None:
            pytest.fail(f"server exited early:\n{(root / 'server.log').read_text()[-3000:]}")
        try:
            get_json(f"{base}/api/health")
            return
        except OSError:
            time.sleep(0.3)
    pytest.fail("server did not come up in 180 s")


@contextlib.contextmanager
def chromium():
    from playwright.sync_api import sync_playwright

    if not Path(CHROMIUM).exists():
        pytest.skip("Debian chromium is not installed")
    with sync_playwright() as p:
        launched = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS)
        try:
            yield launched
        finally:
            launched.close()


@contextlib.contextmanager
def watched_page(browser, base: str, width: int = 1400, height: int = 900):
    """A fresh page that must fetch nothing from outside the server and raise no JavaScript error."""
    context = browser.new_context(viewport={"width": width, "height": height})
    page = context.new_page()
    foreign, errors = [], []
    page.on("request",
            lambda r: None if r.url.startswith((base, "data:", "blob:")) else foreign.append(r.url))
    page.on("pageerror", lambda e: errors.append(str(e)))
    try:
        yield page
    finally:
        context.close()
    assert not foreign, f"the page fetched from outside the server: {foreign}"
    assert not errors, f"JavaScript errors: {errors}"


@contextlib.contextmanager
def studio_page(browser, base: str):
    """A watched page on Pose Studio, ready to edit (its first draft checked)."""
    from playwright.sync_api import expect

    with watched_page(browser, base) as page:
        page.goto(base + "/studio")
        expect(page.locator("#verdict")).to_have_text("ready to save", timeout=15_000)
        yield page
