"""Reading a tour scenario: schema validation, then the whole-scenario checks, as one clear error."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from emopose.tour.scenario import TourConfigError, TourSpec
from emopose.tour.scenario_checks import check_scenario


def _where(loc: tuple, raw: Mapping) -> str:
    """('stops', 2, 'pose', 'x') -> "stops[2] 'mocap_area'.pose.x" (the stop's name from the raw data)."""
    out, node = "", raw
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
            node = node[part] if isinstance(node, list | tuple) and part < len(node) else None
            if isinstance(node, Mapping) and isinstance(node.get("name"), str):
                out += f" '{node['name']}'"
        else:
            out += f".{part}" if out else str(part)
            node = node.get(part) if isinstance(node, Mapping) else None
    return out or "(top level)"


def parse_tour(raw: Any, origin: str = "tour config") -> TourSpec:
    """Validate a scenario mapping; `origin` names where it came from in error messages."""
    if not isinstance(raw, Mapping):
        raise TourConfigError(f"{origin}: a tour scenario must be a mapping, got {type(raw).__name__}")
    try:
        spec = TourSpec.model_validate(dict(raw))
    except ValidationError as exc:
        lines = [f"{origin}: {_where(e['loc'], raw)}: {e['msg']}" for e in exc.errors()]
        raise TourConfigError("invalid tour scenario:\n  " + "\n  ".join(lines)) from None
    problems = check_scenario(spec)
    if problems:
        raise TourConfigError("invalid tour scenario:\n  " + "\n  ".join(f"{origin}: {p}" for p in problems))
    return spec


def load_tour(path: str | Path) -> TourSpec:
    path = Path(path)
    try:
        raw = yaml.safe_load(path.read_text())
    except OSError as exc:
        raise TourConfigError(f"tour scenario {path} cannot be read ({exc.strerror})") from exc
    except yaml.YAMLError as exc:
        raise TourConfigError(f"tour scenario {path} is not valid YAML: {exc}") from exc
    return parse_tour(raw, str(path))
