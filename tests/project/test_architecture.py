"""The house: pumpup's packages import only downward (the layers contract in pyproject.toml, checked by
import-linter), the layers are the ones the developer guide describes, and the package and the tests pass the style
checks of pyproject.toml's [tool.ruff] (the pre-commit hooks run both)."""

from __future__ import annotations

import importlib.util
import os
import shutil
import subprocess
import sys

import helpers
import pytest
import tomllib

ROOT = str(helpers.ROOT)


def _contract() -> dict:
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        return tomllib.load(fh)["tool"]["importlinter"]["contracts"][0]


def test_layers_contract_is_kept():
    exe = shutil.which("lint-imports") or os.path.join(os.path.dirname(sys.executable), "lint-imports")
    if not os.path.exists(exe):
        pytest.fail("lint-imports is not installed: pip install -e \".[test]\"")
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    r = subprocess.run([exe, "--no-cache"], cwd=ROOT, capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-2000:]
    assert "0 broken" in r.stdout


def _ruff() -> list[str]:
    """The command that runs ruff: the module of this interpreter's environment if it has one, else ruff on PATH."""
    if importlib.util.find_spec("ruff") is not None:
        return [sys.executable, "-m", "ruff"]
    exe = shutil.which("ruff")
    if exe is None:
        pytest.fail("ruff is not installed: pip install -e \".[test]\"")
    return [exe]


def test_ruff_check_passes():
    """``ruff check pumpup tests`` finds nothing: pyflakes, pycodestyle, isort, pyupgrade and the numpy docstring
    convention, as selected in pyproject.toml (the pre-commit hook runs the same check with --fix)."""
    r = subprocess.run([*_ruff(), "check", "--no-cache", "--output-format", "concise", "pumpup", "tests"], cwd=ROOT,
                       capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        print(r.stdout, r.stderr, sep="\n")  # all of it, under "Captured stdout call"
    assert r.returncode == 0, f"ruff exit status {r.returncode}:\n{r.stdout[-8000:]}{r.stderr[-2000:]}"


def test_every_package_is_in_a_layer():
    """A new module or package of pumpup must be placed in a layer, or the contract would not see it."""
    layers = {name.strip() for layer in _contract()["layers"] for name in layer.replace("|", ":").split(":")}
    here = os.path.join(ROOT, "pumpup")
    for entry in sorted(os.listdir(here)):
        name = entry[:-3] if entry.endswith(".py") else entry
        if entry.startswith(("_", ".")):
            continue
        if entry.endswith(".py") or os.path.isfile(os.path.join(here, entry, "__init__.py")):
            assert name in layers, f"pumpup.{name} is in no layer of pyproject.toml's import-linter contract"


def test_the_lowest_layers_import_no_upper_one():
    """core and physics import nothing above them, models and the engine not each other: the contract's order."""
    layers = [layer.replace(" ", "") for layer in _contract()["layers"]]
    assert layers[-3:] == ["models|engine", "physics", "core"]
