"""+experiment=recording_report recording=PATH: what any session recording shows, from the file alone.

Works on every session.mcap (plan, serve, tour, sync_eval with run.record=true) and on one that
`python -m emopose.recover` rewrote; a torn file (its writer killed, or a live session's file, whose
chunks reach the disk every 0.5 s) is recovered into the run directory first. Into the run directory go:
  turn_NNN.png      per dispatched turn (/speech/timeline): words, motion spans, trigger onsets, planned,
                    executed (command stream) and simulated strokes, measured as sync_eval does
                    (emopose/sync/recording.py read_stroke_sync);
  loop_health.png   the gap before each /joints/command and the commands per second: the recording stamps
                    each command at its deadline, so a gap over one period is skipped deadlines (a stall,
                    or idle time while nobody drove a virtual-time loop). Send lateness is not recorded:
                    the loop's own stats are quoted from the run's results.json beside the file, if any;
  joints.png        where /joints/sim exists: the simulated joints against the library's limits and speed
                    bounds (emopose/sync/joint_bounds.py);
  results.md/json   a per-turn table: text, gestures planned / started / dropped, stroke offsets.
"""

from __future__ import annotations

import json
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from emopose import CONTROL_DT
from emopose.build import ConfigError
from emopose.contract import EventKind
from emopose.joint_limits import JointLimits
from emopose.recording import read_recording
from emopose.recover import TORN, recover
from emopose.resources import Run
from emopose.results import JobOutput, markdown_table
from emopose.sync.joint_bounds import joint_bounds
from emopose.sync.plot import plot_joint_bounds, plot_loop_health, plot_recorded_turn
from emopose.sync.recording import EVENTS, TIMELINE, read_stroke_sync
from emopose.sync.strokes import stroke_summary

MCAP_MAGIC = b"\x89MCAP0\r\n"
GAP_FACTOR = 1.5  # a gap this many periods long skipped at least one deadline


@dataclass
class RecordingReportJob:
    recording: str | None = None
    turn_figures: int = 50  # the first this many turns get a timeline figure (a long serve has hundreds)

    def __post_init__(self) -> None:
        if not self.recording:
            raise ConfigError("recording_report needs recording=PATH (a session.mcap)")
        path = Path(self.recording)
        if not path.is_file():
            problem = "not a file" if path.exists() else "no such file"
            raise ConfigError(f"recording={self.recording}: {problem}")
        with path.open("rb") as f:
            if f.read(len(MCAP_MAGIC)) != MCAP_MAGIC:
                raise ConfigError(f"recording={self.recording}: not an MCAP file (it lacks the MCAP magic)")

    def __call__(self, run: Run) -> JobOutput:
        return write_report(Path(self.recording), run.resources.run_dir, run.resources.library.limits,
                            self.turn_figures)


def write_report(path: Path, out_dir: Path, limits: JointLimits, turn_figures: int = 50) -> JobOutput:
    """The figures into out_dir; (results, markdown)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    topics, readable, recovered = _read(path, out_dir)
    commands = topics.get("/joints/command", [])
    turns = _turns(readable, topics, out_dir, turn_figures, bool(commands))
    starts = [t["speech_start"] for t in turns["rows"] if t["speech_start"] is not None]
    results = {
        "recording": str(path), "recovered": recovered,
        "channels": {topic: len(rows) for topic, rows in sorted(topics.items())},
        "span_s": max((rows[-1][0] for rows in topics.values()), default=0.0),
        "turns": turns["rows"], "strokes": turns["summary"],
        "loop": _loop_health(out_dir, commands, starts),
        "loop_stats": _loop_stats(path.parent / "results.json"),
        "joints": _joints(out_dir, topics, limits),
        "figures": sorted(p.name for p in out_dir.glob("*.png")),
    }
    return results, _markdown(results)


def _read(path: Path, out_dir: Path) -> tuple[dict, Path, dict | None]:
    """The recording's topics, and the file they came from: the file itself if the official reader takes
    it, else its recovery in out_dir (a torn file)."""
    try:
        return read_recording(path), path, None
    except TORN:
        pass
    try:
        done = recover(path, out_dir / "recovered.mcap")
        return read_recording(done.out), done.out, {"into": str(done.out), "messages": done.messages}
    except TORN as exc:  # not even a torn MCAP, or not JSON messages: no emopose recording
        raise ConfigError(f"recording={path}: not a readable emopose recording ({exc})") from exc


def _turns(path: Path, topics: dict, out_dir: Path, figures: int, has_commands: bool) -> dict:
    """Per dispatched turn: its row and timeline figure; the stroke summary over every turn."""
    timelines = [message for _, message in topics.get(TIMELINE, [])]
    events = [(m["t"], m["kind"], m["command_id"]) for _, m in topics.get(EVENTS, [])]
    strokes = read_stroke_sync(path) if timelines and has_commands else []
    by_turn = defaultdict(list)
    for row in strokes:
        by_turn[row.item].append(row)
    started = {cid for _, kind, cid in events if kind == EventKind.STARTED}
    rows = []
    for number, timeline in enumerate(timelines):
        measured = {r.k: r for r in by_turn[f"turn-{number}"]}
        if number < figures and timeline["speech_start"] is not None:
            plot_recorded_turn(out_dir / f"turn_{number:03d}.png", f"turn {number}: {timeline['text']}",
                               timeline, events, [measured[g["k"]] for g in timeline["gestures"]
                                                  if g["k"] in measured])
        gestures = timeline["gestures"]
        rows.append({
            "turn": number, "speech_start": timeline["speech_start"], "text": timeline["text"],
            "planned": len(gestures),
            "started": sum(g["command_id"] in started for g in gestures if g["command_id"] is not None),
            "dropped": sum(g["dropped"] is not None for g in gestures),
            "stroke_offsets_ms": [_offset_ms(measured.get(g["k"]), "executed_s") for g in gestures],
            "simulated_offsets_ms": [_offset_ms(measured.get(g["k"]), "simulated_s") for g in gestures],
        })
    has_sim = any(r.simulated_s is not None for r in strokes)
    summary = {"command": stroke_summary(strokes)} if strokes else {}
    if has_sim:
        summary["simulated"] = stroke_summary(strokes, simulated=True)
    return {"rows": rows, "summary": summary}


def _offset_ms(row, field: str) -> float | None:
    """Where a gesture's stroke landed against its trigger word's onset (ms; None: not measured)."""
    landed = None if row is None else getattr(row, field)
    if landed is None or row.onset_s is None:
        return None
    return round((landed - row.onset_s) * 1e3, 1)


def _loop_health(out_dir: Path, commands: list, turn_starts: list[float]) -> dict:
    """Gaps between the recorded command deadlines; the figure of them over time."""
    times = np.array([m["t"] for _, m in commands], dtype=float)
    if times.size < 2:
        return {"commands": int(times.size)}
    gaps = np.diff(times)
    plot_loop_health(out_dir / "loop_health.png", times, CONTROL_DT, turn_starts)
    skipped = np.maximum(np.round(gaps / CONTROL_DT) - 1, 0)
    return {"commands": int(times.size), "span_s": float(times[-1] - times[0]), "period_ms": CONTROL_DT * 1e3,
            "gaps_over_period": int(np.sum(gaps > GAP_FACTOR * CONTROL_DT)),
            "skipped_deadlines": int(skipped.sum()), "max_gap_ms": float(gaps.max() * 1e3),
            "p99_gap_ms": float(np.percentile(gaps, 99) * 1e3),
            "worst_gap_at_s": float(times[1:][int(np.argmax(gaps))])}


def _loop_stats(results_path: Path) -> dict | None:
    """The control loop's own stats (lateness, missed deadlines) if the run wrote them (serve does)."""
    try:
        return json.loads(results_path.read_text()).get("loop")
    except (OSError, ValueError, AttributeError):
        return None


