"""The stub sph.pyi declares exactly what the module defines (so editors complete and check
every call, and nothing that does not exist)."""
import ast
import inspect
import os

import sph


def stub():
    path = os.path.join(os.path.dirname(sph.__file__), "sph.pyi")
    with open(path) as f:
        return ast.parse(f.read())


def declared(body):
    names = set()
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
    return names


def public(obj):
    return {n for n in vars(obj) if not n.startswith("__") or n in ("__init__", "__len__", "__eq__")}


def test_the_stub_declares_the_module():
    tree = stub()
    module_names = {n for n in vars(sph) if not n.startswith("__") or n == "__version__"}
    module_names -= {"__version__"}
    assert declared(tree.body) - {"__version__"} == module_names
    classes = {node.name: node for node in tree.body if isinstance(node, ast.ClassDef)}
    for name in ("Scene", "Simulation"):
        cls = getattr(sph, name)
        have = {n for n in public(cls) if not n.startswith("_pybind11")}
        if name == "Scene":  # made by its static functions: pybind11's __init__ only refuses
            have.discard("__init__")
        assert declared(classes[name].body) == have, name


def test_a_scene_is_made_by_its_functions_only():
    import pytest
    with pytest.raises(TypeError):
        sph.Scene()


def test_every_public_function_has_a_docstring():
    for name, obj in vars(sph).items():
        if name.startswith("_"):
            continue
        if callable(obj):
            assert inspect.getdoc(obj), name
    for cls in (sph.Scene, sph.Simulation):
        for name, member in vars(cls).items():
            if not name.startswith("_"):
                assert inspect.getdoc(member), f"{cls.__name__}.{name}"
