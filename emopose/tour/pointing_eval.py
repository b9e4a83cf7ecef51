"""+experiment=pointing_eval: how precisely aimed pointing hits its targets, by FK and in MuJoCo.

Targets: every object of interest of the tour, seen from its stop, plus probe directions around the
robot at its start pose (azimuth x elevation at `probe_range_m` from the torso). For each one the
robot stands at the pose, the pointing motion is aimed by the aim stage (IK), and the motion runs
through the sequencer up to its last aimed keyframe and holds there; after `settle_s` the angle
between the simulated hand's pointing axis and the direction from the hand to the target is
measured from MuJoCo's body frames. The FK error of the commanded pose is reported beside it. A
target is reachable when the IK converged and the aimed motion passed the self-collision check.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from emopose.backends.capabilities import PlanarBase, SimulatedState
from emopose.contract import LibraryEntry
from emopose.execution.gesture_command import GestureCommand
from emopose.resources import Run
from emopose.results import JobOutput, markdown_table
from emopose.robot.kinematics import HAND_ORIGIN
from emopose.robot.pointing_ik import pointing_error
from emopose.scene.geometry import Pose2D, angle_between, map_to_torso, torso_to_map
from emopose.stages.aim import AimStage, peak_indices
from emopose.tour.scenario import TourConfigError
from emopose.tour.scenario_loading import load_tour, parse_tour
from emopose.tour.sim_base import MujocoBase
from emopose.tour.sim_scene import install_scene
from emopose.turn.session import Session

SHOULDER_HEIGHT = 0.24  # probes are centred about shoulder height above the torso origin


@dataclass
class PointingEvalJob:
    tour: dict | None = None
    tour_file: str | None = None
    gesture: str | None = None  # library motion to aim; null = the class default for pointing
    probe_azimuth_deg: list[float] = field(default_factory=lambda: [-75, -45, -15, 15, 45, 75])
    probe_elevation_deg: list[float] = field(default_factory=lambda: [-25, 0, 25])
    probe_range_m: float = 2.0
    settle_s: float = 1.0
    max_error_deg: float = 5.0

    def __call__(self, run: Run) -> JobOutput:
        spec = load_tour(self.tour_file) if self.tour_file else parse_tour(self.tour, "tour config")
        res = run.resources
        if not (isinstance(res.backend, SimulatedState) and isinstance(res.backend.planar_base, PlanarBase)):
            raise TourConfigError("pointing_eval measures in simulation with a planar base: use "
                                  "backend=mujoco with a backend.planar_base (as +experiment=pointing_eval "
                                  "sets)")
        install_scene(res.backend, spec, res.run_dir)
        run.session.open()
        base = MujocoBase(res.backend.planar_base)
        entry = res.library.get(self.gesture) if self.gesture else res.library.class_default("pointing")
        if entry is None:
            raise TourConfigError(f"pointing_eval: no pointing motion {self.gesture!r} in the library")
        # The configured aim stage (pipeline=tour), else one with the stage's defaults and the run's limits.
        stage = res.pipeline.get("aim") or AimStage(res.scene, res.library.limits, res.sequencer.safety)
        rows = [self.trial(run.session, base, stage, entry, pose, name, target)
                for name, pose, target in self.targets(spec)]
        reachable = [r for r in rows if r["reachable"]]
        worst = max((r["sim_error_deg"] for r in reachable), default=float("nan"))
        results = {
            "gesture": entry.name, "targets": len(rows), "reachable": len(reachable),
            "max_sim_error_deg": worst,
            "mean_sim_error_deg": (float(np.mean([r["sim_error_deg"] for r in reachable])) if reachable
                                   else None),
            "max_fk_error_deg": max((r["fk_error_deg"] for r in reachable), default=float("nan")),
            "all_within_limit": bool(reachable) and worst <= self.max_error_deg,
            "max_error_limit_deg": self.max_error_deg, "trials": rows,
        }
        table = markdown_table(["target", "side", "mirrored", "FK deg", "sim deg", "reachable"],
                               [[r["target"], r["side"], r["mirrored"], r["fk_error_deg"], r["sim_error_deg"],
                                 r["reachable"]] for r in rows])
        text = (f"# Pointing accuracy ({entry.name})\n\n{table}\n\n{len(reachable)}/{len(rows)} reachable; "
                f"worst simulated error {worst:.2f} deg (limit {self.max_error_deg} deg), FK worst "
                f"{results['max_fk_error_deg']:.2f} deg.")
        return results, text

    def targets(self, spec) -> list[tuple[str, Pose2D, np.ndarray]]:
        """(label, robot pose, target in the map frame) for the tour's objects and the probes."""
        out = [(f"{stop.name}/{obj.name}", stop.pose.pose(), np.asarray(obj.position, float))
               for stop in spec.stops_in_order for obj in stop.objects]
        start = spec.start.pose()
        for el in self.probe_elevation_deg:
            for az in self.probe_azimuth_deg:
                a, e = math.radians(az), math.radians(el)
                local = self.probe_range_m * np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a),
                                                       math.sin(e)]) + [0.0, 0.0, SHOULDER_HEIGHT]
                out.append((f"probe az {az:+.0f} el {el:+.0f}", start, torso_to_map(local, start)))
        return out

    def trial(self, session: Session, base: MujocoBase, stage: AimStage, entry: LibraryEntry, pose: Pose2D,
              name: str, target: np.ndarray) -> dict:
        loop, backend, sequencer = session.loop, session.backend, session.loop.sequencer
        backend.reset(session.neutral)  # arms at rest, base at the origin; then stand at the pose
        base.place(pose)
        session.restart(session.neutral)
        local = map_to_torso(target, pose)
        aimed, report = stage.aim(entry.q, local, entry.name, name)
        side = 0 if report.side == "left" else 1
        last = peak_indices(aimed, side, stage.peak_fraction)[-1]
        duration = entry.default_duration * last / max(len(aimed) - 1, 1)
        sequencer.submit(GestureCommand(entry.name, aimed[: last + 1], max(duration, 0.5), label="pointing"))
        loop.run_until(sequencer.settled, timeout_s=20.0)
        loop.run_until(lambda: False, timeout_s=self.settle_s)  # hold the pose and let the servos settle
        sim_error = self.measure(backend, side, target)
        return {"target": name, "side": report.side, "mirrored": report.mirrored,
                "fk_error_deg": math.degrees(pointing_error(aimed[last], side, local)),
                "fk_measured_deg": math.degrees(pointing_error(backend.measured(), side, local)),
                "sim_error_deg": sim_error, "reachable": report.converged and report.applied,
                "ik_converged": report.converged, "collision": report.reason}

    @staticmethod
    def measure(backend, side: int, target: np.ndarray) -> float:
        """Angle (deg) from the simulated hand's axis to the target, from MuJoCo's body frames."""
        body = backend.data.body(f"{('left', 'right')[side]}_wrist_yaw_link")
        axis = body.xmat.reshape(3, 3)[:, 0]
        origin = body.xpos + HAND_ORIGIN * axis
        return math.degrees(angle_between(axis, target - origin))
