"""The white furnace a renderer's table predicts (pumpup.furnace_prediction), against independent computations."""

import re

import helpers
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.interpolate import RegularGridInterpolator

import pumpup
from pumpup.conventions import ConventionsError

CYCLES_TABLES = str(helpers.DATA / "cycles_shader.tables")


def _cycles_arrays():
    """Cycles' E (32 x 32, rows mu) and E_avg (32) parsed here, on their own."""
    text = open(CYCLES_TABLES).read()
    out = {}
    for name in ("table_ggx_E", "table_ggx_Eavg"):
        body = re.search(name + r"\[\d+\] = \{(.*?)\}", text, re.S).group(1)
        out[name] = np.array([float(t) for t in re.findall(r"[\d.]+(?=f)", body)], dtype=np.float32).astype(float)
    return out["table_ggx_E"].reshape(32, 32), out["table_ggx_Eavg"]


def _true_E(mu, r):
    return np.array([[float(pumpup.albedo(pumpup.load({"type": "ggx", "alpha": float(x) ** 2,
                                                       "shadowing": "correlated"}), m, rtol=1e-9)) for x in r]
                     for m in mu])


MU = np.array([0.003, 0.05, 0.2, 0.5173, 0.9])
R = np.array([0.02, 0.13, 0.41, 0.77, 1.0])


def test_scale_on_the_shipped_cycles_table_is_true_over_lookup():
    E, _ = _cycles_arrays()
    g = np.arange(32) / 31  # Cycles reads saturatef(x) * 31, bilinearly, with rows mu and columns roughness
    look = RegularGridInterpolator((g, g), E)(np.stack(np.meshgrid(MU, R, indexing="ij"), axis=-1))
    expect = _true_E(MU, R) / look
    ds = pumpup.furnace_prediction("cycles", "scale", path=CYCLES_TABLES, mu=MU, roughness=R)
    assert ds["furnace"].dims == ("mu", "roughness")
    np.testing.assert_allclose(ds["furnace"].values, expect, rtol=2e-8)
    np.testing.assert_allclose(ds["alpha"].values, R**2)
    # near grazing at small roughness the look-up errs by the most (0.102 by the audit): the furnace is off 1
    worst = pumpup.furnace_prediction("cycles", "scale", path=CYCLES_TABLES, mu=[1.1e-4], roughness=[0.01])
    assert float(worst["furnace"][0, 0]) < 0.95


def test_scale_with_exact_nodes_is_one_at_the_nodes():
    """A renderer whose table holds exact E (float64) renders 1 wherever it reads a node; between nodes, it renders
    the look-up's error."""
    conv = {"model": "ggx:shadowing=correlated", "quantity": "E", "format": "npy", "storage": "float64",
            "shape": [9, 7],
            "axes": [{"axis": "mu", "clamp": [[0, 1e-3]]}, {"axis": "roughness", "clamp": [[0, 0.05]]}]}
    mu_nodes = np.arange(1, 9) / 8
    r_nodes = np.arange(1, 7) / 6
    ds = pumpup.furnace_prediction(conv, "scale", mu=mu_nodes, roughness=r_nodes, rtol=1e-10)
    assert np.max(np.abs(ds["furnace"].values - 1)) < 1e-9
    mid = pumpup.furnace_prediction(conv, "scale", mu=mu_nodes[:-1] + 1 / 16, roughness=r_nodes, rtol=1e-10)
    assert np.max(np.abs(mid["furnace"].values - 1)) > 1e-4


def test_kulla_conty_adds_its_lobe_from_the_table():
    E, Eavg = _cycles_arrays()
    g = np.arange(32) / 31
    mu, r = np.array([0.1, 0.6]), np.array([0.35, 0.9])
    ds = pumpup.furnace_prediction("cycles", "kulla_conty", path=CYCLES_TABLES, mu=mu, roughness=r)
    true = _true_E(mu, r)
    for j, x in enumerate(r):
        def col(m, x=x):
            return float(RegularGridInterpolator((g, g), E)([[min(max(m, 0), 1), x]])[0])

        avg_own = 2 * quad(lambda m: col(m) * m, 0, 1, points=list(g[1:-1]), limit=200, epsabs=1e-12)[0]
        avg = float(np.interp(x, g, Eavg))
        for i, m in enumerate(mu):
            # E + integral over wi of (1 - E(mu_i))(1 - E(mu_o)) / (pi (1 - E_avg)) cos(theta_i)
            expect = true[i, j] + (1 - col(m)) * (1 - avg_own) / (1 - avg)
            assert float(ds["furnace"][i, j]) == pytest.approx(expect, abs=1e-8)


def test_none_is_the_albedo_and_bad_input():
    ds = pumpup.furnace_prediction("cycles", "none", mu=[0.5], roughness=[0.5])
    assert float(ds["furnace"][0, 0]) == pytest.approx(_true_E([0.5], [0.5])[0, 0], abs=1e-8)
    with pytest.raises(ConventionsError, match="method must be one of"):
        pumpup.furnace_prediction("cycles", "pump")
    with pytest.raises(ConventionsError, match="roughness must be"):
        pumpup.furnace_prediction("cycles", roughness=[1.5])
    with pytest.raises(ConventionsError, match="mu must be"):
        pumpup.furnace_prediction("cycles", mu=[0.0])
