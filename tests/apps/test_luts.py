"""Renderer look-up tables (pumpup.luts): readers, writers, the renderer's look-up, audits.

Small tables in each preset's format keep the default suite fast; the real Cycles file ships in
tests/data (Blender's shader.tables, Apache-2.0, its header kept).
"""

import dataclasses
import math
import os
import subprocess
import sys

import helpers
import numpy as np
import pytest

import pumpup
from pumpup import luts

ROOT = str(helpers.ROOT)
EXT = {"c": ".h", "filament": ".inc", "npy": ".npy", "netcdf": ".nc", "exr": ".exr"}


#: Cycles' shipped albedo tables (src/scene/shader.tables), an unchanged copy
CYCLES_TABLES = str(helpers.DATA / "cycles_shader.tables")


def small(name, n_mu=6, n_rough=5, **kw):
    """A preset's conventions (axes, floors, storage, layout) at a small size."""
    return dataclasses.replace(luts.PRESETS[name], n_mu=n_mu, n_rough=n_rough, **kw)


def _write_c(path, name, values):
    items = ", ".join(f"{float(np.float32(v)):f}f" for v in np.ravel(values))
    with open(path, "w") as fh:
        fh.write(f"/* test */\nstatic const float {name}[{np.size(values)}] = {{\n  {items}\n}};\n")


# ------------------------------------------------------------------------------------------
# the reader: orientation and clamping, in Cycles' layout
# ------------------------------------------------------------------------------------------


def test_reader_orientation_rows_are_mu(tmp_path):
    p = small("cycles", 4, 3)
    vals = np.array([[10 * y + x for x in range(3)] for y in range(4)]) / 100.0  # data[y * nx + x]
    path = tmp_path / "t.h"
    _write_c(path, "table_ggx_E", vals)
    tab = luts.read_table(path, p)
    assert tab["E"].shape == (4, 3)
    assert tab["E"][2, 1] == pytest.approx(0.21)  # row y = 2 (mu), column x = 1 (rough)
    assert tab["E"][3, 0] == pytest.approx(0.30)


def test_nodes_clamped_at_1e4():
    mu, rough = luts.nodes("cycles")
    assert mu[0] == 1e-4 and rough[0] == 1e-4
    assert mu[1] == pytest.approx(1 / 31) and rough[-1] == 1.0


def test_audit_finds_the_row_and_column_that_are_wrong(tmp_path):
    """A table computed in the right layout passes at the text6 quantisation level; one made with the
    axes swapped, or without the 1e-4 clamp, fails and the audit says where."""
    p = small("cycles", 5, 4)
    spec, param = luts.model_spec("ggx", p)
    mu, rough = luts.nodes(p)
    good = luts.truth_grid(spec, param, mu, rough, rtol=1e-9)["E"]
    path = tmp_path / "good.h"
    _write_c(path, "table_ggx_E", good)
    r = pumpup.audit(path, preset=p, rtol=1e-9, lookup_check=False)
    assert r.max_abs <= luts.STORAGE_BOUND["text6"] + r.truth_error

    # unclamped: the first column at rough = 0.02 instead of 1e-4 (alpha 4e-4 instead of 1e-8)
    r2 = np.array(rough)
    r2[0] = 0.02
    wrong = luts.truth_grid(spec, param, mu, r2, rtol=1e-9)["E"]
    _write_c(tmp_path / "w.h", "table_ggx_E", wrong)
    r = pumpup.audit(tmp_path / "w.h", preset=p, rtol=1e-9, lookup_check=False)
    assert r.max_abs > 1e-3 and r.where_abs[1] == 1e-4

    # transposed: mu along the columns
    sq = small("cycles", 4, 4)
    mu4, rough4 = luts.nodes(sq)
    t = luts.truth_grid(spec, param, mu4, rough4, rtol=1e-9)["E"]
    _write_c(tmp_path / "t.h", "table_ggx_E", t.T)
    r = pumpup.audit(tmp_path / "t.h", preset=sq, rtol=1e-9, lookup_check=False)
    assert r.max_abs > 1e-2


