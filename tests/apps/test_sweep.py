"""pumpup.sweep: equal, exactly, to the cell-by-cell tables whichever way it runs; resumable;
clear errors; the command line."""

import filecmp
import importlib
import itertools
import os
import subprocess
import sys

import helpers
import numpy as np
import pytest
import xarray as xr

import pumpup
from pumpup.cli import main

sweep_module = importlib.import_module("pumpup.sweeps")
REAL_CELL = sweep_module._cell

SPEC = {"type": "stretched_phong"}
PARAMS = {"n": [1, 20], "p": [0.0, 0.5]}
MU = [0.7, 1e-3, 1.0, 0.2]  # unsorted on purpose: the sweep sorts like tabulate


def cell_by_cell(spec, params, mu, pump=None, mean=True, maximum=True):
    """The reference: pumpup.tabulate (and mean_albedo, max_constant, max_albedo) of every cell, one by one."""
    names = list(params)
    shape = tuple(len(params[n]) for n in names)
    out = {k: [] for k in ("albedo", "albedo_error", "mean_albedo", "mean_albedo_error", "max_constant",
                           "max_albedo_theta", "max_constant_error", "max_albedo_mu")}
    for values in itertools.product(*(params[n] for n in names)):
        f = pumpup.load({**spec, **dict(zip(names, values))})
        if pump:
            f = pumpup.pump(f, **pump)
        t = pumpup.tabulate(f, mu=mu, progress=False)
        out["albedo"].append(t["albedo"].values)
        out["albedo_error"].append(t["albedo_error"].values)
        if mean:
            m, e = pumpup.mean_albedo(f, return_error=True)
            out["mean_albedo"].append(m)
            out["mean_albedo_error"].append(e)
        if maximum:
            c, theta = pumpup.max_constant(f)
            mx = pumpup.max_albedo(f)
            out["max_constant"].append(c)
            out["max_albedo_theta"].append(theta)
            out["max_constant_error"].append(mx.constant_error)
            out["max_albedo_mu"].append(mx.mu)
    return {k: np.array(v).reshape(shape + np.shape(v)[1:]) for k, v in out.items() if v}, t


@pytest.fixture(scope="module")
def reference():
    return cell_by_cell(SPEC, PARAMS, MU)


@pytest.fixture(scope="module")
def serial():
    return pumpup.sweep(SPEC, PARAMS, mu=MU, scheduler="synchronous")


def assert_equals_reference(ds, ref):
    arrays, last_table = ref
    assert ds["albedo"].dims == ("n", "p", "mu")
    assert set(arrays) <= set(ds.data_vars)
    for name, expected in arrays.items():
        np.testing.assert_array_equal(ds[name].values, expected, err_msg=name)
    # the mu grid, its theta and their metadata are exactly those of tabulate
    xr.testing.assert_identical(ds["mu"], last_table["mu"])
    xr.testing.assert_identical(ds["theta"].reset_coords(drop=True), last_table["theta"].reset_coords(drop=True))
    for v in ("albedo", "albedo_error"):
        assert ds[v].attrs == last_table[v].attrs
    np.testing.assert_array_equal(ds["n"].values, PARAMS["n"])
    np.testing.assert_array_equal(ds["p"].values, PARAMS["p"])


def test_serial_sweep_equals_cell_by_cell_tabulate(serial, reference):
    assert_equals_reference(serial, reference)
    assert serial.attrs["pumpup_kind"] == "pumpup albedo sweep"
    assert serial.attrs["swept_parameters"] == '["n", "p"]'
    assert serial.attrs["spec"] == '{"type": "stretched_phong"}'
    assert serial.attrs["pump"] == "null"
    assert serial.attrs["pumpup_version"] == pumpup.__version__
    # c follows n cell by cell (the spec leaves it to the model's default)
    assert serial["max_constant"].sel(n=20, p=0.0) == pytest.approx(22 / (2 * np.pi), rel=1e-6)


def test_threaded_sweep_equals_cell_by_cell_tabulate(reference):
    ds = pumpup.sweep(SPEC, PARAMS, mu=MU, scheduler="threads", workers=2, chunks={"n": 1, "p": 1})
    assert_equals_reference(ds, reference)


