"""+experiment=recording_report recording=PATH: the figures and per-turn numbers of any session recording,
from the file alone. A real sync_eval run recorded on MuJoCo gives the live measurement to compare with;
a synthetic recording a known stall and a joint past its limit; a torn copy is recovered first."""

from __future__ import annotations

import json
import subprocess
import sys
from collections import Counter

import pytest

from emopose import app
from emopose.build import ConfigError, build_job
from emopose.clock import FakeClock
from emopose.config import project_path
from emopose.jobs.recording_report import write_report
from emopose.joint_limits import JointLimits
from emopose.recording import Recorder
from tests.conftest import compose_config
from tests.recording.conftest import every_message

LIMITS = project_path("library/g1/limits.yaml")


@pytest.fixture(scope="module")
def live(tmp_path_factory):
    """A recorded sync_eval item on MuJoCo: its live results and its recording's report."""
    run_dir = tmp_path_factory.mktemp("sync_eval")
    live = app.run(compose_config(["+experiment=sync_eval", "planner=keyword", "backend=mujoco",
                                   "run.record=true", "job.limit=2", "job.modes=[timeline]", "job.plots=0"]),
                   run_dir)
    report_dir = tmp_path_factory.mktemp("report")
    report = app.run(compose_config(["+experiment=recording_report",
                                     f"recording={run_dir / 'session.mcap'}"]), report_dir)
    return live, report, report_dir, run_dir / "session.mcap"


def test_the_report_writes_its_figures_and_table(live):
    _, report, report_dir, _ = live
    assert report["figures"] == ["joints.png", "loop_health.png", "turn_000.png", "turn_001.png"]
    for name in report["figures"]:
        assert (report_dir / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    table = (report_dir / "results.md").read_text()
    assert "| turn | speech start (s) | text | gestures planned |" in table
    assert all(turn["text"][:20] in table for turn in report["turns"])


def test_the_turns_match_the_live_measurement(live):
    """Planned, started, dropped and where each stroke landed: as sync_eval measured them live."""
    results, report, _, _ = live
    strokes = results["strokes"]["timeline"]
    assert len(report["turns"]) == results["items"] == 2
    items = list(dict.fromkeys(r["item"] for r in strokes))  # in the order they ran: the recorded turns
    for turn, item in zip(report["turns"], items, strict=True):
        rows = [r for r in strokes if r["item"] == item]
        assert turn["planned"] == len(rows)
        assert turn["dropped"] == sum(r["dropped"] is not None for r in rows)
        assert turn["started"] == sum(r["executed_s"] is not None for r in rows)  # all arrived, none cut
        for field, key in (("executed_s", "stroke_offsets_ms"), ("simulated_s", "simulated_offsets_ms")):
            expected = [(r[field] - r["onset_s"]) * 1e3 for r in rows]
            assert turn[key] == pytest.approx(expected, abs=0.06)


def test_the_loop_and_joints_count_every_sample(live):
    _, report, _, recording = live
    counts = Counter(topic for topic, _, _, _ in every_message(recording))
    assert report["loop"]["commands"] == counts["/joints/command"]
    assert report["loop"]["skipped_deadlines"] == 0  # a virtual-time loop driven without a stall
    assert report["joints"]["simulated"]["samples"] == counts["/joints/sim"]
    assert report["joints"]["simulated"]["samples_beyond_limits"] == 0


def test_a_stall_and_a_joint_past_its_limit_are_counted(tmp_path):
    limits = JointLimits.from_file(LIMITS)
    rest = (limits.lower + limits.upper) / 2
    with Recorder(tmp_path / "session.mcap", clock=FakeClock(), describe_robot=False) as recorder:
        ticks = [*range(50), *range(55, 100)]  # ticks 50-54 skipped: a 120 ms gap before tick 55
        for k in ticks:
            q = rest.copy()
            if k == 70:
                q[3] = limits.upper[3] + 0.1
            recorder.write("/joints/command", k * 0.02, {"q": rest.tolist()})
            recorder.write("/joints/sim", k * 0.02 + 0.02, {"q": q.tolist()})
    results, markdown = write_report(tmp_path / "session.mcap", tmp_path / "report", limits)
    loop = results["loop"]
    assert (loop["commands"], loop["gaps_over_period"], loop["skipped_deadlines"]) == (len(ticks), 1, 5)
    assert loop["max_gap_ms"] == pytest.approx(120) and loop["worst_gap_at_s"] == pytest.approx(1.1)
    sim = results["joints"]["simulated"]
    assert sim["samples_beyond_limits"] == 1 and sim["beyond_limits_max_rad"] == pytest.approx(0.1)
    assert results["turns"] == [] and "No dispatched turns" in markdown


def test_a_torn_recording_is_recovered_first(live, tmp_path):
    _, report, _, recording = live
    torn = tmp_path / "session.mcap"
    data = recording.read_bytes()
    torn.write_bytes(data[: len(data) * 3 // 4])  # as kill -9 leaves it: no footer, a chunk cut
    results, markdown = write_report(torn, tmp_path / "report", JointLimits.from_file(LIMITS))
    assert (tmp_path / "report" / "recovered.mcap").is_file() and "torn" in markdown
    assert 0 < results["recovered"]["messages"] < sum(report["channels"].values())
    assert 0 < results["loop"]["commands"] < report["loop"]["commands"]


def test_no_recording_path_is_a_config_error():
    with pytest.raises(ConfigError, match="needs recording=PATH"):
        build_job(compose_config(["+experiment=recording_report"]))


@pytest.mark.parametrize("what", ["missing", "not_mcap"])
def test_a_bad_path_is_one_line_and_exit_2(tmp_path, what):
    path = tmp_path / "session.mcap"
    if what == "not_mcap":
        path.write_text(json.dumps({"not": "an mcap"}))
    done = subprocess.run([sys.executable, "-m", "emopose", "+experiment=recording_report",
                           f"recording={path}", f"hydra.run.dir={tmp_path / 'run'}"],
                          capture_output=True, text=True)
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert ("no such file" if what == "missing" else "not an MCAP file") in done.stderr
