"""pumpup.caustics (the ``pumpup_caustic`` Mitsuba integrator): its lobe samples what its pdf says, bad input,
and renders of 000 Fig. 8 whose means agree with Mitsuba's ``path`` and with the integrator's own variants
(technique B off, its lobe 16 x wider or narrower) within their standard errors."""

from __future__ import annotations

import math
import os
import sys

import helpers
import numpy as np
import pytest

mi = pytest.importorskip("mitsuba")
pm = pytest.importorskip("pumpup.mitsuba")
LLVM_OK, LLVM_WHY = pm.probe("llvm_ad_rgb")
pytestmark = pytest.mark.skipif(not LLVM_OK, reason=f"llvm_ad_rgb unusable here: {LLVM_WHY}")

ROOT = str(helpers.ROOT)
sys.path.insert(0, os.path.join(ROOT, "scripts", "make"))


@pytest.fixture(scope="module")
def S():
    import pumpup.scenes as scenes

    scenes._mitsuba("llvm_ad_rgb")
    return scenes


def _cls(S):
    from pumpup import caustics

    return caustics._CLASSES[mi.variant()]


@pytest.mark.parametrize("k", [30.0, 5000.0, 80000.0])
def test_lobe_samples_follow_its_pdf(S, k):
    """cos^k lobe about a tilted axis, 2^18 samples: the fraction inside a cap of angle t0 is 1 - cos^(k+1) t0,
    and the mean of 1/q over the cap's samples is its solid angle 2 pi (1 - cos t0), within 4 standard errors."""
    import drjit as dr

    C = _cls(S)
    n = 1 << 18
    rng = np.random.default_rng(1)
    u = mi.Point2f(rng.random(n, dtype=np.float32), rng.random(n, dtype=np.float32))
    d0 = dr.normalize(mi.Vector3f(0.3, -0.8, 0.5))
    kk = mi.Float(k)
    w = C._lobe_sample(d0, kk, u)
    q = np.array(C._lobe_pdf(w, d0, kk, mi.Bool(True)), dtype=np.float64)
    assert np.allclose(np.array(dr.norm(w)), 1.0, atol=1e-6)
    t0 = 1.5 / math.sqrt(k)  # about 1.06 standard deviations of the angle
    cos = np.array(dr.dot(w, d0), dtype=np.float64)
    om = 0.5 * np.array(dr.squared_norm(w - d0), dtype=np.float64)  # 1 - cos, accurate
    inside = om < 1 - math.cos(t0)
    p = 1 - math.exp((k + 1) * math.log(math.cos(t0)))
    assert abs(inside.mean() - p) < 4 * math.sqrt(p * (1 - p) / n)
    g = np.where(inside, 1.0 / q, 0.0)
    cap = 2 * math.pi * (1 - math.cos(t0))
    assert abs(g.mean() - cap) < 4 * g.std() / math.sqrt(n)
    assert np.all(cos > 0)


def test_mirror_faces_of_rectangles_and_cubes(S):
    """A rectangle is one face; two cubes that Mitsuba merges into one mesh (same BSDF) are 12 faces, each a
    rectangle of the cube's half size, centred on its face, its normal pointing outwards."""
    T = mi.ScalarTransform4f
    bsdf = {"type": "diffuse"}
    cubes = [((0.0, 0.5, 0.0), 0.5, 0.0), ((2.0, 0.3, 1.0), 0.3, 45.0)]
    d = {"type": "scene", "plate": {"type": "rectangle", "to_world": T().rotate([1, 0, 0], -90) @ T().scale(3.2)}}
    for i, (c, h, turn) in enumerate(cubes):
        d[f"c{i}"] = {"type": "cube", "bsdf": bsdf,
                      "to_world": T().translate(list(c)) @ T().rotate([0, 1, 0], turn) @ T().scale(h)}
    scene = mi.load_dict(d)
    C = _cls(S)
    faces = [f for shape in scene.shapes() for f in C._faces(shape)]
    assert len(faces) == 13
    plate = [f for f in faces if abs(f[0][1]) < 1e-6 and np.linalg.norm(f[1]) > 3]
    assert len(plate) == 1 and np.allclose(np.cross(plate[0][1], plate[0][2]) / 3.2 ** 2, [0, 1, 0], atol=1e-6)
    for c, u, v in faces:
        if np.linalg.norm(u) > 3:
            continue
        n = np.cross(u, v)
        n /= np.linalg.norm(n)
        owner = [(np.array(cc), h) for cc, h, _ in cubes if np.linalg.norm(c - cc) < h * 1.01]
        assert len(owner) == 1
        cc, h = owner[0]
        assert np.linalg.norm(u) == pytest.approx(h, rel=1e-5) and np.linalg.norm(v) == pytest.approx(h, rel=1e-5)
        assert abs(u @ v) < 1e-6 and (c - cc) @ n == pytest.approx(h, rel=1e-5)


