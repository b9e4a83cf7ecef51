"""The local planner's training hyper-parameters, validated where they enter (planner.training).

Their values live in one place, conf/planner/local.yaml; this model only checks them, so every field
is required (a missing one is an error naming it). Every field is part of the trained artifact's cache
key (planners/local_artifact.py): changing one trains a new model, the old artifact stays on disk.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field


class TrainingConfig(BaseModel):
    """Strict types: a string or a float where an integer belongs is an error naming the field."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True)

    holdout_percent: int = Field(ge=0, lt=100)  # items whose id hashes into this bucket are held out
    synthetic_sequences: int = Field(ge=0)  # joined single-act items added as multi-act examples
    context_distractors: int = Field(ge=0)  # training items given an unrelated dialogue history
    epochs: int = Field(ge=1)
    trainable_layers: int = Field(ge=1, le=6)  # top encoder layers fine-tuned; the rest run once, cached
    lr: float = Field(ge=0)
    head_lr: float = Field(ge=0)
    lr_schedule: Literal["constant", "linear"]  # linear: warm up over 5 % of steps, then decay to 0
    batch_size: int = Field(ge=1)
    logit_scale: float = Field(gt=0)
    anchor_loss_weight: float = Field(ge=0)
    variant_epochs: int = Field(ge=0)  # the variant projections' own passes over the annotated acts
    variant_holdout: float = Field(ge=0, lt=1)  # share of a class's motions left out of each batch
    split_loss_weight: float = Field(ge=0)  # the semi-CRF likelihood of the annotated split
    relevance_loss_weight: float = Field(ge=0)  # whether a history bears on the utterance (distractors: no)
    seed: int
