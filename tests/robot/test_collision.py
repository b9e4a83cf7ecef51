"""Self-collision heuristic: exact segment distances, named rejections, a clean shipped library."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

from emopose.library import MotionLibrary
from emopose.robot.collision import (
    TORSO_BOX,
    CollisionReport,
    SelfCollisionChecker,
    _box_distance_bound,
    segment_distance,
)

ROOT = Path(__file__).resolve().parents[2]
REST = np.array([0.1, 0.12, 0.0, 1.2, 0.0, 0.0, 0.0, 0.1, -0.12, 0.0, 1.2, 0.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def library() -> MotionLibrary:
    return MotionLibrary.from_config(
        paths=[str(ROOT / "library/g1")],
        limits=str(ROOT / "library/g1/limits.yaml"),
        neutral="neutral_rest",
    )


def executed_path(keyframes: np.ndarray, start: np.ndarray | None = None) -> np.ndarray:
    """Paper Eq. (smoothstep): M = 5 smoothstep waypoints per keyframe segment, then the straight
    pieces between them that the 50 Hz resampling runs along (4 samples each); `start` replaces the
    first keyframe as the robot's latest pose would."""
    anchors = np.array(keyframes, dtype=float)
    if start is not None:
        anchors[0] = start
    s = 3 * (np.arange(1, 6) / 5) ** 2 - 2 * (np.arange(1, 6) / 5) ** 3
    waypoints = [anchors[:1]] + [a + s[:, None] * (b - a) for a, b in itertools.pairwise(anchors)]
    waypoints = np.concatenate(waypoints)
    u = (np.arange(4) / 4)[None, :, None]
    pieces = waypoints[:-1, None] + u * np.diff(waypoints, axis=0)[:, None]
    return np.concatenate([pieces.reshape(-1, 14), waypoints[-1:]])


def modulated(entry, library, level: int) -> np.ndarray:
    """Paper Eq. (intensity): interior keyframes scaled about the first by a_i, clipped 0.02 rad in."""
    gain = (0.4, 0.6, 1.0, 1.3, 1.6)[level - 1]
    q = entry.q.copy()
    q[1:-1] = library.limits.project(q[0] + gain * (q[1:-1] - q[0]), 0.02)
    return q


def _brute_force(p1, q1, p2, q2, n=2001):
    """Sample segment 1 densely and project every sample exactly onto segment 2."""
    points = p1 + np.linspace(0.0, 1.0, n)[:, None] * (q1 - p1)
    d2 = q2 - p2
    t = np.clip((points - p2) @ d2 / max(d2 @ d2, 1e-20), 0.0, 1.0)
    return np.linalg.norm(points - (p2 + t[:, None] * d2), axis=1).min()


def test_segment_distance_matches_brute_force():
    rng = np.random.default_rng(0)
    p1, q1, p2, q2 = rng.normal(size=(4, 300, 3))
    q2[:60] = p2[:60] + (q1[:60] - p1[:60]) * rng.uniform(-2, 2, (60, 1))  # parallel pairs
    q2[60:90] = p2[60:90]  # segment vs point
    q1[90:100], q2[90:100] = p1[90:100], p2[90:100]  # point vs point
    exact = segment_distance(p1, q1, p2, q2)
    brute = np.array([_brute_force(*args) for args in zip(p1, q1, p2, q2)])
    assert np.all(exact <= brute + 1e-12)  # never more than any sampled pair of points
    np.testing.assert_allclose(exact, brute, atol=5e-3)  # and close to the sampled minimum


def test_box_distance_bound_is_a_tight_lower_bound():
    rng = np.random.default_rng(3)
    start = rng.uniform([-0.25, -0.3, -0.2], [0.3, 0.3, 0.45], (2000, 3)).T[:, None].astype(np.float32)
    direction = rng.normal(size=(3, 1, 2000))
    direction *= rng.uniform(0.06, 0.19, 2000) / np.linalg.norm(direction, axis=0)
    direction = direction.astype(np.float32)
    bound = _box_distance_bound(start, direction, (direction**2).sum(0))[0]
    points = start[:, 0, None] + np.linspace(0.0, 1.0, 2001)[:, None] * direction[:, 0, None]
    lo, hi = (np.array(c)[:, None, None] for c in TORSO_BOX)
    outside = points - np.clip(points, lo, hi)
    exact = np.sqrt((outside**2).sum(0)).min(axis=0)  # dense sampling: at most 0.1 mm too high
    assert np.all(bound <= exact + 1e-4)  # never optimistic
    near = exact < 0.06
    assert np.mean(exact[near] - bound[near]) < 0.002 and np.max(exact - bound) < 0.015


