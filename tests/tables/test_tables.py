"""Albedo tables: adaptive grid, metadata, exact netCDF round trip, atomic writing, clear errors,
interpolation error between the nodes, mean albedo and maximum constants."""

import json
import os

import numpy as np
import pytest
import xarray as xr

import pumpup
from pumpup.core import SpecError


@pytest.fixture(scope="module")
def phong_table():
    return pumpup.tabulate(pumpup.load({"type": "phong", "n": 20}), interp_tol=1e-8)


def test_dataset_layout_and_metadata(phong_table):
    ds = phong_table
    assert set(ds.data_vars) == {"albedo", "albedo_error"}
    assert ds["mu"].attrs["units"] == "1" and ds["theta"].attrs["units"] == "degree"
    np.testing.assert_allclose(ds["theta"], np.degrees(np.arccos(ds["mu"])))
    assert json.loads(ds.attrs["spec"]) == pumpup.load({"type": "phong", "n": 20}).spec
    assert ds.attrs["pumpup_version"] == pumpup.__version__
    assert ds.attrs["rtol"] > 0 and "Gauss-Kronrod" in ds.attrs["method"]
    assert ds["mu"].min() <= 1e-8 and ds["mu"].max() == 1.0
    assert np.all(np.diff(ds["mu"]) > 0)


def test_adaptive_grid_interpolation_error_is_honest_between_nodes(phong_table):
    table = pumpup.AlbedoTable.from_dataset(phong_table)
    f = pumpup.load({"type": "phong", "n": 20})
    mu = np.sort(10 ** np.random.default_rng(5).uniform(-8, 0, 300))
    miss = np.abs(table(mu) - pumpup.albedo(f, mu))
    assert table.interp_error <= 1e-8
    assert miss.max() <= table.SAFETY * table.interp_error
    assert np.all(table.upper(mu) >= pumpup.albedo(f, mu))


def test_interpolation_error_is_honest_between_nodes_for_a_diverging_albedo():
    """Ward's albedo grows like mu^(-1/2) at grazing: the quintic's miss between the nodes stays
    within the bound that upper() adds."""
    f = pumpup.load({"type": "ward", "m": 0.1})
    table = pumpup.AlbedoTable.from_dataset(pumpup.tabulate(f, rtol=1e-9, progress=False))
    assert table.degree == 5
    mu = np.sort(10 ** np.random.default_rng(6).uniform(-8, 0, 60))
    a = pumpup.albedo(f, mu, rtol=1e-10)
    assert np.abs(table(mu) - a).max() <= table.SAFETY * table.interp_error
    assert np.all(table.upper(mu) >= a)


def _fake_values(monkeypatch, fn):
    """tabulate's values from ``fn(mu)`` (no quadrature; error 1e-16): its adaptive grid alone under test."""
    from pumpup.tables import azimuth

    def table_values(brdf, phi, rtol, atol, threads, interp_tol):
        return (lambda mu, bar: (fn(mu), np.full(mu.shape, 1e-16))), None, None

    monkeypatch.setattr(azimuth, "table_values", table_values)


def test_adaptive_grid_splits_no_interval_below_the_doubles_of_log_mu(monkeypatch):
    """A jump the grid does not know of, at mu = 1.1e-8 (where log(mu)'s doubles are 25 times coarser than mu's): the
    bisection closes in on it, splits no interval whose midpoint is not a new value of log(mu), and counts the last
    one's spread, the jump, as interpolation error: the spline takes one end's value at every mu within it.  Splitting
    down to two nodes of one log(mu) would raise scipy's ValueError (a divergent albedo does it under its own
    noise)."""
    from pumpup import tables

    _fake_values(monkeypatch, lambda mu: np.where(mu > 1.1e-8, 2.0, 1.0) + mu)
    ds = pumpup.tabulate(pumpup.load({"type": "lambert"}), progress=False)
    mu = ds["mu"].values
    lx = np.log(mu)
    assert np.all(np.diff(lx) > 0)
    last = np.flatnonzero(~tables._splittable(mu))
    assert len(last) and np.all(np.abs(mu[last] / 1.1e-8 - 1.0) < 1e-10)  # (it did close in, and only there)
    assert ds.attrs["interpolation_error"] >= 1.0  # (the jump; not the 1e-7 of the smooth parts)


