"""sequence_suite and context_ablation read their suite file when the job is built: a missing, unreadable,
empty or malformed `bench.path` is one line naming the setting (or the file's line) and exit 2, before
the library, the planner or the backend is built; a variant the live library lacks is one line too."""

from __future__ import annotations

import json
import sys

import pytest

from emopose import __main__ as entry
from emopose.build import ConfigError, build_job

EXPERIMENTS = ("sequence_suite", "context_ablation")


def refusal(compose, experiment: str, path) -> str:
    with pytest.raises(ConfigError) as refused:
        build_job(compose(f"+experiment={experiment}", f"bench.path={path}"))
    line = entry.config_error_line(refused.value)
    assert "\n" not in line
    return line


@pytest.mark.parametrize("experiment", EXPERIMENTS)
def test_a_missing_or_empty_suite_is_refused_when_the_job_is_built(experiment, compose, tmp_path):
    for missing in (tmp_path / "absent.jsonl", tmp_path):  # no file, or a folder
        assert f"bench.path={missing}: suite file {missing} does not exist" in refusal(compose, experiment,
                                                                                      missing)
    empty = tmp_path / "empty.jsonl"
    empty.write_text("\n")
    assert refusal(compose, experiment, empty).endswith(f"bench.path={empty}: no items")


@pytest.mark.parametrize("experiment,field", [("sequence_suite", "labels"), ("context_ablation", "history")])
def test_a_suite_of_another_format_is_refused_with_its_file_line_and_field(experiment, field, compose,
                                                                           tmp_path):
    bench_item = tmp_path / "bench.jsonl"  # a single-label benchmark item, not this suite's format
    bench_item.write_text(json.dumps({"id": "b1", "text": "Over there.", "label": "pointing",
                                      "tier": "easy"}) + "\n")
    assert f"{bench_item}:1: field '{field}'" in refusal(compose, experiment, bench_item)


def test_the_command_line_refuses_a_missing_suite_in_one_line_with_exit_2(tmp_path, monkeypatch, capsys):
    missing = tmp_path / "absent.jsonl"
    monkeypatch.setattr(sys, "argv", ["emopose", "+experiment=sequence_suite", f"bench.path={missing}",
                                      f"hydra.run.dir={tmp_path / 'run'}"])
    with pytest.raises(SystemExit) as exited:
        entry.cli()
    err = capsys.readouterr().err
    assert exited.value.code == 2 and err.count("\n") == 1 and err.startswith("error: "), err
    assert f"bench.path={missing}" in err


def test_a_variant_missing_from_the_library_is_one_line_and_exit_2(library_overrides, tmp_path, monkeypatch,
                                                                   capsys):
    suite = tmp_path / "seq.jsonl"
    suite.write_text(json.dumps({"id": "s1", "text": "Hello! Over there.",
                                 "labels": ["welcoming", "pointing"], "anchors": ["Hello", "Over there"],
                                 "variants": ["welcoming_a", "point_left"]}) + "\n")
    monkeypatch.setattr(sys, "argv", ["emopose", "+experiment=sequence_suite", "planner=keyword",
                                      f"bench.path={suite}", *library_overrides,
                                      f"hydra.run.dir={tmp_path / 'run'}"])
    with pytest.raises(SystemExit) as exited:
        entry.cli()
    err = capsys.readouterr().err
    assert exited.value.code == 2 and err.count("\n") == 1, err
    assert err.startswith(f"error: {suite}:1: field 'variants[1]'"), err
