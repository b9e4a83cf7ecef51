"""The local planner's settings (planner.*) and training hyper-parameters (planner.training), validated
where they enter.

Their values live in one place, conf/planner/local.yaml; these models only check them, so every field
is required (a missing one is an error naming it). Every TrainingConfig field is part of the trained
artifact's cache key (planners/local/artifact.py): changing one trains a new model, the old artifact
stays on disk.
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field

from emopose.planners.local.direction import Frame

Direction = Literal["left", "right", "up", "down", "behind", "here", "there", "this", "you", "me"]


class TrainingConfig(BaseModel):
    """Strict types: a string or a float where an integer belongs is an error naming the field."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True)

    holdout_percent: int = Field(ge=0, lt=100)  # items whose id hashes into this bucket are held out
    synthetic_sequences: int = Field(ge=0)  # joined single-act items added as multi-act examples
    context_distractors: int = Field(ge=0)  # training items given an unrelated dialogue history
    epochs: int = Field(ge=1)
    trainable_layers: int = Field(ge=1, le=6)  # top encoder layers fine-tuned; the rest run once, cached
    dropout: float = Field(ge=0, lt=1)  # in the fine-tuned layers (the pretrained encoder's: 0.1)
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


def _not_nan(value: float) -> float:
    if math.isnan(value):
        raise ValueError("must be a number (-.inf keeps every history), not NaN")
    return value


FiniteWeight = Annotated[float, Field(ge=0, allow_inf_nan=False)]  # 0: the term counts nothing


class LocalSettings(BaseModel):
    """planner.* of conf/planner/local.yaml (what LocalPlanner reads); their meaning is documented there."""

    model_config = ConfigDict(frozen=True, extra="forbid", strict=True)

    train_files: list[str]
    cache_dir: str
    training: TrainingConfig
    temperature: float = Field(gt=0)  # the class logits' divisor in the split
    boundary_weight: float
    act_cost: float
    min_words: int = Field(ge=0)
    max_records: int = Field(ge=0)
    variant_word_weight: FiniteWeight
    variant_shared_weight: FiniteWeight
    variant_pretrained_share: float = Field(ge=0, le=1)
    variant_class_weight: FiniteWeight
    variant_class_weight_new: FiniteWeight
    history_threshold: Annotated[float, AfterValidator(_not_nan)]
    bf16_inference: bool
    trace_inference: bool
    pointing_directions: dict[Direction, str]  # a direction word -> the pointing motion that points so
    pointing_frame: Frame  # whose left and right (planners/local/direction.py)
    threads: Annotated[int, Field(ge=1)] | Literal["auto"]  # torch's threads; auto: the cores free at start
