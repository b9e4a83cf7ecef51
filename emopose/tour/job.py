"""+experiment=tour_lab: the guided tour, headless in simulation (or on the G1), with a full report.

Simulation: the MuJoCo backend with its planar base, the tour's objects added to the scene and a
virtual clock (the tour ticks the loop itself, so it runs faster than real time); after the tour, the
video is rendered from the recording in a child process (emopose/tour/video.py). Writes session.mcap,
tour.mp4 (+ tour.vtt captions) and results.json / results.md into the run directory. The base the
tour walks on is the `tour/base` config group (job.base): sim, or g1 (the loco service on onboard
odometry).
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from emopose.backends.base import Backend
from emopose.execution.priority import check_rt_priority
from emopose.library import MotionLibrary
from emopose.planners.base import Planner
from emopose.resources import Run
from emopose.results import JobOutput
from emopose.tour.camera import camera_for
from emopose.tour.navigator import MobileBase
from emopose.tour.runner import TourRunner
from emopose.tour.scenario import TourConfigError, TourSpec
from emopose.tour.scenario_loading import load_tour, parse_tour
from emopose.tour.sim_scene import install_scene
from emopose.tour.video import VideoSettings, make_video

log = logging.getLogger(__name__)


class TourBase(Protocol):
    """A `tour/base` option (conf/tour/base/): opens the mobile base for the connected backend and
    releases it after the tour."""

    def open(self, backend: Backend, spec: TourSpec) -> MobileBase: ...

    def close(self) -> None: ...


@dataclass
class TourJob:
    tour: dict | None = None  # the composed scenario (conf/tour/<name>.yaml)
    tour_file: str | None = None  # or a scenario file of your own (wins over `tour`)
    answer_planner: dict | None = None  # planner config for questions (the experiment passes ${planner})
    answer_mode: str = "respond"  # planners with a `mode` answer visitors in this mode
    video: bool = True  # tour.mp4 in simulation, rendered from the recording after the tour
    video_settings: dict = field(default_factory=dict)  # VideoSettings fields (size, fps, camera)
    base: dict | None = None  # the tour/base node (conf/tour/base/), built by build.make
    rt_priority: int = 0  # run.rt_priority: the control loop thread's SCHED_FIFO priority in real time

    def __post_init__(self) -> None:
        check_rt_priority(self.rt_priority)
        try:
            self._video = VideoSettings(**self.video_settings)
        except (TypeError, ValueError) as exc:
            raise TourConfigError(f"job.video_settings: {exc}") from exc

    def load(self) -> TourSpec:
        if self.tour_file:
            return load_tour(self.tour_file)
        if self.tour is None:
            raise TourConfigError("no tour scenario: add /tour: lab to the experiment or set "
                                  "job.tour_file=PATH")
        name = self.tour.get("name") if isinstance(self.tour, dict) else None
        return parse_tour(self.tour, f"conf/tour/{name}.yaml" if name else "tour config")

    def __call__(self, run: Run) -> JobOutput:
        spec, res, tour_base = self.load(), run.resources, self.tour_base()
        scene = install_scene(res.backend, spec, res.run_dir)
        loop = run.session.open()
        base = tour_base.open(res.backend, spec)
        if res.clock.realtime:
            loop.start(self.rt_priority)  # real time: the loop streams on its thread, the tour waits on it
        runner = TourRunner(run, spec, base, camera_for(res.backend),
                            answer_planner=self.answering_planner(res.planner, res.library))
        started = time.perf_counter()
        try:
            report = runner.run()
        finally:
            tour_base.close()  # the runner has already stopped the base
        wall_s = time.perf_counter() - started
        video = self.render_video(run, scene)
        results = {**report.as_dict(), "wall_time_s": wall_s,
                   "realtime_factor": report.sim_time_s / wall_s if wall_s > 0 else None,
                   "planner": res.planner.name, "backend": res.backend.name,
                   "stop_tolerance_m": spec.navigation.stop_tolerance_m,
                   "mcap": str(run.session.recorder.path) if run.session.recorder else None,
                   **video}
        return results, report.markdown() + f"\n\nWall time {wall_s:.1f} s."

    def render_video(self, run: Run, scene: Path | None) -> dict:
        """tour.mp4 from the finished recording (simulation only); a failure is reported, the tour kept."""
        recorder, started = run.session.recorder, time.perf_counter()
        if not self.video or scene is None or recorder is None:
            return {"video": None}
        run.session.close()  # the recording is complete (`with run:` closing it again does nothing)
        try:
            path = make_video(recorder.path, scene, run.resources.run_dir / "tour.mp4", self._video)
        except Exception as exc:  # noqa: BLE001 -- no GL, no ffmpeg: the tour's results stand without it
            log.warning("tour video not made: %s", exc)
            return {"video": None, "video_error": f"{type(exc).__name__}: {exc}"[:300]}
        return {"video": str(path), "video_wall_s": time.perf_counter() - started}

    def tour_base(self) -> TourBase:
        if not self.base:
            raise TourConfigError("no tour base: add /tour/base: sim (or g1) to the experiment's defaults")
        return self._build(self.base, "job.base")

    def answering_planner(self, planner: Planner, library: MotionLibrary) -> Planner:
        """The run's planner, or a sibling in answer_mode when the configured planner narrates (llm)."""
        node = self.answer_planner
        if not node or "mode" not in node or node["mode"] == self.answer_mode:
            return planner
        log.info("tour: answering questions with a %s-mode copy of the planner", self.answer_mode)
        return self._build({**node, "mode": self.answer_mode}, "job.answer_planner", library=library)

    @staticmethod
    def _build(node: dict, key: str, **runtime: object) -> object:
        """A node the job builds itself (it is built non-recursively: answer_planner stays a config until
        needed), through build.make like every other object."""
        from omegaconf import OmegaConf

        from emopose.build import make

        return make(OmegaConf.create(node), key, **runtime)
