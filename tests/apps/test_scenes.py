"""pumpup.scenes and ``pumpup render scene``: argument checks before rendering, the message without
mitsuba, the ``pumpup_mix`` BSDF against pumpup's albedo, and a tiny render of each scene."""

from __future__ import annotations

import math
import os
import subprocess
import sys

import helpers
import numpy as np
import pytest

import pumpup
import pumpup.scenes as S

ROOT = str(helpers.ROOT)


def _cli(*args, pre=""):
    code = pre + "import sys; from pumpup.cli import main; sys.exit(main(sys.argv[1:]))"
    e = dict(os.environ)
    e["PYTHONPATH"] = ROOT + os.pathsep + e.get("PYTHONPATH", "")
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=ROOT, env=e,
                          timeout=120)


@pytest.mark.parametrize("args, words", [
    (["nope"], "unknown scene 'nope'"),
    (["000-fig8", "--size", "4"], "--size must"),
    (["000-fig8", "--spp", "0"], "--spp must"),
    (["000-fig8", "--spp", "many"], "--spp must"),
    (["000-fig8", "--exposure", "x"], "--exposure"),
])
def test_bad_input_is_one_line(args, words, tmp_path):
    r = _cli("render", "scene", *args, "--out", str(tmp_path / "o"))
    assert r.returncode == 2, r.stderr
    assert words in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "o").exists()  # nothing done


def test_without_mitsuba_names_the_extra(tmp_path):
    block = "import sys; sys.modules['mitsuba'] = None; sys.modules['drjit'] = None\n"
    r = _cli("render", "scene", "000-fig8", "--out", str(tmp_path / "o"), pre=block)
    assert r.returncode == 2 and "render extra" in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr
    with pytest.raises(ValueError, match="unknown scene"):
        S.check_scene("001-fig9")


def test_panels_are_the_papers_parameters():
    (orig, new), = S.panels("000-fig9")
    specs = [m[1][1] for k, m in sorted(orig[1].items()) if k.startswith("s")]
    # pytest.approx takes flat sequences of numbers only (pytest >= 9.1 refuses nested ones): compare an array
    got = np.array([(s["c"] * 2 * math.pi / (s["n"] + 2), s["n"]) for s in specs])
    np.testing.assert_allclose(got, [(0.04, 169), (0.065, 64), (0.09, 9), (0.13, 3)], rtol=1e-6)
    assert new[1]["s0"][0][1][0]["type"] == "plastic"
    (a, b), = S.panels("000-fig8")
    eta, k = S.metal_index("silver")  # the measured silver, one index per RGB channel
    assert a[1]["plate"][0][1] == [{"type": "fresnel", "base": {"type": "phong", "n": 5000.0}, "eta": e, "k": kk}
                                   for e, kk in zip(eta, k)]
    assert b[1]["plate"][0][1] == [{"type": "metal", "n": 5000.0, "eta": e, "k": kk} for e, kk in zip(eta, k)]
    rows = S.panels("001-fig8")
    pumped = {"type": "pumped", "base": {"type": "phong", "n": 5000.0}, "g": "g1", "levels": 1}
    assert [s["base"] for s in rows[1][1][1]["tank"][0][1]] == [pumped] * 3


def test_fig10_panels_are_the_papers_parameters():
    """000 Fig. 10: two teapots of 000 eq. 30 with n = 100 and 20, diffuse dominant, energy-conserving."""
    (orig, new), = S.panels("000-fig10")
    assert [new[1][f"t{i}"][0][1][0]["n"] for i in range(2)] == [100.0, 20.0]
    for (a_s, n), rgb in S.TEAPOTS:
        assert max(rgb) + a_s <= 1 and min(rgb) > a_s  # 000 after eq. 30; the diffuse part dominates
    assert [s["type"] for s in new[1]["t0"][0][1]] == ["plastic"] * 3
    assert orig[1]["t1"][1][1] == {"type": "phong", "n": 20.0, "c": pytest.approx(0.04 * 22 / (2 * math.pi))}


def _signed_volume(v, f):
    return float(np.einsum("ij,ij->i", v[f[:, 0]], np.cross(v[f[:, 1]], v[f[:, 2]])).sum() / 6.0)


def test_teapot_mesh_faces_point_outwards():
    """The body of revolution of a unit sphere's profile encloses 4 pi / 3 with outward faces (positive signed
    volume); every side face of a tube faces away from its axis and its end discs close it; the teapot's indices
    are valid and its faces not degenerate."""
    s = np.linspace(0.0, math.pi, 64)
    v, f = S._revolve(np.sin(s), -np.cos(s), 128)
    assert _signed_volume(v, f) == pytest.approx(4 * math.pi / 3, rel=2e-3)
    t = np.linspace(0.0, 1.0, 20)
    path = np.stack([t, t ** 2, 0 * t], axis=1)
    v, f = S._tube(path, np.full(20, 0.1), 12)
    side = f[:-24]  # (the last 2 x 12 faces are the end discs)
    a, b, c = v[side[:, 0]], v[side[:, 1]], v[side[:, 2]]
    out = np.einsum("ij,ij->i", np.cross(b - a, c - a), (a + b + c) / 3 - path[side[:, 0] // 12])
    assert np.all(out > 0)
    # closed by its discs, faces outward: the signed volume is the 12-gon's area 3 r^2 times the path's length
    # (Pappus), whatever the origin
    length = np.linalg.norm(np.diff(path, axis=0), axis=1).sum()
    for shift in ([0.0, 0.0, 0.0], [5.0, -3.0, 2.0]):
        assert _signed_volume(v + np.array(shift), f) == pytest.approx(3 * 0.1**2 * length, rel=2e-3)
    v, f = S.teapot_mesh()
    assert f.min() == 0 and f.max() == len(v) - 1 and np.all(np.isfinite(v))
    area = np.linalg.norm(np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]]), axis=1)
    assert np.all(area > 0)
    assert v[:, 1].min() == 0.0 and 1.4 < v[:, 1].max() < 1.5  # stands on y = 0


