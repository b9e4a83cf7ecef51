"""The served session's recording report, made on demand in a child process and served to the page.

The report (emopose/jobs/recording_report.py: a timeline figure per turn, loop health, joints against
their bounds, a per-turn table) reads session.mcap while the server still writes it (the flushed chunks
are recovered first). It runs in a child interpreter, never in the server's: matplotlib holds the GIL
for seconds, which would delay the 50 Hz control loop's ticks. One report at a time; the newest one's
files are served by name (only names it wrote, never a path a client chose).

    python -m emopose.web.report RECORDING OUT_DIR LIMITS_JSON     # what the server runs
"""

from __future__ import annotations

import json
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np

from emopose.config import PROJECT_ROOT
from emopose.joint_limits import JointLimits

REPORT_TIMEOUT_S = 300.0  # a long session's figures on a loaded 2-core machine; the child is killed after


class ReportUnavailable(RuntimeError):
    """No report can be made now (nothing recorded, or one is being made); the message says which."""


class ReportFailed(RuntimeError):
    """The child process failed; the message is its last line of output."""


class SessionReport:
    def __init__(self, run_dir: Path, recording: bool, limits: JointLimits) -> None:
        self.recording = (run_dir / "session.mcap").resolve() if recording else None
        self.out_dir = (run_dir / "report").resolve()
        self.limits = limits
        self._busy = threading.Lock()
        self._files: set[str] = set()  # the newest report's files, the only names served

    @property
    def command(self) -> str | None:
        """The same report from a shell, on this session's recording."""
        if self.recording is None:
            return None
        return f"python -m emopose +experiment=recording_report recording={self.recording}"

    def info(self) -> dict:
        return {"recording": None if self.recording is None else str(self.recording), "command": self.command,
                "files": sorted(self._files)}

    def make(self, timeout_s: float = REPORT_TIMEOUT_S) -> dict:
        """Run the report on the recording as it is now (blocking: call it off the event loop)."""
        if self.recording is None:
            raise ReportUnavailable("this session records nothing (run.record=false), so there is no report; "
                                    "serve with run.record=true")
        if not self._busy.acquire(blocking=False):
            raise ReportUnavailable("a report is being made: wait for it")
        try:
            limits = {"names": list(self.limits.names), "lower": self.limits.lower.tolist(),
                      "upper": self.limits.upper.tolist(), "max_velocity": self.limits.max_velocity.tolist()}
            command = [sys.executable, "-m", "emopose.web.report", str(self.recording), str(self.out_dir),
                       json.dumps(limits)]
            try:
                done = subprocess.run(command, cwd=PROJECT_ROOT, capture_output=True, text=True,
                                      timeout=timeout_s, check=False)
            except subprocess.TimeoutExpired:
                raise ReportFailed(f"the report took longer than {timeout_s:g} s and was stopped") from None
            if done.returncode != 0:
                lines = (done.stderr or done.stdout or "no output").strip().splitlines()
                raise ReportFailed(f"the report failed (exit {done.returncode}): {lines[-1][:300]}")
            self._files = {p.name for p in self.out_dir.iterdir() if p.suffix in (".png", ".md", ".json")}
            return {**self.info(), "markdown": (self.out_dir / "results.md").read_text(),
                    "figures": sorted(name for name in self._files if name.endswith(".png"))}
        finally:
            self._busy.release()

    def file(self, name: str) -> Path | None:
        """One file of the newest report, by the name it has there."""
        return self.out_dir / name if name in self._files else None


def main(argv: list[str]) -> None:
    """The child: the report's figures, results.md and results.json into OUT_DIR."""
    from emopose.jobs.recording_report import write_report  # matplotlib and the MCAP reader: child only

    recording, out_dir, limits_json = argv
    raw = json.loads(limits_json)
    limits = JointLimits(tuple(raw["names"]), *(np.asarray(raw[k], dtype=float)
                                                for k in ("lower", "upper", "max_velocity")))
    out = Path(out_dir)
    for old in out.glob("*.png") if out.is_dir() else ():  # an earlier report's figures would linger
        old.unlink()
    results, markdown = write_report(Path(recording), out, limits)
    (out / "results.json").write_text(json.dumps(results, indent=2, default=str))
    (out / "results.md").write_text(markdown)


if __name__ == "__main__":
    main(sys.argv[1:])
