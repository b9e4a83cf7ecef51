"""python -m emopose [+experiment=NAME] [overrides...] — the Hydra entry point."""

from __future__ import annotations

import sys

import hydra
from hydra.core.hydra_config import HydraConfig
from omegaconf import DictConfig

from emopose import app
from emopose.build import ConfigError
from emopose.config import register_resolvers
from emopose.library import LibraryError
from emopose.robot.model import ModelError

register_resolvers()


@hydra.main(config_path="../conf", config_name="config", version_base="1.3")
def main(cfg: DictConfig) -> None:
    try:
        app.run(cfg, HydraConfig.get().runtime.output_dir)
    except (ConfigError, LibraryError, ModelError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)


if __name__ == "__main__":
    main()
