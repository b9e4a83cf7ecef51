"""Suite loading: malformed files are refused with file, line and field named."""

import json
from pathlib import Path

import pytest

from emopose.bench.suites import SuiteError, anchor_spans, load_bench, load_context, load_sequence

FIXTURES = Path(__file__).parent / "fixtures"
GOOD_BENCH = {"id": "b1", "text": "Look over there.", "label": "pointing", "tier": "easy"}
GOOD_CONTEXT = {"id": "c1", "history": [{"role": "user", "content": "Where?"}], "text": "There.",
                "label": "pointing"}
GOOD_SEQ = {"id": "s1", "text": "Welcome! Look over there.", "labels": ["welcoming", "pointing"],
            "anchors": ["Welcome", "over there"], "variants": ["face_wave", "point_left"]}
VARIANT_CLASSES = {"face_wave": "welcoming", "point_left": "pointing", "shrug": "doubting"}


def write(tmp_path: Path, *lines) -> Path:
    path = tmp_path / "suite.jsonl"
    path.write_text("\n".join(line if isinstance(line, str) else json.dumps(line) for line in lines) + "\n")
    return path


def refused(loader, path, line, field, *words, **kwargs):
    with pytest.raises(SuiteError) as info:
        loader(path, **kwargs)
    message = str(info.value)
    assert message.startswith(f"{path}:{line}"), message
    if field:
        assert f"field '{field}'" in message, message
    for word in words:
        assert word in message, message
    return message


def test_fixtures_load():
    assert len(load_bench(FIXTURES / "bench_small.jsonl")) == 24
    assert len(load_bench(FIXTURES / "bench_small.jsonl", tiers=["hard"])) == 8
    assert len(load_context(FIXTURES / "context_small.jsonl")) == 8
    assert [len(i.labels) for i in load_sequence(FIXTURES / "sequence_small.jsonl")] == [2, 2, 3, 3, 4, 4]


def test_bad_json_names_line(tmp_path):
    path = write(tmp_path, GOOD_BENCH, '{"id": "b2", "text": "oops"')
    refused(load_bench, path, 2, None, "not valid JSON")


def test_unknown_label_and_tier(tmp_path):
    refused(load_bench, write(tmp_path, {**GOOD_BENCH, "label": "happy"}), 1, "label", "'happy'", "allowed")
    refused(load_bench, write(tmp_path, {**GOOD_BENCH, "tier": "expert"}), 1, "tier", "easy, medium, hard")


def test_missing_field_and_duplicate_id(tmp_path):
    missing = {k: v for k, v in GOOD_BENCH.items() if k != "text"}
    refused(load_bench, write(tmp_path, GOOD_BENCH, missing | {"id": "b2"}), 2, "text", "missing")
    refused(load_bench, write(tmp_path, GOOD_BENCH, "", GOOD_BENCH), 3, "id", "duplicate")


def test_not_an_object(tmp_path):
    refused(load_bench, write(tmp_path, '["a", "b"]'), 1, None, "JSON object")


def test_context_history_is_checked(tmp_path):
    assert load_context(write(tmp_path, GOOD_CONTEXT))[0].history[0]["role"] == "user"
    bad = {**GOOD_CONTEXT, "history": [{"role": "robot", "content": "hi"}]}
    refused(load_context, write(tmp_path, bad), 1, "history[0]", "role")
    refused(load_context, write(tmp_path, {**GOOD_CONTEXT, "history": "hi"}), 1, "history")


def test_sequence_anchor_not_in_text(tmp_path):
    refused(load_sequence, write(tmp_path, {**GOOD_SEQ, "anchors": ["Welcome", "over here"]}), 1, "anchors",
            "'over here'", "substring")


def test_sync_eval_keeps_an_anchor_missing_from_the_text_for_its_say_do_check(tmp_path):
    path = write(tmp_path, {**GOOD_SEQ, "anchors": ["Welcome", "over here"]})
    (item,) = load_sequence(path, anchors_in_text=False)
    assert item.anchors == ("Welcome", "over here")
    refused(load_sequence, write(tmp_path, {**GOOD_SEQ, "anchors": ["Welcome"]}), 1, "anchors",
            "equal lengths", anchors_in_text=False)  # every other check still applies


def test_a_sequence_item_as_a_scripted_plan():
    item = load_sequence(FIXTURES / "sequence_small.jsonl")[0]
    plan = item.plan()
    assert plan.reply == item.text and plan.source == "scripted"
    assert [(r.cls, r.trigger, r.variant) for r in plan.records] == list(zip(item.labels, item.anchors,
                                                                             item.variants))


def test_sequence_anchors_out_of_order(tmp_path):
    refused(load_sequence, write(tmp_path, {**GOOD_SEQ, "anchors": ["over there", "Welcome"]}), 1, "anchors")


def test_sequence_wrong_lengths(tmp_path):
    refused(load_sequence, write(tmp_path, {**GOOD_SEQ, "variants": ["face_wave"]}), 1, "anchors",
            "equal lengths", "2, 2, 1")


def test_sequence_unknown_label_and_variant(tmp_path):
    refused(load_sequence, write(tmp_path, {**GOOD_SEQ, "labels": ["welcoming", "pointy"]}), 1, "labels[1]")
    unknown = {**GOOD_SEQ, "variants": ["face_wave", "point_down"]}
    refused(load_sequence, write(tmp_path, unknown), 1, "variants[1]", "not a motion",
            variant_classes=VARIANT_CLASSES)
    wrong_class = {**GOOD_SEQ, "variants": ["shrug", "point_left"]}
    refused(load_sequence, write(tmp_path, wrong_class), 1, "variants[0]", "doubting",
            variant_classes=VARIANT_CLASSES)
    item = load_sequence(write(tmp_path, GOOD_SEQ), variant_classes=VARIANT_CLASSES)[0]
    assert item.spans == [(0, 7), (14, 24)]


def test_anchor_spans_sequential():
    assert anchor_spans("no, no, no", ["no", "no", "no"]) == [(0, 2), (4, 6), (8, 10)]
    with pytest.raises(ValueError, match=r"anchors\[1\]"):
        anchor_spans("no, yes", ["yes", "no"])


def test_missing_file_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="bench.path"):
        load_bench(tmp_path / "nope.jsonl")
