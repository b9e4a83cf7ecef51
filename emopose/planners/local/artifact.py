"""The trained local planner on disk: one file per (training files' contents, TrainingConfig), cached.

`train_artifact` is the training job: `python -m emopose +experiment=train_local` runs it explicitly
(retrain=True to replace a cached file), and the planner's first use calls it when its artifact is
missing. `load_model` only loads. The library's motion descriptions supervise the variant projections
but are not part of the key: editing a description does not force a retrain.
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
ARTIFACT_VERSION = 16


def artifact_path(paths: list[str], cache_dir: str | Path, config: TrainingConfig) -> Path:
    missing = [p for p in paths if not Path(p).is_file()]
    if missing:
        raise FileNotFoundError(f"local planner training files missing: {missing} (planner.train_files)")
    digest = hashlib.sha256(f"v{ARTIFACT_VERSION}|{json.dumps(config.model_dump(), sort_keys=True)}".encode())
    for path in sorted(paths):
        digest.update(Path(path).read_bytes())
    return Path(cache_dir).expanduser() / f"local_planner_{digest.hexdigest()[:16]}.pt"


def train_artifact(paths: list[str], cache_dir: str | Path, config: TrainingConfig,
                   catalogue: dict[str, tuple[str, str]], retrain: bool = False,
                   progress: bool = True) -> Path:
    """Train on the training files (held-out slice excluded) and save. A cached artifact for the same
    files and config is returned as it is unless retrain."""
    import torch

    from emopose.planners.local.training import fit

    artifact = artifact_path(paths, cache_dir, config)
    if artifact.is_file() and not retrain:
        return artifact
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


def load_model(artifact: Path, config: TrainingConfig) -> ActModel:
    import torch

    model = ActModel(config)
    model.load_state(torch.load(artifact, weights_only=True))
    return model
