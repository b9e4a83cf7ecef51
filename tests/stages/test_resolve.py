from emopose.contract import GestureRecord
from emopose.stages.resolve import Resolve, resolve_record


def test_exact_name_is_global_lookup(library):
    resolved = resolve_record(GestureRecord(cls="agreeing", variant="pointing_b"), library)
    assert resolved.rule == "exact" and resolved.entry.name == "pointing_b" and not resolved.class_agrees
    assert resolved.as_json()["requested"] == "pointing_b"


def test_missing_name_falls_back_to_class_default(library):
    resolved = resolve_record(GestureRecord(cls="doubting", variant="no_such_motion"), library)
    assert resolved.rule == "class_default" and resolved.entry.name == "doubting_a"
    assert resolved.requested == "no_such_motion"


def test_empty_class_falls_back_to_neutral(tmp_path):
    from tests.conftest import REST, load_library, make_library_dir

    folder = make_library_dir(tmp_path / "lib")
    for path in folder.glob("comforting_*.yaml"):
        path.unlink()
    library = load_library(folder)
    resolved = resolve_record(GestureRecord(cls="comforting"), library)
    assert resolved.rule == "neutral" and resolved.entry.name == "neutral_rest"
    assert list(resolved.entry.q[0]) == REST


def test_confidence_gating_off_by_default_and_on_when_set(library):
    record = GestureRecord(cls="rejecting", variant="rejecting_b", confidence=0.2)
    assert Resolve(library).resolve(record).entry.name == "rejecting_b"
    gated = Resolve(library, min_confidence=0.5).resolve(record)
    assert gated.rule == "gated" and gated.entry.name == "rejecting_a"
    assert (Resolve(library, min_confidence=0.5, gate_to="neutral").resolve(record).entry.name
            == "neutral_rest")
