"""Engine, table and spec arguments are checked like model parameters (issue 13, items 7 and 13):
one clear error naming the argument, never a TypeError deep inside, a hang or a RecursionError."""

import numpy as np
import pytest

import pumpup
from pumpup.core import SpecError

PHONG = pumpup.load({"type": "phong", "n": 20})


@pytest.mark.parametrize("kw, name", [
    ({"rtol": 0}, "rtol"), ({"rtol": -1e-9}, "rtol"), ({"rtol": float("nan")}, "rtol"),
    ({"rtol": None}, "rtol"), ({"rtol": "1e-9"}, "rtol"), ({"rtol": float("inf")}, "rtol"),
    ({"atol": -1e-9}, "atol"), ({"atol": float("nan")}, "atol"), ({"atol": [1e-9]}, "atol"),
    ({"max_regions": -1}, "max_regions"), ({"max_regions": float("inf")}, "max_regions"),
    ({"max_regions": 2.5}, "max_regions"), ({"max_regions": 10**400}, "max_regions"),
    ({"max_regions": True}, "max_regions"),
])
def test_albedo_engine_arguments(kw, name):
    with pytest.raises(SpecError, match=rf"albedo: {name} must be"):
        pumpup.albedo(PHONG, 0.5, **kw)


@pytest.mark.parametrize("kw, name", [
    ({"rtol": 0}, "rtol"), ({"atol": None}, "atol"), ({"atol": -1.0}, "atol"), ({"interp_tol": 0}, "interp_tol"),
    ({"mu_min": 0}, "mu_min"), ({"mu_min": 1}, "mu_min"), ({"mu_min": float("nan")}, "mu_min"),
    ({"max_points": 1}, "max_points"), ({"max_points": float("inf")}, "max_points"),
    ({"max_points": 10**400}, "max_points"),
])
def test_tabulate_arguments(kw, name):
    with pytest.raises(SpecError, match=rf"tabulate: {name} must be"):
        pumpup.tabulate(PHONG, **kw)


def test_mean_and_max_albedo_arguments():
    with pytest.raises(SpecError, match="mean_albedo: rtol"):
        pumpup.mean_albedo(PHONG, rtol=0)
    with pytest.raises(SpecError, match="mean_albedo: max_intervals"):
        pumpup.mean_albedo(PHONG, max_intervals=-1)
    with pytest.raises(SpecError, match="max_albedo: mu_min"):
        pumpup.max_albedo(PHONG, mu_min=0)
    with pytest.raises(SpecError, match="max_albedo: rtol"):
        pumpup.max_albedo(PHONG, rtol=float("nan"))
    with pytest.raises(TypeError, match="tabulate needs a pumpup BRDF"):
        pumpup.tabulate({"type": "phong", "n": 20})


@pytest.mark.parametrize("levels", [0, 100000, float("inf"), 2.5, "two", None, True])
def test_pump_levels(levels):
    with pytest.raises(SpecError, match="levels"):
        pumpup.pump(PHONG, levels=levels)


@pytest.mark.parametrize("levels", [100000, float("inf"), float("nan"), -3])
def test_pumped_spec_levels(levels):
    with pytest.raises(SpecError, match="'levels'"):
        pumpup.load({"type": "pumped", "base": {"type": "phong", "n": 2}, "levels": levels})


def test_spec_values_and_keys():
    with pytest.raises(SpecError, match=r"'c' is too large for a float \(about 401 digits\)"):
        pumpup.load({"type": "phong", "n": 20, "c": 10**400})
    with pytest.raises(SpecError, match="'type' must be a model name"):
        pumpup.load({"type": ["phong"]})
    with pytest.raises(SpecError, match="spec keys must be parameter names"):
        pumpup.load({"type": "phong", "n": 20, 3: 1})
    with pytest.raises(SpecError, match="unknown model type"):
        pumpup.sweep({"type": ["phong"]}, {"n": [1, 2]})
    with pytest.raises(SpecError, match="sweep: rtol"):
        pumpup.sweep({"type": "phong"}, {"n": [1, 2]}, rtol=0)


def test_mismatched_broadcast_of_wi_and_wo():
    wi = np.tile([0.0, 0.0, 1.0], (3, 1))
    wo = np.tile([0.0, 0.0, 1.0], (4, 1))
    for f in (PHONG, pumpup.load({"type": "ward", "m": 0.2})):
        with pytest.raises(ValueError, match=r"wi and wo must broadcast.*\(3, 3\).*\(4, 3\)"):
            f.eval(wi, wo)


# --- item 13: the short spec form everywhere ---------------------------------------------------

def test_short_spec_in_load_pump_and_sweep():
    assert pumpup.load("phong:n=20") == PHONG
    assert pumpup.load("phong:n=20,c=1").p["c"] == 1.0
    assert pumpup.load("lambert") == pumpup.load({"type": "lambert"})
    assert pumpup.load(' {"type": "phong", "n": 20}') == PHONG
    p = pumpup.pump("phong:n=20", g="g2")
    assert p.base == PHONG and p.p["g"] == "g2"
    ds = pumpup.sweep("lambert", {"albedo": [0.25, 0.5]}, mu=[0.5, 1.0], scheduler="synchronous",
                      mean=False, maximum=False, progress=False)
    assert ds["albedo"].values.round(12).tolist() == [[0.25, 0.25], [0.5, 0.5]]
    ds = pumpup.sweep("stretched_phong:p=0.5", {"n": [2.0]}, mu=[1.0], scheduler="synchronous",
                      mean=False, maximum=False, progress=False)
    assert ds.attrs["spec"] == '{"p": 0.5, "type": "stretched_phong"}'
    for bad, match in [("phong:n", "must look like name=value"), (":n=2", "model type before"),
                       ("{not json", "not valid JSON"), ("[1, 2]", "unknown model type")]:
        with pytest.raises(SpecError, match=match):
            pumpup.load(bad)
