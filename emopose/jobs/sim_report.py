"""results.md of the sim suite: the paper's Table execution beside this run's numbers."""

from __future__ import annotations

import math

from emopose import CLASSES
from emopose.results import markdown_table

# Paper, Table execution (MuJoCo trajectory-execution results).
PAPER = {
    "trials": "160 / 8 defaults / level 3",
    "completed": "160/160",
    "stops_timeouts": "0 / 0",
    "mae": "0.04066 rad (2.33 deg)",
    "class_range": "0.02289-0.05420 rad",
    "vlm": "3.532 / 4.368 s",
    "construction": "0.93 / 1.70 ms",
    "submission": "0.23 / 0.60 ms",
}


def _ms(stats: dict) -> str:
    if not stats.get("n"):
        return "-"
    return f"{stats['mean']:.3f} / {stats['p95']:.3f} ms"


def _paper_table(r: dict) -> str:
    """The paper's Table execution beside this run (and the compared arm law's MAE, if any)."""
    per_class = [v for v in r["per_class_mae_rad"].values() if not math.isnan(v)]
    class_range = f"{min(per_class):.5f}-{max(per_class):.5f} rad" if per_class else "-"
    rejected = f" (+{r['rejected']} rejected)" if r["rejected"] else ""
    ours = {
        "trials": f"{r['trials']} / {len(set(r['motions'].values()))} defaults / level {r['intensity']}",
        "completed": f"{r['completed']}/{r['trials']}",
        "stops_timeouts": f"{r['stops']} / {r['timeouts']}" + rejected,
        "mae": f"{r['mae_rad']:.5f} rad ({r['mae_deg']:.2f} deg)",
        "class_range": class_range,
        "vlm": "n/a (scripted records; no model call)",
        "construction": _ms(r["construction_ms"]),
        "submission": _ms(r["submission_ms"]),
    }
    labels = {
        "trials": "Trials / motions / intensity", "completed": "Completed trials",
        "stops_timeouts": "Stops / timeouts", "mae": "Target-sim joint MAE (Eq. sim-MAE)",
        "class_range": "Per-class MAE range", "vlm": "VLM inference mean / P95",
        "construction": "Trajectory construction mean / P95", "submission": "Command submission mean / P95",
    }
    paper = dict(PAPER)
    if r.get("arm_law"):
        labels["mae"] += f" under the {r['arm_law']} arm law"
    if r.get("compare"):  # right below the configured law's MAE
        c = r["compare"]
        at = list(labels).index("mae") + 1
        labels = dict([*list(labels.items())[:at], ("compare", f"... under the {c['arm_law']} arm law"),
                       *list(labels.items())[at:]])
        ours["compare"], paper["compare"] = f"{c['mae_rad']:.5f} rad ({c['mae_deg']:.2f} deg)", "-"
    return markdown_table(["Metric", "Paper", "This run"], [[labels[k], paper[k], ours[k]] for k in labels])


def suite_markdown(r: dict) -> str:
    classes = markdown_table(
        ["class", "motion", "MAE tick (rad)", "MAE time-aligned (rad)", "max force ratio"],
        [[c, r["motions"][c], f"{r['per_class_mae_rad'][c]:.5f}",
          f"{r['per_class_mae_time_aligned_rad'][c]:.5f}",
          f"{r['per_class_max_actuator_force_ratio'][c]:.3f}"] for c in CLASSES])
    return "\n\n".join([
        f"# Sim suite ({r['backend']}, {r['trials']} trials, dispatch until={r['dispatch_until']})",
        _paper_table(r),
        "## Per class",
        classes,
        "## What is compared",
        (f"Each trial's window runs from its `started` tick to its `completed` tick (the whole constructed "
         f"trajectory, initial transition included); both streams are linearly resampled to "
         f"N={r['points']} points and averaged over trials, points and 14 joints (Eq. sim-MAE). "
         f"Alignment: {r['alignment']}. "
         f"The headline MAE uses the tick alignment; the time-aligned MAE "
         f"({r['mae_time_aligned_rad']:.5f} rad) adds one control period of lag. Peak |error| "
         f"{r['max_abs_error_rad']:.4f} rad. Starting poses ({r['start_from']}): the previous trial's held "
         f"end pose or the neutral pose after the sequencer's recovery; mean offset from the motion's first "
         f"keyframe {r['start_offset_rad']['previous']:.3f} / {r['start_offset_rad']['rest']:.3f} rad."),
        (f"Max actuator-force ratio |tau|/limit (servo + gravity compensation): "
         f"{r['max_actuator_force_ratio']:.3f}; robot self-contacts during trials: {r['self_contacts']}. "
         f"Construction = TrajectoryBuilder.build inside the sequencer (safety check excluded); submission = "
         f"Sequencer.submit of one command."),
    ])
