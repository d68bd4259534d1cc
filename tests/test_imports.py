"""The import graph between oit's modules has no circle: a module never imports one that imports
it back, directly or through others. Read from the source with `ast` (imports inside functions
count too), so nothing is imported here."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "oit"


def module_names(root: Path = PACKAGE) -> dict[str, Path]:
    """Dotted name -> file of every module under python/oit (a package by its __init__.py)."""
    names = {}
    for path in sorted(root.rglob("*.py")):
        parts = ("oit", *path.relative_to(root).with_suffix("").parts)
        names[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return names


def defined(path: Path) -> set[str]:
    """The names a module binds at its top level."""
    names = set()
    for node in ast.parse(path.read_text(), str(path)).body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names}
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names |= {n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)}
    return names


def imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The oit modules that `name` imports: `from P import x` counts as P.x when that is a
    module, as nothing when x is a module without Python source (the native oit._oit), else as
    P; the parents a dotted import initializes on the way do not count."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = package.split(".")[: len(package.split(".")) - node.level + 1] if node.level else []
            source = ".".join([*base, *([node.module] if node.module else [])])
            for a in node.names:
                if f"{source}.{a.name}" in modules:
                    found.add(f"{source}.{a.name}")
                elif source not in modules or a.name in defined(modules[source]):
                    found.add(source)
    return {m for m in found if m in modules and m != name}


def import_graph() -> dict[str, set[str]]:
    modules = module_names()
    return {name: imports(name, path, modules) for name, path in modules.items()}


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One circle of the graph as [a, b, ..., a], or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return [*path[path.index(nxt):], nxt]
            if nxt not in state and (cycle := visit(nxt)):
                return cycle
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)):
            return cycle
    return None


def test_the_graph_is_read():
    graph = import_graph()
    assert "oit.bench.harness" in graph["oit.bench.results"]
    assert "oit.bench.cli" in graph["oit.cli"]  # a lazy import inside a function counts
    assert "oit._api" in graph["oit"]


def test_find_cycle_finds_one():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_module_imports_one_that_imports_it_back():
    cycle = find_cycle(import_graph())
    assert cycle is None, "import circle: " + " -> ".join(cycle)


def test_the_bench_harness_is_at_the_bottom():
    graph = import_graph()
    assert not {m for m in graph["oit.bench.harness"] if m.startswith("oit.bench")}
    for experiment in ("results", "figure7", "temporal", "auto", "antialias", "scale"):
        assert {m for m in graph[f"oit.bench.{experiment}"] if m.startswith("oit.bench")} == {"oit.bench.harness"}, experiment
