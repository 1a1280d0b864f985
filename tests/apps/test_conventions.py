"""Tables described as plain data (pumpup.conventions): the presets as files, every format and storage read back,
the report, and one-line errors for descriptions and files that do not fit.
"""

import copy
import dataclasses
import os
import subprocess
import sys

import helpers
import numpy as np
import pytest
import tomllib

import pumpup
from pumpup import conventions as cv
from pumpup import luts

ROOT = str(helpers.ROOT)
CYCLES_TABLES = str(helpers.DATA / "cycles_shader.tables")
EXT = {"c": ".h", "filament": ".inc", "npy": ".npy", "netcdf": ".nc", "exr": ".exr"}

#: the example of issue 52, as written there
ISSUE_TOML = '''
model = "ggx:shadowing=correlated" # height-correlated Smith, Fresnel 1
quantity = "E"
format = "c-array"
array = "table_ggx_E"
storage = "text-decimals-6"
shape = [32, 32]
roughness_to_alpha = "square"
lookup = "bilinear-clamped"

[[axes]]                           # in storage order: the slow axis first
axis = "mu"
nodes = "edges"
map = "linear"
range = [0.0, 1.0]
clamp = [[0, 1e-4]]                # [node index, value it is evaluated at]

[[axes]]
axis = "roughness"
nodes = "edges"
map = "linear"
range = [0.0, 1.0]
clamp = [[0, 1e-4]]
'''


def preset_dict(name):
    with open(os.path.join(cv.PRESET_DIR, cv.PRESET_FILES[name]), "rb") as fh:
        return tomllib.load(fh)


def _small(name, n_mu, n_rough, floor=0.05):
    """A preset and its conventions file at a small size, the roughness column 0 at >= ``floor``."""
    p = luts.PRESETS[name]
    sp = dataclasses.replace(p, n_mu=n_mu, n_rough=n_rough, rough_floor=max(p.rough_floor, floor))
    d = preset_dict(name)
    n = {"mu": n_mu, "roughness": n_rough}
    d["shape"] = [n[a["axis"]] for a in d["axes"]]
    c = cv.load_conventions(d)
    x0 = float(c.rough_axis.x_nodes()[0])
    for a in d["axes"]:
        if a["axis"] == "roughness":
            a["clamp"] = [[0, max(x0, floor)]]
    return sp, d


# ------------------------------------------------------------------------------------------
# the presets as conventions files
# ------------------------------------------------------------------------------------------


def test_every_preset_has_a_file():
    assert set(cv.PRESET_FILES) == set(luts.PRESETS)
    for name in luts.PRESETS:
        c = cv.preset_conventions(name)
        p = luts.PRESETS[name]
        assert c.mu_axis.n == p.n_mu and c.rough_axis.n == p.n_rough and c.stores == p.stores
        mu, x = c.nodes()
        pm, pr = luts.nodes(p)
        np.testing.assert_array_equal(mu, pm)
        np.testing.assert_array_equal(x, pr)


@pytest.mark.parametrize("name", sorted(luts.PRESETS))
def test_preset_file_gives_the_presets_audit(tmp_path, name):
    sp, d = _small(name, 5, 4)
    ds = pumpup.lut("ggx", preset=sp, rtol=1e-8, lookup_check=False)
    path = tmp_path / ("t" + EXT[sp.fmt])
    luts.write_lut(ds, path, preset=sp)
    a = pumpup.audit(path, preset=sp, rtol=1e-8)
    b = pumpup.audit(path, conventions=d, rtol=1e-8)
    assert b.n_nodes == a.n_nodes and b.above_one == a.above_one
    assert b.max_abs == a.max_abs and b.where_abs == a.where_abs
    assert b.max_rel == a.max_rel and b.where_rel == a.where_rel
    assert b.monotonicity == a.monotonicity and b.monotonicity_rounding == a.monotonicity_rounding
    assert b.truth_error == a.truth_error and b.quantisation_bound == pytest.approx(a.quantisation_bound, rel=1e-12)
    assert b.lookup["max_abs"] == pytest.approx(a.lookup["max_abs"], rel=1e-12, abs=1e-15)
    assert b.lookup["where"] == pytest.approx(a.lookup["where"], rel=1e-12)
    assert (a.eavg is None) == (b.eavg is None)
    if a.eavg is not None:
        for k in ("vs_own", "vs_truth"):
            assert b.eavg[k] == pytest.approx(a.eavg[k], rel=1e-9, abs=1e-14)
    # the report's lines agree but for the axis name (rough -> roughness) and the cell indices
    ra = [line for line in a.report().splitlines()[1:] if "[" not in line]
    rb = [line.replace("roughness", "rough") for line in b.report().splitlines()[1:] if "[" not in line]
    assert ra == rb


