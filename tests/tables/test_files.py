"""Files pumpup writes and reads (issue 13, items 5, 6 and 10): validated on open, checksummed,
written with the umask's permissions, no stale temporaries, and a loaded file's tables never
poison the session's shared cache."""

import json
import os
import signal
import subprocess
import sys
import textwrap

import helpers
import numpy as np
import pytest
import xarray as xr

import pumpup
from pumpup.tables.validate import TableError

LAMBERT_HALF = {"type": "lambert", "albedo": 0.5}


@pytest.fixture(scope="module")
def table_file(tmp_path_factory):
    ds = pumpup.tabulate(pumpup.load({"type": "phong", "n": 20}), mu=[0.05, 0.2, 0.5, 0.8, 1.0])
    path = tmp_path_factory.mktemp("t") / "phong.nc"
    pumpup.write_table(ds, path)
    return path, ds


def _write_raw(ds, path):
    """A file as an editor would leave it: plain xarray, no checksums."""
    ds.to_netcdf(path, engine="netcdf4")
    return path


def _variants(ds):
    """Edited versions of a valid table, each with what the error must say."""
    def edit(fn):
        d = ds.copy(deep=True)
        r = fn(d)
        return r if isinstance(r, xr.Dataset) else d

    yield "only the kind", xr.Dataset(attrs={"pumpup_kind": "pumpup albedo table"}), "'albedo' is missing"
    yield "no error", edit(lambda d: d.drop_vars("albedo_error")), "'albedo_error' is missing"
    bad = ds.copy(deep=True)
    bad["albedo"].values[:3] = [-3.0, np.nan, 7.0]
    yield "negative and nan albedo", bad, r"albedo\[0\] = -3.0.*finite and >= 0"
    yield "mu above 1", edit(lambda d: d.assign_coords(mu=d.mu.values * 1.5)), r"mu\[\d\] = .*in \(0, 1\]"
    scrambled = ds.copy(deep=True).isel(mu=[0, 2, 1, 3, 4])
    yield "scrambled mu", scrambled, "strictly increasing as stored"
    yield "spec not JSON", edit(lambda d: d.attrs.update(spec="{phong")), "'spec' is not valid JSON"
    yield "spec does not load", edit(lambda d: d.attrs.update(spec=json.dumps({"type": "phong", "n": -1}))), \
        "'spec' does not load"
    yield "no spec", edit(lambda d: d.attrs.pop("spec")), "'spec'.*missing"
    yield "bad degree", edit(lambda d: d.attrs.update(interpolation_degree=4)), "interpolation_degree"
    yield "nan interpolation error", edit(lambda d: d.attrs.update(interpolation_error=float("nan"))), \
        "interpolation_error"
    yield "one mu", ds.isel(mu=[0]), "at least two values of mu"


def test_open_table_refuses_what_is_not_a_table(tmp_path, table_file):
    _, ds = table_file
    for k, (what, bad, match) in enumerate(_variants(ds)):
        path = _write_raw(bad, tmp_path / f"bad{k}.nc")
        with pytest.raises(TableError, match=match) as exc:
            pumpup.open_table(path, require_digest=False)  # (the checks behind the checksum)
        assert str(path) in str(exc.value), what
    assert issubclass(TableError, ValueError)


def test_edits_of_a_written_table_break_its_digest(tmp_path, table_file):
    path, ds = table_file
    back = pumpup.open_table(path)
    xr.testing.assert_identical(back, ds)  # the digest is checked and dropped
    edited = back.copy(deep=True)
    edited["albedo"].values[2] += 1e-9  # a plausible, silent edit
    edited.attrs["pumpup_digest"] = xr.open_dataset(path).attrs["pumpup_digest"]
    with pytest.raises(TableError, match="does not match the checksum"):
        pumpup.open_table(_write_raw(edited, tmp_path / "edited.nc"))