def test_a_jump_of_the_albedo_counts_in_the_margin():
    """Beckmann alpha 0.0052 with Walter's G1, whose switch level mu = 0.0083 is a jump of 5.3e-5 in the albedo: the
    grid closes in on it to an interval 5 doubles wide whose midpoint is no new log(mu), and at the 4 doubles inside it
    the table is off by the jump.  Its margin covers them (a margin of 2e-7 would not)."""
    from pumpup.models.microfacet import walter_level

    alpha = 0.005184313347496449
    f = pumpup.load({"type": "beckmann", "alpha": alpha, "g1": "walter"})
    table = pumpup.AlbedoTable.from_dataset(pumpup.tabulate(f, progress=False))
    i = np.searchsorted(table.mu, walter_level(alpha))
    inside = [np.nextafter(table.mu[i - 1], 1.0)]
    while inside[-1] < table.mu[i]:
        inside.append(np.nextafter(inside[-1], 1.0))
    inside = np.array(inside[:-1])
    fresh, err = pumpup.albedo(f, inside, rtol=1e-12, return_error=True)
    assert len(inside) and np.abs(table(inside) - fresh).max() > 1e-5  # (the case)
    assert np.all(np.abs(table(inside) - fresh) <= table.margin + err)


def test_the_interval_at_the_normal_is_checked_below_its_midpoint():
    """A g1 pumped plastic with n = 5284: its lobe reaches the normal below theta ~ 1 degree, inside the grid's last
    interval [0.9988, 1], whose midpoint in log(mu) lies at theta = 2 degrees.  The table was 3.1e-7 off at mu =
    0.99995 with a margin of 2.0e-7 (scripts/studies/fuzz_engines.py --tables 43); the checks at 1 - mu = (1 - a) 2^-k
    count in its interpolation error now."""
    spec = {"type": "pumped", "base": {"type": "plastic", "n": 5284.234871880557, "ad": 0.2771143076394261,
                                       "a_s": 0.047413995704811085}, "g": "g1", "levels": 1}
    f = pumpup.load(spec)
    table = pumpup.AlbedoTable.from_dataset(pumpup.tabulate(f, progress=False))
    mu = np.linspace(0.999, 1.0, 41)
    fresh, err = pumpup.albedo(f, mu, rtol=1e-12, return_error=True)
    assert np.abs(table(mu) - fresh).max() > 2.5e-7  # (the case: beyond the old margin)
    assert np.all(np.abs(table(mu) - fresh) <= table.margin + err)


def test_a_model_that_reads_tables_is_checked_off_the_dyadic_points():
    """Kulla-Conty over Torrance-Sparrow D1 (s 844, ior 1.53) reads its base's E table, whose interpolant is exact at
    the same nodes and midpoints this grid checks: its table claimed a margin of 5.9e-9 and was 6.0e-8 off at mu = 0.039
    (scripts/studies/fuzz_engines.py --tables 44).  The thirds of every interval count now (tables.built_on_tables)."""
    spec = {"type": "kulla_conty", "base": {"type": "torrance_sparrow", "d": "D1", "s": 843.9511741619182,
                                            "ior": 1.5263287885853667}}
    assert pumpup.tables.built_on_tables(spec) and not pumpup.tables.built_on_tables(spec["base"])
    f = pumpup.load(spec)
    table = pumpup.AlbedoTable.from_dataset(pumpup.tabulate(f, progress=False))
    mu = np.geomspace(0.02, 0.05, 31)
    fresh, err = pumpup.albedo(f, mu, rtol=1e-12, return_error=True)
    assert np.abs(table(mu) - fresh).max() > 5e-8  # (the case: 8 x the old margin)
    assert np.all(np.abs(table(mu) - fresh) <= table.margin + err)


