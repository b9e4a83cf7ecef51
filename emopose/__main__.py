"""python -m emopose [+experiment=NAME] [overrides...] — the Hydra entry point.

One config-error path: an override Hydra cannot compose (an unknown key or option, bad syntax), and a
value its owner refuses when the run is built (a pydantic model or a constructor, via
emopose.build.ConfigError), end in one line on stderr naming the key and the rule, and exit status 2.
"""

from __future__ import annotations

import os
import sys

import hydra
from hydra.core.hydra_config import HydraConfig
from hydra.errors import ConfigCompositionException, MissingConfigException, OverrideParseException
from omegaconf import DictConfig
from omegaconf.errors import OmegaConfBaseException

from emopose import app
from emopose.build import ConfigError
from emopose.config import CONFIG_DIR, register_resolvers
from emopose.jobs.robot_fault import ROBOT_FAULT_EXIT, RobotFault
from emopose.joint_limits import LibraryError
from emopose.planners.base import PlannerFailure
from emopose.robot.model import ModelError
from emopose.stop_signals import exit_status, signal_name, stop_signals_interrupt

register_resolvers()

RUN_ERRORS = (ConfigError, LibraryError, ModelError, PlannerFailure, OmegaConfBaseException)
COMPOSITION_ERRORS = (ConfigCompositionException, OverrideParseException, OmegaConfBaseException)


@hydra.main(config_path=str(CONFIG_DIR), config_name="config", version_base="1.3")
def main(cfg: DictConfig) -> None:
    run_dir = HydraConfig.get().runtime.output_dir
    try:
        with stop_signals_interrupt():  # SIGTERM (systemd, docker stop) ends a run as cleanly as Ctrl-C
            app.run(cfg, run_dir)
    except RUN_ERRORS as exc:
        refuse(exc)
    except RobotFault as fault:  # results written; one line, exit 3 (emopose/jobs/robot_fault.py)
        print(f"error: {fault}", file=sys.stderr)
        sys.exit(ROBOT_FAULT_EXIT)
    except KeyboardInterrupt as interrupt:
        print(f"interrupted by {signal_name(interrupt)}: robot released, recording closed; "
              f"results in {run_dir}",
              file=sys.stderr)
        sys.exit(exit_status(interrupt))


def cli() -> None:
    """main() with Hydra's composition errors on the one config-error path: Hydra prints them over 6-24
    lines and exits 1, unless HYDRA_FULL_ERROR is set, when it raises them instead."""
    os.environ["HYDRA_FULL_ERROR"] = "1"
    try:
        main()
    except COMPOSITION_ERRORS as exc:
        refuse(exc)


def refuse(error: Exception) -> None:
    print(f"error: {config_error_line(error)}", file=sys.stderr)
    sys.exit(2)


def config_error_line(error: Exception) -> str:
    """One line naming the key and the rule, whatever the error spread over several lines."""
    if isinstance(error, MissingConfigException) and error.options and error.missing_cfg_file:
        group, _, option = error.missing_cfg_file.rpartition("/")
        return f"{group}={option}: no such option; {group} is one of {', '.join(error.options)}"
    if isinstance(error, OmegaConfBaseException) and error.full_key:
        return f"{error.full_key}: {error.msg}"
    text = str(error).split("Config search path:")[0]
    if isinstance(error, OverrideParseException):
        text = f"{error.override}: {text}"
    if isinstance(error, ConfigCompositionException) and isinstance(error.__cause__, OmegaConfBaseException):
        # an unknown key: Hydra's advice, then why
        text += f" ({str(error.__cause__).splitlines()[0]})"
    lines = [line.strip() for line in text.splitlines() if not line.startswith("See https://")]
    return " ".join(line for line in lines if line)


if __name__ == "__main__":
    cli()
