"""`python -m oit bench --report`: run every bench command docs/results.md prints above its tables,
each into its own folder under --out, so that the tables can be compared with the doc's or copied
into it. `--list` (or `--dry-run`) prints the commands and runs nothing; `--quick` runs each at the
smoke test's sizes.

In docs/results.md a table's command is a fenced `sh` block above it whose lines start with
`python -m oit bench`; a table that comes from no command has a line starting with `Source:`
above it instead (tests/test_docs.py checks both, and that every command parses)."""

from __future__ import annotations

import argparse
import glob
import os
import re
import shlex
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

PREFIX = ["python", "-m", "oit", "bench"]
# The doc, where the package runs from the repository (an editable install); else docs/results.md
# under the current folder, or --doc.
DOC = Path(__file__).resolve().parents[3] / "docs" / "results.md"


@dataclass(frozen=True)
class Command:
    line: int  # 1-based line of the doc
    text: str  # as printed
    argv: list[str]  # the arguments after `python -m oit bench`


def _fences(text: str):
    """(line number, line, language of the fenced block it is in or None) for every line."""
    lang = None
    for n, line in enumerate(text.splitlines(), 1):
        if line.startswith("```"):
            lang = (line[3:].strip() or "text") if lang is None else None
            yield n, line, "fence"
            continue
        yield n, line, lang


def commands(text: str) -> list[Command]:
    """The bench commands of the doc's `sh` blocks, in order, without repeats."""
    found: list[Command] = []
    seen: set[str] = set()
    for n, line, lang in _fences(text):
        if lang != "sh":
            continue
        words = shlex.split(line.split(" #", 1)[0])
        if words[:4] == PREFIX and line.strip() not in seen:
            seen.add(line.strip())
            found.append(Command(n, line.strip(), words[4:]))
    return found


def tables_without_source(text: str) -> list[int]:
    """Lines where a table starts with neither a bench command nor a `Source:` line above it in
    its section."""
    missing = []
    sourced = False
    in_table = False
    for n, line, lang in _fences(text):
        if lang is not None:
            if lang == "sh" and line.startswith("python -m oit bench"):
                sourced = True
            in_table = False
            continue
        if re.match(r"#{1,6} ", line):
            sourced = False
        elif line.startswith("Source:"):
            sourced = True
        table = line.startswith("|")
        if table and not in_table and not sourced:
            missing.append(n)
        in_table = table
    return missing


def run_report(a: argparse.Namespace, parser: argparse.ArgumentParser, run: Callable[[argparse.Namespace], int]) -> int:
    """Run (or with --list only print) every command of the doc, each parsed by `parser` and run
    by `run` (the bench's `run_cli`); returns 1 if any failed."""
    doc = Path(a.doc) if a.doc else DOC if DOC.is_file() else Path("docs") / "results.md"
    if not doc.is_file():
        print(f"error: {doc} not found: pass --doc docs/results.md from the repository", file=sys.stderr)
        return 1
    cmds = commands(doc.read_text())
    if a.list_only:
        for c in cmds:
            print(f"{c.text}{' --quick' if a.quick else ''}")
        return 0
    failed = []
    for i, c in enumerate(cmds, 1):
        out = os.path.join(a.out, f"{i:02d}")
        print(f"\n## [{i}/{len(cmds)}] {c.text}{' --quick' if a.quick else ''}  ({doc.name}:{c.line}; --out {out})",
              flush=True)
        try:
            ns = parser.parse_args(c.argv)
            ns.out, ns.quick = out, ns.quick or a.quick
            rc = run(ns)
        except (Exception, SystemExit) as e:  # one command's failure does not stop the others
            print(f"error: {type(e).__name__}: {e}", file=sys.stderr)
            rc = 1
        if rc:
            failed.append(c)
    print("\nTables written:")
    for i, c in enumerate(cmds, 1):
        tables = sorted(glob.glob(os.path.join(a.out, f"{i:02d}", "*.md")))
        print(f"  {c.text}: {', '.join(tables) or 'none'}")
    for c in failed:
        print(f"error: failed: {c.text} ({doc.name}:{c.line})", file=sys.stderr)
    return 1 if failed else 0
