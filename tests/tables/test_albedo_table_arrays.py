"""pumpup.tables.albedo_table: the operators' session tables made without xarray give the same table, and the same
Dataset when it is read, as tabulate + AlbedoTable.from_dataset."""

import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

import pumpup
from pumpup.operators.pumping import TABLE_INTERP_TOL, TABLE_RTOL, grid_interior
from pumpup.tables import AlbedoTable, albedo_table

CASES = [
    ({"type": "phong", "n": 20}, None),
    ({"type": "ggx", "alpha": 0.3}, None),
    ({"type": "pumped", "base": {"type": "blinn", "n": 20}, "g": "g2"}, None),  # a kink: the spline split there
    # an anisotropic base: the supremum over phi (about 10 s)
    pytest.param({"type": "ward_aniso", "ax": 0.3, "ay": 0.5}, "sup", marks=pytest.mark.slow),
]


@pytest.mark.parametrize(("spec", "phi"), CASES)
def test_same_table_and_dataset_as_tabulate(spec, phi):
    f = pumpup.load(spec)
    breaks = f.albedo_kinks(*grid_interior())
    assert (breaks is not None) == (spec["type"] == "pumped")
    t = albedo_table(f, rtol=TABLE_RTOL, interp_tol=TABLE_INTERP_TOL, progress=False, phi=phi, breaks=breaks)
    ds = pumpup.tabulate(f, rtol=TABLE_RTOL, interp_tol=TABLE_INTERP_TOL, progress=False, phi=phi, breaks=breaks)
    ref = AlbedoTable.from_dataset(ds)
    for name in ("mu", "value", "error"):
        np.testing.assert_array_equal(getattr(t, name), getattr(ref, name))
    assert (t.interp_error, t.spec, t.degree, t.breaks, t.margin, t.margin_below) == \
        (ref.interp_error, ref.spec, ref.degree, ref.breaks, ref.margin, ref.margin_below)
    mu = np.geomspace(1e-9, 1.0, 301)
    np.testing.assert_array_equal(t.upper(mu), ref.upper(mu))
    assert isinstance(t.dataset, xr.Dataset)
    xr.testing.assert_identical(t.dataset, ds)
    assert t.dataset is t.dataset  # made once


def test_a_pumped_chain_and_its_shader_need_no_xarray():
    code = ("import sys, numpy as np, pumpup\n"
            "f = pumpup.load({'type': 'pumped', 'base': {'type': 'ggx', 'alpha': 0.3}, 'g': 'g2', 'levels': 2})\n"
            "f.eval(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]))\n"
            "pumpup.shader(f, target='glsl')\n"
            "k = pumpup.load({'type': 'kulla_conty', 'base': {'type': 'ggx', 'alpha': 0.3}})\n"
            "k.eval(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]))\n"
            "print('xarray' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False", out.stderr
