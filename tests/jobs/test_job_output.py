"""The one ending of every job: it returns (results, markdown); app.run writes results.json and
results.md and prints the markdown, and a job that fails at its end (JobFailure) is written the same
way before its error decides how the run exits."""

from __future__ import annotations

import json

import pytest
from omegaconf import OmegaConf

from emopose.app import run
from emopose.resources import Run
from emopose.results import JobFailure, JobOutput
from tests.conftest import compose_config


class Answers:
    def __call__(self, run: Run) -> JobOutput:
        return {"answer": 42, "backend": run.resources.backend.name}, "# Answer\n\n42 on dry_run"


class FailsAtItsEnd:
    def __call__(self, run: Run) -> JobOutput:
        raise JobFailure({"answer": None}, "# No answer", SystemExit("no answer: see results.md"))


def job_config(job: str):
    cfg = compose_config(["+experiment=plan", "planner=keyword", "run.record=false"])
    OmegaConf.update(cfg, "job", {"_target_": f"{__name__}.{job}"}, merge=False)
    return cfg


def test_app_writes_and_prints_what_the_job_returns(tmp_path, capsys):
    results = run(job_config("Answers"), tmp_path)
    assert results == {"answer": 42, "backend": "dry_run"}
    assert json.loads((tmp_path / "results.json").read_text()) == results
    assert (tmp_path / "results.md").read_text() == "# Answer\n\n42 on dry_run\n"
    assert "42 on dry_run" in capsys.readouterr().out


def test_a_job_failing_at_its_end_is_written_then_exits_with_its_error(tmp_path, capsys):
    with pytest.raises(SystemExit, match="no answer: see results.md"):
        run(job_config("FailsAtItsEnd"), tmp_path)
    assert json.loads((tmp_path / "results.json").read_text()) == {"answer": None}
    assert (tmp_path / "results.md").read_text() == "# No answer\n"
    assert "# No answer" in capsys.readouterr().out
