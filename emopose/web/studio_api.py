"""Pose Studio's HTTP API: read the library, build and check a draft, render its preview, save it.

A draft is checked by the execution code itself (emopose.studio.authoring); a save goes through
emopose.studio.saving (name pattern, overwrite, target folder, verdict) into MotionLibrary.save, whose
reload makes the motion visible to the resolver and every planner's guide at once.
"""

from __future__ import annotations

import base64
from dataclasses import asdict

import numpy as np
from fastapi import APIRouter, HTTPException, Path, Request
from fastapi.responses import JSONResponse

from emopose import CLASSES
from emopose.contract import LibraryEntry
from emopose.library import LibraryError
from emopose.planners.local.planner import LocalPlanner
from emopose.planners.local.probes import probe_moves
from emopose.studio.authoring import DraftError, DraftReport
from emopose.studio.saving import NAME_PATTERN, SaveRefused, delete_motion, rename_motion, save_motion
from emopose.web.pose_renderer import RenderUnavailable
from emopose.web.schemas import DraftRequest, PerformRequest, PreviewRequest, RenameRequest, SaveRequest
from emopose.web.session import LiveSession
from emopose.web.stick_figure import stick_frames

router = APIRouter(prefix="/api")
STICK_EVERY = 5  # 50 Hz samples -> 10 Hz stick-figure frames


def session_of(request: Request) -> LiveSession:
    return request.app.state.session


def _round(a: np.ndarray) -> list:
    return np.round(np.asarray(a, dtype=float), 4).tolist()


@router.get("/library")
def library_index(request: Request) -> dict:
    library = session_of(request).res.library
    snapshot, limits = library.snapshot, library.limits
    entries = [{"name": e.name, "class": e.cls, "description": e.description, "motion_type": e.motion_type,
                "keyframes": len(e.keyframes), "duration": e.default_duration, "stroke": list(e.stroke_span),
                "explicit_duration": e.duration is not None} for e in snapshot.entries.values()]
    return {"version": snapshot.version, "classes": list(CLASSES), "neutral": snapshot.neutral,
            "neutral_pose": _round(library.neutral_entry.q[0]), "writable": library.write_dir is not None,
            "limits": {"names": list(limits.names), "lower": _round(limits.lower),
                       "upper": _round(limits.upper)},
            "class_defaults": snapshot.class_defaults, "entries": entries}


@router.get("/library/{name}")
def library_entry(request: Request, name: str = Path(pattern=NAME_PATTERN)) -> dict:
    entry = session_of(request).res.library.get(name)
    if entry is None:
        raise HTTPException(404, f"no motion named {name!r}")
    return entry.model_dump(mode="json", by_alias=True)


def _draft(request: Request, body: DraftRequest, cls: str = "neutral") -> tuple[LibraryEntry, DraftReport]:
    studio = session_of(request).studio
    try:
        entry = studio.draft(body.keyframes, body.motion_type, body.duration, cls, body.stroke, body.times)
    except DraftError as exc:
        raise HTTPException(422, f"draft: {exc}") from exc
    return entry, studio.report(entry, body.intensity)


def _report(request: Request, body: DraftRequest) -> DraftReport:
    return _draft(request, body)[1]


@router.post("/studio/check")
def check(body: DraftRequest, request: Request) -> dict:
    """The 50 Hz trajectory the robot would run at this intensity, and every check, before saving."""
    entry, report = _draft(request, body)
    trajectory = report.trajectory
    return {
        "intensity": report.intensity, "duration": report.duration,
        "default_duration": report.default_duration,
        "explicit_duration": report.explicit_duration, "dt": trajectory.dt, "stretch": trajectory.stretch,
        "samples": _round(trajectory.samples), "keyframes": _round(report.keyframes),
        "keyframe_times": _keyframe_times(entry, trajectory.duration, trajectory.stretch),
        "times_declared": entry.times is not None, "timing_faults": report.timing_faults,
        "stroke": list(entry.stroke_span), "stroke_declared": entry.stroke is not None,
        "keyframe_violations": report.keyframe_violations,
        "trajectory_violations": report.trajectory_violations,
        "levels": [vars(c) for c in report.levels], "problems": report.problems,
        "can_save": not report.problems, "starts": [vars(c) for c in report.starts],
        "warnings": report.warnings, "checked": report.checked, "check_ms": report.check_s * 1e3,
        "stick": stick_frames(trajectory.samples, STICK_EVERY), "stick_dt": trajectory.dt * STICK_EVERY,
    }