def test_damaged_files_give_one_clear_error(tmp_path, table_file):
    """Random byte flips (fixed seed), truncations: a TableError, or (a flip in unused bytes)
    exactly the table that was written; never another exception, never other numbers."""
    path, ds = table_file
    data = path.read_bytes()
    rng = np.random.default_rng(13)
    outcomes = {"error": 0, "same": 0}
    target = tmp_path / "flip.nc"
    for trial in range(80):
        b = bytearray(data)
        for pos in rng.integers(0, len(b), size=1 + trial % 3):
            b[pos] ^= 1 << int(rng.integers(8))
        target.write_bytes(bytes(b))
        try:
            back = pumpup.open_table(target)
        except TableError:
            outcomes["error"] += 1
            continue
        xr.testing.assert_identical(back, ds)
        outcomes["same"] += 1
    assert outcomes["error"] >= 1, outcomes  # most of a small HDF5 file is padding
    # a flip inside the stored values: the Fletcher-32 checksum refuses it
    start = data.find(np.ascontiguousarray(ds["albedo"].values, "<f8").tobytes())
    assert start > 0
    for k in range(0, 40, 3):
        b = bytearray(data)
        b[start + k] ^= 1 << (k % 8)
        target.write_bytes(bytes(b))
        with pytest.raises(TableError, match="not a readable netCDF"):
            pumpup.open_table(target)
    for frac in (0.0, 0.1, 0.5, 0.9, 0.999):
        target.write_bytes(data[: int(len(data) * frac)])
        with pytest.raises(TableError):
            pumpup.open_table(target)


def test_checksums_are_stored(table_file):
    import netCDF4

    path, _ = table_file
    with netCDF4.Dataset(path) as nc:
        assert nc.variables["albedo"].filters()["fletcher32"]
        assert nc.variables["mu"].filters()["fletcher32"]


# --- load_pumped ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def pumped_file(tmp_path_factory):
    p = pumpup.pump(LAMBERT_HALF, g="g1", levels=2)
    path = tmp_path_factory.mktemp("p") / "p.nc"
    pumpup.save_pumped(p, path)
    return path, p


def _edit_group(src, dst, group, fn):
    """Copy a saved pumped BRDF, editing one group (or the root, group None) with fn(Dataset)."""
    import shutil

    shutil.copy(src, dst)
    with xr.open_dataset(src, group=group) as ds:
        d = ds.load()
    r = fn(d)
    d = r if isinstance(r, xr.Dataset) else d
    d.attrs.pop("pumpup_digest", None)
    if group is None:  # consistent with its digest too: the deeper checks must catch it
        import netCDF4

        from pumpup.tables.validate import content_digest

        d.attrs["pumpup_digest"] = content_digest(d)

        with netCDF4.Dataset(dst, "a") as nc:
            for k in list(nc.ncattrs()):
                nc.delncattr(k)
            for k, v in d.attrs.items():
                nc.setncattr(k, v)
    else:  # consistent with its digest: the deeper checks must catch it
        from pumpup.tables.validate import content_digest

        d.attrs["pumpup_digest"] = content_digest(d)
        d.to_netcdf(dst, mode="a", group=group, engine="netcdf4")
    return dst


def test_load_pumped_refuses_damaged_files(tmp_path, pumped_file):
    path, p = pumped_file
    q = pumpup.load_pumped(path)
    assert q == p
    cases = [
        (None, lambda d: d.attrs.update(levels="two"), "'levels' must be an integer"),
        (None, lambda d: d.attrs.update(levels=3), "'levels' = 3 but its spec has 2"),
        (None, lambda d: d.attrs.update(spec="{"), "not valid JSON"),
        (None, lambda d: d.attrs.update(spec=json.dumps({"type": "phong", "n": 2})), "not a pumped BRDF"),
        ("level1", lambda d: d.attrs.update(spec=json.dumps({"type": "lambert", "albedo": 0.7})),
         "holds the table of"),
        ("level2", lambda d: d["albedo"].values.__setitem__(0, -0.5), r"albedo\[0\] = -0.5"),
    ]
    for k, (group, fn, match) in enumerate(cases):
        dst = _edit_group(path, tmp_path / f"bad{k}.nc", group, fn)
        with pytest.raises(TableError, match=match):
            pumpup.load_pumped(dst)
    data = path.read_bytes()
    rng = np.random.default_rng(5)
    target = tmp_path / "flip.nc"
    for _ in range(30):
        b = bytearray(data)
        b[int(rng.integers(len(b)))] ^= 1 << int(rng.integers(8))
        target.write_bytes(bytes(b))
        try:
            r = pumpup.load_pumped(target)
        except TableError:
            continue
        assert r == p
        for a, b_ in zip(r.chain(), p.chain()):
            xr.testing.assert_identical(a.table().dataset, b_.table().dataset)


