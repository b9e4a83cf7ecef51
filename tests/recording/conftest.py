"""A real session recording on the wall clock (the loop's raw monotonic time is thousands of seconds,
so a field left on it cannot pass for session time), shared by the recording tests."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from mcap.reader import make_reader

from emopose import app
from tests.conftest import compose_config

PLAN = (
    "+experiment=plan",
    "planner=keyword",
    "utterance='Welcome! Look over there, on the left.'",
    "run.clock=monotonic",
)


@pytest.fixture(scope="session", params=["dry_run", "mujoco"])
def session_recording(request, tmp_path_factory) -> Path:
    run_dir = tmp_path_factory.mktemp(f"plan_{request.param}")
    app.run(compose_config([*PLAN, f"backend={request.param}"]), run_dir)
    return run_dir / "session.mcap"


def every_message(path: Path) -> list[tuple[str, dict, int, dict]]:
    """(topic, schema, log time ns, payload) of every message, read by the official reader."""
    with path.open("rb") as f:
        return [
            (channel.topic, json.loads(schema.data), message.log_time, json.loads(message.data))
            for schema, channel, message in make_reader(f).iter_messages(log_time_order=True)
        ]
