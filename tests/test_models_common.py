"""Invariants that every registered model must satisfy, run on each model's example specs."""

import json
import math

import numpy as np
import pytest

import pumpup
from pumpup.core import REQUIRED

from helpers import random_directions

CASES = [
    (name, ex)
    for name, cls in pumpup.registry().items()
    for ex in cls.examples
]
IDS = [f"{name}-{json.dumps(ex, sort_keys=True)}" for name, ex in CASES]


def test_every_model_has_examples():
    # "function" needs a registered callable and "pumped" needs tables: tests/test_pump.py covers it
    missing = [name for name, cls in pumpup.registry().items() if name not in ("function", "pumped") and not cls.examples]
    assert not missing, f"models without examples (the common tests skip them): {missing}"


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_kernel_matches_numpy_reference(name, params, rng):
    f = pumpup.load({"type": name, **params})
    wi = random_directions(rng, 4000)
    wo = random_directions(rng, 4000)[::-1]
    # add exact mirror pairs, where the lobes peak
    wo[:200] = wi[:200] * np.array([-1, -1, 1])
    fast = f.eval(wi, wo)
    ref = f.reference(wi, wo)
    np.testing.assert_allclose(fast, ref, rtol=1e-12, atol=1e-300)


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_zero_below_horizon_and_broadcasting(name, params, rng):
    f = pumpup.load({"type": name, **params})
    wi = random_directions(rng, 50, below=0.0)
    wo = random_directions(rng, 7, below=0.0)
    out = f.eval(wi[:, None, :], wo[None, :, :])
    assert out.shape[:2] == (50, 7)
    assert np.all(np.isfinite(out)) and np.all(out >= 0)
    below = wo * np.array([1, 1, -1])
    assert np.all(f.eval(wi[:, None, :], below[None, :, :]) == 0)
    assert np.all(f.eval(below[None, :, :], wi[:, None, :]) == 0)


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_reciprocity_as_declared(name, params):
    f = pumpup.load({"type": name, **params})
    r = pumpup.check_reciprocity(f)
    assert r.reciprocal == f.reciprocal, str(r)


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_spec_round_trip(name, params):
    f = pumpup.load({"type": name, **params})
    text = json.dumps(f.spec)
    g = pumpup.load(json.loads(text))
    assert g == f and g.spec == f.spec
    d = np.array([[0.3, 0.1, math.sqrt(1 - 0.1)], [0.0, 0.0, 1.0]])
    np.testing.assert_array_equal(f.eval(d[0], d[1]), g.eval(d[0], d[1]))


@pytest.mark.parametrize("name", [n for n in pumpup.registry() if n not in ("function", "pumped")])
def test_bad_parameters_name_the_parameter(name):
    cls = pumpup.registry()[name]
    base = dict(cls.examples[0]) if cls.examples else {}
    with pytest.raises(pumpup.SpecError, match="bogus"):
        pumpup.load({"type": name, **base, "bogus": 1})
    for pname, p in cls.params.items():
        if p.kind != "float":
            continue
        with pytest.raises(pumpup.SpecError, match=repr(pname)):
            pumpup.load({"type": name, **base, pname: float("nan")})
        if p.default is REQUIRED:
            spec = {"type": name, **base}
            spec.pop(pname, None)
            with pytest.raises(pumpup.SpecError, match=repr(pname)):
                pumpup.load(spec)
