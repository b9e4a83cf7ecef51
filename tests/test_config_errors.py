"""One config-error path: a bad override, value or input file ends in one line naming the key (or file)
and the rule, exit status 2, before anything starts; nothing is coerced into something it was not."""

from __future__ import annotations

import sys

import pytest
import yaml
from pydantic import ValidationError

from emopose import __main__ as entry
from emopose.build import ConfigError, build_job, build_run
from emopose.joint_limits import LibraryError
from emopose.library import MAX_FILE_BYTES
from emopose.web.schemas import GestureRequest, SayRequest
from tests.conftest import load_library, make_library_dir


@pytest.mark.parametrize("overrides,named", [
    (["+experiment=plan", "nosuchkey=1"], "'nosuchkey'"),
    (["+experiment=plan", "planner.nope.x=1"], "'planner.nope.x'"),
    (["+experiment=plan", "planner=nope"], "planner=nope: no such option; planner is one of annotate,"),
    (["+experiment=nope"], "experiment=nope: no such option; experiment is one of bench,"),
    (["+experiment=plan", "a=b=c]"], "a=b=c]: "),
])
def test_hydra_composition_errors_are_one_line_and_exit_2(overrides, named, tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("HYDRA_FULL_ERROR", "0")  # cli() sets it; monkeypatch restores it afterwards
    monkeypatch.setattr(sys, "argv", ["emopose", *overrides, f"hydra.run.dir={tmp_path}"])
    with pytest.raises(SystemExit) as exited:
        entry.cli()
    assert exited.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: ") and named in err, err


@pytest.mark.parametrize("overrides,named", [
    (["+experiment=plan", "utterance=''"], "utterance is empty"),
    (["+experiment=bench", "job.tiers=[impossible]"], "job.tiers=['impossible']: must be a non-empty subset"),
    (["+experiment=bench", "job.tiers=[]"], "job.tiers=[]: must be a non-empty subset"),
    (["+experiment=bench", "bench.path=/no/such/bench.jsonl"], "/no/such/bench.jsonl does not exist"),
    (["+experiment=bench", "~bench.path"], "'bench.path' not found"),
    (["+experiment=bench", "passes=-1"], "passes=-1: must be >= 1"),
    (["+experiment=sequence_suite", "passes=-1"], "passes=-1: must be >= 1"),
    (["+experiment=context_ablation", "passes=0"], "passes=0: must be >= 1"),
])
def test_a_job_refuses_a_bad_value_when_it_is_built(overrides, named, compose):
    with pytest.raises(ConfigError) as refused:
        build_job(compose(*overrides))
    line = entry.config_error_line(refused.value)
    assert "\n" not in line and named in line, line


def test_a_bad_arm_law_is_refused_whatever_the_backend(tmp_path, compose):
    """dry_run applies no arm law, yet arm_law.kp=-5 is a config error, not a run that ignores it."""
    with pytest.raises(ConfigError, match="'arm_law'.*kp must be >= 0"):
        build_run(compose("planner=keyword", "arm_law.kp=-5"), tmp_path)


def test_web_requests_refuse_strings_for_booleans_and_integers():
    with pytest.raises(ValidationError, match="attach_camera"):
        SayRequest.model_validate({"text": "hi", "attach_camera": "yes"})
    with pytest.raises(ValidationError, match="intensity"):
        GestureRequest.model_validate({"name": "face_wave", "intensity": "3"})
    assert GestureRequest.model_validate({"name": "face_wave", "intensity": 3}).intensity == 3
    assert SayRequest.model_validate({"text": "hi", "attach_camera": True}).attach_camera


def test_an_oversized_library_file_is_refused_before_parsing(tmp_path, monkeypatch):
    folder = make_library_dir(tmp_path / "lib")
    huge = folder / "huge.yaml"
    frame = "  - [" + ", ".join(["0.1"] * 14) + "]\n"
    huge.write_text("name: huge\nclass: pointing\ndescription: too many keyframes\nkeyframes:\n"
                    + frame * 2_000)  # 130 KB: twice the cap
    parsed = []
    real_load = yaml.safe_load
    monkeypatch.setattr(yaml, "safe_load", lambda text: (parsed.append(len(text)), real_load(text))[1])
    with pytest.raises(LibraryError) as refused:
        load_library(folder)
    size = huge.stat().st_size
    assert f"{huge}: {size} bytes; a motion file is at most {MAX_FILE_BYTES}" in str(refused.value)
    assert max(parsed, default=0) <= MAX_FILE_BYTES  # the big file never reached the parser


def test_a_binary_library_file_error_names_the_file(tmp_path):
    folder = make_library_dir(tmp_path / "lib")
    (folder / "blob.yaml").write_bytes(bytes(range(256)) * 4)
    with pytest.raises(LibraryError) as refused:
        load_library(folder)
    message = str(refused.value)
    assert message.startswith(f"{folder / 'blob.yaml'}: not readable YAML ('utf-8' codec can't decode")
    assert "\n" not in message