def _keyframe_times(entry: LibraryEntry, span: float, stretch: float) -> list[float]:
    """When the run reaches each keyframe: its own times (slowed with the run), else evenly spaced."""
    if entry.times is not None:
        return [t * stretch for t in entry.times]
    k = len(entry.keyframes)
    return [span * i / (k - 1) for i in range(k)] if k > 1 else [span]


@router.post("/studio/preview")
def preview(body: PreviewRequest, request: Request) -> dict:
    """A few MuJoCo frames of the trajectory, evenly spaced in time (stick figure when no EGL)."""
    session = session_of(request)
    report = _report(request, body)
    samples = report.trajectory.samples
    count = min(body.frames or session.settings.preview_frames, len(samples))
    index = np.unique(np.linspace(0, len(samples) - 1, count).round().astype(int))
    times = (index * report.trajectory.dt).tolist()
    if session.renderer is None or not session.renderer.available:
        return {"frames": [], "times": times, "fallback": "stick",
                "reason": "MuJoCo offscreen rendering is not available on this server"}
    try:
        jpegs = session.renderer.render_many([(samples[i], None) for i in index], body.camera)
    except RenderUnavailable as exc:
        return {"frames": [], "times": times, "fallback": "stick", "reason": str(exc)}
    frames = ["data:image/jpeg;base64," + base64.b64encode(j).decode() for j in jpegs]
    return {"frames": frames, "times": times, "camera": body.camera, "fallback": None}


@router.post("/studio/perform")
async def perform(body: PerformRequest, request: Request) -> dict:
    """Run the edited draft (not the saved motion) on the robot now; the library is not changed.
    A draft that would leave the limits or collide at this intensity is refused before it is sent."""
    entry, report = _draft(request, body, body.cls)
    refusal = report.refusal_at(body.intensity)
    if refusal is not None:
        raise HTTPException(422, f"draft not performed: {refusal}")
    return await session_of(request).perform_draft(entry, body.intensity)


@router.post("/library", status_code=201)
def save(body: SaveRequest, request: Request):
    session = session_of(request)
    try:
        result = save_motion(session.studio, body.motion(), overwrite=body.overwrite)
    except SaveRefused as exc:
        return JSONResponse({"error": str(exc)}, status_code=exc.status)
    return _saved(session, result)


@router.post("/studio/probes")
def probes(body: SaveRequest, request: Request) -> dict:
    """Before saving: which of the library's probe utterances the motion would take, and from which motion
    (the local planner reads descriptions and examples: planners/local/probes.py)."""
    session = session_of(request)
    try:
        entry = session.res.library.validate(body.motion(), source="request")
    except LibraryError as exc:
        raise HTTPException(422, str(exc)) from exc
    planner = session.res.planner
    if not isinstance(planner, LocalPlanner):
        raise HTTPException(409, f"the probes need planner=local; this server plans with {planner.name}")
    return {"name": entry.name, "class": entry.cls, "taken": [asdict(m) for m in probe_moves(planner, entry)]}


def _saved(session: LiveSession, result) -> dict:
    folder = result.file.parent.name  # shown relative to the library folder, never as an absolute path
    saved = {"name": result.entry.name, "class": result.entry.cls, "version": result.version,
             "replaced": result.replaced, "file": f"{folder}/{result.file.name}",
             "backup": None if result.backup is None else f"{folder}/.backup/{result.backup.name}"}
    session.publish({"type": "library_saved", **saved})
    return saved


@router.post("/library/{name}/rename")
def rename(body: RenameRequest, request: Request, name: str = Path(pattern=NAME_PATTERN)):
    """The motion under a new name (every save check); the old file is kept in .backup/."""
    session = session_of(request)
    try:
        return _saved(session, rename_motion(session.studio, name, body.new_name))
    except SaveRefused as exc:
        return JSONResponse({"error": str(exc)}, status_code=exc.status)


@router.post("/library/{name}/delete")
def delete(request: Request, name: str = Path(pattern=NAME_PATTERN)):
    """Remove a motion (not the rest pose, a class default or a class's last motion); a backup is kept."""
    session = session_of(request)
    library = session.res.library
    try:
        backup = delete_motion(library, name)
    except SaveRefused as exc:
        return JSONResponse({"error": str(exc)}, status_code=exc.status)
    folder = backup.parent.parent.name
    deleted = {"name": name, "version": library.version, "backup": f"{folder}/.backup/{backup.name}"}
    session.publish({"type": "library_deleted", **deleted})
    return deleted