def test_a_loaded_file_does_not_poison_the_cache(tmp_path):
    """Item 5: a file whose tables were edited serves only the object loaded from it."""
    base = {"type": "lambert", "albedo": 0.31}
    p = pumpup.pump(base)
    path = tmp_path / "p.nc"
    pumpup.save_pumped(p, path)
    honest = float(pumpup.albedo(p, 0.5))
    # an edited file, written as pumpup writes files (so it passes every check): its table
    # claims the base reflects 0.62
    with xr.open_dataset(path, group="level1") as ds:
        d = ds.load()
    d["albedo"].values[:] = 0.62
    edited = tmp_path / "edited.nc"
    pumpup.write_table(xr.Dataset(attrs={"pumpup_kind": "pumpup pumped BRDF", "spec": json.dumps(p.spec),
                                         "levels": 1, "pumpup_version": "x"}), edited)
    d.attrs.pop("pumpup_digest", None)
    from pumpup.tables.validate import content_digest

    d.attrs["pumpup_digest"] = content_digest(d)
    d.to_netcdf(edited, mode="a", group="level1", engine="netcdf4")
    q = pumpup.load_pumped(edited)
    assert float(pumpup.albedo(q, 0.5)) == pytest.approx(0.31 / 0.62, rel=1e-6)  # the file's object
    fresh = pumpup.pump(base)
    assert float(pumpup.albedo(fresh, 0.5)) == pytest.approx(honest, abs=1e-12)  # not poisoned
    again = pumpup.pump(q)  # pumping the loaded object: its table is its own, not shared
    pumpup.albedo(again, 0.5)
    assert float(pumpup.albedo(pumpup.pump(pumpup.pump(base)), 0.5)) == pytest.approx(
        float(pumpup.albedo(pumpup.pump(p), 0.5)), abs=1e-12)


# --- item 10: permissions, fsync, stale temporaries -------------------------------------------

def test_files_get_the_umask_permissions(tmp_path):
    ds = pumpup.tabulate(pumpup.load(LAMBERT_HALF), mu=[0.5, 1.0])
    old = os.umask(0o022)
    try:
        path = tmp_path / "t.nc"
        pumpup.write_table(ds, path)
        assert os.stat(path).st_mode & 0o777 == 0o644
        os.chmod(path, 0o600)
        pumpup.write_table(ds, path)  # overwriting: the umask's permissions again
        assert os.stat(path).st_mode & 0o777 == 0o644
        os.umask(0o077)
        pumpup.write_table(ds, path)
        assert os.stat(path).st_mode & 0o777 == 0o600
    finally:
        os.umask(old)


def test_atomic_path_fsyncs_before_rename(tmp_path, monkeypatch):
    from pumpup import tables

    calls = []
    real_fsync, real_replace = os.fsync, os.replace
    monkeypatch.setattr(os, "fsync", lambda fd: (calls.append("fsync"), real_fsync(fd))[1])
    monkeypatch.setattr(os, "replace", lambda a, b: (calls.append("replace"), real_replace(a, b))[1])
    with tables.atomic_path(tmp_path / "x.bin") as tmp:
        with open(tmp, "wb") as fh:
            fh.write(b"data")
    assert calls[:2] == ["fsync", "replace"]
    assert (tmp_path / "x.bin").read_bytes() == b"data"


