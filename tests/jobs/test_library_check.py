"""+experiment=library_check: per-motion contacts, limit margins and contact sheets."""

from __future__ import annotations

import json

import pytest

from emopose.app import run
from tests.conftest import REST, write_motion
from tests.jobs.sim_helpers import RENDER_SKIP, SMALL_FRAMES, compose_config, synthetic_library

# Left shoulder pitched forward, upper arm yawed inward, forearm raised: the hand goes into the chest.
HAND_IN_CHEST = [-0.6, 0.0, -1.2, -0.5, 0, 0, 0] + REST[7:]


def test_library_check_two_g1_motions(tmp_path):
    sheets = RENDER_SKIP is None
    overrides = ["+experiment=library_check", "job.motions=[palm_stop,hands_on_heart]", "job.cameras=[front]",
                 f"job.sheets={str(sheets).lower()}", *SMALL_FRAMES]
    results = run(compose_config(overrides), tmp_path)
    assert results["motions"] == 2 and results["runs"] == 10
    saved = json.loads((tmp_path / "results.json").read_text())
    for name in ("palm_stop", "hands_on_heart"):
        motion = saved["per_motion"][name]
        assert sorted(motion["levels"]) == ["1", "2", "3", "4", "5"]
        assert motion["min_margin_rad"] > 0  # commands never reach a hard limit (projection)
        assert motion["max_force_ratio"] <= 1.0 + 1e-9
        # tracked under the G1's own law (kp 60, kd 1.5, no feed-forward): it lags and sags ~0.01-0.02 rad
        assert motion["levels"]["3"]["mae_rad"] < 0.02 and not motion["levels"]["3"]["contacts"]
        if sheets:
            assert (tmp_path / "sheets" / f"{name}.png").stat().st_size > 1000
    if sheets:
        assert (tmp_path / "sheets" / "overview.png").exists()
    assert "| palm_stop |" in (tmp_path / "results.md").read_text()


def test_library_check_reports_a_self_contact(tmp_path):
    library = synthetic_library(tmp_path / "library")
    write_motion(tmp_path / "library", "hand_in_chest", "comforting",
                 [REST, HAND_IN_CHEST, HAND_IN_CHEST, REST], duration=2.0)
    overrides = ["+experiment=library_check", "job.motions=[hand_in_chest,neutral_rest]",
                 "job.intensities=[1,3]", "job.sheets=false", *library]
    results = run(compose_config(overrides), tmp_path / "run")
    motion = results["per_motion"]["hand_in_chest"]
    assert 3 in motion["contact_levels"], motion["contact_pairs"]
    assert any("left_hand" in pair and ("chest" in pair or "abdomen" in pair)
               for pair in motion["contact_pairs"])
    contact = next(iter(motion["levels"]["3"]["contacts"].values()))
    assert 0 < contact["first_t"] <= contact["last_t"] and contact["ticks"] >= 1
    assert 3 in motion["rejected_levels"]  # the capsule heuristic refuses it before dispatch too
    assert results["with_contacts"] == {"hand_in_chest": motion["contact_levels"]}
    assert list(results["per_motion"]["neutral_rest"]["levels"]) == ["3"]  # a pose runs once


def test_library_check_needs_mujoco(tmp_path):
    with pytest.raises(ValueError, match="backend=mujoco"):
        run(compose_config(["+experiment=library_check", "backend=dry_run", "job.sheets=false",
                            *synthetic_library(tmp_path / "library")]), tmp_path / "run")
