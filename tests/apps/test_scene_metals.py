"""The measured metals of the path-traced scenes (issue 19 item 4): the ``fresnel`` model (a base BRDF x
F(Theta_min)), the scenes' per-channel specs against the spectral metals, and the Mitsuba plugin's
translation of ``fresnel`` over a pumped lobe."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import direction_pairs

import pumpup
import pumpup.scenes as S
from pumpup import spectral
from pumpup.models.metal import fresnel
from pumpup.spectral import optical


def _up_pairs(rng, m=400):
    x = rng.normal(size=(2, m, 3))
    x[..., 2] = np.abs(x[..., 2])
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    return x[0], x[1]


def test_fresnel_over_stretched_phong_is_metal(rng):
    """``fresnel`` over the F = 1 lobe of 000 eq. 28 is ``metal`` (bit for bit: the same product)."""
    f = pumpup.load({"type": "fresnel", "base": {"type": "stretched_phong", "n": 40, "p": 1.0}, "eta": 0.3, "k": 2.5})
    g = pumpup.load({"type": "metal", "n": 40, "eta": 0.3, "k": 2.5})
    wi, wo = direction_pairs(rng)
    np.testing.assert_allclose(f.eval(wi, wo), g.eval(wi, wo), rtol=1e-14, atol=0)
    a, e = pumpup.albedo(f, [1.0, 0.3, 1e-3], return_error=True)
    b, eb = pumpup.albedo(g, [1.0, 0.3, 1e-3], return_error=True)
    assert np.all(np.abs(a - b) <= e + eb)


def test_fresnel_over_pumped_lobe_is_the_colour_keeping_metal(rng):
    """Per channel, ``fresnel`` over the pumped F = 1 lobe equals SpectralPumpedLobe's eval; reciprocal;
    each channel's albedo is at most the pumped lobe's (0 <= F <= 1) and at most 1, within the errors."""
    gold = spectral.SpectralMetal("Au", n=20, wavelengths="rgb")
    keep = spectral.SpectralPumpedLobe(gold)
    lobe = {"type": "pumped", "base": {"type": "stretched_phong", "n": 20.0, "p": 1.0, "c": gold.c}, "g": "g1",
            "levels": 1}
    chans = [pumpup.load({"type": "fresnel", "base": lobe, "eta": e, "k": k}) for e, k in zip(gold.eta, gold.k)]
    wi, wo = _up_pairs(rng)
    ref = keep.eval(wi, wo)
    for c, f in enumerate(chans):
        np.testing.assert_allclose(f.eval(wi, wo), ref[:, c], rtol=1e-13, atol=0)
        np.testing.assert_allclose(f.eval(wi, wo), f.reference(wi, wo), rtol=1e-12, atol=0)
    r = pumpup.check_reciprocity(chans[0])
    assert r.reciprocal and chans[0].reciprocal, str(r)
    mus = [1.0, 0.2, 1e-3]
    la, le = pumpup.albedo(chans[0].base, mus, return_error=True)
    for f in chans:
        a, e = pumpup.albedo(f, mus, return_error=True)
        assert np.all(a - e <= la + le) and np.all(a - e <= 1.0)
    red, blue = (float(pumpup.albedo(f, 1.0)) for f in (chans[0], chans[2]))
    assert red > blue  # still gold after pumping
    assert pumpup.load(chans[1].spec) == chans[1]


def test_fresnel_refuses_bad_input():
    with pytest.raises(pumpup.SpecError, match="'eta'"):
        pumpup.load({"type": "fresnel", "base": {"type": "phong", "n": 20}, "eta": -1.0})
    with pytest.raises(pumpup.SpecError, match="'base'"):
        pumpup.load({"type": "fresnel", "base": 3, "eta": 1.5})
    with pytest.raises(pumpup.SpecError, match="'base'"):
        pumpup.load({"type": "fresnel", "base": {"type": "metal", "material": "Au", "n": 20}, "eta": 1.5})


@pytest.mark.parametrize("colour", ["gold", "copper", "silver", "aluminium"])
def test_scene_metals_are_the_measured_metals_per_channel(colour, rng):
    """The scenes' channel values equal the measured metal at the RGB wavelengths: "stretched" is
    SpectralMetal(material, n, "rgb") channel by channel; "phong" and "pumped" are their lobes times the
    complex-arithmetic Fresnel factor of the measured index (an independent formula)."""
    material = S.METALS[colour]
    wi, wo = _up_pairs(rng, 200)
    eta, k = optical.constants(material, list(spectral.RGB_WAVELENGTHS))
    mx = np.maximum(wi[:, 2], wo[:, 2])
    n = 40.0
    stretched = [pumpup.load(s) for s in S.metal(colour, n, "stretched")[0][1]]
    ref = spectral.SpectralMetal(material, n=n, wavelengths="rgb").eval(wi, wo)
    for c in range(3):
        np.testing.assert_allclose(stretched[c].eval(wi, wo), ref[:, c], rtol=1e-12, atol=0)
    for kind, lobe in (("phong", {"type": "phong", "n": n}),
                       ("pumped", {"type": "pumped", "base": {"type": "phong", "n": n}, "g": "g1", "levels": 1})):
        chans = [pumpup.load(s) for s in S.metal(colour, n, kind)[0][1]]
        base = pumpup.load(lobe).eval(wi, wo)
        for c in range(3):
            np.testing.assert_allclose(chans[c].eval(wi, wo), base * fresnel(mx, eta[c], k[c]), rtol=1e-12, atol=0)
    # F0 per channel is the database's ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2)
    f0 = ((eta - 1) ** 2 + k**2) / ((eta + 1) ** 2 + k**2)
    got = [float(s.eval([0, 0, 1], [0, 0, 1]) / (s.p["c"])) for s in stretched]
    np.testing.assert_allclose(got, f0, rtol=1e-12)
    with pytest.raises(ValueError, match="kind"):
        S.metal(colour, n, "shiny")


mi = pytest.importorskip("mitsuba")
pm = pytest.importorskip("pumpup.mitsuba")
LLVM_OK, LLVM_WHY = pm.probe("llvm_ad_rgb")


@pytest.mark.skipif(not LLVM_OK, reason=f"llvm_ad_rgb unusable here: {LLVM_WHY}")
def test_plugin_translates_fresnel_over_pumped(rng):
    """The plugin's value of a scene's pumped gold equals pumpup's per channel within one float32 rounding
    plus the pumped chain's rounding down, and never exceeds it."""
    import drjit as dr

    pm.register("llvm_ad_rgb")
    specs = S.metal("gold", 20, "pumped")[0][1]
    b = pm.load_dict({"type": "pumpup", "spec": specs})
    wi, wo = _up_pairs(rng, 2000)
    wi = wi.astype(np.float32).astype(np.float64)
    wo = wo.astype(np.float32).astype(np.float64)
    si = dr.zeros(mi.SurfaceInteraction3f, len(wi))
    si.wi = mi.Vector3f(*(mi.Float(wo[:, i].astype(np.float32)) for i in range(3)))
    w = mi.Vector3f(*(mi.Float(wi[:, i].astype(np.float32)) for i in range(3)))
    got = np.array(b.eval(mi.BSDFContext(), si, w), dtype=np.float64)
    tiny = np.finfo(np.float32).tiny
    tol = 2.0**-23 + 2.0**-24 + 1e-12
    for c, s in enumerate(specs):
        ref = pumpup.load(s).eval(wi, wo) * wi[:, 2]
        assert np.all(np.abs(got[c] - ref) <= np.maximum(tol * ref, tiny))
        assert np.all(got[c] <= ref * (1 + 1e-12) + tiny)
        assert np.sum(ref > 1e-30) > 500
    assert np.mean(got[0]) > np.mean(got[2])  # red above blue
