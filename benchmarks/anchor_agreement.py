"""How far careful annotators agree on where a gesture's words start (issue 29, the trigger-onset target).

    python benchmarks/anchor_agreement.py [results.json of +experiment=sequence_suite]
The sequence suite's target asks 90 % of the gold anchors to have their gesture's trigger onset
within 200 ms of theirs. Three annotators marked the anchors of 160 suite items (a random.Random(7)
sample, 485 acts) again, independently, seeing only each item's text and labels and a guide
(benchmarks/data/anchor_agreement/): two the written guide the training anchors follow
(experiments/train/ANCHORS.md, its rule and the stroke's two discourse rules: `guide_written.md`), one a
plain definition of the lexical affiliate (`guide_plain.md`). They were separate model sessions that
never saw a suite's gold nor each other's output. Every annotation, and the planner's triggers from a
sequence_suite run, is scored against every other as the job scores a planner against the gold
(emopose/sync/affiliate.py, espeak word onsets): the share of the reference's anchors matched within
200 ms. Prints JSON.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run from a checkout without installing

from emopose.bench.suites import load_sequence  # noqa: E402
from emopose.speech.espeak import EspeakSynthesizer  # noqa: E402
from emopose.sync.affiliate import WINDOW_S, anchor_offsets, offset_summary, trigger_spans  # noqa: E402

DATA = ROOT / "benchmarks/data/anchor_agreement"
SUITE = ROOT / "experiments/sequence/sequence_suite.jsonl"
ANNOTATORS = ("written_1", "written_2", "plain")


def read_annotation(name: str) -> dict[str, list[str]]:
    return {row["id"]: row["anchors"] for row in map(json.loads, (DATA / f"{name}.jsonl").open())}


def planner_triggers(results: Path, ids: set[str]) -> dict[str, list[str]]:
    """The first pass's triggers of a sequence_suite run over the shipped suite; SystemExit otherwise."""
    try:
        run = json.loads(results.read_text())
    except (OSError, json.JSONDecodeError) as err:
        raise SystemExit(f"{results}: not a readable results.json ({err})") from None
    if run.get("kind") != "sequence_suite":
        raise SystemExit(f"{results}: kind {run.get('kind')!r}, not a +experiment=sequence_suite run")
    triggers = {p["id"]: p["triggers"] for p in run["predictions"] if p["pass"] == 0}
    if missing := sorted(ids - set(triggers)):
        raise SystemExit(f"{results}: no plan for {len(missing)} of the annotated items (e.g. {missing[0]}); "
                         f"run sequence_suite on {SUITE.relative_to(ROOT)}")
    return triggers


def main() -> None:
    default = ROOT / "results/runs/sequence_suite/local/results.json"
    marked = {name: read_annotation(name) for name in ANNOTATORS}
    items = [item for item in load_sequence(SUITE) if item.id in marked["written_1"]]
    marked["gold"] = {item.id: [item.text[a:b] for a, b in item.spans] for item in items}
    marked["planner"] = planner_triggers(Path(sys.argv[1]) if len(sys.argv) > 1 else default,
                                         set(marked["gold"]))
    synthesizer = EspeakSynthesizer()
    events = {item.id: synthesizer.word_events(item.text) for item in items}

    def offsets(reference: str, other: str) -> dict[tuple[str, int], float | None]:
        """(item, act) -> onset of `other`'s words minus the `reference` anchor's, as the job scores it."""
        found = {}
        for item in items:
            anchors = trigger_spans(item.text, marked[reference][item.id])
            words = marked[other][item.id]
            for k, o in enumerate(anchor_offsets(item.text, anchors, words, events[item.id])):
                found[item.id, k] = o
        return found

    def agreement(reference: str, other: str, acts: set | None = None) -> float:
        found = offsets(reference, other)
        return round(offset_summary([o for act, o in found.items() if acts is None or act in acts])
                     ["within_share"], 3)

    names = ["gold", *ANNOTATORS]
    report = {"items": len(items), "acts": sum(len(item.labels) for item in items),
              "agreement": {f"{a} vs {b}": agreement(a, b) for i, a in enumerate(names)
                            for b in names[i + 1:]},
              "planner": {f"against {a}": agreement(a, "planner") for a in names}}
    # where the two annotators of the written guide agree, who else agrees with them
    consensus = {act for act, o in offsets("written_1", "written_2").items()
                 if o is not None and abs(o) <= WINDOW_S + 1e-6}
    report["written consensus"] = {"acts": len(consensus),
                                   **{f"{who} within": agreement("written_1", who, consensus)
                                      for who in ("gold", "planner", "plain")}}
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
