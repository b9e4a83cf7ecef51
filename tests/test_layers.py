"""The import graph points down the layers of ../shared/DESIGN.md and has no circle
(README: How it fits together).

Every `import` / `from ... import` of an emopose module anywhere in a file counts, including those inside
functions and under TYPE_CHECKING: a late import is still a dependency.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "emopose"

# Bottom to top. A module may import from its own layer or a lower one. Within "know" the order of the
# sub-layers matters too: the LLM client and speech sit below the planners, which may use both.
LAYERS: list[tuple[str, tuple[str, ...]]] = [
    ("base", ("emopose", "emopose.config", "emopose.robot", "emopose.clock", "emopose.child_process",
              "emopose.background_call",
              "emopose.recording", "emopose.recording_schemas", "emopose.recover", "emopose.results",
              "emopose.sentences", "emopose.scene")),
    ("know: contract", ("emopose.contract", "emopose.joint_limits", "emopose.library")),
    ("know: llm", ("emopose.llm",)),
    ("know: speech", ("emopose.speech",)),
    ("know: suites", ("emopose.bench",)),
    ("know: sync", ("emopose.sync",)),
    ("know: planners", ("emopose.planners",)),
    ("execute", ("emopose.execution", "emopose.backends")),
    ("turn", ("emopose.turn", "emopose.stages", "emopose.studio")),
    ("compose", ("emopose.build", "emopose.resources")),
    ("entry", ("emopose.__main__", "emopose.app", "emopose.report", "emopose.stop_signals", "emopose.jobs",
               "emopose.web", "emopose.tour", "emopose.testing")),
]


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def is_module(dotted: str) -> bool:
    path = PACKAGE.parent / dotted.replace(".", "/")
    return path.with_suffix(".py").is_file() or path.is_dir()


def imported_modules(path: Path) -> set[str]:
    """The emopose modules a file imports (`from a.b import c` counts as a.b.c when that is a module)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names if alias.name.startswith("emopose")}
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("emopose"):
            found.add(node.module)
            found |= {f"{node.module}.{a.name}" for a in node.names if is_module(f"{node.module}.{a.name}")}
    return found


def layer_of(module: str) -> int:
    """The layer of the longest matching prefix; the package itself (constants) matches only exactly."""
    best, index = "", None
    for i, (_, prefixes) in enumerate(LAYERS):
        for prefix in prefixes:
            inside = module == prefix or (prefix != "emopose" and module.startswith(prefix + "."))
            if inside and len(prefix) > len(best):
                best, index = prefix, i
    if index is None:
        raise AssertionError(f"{module} belongs to no layer: add it to LAYERS in {Path(__file__).name}")
    return index


GRAPH = {module_name(p): imported_modules(p) for p in sorted(PACKAGE.rglob("*.py"))}


def test_every_module_has_a_layer():
    for module in GRAPH:
        layer_of(module)


def test_imports_point_down():
    upward = [f"{module} ({LAYERS[layer_of(module)][0]}) -> {target} ({LAYERS[layer_of(target)][0]})"
              for module, targets in GRAPH.items() for target in sorted(targets)
              if layer_of(target) > layer_of(module)]
    assert not upward, "imports that run up the layers:\n" + "\n".join(upward)


def test_no_import_circle():
    modules = {m for m in GRAPH}
    edges = {m: {t for t in GRAPH[m] if t in modules and t != m} for m in modules}
    # A package's __init__ imported by its own modules is not a circle of modules: skip parent packages.
    edges = {m: {t for t in ts if not m.startswith(t + ".")} for m, ts in edges.items()}
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(edges[node]):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state and (cycle := visit(nxt)):
                return cycle
        stack.pop()
        state[node] = 2
        return None

    for module in sorted(modules):
        if module not in state and (cycle := visit(module)):
            pytest.fail("import circle: " + " -> ".join(cycle))
