"""The tour video (issue 31 item 15): made from a recording after the tour, in a child process, at 640x480
and 15 fps, with the robot followed by the camera, the spoken sentence burned in as a caption (and in
tour.vtt) and the spoken audio as an AAC track. A test double of a tour's recording stands in for a tour:
two seconds of arm and base motion and one spoken clip (a tone as its audio)."""

from __future__ import annotations

import re
import subprocess

import imageio.v3 as iio
import imageio_ffmpeg
import numpy as np
import pytest

from emopose.clock import FakeClock
from emopose.recording import Recorder
from emopose.speech.audio_channel import SpeechRecording
from emopose.speech.clip import SpeechClip
from emopose.speech.wav import write_wav
from emopose.tour.scenario_loading import parse_tour
from emopose.tour.sim_scene import write_scene
from emopose.tour.video import VideoSettings, make_video
from tests.tour.tour_helpers import RENDER_SKIP, small

SPOKEN = "Hello there. Look at the red box."  # said from 0.2 s to 1.2 s


def tour_double(tmp_path):
    """A recording as a tour leaves it (/joints/sim, /base/true, /speech/said, /speech/audio), its scene."""
    clock = FakeClock()
    recorder = Recorder(tmp_path / "session.mcap", clock=clock)
    tone = (8000 * np.sin(2 * np.pi * 440 * np.arange(16000) / 16000)).astype("<i2").tobytes()
    clip = SpeechClip(SPOKEN, 1.0, audio_path=write_wav(tmp_path / "clip.wav", tone, 16000))
    for tick in range(101):  # 2 s at 50 Hz: the right arm rises while the base turns and drives
        t = tick * 0.02
        clock.advance(0.02 if tick else 0.0)
        q = np.zeros(14)
        q[7] = -1.5 * t / 2
        recorder.write("/joints/sim", t, {"q": q.tolist()})
        recorder.write_now("/base/true", {"x": 0.2 * t, "y": 0.0, "yaw_deg": 20.0 * t})
        if tick == 10:
            SpeechRecording(recorder.write)(clip, t)
    recorder.close()
    scene = write_scene(parse_tour(small(), "small"), tmp_path / "tour_scene.xml")
    return recorder.path, scene


def probe(path) -> str:
    """ffmpeg's description of the file's streams."""
    run = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-i", str(path)],
                         capture_output=True, text=True, check=False)
    return run.stderr


@pytest.mark.skipif(RENDER_SKIP is not None, reason=str(RENDER_SKIP))
def test_the_video_has_the_size_rate_audio_and_captions(tmp_path):
    recording, scene = tour_double(tmp_path)
    video = make_video(recording, scene, tmp_path / "tour.mp4")
    streams = probe(video)
    assert re.search(r"Video: h264.*640x480.*15 fps", streams), streams
    assert re.search(r"Audio: aac.*16000 Hz", streams), streams
    frames = iio.imread(video, index=None)
    assert frames.shape[1:] == (480, 640, 3) and len(frames) == 31  # 0..2 s at 15 fps
    band = slice(440, 480)  # the caption's band at the bottom of the frame
    speaking, silent = frames[9][band], frames[25][band]  # at 0.6 s and at 1.67 s
    assert (speaking > 200).all(axis=2).sum() > 200  # white letters
    assert speaking.mean() < 0.6 * silent.mean()  # on a darkened band; no band once the clip has ended
    assert np.abs(frames[0].astype(int) - frames[30]).mean() > 2  # the arm and the base moved
    vtt = (tmp_path / "tour.vtt").read_text()
    assert vtt.startswith("WEBVTT") and "00:00:00.200 --> " in vtt
    assert "Hello there." in vtt and "Look at the red box." in vtt


def test_bad_video_settings_are_refused_in_one_line():
    with pytest.raises(ValueError, match="at least 64x64"):
        VideoSettings(width=641)
    with pytest.raises(ValueError, match="fps"):
        VideoSettings(fps=0)
