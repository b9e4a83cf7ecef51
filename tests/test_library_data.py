"""The shipped G1 library: names and counts from the spec, limits, timing, what motions look like."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from emopose import CLASSES
from emopose.library import MotionLibrary
from emopose.robot import kinematics as K

ROOT = Path(__file__).resolve().parents[1]
SPEC = {
    "pointing": ["point_forward_right", "point_left", "point_up", "point_to_self"],
    "emphasizing": ["beat_both_hands", "chop_right", "palms_down_press", "raised_fist_emphasis"],
    "rejecting": ["palm_stop", "cross_arms_x", "wave_off", "push_away"],
    "agreeing": ["affirm_palm_forward", "double_hand_nod", "raise_arm_yes"],
    "doubting": ["shrug", "chin_stroke", "palm_tilt_waver"],
    "welcoming": ["face_wave", "open_arms", "beckon_in", "sweep_invite"],
    "comforting": [
        "hands_on_heart",
        "gentle_pat",
        "calm_down_palms",
        "reach_out_support",
        "self_hug",
    ],
    "neutral": ["idle_breathe", "hands_clasped"],
}
POSES = ("neutral_rest", "neutral_ready")
HEAD_TOP = 0.52  # top of the collision model's head: capsule up to 0.43 m, radius 0.09 m
CHEST_FRONT = 0.075  # front of the collision model's torso box
CHIN = np.array([0.07, 0.0, 0.33])


@pytest.fixture(scope="module")
def library() -> MotionLibrary:
    return MotionLibrary.from_config(
        paths=[str(ROOT / "library/g1")],
        limits=str(ROOT / "library/g1/limits.yaml"),
        neutral="neutral_rest",
    )


def test_names_classes_and_counts_match_the_spec(library):
    entries = library.snapshot.entries
    sequences = {n: e for n, e in entries.items() if e.motion_type == "sequence"}
    assert len(sequences) == 29 and set(entries) == set(sequences) | set(POSES)
    assert [len(v) for v in SPEC.values()] == [4, 4, 4, 3, 3, 4, 5, 2] and list(SPEC) == list(CLASSES)
    for cls, names in SPEC.items():
        assert sorted(n for n, e in sequences.items() if e.cls == cls) == sorted(names)
    for name in POSES:
        assert entries[name].motion_type == "pose" and entries[name].cls == "neutral"
    for entry in entries.values():
        assert (ROOT / f"library/g1/{entry.name}.yaml").is_file()  # one file per motion, named after it
        assert "\n" not in entry.description


def test_spec_defaults_are_valid_class_defaults():
    defaults = {cls: names[0] for cls, names in SPEC.items()}
    library = MotionLibrary.from_config(
        paths=[str(ROOT / "library/g1")],
        limits=str(ROOT / "library/g1/limits.yaml"),
        class_defaults=defaults,
    )
    assert {cls: library.class_default(cls).name for cls in CLASSES} == defaults


def test_keyframes_stay_well_inside_the_limits_and_start_and_end_near_rest(library):
    limits, rest = library.limits, library.neutral_entry.q[0]
    for entry in library.snapshot.entries.values():
        assert not limits.violations(entry.q, margin=0.1), entry.name
        if entry.motion_type == "sequence":
            k = len(entry.keyframes)
            assert 3 <= k <= 14, entry.name
            interior = entry.q[1:-1]
            assert np.abs(interior - entry.q[0]).max() > 0.05, f"{entry.name} has no interior excursion"
            for boundary in (entry.q[0], entry.q[-1]):
                assert np.abs(boundary - rest).max() < 0.3, f"{entry.name} does not start/end near rest"


def test_smoothstep_speeds_stay_under_the_velocity_bounds(library):
    """Peak speed of a smoothstep segment is 1.5x its mean; every segment lasts d / (K - 1)."""
    for entry in library.snapshot.entries.values():
        if entry.motion_type == "sequence":
            segment = entry.default_duration / (len(entry.keyframes) - 1)
            peak = 1.5 * np.abs(np.diff(entry.q, axis=0)).max(axis=0) / segment
            assert np.all(peak <= library.limits.max_velocity), f"{entry.name}: {peak.round(2)}"


def _features(q: np.ndarray) -> dict[str, np.ndarray]:
    rot, pos = K.link_frames(q)
    point, palm = K.hand_axes(q)
    return {
        "tip": K.arm_points(q)[..., 3, :],
        "mid": K.hand_point(rot, pos, 0.07),
        "elbow": pos[..., 3, :],
        "point": point,
        "palm": palm,
    }


def _interior(library, name):
    q = library.get(name).q
    return [_features(frame) for frame in q[1:-1]]


def _crossing_2d(a0, a1, b0, b1):
    """Parameters (u, v) where 2D segments a0-a1 and b0-b1 cross, or None."""
    da, db, r = a1 - a0, b1 - b0, b0 - a0
    den = da[0] * db[1] - da[1] * db[0]
    u, v = (r[0] * db[1] - r[1] * db[0]) / den, (r[0] * da[1] - r[1] * da[0]) / den
    return (u, v) if 0 <= u <= 1 and 0 <= v <= 1 else None


L, R = 0, 1
SEMANTICS = {
    # name: (quantifier over interior keyframes, predicate on FK features), in the torso_link frame
    "point_up": (any, lambda f: f["tip"][R, 2] > HEAD_TOP + 0.1 and f["point"][R, 2] > 0.9),
    "point_forward_right": (
        all,
        lambda f: f["tip"][R, 0] > 0.35 and f["tip"][R, 1] < -0.25 and f["point"][R, 0] > 0.7,
    ),
    "point_left": (all, lambda f: f["tip"][L, 1] > 0.45 and f["point"][L, 1] > 0.8),
    "point_to_self": (
        any,
        lambda f: (
            f["point"][R, 0] < -0.4 and f["tip"][R, 0] < CHEST_FRONT + 0.05 and abs(f["tip"][R, 1]) < 0.1
        ),
    ),
    "face_wave": (
        all,
        lambda f: 0.35 < f["tip"][R, 2] < 0.6 and f["tip"][R, 1] < -0.2 and f["palm"][R, 0] > 0.8,
    ),
    "open_arms": (any, lambda f: f["tip"][L, 1] - f["tip"][R, 1] > 0.8),
    "hands_on_heart": (
        all,
        lambda f: np.all(
            (f["mid"][:, 0] < 0.22)
            & (np.abs(f["mid"][:, 1]) < 0.15)
            & (f["mid"][:, 2] > 0.08)
            & (f["mid"][:, 2] < 0.3)
            & (f["palm"][:, 0] < -0.7)
        ),
    ),
    "palm_stop": (all, lambda f: f["palm"][R, 0] > 0.8 and f["point"][R, 2] > 0.8),
    "push_away": (all, lambda f: np.all(f["palm"][:, 0] > 0.8)),
    "shrug": (
        all,
        lambda f: np.all(f["palm"][:, 2] > 0.8) and f["tip"][L, 1] - f["tip"][R, 1] > 0.6,
    ),
    "raise_arm_yes": (any, lambda f: f["tip"][R, 2] > HEAD_TOP + 0.1),
    "raised_fist_emphasis": (all, lambda f: f["tip"][R, 2] > 0.3),
    "chin_stroke": (
        all,  # right fingertips within 12 cm of the chin, the hand pointing up
        lambda f: np.linalg.norm(f["tip"][R] - CHIN) < 0.12 and f["point"][R, 2] > 0.8,
    ),
    "self_hug": (
        any,  # arms folded over the chest: each hand on the other side, at chest height
        lambda f: (
            f["tip"][L, 1] < -0.1
            and f["tip"][R, 1] > 0.05
            and np.all((f["tip"][:, 2] > 0.15) & (f["tip"][:, 2] < 0.3))
        ),
    ),
    "palms_down_press": (all, lambda f: np.all(f["palm"][:, 2] < -0.8)),
    "calm_down_palms": (all, lambda f: np.all(f["palm"][:, 2] < -0.8)),
    "gentle_pat": (all, lambda f: f["palm"][R, 2] < -0.8),
    "double_hand_nod": (all, lambda f: np.all(f["palm"][:, 2] > 0.8)),
    "reach_out_support": (all, lambda f: f["palm"][R, 2] > 0.8 and f["tip"][R, 0] > 0.45),
    "sweep_invite": (all, lambda f: f["palm"][R, 2] > 0.8),
    "hands_clasped": (
        all,  # fingertips together in front of the waist
        lambda f: (
            np.linalg.norm(f["tip"][L] - f["tip"][R]) < 0.13
            and np.all(np.abs(f["tip"][:, 1]) < 0.06)
            and np.all(f["tip"][:, 2] < 0.1)
        ),
    ),
}


@pytest.mark.parametrize("name", sorted(SEMANTICS))
def test_motion_looks_like_its_name(library, name):
    quantifier, predicate = SEMANTICS[name]
    assert quantifier(bool(predicate(f)) for f in _interior(library, name))


def test_cross_arms_x_forearms_cross_in_front_of_the_torso(library):
    crossed = False
    for f in _interior(library, "cross_arms_x"):
        # Frontal (y, z) view: the left elbow-to-fingertip line crosses the right one ...
        hit = _crossing_2d(f["elbow"][L, 1:], f["tip"][L, 1:], f["elbow"][R, 1:], f["tip"][R, 1:])
        if hit is None:
            continue
        left = f["elbow"][L] + hit[0] * (f["tip"][L] - f["elbow"][L])
        right = f["elbow"][R] + hit[1] * (f["tip"][R] - f["elbow"][R])
        # ... in front of the chest, with the left forearm in front of the right one.
        crossed |= right[0] > CHEST_FRONT and left[0] > right[0] + 0.05 and 0.1 < left[2] < 0.35
    assert crossed


def test_neutral_poses(library):
    rest, ready = (
        _features(library.get("neutral_rest").q[0]),
        _features(library.get("neutral_ready").q[0]),
    )
    assert np.all(rest["tip"][:, 2] < -0.15) and np.all(rest["point"][:, 2] < -0.8)  # hanging at the sides
    assert 1.0 < library.get("neutral_rest").q[0, 3] < 1.45  # slight elbow bend (straight is ~1.57)
    assert np.all(np.abs(ready["point"][:, 0]) > 0.95) and np.all(
        ready["tip"][:, 0] > 0.3
    )  # forearms forward
    assert abs(library.get("neutral_ready").q[0, 3]) < 0.2  # elbow ~90 degrees


def test_every_shipped_motion_declares_its_stroke(library):
    """Authored, not derived: each sequence says where its stroke starts and ends (library/README.md)."""
    sequences = [e for e in library.snapshot.entries.values() if e.motion_type == "sequence"]
    assert len(sequences) == 29 and all(e.stroke is not None for e in sequences)
    for entry in sequences:  # the stroke starts at a real excursion of the motion, not near its rest
        excursion = np.max(np.abs(entry.q - entry.q[0]), axis=1)
        assert excursion[entry.stroke[0]] >= 0.5 * excursion.max(), entry.name