def test_process_sweep_equals_cell_by_cell_tabulate(reference):
    ds = pumpup.sweep(SPEC, PARAMS, mu=MU, scheduler="processes", workers=2, chunks={"n": 1, "p": 2})
    assert_equals_reference(ds, reference)


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as c:
        yield c


def test_distributed_sweep_equals_cell_by_cell_tabulate(cluster, reference):
    from distributed import Client

    with Client(cluster) as client:
        ds = pumpup.sweep(SPEC, PARAMS, mu=MU, client=client, chunks={"n": 2, "p": 1})
        assert client.status == "running"  # the user's client is left open
    assert_equals_reference(ds, reference)


def test_sweep_by_scheduler_address(cluster, serial):
    ds = pumpup.sweep(SPEC, PARAMS, mu=MU, scheduler=cluster.scheduler_address, chunks={"n": 1, "p": 1})
    xr.testing.assert_identical(ds, serial)


def test_pumped_sweep_equals_cell_by_cell_pump_and_tabulate():
    params = {"n": [1, 3]}
    pump = {"g": "g2", "levels": 1}
    mu = [0.05, 0.5, 1.0]
    ds = pumpup.sweep({"type": "phong"}, params, mu=mu, pump=pump, mean=False, maximum=False, workers=2)
    arrays, _ = cell_by_cell({"type": "phong"}, params, mu, pump=pump, mean=False, maximum=False)
    np.testing.assert_array_equal(ds["albedo"].values, arrays["albedo"])
    np.testing.assert_array_equal(ds["albedo_error"].values, arrays["albedo_error"])
    assert "mean_albedo" not in ds and "max_constant" not in ds
    assert ds.attrs["pump"] == '{"g": "g2", "levels": 1}'
    # the pumped cells really are pumped: above the plain model's albedo at grazing incidence
    plain = pumpup.tabulate(pumpup.load({"type": "phong", "n": 3}), mu=mu)["albedo"].values
    assert ds["albedo"].sel(n=3).values[0] > plain[0] + 1e-3


# --- interrupted sweeps resume ----------------------------------------------------------------


def count_cells(monkeypatch, fail_after=None):
    """Wrap the per-cell function: count the cells computed, and raise after ``fail_after`` of them."""
    real = REAL_CELL
    calls = []

    def wrapped(spec, pump, mu, opts):
        if fail_after is not None and len(calls) >= fail_after:
            raise RuntimeError("simulated interruption")
        calls.append(spec)
        return real(spec, pump, mu, opts)

    monkeypatch.setattr(sweep_module, "_cell", wrapped)
    return calls


RESUME = {"spec": {"type": "phong"}, "params": {"n": [1, 2, 5, 10], "c": [0.1, 0.2]}, "mu": [0.01, 0.5, 1.0],
          "chunks": {"n": 1, "c": 2}, "scheduler": "synchronous", "maximum": False}


def test_interrupted_sweep_resumes_and_gives_the_same_file(tmp_path, monkeypatch):
    out = tmp_path / "sweep.nc"
    parts = tmp_path / "sweep.nc.parts"
    calls = count_cells(monkeypatch, fail_after=4)  # two chunks of two cells, then an error
    with pytest.raises(RuntimeError, match="simulated interruption"):
        pumpup.sweep(**RESUME, out=out)
    assert len(calls) == 4
    done = sorted({c["n"] for c in calls})
    assert len(done) == 2
    assert not out.exists()
    index = {n: i for i, n in enumerate(RESUME["params"]["n"])}
    expected = sorted([f"chunk-{index[n]}-0.npz" for n in done] + ["sweep.json"])
    assert sorted(os.listdir(parts)) == expected  # the finished chunks, no temporary files

    calls = count_cells(monkeypatch)
    resumed = pumpup.sweep(**RESUME, out=out)
    assert len(calls) == 4  # only the missing chunks
    assert {c["n"] for c in calls} == set(RESUME["params"]["n"]) - set(done)
    assert out.exists() and not parts.exists()

    calls = count_cells(monkeypatch)
    whole = pumpup.sweep(**RESUME, out=tmp_path / "whole.nc")
    assert len(calls) == 8
    xr.testing.assert_identical(resumed, whole)
    xr.testing.assert_identical(pumpup.open_table(out), pumpup.open_table(tmp_path / "whole.nc"))
    assert filecmp.cmp(out, tmp_path / "whole.nc", shallow=False)


