"""One source for the types: the package's modules are annotated in place (no
``__init__.pyi`` beside them), and ``_native.pyi`` describes the extension as it is."""

import ast
import inspect
from pathlib import Path

import drive_monitor as dm
from drive_monitor import _native, fleet

PKG = Path(dm.__file__).resolve().parent


def stub_functions():
    tree = ast.parse((PKG / "_native.pyi").read_text())
    return {
        n.name: [a.arg for a in n.args.args] + ([n.args.kwarg.arg] if n.args.kwarg else [])
        for n in tree.body
        if isinstance(n, ast.FunctionDef)
    }


def test_the_extensions_stub_lists_its_functions_and_their_parameters():
    stubs = stub_functions()
    native = {n: f for n, f in vars(_native).items() if callable(f) and not isinstance(f, type)}
    assert set(stubs) == set(native)
    for name, f in native.items():
        assert stubs[name] == list(inspect.signature(f).parameters), name


def test_the_package_is_annotated_in_place():
    assert not (PKG / "__init__.pyi").exists()
    for mod in (dm, fleet):
        for name in mod.__all__:
            f = getattr(mod, name)
            if not inspect.isfunction(f):
                continue
            sig = inspect.signature(f)
            assert sig.return_annotation is not inspect.Signature.empty, name
            for p in sig.parameters.values():
                assert p.annotation is not inspect.Parameter.empty, (name, p.name)


def test_diagnose_takes_every_described_option_by_name():
    # One description (the library's DIAGNOSE_OPTIONS): the signature and the docs of
    # drive_monitor.diagnose are made from it, so a new option needs no line here.
    described = _native.diagnose_options()
    names = [d[0] for d in described]
    assert "commission" in names and "timeline_step" in names, names
    sig = inspect.signature(dm.diagnose)
    for name, annotation, default, doc in described:
        p = sig.parameters[name]
        assert p.kind is inspect.Parameter.KEYWORD_ONLY, name
        assert p.annotation == annotation and doc, name
        assert f"{name} : {annotation}" in dm.diagnose.__doc__, name
    assert "{options}" not in dm.diagnose.__doc__
