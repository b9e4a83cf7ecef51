"""python -m emopose [+experiment=NAME] [overrides...] — the Hydra entry point."""

from __future__ import annotations

import sys

import hydra
from hydra.core.hydra_config import HydraConfig
from omegaconf import DictConfig

from emopose import app
from emopose.build import ConfigError
from emopose.config import register_resolvers
from emopose.joint_limits import LibraryError
from emopose.planners.base import PlannerFailure
from emopose.robot.model import ModelError
from emopose.stop_signals import exit_status, signal_name, sigterm_interrupts

register_resolvers()


@hydra.main(config_path="../conf", config_name="config", version_base="1.3")
def main(cfg: DictConfig) -> None:
    run_dir = HydraConfig.get().runtime.output_dir
    try:
        with sigterm_interrupts():  # SIGTERM (systemd, docker stop) ends a run as cleanly as Ctrl-C
            app.run(cfg, run_dir)
    except (ConfigError, LibraryError, ModelError, PlannerFailure) as exc:
        print(f"error: {exc}", file=sys.stderr)
        sys.exit(2)
    except KeyboardInterrupt as interrupt:
        print(f"interrupted by {signal_name(interrupt)}: robot released, recording closed; "
              f"results in {run_dir}",
              file=sys.stderr)
        sys.exit(exit_status(interrupt))


if __name__ == "__main__":
    main()