def test_real_cycles_file():
    path = CYCLES_TABLES
    tab = luts.read_table(path, "cycles")
    assert tab["E"].shape == (32, 32) and tab["E_avg"].shape == (32,)
    # the second printed row is y = 1 (mu = 1/31): 1.000000f, 0.999451f, 0.990086f, ...
    assert tab["E"][1, :3].tolist() == pytest.approx([1.0, 0.999451, 0.990086], abs=1e-7)
    assert tab["E"][:, 0].min() == 1.0  # rough = 1e-4 (alpha = 1e-8): a mirror
    # three cells against pumpup's truth, in the orientation the generator uses
    spec, param = luts.model_spec("ggx", "cycles")
    mu, rough = luts.nodes("cycles")
    for i, j in ((1, 4), (20, 10), (31, 31)):
        e, err = luts._albedo(luts._brdf(spec, param, rough[j]), mu[i], 1e-9, 400)
        assert abs(tab["E"][i, j] - float(e)) < 2e-6
        assert abs(tab["E"][j, i] - float(e)) > 1e-3 or i == j  # not the transpose


@pytest.mark.slow
def test_real_cycles_audit_full():
    path = CYCLES_TABLES
    r = pumpup.audit(path, preset="cycles", lookup_check=False)
    assert r.n_nodes == 1024 and r.max_abs < 2e-6 and r.above_one == 0
    assert r.eavg["vs_truth"] < 2e-6


# ------------------------------------------------------------------------------------------
# lut -> file -> audit, every preset, at the format's quantisation level
# ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(luts.PRESETS))
def test_round_trip_every_preset(tmp_path, name):
    # the format's code paths at a small size; rough >= 0.05 skips the dear near-mirror column
    # (the 1e-4 clamp has its own tests above)
    p = small(name, 5, 4, rough_floor=max(luts.PRESETS[name].rough_floor, 0.05))
    ds = pumpup.lut("ggx", preset=p, rtol=1e-8, lookup_check=False)
    assert ds.attrs["quantisation_error"] <= luts.STORAGE_BOUND[p.storage]
    path = tmp_path / ("t" + EXT[p.fmt])
    luts.write_lut(ds, path, preset=p)
    r = pumpup.audit(path, preset=p, rtol=1e-8, lookup_check=False)
    q = ds.attrs["quantisation_error"]
    assert r.max_abs <= q + 2 * r.truth_error + 1e-15
    assert r.max_abs >= q - 2 * r.truth_error - 1e-15  # what the format rounds is what the audit sees
    if p.split:
        assert np.allclose(ds["A"] + ds["B"], ds["E"], atol=1e-15)
    if p.eavg and p.fmt != "c" or (p.eavg and len(p.names) > 1):
        assert r.eavg is not None and r.eavg["vs_truth"] <= luts.STORAGE_BOUND[p.storage] + 1e-8


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(luts.PRESETS))
def test_round_trip_full_size(tmp_path, name):
    p = luts.PRESETS[name]
    ds = pumpup.lut("ggx", preset=name, lookup_check=False)
    path = tmp_path / ("t" + EXT[p.fmt])
    luts.write_lut(ds, path)
    r = pumpup.audit(path, preset=name, rtol=1e-8, lookup_check=False)
    assert r.max_abs <= ds.attrs["quantisation_error"] + 2 * r.truth_error + 1e-15


def test_filament_layout(tmp_path):
    """cmgen's order: GL rows (lowest roughness first), per texel (B, E) as half floats."""
    p = small("filament", 4, 3)
    ds = pumpup.lut("ggx", preset=p, rtol=1e-9, lookup_check=False)
    path = tmp_path / "dfg.inc"
    luts.write_lut(ds, path, preset=p)
    words = [int(w, 16) for w in open(path).read().split("0x")[1:] for w in [w.split(",")[0]]]
    half = np.array(words, np.uint16).view(np.float16).astype(float)
    assert half[1] == np.float16(ds["E"].values[0, 0])  # texel (x = 0, GL row 0): NoV = 1/8, roughness row 0
    assert half[0] == np.float16(ds["B"].values[0, 0])
    assert half[2 * 4 + 1] == np.float16(ds["E"].values[0, 1])  # GL row 1 starts after 4 texels
    assert ds["rough"].values.tolist() == pytest.approx([1.5 / 3, 2.5 / 3, 1.0])  # Filament: (t + 1.5)/n, saturated
    assert ds["mu"].values.tolist() == pytest.approx([0.125, 0.375, 0.625, 0.875])


