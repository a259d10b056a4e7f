"""The type stubs (`carom/_carom.pyi`) match the extension module: every public name, class,
method, property and parameter list. (`mypy.stubtest carom._carom`, run by `make
python-test`, checks the same more deeply but takes several seconds.)"""

from __future__ import annotations

import ast
import inspect
from pathlib import Path
from typing import Any

import pytest

import carom
import carom._carom as runtime

STUB = Path(carom.__file__).with_name("_carom.pyi")
TREE = ast.parse(STUB.read_text())


def stub_classes() -> dict[str, ast.ClassDef]:
    return {n.name: n for n in TREE.body if isinstance(n, ast.ClassDef)}


def stub_all() -> list[str]:
    """`__all__ = [...]` plus every later `__all__ += [...]` of the stub."""
    names: list[str] | None = None
    for n in TREE.body:
        if isinstance(n, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__all__" for t in n.targets):
            names = [ast.literal_eval(e) for e in n.value.elts]  # type: ignore[attr-defined]
        elif isinstance(n, ast.AugAssign) and isinstance(n.target, ast.Name) and n.target.id == "__all__":
            assert names is not None, "__all__ += before __all__ ="
            names += [ast.literal_eval(e) for e in n.value.elts]  # type: ignore[attr-defined]
    if names is None:
        raise AssertionError("no __all__ in the stub")
    return names


def is_property(f: ast.FunctionDef) -> bool:
    return any(isinstance(d, ast.Name) and d.id == "property" for d in f.decorator_list)


def stub_params(f: ast.FunctionDef) -> list[tuple[str, bool]]:
    args = f.args
    params = args.posonlyargs + args.args
    defaults = [False] * (len(params) - len(args.defaults)) + [True] * len(args.defaults)
    out = [(a.arg, d) for a, d in zip(params, defaults)]
    return [p for p in out if p[0] not in ("self", "cls")]


def runtime_params(obj: Any) -> list[tuple[str, bool]]:
    sig = inspect.signature(obj)
    return [
        (name, p.default is not inspect.Parameter.empty)
        for name, p in sig.parameters.items()
        if name not in ("self", "cls", "$self", "$cls")
    ]


def test_public_names_match() -> None:
    names = stub_all()
    assert sorted(names) == sorted(runtime.__all__)
    assert sorted(names) == sorted(carom.__all__)
    for name in names:
        assert hasattr(runtime, name) and getattr(carom, name) is getattr(runtime, name)
    assert set(stub_classes()) == {n for n in names if inspect.isclass(getattr(runtime, n))}


@pytest.mark.parametrize("name", sorted(stub_classes()))
def test_class_members_match(name: str) -> None:
    cls = getattr(runtime, name)
    node = stub_classes()[name]
    bases = [b.id for b in node.bases if isinstance(b, ast.Name)]
    assert [b.__name__ for b in cls.__bases__] == (bases or ["object"]) if name != "CaromError" else True
    stub_members: dict[str, ast.FunctionDef] = {
        f.name: f for f in node.body if isinstance(f, ast.FunctionDef)
    }
    # Every public runtime member defined on this class is in the stub.
    own = {k for k in vars(cls) if not k.startswith("_")}
    assert own <= set(stub_members), f"missing from the stub: {own - set(stub_members)}"
    for member, f in stub_members.items():
        if member == "__new__":
            assert runtime_params(cls) == stub_params(f), member
            continue
        assert hasattr(cls, member), f"{name}.{member} is only in the stub"
        attr = inspect.getattr_static(cls, member)
        if is_property(f):
            assert inspect.isdatadescriptor(attr), f"{name}.{member} should be a property"
            continue
        assert callable(getattr(cls, member)), member
        if member.startswith("__"):
            continue
        assert runtime_params(getattr(cls, member)) == stub_params(f), f"{name}.{member}"


def test_every_public_item_has_a_docstring() -> None:
    assert carom.__doc__
    for name in carom.__all__:
        obj = getattr(carom, name)
        if not inspect.isclass(obj):
            continue
        assert obj.__doc__ and len(obj.__doc__) > 20, name
        for member, value in vars(obj).items():
            if member.startswith("_"):
                continue
            assert getattr(value, "__doc__", None), f"{name}.{member} has no docstring"
