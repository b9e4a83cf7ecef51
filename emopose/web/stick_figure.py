"""A 2D stick figure of the 14 joint angles (forward kinematics), for when no MuJoCo frame exists.

The browser draws it (dry_run backend, or no EGL): two views in metres, torso frame. front: the
viewer faces the robot, so the robot's left arm (+y) is on the viewer's right (horizontal = +y); side:
the robot faces right (horizontal = x). Vertical is z in both.
"""

from __future__ import annotations

import numpy as np

from emopose.robot.collision import FIXED_BODIES
from emopose.robot.kinematics import arm_points, link_frames

_VIEWS = {"front": (lambda p: p[..., 1]), "side": (lambda p: p[..., 0])}


def _flat(points: np.ndarray, view: str) -> list:
    horizontal = _VIEWS[view](points)
    return np.round(np.stack([horizontal, points[..., 2]], axis=-1), 4).tolist()


def stick_figure(q: np.ndarray) -> dict:
    """{'front'|'side': {'arms': [[[h, v] x 5] x 2], 'torso': [[h, v], [h, v]], 'torso_r',
    'head': [h, v, r]}}."""
    q = np.asarray(q, dtype=float).reshape(14)
    _, pos = link_frames(q)
    chain = np.concatenate([pos[:, :1, :], arm_points(q)], axis=1)  # (2 arms, root + 4 points, 3)
    (t0, t1, torso_r), (h0, _, head_r) = FIXED_BODIES["torso"], FIXED_BODIES["head"]
    out = {}
    for view in _VIEWS:
        head = _flat(np.asarray(h0), view)
        out[view] = {"arms": _flat(chain, view), "torso": _flat(np.asarray([t0, t1]), view),
                     "torso_r": torso_r, "head": [*head, head_r]}
    return out


def stick_frames(samples: np.ndarray, every: int = 5) -> list[dict]:
    """Stick figures of every `every`-th trajectory sample (and the last), e.g. 10 Hz from 50 Hz."""
    index = list(range(0, len(samples), every))
    if index[-1] != len(samples) - 1:
        index.append(len(samples) - 1)
    return [stick_figure(samples[i]) for i in index]
