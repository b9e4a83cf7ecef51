"""+experiment=replay: a recorded dry-run session's commands replayed in MuJoCo and rendered to MP4."""

from __future__ import annotations

import numpy as np
import pytest

from emopose import CONTROL_DT
from emopose.app import run
from emopose.build import ConfigError
from emopose.jobs.replay import command_grid
from tests.jobs.sim_helpers import RENDER_SKIP, SMALL_FRAMES, compose_config


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    """A short recorded dry-run session (keyword planner, one utterance)."""
    folder = tmp_path_factory.mktemp("session")
    run(compose_config(["+experiment=plan", "utterance=Yes exactly right."]), folder)
    return folder / "session.mcap"


def test_replay_renders_and_tracks(session, tmp_path):
    video = "replay.mp4" if RENDER_SKIP is None else "null"
    overrides = ["+experiment=replay", f"mcap={session}", "job.max_seconds=1.0", "job.render_every=10",
                 f"job.video={video}", *SMALL_FRAMES]
    results = run(compose_config(overrides), tmp_path)
    assert results["ticks"] == 51 and results["duration_s"] == pytest.approx(1.0)
    assert results["mae_rad"] < 0.02 and results["max_actuator_force_ratio"] <= 1.0 + 1e-9
    if RENDER_SKIP is None:
        assert (tmp_path / "replay.mp4").stat().st_size > 1000
    assert (tmp_path / "replay.mcap").exists() and (tmp_path / "results.md").exists()


def test_command_grid_holds_across_gaps_and_drops_duplicates():
    q = [np.full(14, k, dtype=float).tolist() for k in range(3)]
    rows = [(0.0, {"t": 0.0, "q": q[0]}), (0.0, {"t": 0.0, "q": q[0]}), (0.06, {"t": 0.06, "q": q[1]}),
            (0.08, {"t": 0.08, "q": q[2]})]
    times, commands = command_grid(rows)
    np.testing.assert_allclose(times, np.arange(5) * CONTROL_DT)
    assert commands[:, 0].tolist() == [0, 0, 0, 1, 2]


@pytest.mark.parametrize("mcap, match", [("null", "needs mcap=PATH"),
                                         ("/no/such/session.mcap", "does not exist")])
def test_replay_needs_an_existing_recording(mcap, match, tmp_path):
    with pytest.raises(ConfigError, match=match):
        run(compose_config(["+experiment=replay", f"mcap={mcap}"]), tmp_path)
