"""The docs say what is true now: every code pointer in docs/*.md and README.md names something
that exists, and every bench command docs/results.md prints above a table is one the bench's
command line accepts.

Pointers checked (each failure lists every stale pointer at once, with its file and line):
- a path to a source file (`crates/.../x.rs`, `shaders/x.wgsl`, `python/oit/x.py`, `tests/x.py`,
  `scripts/x.sh`, or a tail such as `renderer/execute.rs`): some file of the repository has it;
- `file.rs:NN` or `file.rs:NN-MM`: the file has at least that many lines;
- a symbol named with its file: `` `file.rs` `Name` ``, `` `file.rs`'s `Name` ``,
  `` `Name` (file.rs) `` or `` `Name` in `file.rs` ``: the name occurs in that file;
- a Rust path `` `a::b::Name` `` whose head is this project's (a crate, a module file or a type
  defined in crates/): its last name is defined in crates/;
- a backticked CamelCase name (`MethodInfo`, `AccumTargets`): defined in crates/ or python/,
  unless it is a peer's (pygfx, VTK, wgpu, numpy) listed in EXTERNAL;
- a Python path `` `oit.module.name` ``: the module exists under python/oit and defines the name;
- a section pointer `docs/x.md, "Heading"`: docs/x.md has a heading that starts with it.
"""

from __future__ import annotations

import argparse
import functools
import re
import shlex
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
DOCS = [*sorted((REPO / "docs").glob("*.md")), REPO / "README.md"]
SKIP_DIRS = {".git", ".venv", "target", "out", "node_modules", "__pycache__", ".gpu", "shared"}

# Names of other libraries and tools the docs cite (not this project's code).
EXTERNAL = {
    "MeshPhongMaterial", "MeshBasicMaterial", "MeshStandardMaterial", "WgpuRenderer", "PolyData",
    "SetUseDepthPeeling", "SetUseOIT", "SetMaximumNumberOfPeels", "GetLastRenderingUsedDepthPeeling",
    "ForceOpaque", "SetExplicitProjectionTransformMatrix", "SetUseExplicitProjectionTransformMatrix",
    "VtkRenderer", "TypeError", "ValueError", "OSError", "MemoryError", "RuntimeError", "IndexError",
    "KeyError", "NotImplementedError", "PyErr", "OitError", "GpuContext", "BindGroupLayoutEntries",
    "BindGroupEntries", "SpecializedRenderPipeline", "OitResolvePipelineKey", "GpuRenderPipelinePool",
    "RenderPipelineDesc", "ShaderType", "TextureFormat", "CommandEncoder", "RenderPass", "ComputePass",
    "PyVista", "PyO3", "WebGPU", "OpenGL", "FreeType", "NumPy", "GitHub", "LaTeX", "JavaScript",
    "TrueType", "DirectX", "MacOS", "LightType", "AlphaBlendModeTest", "CesiumMilkTruck",
    "SpecGloss", "KhronosGroup", "BoxTextured", "MetalRoughSpheres", "TextureCoordinateTest",
    "TextureSettingsTest", "TextureTransformTest", "DamagedHelmet", "WaterBottle", "BoomBox",
}


@functools.cache
def repo_files() -> tuple[str, ...]:
    """Every file of the working tree, as a path relative to the repository."""
    out = []
    for path in REPO.rglob("*"):
        rel = path.relative_to(REPO)
        if rel.parts and (rel.parts[0] in SKIP_DIRS or any(p in SKIP_DIRS for p in rel.parts)):
            continue
        if path.is_file():
            out.append(rel.as_posix())
    return tuple(sorted(out))


def find(pointer: str) -> list[str]:
    """The repository files a pointer names: the path itself, or every file ending in it."""
    pointer = pointer.strip("./")
    if (REPO / pointer).is_file():
        return [pointer]
    if pointer.startswith("oit/") and (REPO / "python" / pointer).is_file():
        return ["python/" + pointer]
    return [f for f in repo_files() if f.endswith("/" + pointer)]


@functools.cache
def text(rel: str) -> str:
    return (REPO / rel).read_text(errors="replace")


@functools.cache
def code_text(root: str, exts: tuple[str, ...]) -> str:
    return "\n".join(text(f) for f in repo_files() if f.startswith(root) and f.endswith(exts))


def defined_in_code(name: str) -> bool:
    """The name is defined (a type, function, constant, field or variant) in crates/ or python/."""
    word = re.compile(rf"\b{re.escape(name)}\b")
    return bool(word.search(code_text("crates/", (".rs",))) or word.search(code_text("python/", (".py", ".pyi")))
                or word.search(code_text("shaders/", (".wgsl",))))


def doc_lines(src: str):
    """(line number, line without URLs, whether it is inside a fenced block) of a doc."""
    fenced = False
    for n, line in enumerate(src.splitlines(), 1):
        if line.startswith("```"):
            fenced = not fenced
            continue
        yield n, re.sub(r"https?://\S+", "", line), fenced