def test_fireflies_counts_isolated_bright_pixels():
    sys.path.insert(0, os.path.join(ROOT, "scripts", "make"))
    from make_scenes import fireflies

    y = np.tile(np.linspace(0.2, 0.8, 64), (64, 1))  # a smooth ramp: none
    assert fireflies(y) == 0
    y[10, 10] = y[40, 50] = 5.0
    assert fireflies(y) == 2


mi = pytest.importorskip("mitsuba")
pm = pytest.importorskip("pumpup.mitsuba")
LLVM_OK, LLVM_WHY = pm.probe("llvm_ad_rgb")
needs_llvm = pytest.mark.skipif(not LLVM_OK, reason=f"llvm_ad_rgb unusable here: {LLVM_WHY}")


@needs_llvm
def test_mix_bsdf_albedo_matches_pumpup():
    """pumpup_mix of 0.3 x Lambert (per channel 0.2, 0.5, 0.8) + 1 x Phong n = 20: the mean sample weight at
    mu = 0.6 (10^5 draws, fixed seed) is the sum of the components' albedos within 4 standard errors;
    eval equals the weighted sum of the components' eval x cos."""
    import drjit as dr

    S._mitsuba("llvm_ad_rgb")
    rgb = (0.2, 0.5, 0.8)
    mat = [(rgb, {"type": "lambert", "albedo": 1.0}), ((1.0, 1.0, 1.0), {"type": "phong", "n": 20.0})]
    b = mi.load_dict(S._bsdf(mat))
    n = 100_000
    rng = np.random.default_rng(5)
    mu = 0.6
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(math.sqrt(1 - mu * mu), 0.0, mu)
    u = rng.random((3, n)).astype(np.float32)
    bs, w = b.sample(mi.BSDFContext(), si, mi.Float(u[0]), mi.Point2f(u[1], u[2]))
    w = np.array(w)
    a_phong = float(pumpup.albedo(pumpup.load({"type": "phong", "n": 20}), mu))
    for c in range(3):
        est, se = w[c].mean(), w[c].std() / math.sqrt(n)
        assert abs(est - (rgb[c] + a_phong)) < 4 * se + 1e-6, (c, est, rgb[c] + a_phong, se)
    wo = bs.wo
    e = np.array(b.eval(mi.BSDFContext(), si, wo))
    cos = np.maximum(np.array(wo.z), 0.0)
    wi = np.array([math.sqrt(1 - mu * mu), 0.0, mu])
    ph = pumpup.load({"type": "phong", "n": 20}).eval(np.array(wo, dtype=np.float64).T, wi)
    ref = (np.array(rgb)[:, None] / math.pi + ph[None, :]) * cos
    np.testing.assert_allclose(e, ref, rtol=2e-6, atol=1e-7)


@needs_llvm
@pytest.mark.parametrize("name", ["000-fig8", "000-fig9", "000-fig10",
                                  pytest.param("001-fig8", marks=pytest.mark.slow)])
def test_tiny_render(name, tmp_path):
    """Each scene renders at 16 x 16, 4 spp: finite, non-negative, the two versions differ; files written."""
    import io

    buf = io.StringIO()
    v, rows, times = S.render_scene(name, 4, 16, "llvm_ad_rgb", out=buf)
    assert v == "llvm_ad_rgb" and "variant llvm_ad_rgb" in buf.getvalue() and "pass 4/4" in buf.getvalue()
    imgs = [im for r in rows for _, im in r]
    assert all(im.shape == (16, 16, 3) and np.all(np.isfinite(im)) and im.min() >= 0 for im in imgs)
    assert not np.allclose(imgs[0], imgs[-1])
    paths = S.write_scene(name, rows, str(tmp_path), variant=v, spp=4)
    assert all(os.path.getsize(p) > 0 for p in paths) and paths[-1].endswith(f"{name}.png")


@needs_llvm
@pytest.mark.slow
def test_cli_renders_and_prints_the_variant(tmp_path):
    r = _cli("render", "scene", "000-fig9", "--spp", "4", "--size", "16", "--variant", "auto", "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    assert "Mitsuba variant llvm_ad_rgb" in r.stderr and "pass 4/4" in r.stderr
    assert "variant llvm_ad_rgb; 2 panels" in r.stdout
    assert sorted(os.listdir(tmp_path)) == ["000-fig9.png", "000-fig9_00.exr", "000-fig9_01.exr"]