def test_bad_mirror_is_one_line(S):
    label, mats = S.panels("000-fig8")[0][0]
    d = S._scene_dict("000-fig8", mats, 8, 1)
    for integ, words in (({"type": "pumpup_caustic", "mirror": "nope"},
                          "mirror must name shapes of the scene (comma-separated ids, or '*' and '-id' to "
                          "exclude), got 'nope'"),
                         ({"type": "pumpup_caustic", "k_scale": 0.0}, "mirror_n and k_scale must be > 0"),
                         ({"type": "pumpup_caustic", "margin": -1.0}, "margin must be >= 0, got -1.0")):
        d["integrator"] = integ
        with pytest.raises(Exception) as e:
            mi.render(mi.load_dict(d))
        chain, x = [], e.value
        while x is not None:
            chain.append(str(x))
            x = x.__cause__ or x.__context__
        assert any(words in m for m in chain), chain


def _check(size, spp, passes, pairs, zmax, rough=None, scene="000-fig8"):
    import caustic_check as C

    S = C.S
    setup = C.SETUP[scene]
    i, j = setup["panels"][0]
    label, mats = S.panels(scene)[i][j]
    integ = {k: dict(v) for k, v in C.INTEGRATORS.items()}
    for v in integ.values():
        if v["type"] == "pumpup_caustic":
            v.update(mirror=setup["mirror"], mirror_n=float(rough or 5000))
    if rough is not None:  # rougher mirrors: Mitsuba's path converges too, the comparison is tight
        mats = dict(mats, **{o: S.metal(metal, rough, "phong") for o, metal in setup["metals"].items()})
    masks = C.regions(scene, mats, size)
    assert masks["plate"].sum() > 0.2 * size * size and masks["sky"].sum() > 0.2 * size * size
    ys = {k: C.passes(scene, mats, integ[k], size, spp, passes, 1000 * j)[0] for j, k in enumerate(C.INTEGRATORS)}
    res = C.compare(ys, {k: m for k, m in masks.items() if m.sum() >= 4})
    for region, r in res.items():
        for pair in pairs:
            assert abs(r["z"][pair]) < zmax, (region, pair, r)
    return res


#: the pairs of integrators (scripts/make/caustic_check.py's INTEGRATORS) whose means the small renders compare
PAIRS = ["path vs caustic, B off", "path vs caustic", "caustic, B off vs caustic", "caustic vs caustic, k / 16",
         "caustic vs caustic, k x 16", "caustic, C off vs caustic", "path vs caustic, C off"]


def test_means_agree_small_render(S):
    """000 Fig. 8 with a plate of n = 300 (not 5000: there Mitsuba's path needs far more samples to converge),
    24 x 24, 6 passes x 64 spp of each integrator: per region (all, sky, each object, plate), pumpup_caustic
    with its mirror-image technique agrees with its lobe 16 x wider and narrower, with technique B off and
    with Mitsuba's path, and B off with path, within 4 combined standard errors."""
    res = _check(24, 64, 6, PAIRS, 4.0, rough=300)
    assert res["all"]["caustic"]["se"] < res["all"]["caustic, B off"]["se"]  # and it is less noisy


def test_means_agree_small_render_cubes(S):
    """001 Fig. 8's reciprocal Phong panel with its five cubes at n = 300 (the near-mirrors are the cubes'
    faces), 20 x 20, 5 passes x 48 spp: the same agreement per region."""
    _check(20, 48, 5, PAIRS, 4.0, rough=300, scene="001-fig8")


def test_margin_keeps_the_mean(S):
    """001 Fig. 8's reciprocal Phong panel, cubes at n = 300, 20 x 20, 5 passes x 48 spp: technique B with
    specular points only on the faces (margin 0), with the default margin and with a margin 4 x wider agree per
    region within 4 combined standard errors (the margin changes both MIS weights, not the expectation)."""
    import caustic_check as C

    setup = C.SETUP["001-fig8"]
    i, j = setup["panels"][0]
    label, mats = C.S.panels("001-fig8")[i][j]
    mats = dict(mats, **{o: C.S.metal(metal, 300, "phong") for o, metal in setup["metals"].items()})
    masks = C.regions("001-fig8", mats, 20)
    ys = {}
    for k, m in enumerate((0.0, 3.0, 12.0)):
        integ = {"type": "pumpup_caustic", "max_depth": 6, "mirror": setup["mirror"], "mirror_n": 300.0,
                 "margin": m}
        ys[m] = C.passes("001-fig8", mats, integ, 20, 48, 5, 500 * k)[0]
    res = C.compare(ys, {k: m for k, m in masks.items() if m.sum() >= 4})
    for region, r in res.items():
        for pair, z in r["z"].items():
            assert abs(z) < 4.0, (region, pair, r)


@pytest.mark.slow
def test_means_agree_and_fireflies_drop(S):
    """64 x 64, 16 passes x 256 spp: every pair of integrators agrees within 4 combined standard errors per
    region; at 256 x 256 and 64 spp the fireflies of 000 Fig. 8's left panel drop at least 10 x."""
    import caustic_check as C

    res = _check(64, 256, 16, [], 4.0)
    for region, r in res.items():
        assert all(abs(z) < 4.0 for z in r["z"].values()), (region, r)
    from make_scenes import fireflies

    label, mats = C.S.panels("000-fig8")[0][0]
    y_path = C.passes("000-fig8", mats, C.INTEGRATORS["path"], 256, 64, 1, 7)[0][0]
    y_new = C.passes("000-fig8", mats, C.INTEGRATORS["caustic"], 256, 64, 1, 7)[0][0]
    assert fireflies(y_new) * 10 <= fireflies(y_path)
