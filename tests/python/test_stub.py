# SPDX-License-Identifier: MIT
"""The type stubs (renderer/python/whitted.pyi) against the built module, so that they cannot drift.

Every public name of the module is in the stub and every name of the stub is in the module; each
function's and method's parameters (names, order, keyword-only marks, defaults) are those of
pybind11's signature, the first line of its __doc__. $WHITTED_STUB names the stub to check (the
pip test checks the installed one); by default the one in the source tree.
"""
import ast
import inspect
import os

import pytest

import whitted

STUB = os.environ.get("WHITTED_STUB") or os.path.join(
    os.path.dirname(__file__), "..", "..", "renderer", "python", "whitted.pyi")


def split_top_level(text):
    """Split at the commas outside brackets and quotes."""
    parts, depth, quote, current = [], 0, None, ""
    for ch in text:
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(current.strip())
            current = ""
            continue
        current += ch
    if current.strip():
        parts.append(current.strip())
    return parts


def pybind_parameters(obj, name):
    """[(name, keyword_only, default or inspect.Parameter.empty)] from pybind11's signature line,
    without `self`."""
    line = (obj.__doc__ or "").splitlines()[0]
    assert line.startswith(name + "("), f"{name}: no pybind11 signature in its __doc__: {line!r}"
    inside = line[len(name) + 1:line.rindex(") -> ")]
    out, keyword_only = [], False
    for part in split_top_level(inside):
        if part == "*":
            keyword_only = True
            continue
        head, _, default = part.partition(" = ")
        pname = head.partition(":")[0].strip()
        if pname == "self":
            continue
        out.append((pname, keyword_only, ast.literal_eval(default) if default else inspect.Parameter.empty))
    return out


def stub_parameters(function):
    """The same list from a stub's ast.FunctionDef, without `self`."""
    args = function.args
    assert not args.vararg and not args.kwarg, f"{function.name}: *args/**kwargs in the stub"
    positional = args.posonlyargs + args.args
    defaults = [inspect.Parameter.empty] * (len(positional) - len(args.defaults)) + [
        ast.literal_eval(d) for d in args.defaults]
    out = [(a.arg, False, d) for a, d in zip(positional, defaults) if a.arg != "self"]
    out += [(a.arg, True, ast.literal_eval(d) if d is not None else inspect.Parameter.empty)
            for a, d in zip(args.kwonlyargs, args.kw_defaults)]
    return out


def is_property(function):
    return any(isinstance(d, ast.Name) and d.id == "property" for d in function.decorator_list)


@pytest.fixture(scope="module")
def stub():
    with open(STUB) as f:
        tree = ast.parse(f.read(), STUB)
    names = {}
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names[node.name] = node
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names[node.target.id] = node
    return {n: node for n, node in names.items() if not n.startswith("_") or n == "__version__"}


def module_public_names():
    return {n for n in dir(whitted) if not n.startswith("_")} | {"__version__"}


def test_every_module_name_is_in_the_stub_and_back(stub):
    assert sorted(module_public_names() - set(stub)) == [], "in the module, missing from the stub"
    assert sorted(set(stub) - module_public_names()) == [], "in the stub, not in the module"


def test_functions_have_pybind11s_parameters(stub):
    functions = [n for n in module_public_names() if callable(getattr(whitted, n))
                 and not inspect.isclass(getattr(whitted, n))]
    assert "render" in functions and "load" in functions
    for name in functions:
        assert isinstance(stub[name], ast.FunctionDef), f"{name} is a function in the module"
        assert stub_parameters(stub[name]) == pybind_parameters(getattr(whitted, name), name), name


def test_classes_have_the_modules_members(stub):
    classes = [n for n in module_public_names() if inspect.isclass(getattr(whitted, n))]
    assert {"Scene", "SceneBuilder", "CheckResult", "Error"} <= set(classes)
    for class_name in classes:
        cls = getattr(whitted, class_name)
        assert isinstance(stub[class_name], ast.ClassDef), f"{class_name} is a class in the module"
        members = {n: node for n, node in (
            (getattr(node, "name", None), node) for node in stub[class_name].body) if n}
        if class_name == "Error":
            continue  # its attributes are per instance: test_error_attributes
        # pybind11's own: the public members, and the special methods it defines (not __repr__,
        # which every object has, nor those pybind11 adds to every class).
        ours = {n for n, v in vars(cls).items() if not n.startswith("_")
                or (n in ("__init__", "__bool__") and type(v).__name__ == "instancemethod")}
        assert sorted(ours - set(members)) == [], f"{class_name}: missing from the stub"
        assert sorted(set(members) - ours) == [], f"{class_name}: in the stub, not in the module"
        for name in ours:
            member = vars(cls)[name]
            node = members[name]
            qualified = f"{class_name}.{name}"
            if isinstance(member, property):
                assert is_property(node), f"{qualified} is a property in the module"
                assert stub_parameters(node) == [], f"{qualified}: a property takes only self"
                continue
            assert not is_property(node), f"{qualified} is a method in the module"
            assert stub_parameters(node) == pybind_parameters(member, name), qualified


def test_error_attributes(stub):
    declared = {node.target.id for node in stub["Error"].body if isinstance(node, ast.AnnAssign)}
    with pytest.raises(whitted.Error) as raised:
        whitted.loads("version: 1\nimage: {width: 8}\n", "bad.yaml")
    assert declared == {"message", "file", "line", "column", "kind"}
    for name in declared:
        assert hasattr(raised.value, name), name
    assert isinstance(raised.value.line, int) and raised.value.kind == "bad_input"
    assert issubclass(whitted.Error, RuntimeError)
