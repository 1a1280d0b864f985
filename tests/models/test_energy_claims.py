"""Every claim of energy conservation a model's checks make is true (issue 13 item 6b)."""

import numpy as np
import pytest

import pumpup
from pumpup.models.metal import PLASTIC_MAX_S, _plastic_max_s

MU = np.concatenate([np.cos(np.radians(np.linspace(0, 89.9, 30))), [1e-3, 1e-5, 1e-8]])


def _max_albedo_bound(f):
    """max over a scan of mu of albedo + error: what 'conserves energy' must keep <= 1."""
    a, e = pumpup.albedo(f, MU, return_error=True, rtol=1e-9)
    return float(np.max(a - e)), float(np.max(a + e))


@pytest.mark.parametrize("n", [0.0, 0.2])
def test_plastic_refuses_what_reflects_more_than_it_receives(n):
    # the issue: n = 0, a_s = 1 has a maximum albedo of 1.0858 at 45 degrees (n = 0.2: 1.041);
    # a_s + ad <= 1 let it through
    lobe = pumpup.load({"type": "stretched_phong", "n": n})  # plastic's lobe with a_s = 1, F = 1
    lo, _ = _max_albedo_bound(lobe)
    assert lo > 1.04
    with pytest.raises(pumpup.SpecError, match="'a_s' must be at most"):
        pumpup.load({"type": "plastic", "n": n, "ad": 0.0, "a_s": 1.0})


@pytest.mark.parametrize("spec", [{"n": 0.0, "ad": 0.0, "a_s": 0.92}, {"n": 0.0, "ad": 0.5, "a_s": 0.46},
                                  {"n": 2.0, "ad": 0.0, "a_s": 1.0}, {"n": 0.0, "ad": 0.0, "a_s": 1.0, "eta": 1.5},
                                  {"n": 20, "ad": 0.5, "a_s": 0.5}])
def test_accepted_plastic_conserves_energy(spec):
    f = pumpup.load({"type": "plastic", **spec})
    lo, _ = _max_albedo_bound(f)
    assert lo <= 1.0


def test_plastic_bound_holds_at_its_worst():
    # PLASTIC_MAX_S (the cheap check) must bound max S; it is attained at n = 0
    s0 = _plastic_max_s(0.0, None)
    assert 1.0857 < s0 <= PLASTIC_MAX_S


@pytest.mark.slow
def test_plastic_max_s_falls_with_n_and_is_one_from_n_2():
    # the cheap check uses max S <= PLASTIC_MAX_S for n < 2 and max S = 1 for n >= 2
    ns = [0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0]
    s = [_plastic_max_s(n, None) for n in ns]
    assert all(b <= a for a, b in zip(s, s[1:]))
    for n in (2.0, 3.0, 10.0, 100.0, 1e4):
        assert _plastic_max_s(n, None) <= 1.0 + 1e-8


@pytest.mark.parametrize("spec", [{"type": "lambert", "albedo": 1.0},
                                  {"type": "lewis_phong", "n": 0}, {"type": "lewis_phong", "n": 1},
                                  {"type": "lewis_phong", "n": 50, "k_sigma": 0.5},
                                  {"type": "phong", "n": 0}, {"type": "phong", "n": 1}, {"type": "phong", "n": 50},
                                  {"type": "oren_nayar", "albedo": 1.0, "sigma": 0.0}])
def test_other_energy_claims(spec):
    # lambert's albedo <= 1, Lewis's energy-conserving shader (k_rho <= 1), Phong's (n + 2)/(2 pi)
    # "the largest c that conserves energy" (000 eq. 6)
    lo, _ = _max_albedo_bound(pumpup.load(spec))
    assert lo <= 1.0


@pytest.mark.parametrize("n, ad", [(0.0, 0.3), (0.5, 0.1), (0.2, 0.0), (1.0, 0.5), (0.05, 0.7)])
def test_plastics_advice_on_a_s_can_be_followed(n, ad):
    """The error names the largest a_s energy conservation allows, rounded down to its 6 digits: a plastic with that
    a_s loads (rounded to nearest, the advice could be refused)."""
    import re

    with pytest.raises(pumpup.SpecError, match="must be at most") as exc:
        pumpup.load({"type": "plastic", "n": n, "ad": ad, "a_s": 1.0 - ad})
    limit = float(re.search(r"at most ([0-9.e+-]+);", str(exc.value)).group(1))
    pumpup.load({"type": "plastic", "n": n, "ad": ad, "a_s": limit})
