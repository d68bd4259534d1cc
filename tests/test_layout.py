"""The layout explains itself (docs/methods.md, "The code's layout"): no source file over 500
lines, no `too_many_arguments` allowance, no adapter matched by name outside the device profile
(crates/oit-core/src/context.rs), no import circle between the core's modules, and no two types
of one name. Reads the sources only: no GPU, no build."""

import re
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MAX_LINES = 500
CORE = ROOT / "crates" / "oit-core" / "src"


def sources(*suffixes):
    roots = [ROOT / "crates", ROOT / "python", ROOT / "shaders", ROOT / "tests", ROOT / "scripts"]
    for root in roots:
        for path in sorted(root.rglob("*")):
            if path.suffix in suffixes and path.is_file() and "snapshots" not in path.parts:
                yield path


def code_lines(path):
    """The lines of a Rust file without its comments."""
    return [line.split("//")[0] for line in path.read_text().splitlines()]


def test_no_source_file_is_over_500_lines():
    counted = ((p, len(p.read_text().splitlines())) for p in sources(".rs", ".py", ".wgsl", ".pyi"))
    long = [f"{p.relative_to(ROOT)}: {n}" for p, n in counted if n > MAX_LINES]
    assert not long, f"files over {MAX_LINES} lines (split them by what they hold):\n" + "\n".join(long)


def test_no_function_is_allowed_too_many_arguments():
    lines = ((p, i, line) for p in sources(".rs") for i, line in enumerate(p.read_text().splitlines(), 1))
    found = [f"{p.relative_to(ROOT)}:{i}" for p, i, line in lines if "too_many_arguments" in line]
    assert not found, "group the arguments into a value instead of allowing clippy::too_many_arguments:\n" + "\n".join(found)


ADAPTER_NAMES = re.compile(r'"[^"]*(llvmpipe|lavapipe|swiftshader|nvidia|radeon|intel|apple)[^"]*"', re.IGNORECASE)


def test_no_adapter_is_matched_by_name_outside_the_device_profile():
    """Adapter facts live in `DeviceProfile` (context.rs); generic code reads the profile. A name
    in an error message is fine; a name compared against is not."""
    found = []
    for path in sorted(CORE.rglob("*.rs")):
        if path.name == "context.rs":
            continue
        for i, line in enumerate(code_lines(path), 1):
            for m in ADAPTER_NAMES.finditer(line):
                if re.search(r"(contains|starts_with|ends_with|==|!=|matches!|eq_ignore_ascii_case)\s*\(?\s*$", line[: m.start()]):
                    found.append(f"{path.relative_to(ROOT)}:{i}: {line.strip()}")
    assert not found, "adapter names matched outside context.rs's DeviceProfile:\n" + "\n".join(found)


def module_of(path):
    """The module path of a core source file: method/lists.rs -> ('method', 'lists')."""
    parts = list(path.relative_to(CORE).with_suffix("").parts)
    if parts[-1] in ("mod", "lib"):
        parts = parts[:-1]
    return tuple(parts)


def imports(path):
    """The core modules `path` uses (`use crate::a::b`, `use super::x`, `crate::a::f(..)`)."""
    me = module_of(path)
    # `super` is the parent of the file's module (a mod.rs's module is its folder).
    text = "\n".join(code_lines(path))
    # `#[cfg(test)] mod tests` may reach anywhere: leave it out.
    text = text.split("#[cfg(test)]")[0]
    used = set()
    for m in re.finditer(r"\b(crate|super)((?:::[a-z_][a-z0-9_]*)+)", text):
        head = () if m.group(1) == "crate" else me[:-1]
        names = m.group(2).strip(":").split("::")
        used.add(head + tuple(names))
    # Braced groups: `use super::{a, b::C}`.
    for m in re.finditer(r"\b(crate|super)::\{([^}]*)\}", text):
        head = () if m.group(1) == "crate" else me[:-1]
        for item in m.group(2).split(","):
            item = item.strip()
            if item and item[0].islower():
                used.add(head + tuple(item.split("::")))
    return used


def resolve(target, modules):
    """The longest known module that `target` (a path of names) names or lies inside."""
    for n in range(len(target), 0, -1):
        if target[:n] in modules:
            return target[:n]
    return None


def test_no_import_circle_between_the_cores_modules():
    files = sorted(CORE.rglob("*.rs"))
    modules = {module_of(p) for p in files}
    edges = defaultdict(set)
    for path in files:
        me = module_of(path)
        for target in imports(path):
            other = resolve(target, modules)
            # A module and its ancestors or descendants are one unit: only siblings and cousins count.
            if other is None or other == me or other[: len(me)] == me or me[: len(other)] == other:
                continue
            edges[me].add(other)
    # Tarjan's strongly connected components.
    index, low, stack, on, circles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append("::".join(w))
                if w == v:
                    break
            if len(component) > 1:
                circles.append(sorted(component))

    for v in sorted(modules):
        if v not in index:
            visit(v)
    listed = "\n".join(" <-> ".join(c) for c in circles)
    assert not circles, "modules that import each other (move what they share to one of them or a third):\n" + listed


def test_no_two_types_of_one_name():
    """Within a crate (the binding's `Renderer` wraps the core's: one name on each side)."""
    seen = defaultdict(list)
    for crate in ("oit-core", "oit-py", "oit-viewer"):
        for path in sorted((ROOT / "crates" / crate / "src").rglob("*.rs")):
            text = "\n".join(code_lines(path)).split("#[cfg(test)]")[0]
            for m in re.finditer(r"^\s*(?:pub(?:\([a-z]+\))?\s+)?(?:struct|enum|trait|type)\s+([A-Z][A-Za-z0-9]*)", text, re.MULTILINE):
                seen[(crate, m.group(1))].append(str(path.relative_to(ROOT / "crates" / crate / "src")))
    twice = {name: where for name, where in seen.items() if len(where) > 1}
    assert not twice, "types of one name in several places (name each after what it holds):\n" + "\n".join(
        f"{crate} {name}: {', '.join(where)}" for (crate, name), where in sorted(twice.items())
    )


def test_a_simple_method_lives_in_four_places():
    """docs/methods.md, "Adding a method": screen_door is its file, its shader, its registry line
    and its CPU model, and no other code of the engine or its package names it (the bench's
    claims and the tests compare methods by name)."""
    places = set()
    for path in sources(".rs", ".py", ".wgsl"):
        rel = path.relative_to(ROOT).as_posix()
        if rel.startswith(("tests/", "scripts/", "python/oit/bench/")) or "/tests/" in rel:
            continue
        lines = code_lines(path) if path.suffix in (".rs", ".wgsl") else path.read_text().splitlines()
        if path.stem == "screen_door" or any("screen_door" in line for line in lines):
            places.add(rel)
    assert places == {
        "crates/oit-core/src/method/screen_door.rs",
        "crates/oit-core/src/method/mod.rs",
        "shaders/screen_door.wgsl",
        "python/oit/models.py",
    }, sorted(places)
