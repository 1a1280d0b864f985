"""The BRDF interface: specs, registry, input checks, user functions, reciprocity check."""

import json

import helpers
import numpy as np
import pytest

import pumpup
from pumpup.core import SpecError


def test_unknown_type_lists_known_types():
    with pytest.raises(pumpup.SpecError, match="unknown model type 'nope'.*phong"):
        pumpup.load({"type": "nope"})


def test_spec_must_be_dict_with_type():
    with pytest.raises(pumpup.SpecError, match="'type'"):
        pumpup.load({"n": 3})
    with pytest.raises(pumpup.SpecError):
        pumpup.load(["phong"])
    with pytest.raises(pumpup.SpecError, match="JSON"):
        pumpup.load("{not json")


def test_spec_never_evaluates_code():
    # a string where a number belongs is refused, not evaluated
    with pytest.raises(pumpup.SpecError, match="'n'"):
        pumpup.load({"type": "phong", "n": "__import__('os').system('true')"})


@pytest.mark.parametrize("bad", [-1, -1e-9, float("inf"), True, None])
def test_negative_or_nonfinite_exponent(bad):
    with pytest.raises(pumpup.SpecError, match="'n'"):
        pumpup.load({"type": "phong", "n": bad})


def test_zero_exponent_is_allowed():
    assert pumpup.load({"type": "phong", "n": 0}).spec["n"] == 0.0


def test_p_range():
    with pytest.raises(pumpup.SpecError, match=r"'p'.*\[0, 1\]"):
        pumpup.load({"type": "stretched_phong", "n": 3, "p": 1.5})


def test_json_string_spec():
    f = pumpup.load('{"type": "phong", "n": 4}')
    assert f.spec["n"] == 4.0


def test_eval_rejects_non_unit_and_bad_shapes():
    f = pumpup.load({"type": "phong", "n": 4})
    with pytest.raises(ValueError, match="unit"):
        f.eval([0, 0, 2], [0, 0, 1])
    with pytest.raises(ValueError, match="3 components"):
        f.eval([0, 1], [0, 0, 1])
    with pytest.raises(ValueError, match="non-finite"):
        f.eval([np.nan, 0, 1], [0, 0, 1])


def test_closed_form_values_phong_family():
    n = 20.0
    c = (n + 2) / (2 * np.pi)
    N = np.array([0.0, 0.0, 1.0])
    phong = pumpup.load({"type": "phong", "n": n})
    assert phong.eval(N, N) == pytest.approx(c, rel=1e-15)
    # mirror direction at theta: reciprocal Phong gives c, stretched Phong c / cos(theta)
    th = np.radians(70.0)
    wi = np.array([np.sin(th), 0, np.cos(th)])
    wo = np.array([-np.sin(th), 0, np.cos(th)])
    assert phong.eval(wi, wo) == pytest.approx(c, rel=1e-13)
    sp = pumpup.load({"type": "stretched_phong", "n": n})
    assert sp.eval(wi, wo) == pytest.approx(c / np.cos(th), rel=1e-13)
    # p-model: c / cos^p
    pm = pumpup.load({"type": "stretched_phong", "n": n, "p": 0.5})
    assert pm.eval(wi, wo) == pytest.approx(c / np.cos(th) ** 0.5, rel=1e-13)
    # (R.V) = cos(alpha) off the mirror direction, in the plane of incidence
    a = np.radians(10.0)
    wo2 = np.array([-np.sin(th - a), 0, np.cos(th - a)])
    assert phong.eval(wi, wo2) == pytest.approx(c * np.cos(a) ** n, rel=1e-12)
    assert sp.eval(wi, wo2) == pytest.approx(c * np.cos(a) ** n / np.cos(th - a), rel=1e-12)
    # retro-reflective peaks back towards the light
    retro = pumpup.load({"type": "retro", "n": n})
    assert retro.eval(wi, wi) == pytest.approx(c / np.cos(th), rel=1e-13)
    # Phong's shader divides by N.L
    shader = pumpup.load({"type": "phong_shader", "n": n, "kd": 0.1})
    assert shader.eval(wi, wo) == pytest.approx(0.1 + c / np.cos(th), rel=1e-13)


def test_from_function_round_trip_and_checks():
    f = pumpup.from_function(lambda wi, wo: np.full(np.broadcast_shapes(wi.shape, wo.shape)[:-1], 0.2), name="flat")
    g = pumpup.load(f.spec)
    assert g.spec == {"type": "function", "name": "flat"}
    assert g.eval([0, 0, 1], [0, 0, 1]) == 0.2
    assert g.eval([0, 0, 1], [0, 0, -1]) == 0.0  # below the horizon
    bad = pumpup.from_function(lambda wi, wo: -np.ones(np.broadcast_shapes(wi.shape, wo.shape)[:-1]), name="neg")
    with pytest.raises(ValueError, match="non-negative"):
        bad.eval([0, 0, 1], [0, 0, 1])
    nan = pumpup.from_function(lambda wi, wo: wi[..., 0] * np.nan, name="nan")
    with pytest.raises(ValueError, match="finite"):
        nan.eval([0, 0, 1], [0, 0, 1])
    with pytest.raises(pumpup.SpecError, match="no function named"):
        pumpup.load({"type": "function", "name": "never-registered"})
    with pytest.raises(TypeError):
        pumpup.from_function(3)


