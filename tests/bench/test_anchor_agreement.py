"""benchmarks/anchor_agreement.py refuses a results file it cannot score, in one line naming it."""

import json
import subprocess
import sys

import pytest

from emopose.config import PROJECT_ROOT

SCRIPT = PROJECT_ROOT / "benchmarks/anchor_agreement.py"


@pytest.mark.parametrize("content,expected", [
    (None, "not a readable results.json"),
    ("{not json", "not a readable results.json"),
    (json.dumps({"kind": "bench", "predictions": []}), "kind 'bench', not a +experiment=sequence_suite run"),
    (json.dumps({"kind": "sequence_suite", "predictions": []}), "no plan for 160 of the annotated items"),
])
def test_a_results_file_it_cannot_score_is_a_one_line_error(tmp_path, content, expected):
    results = tmp_path / "results.json"
    if content is not None:
        results.write_text(content)
    run = subprocess.run([sys.executable, str(SCRIPT), str(results)], capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 1 and run.stdout == ""
    assert run.stderr.strip().splitlines() == [run.stderr.strip()] and expected in run.stderr
    assert str(results) in run.stderr
