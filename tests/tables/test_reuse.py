"""mean_albedo and max_albedo reuse the table just computed for the same BRDF object (pumpup/tables/reuse.py):
the same numbers within the stated errors, the independent references, and a fall-back where the
table cannot meet the tolerance."""

import json

import helpers
import numpy as np
import pytest

import pumpup
from pumpup.sweeps import default_mu
from pumpup.tables import reuse as _reuse

DATA = json.loads((helpers.DATA / "independent_reference.json").read_text())
MEAN = [e for e in DATA["entries"] if e["quantity"] == "mean_albedo"]
MU = default_mu(257)  # the sweep's grid


def _fresh_low(f, rtol):
    return lambda mu_min, scale: _reuse.fresh_low(f, mu_min, 0.25 * rtol * scale, rtol / 10)


@pytest.mark.parametrize("entry", MEAN, ids=[f"{e['model']}-{e['params']}" for e in MEAN])
def test_mean_from_the_table_against_independent_reference(entry):
    f = pumpup.load({"type": entry["model"], **entry["params"]})
    pumpup.tabulate(f, mu=MU, progress=False)
    assert _reuse.mean_from_table(f, 1e-9, _fresh_low(f, 1e-9)) is not None  # the table is used
    m, e = pumpup.mean_albedo(f, return_error=True)
    assert abs(m - entry["value"]) <= e + entry["abs_err_estimate"]  # honest
    assert e <= 1e-9 * m


@pytest.mark.parametrize("spec", [{"type": "stretched_phong", "n": 20}, {"type": "retro", "n": 10},
                                  {"type": "stretched_phong", "n": 300}, {"type": "lewis_phong", "n": 5}])
def test_reuse_agrees_with_fresh(spec):
    fresh = pumpup.load(spec)
    m0, e0 = pumpup.mean_albedo(fresh, return_error=True)
    x0 = pumpup.max_albedo(fresh)
    f = pumpup.load(spec)
    pumpup.tabulate(f, mu=MU, progress=False)
    m1, e1 = pumpup.mean_albedo(f, return_error=True)
    assert abs(m1 - m0) <= e0 + e1 and e1 <= 1e-9 * m1
    x1 = pumpup.max_albedo(f)
    assert abs(x1.albedo - x0.albedo) <= x0.error + x1.error + 1e-12 * x0.albedo  # Brent's bracket may differ
    assert x1.at_boundary == x0.at_boundary


def test_an_unresolved_table_falls_back():
    f = pumpup.load({"type": "stretched_phong", "n": 3000})  # the lobe is narrower than the grid near grazing
    pumpup.tabulate(f, mu=MU, progress=False)
    assert _reuse.mean_from_table(f, 1e-9, _fresh_low(f, 1e-9)) is None
    m, e = pumpup.mean_albedo(f, return_error=True)
    g = pumpup.load(f.spec)  # no table: the fresh computation
    assert (m, e) == tuple(pumpup.mean_albedo(g, return_error=True))


@pytest.mark.parametrize("spec", [{"type": "phong", "n": 20000}, {"type": "ward", "m": 0.1},
                                  {"type": "ward_aniso", "ax": 0.1, "ay": 0.3},
                                  {"type": "stretched_phong", "n": 20, "p": 0.5}])
def test_the_estimate_bounds_the_error_of_a_barely_resolved_table(spec):
    """The quintic spline's error is the larger difference to the cubic's and to the quintic's through every other node:
    with the cubic's alone, Phong n = 20000 (a feature that the sweep's grid barely resolves) was 1.1e-9 off
    with an estimate of 3.5e-10.  Ward's and anisotropic Ward's steep rise at grazing incidence makes the whole table
    miss the tolerance: the table is cut short and the rest is computed afresh
    (scripts/calibration/reuse_calibration.py)."""
    f = pumpup.load(spec)
    pumpup.tabulate(f, mu=MU, progress=False)
    m, e = pumpup.mean_albedo(f, return_error=True)
    ref, ref_e = pumpup.mean_albedo(pumpup.load(spec), rtol=1e-12, return_error=True)  # no table: afresh
    assert abs(m - ref) <= e + ref_e and e <= 1e-9 * m