def test_split_sum_against_dblquad():
    """B = integral (1 - wi.h)^5 f_r cos d omega_o by scipy dblquad in (theta_o, phi_o)."""
    from scipy.integrate import dblquad

    alpha, mu = 0.36, 0.5
    f = pumpup.load({"type": "ggx", "alpha": alpha, "shadowing": "correlated"})
    b, be = luts._albedo(luts._SchlickWeighted(f), mu, 1e-10, 2000)
    wi = np.array([math.sqrt(1 - mu * mu), 0.0, mu])

    def g(phi, th):
        wo = np.array([math.sin(th) * math.cos(phi), math.sin(th) * math.sin(phi), math.cos(th)])
        c = 0.5 * np.linalg.norm(wi + wo)
        return float(f.eval(wi, wo)) * (1 - c) ** 5 * math.cos(th) * math.sin(th)

    ref, _ = dblquad(g, 0, math.pi / 2, 0, 2 * math.pi, epsabs=1e-11, epsrel=1e-9)
    assert abs(float(b) - ref) < 1e-7


def _b_both_routes(alphas, mu, rtol):
    """B at every (mu, alpha) by the 1-D routes (Schlick's Fc at wi.h) and by the nested quadrature of eval alone."""
    out = []
    for alpha in alphas:
        f = pumpup.load({"type": "ggx", "alpha": alpha, "shadowing": "correlated"})
        e, _ = luts._albedo(f, mu, rtol, 200)
        atol = rtol * float(np.min(e))
        assert luts._SchlickWeighted(f).azimuth_hint() is not None
        b1, e1 = luts._albedo(luts._SchlickWeighted(f), mu, rtol, 200, atol=atol)
        b0, e0 = luts._albedo(luts._NestedSchlickWeighted(f), mu, rtol, 200, atol=atol)
        out.append((b1, e1, b0, e0))
    return out


def test_split_sum_b_routes_agree_within_their_estimates():
    """The 1-D routes' B (frame 6 above N_FRESNEL_MU_MIN, the half-vector arc below) against the nested quadrature of
    _eval: they differ by at most the sum of their error estimates, at Filament's rtol and a tighter one.
    """
    mu = np.array([1e-4, 0.01, 0.1, 0.2, 0.3, 0.5, 0.8, 0.99, 1.0])
    for rtol in (1e-6, 1e-9):
        for b1, e1, b0, e0 in _b_both_routes([1.4e-4, 0.003, 0.06, 0.36, 1.0], mu, rtol):
            assert np.all(b1 >= 0) and np.all(b1 <= 1)
            assert np.all(np.abs(b1 - b0) <= e1 + e0 + 1e-15), (b1 - b0, e1 + e0)


def test_schlick_hint_is_only_for_a_plain_smith_model():
    assert luts._SchlickWeighted(pumpup.load({"type": "ggx", "alpha": 0.3, "ior": 1.5})).azimuth_hint() is None
    assert luts._SchlickWeighted(pumpup.load({"type": "phong", "n": 20})).azimuth_hint() is None
    from pumpup.core.hints import Fresnel

    with pytest.raises(ValueError, match="schlick"):
        Fresnel(schlick=1.5)
    with pytest.raises(ValueError, match="give ior"):
        Fresnel(ior=1.5, schlick=0.0)


@pytest.mark.slow
def test_filament_table_b_against_the_nested_route():
    """The whole 128 x 128 Filament table: B by the 1-D routes and by the nested quadrature agree within their
    estimates, and E (the same route either way) is the same.
    """
    spec, param = luts.model_spec("ggx", "filament")
    mu, rough = luts.nodes("filament")
    new = luts.truth_grid(spec, param, mu, rough, rtol=1e-6, split=True)
    old = luts.truth_grid(spec, param, mu, rough, rtol=1e-6, split=True, _weighted=luts._NestedSchlickWeighted)
    np.testing.assert_array_equal(new["E"], old["E"])
    assert np.all(np.abs(new["B"] - old["B"]) <= new["B_error"] + old["B_error"])
    assert new["over_tolerance"] == 0


# ------------------------------------------------------------------------------------------
# the renderer's look-up
# ------------------------------------------------------------------------------------------


