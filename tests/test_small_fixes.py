"""Issue 13, item 16: the chi-square result's repr, and no NumbaWarning from a threaded sweep."""

import os
import subprocess
import sys

import numpy as np
import pytest

from pumpup.testing import Chi2Result


def _result(passed, p):
    k = len(p)
    return Chi2Result(
        wo=np.tile([0.0, 0.0, 1.0], (k, 1)), p_values=np.array(p), statistics=np.full(k, 31.5),
        dofs=np.full(k, 40), alpha=0.01, significance=1 - 0.99 ** (1 / k), passed_each=np.full(k, passed),
        passed=passed, messages=[[] for _ in p], observed=np.ones((k, 64, 128), int),
        expected=np.ones((k, 64, 128)), observed_rejected=np.zeros(k), expected_rejected=np.zeros(k),
        pdf_integral=np.ones(k), integration_error=np.zeros(k), pdf_mismatches=np.zeros(k, int),
        pooled_in=np.zeros(k, int), pooled_out=np.zeros(k, int), n_samples=1_000_000, n_theta=64, n_phi=128)


def test_chi2_repr_shows_the_verdict_and_p_value():
    r = _result(True, [0.5, 0.2, 0.9])
    text = repr(r)
    assert text.startswith("<Chi2Result passed: p = 0.488")  # 1 - 0.8^3
    assert "array" not in text and len(text) < 250
    assert "FAILED" in repr(_result(False, [1e-6]))


@pytest.mark.slow
def test_threaded_sweep_compiles_without_numba_warning(tmp_path):
    """With an empty numba cache every ufunc compiles during the sweep; two threads asking for one
    signature at once made numba warn ("Compilation requested for previously compiled argument
    types"). About 30 s: everything compiles."""
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ, PYTHONPATH=root, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    r = subprocess.run([sys.executable, "-m", "pumpup.cli", "sweep", "stretched_phong", "--param", "n=1,2,4",
                        "--param", "p=0,1", "--mu", "1", "0.5", "--no-maximum", "--out", str(tmp_path / "x.nc"),
                        "--threads", "--workers", "2"], capture_output=True, text=True, env=env, timeout=1800)
    assert r.returncode == 0, r.stderr
    assert "NumbaWarning" not in r.stderr and "previously compiled" not in r.stderr, r.stderr


def test_modules_are_not_hidden_by_their_functions():
    """Issue 13 item 16: the modules of pump, sweep and fit have names of their own."""
    import importlib
    import types

    import pumpup

    for mod, func in (("operators.pumping", "pump"), ("sweeps", "sweep"), ("fitting", "fit")):
        m = importlib.import_module(f"pumpup.{mod}")
        reached = pumpup
        for part in mod.split("."):  # pumpup.operators.pumping: attributes all the way
            reached = getattr(reached, part)
        assert isinstance(m, types.ModuleType) and reached is m
        assert callable(getattr(pumpup, func)) and getattr(m, func) is getattr(pumpup, func)
