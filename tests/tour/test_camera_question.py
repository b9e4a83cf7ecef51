"""Camera-grounded answers: "what is this?" sends the head camera frame to the VLM as an image part.

The llm planner talks to a local fake OpenAI server (tests/planners/fake_openai.py) that records
every request; the tour runs in MuJoCo, so the image is a real offscreen render of the head camera.
"""

from __future__ import annotations

import base64
import io
import sys
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "planners"))
from fake_openai import FakeOpenAI

from emopose.app import run
from emopose.tour.camera import camera_for
from tests.tour.tour_helpers import RENDER_SKIP, small, tour_config, tour_runner


def user_content(body: dict):
    return body["messages"][-1]["content"]


@pytest.mark.skipif(RENDER_SKIP is not None, reason=str(RENDER_SKIP))
def test_scene_question_attaches_the_head_camera_frame_to_the_vlm_request(tmp_path):
    scenario = small(route=["first"], interruptions=[
        {"at_stop": "first", "after_s": 1.5, "text": "What is this?"}])
    path = tmp_path / "tour.yaml"
    path.write_text(yaml.safe_dump(scenario))
    with FakeOpenAI() as server:
        cfg = tour_config(tmp_path, "planner=llm", f"planner.client.api_base={server.url}",
                          "planner.client.model=openai/fake-model", "planner.client.cache=false",
                          "planner.client.max_retries=0", f"job.tour_file={path}")
        results = run(cfg, tmp_path / "run")
        requests = list(server.requests)
    with_image = [r for r in requests if isinstance(user_content(r), list)]
    assert len(with_image) == 1, "only the scene question carries a picture"
    text, image = user_content(with_image[0])
    assert text == {"type": "text", "text": "What is this?"}  # the visitor's own words: respond mode
    assert image["type"] == "image_url"
    url = image["image_url"]["url"]
    assert url.startswith("data:image/jpeg;base64,")
    import imageio.v3 as iio

    frame = iio.imread(io.BytesIO(base64.b64decode(url.split(",", 1)[1])))
    assert frame.shape == (240, 320, 3) and frame.std() > 5  # a real render, not a blank
    # The dialogue so far (the interrupted narration) travels with the question.
    history = with_image[0]["messages"][1:-1]
    assert history and history[-1]["role"] == "assistant"
    narration_requests = [r for r in requests if r is not with_image[0]]
    assert narration_requests and all(isinstance(user_content(r), str) for r in narration_requests)
    exchange = results["exchanges"][0]
    assert exchange["image_attached"] and exchange["question"] == "What is this?"
    assert results["stops_within_tolerance"] == 1 and results["ended_at_rest"]


@pytest.mark.skipif(RENDER_SKIP is not None, reason=str(RENDER_SKIP))
def test_the_head_camera_shows_the_simulators_state_rendered_outside_the_loops_process(tmp_path, monkeypatch):
    import imageio.v3 as iio
    import numpy as np

    with tour_runner(tmp_path, small()) as (run, _):
        backend = run.resources.backend
        backend.planar_base.place(0.6, 0.0, 0.0)  # the red box ahead, to the right
        here = backend.render_frame("head").astype(float)  # in this process, for comparison only
        backend.planar_base.place(0.6, 0.0, np.pi)  # facing away from it
        away = backend.render_frame("head").astype(float)
        backend.planar_base.place(0.6, 0.0, 0.0)
        monkeypatch.setattr(type(backend), "render_frame", lambda *a, **k: pytest.fail("rendered in-process"))
        camera = camera_for(backend)
        try:
            frame = iio.imread(io.BytesIO(camera.frame_image())).astype(float)
        finally:
            camera.close()
    assert frame.shape == here.shape == (240, 320, 3) and camera.frames == 1
    # the child's frame is the same view (no MSAA there: edges differ), not the one facing away
    assert np.abs(frame - here).mean() < 0.5 * np.abs(frame - away).mean()
