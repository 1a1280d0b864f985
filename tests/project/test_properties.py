"""Property-based test over every registered model (issue 13, "what must hold").

Generated specs (parameters drawn within and at the edges of their ``Param`` ranges, and
outside them), incidence mu, azimuth phi and engine options: either the albedo is finite
with a finite error estimate, or a clear exception (a ValueError / TypeError subclass whose
message names the argument) is raised, within a time bound.  A fixed seed
(``derandomize=True``) and a bounded number of examples in the default suite; a bigger run
under ``-m slow``.
"""

import math
import time
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import pumpup

#: "function" needs a registered callable; "pumped" builds tables (seconds each): tests/operators/test_pump.py
MODELS = {name: cls for name, cls in pumpup.registry().items() if name not in ("function", "pumped") and cls.examples}
#: the time one example may take (the engine's work limit must stop it before), seconds on a loaded machine
TIME_BOUND = 120.0


def _edge_values(p):
    """Values at and around the ends of a Param's range, inside and just outside."""
    out = []
    for end, is_open, side in ((p.lo, p.lo_open, 1), (p.hi, p.hi_open, -1)):
        if math.isinf(end):
            out += [side * -1e300, side * -1e30, side * -1e9]  # the far end of an unbounded range
            continue
        out.append(end)  # refused if open
        out.append(math.nextafter(end, side * math.inf))
        out.append(math.nextafter(end, -side * math.inf))  # outside: refused
        out.append(end + side * max(abs(end), 1.0) * 1e-9)
        if end == 0.0:
            out += [side * 5e-324, side * 1e-300, side * 1e-30]
    return out


def _value(p, example_values):
    if p.kind == "str":
        return st.sampled_from(p.choices) if p.choices else st.just("x")
    if p.kind == "bool":
        return st.booleans()
    inner_lo = max(p.lo, -1e6) if math.isfinite(p.lo) or True else -1e6
    inner_hi = min(p.hi, 1e6)
    inside = st.floats(min_value=inner_lo, max_value=inner_hi, allow_nan=False, allow_infinity=False)
    choices = [st.sampled_from(_edge_values(p)), inside]
    if example_values:
        choices.append(st.sampled_from(example_values))
    return st.one_of(*choices)


@st.composite
def specs(draw):
    name = draw(st.sampled_from(sorted(MODELS)))
    cls = MODELS[name]
    example = draw(st.sampled_from(cls.examples))
    spec = {"type": name, **example}
    for pname, p in cls.params.items():
        if p.kind == "spec":
            continue
        if not draw(st.booleans()):  # leave half of the parameters at the example's value
            continue
        values = [ex[pname] for ex in cls.examples if pname in ex]
        if p.kind == "floats":
            n = len(spec.get("n", [1.0])) if isinstance(spec.get("n"), list) else 1
            spec[pname] = draw(st.lists(_value(p, [v for vs in values for v in vs]), min_size=n, max_size=n))
        else:
            spec[pname] = draw(_value(p, values))
    return spec


mus = st.one_of(st.sampled_from([1.0, 0.5, 1e-8, 1e-300, 5e-324, 0.999999999]),
                st.floats(min_value=5e-324, max_value=1.0, exclude_min=False))
phis = st.one_of(st.just(0.0), st.floats(min_value=-10.0, max_value=10.0, allow_nan=False))
options = st.fixed_dictionaries({"rtol": st.sampled_from([1e-10, 1e-8, 1e-5]),
                                  "max_regions": st.sampled_from([50, 2000, 20000])})


def _check(spec, mu, phi, opts):
    t0 = time.perf_counter()
    try:
        f = pumpup.load(spec)
    except (ValueError, TypeError) as exc:  # SpecError is a ValueError
        msg = str(exc)
        names = set(spec) | set(MODELS[spec["type"]].params)
        assert "\n" not in msg.strip() and ("parameter" in msg or any(f"'{k}'" in msg for k in names)), msg
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # AlbedoWarning: the tolerance not met, the error says by how much
        try:
            a, e = pumpup.albedo(f, mu, phi=phi, return_error=True, **opts)
        except (ValueError, TypeError) as exc:
            msg = str(exc)
            assert any(w in msg for w in ("mu", "phi", "parameter", "rtol", "atol", "max_regions")), msg
            return
    elapsed = time.perf_counter() - t0
    assert np.isfinite(a) and np.isfinite(e) and e >= 0, (spec, mu, phi, a, e)
    assert a >= -e, (spec, mu, a, e)
    assert elapsed < TIME_BOUND, (spec, mu, elapsed)


@settings(max_examples=40, derandomize=True, deadline=None, suppress_health_check=list(HealthCheck))
@given(spec=specs(), mu=mus, phi=phis, opts=options)
def test_albedo_is_finite_or_refused(spec, mu, phi, opts):
    _check(spec, mu, phi, opts)


@pytest.mark.slow
@settings(max_examples=600, derandomize=False, database=None, deadline=None, suppress_health_check=list(HealthCheck))
@given(spec=specs(), mu=mus, phi=phis, opts=options)
def test_albedo_is_finite_or_refused_many(spec, mu, phi, opts):
    _check(spec, mu, phi, opts)
