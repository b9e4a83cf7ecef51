"""Run one composed config: build the resources, session, runner and job, run it, always release the robot.

Every job ends here: it returns `(results, markdown)` (emopose/results.py) and run() writes
results.json / results.md and prints the markdown, while the robot is still held, so an interrupt
during the release that follows finds the results written. An interrupted job (Ctrl-C, or SIGTERM
inside emopose.stop_signals.sigterm_interrupts) still leaves a complete run directory: `with run:`
releases the robot and closes the MCAP recording on the way out, and when the job had no chance to
return its results, results.json / results.md say it was interrupted.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path

from omegaconf import DictConfig

from emopose.build import build_job, build_run
from emopose.resources import Run
from emopose.results import JobFailure, JobOutput, write_results
from emopose.stop_signals import signal_name

log = logging.getLogger(__name__)


def run(cfg: DictConfig, run_dir: str | Path) -> dict:
    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    job = build_job(cfg)
    try:
        with build_run(cfg, run_dir) as built:
            return _finish(run_dir, job, built)
    except KeyboardInterrupt as interrupt:
        if not (run_dir / "results.json").exists():
            _write_interrupted(run_dir, type(job).__name__, signal_name(interrupt))
        raise


def _finish(run_dir: Path, job: Callable[[Run], JobOutput], built: Run) -> dict:
    """Run the job, write and print what it returns; a JobFailure is written the same way, then raised."""
    error = None
    try:
        results, markdown = job(built)
    except JobFailure as failure:
        results, markdown, error = failure.results, failure.markdown, failure.error
    write_results(run_dir, results, markdown)
    print(markdown)
    if error is not None:
        raise error
    return results


def _write_interrupted(run_dir: Path, job: str, signal: str) -> None:
    recording = run_dir / "session.mcap"
    results = {"interrupted": True, "signal": signal, "job": job, "completed": False,
               "mcap": str(recording) if recording.is_file() else None}
    write_results(run_dir, results, f"# {job} interrupted by {signal}\n\nThe robot was released and the "
                                    f"recording closed before the job finished; "
                                    f"recording: {results['mcap'] or 'none'}.")
    log.warning("%s interrupted by %s; results in %s", job, signal, run_dir)
