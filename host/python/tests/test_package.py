"""The package itself: the stub names what the extension module defines (no more, no less), every
public name has a docstring, results print readably."""
import ast
import pathlib

import numpy as np

import vibid
from vibid import _vibid

STUB = pathlib.Path(vibid.__file__).with_name("_vibid.pyi")


def stub_names(tree):
    names = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            members = set()
            for n in node.body:
                if isinstance(n, ast.FunctionDef) and not n.name.startswith("__"):
                    members.add(n.name)
                elif isinstance(n, ast.AnnAssign):
                    members.add(n.target.id)
            names[node.name] = members
        elif isinstance(node, ast.FunctionDef):
            names[node.name] = None
    return names


def test_stub_matches_the_module():
    stub = stub_names(ast.parse(STUB.read_text()))
    module = {n for n in dir(_vibid) if not n.startswith("__")}
    assert set(stub) == module
    for name, members in stub.items():
        obj = getattr(_vibid, name)
        if members is not None and name != "DeviceError":
            assert members == {a for a in vars(obj) if not a.startswith("__")}, name


def test_public_names_have_docstrings():
    for name in vibid.__all__:
        assert getattr(vibid, name).__doc__, name


def test_readable_reprs():
    m = vibid.Model.chain([2.0], [800.0])
    assert repr(vibid.modal(m)).startswith("Modal(freq_hz=")
    assert "Recording(names=['x1_m'], samples=3" in repr(
        vibid.Recording(["x1_m"], np.zeros((1, 3)), 10.0))
