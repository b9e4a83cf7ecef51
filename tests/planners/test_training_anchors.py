"""The training sequences' anchors keep the checkable rules of experiments/train/ANCHORS.md, whose
examples are its own."""

import json
import re
from pathlib import Path

import pytest

from emopose.bench.suites import load_sequence

FILES = sorted((Path(__file__).parents[2] / "experiments" / "train").glob("train_sequences*.jsonl"))


def test_every_training_sequence_file_is_checked():
    assert len(FILES) == 6


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_training_anchors_are_ordered_exact_phrases_of_one_to_six_words(path):
    items = load_sequence(path)  # one anchor per label, exact substrings in label order (else SuiteError)
    too_long = [(item.id, anchor) for item in items for anchor in item.anchors
                if not 1 <= len(anchor.split()) <= 6]
    assert too_long == []


def test_the_guide_quotes_no_suite_anchor():
    # the annotators read the guide, never a suite item: its examples must not carry a suite's answers
    # (single words such as "Yes" or "Absolutely" are the classes' own vocabulary, not an answer)
    root = Path(__file__).parents[2] / "experiments"
    examples = set(re.findall(r'"([^"]+)"', (root / "train" / "ANCHORS.md").read_text()))
    suites = ("sequence/sequence_suite.jsonl", "speech/sync_fixture.jsonl")
    suite_anchors = {_words(anchor) for suite in suites
                     for line in (root / suite).read_text().splitlines()
                     for anchor in json.loads(line).get("anchors", [])}
    quoted = [example for example in examples if len(_words(example).split()) >= 2]
    assert len(quoted) > 30 and not [e for e in quoted if _words(e) in suite_anchors]


def _words(text: str) -> str:
    """Lower case, punctuation dropped, every run of whitespace (a quote wrapped over lines) one space."""
    return " ".join(re.sub(r"[^\w'\s]", "", text.lower()).split())
