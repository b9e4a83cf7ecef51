"""Fixtures for the G1 DDS tests: a fake robot in its own process on a private DDS domain.

Every test module gets its own random domain id, so modules (and other projects' DDS tests on
this machine) cannot hear each other; the fake robot is a real `python -m` process speaking
Cyclone DDS 0.10.2 on loopback, started per test and killed after it.
"""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
_USED_DOMAINS: set[int] = set()


def require_dds() -> None:
    try:
        import cyclonedds.domain  # noqa: F401
    except ImportError as exc:
        pytest.skip(
            f"cyclonedds is not importable ({exc}); run .ci/install_cyclonedds.sh to build 0.10.2"
        )


@pytest.fixture(scope="module")
def domain_id() -> int:
    rng = random.SystemRandom()
    while (d := rng.randint(20, 230)) in _USED_DOMAINS:
        pass
    _USED_DOMAINS.add(d)
    return d


class FakeRobot:
    def __init__(self, domain_id: int, log_path: Path, args: list[str]) -> None:
        self.domain_id = domain_id
        self.log_path = log_path
        env = {**os.environ, "PYTHONPATH": f"{REPO}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
        cmd = [
            sys.executable,
            "-m",
            "emopose.testing.fake_robot",
            "--domain-id",
            str(domain_id),
            "--log",
            str(log_path),
            *args,
        ]
        self.proc = subprocess.Popen(
            cmd, cwd=REPO, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        line = self.proc.stdout.readline()  # blocks until READY (or the process dies)
        if line.strip() != "READY":
            self.proc.kill()
            raise RuntimeError(f"fake robot did not start: {line!r} {self.proc.stderr.read()}")

    def kill(self) -> None:
        """SIGKILL: the robot vanishes mid-stream, as a cut cable would look."""
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(timeout=5)

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.kill()

    def entries(self, kind: str | None = None) -> list[dict]:
        if not self.log_path.exists():
            return []
        # The robot may be appending: only lines it has finished (newline-terminated) are read.
        complete = self.log_path.read_text().split("\n")[:-1]
        rows = [json.loads(line) for line in complete if line.strip()]
        return [r for r in rows if kind is None or r["kind"] == kind]

    def wait_for(self, kind: str, count: int, timeout_s: float = 5.0) -> list[dict]:
        deadline = time.monotonic() + timeout_s
        while len(rows := self.entries(kind)) < count and time.monotonic() < deadline:
            time.sleep(0.02)
        return rows


def _launcher(domain_id: int, folder: Path):
    require_dds()
    started: list[FakeRobot] = []

    def start(*args: str) -> FakeRobot:
        robot = FakeRobot(domain_id, folder / f"fake{len(started)}.jsonl", list(args))
        started.append(robot)
        return robot

    return start, started


@pytest.fixture
def fake_robot(domain_id, tmp_path):
    """Factory: fake_robot(*extra_cli_args) starts a fake G1; all are stopped after the test."""
    start, started = _launcher(domain_id, tmp_path)
    yield start
    for robot in started:
        robot.stop()


@pytest.fixture(scope="module")
def module_fake_robot(domain_id, tmp_path_factory):
    """Same factory, for fakes shared by a whole test module."""
    start, started = _launcher(domain_id, tmp_path_factory.mktemp("fake"))
    yield start
    for robot in started:
        robot.stop()
