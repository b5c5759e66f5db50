"""The package's layering, checked on its source with ``ast``: no import cycles, imports that
point down the layers only, and no import of the package's own modules inside a function."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "aerostat_gym"
#: Layers from the bottom up; a module may import from its own layer and the layers below.
LAYERS = (
    ("aerostat_gym", "aerostat_gym.params", "aerostat_gym.registration"),
    ("aerostat_gym.physics",),
    ("aerostat_gym.wind",),
    ("aerostat_gym.sim",),
    ("aerostat_gym.analysis",),
    ("aerostat_gym.envs",),
    ("aerostat_gym.agents",),
    ("aerostat_gym.bench", "aerostat_gym.scale"),
    ("aerostat_gym.cli", "aerostat_gym.__main__"),  # __main__: python -m aerostat_gym
)


def _modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _is_package(name: str) -> bool:
    return MODULES[name].name == "__init__.py"


def _resolve(module: str, node: ast.ImportFrom | ast.Import) -> list[str]:
    """Package-internal modules an import statement loads (each with its parent packages)."""
    if isinstance(node, ast.Import):
        names = [a.name for a in node.names]
    else:
        if node.level:
            base = module.split(".") if _is_package(module) else module.split(".")[:-1]
            base = base[: len(base) - node.level + 1]
            prefix = ".".join(base + ([node.module] if node.module else []))
        else:
            prefix = node.module or ""
        names = [prefix] + [f"{prefix}.{a.name}" for a in node.names]
    targets = set()
    for name in names:
        if not name.startswith("aerostat_gym"):
            continue
        parts = name.split(".")
        for k in range(1, len(parts) + 1):  # importing a.b.c runs a and a.b first
            if ".".join(parts[:k]) in MODULES:
                targets.add(".".join(parts[:k]))
    return sorted(targets)


def _ancestors(name: str) -> set[str]:
    parts = name.split(".")
    return {".".join(parts[:k]) for k in range(1, len(parts))}


def _is_type_checking(test: ast.expr) -> bool:
    """``if TYPE_CHECKING:`` or ``if typing.TYPE_CHECKING:``: a block for annotations that never
    runs."""
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _imports(module: str, source: str | None = None) -> tuple[set[str], list[str]]:
    """(internal imports run at import time, descriptions of imports inside functions). Import
    time covers every statement outside a function: the module body and anything nested in a
    ``try``, an ``if`` or a class body, not only the top-level statements; an
    ``if TYPE_CHECKING:`` body (annotations only) never runs."""
    tree = ast.parse(MODULES[module].read_text() if source is None else source)
    top, nested = set(), []

    def visit(node, function: str | None) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
                visit(child, function or getattr(child, "name", "lambda"))
            elif isinstance(child, ast.If) and _is_type_checking(child.test):
                for other in child.orelse:  # the body runs for type checkers only
                    visit(ast.Module(body=[other], type_ignores=[]), function)
            elif isinstance(child, (ast.Import, ast.ImportFrom)):
                if function is None:
                    top.update(_resolve(module, child))
                elif _resolve(module, child):
                    nested.append(f"{module}:{child.lineno} in {function}()")
            else:
                visit(child, function)

    visit(tree, None)
    # a module's own parent packages are initialised before it: not a dependency edge
    return top - _ancestors(module) - {module}, nested


GRAPH = {m: _imports(m)[0] for m in MODULES}


def _cycle() -> list[str] | None:
    """One import cycle, or None (depth-first search with colours)."""
    colour, stack = {}, []

    def visit(m):
        colour[m] = "grey"
        stack.append(m)
        for t in sorted(GRAPH[m]):
            if colour.get(t) == "grey":
                return stack[stack.index(t):] + [t]
            if t not in colour:
                found = visit(t)
                if found:
                    return found
        stack.pop()
        colour[m] = "black"
        return None

    for m in sorted(GRAPH):
        if m not in colour:
            found = visit(m)
            if found:
                return found
    return None


def _layer(module: str) -> int:
    best, rank = -1, -1
    for i, prefixes in enumerate(LAYERS):
        for p in prefixes:
            if (module == p or module.startswith(p + ".")) and len(p) > best:
                best, rank = len(p), i
    return rank


def test_the_walker_sees_the_package():
    """The graph covers the package and finds known edges (so an empty graph cannot pass)."""
    assert len(MODULES) > 50
    assert "aerostat_gym.physics.core" in GRAPH["aerostat_gym.physics.integrators"]
    assert "aerostat_gym.sim" in GRAPH["aerostat_gym.analysis.trim"]  # from ..sim import Model


def test_the_walker_sees_imports_nested_at_import_time():
    """An import in a try, an if (its else too) or a class body runs at import time and is an
    edge; one in a function, a lambda's default or an ``if TYPE_CHECKING:`` body is not (a check
    of the check)."""
    source = ("try:\n    from ..envs import env\nexcept ImportError:\n    pass\n"
              "if True:\n    from ..agents import lqr\n"
              "class C:\n    from ..sim import model\n"
              "def f():\n    from ..cli import main\n"
              "if TYPE_CHECKING:\n    from ..scale import tune\nelse:\n    from ..bench import soak\n")
    top, nested = _imports("aerostat_gym.physics.outputs", source)
    assert top == {"aerostat_gym.envs", "aerostat_gym.envs.env", "aerostat_gym.agents",
                   "aerostat_gym.agents.lqr", "aerostat_gym.sim", "aerostat_gym.sim.model",
                   "aerostat_gym.bench", "aerostat_gym.bench.soak"}
    assert nested == ["aerostat_gym.physics.outputs:10 in f()"]


def test_no_import_cycle():
    cycle = _cycle()
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_a_cycle_would_be_found():
    """The cycle finder on a graph with a known cycle (a check of the check)."""
    saved = dict(GRAPH)
    try:
        GRAPH["aerostat_gym.physics.core"] = GRAPH["aerostat_gym.physics.core"] | {
            "aerostat_gym.sim.model"}
        assert _cycle() is not None
    finally:
        GRAPH.clear()
        GRAPH.update(saved)


def test_imports_point_down_the_layers():
    bad = [f"{m} (layer {_layer(m)}) imports {t} (layer {_layer(t)})"
           for m, targets in GRAPH.items() for t in targets
           if _layer(t) > _layer(m) and t != "aerostat_gym"]
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_in_function_import_of_the_package(module):
    """Imports inside functions are for optional heavy dependencies only (SB3, torch,
    matplotlib, moordyn, ray), never for the package's own modules."""
    assert _imports(module)[1] == []