PATH = re.compile(r"(?<![\w/.-])((?:[\w.-]+/)+[\w.-]+\.(?:rs|wgsl|py|pyi|sh|toml|json|npz|md|png))(?::(\d+)(?:-(\d+))?)?")
BARE = re.compile(r"(?<![\w/.-])([\w-]+\.(?:rs|wgsl))(?::(\d+)(?:-(\d+))?)?\b")
FILE_THEN_NAME = re.compile(r"`?([\w/.-]+\.(?:rs|wgsl|py))`?(?:'s)?[,:]? \(?`(\w+)(?:\(\))?`")
NAME_THEN_FILE = re.compile(r"`(\w+)(?:\(\))?` (?:\(|in `?|of `?)([\w/.-]+\.(?:rs|wgsl|py))")
RUST_PATH = re.compile(r"`((?:\w+::)+\w+)(?:\(\))?`")
CAMEL = re.compile(r"`([A-Z][a-z0-9]+(?:[A-Z][a-z0-9]*)+)`")
PY_PATH = re.compile(r"`(oit(?:\.\w+)+)(?:\(|`)")
SECTION = re.compile(r"docs/(\w[\w-]*\.md),?\s+\(?\"([^\"]+)\"")


def headings(rel: str) -> list[str]:
    """A doc's headings, and the bold words that open a paragraph or an item (`**Sampling** ...`)."""
    src = text(rel)
    return ([re.sub(r"^#+\s*", "", h).strip() for h in re.findall(r"^#+ .*$", src, flags=re.M)]
            + re.findall(r"^(?:[-\d.]+ )?\*\*([^*]+)\*\*", src, flags=re.M))


def rust_name_defined(path: str) -> bool:
    parts = path.split("::")
    crates = {"oit_core", "oit_py", "oit_viewer", "crate", "self", "super"}
    head = parts[0]
    name = parts[-1]
    ours = (head in crates or find(f"{head}.rs") or find(f"{head}/mod.rs")
            or re.search(rf"\b(?:struct|enum|trait|type|mod)\s+{re.escape(head)}\b", code_text("crates/", (".rs",))))
    if not ours:
        return True  # another library's path (vtk, wgpu): not ours to check
    if len(parts) >= 2 and parts[-2][0].islower() and parts[-2] not in crates:
        files = find(f"{parts[-2]}.rs") + find(f"{parts[-2]}/mod.rs")
        if files:
            module_dir = [f for f in repo_files() if f.startswith(tuple(f[:-3] + "/" if not f.endswith("mod.rs")
                                                                         else f[:-6] for f in files))]
            return any(re.search(rf"\b{re.escape(name)}\b", text(f)) for f in files + module_dir)
    return bool(re.search(rf"\b{re.escape(name)}\b", code_text("crates/", (".rs",))))


def python_name_defined(dotted: str) -> bool:
    parts = dotted.split(".")
    # The longest prefix that is a module of python/oit.
    for i in range(len(parts), 0, -1):
        base = REPO / "python" / Path(*parts[:i])
        module = base.with_suffix(".py") if base.with_suffix(".py").is_file() else base / "__init__.py"
        if module.is_file():
            rest = parts[i:]
            if not rest:
                return True
            src = module.read_text()
            if i == 1:  # oit.X: what the package exports, from any of its modules
                src += code_text("python/oit/", (".py", ".pyi"))
            return bool(re.search(rf"\b{re.escape(rest[0])}\b", src))
    return False


def stale_pointers() -> list[str]:
    """Every stale pointer of docs/*.md and README.md, as `file:line: what`."""
    return [p for doc in DOCS for p in problems_in(doc.relative_to(REPO).as_posix(), doc.read_text())]


