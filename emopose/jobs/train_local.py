"""+experiment=train_local: train the local planner and score it on the held-out training slice.

This is where training belongs: building the run trains when no cached artifact matches the training
files and hyper-parameters (the experiment sets planner.train_if_missing; LocalPlanner.from_config), and
`job.retrain=true` trains again even when one does (progress bars with ETA on stderr). The held-out
slice is every training item (single-act, multi-act and dialogue) whose id hashes into
planner.training.holdout_percent; those never enter training. Dialogues are scored with and without
their history (history must never hurt). The benchmark suites are not touched:
this is where the split parameters (temperature, boundary_weight, act_cost) are chosen, with
`job.search` listing values to try (every combination is scored from one forward pass per item).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

from emopose.bench.sequence_metrics import SequencePrediction, item_scores
from emopose.bench.suites import SequenceItem
from emopose.planners.local.affiliate import act_trigger
from emopose.planners.local.data import Example, load_examples
from emopose.planners.local.planner import LocalPlanner, ScoredUtterance
from emopose.resources import Run
from emopose.results import JobOutput, markdown_table

SPLIT_PARAMETERS = ("temperature", "boundary_weight", "act_cost")


def held_out_examples(planner: LocalPlanner) -> list[Example]:
    """The training items held out of the planner's training (planner.training.holdout_percent)."""
    settings = planner.settings
    return load_examples(settings.train_files, settings.training.holdout_percent, held_out=True)


def scored_dialogues(planner: LocalPlanner, dialogues: list[Example]) -> dict[bool, list[ScoredUtterance]]:
    """The dialogue items' final utterances scored with their history (True) and without (False)."""
    return {with_history: [planner.score(e.text, e.history if with_history else ()) for e in dialogues]
            for with_history in (True, False)}


def context_metrics(planner: LocalPlanner, dialogues: list[Example],
                    scored: dict[bool, list[ScoredUtterance]]) -> dict:
    """Top-1 of the dialogue items read with and without their history (fractions); scored as
    scored_dialogues() gives them."""
    def top1(with_history: bool) -> float | None:
        if not dialogues:  # a planner trained without the dialogue split has none held out
            return None
        first = [planner.best_split(s)[0] for s in scored[with_history]]
        return sum(a.cls == e.acts[0].label for a, e in zip(first, dialogues)) / len(dialogues)

    return {"context_with_history": top1(True), "context_without": top1(False), "dialogues": len(dialogues)}


def held_out_metrics(planner: LocalPlanner, examples: list[Example], scored: list[ScoredUtterance]) -> dict:
    """Single-act top-1 and kept-whole rate; multi-act ordered exact, anchor recall and exact-variant
    match, scored as the sequence suite scores them (emopose.bench.sequence_metrics). Fractions."""
    single_hits = single_whole = sequences = exact = anchors = anchor_hits = variant_hits = 0
    for example, scores in zip(examples, scored):
        acts = planner.best_split(scores)[: planner.settings.max_records]
        classes = tuple(a.cls for a in acts)
        gold = tuple(a.label for a in example.acts)
        if len(gold) == 1:
            single_hits += classes[0] == gold[0]
            single_whole += len(classes) == 1
            continue
        gold_anchors = tuple(example.text[a:b] for a, b in example.anchors)
        item = SequenceItem(example.id, example.text, gold, gold_anchors, tuple(example.variants))
        spans = [act_trigger(example.text, scores.analysis, (a.start, a.end), a.cls) for a in acts]
        triggers = tuple(example.text[start:end] for start, end in spans)
        result = item_scores(item, SequencePrediction(classes, triggers,
                                                      tuple(a.variant for a in acts)))
        sequences += 1
        exact += result["exact"]
        anchors += len(item.anchors)
        anchor_hits += result["anchors_hit"]
        variant_hits += result["variants_hit"]
    singles = len(examples) - sequences
    return {"single_top1": single_hits / max(1, singles), "single_kept_whole": single_whole / max(1, singles),
            "sequence_exact": exact / max(1, sequences), "anchor_recall": anchor_hits / max(1, anchors),
            "exact_variant": variant_hits / max(1, anchors),
            "singles": singles, "sequences": sequences}


@dataclass
class TrainLocalJob:
    search: dict[str, list[float]] | None  # split parameter -> values to try
    retrain: bool  # train even when a cached artifact matches

    def __post_init__(self) -> None:
        """Check job.search when the job is built, before the run (and any training) is."""
        search = self.search or {}
        unknown = set(search) - set(SPLIT_PARAMETERS)
        if unknown:
            raise ValueError(f"job.search: unknown split parameters {sorted(unknown)}; "
                             f"use {SPLIT_PARAMETERS}")
        not_lists = [name for name, values in search.items()
                     if not isinstance(values, list) or not all(isinstance(v, int | float) for v in values)]
        if not_lists:
            raise ValueError(f"job.search: {not_lists} must each be a list of numbers, "
                             "e.g. job.search={act_cost:[-1.0,-0.5]}")

    def __call__(self, run: Run) -> JobOutput:
        planner = run.resources.planner
        if not isinstance(planner, LocalPlanner):
            raise ValueError("train_local needs planner=local")
        if self.retrain:
            planner.retrain()
        search = self.search or {}
        grid = [dict(zip(search, values)) for values in itertools.product(*search.values())]
        rows = held_out_rows(planner, grid or [{}])
        text = (f"Local planner on the held-out training slice ({rows[0]['singles']} single-act, "
                f"{rows[0]['sequences']} multi-act, {rows[0]['dialogues']} dialogue items)\n\n"
                f"{held_out_table(rows)}")
        return {"held_out": rows, "training": planner.settings.training.model_dump()}, text


def held_out_rows(planner: LocalPlanner, settings: list[dict[str, float]]) -> list[dict]:
    """The held-out metrics under each setting of the split parameters (the planner's own restored after)."""
    held_out = held_out_examples(planner)
    examples = [e for e in held_out if not e.history]
    dialogues = [e for e in held_out if e.history]
    scored = [planner.score(e.text) for e in examples]  # once: every setting re-splits the same scores
    dialogue_scores = scored_dialogues(planner, dialogues)
    configured = {p: getattr(planner, p) for p in SPLIT_PARAMETERS}
    rows = []
    try:
        for setting in settings:
            for name, value in {**configured, **setting}.items():
                setattr(planner, name, value)
            rows.append({**configured, **setting, **held_out_metrics(planner, examples, scored),
                         **context_metrics(planner, dialogues, dialogue_scores)})
    finally:
        for name, value in configured.items():
            setattr(planner, name, value)
    return rows


def held_out_table(rows: list[dict]) -> str:
    header = [*SPLIT_PARAMETERS, "single top-1", "kept whole", "sequence exact", "anchor recall",
              "exact variant", "dialogue, with history", "without"]
    metrics = ("single_top1", "single_kept_whole", "sequence_exact", "anchor_recall", "exact_variant",
               "context_with_history", "context_without")
    return markdown_table(header, [[*(r[p] for p in SPLIT_PARAMETERS),
                                    *("-" if r[k] is None else f"{100 * r[k]:.1f}%" for k in metrics)]
                                   for r in rows])
