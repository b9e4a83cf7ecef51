"""+experiment=tour_lab: the guided tour, headless in simulation (or on the G1), with a full report.

Simulation: the MuJoCo backend with its planar base, the tour's objects added to the scene, a
virtual clock (the tour ticks the loop itself, so it runs faster than real time) and a low-rate
video from the overview camera. Writes session.mcap, tour.mp4 and results.json / results.md into
the run directory. On the G1 the base walks through the loco service on onboard odometry.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

from emopose.backends.base import Backend
from emopose.backends.capabilities import PlanarBase, SimulatedState
from emopose.backends.g1.backend import G1Backend
from emopose.clock import FakeClock
from emopose.library import MotionLibrary
from emopose.planners.base import Planner
from emopose.resources import Run
from emopose.results import write_results
from emopose.tour.camera import camera_for
from emopose.tour.g1_base import G1Base
from emopose.tour.navigator import MobileBase
from emopose.tour.runner import TourRunner
from emopose.tour.scenario import TourConfigError, TourSpec
from emopose.tour.scenario_loading import load_tour, parse_tour
from emopose.tour.sim_base import MujocoBase
from emopose.tour.sim_scene import install_scene

log = logging.getLogger(__name__)


@dataclass
class TourJob:
    tour: dict | None = None  # the composed scenario (conf/tour/<name>.yaml)
    tour_file: str | None = None  # or a scenario file of your own (wins over `tour`)
    answer_planner: dict | None = None  # planner config for questions (the experiment passes ${planner})
    answer_mode: str = "respond"  # planners with a `mode` answer visitors in this mode
    video: bool = True
    g1_odometry: str | None = None  # import path of a factory (loco, backend) -> () -> Pose2D

    def load(self) -> TourSpec:
        if self.tour_file:
            return load_tour(self.tour_file)
        if self.tour is None:
            raise TourConfigError("no tour scenario: add /tour: lab to the experiment or set job.tour_file=PATH")
        name = self.tour.get("name") if isinstance(self.tour, dict) else None
        return parse_tour(self.tour, f"conf/tour/{name}.yaml" if name else "tour config")

    def __call__(self, run: Run) -> dict:
        spec, res = self.load(), run.resources
        install_scene(res.backend, spec, res.run_dir, self.video)
        loop = run.session.open()
        base = self.make_base(res.backend, spec)
        if not isinstance(res.clock, FakeClock):
            loop.start()  # real time: the loop streams on its own thread, the tour waits on it
        runner = TourRunner(run, spec, base, camera_for(res.backend),
                            answer_planner=self.answering_planner(res.planner, res.library))
        started = time.perf_counter()
        try:
            report = runner.run()
        finally:
            if isinstance(base, G1Base):
                base.loco.close()  # the G1's loco client (the runner has already stopped the base)
        wall_s = time.perf_counter() - started
        results = {**report.as_dict(), "wall_time_s": wall_s,
                   "realtime_factor": report.sim_time_s / wall_s if wall_s > 0 else None,
                   "planner": res.planner.name, "backend": res.backend.name,
                   "stop_tolerance_m": spec.navigation.stop_tolerance_m,
                   "mcap": str(run.session.recorder.path) if run.session.recorder else None,
                   "video": res.backend.renderer.video_path if isinstance(res.backend, SimulatedState) else None}
        text = report.markdown() + f"\n\nWall time {wall_s:.1f} s."
        write_results(res.run_dir, results, text)
        print(text)
        return results

    def make_base(self, backend: Backend, spec: TourSpec) -> MobileBase:
        start = spec.start.pose()
        if isinstance(backend, SimulatedState) and isinstance(backend.planar_base, PlanarBase):
            noise = spec.odometry_noise
            base = MujocoBase(backend.planar_base, noise.velocity_std, noise.yaw_rate_std, noise.seed)
            base.place(start)
            return base
        if isinstance(backend, G1Backend):
            return self._g1_base(backend, spec)
        raise TourConfigError(f"the tour needs a mobile base: backend={backend.name} has none; use backend=mujoco "
                              "with a backend.planar_base (as +experiment=tour_lab sets) or backend=g1")

    def _g1_base(self, backend: Backend, spec: TourSpec) -> MobileBase:
        from hydra.utils import get_method

        from emopose.backends.g1 import LocoClient

        if not self.g1_odometry:
            raise TourConfigError("the tour on the G1 walks on onboard odometry: set job.g1_odometry to a "
                                  "factory (loco, backend) -> callable returning emopose.scene.geometry.Pose2D")
        settings = backend.settings
        loco = LocoClient(domain_id=settings.domain_id, network_interface=settings.network_interface,
                          max_vx=spec.navigation.max_vx, max_omega=spec.navigation.max_wz).open()
        odometry = get_method(self.g1_odometry)(loco, backend)
        return G1Base(loco, odometry, origin=spec.start.pose())

    def answering_planner(self, planner: Planner, library: MotionLibrary) -> Planner:
        """The run's planner, or a sibling in answer_mode when the configured planner narrates (llm)."""
        node = self.answer_planner
        if not node or "mode" not in node or node["mode"] == self.answer_mode:
            return planner
        from omegaconf import OmegaConf

        from emopose.build import make

        log.info("tour: answering questions with a %s-mode copy of the planner", self.answer_mode)
        return make(OmegaConf.create({**node, "mode": self.answer_mode}), "job.answer_planner", library=library)
