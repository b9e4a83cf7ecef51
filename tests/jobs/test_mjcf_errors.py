"""A missing or broken MJCF is refused with a message naming the file, not a traceback from mujoco."""

from __future__ import annotations

import subprocess
import sys

import pytest

from emopose.app import run
from emopose.config import PROJECT_ROOT
from emopose.robot.model import ModelError, build_model
from tests.jobs.sim_helpers import compose_config, synthetic_library


@pytest.mark.parametrize("text, match", [
    (None, "does not exist"),
    ("<mujoco><worldbody><body></worldbody></mujoco>", "cannot be loaded"),
    ('<mujoco><worldbody><geom type="sphere" size="-1"/></worldbody></mujoco>',
     "cannot be loaded|does not compile"),
    ('<mujoco><worldbody><geom type="sphere" size="0.1"/></worldbody></mujoco>', "lacks the joint"),
])
def test_build_model_names_the_file(tmp_path, text, match):
    path = tmp_path / "robot.xml"
    if text is not None:
        path.write_text(text)
    with pytest.raises(ModelError, match=match) as info:
        build_model(path)
    assert str(path) in str(info.value)


def test_sim_suite_with_a_missing_model(tmp_path):
    cfg = compose_config(["+experiment=sim_suite", "trials=8",
                          f"backend.model_path={tmp_path / 'absent.xml'}",
                          *synthetic_library(tmp_path / "library")])
    with pytest.raises(ModelError, match="backend.model_path"):
        run(cfg, tmp_path / "run")


def test_cli_prints_one_line(tmp_path):
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody>")
    proc = subprocess.run([sys.executable, "-m", "emopose", "+experiment=library_check", "job.sheets=false",
                           f"backend.model_path={broken}", f"hydra.run.dir={tmp_path / 'run'}",
                           *synthetic_library(tmp_path / "library")],
                          check=False, cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert f"error: MJCF {broken} cannot be loaded" in proc.stderr and "Traceback" not in proc.stderr
