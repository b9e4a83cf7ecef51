"""python -m emopose [+experiment=NAME] [overrides...] — the Hydra entry point.

One config-error path: an override Hydra cannot compose (an unknown key or option, bad syntax), and a
value its owner refuses when the run is built (a pydantic model or a constructor, via
emopose.build.ConfigError), end in one line on stderr naming the key and the rule, and exit status 2.

A stop signal is handled from the start: cli() installs the SIGTERM handler (emopose/stop_signals.py,
standard library only) before it imports Hydra and the run's code and composes the config, which takes
seconds on a loaded machine (hence the imports inside the functions below). SIGTERM or Ctrl-C then always
exits 143 / 130. Once main() knows the run directory, results.json says the run was interrupted (written
here if the job had not written its own yet, so a reused directory never keeps an earlier run's results);
before that, one line on stderr says that no results were written. Only the interpreter's start and
`import emopose` with this module's first lines (about 5 ms beyond the interpreter's own start; json and
logging are imported later) come before the handler; a SIGTERM there exits 143 with nothing written, and
since no run directory exists yet, nothing is lost.
"""

from __future__ import annotations

import importlib
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from emopose.stop_signals import exit_status, signal_name, stop_signals_interrupt

if TYPE_CHECKING:
    from omegaconf import DictConfig


def cli() -> None:
    """main() under Hydra with its composition errors on the one config-error path: Hydra prints them
    over 6-24 lines and exits 1, unless HYDRA_FULL_ERROR is set, when it raises them instead."""
    os.environ["HYDRA_FULL_ERROR"] = "1"
    with stop_signals_interrupt():  # SIGTERM (systemd, docker stop) ends a run as cleanly as Ctrl-C
        try:
            import hydra

            from emopose.config import CONFIG_DIR  # registers the ${root:...} resolver

            # The run's code (seconds of imports) is loaded now, before there is a run directory, so that
            # main() reaches its handler at once; there its own imports find the modules loaded.
            importlib.import_module("emopose.app")
            hydra.main(config_path=str(CONFIG_DIR), config_name="config", version_base="1.3")(main)()
        except KeyboardInterrupt as interrupt:  # main() did not know the run directory yet
            print(f"interrupted by {signal_name(interrupt)} before the run directory was chosen (imports, "
                  f"config composition): no results written", file=sys.stderr)
            sys.exit(exit_status(interrupt))
        except composition_errors() as exc:
            refuse(exc)


def main(cfg: DictConfig) -> None:
    """The task Hydra calls with the composed config: run the job in its run directory."""
    from hydra.core.hydra_config import HydraConfig

    from emopose import app
    from emopose.jobs.robot_fault import ROBOT_FAULT_EXIT, RobotFault

    run_dir = Path(HydraConfig.get().runtime.output_dir)
    earlier = results_stamp(run_dir)
    try:
        app.run(cfg, run_dir)
    except run_errors() as exc:
        refuse(exc)
    except RobotFault as fault:  # results written; one line, exit 3 (emopose/jobs/robot_fault.py)
        print(f"error: {fault}", file=sys.stderr)
        sys.exit(ROBOT_FAULT_EXIT)
    except KeyboardInterrupt as interrupt:
        stopped = f"interrupted by {signal_name(interrupt)}"
        if finished_writing(run_dir, earlier):
            print(f"{stopped}: robot released, recording closed; results in {run_dir}", file=sys.stderr)
        else:  # the signal came before app.run wrote its marker or its outcome
            app.write_unfinished(run_dir, app.name_of_job(cfg), interrupt, interrupt)
            print(f"{stopped} before the job started; results in {run_dir}", file=sys.stderr)
        sys.exit(exit_status(interrupt))


def results_stamp(run_dir: Path) -> tuple[int, int, int] | None:
    """What identifies the results.json in `run_dir` now (inode, size, mtime); None if there is none."""
    try:
        stat = (run_dir / "results.json").stat()
    except OSError:
        return None
    return stat.st_ino, stat.st_size, stat.st_mtime_ns


def finished_writing(run_dir: Path, earlier: tuple[int, int, int] | None) -> bool:
    """Whether this run replaced the `earlier` results.json with its outcome (not its in-progress marker)."""
    import json  # not at the top: the stop-signal handler comes first (see the module's docstring)

    now = results_stamp(run_dir)
    if now is None or now == earlier:
        return False
    try:
        return not json.loads((run_dir / "results.json").read_text()).get("in_progress")
    except (OSError, ValueError, AttributeError):  # cut off mid-write: not an outcome
        return False


def run_errors() -> tuple[type[BaseException], ...]:
    """Errors of a bad value found while the run is built or its input read: one line, exit 2."""
    from omegaconf.errors import OmegaConfBaseException

    from emopose.bench.suites import SuiteError
    from emopose.build import ConfigError
    from emopose.joint_limits import LibraryError
    from emopose.planners.base import PlannerFailure
    from emopose.robot.model import ModelError

    return ConfigError, LibraryError, ModelError, PlannerFailure, SuiteError, OmegaConfBaseException


def composition_errors() -> tuple[type[BaseException], ...]:
    from hydra.errors import ConfigCompositionException, OverrideParseException
    from omegaconf.errors import OmegaConfBaseException

    return ConfigCompositionException, OverrideParseException, OmegaConfBaseException


def refuse(error: Exception) -> None:
    print(f"error: {config_error_line(error)}", file=sys.stderr)
    sys.exit(2)


def config_error_line(error: Exception) -> str:
    """One line naming the key and the rule, whatever the error spread over several lines."""
    from hydra.errors import ConfigCompositionException, MissingConfigException, OverrideParseException
    from omegaconf.errors import OmegaConfBaseException

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
