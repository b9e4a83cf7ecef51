"""Every message of a recording lies on one monotonic time base: read in the order written, no
channel's log time ever goes back (dry_run and mujoco here; the G1 in g1/test_g1_recording.py)."""

from __future__ import annotations

import pytest

from emopose import app
from tests.backends.mcap_order import assert_never_back
from tests.wiring import wire

PLAN = ("+experiment=plan", "planner=keyword", "utterance='Welcome! Look over there.'")


@pytest.mark.parametrize("backend", ["dry_run", "mujoco"])
def test_plan_recording_is_monotonic_per_channel(backend, tmp_path, compose):
    app.run(compose(*PLAN, f"backend={backend}"), tmp_path)
    rows = assert_never_back(tmp_path / "session.mcap")
    assert "/joints/command" in rows and "/plan" in rows
    if backend == "mujoco":
        assert len(rows["/joints/sim"]) == len(rows["/joints/command"])


def test_a_restarted_stream_goes_on_not_back(library, tmp_path):
    built = wire(library, tmp_path)
    with built.session as session:
        loop = session.open()
        loop.run_until(lambda: False, 0.2)
        session.write("/note", {"before": "restart"})
        session.restart(session.neutral)  # stream time starts from zero again
        session.write("/note", {"after": "restart"})
        loop.run_until(lambda: False, 0.2)
    rows = assert_never_back(tmp_path / "session.mcap")
    assert len(rows["/joints/command"]) == 20 and len(rows["/note"]) == 2