def test_max_points_below_the_first_grid_measures_its_misses(monkeypatch):
    """max_points below the first grid's 45 nodes: that grid, with its misses at the midpoints measured once as the
    interpolation error."""
    f = pumpup.load({"type": "phong", "n": 20})
    ds = pumpup.tabulate(f, max_points=10, progress=False)
    assert ds.sizes["mu"] == len(pumpup.tables.default_grid())
    table = pumpup.AlbedoTable.from_dataset(ds)
    mids = np.sqrt(ds["mu"].values[:-1] * ds["mu"].values[1:])
    assert table.interp_error == pytest.approx(np.abs(table(mids) - pumpup.albedo(f, mids)).max(), rel=1e-6)
    assert table.interp_error > 1e-7  # (the full table's tolerance: unmet here, and said)


@pytest.mark.parametrize("mu_min", [1e-300, 5e-324])
def test_tiny_mu_min(mu_min):
    """mu_min down to the smallest double: the grid reaches it (its midpoints underflowed to 0 at 1e-300, and
    log10(0.02 / mu_min) overflowed for a subnormal one), and the values there are the closed form's limit."""
    f = pumpup.load({"type": "lambert", "albedo": 0.5})
    ds = pumpup.tabulate(f, mu_min=mu_min, progress=False)
    assert ds["mu"].values[0] == mu_min and np.all(ds["mu"].values > 0)
    np.testing.assert_allclose(ds["albedo"].values, 0.5, rtol=1e-12)


def test_mu_min_above_the_decades():
    """mu_min >= 0.02: the grid starts at mu_min (it reached down to 0.02 before)."""
    ds = pumpup.tabulate(pumpup.load({"type": "phong", "n": 20}), mu_min=0.5, progress=False)
    assert ds["mu"].values[0] == 0.5


@pytest.mark.parametrize("args,message", [
    (([0.5, 0.5, 1.0], [1, 1, 1], [0, 0, 0]), "distinct"),
    (([0.5, 0.7, 1.0], [1, np.nan, 1], [0, 0, 0]), "finite"),
    (([0.5, 0.7, 1.0], [1, 1, 1], [0, -1e-9, 0]), "finite and >= 0"),
    (([-0.5, 0.7, 1.0], [1, 1, 1], [0, 0, 0]), "(0, 1]"),
    (([0.5, 0.7, 1.0], [1, 1], [0, 0, 0]), "one value and one error per mu"),
    (([0.5], [1], [0]), "at least two"),
])
def test_albedo_table_bad_input(args, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace("]", r"\]")):
        pumpup.AlbedoTable(*args)


def test_tabulate_with_no_azimuth():
    with pytest.raises(ValueError, match="phi must hold at least one azimuth"):
        pumpup.tabulate(pumpup.load({"type": "ward_aniso", "ax": 0.1, "ay": 0.3}), phi=[])


def test_write_table_and_max_constant_name_themselves(tmp_path):
    with pytest.raises(TypeError, match="write_table needs an xarray.Dataset"):
        pumpup.write_table({"albedo": [1.0]}, tmp_path / "t.nc")
    assert not list(tmp_path.iterdir())
    with pytest.raises(TypeError, match="max_constant needs a pumpup BRDF"):
        pumpup.max_constant("phong")


def test_netcdf_round_trip_is_exact(phong_table, tmp_path):
    path = pumpup.write_table(phong_table, tmp_path / "t.nc")
    back = pumpup.open_table(path)
    xr.testing.assert_identical(back, phong_table)


def test_writing_is_atomic(tmp_path, monkeypatch):
    ds = pumpup.tabulate(pumpup.load({"type": "lambert"}), mu=[0.5, 1.0])
    target = tmp_path / "t.nc"
    pumpup.write_table(ds, target)
    before = target.read_bytes()

    def broken(self, path, *a, **k):
        with open(path, "wb") as fh:
            fh.write(b"half a table")
        raise KeyboardInterrupt

    monkeypatch.setattr(xr.Dataset, "to_netcdf", broken)
    with pytest.raises(KeyboardInterrupt):
        pumpup.write_table(ds, target)
    assert target.read_bytes() == before  # the old file is untouched
    assert sorted(os.listdir(tmp_path)) == ["t.nc"]  # and no temporary file is left


