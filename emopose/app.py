"""Run one composed config: build the resources, session, runner and job, run it, always release the robot.

Every job ends here: it returns `(results, markdown)` (emopose/results.py) and run() writes
results.json / results.md and prints the markdown, while the robot is still held, so an interrupt
during the release that follows finds the results written. The run directory never shows another
run's results: run() first writes an in-progress marker, which a finished job's results replace, and a
job that never returned leaves results saying why (interrupted by a signal, or the error). An
interrupted job (Ctrl-C, or SIGTERM inside emopose.stop_signals.stop_signals_interrupt) still leaves a
complete run directory: `with run:` releases the robot and closes the MCAP recording on the way out;
a stop signal a library swallowed or wrapped ends the run as the interrupt all the same.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from emopose.build import build_job, build_run
from emopose.jobs.robot_fault import fault_failure
from emopose.resources import Run
from emopose.results import JobFailure, JobOutput, write_results
from emopose.stop_signals import interrupt_behind, signal_name, stop_requested

log = logging.getLogger(__name__)


def run(cfg: DictConfig, run_dir: str | Path) -> dict:
    run_dir = Path(run_dir)
    job_name = name_of_job(cfg)
    # Before anything else: a reused run directory must never show a previous run's results as this run's.
    write_results(run_dir, {"job": job_name, "completed": False, "in_progress": True},
                  f"# {job_name} in progress\n\nNo results yet: the run is still going, or was killed.")
    written = False
    try:
        job = build_job(cfg)
        with build_run(cfg, run_dir) as built:
            results, markdown, error = _outcome(job, built)
            write_results(run_dir, results, markdown)
            written = True
            print(markdown)
            if error is not None:
                raise error
    except BaseException as exc:
        interrupt = interrupt_behind(exc)
        if not written:
            write_unfinished(run_dir, job_name, exc, interrupt)
        if interrupt is None or interrupt is exc:
            raise
        raise interrupt from exc  # a stop signal a library wrapped (ctypes.ArgumentError) ends as itself
    interrupt = stop_requested()
    if interrupt is not None:  # a server that shut down gracefully on the signal returned: 143/130 even so
        raise interrupt
    return results


def _outcome(job: Callable[[Run], JobOutput], built: Run) -> tuple[dict, str, BaseException | None]:
    """What the job returns; a JobFailure's results and markdown with the error to raise once written."""
    try:
        results, markdown = job(built)
        return results, markdown, None
    except JobFailure as failure:
        return failure.results, failure.markdown, failure.error
    except Exception as exc:  # a robot fault is a result too (emopose/jobs/robot_fault.py)
        failure = fault_failure(built, job, exc)
        if failure is None:
            raise
        return failure.results, failure.markdown, failure.error


def name_of_job(cfg: DictConfig) -> str:
    """The job's class name, as results.json names it."""
    return str(OmegaConf.select(cfg, "job._target_") or "job").rpartition(".")[2]


def write_unfinished(run_dir: Path, job: str, error: BaseException,
                     interrupt: KeyboardInterrupt | None) -> None:
    """results.json / results.md for a job that never returned: interrupted, or failed with `error`
    (also emopose.__main__'s, for a stop signal that came before run() could write them)."""
    if interrupt is None:
        problem = " ".join(str(error).split()) or type(error).__name__
        write_results(run_dir, {"job": job, "completed": False, "error": problem},
                      f"# {job} failed\n\n{problem}")
        return
    signal = signal_name(interrupt)
    recording = run_dir / "session.mcap"
    results = {"interrupted": True, "signal": signal, "job": job, "completed": False,
               "mcap": str(recording) if recording.is_file() else None}
    write_results(run_dir, results, f"# {job} interrupted by {signal}\n\nThe robot was released and the "
                                    f"recording closed before the job finished; "
                                    f"recording: {results['mcap'] or 'none'}.")
    log.warning("%s interrupted by %s; results in %s", job, signal, run_dir)
