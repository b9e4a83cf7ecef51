"""python -m tests.paused_start MOMENT OVERRIDES...: `python -m emopose OVERRIDES...` that pauses at one
early MOMENT of its start, so that a test can send it SIGTERM exactly there.

At the moment it writes MOMENT to the file named by $EMOPOSE_PAUSED (the marker the test waits for) and
sleeps; the stop signal interrupts the sleep as it would interrupt the real work of that moment.
"""

from __future__ import annotations

import importlib.abc
import os
import sys
import time
from pathlib import Path

from emopose.__main__ import cli

PAUSED = "EMOPOSE_PAUSED"
# In the order they happen: importing Hydra and the jobs, composing the config, main() with the run
# directory known before app.run starts, app.run building the job.
MOMENTS = ("import", "compose", "before_run", "build")


def pause(moment: str) -> None:
    Path(os.environ[PAUSED]).write_text(moment)
    time.sleep(60)  # the test's SIGTERM interrupts this
    raise AssertionError(f"no stop signal came at {moment}")


class PauseOnImport(importlib.abc.MetaPathFinder):
    """Pauses when `hydra` is first imported (cli() imports it after installing the stop handler)."""

    def find_spec(self, name, path=None, target=None):
        if name == "hydra":
            sys.meta_path.remove(self)
            pause("import")
        return None


def pause_instead(owner: object, name: str, moment: str) -> None:
    setattr(owner, name, lambda *args, **kwargs: pause(moment))


def arm(moment: str) -> None:
    if moment == "import":
        assert "hydra" not in sys.modules, "hydra was imported before cli() ran"
        sys.meta_path.insert(0, PauseOnImport())
        return
    if moment == "compose":
        from hydra._internal.config_loader_impl import ConfigLoaderImpl

        pause_instead(ConfigLoaderImpl, "load_configuration", moment)
        return
    from emopose import app

    pause_instead(app, {"before_run": "run", "build": "build_job"}[moment], moment)


if __name__ == "__main__":
    arm(sys.argv[1])
    sys.argv = ["emopose", *sys.argv[2:]]
    cli()
