"""The trained local planner on disk: one file per (training files' contents, TrainingConfig), cached.

Training runs only where it is asked for: `python -m emopose +experiment=train_local` (job.retrain=true
replaces a cached file), or `train_missing_artifact`, the first-use step LocalPlanner.from_config takes
when planner.train_if_missing is true. `cached_artifact` and `load_model` only find and load. The
library's motion descriptions supervise the variant projections but are not part of the key: editing a
description does not force a retrain.
"""

from __future__ import annotations

import hashlib
import json
import logging
from pathlib import Path

from emopose.planners.local.config import TrainingConfig
from emopose.planners.local.data import load_examples
from emopose.planners.local.model import ActModel

log = logging.getLogger(__name__)
ARTIFACT_VERSION = 17


def artifact_path(paths: list[str], cache_dir: str | Path, config: TrainingConfig) -> Path:
    missing = [p for p in paths if not Path(p).is_file()]
    if missing:
        raise FileNotFoundError(f"local planner training files missing: {missing} (planner.train_files)")
    digest = hashlib.sha256(f"v{ARTIFACT_VERSION}|{json.dumps(config.model_dump(), sort_keys=True)}".encode())
    for path in sorted(paths):
        digest.update(Path(path).read_bytes())
    return Path(cache_dir).expanduser() / f"local_planner_{digest.hexdigest()[:16]}.pt"


def train_artifact(paths: list[str], cache_dir: str | Path, config: TrainingConfig,
                   catalogue: dict[str, tuple[str, str]], progress: bool = True) -> Path:
    """Train on the training files (held-out slice excluded) and save, replacing any cached file."""
    import torch

    from emopose.planners.local.training import fit

    artifact = artifact_path(paths, cache_dir, config)
    log.warning("training the local planner on %s (cached at %s)", [Path(p).name for p in paths], artifact)
    model = ActModel(config)
    examples = load_examples(paths, config.holdout_percent, synthetic=config.synthetic_sequences,
                             distractors=config.context_distractors, seed=config.seed)
    fit(model, examples, catalogue, progress)
    artifact.parent.mkdir(parents=True, exist_ok=True)
    tmp = artifact.with_suffix(".tmp")
    torch.save(model.state(), tmp)
    tmp.replace(artifact)
    return artifact


def train_missing_artifact(paths: list[str], cache_dir: str | Path, config: TrainingConfig,
                           catalogue: dict[str, tuple[str, str]]) -> Path:
    """The first-use step (planner.train_if_missing: true): train the artifact when none is cached."""
    artifact = artifact_path(paths, cache_dir, config)
    if not artifact.is_file():
        log.warning("planner.train_if_missing: no trained local planner at %s, training it before the run "
                    "(`python -m emopose +experiment=train_local` trains it ahead)", artifact)
        train_artifact(paths, cache_dir, config, catalogue)
    return artifact


def cached_artifact(paths: list[str], cache_dir: str | Path, config: TrainingConfig) -> Path:
    """The cached artifact for these files and config; none is an error saying how to train one."""
    artifact = artifact_path(paths, cache_dir, config)
    if not artifact.is_file():
        raise ValueError(f"no trained local planner at {artifact} for these training files and "
                         "planner.training: train it with `python -m emopose +experiment=train_local`, "
                         "or set planner.train_if_missing=true to train it on first use")
    return artifact


def load_model(artifact: Path, config: TrainingConfig) -> ActModel:
    import torch

    model = ActModel(config)
    model.load_state(torch.load(artifact, weights_only=True))
    return model