def test_a_killed_write_leaves_no_temporary_behind(tmp_path):
    """A write killed by SIGKILL leaves its temporary; the next write of that target removes it
    (and leaves other targets' and live processes' temporaries alone)."""
    target = tmp_path / "big.nc"
    code = textwrap.dedent(f"""
        import os, time, pumpup
        from pumpup.tables import atomic_path
        with atomic_path({str(target)!r}) as tmp:
            open(tmp, "wb").write(b"x" * 100000)
            print("ready", flush=True)
            time.sleep(60)
    """)
    root = str(helpers.ROOT)
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                            env=dict(os.environ, PYTHONPATH=root))
    assert proc.stdout.readline().strip() == "ready"
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    left = [n for n in os.listdir(tmp_path) if n != "big.nc"]
    assert len(left) == 1 and left[0].startswith(".big.nc.")  # the kill left it
    mine = tmp_path / f".other.nc.{os.getpid()}.abc.pumpup-tmp"
    mine.write_bytes(b"")  # another target's temporary: not touched
    live = tmp_path / f".big.nc.{os.getpid()}.zzz.pumpup-tmp"
    live.write_bytes(b"")  # a live process's temporary of this target: not touched
    pumpup.write_table(pumpup.tabulate(pumpup.load(LAMBERT_HALF), mu=[0.5, 1.0]), target)
    assert sorted(os.listdir(tmp_path)) == sorted(["big.nc", mine.name, live.name])


def test_a_fifo_or_a_directory_at_a_table_path_is_refused_at_once(tmp_path):
    """A FIFO would block the netCDF reader forever: open_table, load_pumped and audit refuse non-regular files in one
    line, within a second."""
    import time

    fifo = tmp_path / "table.nc"
    os.mkfifo(fifo)
    start = time.monotonic()
    for call in (lambda: pumpup.open_table(fifo), lambda: pumpup.load_pumped(fifo), lambda: pumpup.open_table(tmp_path),
                 lambda: pumpup.audit(fifo, preset="bsdl", lookup_check=False)):
        with pytest.raises(ValueError, match="is not a regular file"):
            call()
    assert time.monotonic() - start < 1.0


def test_a_file_without_its_checksum_is_refused_unless_asked(tmp_path):
    """Every file pumpup writes carries its checksum; deleting it (and editing the albedo) is refused, and
    ``require_digest=False`` reads a file from another tool unchecked."""
    path = tmp_path / "t.nc"
    pumpup.write_table(pumpup.tabulate(pumpup.load({"type": "phong", "n": 20}), rtol=1e-8), path)
    import netCDF4

    with netCDF4.Dataset(path, "a") as nc:
        nc.delncattr("pumpup_digest")
        nc["albedo"][0] = 1.083
    with pytest.raises(ValueError, match="has no checksum"):
        pumpup.open_table(path)
    assert float(pumpup.open_table(path, require_digest=False)["albedo"][0]) == 1.083


def test_a_killed_writes_temporary_is_removed_by_the_next_write_in_its_directory(tmp_path):
    """A temporary left by a write whose process is gone is removed by the next pumpup write in the same directory, of
    any file; one of a live process (this one) is left alone."""
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    pid = int(dead.stdout)
    stale = tmp_path / f".other.nc.{pid}.abc123.pumpup-tmp"
    live = tmp_path / f".other.nc.{os.getpid()}.xyz789.pumpup-tmp"
    stale.write_bytes(b"half")
    live.write_bytes(b"half")
    pumpup.write_table(pumpup.tabulate(pumpup.load({"type": "lambert"}), mu=[0.5, 1.0]), tmp_path / "t.nc")
    assert not stale.exists() and live.exists()


def test_open_table_on_a_saved_brdf_names_its_reader(tmp_path):
    """A saved pumped or compensated BRDF keeps its tables in groups: open_table of its root said nothing and returned
    an empty Dataset; it names the function that reads it (and its groups still open)."""
    pumped, comp = tmp_path / "p.nc", tmp_path / "c.nc"
    pumpup.save_pumped(pumpup.pump({"type": "phong", "n": 20}), pumped)
    pumpup.save_compensated(pumpup.compensate({"type": "ggx", "alpha": 0.3}), comp)
    with pytest.raises(ValueError, match="is a pumped BRDF, not a table: read it with pumpup.load_pumped"):
        pumpup.open_table(pumped)
    with pytest.raises(ValueError, match="is a compensated BRDF, not a table: read it with pumpup.load_compensated"):
        pumpup.open_table(comp)
    assert pumpup.open_table(pumped, group="level1")["albedo"].size > 2
    assert float(pumpup.albedo(pumpup.load_pumped(pumped), 0.5)) == float(pumpup.albedo(pumpup.pump(
        {"type": "phong", "n": 20}), 0.5))