def test_lookup_node_matches_scipy():
    from scipy.interpolate import RegularGridInterpolator

    rng = np.random.default_rng(5)
    p = small("cycles", 7, 6)
    table = rng.random((7, 6))
    mu = rng.random(200)
    r = rng.random(200)
    ref = RegularGridInterpolator((np.linspace(0, 1, 7), np.linspace(0, 1, 6)), table)(np.stack([mu, r], -1))
    assert np.allclose(luts.lookup(table, mu, r, p), ref, atol=1e-14)
    assert luts.lookup(table, -0.5, 2.0, p) == table[0, -1]  # saturated coordinates
    b = small("bsdl", 7, 6)  # BSDL's mu axis: index sqrt(mu) (n - 1)
    assert np.allclose(luts.lookup(table, mu, r, b), RegularGridInterpolator(
        (np.linspace(0, 1, 7), np.linspace(0, 1, 6)), table)(np.stack([np.sqrt(mu), r], -1)), atol=1e-12)
    w = small("cycles", 7, 6, mu_axis="power:3", rough_axis="power:2")  # the warped axes of warp_search
    assert np.allclose(luts.lookup(table, mu, r, w), RegularGridInterpolator(
        (np.linspace(0, 1, 7), np.linspace(0, 1, 6)), table)(np.stack([np.cbrt(mu), np.sqrt(r)], -1)), atol=1e-12)
    assert luts.nodes(w)[0][1] == pytest.approx((1 / 6) ** 3)
    with pytest.raises(pumpup.SpecError, match="exponent must be a number in"):
        luts.axis_values("power:x", 4)
    with pytest.raises(pumpup.SpecError, match="needs a preset with node axes"):
        luts.warp_search("ggx", "mitsuba")


def test_lookup_texel_matches_mitsuba_texture():
    mi = pytest.importorskip("mitsuba")
    import drjit as dr

    mi.set_variant("scalar_rgb")
    rng = np.random.default_rng(6)
    table = rng.random((8, 5))  # (n_mu, n_rough)
    tex = mi.Texture2f(mi.TensorXf(table.T[..., None].astype(np.float32)), use_accel=False,
                       wrap_mode=dr.WrapMode.Clamp)
    p = small("mitsuba", 8, 5)
    for mu, r in rng.random((50, 2)):
        got = tex.eval(mi.Point2f(mu, r))[0]
        assert float(luts.lookup(table, mu, r, p)) == pytest.approx(got, abs=2e-6)


def test_lookup_error_against_brute_force():
    """The reported look-up error (dense grid + refinement) against the renderer's interpolation
    evaluated independently (scipy) on a fine grid of true albedos."""
    from scipy.interpolate import RegularGridInterpolator

    p = small("cycles", 5, 5, lookup_mu_min=0.05, lookup_rough_min=0.2)
    spec, param = luts.model_spec("ggx", p)
    mu, rough = luts.nodes(p)
    table = luts.truth_grid(spec, param, mu, rough, rtol=1e-9)["E"]
    le = luts.lookup_error(table, spec, param, p, per_cell=1, refine=3, rtol=1e-8)
    fm = np.linspace(0.05, 1, 33)
    fr = np.linspace(0.2, 1, 33)
    truth = luts.truth_grid(spec, param, fm, fr, rtol=1e-8)["E"]
    interp = RegularGridInterpolator((np.linspace(0, 1, 5), np.linspace(0, 1, 5)), table)
    brute = np.abs(interp(np.stack(np.meshgrid(fm, fr, indexing="ij"), -1)) - truth)
    assert le["max_abs"] >= 0.98 * brute.max()  # the refinement finds the worst point of the fine grid ...
    assert le["max_abs"] <= brute.max() * 1.2  # ... and does not invent a larger one
    assert le["grid_max_abs"] <= le["max_abs"]


def test_max_lookup_error_fails_with_where():
    p = small("cycles", 4, 4)
    with pytest.raises(luts.LutError, match=r"exceeds max_lookup_error=1e-06 at mu = .*, rough = "):
        pumpup.lut("ggx", preset=p, max_lookup_error=1e-6, eavg=False)


def test_own_eavg_is_exact_for_piecewise_linear():
    p = small("cycles", 5, 2)
    E = np.repeat(np.linspace(0.2, 1.0, 5)[:, None], 2, axis=1)  # E = 0.2 + 0.8 mu: 2 int E mu = 0.2 + 0.8 * 2/3
    assert luts._own_eavg(E, p) == pytest.approx([0.2 + 1.6 / 3] * 2, abs=1e-14)


