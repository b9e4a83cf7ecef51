"""What adding motions by file costs (issue 29, deliverable 4): the probes they take and the held-out slice.

    python benchmarks/new_motion_probes.py
Adds tests/planners/new_motions/*.yaml (five motions of five classes) and
tests/planners/studio_motions/little_salute.yaml (a salute whose description says "greeting") to a copy of
the G1 library, one at a time and then all together, and prints JSON: per motion, the probe utterances
of library/probes.yaml it would take (and from which motion), those of another intent apart; and the
held-out slice (single-act top-1, sequences ordered exact) before and after all six are in the library.
The salute is measured with its `examples:` and without them.
"""

from __future__ import annotations

import json
import shutil
import sys
import tempfile
from dataclasses import asdict
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # run from a checkout without installing

from emopose.contract import LibraryEntry  # noqa: E402
from emopose.jobs.train_local import held_out_examples, held_out_metrics  # noqa: E402
from emopose.planners.local.probes import probe_moves  # noqa: E402
from tests.planners.local_helpers import configured_local_planner  # noqa: E402

FILES = sorted((ROOT / "tests/planners/new_motions").glob("*.yaml")) + [
    ROOT / "tests/planners/studio_motions/little_salute.yaml"]


def main() -> None:
    folder = Path(tempfile.mkdtemp()) / "g1"
    planner = configured_local_planner(folder)
    entries = [LibraryEntry.model_validate(yaml.safe_load(f.read_text())) for f in FILES]
    entries.append(entries[-1].model_copy(update={"name": "little_salute_no_examples", "examples": ()}))
    report: dict = {"probes": {}}
    for entry in entries:
        moves = probe_moves(planner, entry)
        report["probes"][entry.name] = {"taken": [asdict(m) for m in moves],
                                        "other_intent": sum(m.intent != entry.cls for m in moves)}
    examples = [e for e in held_out_examples(planner) if not e.history]
    scored = [planner.score(e.text) for e in examples]
    report["held_out_before"] = held_out_metrics(planner, examples, scored)
    for motion_file in FILES:
        shutil.copy(motion_file, folder)
    planner.library.reload()
    report["held_out_after"] = held_out_metrics(planner, examples, scored)
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
