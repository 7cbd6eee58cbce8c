"""The type stubs and docstrings describe the module as it is."""
import ast
import inspect
import pathlib

import skybake
import skybake._core as core

STUBS = pathlib.Path(skybake.__file__).with_name("__init__.pyi")


def stub_tree():
    return ast.parse(STUBS.read_text())


def public(names):
    return {n for n in names if not n.startswith("_")}


def test_every_name_has_a_stub_and_every_stub_a_name():
    tree = stub_tree()
    stubbed = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    exported = public(dir(core))
    assert exported - stubbed == set(), "missing from the stubs"
    assert stubbed - exported == set(), "stubs of names the module lacks"


def test_class_members_match():
    for node in stub_tree().body:
        if not isinstance(node, ast.ClassDef) or node.name == "Error":
            continue
        cls = getattr(core, node.name)
        stubbed = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        stubbed |= {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)}
        actual = public(vars(cls))
        assert actual - stubbed == set(), f"{node.name}: missing from the stubs"
        assert stubbed - actual - {"__init__", "__len__"} == set(), f"{node.name}: stubbed but absent"


def test_function_arguments_match():
    for node in stub_tree().body:
        if not isinstance(node, ast.FunctionDef):
            continue
        doc = inspect.getdoc(getattr(core, node.name)) or ""
        signature = doc.splitlines()[0]
        for a in node.args.args:
            assert f"{a.arg}:" in signature, f"{node.name}: argument {a.arg} not in {signature}"


def test_everything_has_a_docstring():
    for name in public(dir(core)):
        obj = getattr(core, name)
        if callable(obj) and not isinstance(obj, type):
            assert len(inspect.getdoc(obj).splitlines()) > 1 or name in {"version", "threads"}, name