def test_from_function_isotropic_claim_is_checked():
    """isotropic=True: the albedo has no azimuth of wi (azimuth_range None, one table when pumped); the claim is
    measured on random pairs turned about N, and a function that changes is refused with the pair and the change,
    leaving no registration behind."""
    def phong(wi, wo):
        return 3.0 * np.maximum(2 * wi[..., 2] * wo[..., 2] - np.sum(wi * wo, axis=-1), 0.0) ** 4

    assert pumpup.from_function(phong, name="iso-phong", isotropic=True).azimuth_range() is None
    assert pumpup.from_function(phong, name="any-phong").azimuth_range() == pytest.approx(2 * np.pi)

    def tilted(wi, wo):  # depends on the azimuth of wi: anisotropic
        return 0.2 + 0.01 * wi[..., 0] + 0.0 * wo[..., 0]

    with pytest.raises(ValueError, match=r"isotropic=True, but 'tilted' changes by .* when wi=\[.*turn about N"):
        pumpup.from_function(tilted, name="tilted", isotropic=True)
    with pytest.raises(pumpup.SpecError, match="no function named 'tilted'"):
        pumpup.load({"type": "function", "name": "tilted"})
    # a function that fails on the check's pairs fails there, with its own clear error
    with pytest.raises(ValueError, match="non-negative"):
        pumpup.from_function(lambda wi, wo: -np.ones(np.broadcast_shapes(wi.shape, wo.shape)[:-1]), name="neg-iso",
                             isotropic=True)


def test_check_reciprocity_finds_asymmetry_and_reports_worst_pair():
    def lopsided(wi, wo):
        return 0.1 + 0.05 * wi[..., 2] * (1 - wo[..., 2])

    r = pumpup.check_reciprocity(pumpup.from_function(lopsided, name="lopsided", reciprocal=False))
    assert not r.reciprocal
    assert r.max_rel_error > 0.1
    assert r.worst_wi.shape == (3,) and "NOT reciprocal" in str(r)
    # the reported pair really is asymmetric by the reported amount
    fw = lopsided(r.worst_wi, r.worst_wo)
    bw = lopsided(r.worst_wo, r.worst_wi)
    assert abs(fw - bw) / max(fw, bw) == pytest.approx(r.max_rel_error, rel=1e-12)


def test_direction_set_includes_grazing():
    from pumpup.core import direction_set

    d = direction_set()
    assert d[:, 2].min() <= 1e-8 and d[:, 2].max() == 1.0
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1.0, rtol=1e-15)


def test_first_loads_from_many_threads_see_the_whole_registry():
    """The registry imports its providers on first use; a thread that loads while another is still importing them waits
    for them (a Mitsuba scene instantiates pumpup's plugins from its own threads: 'unknown model type' before)."""
    import os
    import subprocess
    import sys

    code = ("import threading, pumpup\n"
            "errors = []\n"
            "def load():\n"
            "    try:\n"
            "        pumpup.load({'type': 'fresnel', 'base': {'type': 'phong', 'n': 20}, 'eta': 0.5, 'k': 2.0})\n"
            "    except Exception as exc:\n"
            "        errors.append(repr(exc))\n"
            "threads = [threading.Thread(target=load) for _ in range(8)]\n"
            "[t.start() for t in threads]\n"
            "[t.join() for t in threads]\n"
            "print(errors)\n")
    root = str(helpers.ROOT)
    env = dict(os.environ, PYTHONPATH=root)
    for _ in range(3):
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
        assert r.returncode == 0 and r.stdout.strip() == "[]", (r.stdout, r.stderr[-2000:])

# --- arguments checked like model parameters (issue 13, items 7 and 13): one clear error naming the argument, never
# a TypeError deep inside, a hang or a RecursionError ------------------------------------------------------------

PHONG = pumpup.load({"type": "phong", "n": 20})


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


def test_a_spec_nested_too_deep_is_refused_in_one_line():
    spec = {"type": "lambert"}
    for _ in range(500):
        spec = {"type": "pumped", "base": spec}
    with pytest.raises(pumpup.SpecError, match="at most 64 levels deep"):
        pumpup.load(spec)
    with pytest.raises(pumpup.SpecError, match="at most 64 levels deep"):
        pumpup.load(json.dumps(spec))
    ok = {"type": "lambert"}
    for _ in range(20):
        ok = {"type": "pumped", "base": ok}
    assert pumpup.load(ok).depth == 20
