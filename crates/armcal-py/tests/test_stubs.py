"""The type stubs (python/armcal/_armcal.pyi) name exactly the native module's public
classes, their public methods and properties, and its functions."""

import ast
import inspect
import pathlib

import armcal
from armcal import _armcal

STUBS = pathlib.Path(armcal.__file__).with_name("_armcal.pyi")


def stub_names():
    tree = ast.parse(STUBS.read_text())
    names = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            members = {
                n.name for n in node.body if isinstance(n, (ast.FunctionDef, ast.AnnAssign))
            }
            for base in node.bases:  # the shared record methods
                if isinstance(base, ast.Name):
                    members |= names.get(base.id, set())
            names[node.name] = members
        elif isinstance(node, ast.FunctionDef):
            names[node.name] = None
    return names


def native_names():
    names = {}
    for name, obj in vars(_armcal).items():
        if name.startswith("__"):
            continue
        if inspect.isclass(obj):
            own = set(vars(obj))
            names[name] = {m for m in own if not m.startswith("__")} | ({"__len__"} & own)
        elif callable(obj):
            names[name] = None
    return names


def test_every_native_item_has_a_stub():
    stubs, native = stub_names(), native_names()
    for name, members in native.items():
        assert name in stubs, f"{name} has no stub"
        if members is not None:
            missing = members - stubs[name]
            assert not missing, f"{name}: no stub for {sorted(missing)}"
    extra = {n for n in stubs if not n.startswith("_") and n not in native}
    assert not extra, f"stubs of nothing: {sorted(extra)}"


def test_package_reexports_the_native_module():
    public = {n for n in vars(_armcal) if not n.startswith("_")}
    assert public <= set(armcal.__all__), public - set(armcal.__all__)
    assert (pathlib.Path(armcal.__file__).with_name("py.typed")).exists()