def test_a_table_whose_grazing_end_is_unresolved_is_cut_short():
    f = pumpup.load({"type": "ward", "m": 0.1})  # the albedo diverges at grazing incidence (001 sec. 2.1)
    pumpup.tabulate(f, mu=MU, progress=False)
    mu, a, e, _ = _reuse.recall(f)
    fresh = _fresh_low(f, 1e-9)
    assert _reuse._mean_of(mu, a, e, 1e-9, fresh)[0] is None  # the whole table misses the tolerance
    calls = []
    reused = _reuse.mean_from_table(f, 1e-9, lambda mu_min, scale: calls.append(mu_min) or fresh(mu_min, scale))
    assert reused is not None
    assert calls[0] == mu[0] and mu[0] < calls[1] <= _reuse.TRUNCATE_MU_MAX  # the second table starts higher


def test_a_table_cut_short_too_far_from_grazing_falls_back():
    f = pumpup.load({"type": "metal", "n": 0, "eta": 0.999, "k": 0.001})  # the albedo rises from mu ~ 0.35
    pumpup.tabulate(f, mu=MU, progress=False)
    assert _reuse.mean_from_table(f, 1e-9, _fresh_low(f, 1e-9)) is None


def test_only_the_tabulated_object_and_a_proportional_unit_model():
    f = pumpup.load({"type": "phong", "n": 20})
    pumpup.tabulate(f, mu=MU, progress=False)
    assert _reuse.recall(f) is not None and _reuse.recall(pumpup.load(f.spec)) is None
    k = _reuse.proportional_factor(f, f.with_params(c=1.0))
    assert abs(k - 2 * np.pi / 22) < 1e-13
    shader = pumpup.load({"type": "phong_shader", "n": 5, "kd": 0.1})  # kd is not scaled with ks
    assert _reuse.proportional_factor(shader, shader.with_params(ks=1.0)) is None


@pytest.mark.slow
@pytest.mark.parametrize("spec", [{"type": "blinn", "n": 16}, {"type": "ward", "m": 0.3},
                                  {"type": "cook_torrance", "m": 0.3}])
def test_reuse_agrees_with_fresh_two_d_models(spec):
    fresh = pumpup.load(spec)
    m0, e0 = pumpup.mean_albedo(fresh, return_error=True)
    x0 = pumpup.max_albedo(fresh)
    f = pumpup.load(spec)
    pumpup.tabulate(f, mu=MU, progress=False)
    m1, e1 = pumpup.mean_albedo(f, return_error=True)
    assert abs(m1 - m0) <= e0 + e1
    x1 = pumpup.max_albedo(f)
    assert abs(x1.albedo - x0.albedo) <= x0.error + x1.error + 1e-12 * x0.albedo


def test_a_table_with_nodes_that_share_theta():
    """Beckmann alpha 0.0052 with Walter's G1: its switch level mu = 0.0083 is a jump of the albedo, and the adaptive
    grid bisected towards it down to the last bit, 70 nodes that share theta = arccos(mu).  The mean from that table
    raised scipy's "Expect x to not have duplicates" (found by scripts/studies/fuzz_engines.py --mean); it keeps the
    last of each now, and agrees with the mean afresh within the two estimates."""
    f = pumpup.load({"type": "beckmann", "alpha": 0.005184313347496449, "g1": "walter"})
    fresh, e_fresh = pumpup.mean_albedo(f, return_error=True)
    mu = pumpup.tabulate(f).mu.values
    s = np.sqrt((1.0 - mu) * (1.0 + mu))
    assert np.any(np.diff(np.arctan2(s, mu)) == 0)  # (the case)
    m, e = pumpup.mean_albedo(f, return_error=True)
    assert abs(m - fresh) <= e + e_fresh
