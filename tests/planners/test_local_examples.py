"""A motion file's `examples:` (read by the local planner without retraining) and the probe utterances that
show which acts a new motion would take (planners/local/probes.py)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import yaml

from emopose.config import PROJECT_ROOT
from emopose.contract import LibraryEntry
from emopose.library import LibraryError, MotionLibrary
from emopose.planners.local.probes import load_probes, probe_moves, with_candidate
from tests.planners.local_helpers import configured_local_planner

SALUTE = Path(__file__).parent / "studio_motions/little_salute.yaml"


def library_with(folder: Path, examples: object) -> MotionLibrary:
    shutil.copytree(PROJECT_ROOT / "library/g1", folder)
    raw = yaml.safe_load(SALUTE.read_text()) | {"examples": examples}
    (folder / "little_salute.yaml").write_text(yaml.safe_dump(raw))
    return MotionLibrary.from_config(paths=[str(folder)], limits=str(folder / "limits.yaml"))


def test_a_motion_file_may_carry_a_few_example_utterances(tmp_path):
    library = library_with(tmp_path / "g1", ["Ahoy there, sailor!", "  At your service, commander.  "])
    assert library.get("little_salute").examples == ("Ahoy there, sailor!", "At your service, commander.")


@pytest.mark.parametrize(("examples", "problem"), [
    ("Ahoy there!", "examples: Input should be a valid tuple"),
    (["Ahoy there!", 7], "examples.1: Input should be a valid string"),
    (["ok"], "examples.0: String should have at least 3 characters"),
    (["Ahoy there!"] * 9, "examples: Tuple should have at most 8 items"),
])
def test_malformed_examples_are_one_line_naming_the_file_and_field(tmp_path, examples, problem):
    with pytest.raises(LibraryError) as error:
        library_with(tmp_path / "g1", examples)
    message = str(error.value)
    assert "little_salute.yaml" in message and problem in message and "\n" not in message


def test_the_probes_ship_with_the_library_a_few_per_class():
    probes = load_probes()
    assert set(probes) == set(LibraryEntry.model_fields["cls"].annotation.__args__)
    assert all(len(utterances) >= 3 for utterances in probes.values())


def test_a_malformed_probe_file_is_one_line_naming_it(tmp_path):
    path = tmp_path / "probes.yaml"
    path.write_text("pointing: [The door on the left., 3]\n")
    with pytest.raises(ValueError, match=r"probes\.yaml: expected a mapping from classes"):
        load_probes(path)


@pytest.fixture(scope="module")
def planner(tmp_path_factory):
    return configured_local_planner(tmp_path_factory.mktemp("lib") / "g1")


@pytest.mark.slow
def test_examples_are_evidence_next_to_the_description(planner):
    salute = LibraryEntry.model_validate(yaml.safe_load(SALUTE.read_text()))
    described_only = salute.model_copy(update={"examples": ()})
    utterance = "At your command, general."  # like an example, unlike the description
    def picked(entry):
        return [act.variant for act in with_candidate(planner, entry).acts(utterance)[1]]

    assert picked(salute) == ["little_salute"] and "little_salute" not in picked(described_only)


@pytest.mark.slow
def test_probes_tell_which_acts_a_new_motion_would_take_and_from_which(planner):
    salute = LibraryEntry.model_validate(yaml.safe_load(SALUTE.read_text()))
    assert [m for m in probe_moves(planner, salute) if m.intent != "welcoming"] == []
    probe = load_probes()["comforting"][0]
    pat = salute.model_copy(update={"name": "cheek_pat", "cls": "comforting", "examples": (probe,)})
    moves = probe_moves(planner, pat, {"comforting": (probe,)})
    before = planner.acts(probe)[1][0]
    assert [(m.utterance, m.before) for m in moves] == [(probe, before.variant)]
    assert planner.acts(probe)[1][0].variant == before.variant  # the planner itself is untouched
