"""Inference with a trained local planner model (planners/local_model.py): thread-safe, fast encoder.

The encoder used here is a copy made once at load: bfloat16 where the CPU has native support, traced
and frozen with TorchScript when asked (a traced graph skips most of eager PyTorch's per-operator
overhead, which dominates at utterance length). The traced copy is checked against eager on a probe
and dropped, with a warning, if they disagree.
"""

from __future__ import annotations

import copy
import logging
import threading
import warnings
from collections.abc import Sequence

import numpy as np

from emopose.planners.local.heads import Analysis, boundary_scores, span_scores, variant_features
from emopose.planners.local.model import ActModel
from emopose.planners.local.segment import Segment
from emopose.planners.local.variant_score import Features

log = logging.getLogger(__name__)
_NAMES = ("input_ids", "token_type_ids", "attention_mask")


def inference_encoder(modules: list, encode, example: dict, probe: dict, bf16: bool, trace: bool):
    """inputs -> encode(copies of modules, inputs), for inference: the modules are copied, in bfloat16
    where asked and the CPU supports it, traced when asked (example: inputs to trace with; probe: inputs
    the traced copy must reproduce eager outputs on)."""
    import torch

    copies = [copy.deepcopy(m).eval() for m in modules]
    dtype = torch.bfloat16 if bf16 and torch.ops.mkldnn._is_mkldnn_bf16_supported() else torch.float32
    for module in copies:
        module.to(dtype)

    def eager(inputs: dict) -> tuple:
        return encode(copies, inputs)

    if not trace:
        return eager

    class Wrapped(torch.nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.parts = torch.nn.ModuleList(copies)

        def forward(self, input_ids, token_type_ids, attention_mask):
            return encode(list(self.parts), dict(zip(_NAMES, (input_ids, token_type_ids, attention_mask))))

    try:
        with torch.no_grad(), warnings.catch_warnings():
            warnings.simplefilter("ignore", torch.jit.TracerWarning)  # shape checks that hold for any length
            # torch.jit is deprecated for torch.compile, which needs a toolchain and minutes at load;
            # the pinned torch still ships it, and a release without it falls back to eager below.
            warnings.simplefilter("ignore", DeprecationWarning)
            traced = torch.jit.freeze(torch.jit.trace(Wrapped().eval(), tuple(example[n] for n in _NAMES),
                                                      strict=False))
            expected, got = eager(probe), traced(*(probe[n] for n in _NAMES))
    except (AttributeError, RuntimeError) as exc:
        log.warning("cannot trace the encoder (%s); using eager inference", exc)
        return eager
    tolerance = 0.1 if dtype == torch.bfloat16 else 1e-3
    if any((a.float() - b.float()).abs().max() > tolerance for a, b in zip(expected, got)):
        log.warning("traced encoder disagrees with eager PyTorch; using eager inference")
        return eager
    return lambda inputs: traced(*(inputs[n] for n in _NAMES))


EXAMPLE_TEXTS = ["A probe sentence, with a comma and more words.", "Short one."]
PROBE_TEXT = "Over there, next to the tall green cabinet!"


class LocalInference:
    """A trained ActModel's predictions for the planner: analyse texts, then score spans from the states."""

    def __init__(self, model: ActModel, bf16: bool = False, trace: bool = False) -> None:
        import torch

        self.model = model
        asked = [{"role": "assistant", "content": "Where is it?"}]
        with torch.inference_mode():
            self._encoder = inference_encoder(
                [model.body, model.sentence_top], lambda parts, inputs: model.encode(*parts, inputs),
                model.tokens(EXAMPLE_TEXTS).inputs, model.tokens([PROBE_TEXT], [asked]).inputs, bf16, trace)
        self._lock = threading.Lock()

    @property
    def config(self):
        return self.model.config

    def analyse(self, texts: list[str], histories: Sequence[Sequence[dict]] | None = None) -> list[Analysis]:
        """Each text read after its dialogue history (histories[k], may be empty); with one, the relevance
        head's logit that it bears on the text."""
        import torch

        with self._lock, torch.inference_mode():
            tokens = self.model.tokens(texts, histories)
            class_states, semantic = self._encoder(tokens.inputs)
            words, weights = self.model.words(tokens.inputs), self.model.word_weights(tokens.inputs)
            out = []
            for k, idx in enumerate(tokens.real):
                states = class_states[k, idx].float()
                anchor = self.model.anchor_head(states).squeeze(-1).numpy()
                onset = self.model.onset_head(states).squeeze(-1).numpy()
                relevance = (float(self.model.relevance_head(class_states[k, 0].float()))
                             if tokens.prefixed[k] else None)
                out.append(Analysis(tokens.starts[k], states, semantic[k, idx].float(), words[k, idx], anchor,
                                    onset, relevance, tokens.inputs["input_ids"][k, idx].numpy(),
                                    weights[k, idx]))
        return out

    def readable(self, text: str) -> bool:
        """Whether the text has any token (a zero-width space or a control character alone has none)."""
        with self._lock:  # the fast tokenizer must not be used from two threads at once
            return bool(self.model.tokenizer.tokenize(text))

    def classify_spans(self, analysis: Analysis, spans: list[tuple[int, int]]) -> tuple[np.ndarray, Features]:
        """(class logits, variant features) of character spans (planners/local_heads.py)."""
        return span_scores(self.model.act_head, self.config.logit_scale, analysis, spans)

    def boundary_logits(self, analysis: Analysis, pieces: list[Segment]) -> np.ndarray:
        return boundary_scores(self.model.boundary_head, analysis, pieces)

    def read_classes(self, texts: list[str]) -> np.ndarray:
        """(N, classes): the class head's log-probabilities of each whole text read as one act."""
        logits = np.stack([self.classify_spans(a, [(0, len(text))])[0][0]
                           for a, text in zip(self.analyse(texts), texts, strict=True)])
        return logits - np.logaddexp.reduce(logits, axis=1, keepdims=True)

    def describe(self, texts: list[str]) -> Features:
        """The variant features of whole texts (descriptions)."""
        rows = [variant_features(a, [(0, len(a.starts))]) for a in self.analyse(texts)] if texts else []
        return Features.stacked(rows, self.model.body.config.hidden_size)
