"""Invariants that every registered model must satisfy, run on each model's example specs."""

import json
import math

import numpy as np
import pytest
from helpers import direction_pairs, random_directions

import pumpup
from pumpup.core import REQUIRED

CASES = [
    (name, ex)
    for name, cls in pumpup.registry().items()
    for ex in cls.examples
]
IDS = [f"{name}-{json.dumps(ex, sort_keys=True)}" for name, ex in CASES]


def test_every_model_has_examples():
    # "function" needs a registered callable and "pumped" needs tables: tests/operators/test_pump.py covers it
    missing = [name for name, cls in pumpup.registry().items()
               if name not in ("function", "pumped") and not cls.examples]
    assert not missing, f"models without examples (the common tests skip them): {missing}"


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_kernel_matches_numpy_reference(name, params, rng):
    f = pumpup.load({"type": name, **params})
    # random pairs (some below the horizon, some near grazing), exact mirror pairs where the
    # lobes peak, pairs at mu = 1e-8 exactly and grazing near-opposite pairs
    wi, wo = direction_pairs(rng)
    fast = f.eval(wi, wo)
    ref = f.reference(wi, wo)
    assert np.all(np.isfinite(fast)) and np.all(fast >= 0)
    np.testing.assert_allclose(fast, ref, rtol=1e-12, atol=0)
    below = (wi[:, 2] <= 0) | (wo[:, 2] <= 0)
    assert below.any() and np.all(fast[below] == 0)


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


def test_declared_reciprocity():
    # pins what test_reciprocity_as_declared measures against: every built-in model is
    # declared reciprocal except Lewis's shader and the Phong shader (and the 1/E scaling operator)
    not_reciprocal = sorted(name for name, cls in pumpup.registry().items() if not cls.reciprocal)
    assert not_reciprocal == ["lewis_phong", "phong_shader", "scaled"]


@pytest.mark.parametrize("name,params", CASES, ids=IDS)
def test_spec_round_trip(name, params):
    f = pumpup.load({"type": name, **params})
    text = json.dumps(f.spec)
    g = pumpup.load(json.loads(text))
    assert g == f and g.spec == f.spec
    assert pumpup.load(f.spec) == f
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
