"""+experiment=tour_lab end to end: the four-stop lab tour in MuJoCo with the G1 library (slow)."""

from __future__ import annotations

import json

import pytest

from emopose.app import run
from emopose.recording import read_recording
from tests.tour.tour_helpers import RENDER_SKIP, compose_config


@pytest.mark.slow
@pytest.mark.skipif(RENDER_SKIP is not None, reason=str(RENDER_SKIP))
def test_tour_lab_end_to_end(tmp_path):
    results = run(compose_config(["+experiment=tour_lab"]), tmp_path)
    assert results["stops_reached"] == 4 and results["stops_within_tolerance"] == 4
    assert results["max_position_error_m"] <= 0.15
    assert all(s["true_error_m"] <= 0.15 for s in results["stops"])
    assert results["interruptions_handled"] == 3 and not results["aborted"] and results["ended_at_rest"]
    assert sum(e["image_attached"] for e in results["exchanges"]) == 1  # "What am I looking at?"
    assert results["gestures_executed"] >= 8
    assert all(s["gestures_while_walking"] == 0 for s in results["stops"])
    aims = [a for s in results["stops"] for a in s["aims"]]
    assert aims and all(a["applied"] and a["error_deg"] <= 5.0 for a in aims)
    legs = [s["leg_s"] for s in results["stops"]]  # virtual seconds (wall time: benchmarks/tour_lab.py)
    assert all(0 < leg < 120.0 for leg in legs)  # each leg inside conf/tour/lab.yaml's leg_timeout_s
    assert sum(legs) < results["sim_time_s"]  # the narration and questions ran on the same virtual clock
    assert json.loads((tmp_path / "results.json").read_text())["tour"] == "lab"
    assert (tmp_path / "tour.mp4").stat().st_size > 10_000
    recording = read_recording(tmp_path / "session.mcap")
    events = [payload["event"] for _, payload in recording["/tour/event"]]
    assert events[0] == "start" and events[-1] == "end" and events.count("arrive") == 4
    assert events.count("question") == 3 and recording["/base/true"] and recording["/plan"]
