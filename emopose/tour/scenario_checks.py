"""Whole-scenario checks that field types cannot express: names, references, reachability.

Each check returns human-readable problems naming the stop and the field, so a tour file with an
unknown target or an unreachable stop is refused before the robot moves.
"""

from __future__ import annotations

from collections import Counter
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

from emopose.scene.geometry import box_clearance, segment_clearance

if TYPE_CHECKING:
    from emopose.tour.scenario import TourSpec


def _duplicates(names: list[str]) -> list[str]:
    return sorted(n for n, count in Counter(names).items() if count > 1)


def check_names(spec: TourSpec) -> list[str]:
    problems = []
    stop_names = [s.name for s in spec.stops]
    if dup := _duplicates(stop_names):
        problems.append(f"stops: duplicate stop names {dup}")
    if dup := _duplicates([o.name for o in spec.objects]):
        problems.append(f"objects: duplicate object names {dup} (object names are unique across stops)")
    for k, name in enumerate(spec.route or ()):
        if name not in stop_names:
            problems.append(f"route[{k}] = '{name}' is not a stop; stops are {stop_names}")
    if spec.route is not None and (dup := _duplicates(list(spec.route))):
        problems.append(f"route visits {dup} twice")
    for k, stop in enumerate(spec.stops):
        objects = [o.name for o in stop.objects]
        if stop.point_at is not None and stop.point_at not in objects:
            problems.append(f"stops[{k}] '{stop.name}'.point_at = '{stop.point_at}' is not one of its "
                            f"objects {objects}")
    for k, item in enumerate(spec.interruptions):
        field, target = (("at_stop", item.at_stop) if item.at_stop is not None
                         else ("during_leg", item.during_leg))
        if target not in stop_names:
            problems.append(f"interruptions[{k}].{field} = '{target}' is not a stop; stops are {stop_names}")
        elif spec.route is not None and target not in spec.route:
            problems.append(f"interruptions[{k}].{field} = '{target}' is not on the route {list(spec.route)}")
    return problems


def check_reachable(spec: TourSpec) -> list[str]:
    """Stops inside the arena (by the robot's radius) and clear of objects; legs clear of objects."""
    problems = []
    r = spec.robot_radius_m
    (x_lo, x_hi), (y_lo, y_hi) = spec.arena.x, spec.arena.y
    if x_lo >= x_hi or y_lo >= y_hi:
        return [f"arena: bounds must be [low, high], got x={list(spec.arena.x)} y={list(spec.arena.y)}"]
    boxes = [(o.name, np.array(o.position[:2]), np.array(o.size[:2])) for o in spec.objects]
    index = {s.name: k for k, s in enumerate(spec.stops)}
    waypoints = [("start", "start", spec.start)] + [
        (f"stops[{index[s.name]}] '{s.name}'", s.name, s.pose) for s in _route(spec)]
    for where, _, pose in waypoints:
        if not (x_lo + r <= pose.x <= x_hi - r and y_lo + r <= pose.y <= y_hi - r):
            problems.append(f"{where}.pose ({pose.x:g}, {pose.y:g}) is unreachable: outside the arena "
                            f"x {list(spec.arena.x)} y {list(spec.arena.y)} less the robot radius {r:g} m")
        for name, center, half in boxes:
            if box_clearance(np.array([pose.x, pose.y]), center, half) < r:
                problems.append(f"{where}.pose ({pose.x:g}, {pose.y:g}) is blocked: within {r:g} m of "
                                f"object '{name}'")
    for (_, _, a), (where, stop, b) in pairwise(waypoints):
        for name, center, half in boxes:
            if segment_clearance([a.x, a.y], [b.x, b.y], center, half) < r:
                problems.append(f"{where}: the straight leg to '{stop}' is blocked by object '{name}' "
                                f"(passes within {r:g} m); move the stop or the object")
    return problems


def _route(spec: TourSpec):
    by_name = {s.name: s for s in spec.stops}
    return [by_name[n] for n in (spec.route or [s.name for s in spec.stops]) if n in by_name]


def check_scenario(spec: TourSpec) -> list[str]:
    problems = check_names(spec)
    return problems or check_reachable(spec)