def test_shipped_cycles_table_same_report_both_ways():
    a = pumpup.audit(CYCLES_TABLES, preset="cycles")
    b = pumpup.audit(CYCLES_TABLES, conventions="cycles")
    assert (b.max_abs, b.where_abs, b.max_rel) == (a.max_abs, a.where_abs, a.max_rel)
    assert b.lookup["max_abs"] == a.lookup["max_abs"] and b.lookup["where"] == a.lookup["where"]
    assert b.eavg["vs_truth"] == pytest.approx(a.eavg["vs_truth"], abs=1e-15)
    assert b.eavg["vs_own"] == pytest.approx(a.eavg["vs_own"], abs=1e-14)
    assert 9e-7 < b.max_abs < 1e-6 and 0.1 < b.lookup["max_abs"] < 0.105
    # the two pairs an older check flagged step by less than two rounding bounds: rounding, not errors
    assert b.monotonicity == [] and b.monotonicity_rounding >= 2
    # the worst node in the file's own indices: data[20 * 32 + 5]
    assert b.worst[0].startswith("[20, 5] (item 645) mu = 0.645161, roughness = 0.16129")


def test_issue_example_works_as_written(tmp_path):
    conv = tmp_path / "cycles.toml"
    conv.write_text(ISSUE_TOML)
    r = pumpup.audit(CYCLES_TABLES, conventions=str(conv), lookup_check=True)
    assert r.max_abs < 2e-6 and r.above_one == 0 and r.eavg is None  # the example names no E_avg array
    assert 0.1 < r.lookup["max_abs"] < 0.105 and r.lookup["where"][0] < 2e-4
    json_conv = tmp_path / "cycles.json"
    import json

    json_conv.write_text(json.dumps(tomllib.loads(ISSUE_TOML)))
    r2 = pumpup.audit(CYCLES_TABLES, conventions=str(json_conv), lookup_check=False)
    assert r2.max_abs == r.max_abs


# ------------------------------------------------------------------------------------------
# every format and storage, from pumpup's exact values
# ------------------------------------------------------------------------------------------

BASE = {"model": "ggx:shadowing=separable", "quantity": "E", "shape": [5, 4], "roughness_to_alpha": "square",
        "axes": [{"axis": "mu", "nodes": "edges", "clamp": [[0, 1e-3]]},
                 {"axis": "roughness", "nodes": "edges", "clamp": [[0, 0.1]]}]}
FORMATS = {"c-array": {"array": "t"}, "text": {}, "npy": {}, "exr": {"channel": "Y"}, "netcdf": {"variable": "E"}}
CASES = [(f, s) for f in FORMATS for s in ("float32", "float16", "float64", "unorm8", "unorm16", "text-decimals-4")
         if not (f in ("npy", "exr", "netcdf") and s.startswith("text"))
         and not (f == "exr" and s not in ("float32", "float16")) and not (f == "netcdf" and s == "float16")]


def _exact(c):
    spec, param = luts.model_spec(c.model)
    mu, x = c.nodes()
    tr = luts.truth_grid(spec, param, mu, c.rough_of(x), rtol=1e-10)
    return tr["E"], float(tr["E_error"].max())


@pytest.mark.parametrize("fmt,storage", CASES)
@pytest.mark.parametrize("quantity", ["E", "1-E"])
def test_every_format_and_storage_reads_back_at_its_quantisation(tmp_path, fmt, storage, quantity):
    d = {**copy.deepcopy(BASE), "format": fmt, "storage": storage, "quantity": quantity, **FORMATS[fmt]}
    c = cv.load_conventions(d)
    E, terr = _exact(c)
    path = c.write(E, tmp_path / "t")
    r = pumpup.audit(path, conventions=d, rtol=1e-10, lookup_check=False)
    stored = E if quantity == "E" else 1 - E
    q = float(np.max(np.abs(cv.quantise(stored, storage) - stored)))  # what the storage rounds
    bound = cv.storage_bound(storage)
    assert q <= bound
    assert abs(r.max_abs - q) <= 2 * terr + 1e-15  # the audit sees the storage's rounding, no more
    assert r.quantisation_bound == bound and r.monotonicity == []


def _unorm16_one_minus_e(path, name, stored, extra=""):
    codes = np.round(np.clip(stored, 0, 1) * 65535).astype(int)
    rows = ",\n".join("    " + ", ".join(f"{v}u" for v in row) for row in codes)
    path.write_text(f"// 1 - E of GGX, rows sqrt(alpha)\n{extra}static const uint16_t {name}[{codes.size}] = {{\n"
                    f"{rows}\n}};\n")


