"""python/oit/_oit.pyi describes the native module oit._oit: the same public names, the same
members of each class, and the same parameters (names and defaults) as the signatures PyO3
reports. When crates/oit-py/src gains or changes a function, the stub changes with it."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import pytest

import oit
from oit import _oit

SOURCE = Path(__file__).resolve().parents[1] / "python" / "oit"
STUB = ast.parse((SOURCE / "_oit.pyi").read_text())


def public(names):
    return {n for n in names if not n.startswith("_")}


def stub_classes() -> dict[str, ast.ClassDef]:
    return {n.name: n for n in STUB.body if isinstance(n, ast.ClassDef) and not n.name.startswith("_")}


def stub_functions(body) -> dict[str, ast.FunctionDef]:
    return {n.name: n for n in body if isinstance(n, ast.FunctionDef)}


def stub_parameters(fn: ast.FunctionDef) -> list[tuple[str, object]]:
    """(name, default or inspect.Parameter.empty) of each parameter but self."""
    args = fn.args.args
    defaults = [inspect.Parameter.empty] * (len(args) - len(fn.args.defaults)) + [ast.literal_eval(d) for d in fn.args.defaults]
    return [(a.arg, d) for a, d in zip(args, defaults) if a.arg != "self"]


def native_parameters(obj) -> list[tuple[str, object]]:
    return [(p.name, p.default) for p in inspect.signature(obj).parameters.values() if p.name != "self"]


def test_the_stub_names_what_the_module_exports():
    stub = set(stub_classes()) | public(stub_functions(STUB.body))
    assert stub == public(dir(_oit)) - {"__all__"}


@pytest.mark.parametrize("name", sorted(stub_classes()))
def test_each_class_has_the_stub_members(name):
    cls = getattr(_oit, name)
    members = stub_functions(stub_classes()[name].body)
    assert public(members) == public(dir(cls))
    for member, fn in members.items():
        is_property = any(isinstance(d, ast.Name) and d.id == "property" for d in fn.decorator_list)
        if is_property:
            assert inspect.isdatadescriptor(getattr(cls, member)), member
        elif member == "__init__":
            assert stub_parameters(fn) == native_parameters(cls), name
        else:
            assert stub_parameters(fn) == native_parameters(getattr(cls, member)), f"{name}.{member}"


@pytest.mark.parametrize("name", sorted(public(stub_functions(STUB.body))))
def test_each_function_has_the_stub_parameters(name):
    assert stub_parameters(stub_functions(STUB.body)[name]) == native_parameters(getattr(_oit, name))


def test_the_package_ships_the_stub_and_py_typed():
    # maturin packs everything under python/oit into the wheel; an installed copy without these
    # was built before they existed (rebuild with scripts/setup.sh).
    installed = Path(oit.__file__).parent
    assert (installed / "_oit.pyi").is_file() and (installed / "py.typed").is_file()
