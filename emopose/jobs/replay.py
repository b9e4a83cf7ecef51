"""+experiment=replay mcap=PATH: replay a recorded session's /joints/command stream in MuJoCo.

The commands are put back on the 50 Hz grid of their own timestamps (zero-order hold across any gap,
as the robot keeps its last setpoint; duplicates of one tick are dropped), the model starts at rest in
the first command, and every tick is stepped like the live backend does. Frames are rendered every
`render_every` ticks into replay.mp4; tracking MAE uses the sim suite's tick alignment.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from emopose import CONTROL_DT, NUM_JOINTS
from emopose.backends.capabilities import SimulatedState
from emopose.backends.stream_tap import StreamTap
from emopose.jobs.contact_sheet import view
from emopose.jobs.tracking import tracking_error
from emopose.recording import Recorder, read_recording
from emopose.resources import Run
from emopose.results import JobOutput


def command_grid(rows: list[tuple[float, dict]], dt: float = CONTROL_DT) -> tuple[np.ndarray, np.ndarray]:
    """(times, (T, 14) commands) on a dt grid from recorded (t, {"q": [...]}) messages."""
    stamped, first = {}, None
    for t, payload in rows:
        q = payload.get("q") if isinstance(payload, dict) else None
        if q is None or len(q) != NUM_JOINTS:
            raise ValueError(f"replay: a command message at t={t:.3f} s has no {NUM_JOINTS}-value 'q'")
        at = float(payload.get("t", t))
        first = at if first is None else first  # ticks counted from the first: session time is off-grid
        stamped.setdefault(round((at - first) / dt), np.asarray(q, dtype=float))
    ticks = np.array(sorted(stamped))
    grid = np.arange(ticks[0], ticks[-1] + 1)
    held = ticks[np.searchsorted(ticks, grid, side="right") - 1]  # latest recorded tick at or before
    return grid * dt, np.array([stamped[k] for k in held])


@dataclass
class ReplayJob:
    mcap: str | None = None
    topic: str = "/joints/command"
    video: str = "replay.mp4"  # relative to the run directory; null: no video
    camera: str = "front"  # front | oblique | side (upper-body presets) or an MJCF camera (head, ...)
    render_every: int = 2  # ticks per frame: 2 -> 25 fps
    max_seconds: float | None = None  # replay only the first part of a long session

    def __post_init__(self) -> None:
        if not self.mcap:
            raise ValueError("replay needs mcap=PATH (a session.mcap written by a run)")
        if not Path(self.mcap).is_file():
            raise ValueError(f"replay: mcap={self.mcap} does not exist")
        if self.render_every < 1:
            raise ValueError(f"replay: render_every must be >= 1, got {self.render_every}")

    def __call__(self, run: Run) -> JobOutput:
        res = run.resources
        streams = read_recording(self.mcap)
        if not streams.get(self.topic):
            raise ValueError(f"replay: {self.mcap} has no messages on {self.topic}; "
                             f"topics: {sorted(streams)}")
        times, commands = command_grid(streams[self.topic])
        if self.max_seconds is not None:
            keep = times - times[0] <= self.max_seconds + 1e-9
            times, commands = times[keep], commands[keep]
        backend = res.backend
        if not isinstance(backend, SimulatedState):
            raise ValueError(f"replay needs backend=mujoco (got backend {backend.name!r})")
        # The replay's own recording (the simulated response), not the session's: no control loop runs here.
        recorder = Recorder(res.run_dir / "replay.mcap") if run.session.record else None
        backend.connect(recorder)
        backend.reset(commands[0])
        sink, video = self._sink(res.run_dir)
        tap = StreamTap(backend)
        camera = view(self.camera)  # front/oblique/side: upper-body presets; else an MJCF camera
        try:
            for n, (t, q) in enumerate(zip(times - times[0], commands)):
                tap.send(float(t), q)
                if sink is not None and n % self.render_every == 0:
                    sink.add(backend.render_frame(camera))
        finally:
            if sink is not None:
                sink.close()
            if recorder is not None:
                recorder.close()
        error = tracking_error(np.array(tap.commands), np.array(tap.states), points=100)
        raw = np.abs(np.array(tap.states) - np.array(tap.commands))
        results = {
            "mcap": str(self.mcap), "topic": self.topic, "ticks": len(times),
            "recorded_messages": len(streams[self.topic]), "duration_s": float(times[-1] - times[0]),
            "mae_rad": float(raw.mean()), "mae_resampled_rad": error.mae,
            "mae_time_aligned_rad": error.mae_time_aligned, "max_abs_error_rad": error.max_abs,
            "max_actuator_force_ratio": float(backend.max_actuator_force_ratio),
            "self_contacts": sorted({f"{p[0]}|{p[1]}" for _, _, p in tap.contacts}),
            "video": str(video) if video else None,
        }
        return results, self._markdown(results)

    @staticmethod
    def _markdown(r: dict) -> str:
        return (f"# Replay of {r['mcap']}\n\n{r['ticks']} ticks ({r['duration_s']:.2f} s) of {r['topic']} "
                f"replayed in MuJoCo.\n\nTracking MAE {r['mae_rad']:.5f} rad over every tick "
                f"(command n vs the pose after tick n's physics; N=100 resampled: "
                f"{r['mae_resampled_rad']:.5f}; time-aligned: {r['mae_time_aligned_rad']:.5f}); "
                f"peak {r['max_abs_error_rad']:.4f} rad. Max actuator-force ratio "
                f"{r['max_actuator_force_ratio']:.3f}. Self-contacts: {r['self_contacts'] or 'none'}."
                f"\n\nVideo: {r['video'] or 'not rendered'}")

    def _sink(self, run_dir: Path):
        if not self.video:
            return None, None
        from emopose.robot.render import FrameSink

        path = run_dir / self.video
        return FrameSink(str(path), None, fps=1.0 / (CONTROL_DT * self.render_every)), path