def test_open_table_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        pumpup.open_table(tmp_path / "missing.nc")
    junk = tmp_path / "junk.nc"
    junk.write_bytes(b"this is not netCDF")
    with pytest.raises(ValueError, match="not a readable netCDF"):
        pumpup.open_table(junk)
    other = tmp_path / "other.nc"
    xr.Dataset({"x": ("i", [1.0, 2.0])}).to_netcdf(other)
    with pytest.raises(ValueError, match="not a pumpup table"):
        pumpup.open_table(other)
    good = pumpup.write_table(pumpup.tabulate(pumpup.load({"type": "lambert"}), mu=[0.5, 1.0]), tmp_path / "g.nc")
    data = bytearray(open(good, "rb").read())
    damaged = tmp_path / "damaged.nc"
    damaged.write_bytes(bytes(data[: len(data) // 3]))
    with pytest.raises(ValueError, match="not a readable netCDF"):
        pumpup.open_table(damaged)


def test_write_to_missing_directory_is_a_clear_error(tmp_path):
    ds = pumpup.tabulate(pumpup.load({"type": "lambert"}), mu=[1.0, 0.5])
    with pytest.raises(OSError, match="does not exist"):
        pumpup.write_table(ds, tmp_path / "nope" / "t.nc")


def test_given_grid_and_bad_grid():
    ds = pumpup.tabulate(pumpup.load({"type": "lambert", "albedo": 0.7}), mu=[1.0, 0.3, 0.3, 1e-6])
    assert ds.sizes["mu"] == 3  # sorted, duplicates dropped
    with pytest.raises(ValueError, match="mu"):
        pumpup.tabulate(pumpup.load({"type": "lambert"}), mu=[0.5, 2.0])


def test_mean_albedo_closed_forms():
    assert pumpup.mean_albedo(pumpup.load({"type": "lambert", "albedo": 0.4})) == pytest.approx(0.4, abs=1e-12)
    # Minnaert with b = (k+1)/(2 pi): a(mu) = mu^(k-1), so the mean albedo is 2/(k+1)
    m, e = pumpup.mean_albedo(pumpup.load({"type": "minnaert", "k": 2.0}), return_error=True)
    assert abs(m - 2 / 3) <= e and e < 1e-9


def test_max_constant_uses_the_unit_constant():
    c, theta = pumpup.max_constant(pumpup.load({"type": "lambert", "albedo": 0.2}))
    assert c == pytest.approx(1.0, abs=1e-12)
    # reciprocal Phong with c = 1: the albedo peaks at normal incidence at 2 pi / (n + 2)
    c, theta = pumpup.max_constant(pumpup.load({"type": "phong", "n": 8, "c": 5.0}))
    assert c == pytest.approx(10 / (2 * np.pi), rel=1e-9) and theta == pytest.approx(0.0, abs=1e-6)


def test_blinn_max_constant_matches_table_2_of_000():
    for n, published in [(1, 0.350), (16, 0.895)]:
        c, _ = pumpup.max_constant(pumpup.load({"type": "blinn", "n": n}))
        assert round(c, 3) == published


def test_compiled_upper_bound_is_the_tables_upper_bound(phong_table):
    # the pumping operator's look-up and AlbedoTable.upper are one definition (capped at 1)
    from pumpup.operators.pumping import _Lookup

    table = pumpup.AlbedoTable.from_dataset(phong_table)
    lookup = _Lookup(table)
    mu = np.concatenate([10 ** np.random.default_rng(9).uniform(-10, 0, 200), [1.0, 1e-12]])
    np.testing.assert_allclose(lookup.upper(mu), np.minimum(lookup.cap, table.upper(mu)), rtol=1e-12, atol=1e-15)
    assert np.any(mu < table.mu[0])


def test_is_increasing_is_exact(phong_table):
    """AlbedoTable.is_increasing agrees with a dense check of the spline, and says False for a
    table that goes down (the pumping kernel takes one look-up per level only when it is True)."""
    table = pumpup.AlbedoTable.from_dataset(phong_table)
    mu = np.clip(np.exp(np.linspace(np.log(table.mu[0]), 0.0, 200_001)), table.mu[0], 1.0)  # on the spline
    dense = bool(np.all(np.diff(table.upper(mu)) >= -1e-15))
    assert table.is_increasing() and dense
    down = pumpup.AlbedoTable(table.mu, table.value[::-1], table.error, table.interp_error)
    assert not down.is_increasing()
    # a wiggle on the increasing values is found, as the dense check finds it
    x = np.log(table.mu)
    bump = pumpup.AlbedoTable(table.mu, table.value + 1e-3 * np.sin(40 * x), table.error, table.interp_error)
    assert not bool(np.all(np.diff(bump(mu)) >= 0))
    assert not bump.is_increasing()


@pytest.mark.parametrize("threads", [1, 3])
def test_table_is_the_same_on_any_number_of_threads(monkeypatch, threads):
    """tabulate spreads its albedos over THREADS threads; a value of mu does not depend on the
    others, so the adaptive grid, the values, the errors and the interpolation error are equal."""
    import sys

    mod = sys.modules["pumpup.tables"]
    f = pumpup.load({"type": "ward", "m": 0.2})
    monkeypatch.setattr(mod, "THREADS", 2)
    two = pumpup.tabulate(f, rtol=1e-9, interp_tol=1e-5)
    monkeypatch.setattr(mod, "THREADS", None)
    other = pumpup.tabulate(f, rtol=1e-9, interp_tol=1e-5, threads=threads)
    for name in ("mu", "albedo", "albedo_error"):
        np.testing.assert_array_equal(other[name].values, two[name].values)
    assert other.attrs["interpolation_error"] == two.attrs["interpolation_error"]


@pytest.mark.parametrize("threads", [0, -1, 1.5, True, "2", 1025, 10**400], ids=str)
def test_tabulate_bad_threads(threads):
    with pytest.raises(ValueError, match=r"threads must be an integer in \[1, 1024\], got "):
        pumpup.tabulate(pumpup.load({"type": "lambert"}), mu=[0.5], threads=threads)


def test_a_table_over_mu_and_phi_is_refused_with_one_clear_line():
    """An anisotropic model's table over (mu, phi) made AlbedoTable.from_dataset fail inside scipy's spline
    ("len(c)>=n-k-1 failed"; found by scripts/studies/fuzz_engines.py --tables); it now names the dimensions, and one
    azimuth of it is a table."""
    f = pumpup.load({"type": "ward_aniso", "ax": 0.2, "ay": 0.3})
    ds = pumpup.tabulate(f, phi=[0.0, 0.5], progress=False, rtol=1e-6)
    with pytest.raises(ValueError, match=r"function of mu alone.*\('mu', 'phi'\).*isel\(phi=0\)"):
        pumpup.AlbedoTable.from_dataset(ds)
    t = pumpup.AlbedoTable.from_dataset(ds.isel(phi=1))
    np.testing.assert_allclose(t(np.array([0.5])), pumpup.albedo(f, 0.5, phi=0.5), rtol=0, atol=10 * t.margin)

# --- arguments checked like model parameters (issue 13, items 7 and 13): one clear error naming the argument, never
# a TypeError deep inside, a hang or a RecursionError ------------------------------------------------------------

PHONG = pumpup.load({"type": "phong", "n": 20})


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


@pytest.mark.parametrize("name, match", [("", "empty path"), ("sub/", "names a directory"),
                                         ("/proc/x.nc", "takes no new file"), ("a" * 300 + ".nc", "characters long")],
                         ids=str)
def test_output_paths_are_checked_before_writing(tmp_path, name, match):
    """An empty name, a trailing separator, a directory that takes no file (/proc) and a name too long for the file
    system: one OSError naming the user's path (not a hidden temporary), before anything is written; the command line
    exits 2 with one line before it computes."""
    import subprocess
    import sys

    (tmp_path / "sub").mkdir()
    path = name if name.startswith("/") or not name else str(tmp_path / name)
    ds = pumpup.tabulate(pumpup.load({"type": "lambert"}), mu=[0.5, 1.0])
    with pytest.raises(OSError, match=match) as exc:
        pumpup.write_table(ds, path)
    assert "pumpup-tmp" not in str(exc.value) and (not path or repr(path) in str(exc.value))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sub"]
    run = subprocess.run([sys.executable, "-m", "pumpup.cli", "table", "phong:n=20", "--out", path],
                         capture_output=True, text=True, timeout=60)
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1 and match in run.stderr, run.stderr
