"""What the tour video shows, read from the session recording: the robot's pose at any time, the captions
and the sound. The video is made from the recording after the tour (emopose/tour/video.py), so nothing of
it is rendered while the control loop runs.

Poses: the arms from /joints/sim (the simulated joints as they moved), the base from /base/true, both
interpolated to the frame times. Captions: each clip on /speech/said, one sentence at a time (a sentence's
share of the clip is its share of the characters, the anchor rule's linear map), until the clip ends or
the next one cuts it off. Sound: /speech/audio's PCM16 chunks placed at their times on one mono track; a
clip that starts cuts off the rest of the one before, as the player does.
"""

from __future__ import annotations

import base64
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mcap.reader import make_reader

from emopose.recording import recording_start_ns
from emopose.sentences import split_sentences
from emopose.speech.audio_channel import AUDIO, SAID


@dataclass(frozen=True)
class Cue:
    start_s: float
    end_s: float
    text: str


@dataclass
class TourTrack:
    joint_t: np.ndarray  # (n,) session time of each /joints/sim sample
    joints: np.ndarray  # (n, 14) rad
    base_t: np.ndarray = field(default_factory=lambda: np.zeros(1))
    base: np.ndarray = field(default_factory=lambda: np.zeros((1, 3)))  # (m, 3) x, y, yaw (rad, unwrapped)
    said: list[tuple[float, float, str]] = field(default_factory=list)  # (start, duration, text)
    chunks: list[dict] = field(default_factory=list)  # the /speech/audio payloads

    @property
    def end_s(self) -> float:
        return float(self.joint_t[-1])

    def pose_at(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(x, y, yaw) of the base and the 14 arm joints at session time t (held before/after the ends)."""
        arms = np.array([np.interp(t, self.joint_t, self.joints[:, j]) for j in range(self.joints.shape[1])])
        base = np.array([np.interp(t, self.base_t, self.base[:, k]) for k in range(3)])
        return base, arms


def read_track(recording: str | Path) -> TourTrack:
    """The recording's poses, speech and sound; ValueError when it holds no simulated joints."""
    with Path(recording).open("rb") as f:
        reader = make_reader(f)
        start_ns = recording_start_ns(reader) or 0
        rows: dict[str, list] = {"/joints/sim": [], "/base/true": [], SAID: [], AUDIO: []}
        for _, channel, message in reader.iter_messages(topics=list(rows), log_time_order=True):
            rows[channel.topic].append(((message.log_time - start_ns) / 1e9, json.loads(message.data)))
    if not rows["/joints/sim"]:
        raise ValueError(f"{recording}: no /joints/sim messages, so no robot to show")
    track = TourTrack(np.array([t for t, _ in rows["/joints/sim"]]),
                      np.array([p["q"] for _, p in rows["/joints/sim"]], dtype=float),
                      said=[(p["t"], p["duration_s"], p["text"]) for _, p in rows[SAID]],
                      chunks=[p for _, p in rows[AUDIO]])
    if rows["/base/true"]:
        track.base_t = np.array([t for t, _ in rows["/base/true"]])
        track.base = np.array([[p["x"], p["y"], np.radians(p["yaw_deg"])] for _, p in rows["/base/true"]])
        track.base[:, 2] = np.unwrap(track.base[:, 2])  # interpolated across +-180 degrees the short way
    return track


def caption_cues(said: list[tuple[float, float, str]]) -> list[Cue]:
    """One cue per sentence of each clip, cut where the next clip starts."""
    cues: list[Cue] = []
    starts = [start for start, _, _ in said][1:] + [np.inf]
    for (start, duration, text), next_start in zip(said, starts):
        sentences = split_sentences(text)
        total = max(sum(len(s) for s in sentences), 1)
        at = start
        for sentence in sentences:
            end = at + duration * len(sentence) / total
            if at < next_start:
                cues.append(Cue(at, min(end, next_start), sentence))
            at = end
    return cues


def audio_track(chunks: list[dict], end_s: float) -> tuple[int, np.ndarray] | None:
    """(sample rate, mono int16 samples from session time 0 to end_s); None without audio."""
    if not chunks:
        return None
    rate = chunks[0]["sample_rate"]
    samples = np.zeros(int(end_s * rate) + 1, dtype=np.int16)
    clip_start = -np.inf
    for chunk in chunks:
        pcm = np.frombuffer(base64.b64decode(chunk["data"]), dtype="<i2")
        pcm = pcm.reshape(-1, chunk["number_of_channels"]).mean(axis=1)  # mono
        if chunk["sample_rate"] != rate:
            pcm = np.interp(np.arange(0, len(pcm), chunk["sample_rate"] / rate), np.arange(len(pcm)), pcm)
        if chunk["t"] - chunk["offset_s"] > clip_start + 1e-6:  # a new clip: it cuts the last one off
            clip_start = chunk["t"] - chunk["offset_s"]
            samples[max(0, int(clip_start * rate)):] = 0
        first = int(round(chunk["t"] * rate))
        part = pcm[max(0, -first): max(0, len(samples) - first)]
        samples[max(0, first): max(0, first) + len(part)] = part.astype(np.int16)
    return rate, samples


def webvtt(cues: list[Cue]) -> str:
    """The captions as a WebVTT file (players load tour.vtt beside tour.mp4)."""
    def stamp(t: float) -> str:
        ms = int(round(max(t, 0.0) * 1000))
        return f"{ms // 3_600_000:02d}:{ms // 60_000 % 60:02d}:{ms // 1000 % 60:02d}.{ms % 1000:03d}"

    blocks = [f"{stamp(c.start_s)} --> {stamp(c.end_s)}\n{c.text}" for c in cues]
    return "WEBVTT\n\n" + "\n\n".join(blocks) + "\n"