def _joints(out_dir: Path, topics: dict, limits: JointLimits) -> dict:
    """The command and simulated streams against the limits and speed bounds; the simulated one drawn."""
    found = {}
    for stream, topic in (("command", "/joints/command"), ("simulated", "/joints/sim")):
        rows = topics.get(topic, [])
        if len(rows) >= 2:
            times = np.array([m["t"] for _, m in rows], dtype=float)
            q = np.array([m["q"] for _, m in rows], dtype=float)
            found[stream] = joint_bounds(times, q, limits)
            if stream == "simulated":
                plot_joint_bounds(out_dir / "joints.png", times, q, limits)
    return found


def _numbers(values: list[float | None], form: str = "{:+.0f}") -> str:
    """Table cell: each value in `form`, '-' for a missing one."""
    return ", ".join("-" if v is None else form.format(v) for v in values) or "-"


def _markdown(results: dict) -> str:
    recovered = results["recovered"]
    source = (f"torn (its writer was killed, or is still writing): {recovered['messages']} messages "
              f"recovered into {recovered['into']}" if recovered else "complete")
    turn_rows = [[t["turn"], _numbers([t["speech_start"]], "{:.2f}"), _short(t["text"]), t["planned"],
                  t["started"], t["dropped"], _numbers(t["stroke_offsets_ms"]),
                  _numbers(t["simulated_offsets_ms"])]
                 for t in results["turns"]]
    table = markdown_table(["turn", "speech start (s)", "text", "gestures planned", "started", "dropped",
                            "stroke - onset (ms)", "simulated - onset (ms)"], turn_rows)
    loop = results["loop"]
    lines = [f"# Recording report: {results['recording']}", "",
             f"File: {source}; {sum(results['channels'].values())} messages on {len(results['channels'])} "
             f"channels over {results['span_s']:.1f} s.", "",
             "## Turns", "", table if turn_rows else "No dispatched turns (no /speech/timeline).", "",
             "Stroke offsets: where the command stream (and the simulated joints) reached each gesture's "
             "stroke, from its trigger word's onset (negative: before; '-': no onset or not reached).", "",
             "## Control loop", ""]
    if "gaps_over_period" in loop:
        lines.append(f"{loop['commands']} commands over {loop['span_s']:.1f} s; {loop['gaps_over_period']} "
                     f"gaps over one period ({loop['skipped_deadlines']} deadlines skipped; the longest "
                     f"{loop['max_gap_ms']:.0f} ms at {loop['worst_gap_at_s']:.2f} s); see loop_health.png.")
    else:
        lines.append(f"{loop['commands']} commands: nothing to measure.")
    stats = results["loop_stats"]
    told = ", ".join(f"{k} {v:.2f}" if isinstance(v, float) else f"{k} {v}" for k, v in (stats or {}).items())
    lines += ["", f"The loop's own stats (the run's results.json): {told or 'not recorded'}.", ""]
    for stream, bounds in results["joints"].items():
        lines.append(f"Joints ({stream}): {bounds['samples_beyond_limits']} samples past a limit (worst "
                     f"{bounds['beyond_limits_max_rad']:.4f} rad), speed up to "
                     f"{bounds['speed_ratio_max']:.2f}x its bound ({bounds['speed_ratio_worst_joint']}).")
    return "\n".join(lines) + "\n"


def _short(text: str, limit: int = 60) -> str:
    text = " ".join(text.split()).replace("|", "/")
    return text if len(text) <= limit else text[: limit - 3].rsplit(" ", 1)[0] + "..."