def problems_in(rel_doc: str, src: str) -> list[str]:
    """The stale pointers of one doc, `rel_doc` being its path in messages."""
    problems: list[str] = []
    for n, line, fenced in doc_lines(src):
        where = f"{rel_doc}:{n}"
        spans = []
        for m in PATH.finditer(line):
            spans.append(m.span(1))
            pointer, first, last = m.group(1), m.group(2), m.group(3)
            if pointer.startswith(("out/", "../", ".gpu/")) or "<" in pointer or "*" in pointer:
                continue
            if fenced and re.match(r"[ab]/", pointer):
                pointer = pointer[2:]  # a diff's a/ and b/ sides
            files = find(pointer)
            if not files:
                problems.append(f"{where}: no file {pointer}")
            elif first:
                lines = max(len(text(f).splitlines()) for f in files)
                need = int(last or first)
                if lines < need:
                    problems.append(f"{where}: {pointer}:{first}{'-' + last if last else ''} but the file has {lines} lines")
        if fenced:
            continue
        for m in BARE.finditer(line):
            if any(a <= m.start(1) < b for a, b in spans):
                continue
            pointer, first, last = m.group(1), m.group(2), m.group(3)
            files = find(pointer)
            if not files:
                problems.append(f"{where}: no file {pointer}")
            elif first:
                lines = max(len(text(f).splitlines()) for f in files)
                if lines < int(last or first):
                    problems.append(f"{where}: {pointer}:{first} but the file has {lines} lines")
        for pattern, order in ((FILE_THEN_NAME, (1, 2)), (NAME_THEN_FILE, (2, 1))):
            for m in pattern.finditer(line):
                pointer, name = m.group(order[0]), m.group(order[1])
                files = find(pointer)
                if files and not any(re.search(rf"\b{re.escape(name)}\b", text(f)) for f in files):
                    problems.append(f"{where}: `{name}` is not in {pointer}")
        for m in RUST_PATH.finditer(line):
            if not rust_name_defined(m.group(1)):
                problems.append(f"{where}: `{m.group(1)}` is not defined in crates/")
        for m in CAMEL.finditer(line):
            name = m.group(1)
            if name not in EXTERNAL and not name.startswith(("Vtk", "vtk", "Gfx")) and not defined_in_code(name):
                problems.append(f"{where}: `{name}` is defined nowhere in crates/, python/ or shaders/")
        for m in PY_PATH.finditer(line):
            if not python_name_defined(m.group(1)):
                problems.append(f"{where}: `{m.group(1)}` is not in python/oit")
    # Section pointers may break across lines: read them from the whole text.
    for m in SECTION.finditer(src):
        target, title = m.group(1), " ".join(m.group(2).split())
        n = src.count("\n", 0, m.start()) + 1
        if (REPO / "docs" / target).is_file() and not any(h.startswith(title) or title in h
                                                           for h in headings(f"docs/{target}")):
            problems.append(f'{rel_doc}:{n}: docs/{target} has no section "{title}"')
    return problems


def test_the_check_finds_stale_pointers():
    doc = "\n".join([
        "The pool is `NodePool` (lists.rs) and `NoSuchPool` (lists.rs).",  # 2: not in the file
        "See crates/oit-core/src/method/lists.rs:1 and crates/oit-core/src/method/lists.rs:999999.",  # 3
        "Gone: `crates/oit-core/src/method/gone.rs` and shaders/gone.wgsl.",  # 4, 4
        "`oit_core::method::lists::NoSuchFn` and `lists::ListMethod`.",  # 5
        "`oit.bench.report.commands` and `oit.bench.report.no_such_name`.",  # 6
        'docs/results.md, "Against pygfx" and docs/results.md, "No such section".',  # 7
        "`WhollyMadeUpType` here.",  # 8
    ])
    found = problems_in("docs/x.md", doc)
    expect = ["docs/x.md:1: `NoSuchPool` is not in lists.rs", "docs/x.md:2: crates/oit-core/src/method/lists.rs:999999",
              "docs/x.md:3: no file crates/oit-core/src/method/gone.rs", "docs/x.md:3: no file shaders/gone.wgsl",
              "docs/x.md:4: `oit_core::method::lists::NoSuchFn`", "docs/x.md:5: `oit.bench.report.no_such_name`",
              'docs/x.md:6: docs/results.md has no section "No such section"', "docs/x.md:7: `WhollyMadeUpType`"]
    for e in expect:
        assert any(f.startswith(e) for f in found), (e, found)
    assert len(found) == len(expect) + 1, found  # NoSuchPool is also defined nowhere


def test_every_code_pointer_in_the_docs_exists():
    problems = stale_pointers()
    assert not problems, f"{len(problems)} stale pointers in the docs:\n" + "\n".join(problems)


# The bench commands docs/results.md prints above its tables.

RESULTS = REPO / "docs" / "results.md"


def test_results_md_is_the_current_state_and_short():
    lines = RESULTS.read_text().splitlines()
    assert len(lines) <= 800, f"docs/results.md has {len(lines)} lines: history goes to docs/history.md"
    assert "docs/history.md" in "\n".join(lines[:40])


def test_every_command_in_results_md_parses():
    from oit.bench.cli import add_arguments
    from oit.bench.report import commands

    found = commands(RESULTS.read_text())
    assert len(found) >= 10, "docs/results.md prints the bench command above each table"
    ap = argparse.ArgumentParser(prog="python -m oit bench", exit_on_error=False)
    add_arguments(ap)
    bad = []
    for cmd in found:
        try:
            ap.parse_args(cmd.argv)
        except (argparse.ArgumentError, SystemExit) as e:
            bad.append(f"line {cmd.line}: {cmd.text}: {e}")
    assert not bad, "bench commands in docs/results.md the CLI rejects:\n" + "\n".join(bad)


def test_every_table_in_results_md_has_its_command_or_says_where_it_comes_from():
    from oit.bench.report import tables_without_source

    missing = tables_without_source(RESULTS.read_text())
    assert not missing, "tables with no command above them (lines): " + ", ".join(map(str, missing))


@pytest.mark.parametrize("flag", ["--list"])
def test_report_lists_the_commands(flag, capsys):
    from oit.bench.cli import main

    assert main(["--report", flag, "--doc", str(RESULTS)]) == 0
    out = capsys.readouterr().out
    assert out.count("python -m oit bench") >= 10
    assert all(shlex.split(line)[:4] == ["python", "-m", "oit", "bench"]
               for line in out.splitlines() if line.startswith("python -m oit bench"))