def test_hand_inside_torso_is_rejected_with_the_bodies_and_sample_named():
    bad = REST.copy()
    bad[7:] = [
        -0.62,
        -0.8,
        1.33,
        -0.21,
        -0.07,
        -1.24,
        0.39,
    ]  # right fingertips pushed into the chest
    samples = np.repeat(REST[None], 10, axis=0)
    samples[6] = bad
    report = SelfCollisionChecker().check(samples)
    assert isinstance(report, CollisionReport) and not report.ok
    assert "right_hand vs torso" in report.reason and "sample 6" in report.reason
    assert report.min_clearance_m < -0.02


@pytest.mark.parametrize(
    ("pose", "bodies"),
    [
        (
            {2: -1.0, 9: 1.0},
            "left_forearm vs right_forearm",
        ),  # both forearms swung through each other
        ({7: -2.8, 8: 0.3, 10: 0.3}, "right_forearm vs head"),  # right arm raised across the face
    ],
)
def test_other_collisions_are_named(pose, bodies):
    q = np.zeros(14)
    for joint, value in pose.items():
        q[joint] = value
    report = SelfCollisionChecker().check(q)
    assert not report.ok and report.reason.startswith(bodies)


def test_clearance_threshold_and_single_sample():
    gap = SelfCollisionChecker().check(REST).min_clearance_m
    assert 0.02 < gap < 0.05  # the rest pose: arms close to, but clear of, the torso
    assert SelfCollisionChecker(clearance=gap - 1e-3).check(REST).ok
    assert not SelfCollisionChecker(clearance=gap + 1e-3).check(REST).ok


def test_every_library_keyframe_and_smoothstep_path_is_collision_free(library):
    checker = SelfCollisionChecker()
    for entry in library.snapshot.entries.values():
        report = checker.check(entry.q)
        assert report.ok, f"{entry.name} keyframes: {report.reason}"
        if entry.motion_type == "sequence":
            report = checker.check(executed_path(entry.q))
            assert report.ok, f"{entry.name} path: {report.reason}"


@pytest.mark.parametrize("level", [1, 2, 4, 5])
def test_library_paths_stay_clear_at_every_intensity(library, level):
    """Intensity scales the interior excursion, so contact-like motions keep slack for level 5; the
    path is also checked from the neutral pose, where the robot usually starts."""
    checker = SelfCollisionChecker()
    rest = library.neutral_entry.q[0]
    for entry in library.snapshot.entries.values():
        if entry.motion_type == "sequence":
            q = modulated(entry, library, level)
            for start in (None, rest):
                report = checker.check(executed_path(q, start))
                assert report.ok, f"{entry.name} at intensity {level}: {report.reason}"


def test_neutral_poses_are_clean(library):
    for name in ("neutral_rest", "neutral_ready"):
        report = SelfCollisionChecker(clearance=0.02).check(library.get(name).q)
        assert report.ok, f"{name}: {report.reason}"


def test_check_is_vectorised(monkeypatch):
    """A batch is one pass through the kinematics (its time is in benchmarks/construction.py), and the
    batch verdict is the per-sample one."""
    import emopose.robot.collision as collision

    samples = np.random.default_rng(1).uniform(-0.6, 0.6, (250, 14))
    calls = []
    chain = collision.mirrored_chain
    monkeypatch.setattr(collision, "mirrored_chain", lambda *a: calls.append(a[0].shape) or chain(*a))
    gaps = SelfCollisionChecker().clearances(samples)
    assert calls == [(250, 2, 7)]
    one_by_one = np.vstack([SelfCollisionChecker().clearances(q) for q in samples[:20]])
    assert np.allclose(gaps[:20], one_by_one, atol=1e-5)