def test_unorm16_one_minus_e_rows_by_sqrt_alpha(tmp_path):
    """The table of issue 52: 1 - E of GGX with the separable Smith term as a unorm16 C array, rows by sqrt(alpha),
    the mu = 0 column computed at 1e-3; written here by hand from pumpup's values, read through a description."""
    n_a, n_mu = 6, 5
    sa = np.arange(n_a) / (n_a - 1)  # row i: sqrt(alpha) = i / 5
    alpha = np.maximum(sa**2, 1e-4)
    mu = np.arange(n_mu) / (n_mu - 1)
    mu[0] = 1e-3
    spec, param = luts.model_spec("ggx:shadowing=separable")
    E = np.array([[float(pumpup.albedo(pumpup.load({**spec, "alpha": a}), m)) for m in mu] for a in alpha])
    _unorm16_one_minus_e(tmp_path / "t.h", "ggx_1mE", 1 - E, "static const uint16_t other[2] = {1, 2};\n")
    d = {"model": "ggx:shadowing=separable", "quantity": "1-E", "format": "c-array", "array": "ggx_1mE",
         "storage": "unorm16", "shape": [n_a, n_mu],
         "axes": [{"axis": "alpha", "nodes": "edges", "map": "sqrt", "clamp": [[0, 1e-4]]},
                  {"axis": "mu", "nodes": "edges", "clamp": [[0, 1e-3]]}]}
    c = cv.load_conventions(d)
    np.testing.assert_allclose(c.nodes()[1], alpha, rtol=1e-15)
    r = pumpup.audit(tmp_path / "t.h", conventions=d, rtol=1e-9, lookup_check=True)
    assert r.max_abs <= 0.5 / 65535 + 2 * r.truth_error
    assert r.stores == "1-E" and r.max_rel_stored <= 0.5 / 65535 / (10 * 0.5 / 65535) + 1e-12
    assert r.labels == ("mu", "alpha") and "relative to the stored 1-E" in r.report()
    assert r.lookup is not None and r.lookup["max_abs"] > r.max_abs  # interpolation errs more than storage

    # a deliberately biased row (alpha = 0.04, i = 1): caught and located, in the file's own indices
    bad = 1 - E
    bad[1] += 2e-3
    _unorm16_one_minus_e(tmp_path / "b.h", "ggx_1mE", bad)
    rb = pumpup.audit(tmp_path / "b.h", conventions=d, rtol=1e-9, lookup_check=False)
    assert rb.max_abs == pytest.approx(2e-3, abs=1e-4)
    assert rb.where_abs[1] == pytest.approx(0.04)
    assert all(w.startswith("[1, ") for w in rb.worst[:n_mu])
    # relative to 1 - E the bias is large where 1 - E is small (near normal incidence): the report says it
    assert rb.max_rel_stored > 10 * rb.max_rel


def test_e_avg_table(tmp_path):
    d = {"model": "ggx:shadowing=correlated", "quantity": "1-E_avg", "format": "text", "storage": "float32",
         "shape": [6], "axes": [{"axis": "roughness", "nodes": "centres"}]}
    c = cv.load_conventions(d)
    spec, param = luts.model_spec(c.model)
    x = c.nodes()[1]
    ea, _ = luts.mean_albedo_grid(spec, param, x, rtol=1e-9)
    path = c.write(ea, tmp_path / "avg.txt")
    r = pumpup.audit(path, conventions=d, rtol=1e-9)
    assert r.max_abs <= 2**-25 + 2 * r.truth_error and r.n_nodes == 6


def test_lookup_kinds():
    d = {**copy.deepcopy(BASE), "format": "text", "storage": "float32"}
    table = np.arange(20, dtype=float).reshape(5, 4)
    c = cv.load_conventions(d)  # mu nodes 0, .25, .5, .75, 1; roughness 0, 1/3, 2/3, 1
    assert c.look_up(table, 0.375, 0.5) == pytest.approx(0.5 * (5.5 + 9.5))
    assert c.look_up(table, -1.0, 2.0) == 3.0  # clamped
    cn = cv.load_conventions({**d, "lookup": "nearest"})
    assert cn.look_up(table, 0.3, 0.6) == 4 * 1 + 2
    cb = cv.load_conventions({**d, "lookup": "bilinear", "axes": [{"axis": "mu", "nodes": "centres"},
                                                                   {"axis": "roughness", "nodes": "centres"}]})
    # texel centres at (i + 0.5) / 5: mu = 0 lies half a texel before the first, extended linearly
    assert cb.look_up(table, 0.0, 0.125) == pytest.approx(-0.5 * 4)


