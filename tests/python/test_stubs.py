"""The type stubs (python/sandbox/_sandbox.pyi) match the built extension.

mypy's stubtest checks that every name in the stub is at the module's runtime
and the other way round; pybind11 gives no inspectable signatures, so the
parameter names and defaults are compared here with the signatures pybind11
writes into each docstring.
"""
import ast
import inspect
import os
import pathlib
import re
import subprocess
import sys

import sandbox._sandbox as extension

HERE = pathlib.Path(__file__).resolve().parent
STUB = pathlib.Path(extension.__file__).parent / "_sandbox.pyi"


def test_stubtest_finds_no_difference():
    result = subprocess.run([sys.executable, "-m", "mypy.stubtest", "sandbox._sandbox",
                             "--allowlist", str(HERE / "stubtest_allowlist.txt"),
                             "--ignore-unused-allowlist"],
                            capture_output=True, text=True, env=os.environ, cwd=HERE)
    assert result.returncode == 0, result.stdout + result.stderr


def stub_parameters():
    """{"Class.method": [parameter names]} from the stub."""
    found = {}
    for node in ast.parse(STUB.read_text()).body:
        if isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and not any(
                        isinstance(d, ast.Name) and d.id == "property" for d in item.decorator_list):
                    found[f"{node.name}.{item.name}"] = [a.arg for a in item.args.args]
    return found


def runtime_parameters():
    """The same from pybind11's docstring signatures."""
    found = {}
    for class_name, cls in inspect.getmembers(extension, inspect.isclass):
        if issubclass(cls, BaseException):
            continue
        for name, member in vars(cls).items():
            doc = getattr(member, "__doc__", None) or ""
            match = re.match(rf"{re.escape(name)}\((.*?)\) ->", doc)
            if not match or isinstance(member, property):
                continue
            names = [part.split(":")[0].strip() for part in re.split(r",\s*(?![^\[]*\])", match.group(1))
                     if part.strip()]
            found[f"{class_name}.{name}"] = names
    return found


def test_parameter_names_match_the_docstrings():
    stub, runtime = stub_parameters(), runtime_parameters()
    assert len(runtime) >= 20
    for name, parameters in runtime.items():
        assert name in stub, f"{name} is not in the stub"
        assert stub[name] == parameters, name
