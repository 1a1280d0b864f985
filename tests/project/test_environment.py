"""The installed test environment is the one pyproject.toml promises.

Every requirement of the package and of its ``test`` extra is installed at a version inside its
range: a test run under a version outside the tested range (an old pytest left in a venv, say)
fails here with the package's name, instead of somewhere deep in an assertion.
"""

from __future__ import annotations

import os
from importlib import metadata

import helpers
import pytest
from packaging.requirements import Requirement

tomllib = pytest.importorskip("tomllib")  # Python >= 3.11

ROOT = str(helpers.ROOT)


def requirements(extra: str | None = None) -> list[Requirement]:
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        project = tomllib.load(fh)["project"]
    lines = project["dependencies"] if extra is None else project["optional-dependencies"][extra]
    return [Requirement(line) for line in lines]


def test_the_test_tools_have_upper_bounds():
    for req in requirements("test"):
        assert any(s.operator in ("<", "<=", "~=", "==") for s in req.specifier), \
            f"{req.name}: the test extra gives no upper bound, so a new major release changes the suite untested"


@pytest.mark.parametrize("req", requirements() + requirements("test"), ids=str)
def test_installed_version_is_in_range(req):
    version = metadata.version(req.name)
    assert req.specifier.contains(version, prereleases=True), f"{req.name} {version} is outside {req.specifier}"


def test_approx_of_nested_sequences_is_not_relied_on():
    """pytest >= 9.1 refuses ``pytest.approx`` of a list of tuples (TypeError); the suite compares arrays instead."""
    import ast
    import glob

    for path in glob.glob(os.path.join(ROOT, "tests", "**", "*.py"), recursive=True):
        tree = ast.parse(open(path).read())
        for node in ast.walk(tree):
            if (isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "approx" and node.args
                    and isinstance(node.args[0], (ast.List, ast.Tuple))
                    and any(isinstance(e, (ast.List, ast.Tuple)) for e in node.args[0].elts)):
                pytest.fail(f"{os.path.relpath(path, ROOT)}:{node.lineno}: pytest.approx of a nested sequence")