# ------------------------------------------------------------------------------------------
# descriptions and files that do not fit: one line naming the field, or what differs
# ------------------------------------------------------------------------------------------

GOOD = tomllib.loads(ISSUE_TOML)


@pytest.mark.parametrize("edit,field", [
    (lambda d: d.pop("model"), "'model' is missing"),
    (lambda d: d.update(model="phong"), "field 'model'"),
    (lambda d: d.update(quantity="albedo"), "field 'quantity' must be one of"),
    (lambda d: d.update(format="hdf5"), "field 'format' must be one of"),
    (lambda d: d.pop("array"), "field 'array' is missing"),
    (lambda d: d.update(storage="unorm12"), "field 'storage'"),
    (lambda d: d.update(shape=[32]), "field 'shape'"),
    (lambda d: d["axes"].pop(), "field 'axes'"),
    (lambda d: d["axes"][0].update(nodes="edge"), "field axes[0].'nodes'"),
    (lambda d: d["axes"][1].update(map="pow"), "field axes[1].'exponent' is missing"),
    (lambda d: d["axes"][0].update(range=[0.5, 0.2]), "field axes[0].'range'"),
    (lambda d: d["axes"][0].update(clamp=[[40, 1e-4]]), "field axes[0].'clamp': node index"),
    (lambda d: d["axes"][1].update(axis="f0"), "field axes[1].'axis'"),
    (lambda d: d["axes"][1].update(axis="mu"), "field 'axes' must be mu and roughness|alpha"),
    (lambda d: d.update(lookup="bicubic"), "field 'lookup'"),
    (lambda d: d.update(roughness_to_alpha="cube"), "field 'roughness_to_alpha'"),
    (lambda d: d.update(colour="red"), "unknown field 'colour'"),
])
def test_wrong_description_names_the_field(edit, field):
    d = copy.deepcopy(GOOD)
    edit(d)
    with pytest.raises(cv.ConventionsError, match="^conventions") as e:
        cv.load_conventions(d)
    assert field in str(e.value) and "\n" not in str(e.value)


def test_file_that_does_not_match_says_what_differs(tmp_path):
    with pytest.raises(luts.LutError, match="no array named 'table_ggx_Q'.*table_ggx_E"):
        pumpup.audit(CYCLES_TABLES, conventions={**GOOD, "array": "table_ggx_Q"})
    with pytest.raises(luts.LutError, match="has 1024 values.*need 256"):
        pumpup.audit(CYCLES_TABLES, conventions={**GOOD, "shape": [16, 16]})
    with pytest.raises(luts.LutError, match="read as integer codes"):
        pumpup.audit(CYCLES_TABLES, conventions={**GOOD, "storage": "unorm16"})
    (tmp_path / "big.txt").write_text(", ".join(["0.5"] * 19 + ["7.5"]))
    d = {**copy.deepcopy(BASE), "format": "text", "storage": "float32"}
    with pytest.raises(luts.LutError, match=r"value 7.5 at \[4, 3\] is out of range"):
        pumpup.audit(tmp_path / "big.txt", conventions=d)
    np.save(tmp_path / "t.npy", np.zeros((4, 5), np.float32))
    with pytest.raises(luts.LutError, match=r"shape \(4, 5\); the conventions need \(5, 4\)"):
        pumpup.audit(tmp_path / "t.npy", conventions={**d, "format": "npy"})


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "pumpup.cli", *args], capture_output=True, text=True, cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": ROOT})


def test_cli(tmp_path):
    conv = tmp_path / "c.toml"
    conv.write_text(ISSUE_TOML)
    r = _cli("audit", CYCLES_TABLES, "--conventions", str(conv), "--no-lookup-check", "--png", str(tmp_path / "m.png"))
    assert r.returncode == 0, r.stderr
    assert "worst nodes" in r.stdout and os.path.getsize(tmp_path / "m.png") > 1000
    r = _cli("audit", CYCLES_TABLES, "--conventions", str(conv), "--no-lookup-check", "--tol", "1e-7")
    assert r.returncode == 1 and "at mu = 0.645161, roughness = 0.16129" in r.stderr
    bad = tmp_path / "bad.toml"
    bad.write_text(ISSUE_TOML.replace('storage = "text-decimals-6"', 'storage = "text6"'))
    for args in (["--conventions", str(bad)], ["--conventions", str(tmp_path / "none.toml")], [],
                 ["--conventions", str(conv), "--preset", "cycles"]):
        r = _cli("audit", CYCLES_TABLES, *args)
        assert r.returncode == 2 and r.stderr.count("\n") == 1 and "Traceback" not in r.stderr, (args, r.stderr)
    assert "field 'storage'" in _cli("audit", CYCLES_TABLES, "--conventions", str(bad)).stderr