def test_finished_sweep_is_read_back_not_recomputed(tmp_path, monkeypatch):
    out = tmp_path / "sweep.nc"
    first = pumpup.sweep(**RESUME, out=out)
    calls = count_cells(monkeypatch)
    again = pumpup.sweep(**RESUME, out=out)
    assert calls == []  # no cell computed again
    xr.testing.assert_identical(again, pumpup.open_table(out))
    np.testing.assert_array_equal(again["albedo"].values, first["albedo"].values)
    pumpup.sweep(**RESUME, out=out, overwrite=True)  # overwrite computes afresh
    assert len(calls) == 8
    data = bytearray(out.read_bytes())  # a damaged result is not taken as finished: refused with one line
    data[len(data) // 2] ^= 0xFF
    out.write_bytes(bytes(data))
    with pytest.raises(sweep_module.SweepError, match="exists and holds something that is not a result of this sweep"):
        pumpup.sweep(**RESUME, out=out)


def test_damaged_part_is_recomputed(tmp_path, monkeypatch):
    out = tmp_path / "sweep.nc"
    count_cells(monkeypatch, fail_after=2)
    with pytest.raises(RuntimeError):
        pumpup.sweep(**RESUME, out=out)
    (part,) = (tmp_path / "sweep.nc.parts").glob("chunk-*.npz")
    part.write_bytes(b"not a part")
    calls = count_cells(monkeypatch)
    ds = pumpup.sweep(**RESUME, out=out)
    assert len(calls) == 8
    assert np.isfinite(ds["albedo"].values).all()


def test_parts_of_another_sweep_are_refused(tmp_path, monkeypatch):
    out = tmp_path / "sweep.nc"
    count_cells(monkeypatch, fail_after=2)
    with pytest.raises(RuntimeError):
        pumpup.sweep(**RESUME, out=out)
    count_cells(monkeypatch)
    with pytest.raises(ValueError, match="different sweep"):
        pumpup.sweep(**{**RESUME, "mu": [0.5, 1.0]}, out=out)
    assert len(os.listdir(tmp_path / "sweep.nc.parts")) == 2  # left as they were


def test_zarr_output(tmp_path):
    kw = {"spec": {"type": "lambert"}, "params": {"albedo": [0.25, 0.5, 1.0]}, "mu": [0.1, 1.0],
          "scheduler": "synchronous", "maximum": False}
    nc = pumpup.sweep(**kw, out=tmp_path / "s.nc")
    store = tmp_path / "s.zarr"
    pumpup.sweep(**kw, out=store)
    assert not (tmp_path / "s.zarr.parts").exists()
    with xr.open_zarr(store) as z:
        xr.testing.assert_identical(z.load(), nc)
    assert nc["albedo"].dims == ("lambert_albedo", "mu")
    np.testing.assert_allclose(nc["albedo"].values, [[0.25, 0.25], [0.5, 0.5], [1.0, 1.0]], rtol=1e-12)


# --- errors -------------------------------------------------------------------------------------


@pytest.mark.parametrize("params, match", [
    ({"m": [0.1]}, r"stretched_phong has no parameter 'm'; its parameters: n, p, c"),
    ({"n": [1, -2]}, r"'n' = -2 is outside its allowed range \[0, 1e\+06\]"),  # core.MAX_EXPONENT
    ({"n": [1], "p": [0.5, 1.5]}, r"'p' = 1.5 is outside its allowed range \[0, 1\]"),
    ({"n": []}, r"list of values of 'n' is empty"),
    ({"n": [1, 1]}, r"values of 'n' repeat"),
    ({"n": 3}, r"values of 'n' must be a list"),
    ({}, r"non-empty dict"),
])
def test_bad_parameters_are_clear_errors(params, match):
    with pytest.raises(pumpup.SpecError, match=match):
        pumpup.sweep(SPEC, params, mu=[1.0])


@pytest.mark.parametrize("mu", [[0.0, 0.5], [0.5, 1.5], [-0.1], [np.nan]])
def test_mu_outside_the_unit_interval_is_an_error(mu):
    with pytest.raises(ValueError, match=r"\(0, 1\]"):
        pumpup.sweep(SPEC, {"n": [1]}, mu=mu)


def test_other_bad_input():
    with pytest.raises(ValueError, match="mu is empty"):
        pumpup.sweep(SPEC, {"n": [1]}, mu=[])
    with pytest.raises(pumpup.SpecError, match="unknown model type"):
        pumpup.sweep({"type": "nope"}, {"n": [1]}, mu=[1.0])
    with pytest.raises(pumpup.SpecError, match="unknown pump option"):
        pumpup.sweep(SPEC, {"n": [1]}, mu=[1.0], pump={"g": "g2", "level": 2})
    with pytest.raises(pumpup.SpecError, match="g1' or 'g2"):
        pumpup.sweep(SPEC, {"n": [1]}, mu=[1.0], pump={"g": "g3"})
    with pytest.raises(pumpup.SpecError, match="not reciprocal"):
        pumpup.sweep({"type": "phong_shader"}, {"n": [1]}, mu=[1.0], pump={"g": "g2"})
    with pytest.raises(ValueError, match="client= or scheduler="):
        pumpup.sweep(SPEC, {"n": [1]}, mu=[1.0], client=object(), scheduler="threads")
    with pytest.raises(ValueError, match="scheduler must be one of 'threads', 'processes', 'synchronous' or"):
        pumpup.sweep(SPEC, {"n": [1]}, mu=[1.0], scheduler="thread")
    with pytest.raises(ValueError, match="chunks names 'q'"):
        pumpup.sweep(SPEC, {"n": [1]}, mu=[1.0], chunks={"q": 2})


# --- command line -------------------------------------------------------------------------------


def test_cli_round_trip(tmp_path, serial, capsys):
    out = tmp_path / "sweep.nc"
    assert main(["sweep", "stretched_phong", "--param", "n=1,20", "--param", "p=0,0.5",
                 "--mu", *map(str, MU), "--out", str(out), "--serial"]) == 0
    assert "wrote" in capsys.readouterr().out
    xr.testing.assert_identical(pumpup.open_table(out), serial)


def test_cli_ranges_and_pump(tmp_path):
    out = tmp_path / "sweep.nc"
    assert main(["sweep", "phong", "--param", "n=geom:1:4:3", "--n-mu", "3", "--pump", "g1:1", "--out", str(out),
                 "--threads", "--no-mean", "--no-maximum"]) == 0
    ds = pumpup.open_table(out)
    np.testing.assert_allclose(ds["n"].values, [1, 2, 4], rtol=1e-15)
    np.testing.assert_array_equal(ds["mu"].values, np.sort(sweep_module.default_mu(3)))
    assert ds.attrs["pump"] == '{"g": "g1", "levels": 1}'


@pytest.mark.parametrize("argv, match", [
    (["--param", "m=1"], "no parameter 'm'"),
    (["--param", "n=-1,2"], r"'n' = -1 is outside"),
    (["--param", "n="], "empty"),
    (["--param", "n"], "name=v1,v2"),
    (["--param", "n=1", "--param", "n=2"], "given twice"),
    (["--param", "n=1", "--mu", "0"], r"\(0, 1\]"),
    (["--param", "n=1", "--pump", "g2:x"], "g2:LEVELS"),
    (["--param", "n=1", "--pump", "g3"], "'g1' or 'g2'"),
    (["--param", "n=lin:0:1:x"], "lin:a:b:k"),
])
def test_cli_errors(tmp_path, argv, match):
    with pytest.raises(SystemExit, match=match):
        main(["sweep", "phong", "--out", str(tmp_path / "x.nc"), *argv])
    assert not (tmp_path / "x.nc").exists()


@pytest.mark.slow
def test_threaded_sweep_compiles_without_numba_warning(tmp_path):
    """With an empty numba cache every ufunc compiles during the sweep; two threads asking for one
    signature at once made numba warn ("Compilation requested for previously compiled argument
    types"). About 30 s: everything compiles."""
    root = str(helpers.ROOT)
    env = dict(os.environ, PYTHONPATH=root, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    r = subprocess.run([sys.executable, "-m", "pumpup.cli", "sweep", "stretched_phong", "--param", "n=1,2,4",
                        "--param", "p=0,1", "--mu", "1", "0.5", "--no-maximum", "--out", str(tmp_path / "x.nc"),
                        "--threads", "--workers", "2"], capture_output=True, text=True, env=env, timeout=1800)
    assert r.returncode == 0, r.stderr
    assert "NumbaWarning" not in r.stderr and "previously compiled" not in r.stderr, r.stderr