def test_monotonicity_violation_found(tmp_path):
    p = small("cycles", 5, 4)
    spec, param = luts.model_spec("ggx", p)
    mu, rough = luts.nodes(p)
    t = luts.truth_grid(spec, param, mu, rough, rtol=1e-9)["E"]
    assert t[4, 3] < t[3, 3]  # at rough = 1, E falls with mu (0.31 at mu = 1); make one step rise
    t[3, 3] = t[4, 3] - 0.01
    _write_c(tmp_path / "m.h", "table_ggx_E", t)
    r = pumpup.audit(tmp_path / "m.h", preset=p, rtol=1e-9, lookup_check=False)
    assert any("along mu" in m for m in r.monotonicity)


# ------------------------------------------------------------------------------------------
# bad input
# ------------------------------------------------------------------------------------------


def test_bad_files(tmp_path):
    with pytest.raises(luts.LutError, match="no such file"):
        luts.read_table(tmp_path / "none.h", "cycles")
    _write_c(tmp_path / "small.h", "table_ggx_E", np.ones(16))
    with pytest.raises(luts.LutError, match="has 16 values.*needs 1024"):
        luts.read_table(tmp_path / "small.h", "cycles")
    _write_c(tmp_path / "other.h", "table_other", np.ones(16))
    with pytest.raises(luts.LutError, match="no array named 'table_ggx_E'.*table_other"):
        luts.read_table(tmp_path / "other.h", "cycles")
    (tmp_path / "junk.npy").write_bytes(b"\x00\x01junk")
    with pytest.raises(luts.LutError, match="not a readable .npy"):
        luts.read_table(tmp_path / "junk.npy", "mitsuba")
    (tmp_path / "junk.exr").write_bytes(b"junk")
    with pytest.raises(luts.LutError, match="not a readable OpenEXR"):
        luts.read_table(tmp_path / "junk.exr", "exr")
    with pytest.raises(pumpup.SpecError, match="preset must be one of"):
        pumpup.lut("ggx", preset="unity")
    with pytest.raises(pumpup.SpecError, match="no roughness-like parameter"):
        pumpup.lut("phong", preset="cycles")


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "pumpup.cli", *args], capture_output=True, text=True, cwd=ROOT,
                          env={**os.environ, "PYTHONPATH": ROOT})


def test_cli_errors(tmp_path):
    _write_c(tmp_path / "small.h", "table_ggx_E", np.ones(16))
    for args in (["audit", str(tmp_path / "small.h"), "--preset", "cycles"],
                 ["audit", str(tmp_path / "none.h"), "--preset", "cycles"],
                 ["audit", str(tmp_path / "small.h"), "--preset", "unity"],
                 ["lut", "--preset", "cycles", "--out", str(tmp_path / "x.npy")]):
        r = _cli(*args)
        assert r.returncode == 2, (args, r.stderr)
        assert r.stderr.count("\n") == 1 and r.stderr.startswith("pumpup: ") and "Traceback" not in r.stderr


def test_cli_audit_exit_status(tmp_path):
    p = small("cycles", 32, 32)
    vals = np.full((32, 32), 0.5)
    _write_c(tmp_path / "bad.h", "table_ggx_E", vals)  # the right size, all wrong
    r = _cli("audit", str(tmp_path / "bad.h"), "--preset", "cycles", "--tol", "1e-3", "--no-lookup-check",
             "--no-eavg", "--rtol", "1e-5")
    assert r.returncode == 1 and "node error" in r.stderr and "at mu =" in r.stderr
    assert p.n_mu == 32


@pytest.mark.slow
def test_cli_lut_then_audit(tmp_path):
    out = str(tmp_path / "t.npy")
    r = _cli("lut", "ggx", "--preset", "mitsuba", "--out", out, "--no-eavg", "--max-lookup-error", "1e-6")
    assert r.returncode == 1 and "exceeds max_lookup_error=1e-06 at mu = " in r.stderr and not os.path.exists(out)
    r = _cli("lut", "ggx", "--preset", "mitsuba", "--out", out, "--no-eavg", "--no-lookup-check")
    assert r.returncode == 0, r.stderr
    assert "storage (float32) rounds by" in r.stdout
    r = _cli("audit", out, "--preset", "mitsuba", "--no-lookup-check", "--tol", "1e-6")
    assert r.returncode == 0, r.stderr
    assert "max |table - E| = " in r.stdout


