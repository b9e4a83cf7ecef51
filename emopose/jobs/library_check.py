"""+experiment=library_check: a pre-dispatch safety check of every library motion at every intensity.

Each (motion, level) is modulated (Eq. intensity), built by the sequencer's TrajectoryBuilder from the
library's neutral pose, and streamed at 50 Hz into the MuJoCo model reset to that pose, then held for
`hold_s`. Reported per run: robot self-contacts of the MJCF collision geometry (geom pairs, first/last
time), the smallest distance to a hard joint limit (commanded and simulated), the capsule heuristic's
minimum clearance and whether the configured safety check would reject the trajectory, the speed
stretch, tracking MAE and peak actuator-force ratio. Poses (one keyframe) are run once, at level 3
(intensity cannot change them). A contact sheet per motion and one overview image go to sheets/.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from emopose import CONTROL_DT
from emopose.backends.capabilities import Renderable, SimulatedState
from emopose.backends.stream_tap import StreamTap
from emopose.jobs.contact_sheet import render_keyframes, render_pose, write_overview, write_sheet
from emopose.jobs.tracking import tracking_error
from emopose.resources import Resources, Run
from emopose.results import JobOutput, markdown_table
from emopose.robot.collision import SelfCollisionChecker
from emopose.stages.modulate import Modulate

log = logging.getLogger(__name__)


@dataclass
class LibraryCheckJob:
    motions: list[str] | None = None  # None: every motion in the library
    intensities: list[int] = field(default_factory=lambda: [1, 2, 3, 4, 5])
    hold_s: float = 0.3  # keep simulating (and watching contacts) after the trajectory ends
    cameras: list[str] = field(default_factory=lambda: ["front", "oblique"])
    sheets: bool = True

    def __post_init__(self) -> None:
        bad = [i for i in self.intensities if i not in (1, 2, 3, 4, 5)]
        if bad or not self.intensities:
            raise ValueError(f"library_check: intensities must be a non-empty subset of 1..5, "
                             f"got {self.intensities}")

    def __call__(self, run: Run) -> JobOutput:
        res = run.resources
        backend = res.backend
        if not (isinstance(backend, SimulatedState) and isinstance(backend, Renderable)):
            raise ValueError(f"library_check needs backend=mujoco (got backend {backend.name!r})")
        names = self.motions or res.library.names
        unknown = [n for n in names if res.library.get(n) is None]
        if unknown:
            raise ValueError(f"library_check: unknown motions {unknown}; the library has {res.library.names}")
        backend.connect(None)
        # The configured intensity law (or the paper's, when the pipeline ablates modulate).
        modulate = res.pipeline.get("modulate") or Modulate(res.library.limits)
        report, images = {}, {}
        for name in names:
            entry = res.library.get(name)
            levels = self.intensities if entry.motion_type == "sequence" else [3]
            runs = {level: self._run(res, modulate.keyframes(entry.q, level), entry.default_duration)
                    for level in levels}
            report[name] = self._motion_summary(entry, runs)
            if self.sheets:
                images[name] = render_keyframes(backend, entry.q, self.cameras)
                contact = self._worst_contact(runs)
                extra = None
                if contact is not None:
                    level, t, pair, q = contact
                    extra = (render_pose(backend, q, self.cameras), f"contact L{level} t={t:.2f}s\n{pair}")
                report[name]["sheet"] = str(write_sheet(res.run_dir / "sheets", entry, images[name], extra,
                                                        self._status(report[name])))
            log.info("%s: %s", name, self._status(report[name]))
        if self.sheets:
            write_overview(res.run_dir / "sheets" / "overview.png", res.library, images,
                           {n: self._status(r) for n, r in report.items()})
        results = self._results(report)
        return results, self._markdown(results)

    # -- one (motion, level) run ---------------------------------------------------------------
    def _run(self, res: Resources, keyframes: np.ndarray, duration: float) -> dict:
        backend, limits = res.backend, res.library.limits
        neutral = res.library.neutral_entry.q[0]
        trajectory = res.sequencer.builder.build(keyframes, duration, neutral)
        samples = trajectory.samples
        tap = StreamTap(backend)
        backend.reset(samples[0])
        hold = round(self.hold_s / CONTROL_DT)
        for n, q in enumerate(np.vstack([samples[1:], np.repeat(samples[-1:], hold, axis=0)])):
            tap.send((n + 1) * CONTROL_DT, q)
        commands, states = np.array(tap.commands), np.array(tap.states)
        contacts: dict[str, dict] = {}
        for tick, t, pair in tap.contacts:
            c = contacts.setdefault(f"{pair[0]}|{pair[1]}",
                                    {"first_t": t, "last_t": t, "ticks": 0, "tick": tick})
            c["last_t"], c["ticks"] = t, c["ticks"] + 1
        first_contact = min(contacts.values(), key=lambda c: c["first_t"], default=None)
        reason = res.sequencer.safety(samples) if res.sequencer.safety else None
        return {
            "contacts": {p: {k: v for k, v in c.items() if k != "tick"} for p, c in contacts.items()},
            "_contact_state": None if first_contact is None else states[first_contact["tick"]],
            "margin_cmd": _margins(commands, limits),
            "margin_sim": _margins(states, limits),
            "capsule_clearance_m": float(SelfCollisionChecker(0.0).clearances(samples).min()),
            "safety_rejects": reason,
            "stretch": trajectory.stretch,
            "duration_s": trajectory.duration,
            "mae_rad": tracking_error(commands, states).mae,
            "force_ratio": float(backend.max_actuator_force_ratio),
        }

    @staticmethod
    def _worst_contact(runs: dict) -> tuple | None:
        for level, run in sorted(runs.items()):  # the lowest intensity that touches is the most telling
            if run["contacts"]:
                pair, c = min(run["contacts"].items(), key=lambda kv: kv[1]["first_t"])
                return level, c["first_t"], pair, run["_contact_state"]
        return None

    # -- summaries -----------------------------------------------------------------------------
    @staticmethod
    def _motion_summary(entry, runs: dict) -> dict:
        levels = {}
        for level, run in runs.items():
            run = {k: v for k, v in run.items() if not k.startswith("_")}
            levels[str(level)] = run
        worst = min(levels.items(), key=lambda kv: kv[1]["margin_cmd"]["rad"])
        return {
            "class": entry.cls, "motion_type": entry.motion_type, "keyframes": len(entry.keyframes),
            "duration_s": entry.default_duration, "levels": levels,
            "contact_levels": [int(lv) for lv, r in levels.items() if r["contacts"]],
            "contact_pairs": sorted({p for r in levels.values() for p in r["contacts"]}),
            "min_margin_rad": worst[1]["margin_cmd"]["rad"],
            "min_margin_joint": worst[1]["margin_cmd"]["joint"],
            "min_margin_level": int(worst[0]),
            "level3_margin_rad": levels.get("3", worst[1])["margin_cmd"]["rad"],
            "min_capsule_clearance_m": min(r["capsule_clearance_m"] for r in levels.values()),
            "rejected_levels": [int(lv) for lv, r in levels.items() if r["safety_rejects"]],
            "max_force_ratio": max(r["force_ratio"] for r in levels.values()),
            "max_mae_rad": max(r["mae_rad"] for r in levels.values()),
            "max_stretch": max(r["stretch"] for r in levels.values()),
        }

    @staticmethod
    def _status(summary: dict) -> str:
        if summary["contact_levels"]:
            return f"CONTACT at L{','.join(map(str, summary['contact_levels']))}"
        return "ok"

    def _results(self, report: dict) -> dict:
        runs = sum(len(r["levels"]) for r in report.values())
        return {
            "motions": len(report), "runs": runs, "intensities": self.intensities, "hold_s": self.hold_s,
            "with_contacts": {n: r["contact_levels"] for n, r in report.items() if r["contact_levels"]},
            "contacts_at_level3": sorted(n for n, r in report.items() if 3 in r["contact_levels"]),
            "safety_rejections": {n: r["rejected_levels"] for n, r in report.items() if r["rejected_levels"]},
            "min_margin_rad": min(r["min_margin_rad"] for r in report.values()),
            "max_force_ratio": max(r["max_force_ratio"] for r in report.values()),
            "per_motion": report,
        }

    @staticmethod
    def _markdown(results: dict) -> str:
        rows = []
        for name, r in results["per_motion"].items():
            rows.append([name, r["class"], r["keyframes"], f"{r['duration_s']:.2f}",
                         ",".join(map(str, r["contact_levels"])) or "-",
                         "; ".join(r["contact_pairs"]) or "-",
                         f"{r['min_margin_rad']:.3f} {r['min_margin_joint']} (L{r['min_margin_level']})",
                         f"{r['min_capsule_clearance_m'] * 100:.1f}",
                         ",".join(map(str, r["rejected_levels"])) or "-",
                         f"{r['max_force_ratio']:.2f}", f"{r['max_mae_rad']:.4f}", f"{r['max_stretch']:.2f}"])
        table = markdown_table(["motion", "class", "K", "d (s)", "contact levels", "MJCF contact pairs",
                                "min limit margin (rad)", "min capsule gap (cm)", "safety rejects",
                                "force ratio", "max MAE", "stretch"], rows)
        return "\n\n".join([
            f"# Library check: {results['motions']} motions, {results['runs']} simulated runs",
            table,
            (f"Motions with MJCF self-contacts: {results['with_contacts'] or 'none'}. "
             f"Rejected by the configured safety check: {results['safety_rejections'] or 'none'}. "
             f"Smallest commanded joint-limit margin {results['min_margin_rad']:.3f} rad; peak "
             f"actuator-force ratio {results['max_force_ratio']:.2f}. Each run starts at rest in the neutral "
             f"pose; the trajectory is held {results['hold_s']} s after it ends. "
             f"Contact sheets: sheets/<motion>.png."),
        ])


def _margins(q: np.ndarray, limits) -> dict:
    """Smallest distance (rad) of any sample to a hard limit, and the joint where it occurs."""
    gap = np.minimum(q - limits.lower, limits.upper - q).min(axis=0)
    j = int(np.argmin(gap))
    return {"rad": float(gap[j]), "joint": limits.names[j]}
