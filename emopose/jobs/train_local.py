"""+experiment=train_local: (re)train the local planner and report accuracy on the held-out slice.

Building the context trains the planner if no cached artifact matches the training files and
hyper-parameters (delete the cache file, or change planner.training.seed, to force a retrain). The
held-out slice is the single-act training items whose id hashes into planner.training.holdout_percent;
they never enter training. The benchmark suites are not touched.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from emopose import CLASSES
from emopose.context import RunContext
from emopose.jobs.report import markdown_table, write_results
from emopose.planners.local_model import load_training


@dataclass
class TrainLocalJob:
    def __call__(self, ctx: RunContext) -> dict:
        planner = ctx.planner
        if not hasattr(planner, "train_files"):
            raise ValueError("train_local needs planner=local")
        held_out = load_training(planner.train_files, planner.model.config.holdout_percent, held_out=True)
        _, proba = planner.model.encode_and_classify([item.text for item in held_out])
        predicted = [CLASSES[k] for k in proba.argmax(1)]
        correct = np.array([p == item.label for p, item in zip(predicted, held_out)])
        per_class = {c: float(correct[[i.label == c for i in held_out]].mean()) for c in CLASSES}
        results = {"held_out_items": len(held_out), "accuracy": float(correct.mean()),
                   "per_class_accuracy": per_class, "training": vars(planner.model.config)}
        table = markdown_table(["class", "held-out accuracy"], [[c, f"{100 * a:.1f}%"] for c, a in per_class.items()])
        text = f"Local planner, held-out slice of the training split: {100 * correct.mean():.1f}% " \
               f"of {len(held_out)} items\n\n{table}"
        write_results(ctx.run_dir, results, text)
        print(text)
        return results