def test_appleseed_layout_rows_are_roughness(tmp_path):
    """appleseed: one array, data[y * n + x] with y the roughness and x the cosine, E_avg appended;
    E = 1 by definition where cos_theta = 0 or roughness = 0."""
    p = small("appleseed", 4, 3)
    vals = np.array([[10 * y + x for x in range(4)] for y in range(3)]) / 100.0  # y: rough, x: mu
    avg = np.array([0.9, 0.8, 0.7])
    path = tmp_path / "a.cpp"
    items = ", ".join(f"{v:f}f" for v in np.concatenate([vals.ravel(), avg]))
    path.write_text(f"extern const float g_glossy_ggx_albedo_table[15] =\n{{\n    {items}\n}};\n")
    tab = luts.read_table(path, p)
    assert tab["E"].shape == (4, 3) and tab["E"][3, 1] == pytest.approx(0.13)  # mu index 3, rough index 1
    assert tab["E_avg"].tolist() == pytest.approx(avg.tolist())
    ds = pumpup.lut("ggx", preset=p, lookup_check=False, rtol=1e-7)
    assert np.all(ds["E"].values[0, :] == 1.0) and np.all(ds["E"].values[:, 0] == 1.0)
    luts.write_lut(ds, tmp_path / "b.cpp", preset=p)
    assert "extern const float g_glossy_ggx_albedo_table[15]" in (tmp_path / "b.cpp").read_text()
    assert luts.read_table(tmp_path / "b.cpp", p)["E"] == pytest.approx(ds["E"].values, abs=6e-7)


def test_audit_counts_e_above_one_beyond_rounding_only(monkeypatch, tmp_path):
    """A node 2.2e-16 above 1 is rounding (within the format's bound and the truth's error), not a violation of energy
    conservation; a node 1e-3 above 1 is one."""
    path = str(tmp_path / "t.h")
    luts.write_lut(pumpup.lut("ggx", preset="bsdl", lookup_check=False), path)
    real = luts.read_table

    def edited(path, preset):
        tab = real(path, preset)
        E = np.array(tab["E"], dtype=float)
        E[0, 0], E[1, 1] = 1.0 + 2.2e-16, 1.001
        return {**tab, "E": E}

    monkeypatch.setattr(luts, "read_table", edited)
    assert pumpup.audit(path, preset="bsdl", lookup_check=False, eavg=False).above_one == 1


def test_damaged_or_oversized_table_files_are_refused_before_reading(tmp_path):
    """An empty .npy, a header that declares terabytes, a truncated array and a 60 MB C file of commas: one LutError
    each, before any array is allocated or any text scanned (the commas took 29 s, the header a MemoryError)."""
    import time

    p = luts.PRESETS["mitsuba"]
    empty = tmp_path / "empty.npy"
    empty.write_bytes(b"")
    huge, short = tmp_path / "huge.npy", tmp_path / "short.npy"
    with open(huge, "wb") as fh:
        np.lib.format.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False, "shape": (10**6, 10**6, 1)})
    with open(short, "wb") as fh:
        np.lib.format.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False,
                                                  "shape": (p.n_rough, p.n_mu, 1)})
        fh.write(b"\0" * 100)
    commas = tmp_path / "commas.h"
    commas.write_bytes(b"," * (60 * 2**20))
    start = time.monotonic()
    for path, preset, match in ((empty, "mitsuba", "not a readable .npy"), (huge, "mitsuba", "needs \\(32, 32"),
                                (short, "mitsuba", "is truncated"), (commas, "cycles", "is read up to")):
        with pytest.raises(luts.LutError, match=match):
            luts.read_table(path, preset)
    assert time.monotonic() - start < 1.0


def test_a_roughness_the_tables_axis_sets_is_refused_in_the_model():
    """The table's axis sets alpha = rough^2 at every node: an alpha in the model spec was silently ignored."""
    with pytest.raises(pumpup.SpecError, match="the table's axis sets ggx's 'alpha'"):
        pumpup.audit(helpers.DATA / "cycles_shader.tables", preset="cycles", model="ggx:alpha=0.3")
    with pytest.raises(pumpup.SpecError, match="remove alpha=0.3"):
        pumpup.lut({"type": "ggx", "alpha": 0.3}, preset="bsdl")
